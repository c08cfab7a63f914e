//! Verification of the finite-strain solver against closed forms (issue: solver core).

use std::path::Path;

use splinecontact::format::scres::Results;
use splinecontact::format::setup::SolveSetup;
use splinecontact::format::{scmesh, scres::RunStatus};
use splinecontact::mesh::Mesh;
use splinecontact::solver::log::Verbosity;
use splinecontact::stages::solve::solve;

use crate::common::grid::{add_node_set, block};
use crate::common::tempdir;

/// Solve `mesh` with the setup YAML through the real stage (files on disk).
pub fn run(mesh: &Mesh, setup_yaml: &str) -> Results {
    try_run(mesh, setup_yaml).unwrap_or_else(|e| panic!("solve failed: {e}"))
}

pub fn try_run(mesh: &Mesh, setup_yaml: &str) -> Result<Results, String> {
    let dir = tempdir();
    let m = dir.path().join("m.scmesh");
    scmesh::write(&m, mesh, "test").unwrap();
    let setup = SolveSetup::parse("setup", setup_yaml).map_err(|e| e.to_string())?;
    let out = dir.path().join("r.scres");
    let r = solve(&m, &setup, "setup", &out, None, None, Verbosity::Quiet);
    let results = Results::read(Path::new(&out)).ok();
    match (r, results) {
        (Ok(_), Some(res)) => Ok(res),
        (Err(e), Some(res)) if matches!(res.status, RunStatus::Stopped { .. }) => Err(format!("{e} [kept {} increments]", res.increments.len())),
        (Err(e), _) => Err(e.to_string()),
        (Ok(_), None) => Err("no results file".into()),
    }
}

/// Lateral stretch of uniaxial stress at axial stretch `l1`: σ22(l1, l2) = 0 by bisection.
fn lateral_stretch(sigma: impl Fn(f64, f64) -> [f64; 2], l1: f64) -> f64 {
    let (mut a, mut b) = (0.2, 1.5);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if sigma(l1, m)[1] > 0.0 {
            b = m
        } else {
            a = m
        }
    }
    0.5 * (a + b)
}

/// (σ11, σ22) of the Ciarlet–Simo neo-Hookean (eq. 3.3) for b = diag(l1², l2², l2²).
fn ciarlet_simo(lam: f64, mu: f64) -> impl Fn(f64, f64) -> [f64; 2] {
    move |l1, l2| {
        let j = l1 * l2 * l2;
        let p = lam / (2.0 * j) * (j * j - 1.0);
        [p + mu / j * (l1 * l1 - 1.0), p + mu / j * (l2 * l2 - 1.0)]
    }
}

/// (σ11, σ22) of the deviatoric/volumetric neo-Hookean (eq. 8.2): μ J^{-5/3} dev b + K (J − 1) I.
fn dev_vol(mu: f64, kappa: f64) -> impl Fn(f64, f64) -> [f64; 2] {
    move |l1, l2| {
        let j = l1 * l2 * l2;
        let tr = (l1 * l1 + 2.0 * l2 * l2) / 3.0;
        let f = mu * j.powf(-5.0 / 3.0);
        [f * (l1 * l1 - tr) + kappa * (j - 1.0), f * (l2 * l2 - tr) + kappa * (j - 1.0)]
    }
}

const E: f64 = 1000.0;
const NU: f64 = 0.3;

fn lame() -> (f64, f64) {
    (E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU)), E / (2.0 * (1.0 + NU)))
}

/// Uniaxial stretch of a distorted 3×3×3 mesh (symmetry planes x0, y0, z0; face x1
/// pulled to stretch 1.4 in 4 increments): every Gauss-point stress equals the
/// closed form to round-off, for both neo-Hookean forms. The homogeneous state is
/// in the trial space of any hex8 mesh, so only round-off may separate them.
fn patch_test(model: &str, closed: impl Fn(f64, f64) -> [f64; 2]) {
    let mesh = block([3, 3, 3], [1.0, 1.0, 1.0], 0.35);
    let l1 = 1.4;
    let setup = format!(
        "materials: [{{body: block, model: {model}, E: {E}, nu: {NU}}}]\nconstraints:\n  - {{set: x0, fix: [x]}}\n  - {{set: y0, fix: [y]}}\n  - {{set: z0, fix: [z]}}\n  - {{set: x1, displacement: {{x: {}}}}}\nincrements: {{count: 4}}\nnewton: {{residual_tolerance: 1.0e-12, energy_tolerance: 1.0e-24}}\n",
        l1 - 1.0
    );
    let r = run(&mesh, &setup);
    let l2 = lateral_stretch(&closed, l1);
    let s11 = closed(l1, l2)[0];
    let last = r.increments.last().unwrap();
    let mut worst: f64 = 0.0;
    for el in &last.stress {
        for s in el {
            let expect = [s11, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
            for i in 0..9 {
                worst = worst.max((s[i] - expect[i]).abs() / s11.abs());
            }
        }
    }
    assert!(worst < 1e-9, "{model}: worst relative stress error {worst:e} (σ11 = {s11})");
    // Lateral contraction of the free faces matches the closed form too.
    let y1 = mesh.node_set("y1").unwrap();
    for &n in &y1.nodes {
        let uy = last.u[n as usize][1];
        assert!((uy - (l2 - 1.0)).abs() < 1e-9, "u_y = {uy}, expected {}", l2 - 1.0);
    }
}

#[test]
fn patch_test_uniaxial_ciarlet_simo() {
    let (lam, mu) = lame();
    patch_test("neo_hookean", ciarlet_simo(lam, mu));
}

#[test]
fn patch_test_uniaxial_dev_vol() {
    let (lam, mu) = lame();
    patch_test("neo_hookean_dev_vol", dev_vol(mu, lam + 2.0 * mu / 3.0));
}

/// Total and updated Lagrangian give the same solution (to solver tolerance).
#[test]
fn total_and_updated_lagrangian_agree() {
    let mesh = block([4, 2, 2], [4.0, 1.0, 1.0], 0.2);
    let base = "materials: [{body: block, model: neo_hookean, E: 1000.0, nu: 0.3}]\nconstraints: [{set: x0, fix: [x, y, z]}]\nloads: [{set: x1, force: [0, 0, -20]}]\nincrements: {count: 3}\nnewton: {residual_tolerance: 1.0e-11}\n";
    let tl = run(&mesh, &format!("formulation: total_lagrangian\n{base}"));
    let ul = run(&mesh, &format!("formulation: updated_lagrangian\n{base}"));
    let (a, b) = (&tl.increments.last().unwrap().u, &ul.increments.last().unwrap().u);
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.1, "the load must bend the beam visibly: max |u| = {scale}");
    let diff = a.iter().flatten().zip(b.iter().flatten()).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(diff < 1e-8 * scale, "TL and UL differ by {diff:e} (max |u| {scale})");
}

/// The `rotation` constraint (setup YAML): a node set of three corners turned by
/// 120° about the axis (1, 1, 1) through the block's centre after a translation
/// d = (0.3, −0.2, 0.1), in 24 increments through the whole solve. Every node ends at
/// x = c + R(X + d − c) (u to 1e-10), the stress stays at round-off, and the
/// reaction on the set is zero: a rigid motion needs no force. A rotation with
/// `fix`, or about a zero axis, is refused naming the set.
#[test]
fn rotation_constraint_moves_a_set_rigidly() {
    let mut mesh = block([2, 2, 2], [1.0, 1.0, 1.0], 0.25);
    add_node_set(&mut mesh, "three", |x| x == &[0.0, 0.0, 0.0] || x == &[1.0, 0.0, 0.0] || x == &[0.0, 1.0, 1.0]);
    let yaml = "materials: [{body: block, model: neo_hookean, E: 1000.0, nu: 0.3}]\n\
        constraints:\n  - {set: three, displacement: {x: 0.3, y: -0.2, z: 0.1}, rotation: {axis: [1, 1, 1], center: [0.5, 0.5, 0.5], angle: 2.0943951023931953}}\n\
        increments: {count: 24}\nnewton: {residual_tolerance: 1.0e-10}\n";
    let r = run(&mesh, yaml);
    let u = &r.increments.last().unwrap().u;
    let axis = nalgebra::Unit::new_normalize(nalgebra::Vector3::new(1.0, 1.0, 1.0));
    let rot = nalgebra::Rotation3::from_axis_angle(&axis, 2.0 * std::f64::consts::PI / 3.0);
    let (c, d) = (nalgebra::Vector3::new(0.5, 0.5, 0.5), nalgebra::Vector3::new(0.3, -0.2, 0.1));
    for (n, x) in mesh.nodes.iter().enumerate() {
        let x = nalgebra::Vector3::from(*x);
        let expect = c + rot * (x + d - c) - x;
        for i in 0..3 {
            assert!((u[n][i] - expect[i]).abs() < 1e-10, "node {n}: u = {:?}, expected {expect:?}", u[n]);
        }
    }
    let worst = r.increments.last().unwrap().stress.iter().flatten().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(worst < 1e-9 * 1000.0, "stress after a rigid motion: {worst:e}");
    let reaction = &r.increments.last().unwrap().info.reactions[0];
    assert!(reaction.force.iter().all(|f| f.abs() < 1e-8), "{reaction:?}");
    // refusals
    let e = try_run(&mesh, &yaml.replace("displacement: {x: 0.3, y: -0.2, z: 0.1}", "fix: [x]")).unwrap_err();
    assert!(e.contains("constraint on 'three': `rotation` prescribes every component, so `fix` cannot be given with it"), "{e}");
    let e = try_run(&mesh, &yaml.replace("axis: [1, 1, 1]", "axis: [0, 0, 0]")).unwrap_err();
    assert!(e.contains("constraint on 'three': the rotation axis [0, 0, 0] has no direction"), "{e}");
}

/// Rigid rotation of 90° about z in 18 increments, imposed on three nodes only: the
/// free nodes follow the rotation and the stress stays at round-off.
#[test]
fn rigid_rotation_90_degrees() {
    use splinecontact::solver::newton::Newton;
    use splinecontact::solver::problem::{Prescribed, Problem};
    let mut mesh = block([2, 2, 2], [1.0, 1.0, 1.0], 0.25);
    add_node_set(&mut mesh, "a", |x| x == &[0.0, 0.0, 0.0]);
    add_node_set(&mut mesh, "b", |x| x == &[1.0, 0.0, 0.0]);
    add_node_set(&mut mesh, "c", |x| x == &[0.0, 1.0, 0.0]);
    let setup = SolveSetup::parse(
        "s",
        "materials: [{body: block, model: neo_hookean, E: 1000.0, nu: 0.3}]\nconstraints:\n  - {set: a, fix: [x, y, z]}\n  - {set: b, fix: [x, y, z]}\n  - {set: c, fix: [x, y, z]}\nnewton: {residual_tolerance: 1.0e-10}\n",
    )
    .unwrap();
    let mut problem = Problem::new(&mesh, &setup, "s").unwrap();
    let pinned: Vec<u32> = ["a", "b", "c"].iter().map(|s| mesh.node_set(s).unwrap().nodes[0]).collect();
    let mut u = vec![0.0; 3 * mesh.nodes.len()];
    let steps = 18;
    for k in 1..=steps {
        let th = std::f64::consts::FRAC_PI_2 * k as f64 / steps as f64;
        let (c, s) = (th.cos(), th.sin());
        problem.prescribed = pinned
            .iter()
            .flat_map(|&n| {
                let x = mesh.nodes[n as usize];
                let d = 3 * n as usize;
                [(d, c * x[0] - s * x[1] - x[0]), (d + 1, s * x[0] + c * x[1] - x[1]), (d + 2, 0.0)].map(|(dof, value)| Prescribed { dof, value, amplitude: 0 })
            })
            .collect();
        let mut newton = Newton::new(&problem, setup.newton.clone(), setup.linear_solver.clone()).unwrap();
        newton.solve_increment(1.0, &mut u, &mut |_| {}).unwrap();
    }
    // Every node rotated by 90°: u = (R − I) X.
    for (n, x) in mesh.nodes.iter().enumerate() {
        let expect = [-x[1] - x[0], x[0] - x[1], 0.0];
        for i in 0..3 {
            assert!((u[3 * n + i] - expect[i]).abs() < 1e-10, "node {n}: u = {:?}", &u[3 * n..3 * n + 3]);
        }
    }
    let stress = splinecontact::solver::newton::gauss_stresses(&problem, &u).unwrap();
    let worst = stress.iter().flatten().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(worst < 1e-9 * 1000.0, "stress after a rigid rotation: {worst:e}");
}

/// Cantilever 10×1×1, ν = 0, clamped at x = 0, tip load P small: tip deflection
/// against Timoshenko beam theory δ = PL³/(3EI) + PL/(κGA). Fully integrated hex8
/// locks in bending, so it is stiffer: the tolerance is set from the measured locking
/// on each mesh (reported in docs/validation.md) and asserts it does not grow.
fn cantilever_tip(n: [usize; 3]) -> (f64, f64) {
    let mesh = block(n, [10.0, 1.0, 1.0], 0.0);
    let p = 1e-3;
    let setup = format!(
        "materials: [{{body: block, model: linear_elastic, E: 1000.0, nu: 0.0}}]\nconstraints: [{{set: x0, fix: [x, y, z]}}]\nloads: [{{set: x1, force: [0, 0, {}]}}]\n",
        -p
    );
    let r = run(&mesh, &setup);
    let tip = mesh.node_set("x1").unwrap();
    let inc = r.increments.last().unwrap();
    let uz = -tip.nodes.iter().map(|&n| inc.u[n as usize][2]).sum::<f64>() / tip.nodes.len() as f64;
    let (e, l, i, g, a): (f64, f64, f64, f64, f64) = (1000.0, 10.0, 1.0 / 12.0, 500.0, 1.0);
    let theory = p * l.powi(3) / (3.0 * e * i) + p * l / (5.0 / 6.0 * g * a);
    (uz, theory)
}

#[test]
fn cantilever_refined_matches_beam_theory() {
    let (uz, theory) = cantilever_tip([40, 4, 4]);
    let ratio = uz / theory;
    // Measured 0.9694: fully integrated hex8 with 4 cubic elements through the depth
    // is ~3 % too stiff in bending (shear locking), and beam theory itself is exact to
    // well under 1 % at L/h = 10 with ν = 0. The band [0.96, 1.0] allows the locking
    // and nothing else: a wrong stiffness, load or constraint moves it far outside.
    assert!(ratio > 0.96 && ratio < 1.0, "tip deflection {uz:e} vs theory {theory:e}: ratio {ratio}");
}

#[test]
fn cantilever_coarse_locking_is_measured() {
    // The paper's beams are two elements deep with elongated elements: locking is
    // severe there. Pin the measured ratio so a change in the element is noticed.
    let (uz, theory) = cantilever_tip([15, 2, 2]);
    let ratio = uz / theory;
    // Measured 0.8174: hex8 full integration, 2 elements deep (as the paper's beams),
    // is 18 % too stiff. ±0.01 pins it: any change of the element formulation shows.
    assert!((ratio - 0.8174).abs() < 0.01, "coarse ratio {ratio}");
    eprintln!("coarse cantilever 15x2x2: deflection ratio {ratio:.4}");
}

/// Newton's rate: a block compressed by 30 % in one increment (strongly nonlinear);
/// near the solution each residual is about the square of the previous one. Pure
/// Newton (`max_step_halvings: 0`): a correction that inverts an element cuts the
/// increment back instead of being halved, so every correction measured is a full
/// Newton step and the rate is the tangent's.
#[test]
fn newton_converges_quadratically() {
    let mesh = block([3, 3, 3], [1.0, 1.0, 1.0], 0.3);
    let setup = "materials: [{body: block, model: neo_hookean, E: 1000.0, nu: 0.3}]\nconstraints:\n  - {set: z0, fix: [x, y, z]}\n  - {set: z1, displacement: {x: 0.2, z: -0.3}}\nnewton: {residual_tolerance: 1.0e-13, energy_tolerance: 1.0e-30, max_iterations: 30, max_step_halvings: 0}\n";
    let r = run(&mesh, setup);
    let it = &r.increments[0].info.iterations;
    let res: Vec<f64> = it.iter().map(|i| i.residual).collect();
    assert!(res.len() >= 4, "too few iterations to see a rate: {res:?}");
    // Every pair with r_k < 1e-2 and r_{k+1} above the round-off floor (1e-13):
    // log r_{k+1} / log r_k ≥ 1.8 (2 is the quadratic rate).
    let pairs: Vec<(f64, f64)> = res.windows(2).map(|w| (w[0], w[1])).filter(|(a, b)| *a < 1e-2 && *b > 1e-13).collect();
    assert!(!pairs.is_empty(), "no pair in the asymptotic range: {res:?}");
    for (a, b) in pairs {
        let rate = b.ln() / a.ln();
        assert!(rate > 1.8, "rate {rate} from {a:e} to {b:e}; residuals {res:?}");
    }
}

/// A cube under a follower pressure on all six faces compresses uniformly with
/// σ = −p I; the closed form for Ciarlet–Simo gives J from p = −σ(J). Exercises the
/// load stiffness and the LU path (the tangent is non-symmetric face by face).
#[test]
fn hydrostatic_follower_pressure() {
    let mesh = block([2, 2, 2], [1.0, 1.0, 1.0], 0.2);
    let p = 200.0;
    let setup = format!(
        "materials: [{{body: block, model: neo_hookean, E: {E}, nu: {NU}}}]\nconstraints:\n  - {{set: x0, fix: [x]}}\n  - {{set: y0, fix: [y]}}\n  - {{set: z0, fix: [z]}}\nloads:\n  - {{face_set: x1, pressure: {p}}}\n  - {{face_set: y1, pressure: {p}}}\n  - {{face_set: z1, pressure: {p}}}\nincrements: {{count: 2}}\nnewton: {{residual_tolerance: 1.0e-12}}\n"
    );
    let r = run(&mesh, &setup);
    let (lam, mu) = lame();
    // σ = λ/(2J)(J² − 1) + μ/J (J^{2/3} − 1) = −p, solved by bisection.
    let sig = |j: f64| lam / (2.0 * j) * (j * j - 1.0) + mu / j * (j.powf(2.0 / 3.0) - 1.0);
    let (mut a, mut b) = (0.1, 1.0);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if sig(m) > -p {
            b = m
        } else {
            a = m
        }
    }
    let stretch = (0.5 * (a + b)).cbrt();
    let inc = r.increments.last().unwrap();
    for (n, x) in mesh.nodes.iter().enumerate() {
        for (i, xi) in x.iter().enumerate() {
            let expect = (stretch - 1.0) * xi;
            assert!((inc.u[n][i] - expect).abs() < 1e-9, "node {n} comp {i}: {} vs {expect}", inc.u[n][i]);
        }
    }
    let s = inc.stress[0][0];
    assert!((s[0] + p).abs() < 1e-8 * p && s[1].abs() < 1e-8 * p, "σ = {s:?}");
}

/// An increment too large for Newton is cut back and the solve still reaches λ = 1.
#[test]
fn cutback_recovers_a_too_large_increment() {
    let mesh = block([2, 2, 2], [1.0, 1.0, 1.0], 0.0);
    let setup = "materials: [{body: block, model: neo_hookean, E: 1000.0, nu: 0.3}]\nconstraints:\n  - {set: z0, fix: [x, y, z]}\n  - {set: z1, displacement: {x: 0.6, z: -0.5}}\nnewton: {max_iterations: 6, residual_tolerance: 1.0e-9}\nincrements: {count: 1, max_cutbacks: 6}\n";
    let r = run(&mesh, setup);
    let cutbacks: u32 = r.increments.iter().map(|i| i.info.cutbacks).sum();
    assert!(cutbacks > 0, "expected cutbacks, got none");
    assert_eq!(r.increments.last().unwrap().info.load_factor, 1.0);
    assert!(r.increments.len() > 1, "sub-increments are kept as increments");
}

/// When cutbacks are exhausted the solve stops, names the increment, and every
/// converged increment is on disk.
#[test]
fn exhausted_cutbacks_stop_and_keep_converged_increments() {
    let mesh = block([2, 2, 2], [1.0, 1.0, 1.0], 0.0);
    let setup = "materials: [{body: block, model: neo_hookean, E: 1000.0, nu: 0.3}]\nconstraints:\n  - {set: z0, fix: [x, y, z]}\n  - {set: z1, displacement: {z: -0.95}}\nnewton: {max_iterations: 3}\nincrements: {factors: [0.05, 1.0], max_cutbacks: 1}\n";
    let e = try_run(&mesh, setup).unwrap_err();
    assert!(e.contains("solve stopped at increment 2") && e.contains("kept 1 increments"), "{e}");
}
