//! Verification of frictionless contact (issue: frictionless contact): the contact
//! patch test on flat masters, against the closed form of two elastic blocks in
//! series with the penalty layer between them.

use splinecontact::format::sccontact::MasterKind;
use splinecontact::format::scres::{Results, RunStatus};
use splinecontact::format::setup::SolveSetup;
use splinecontact::mesh::Mesh;
use splinecontact::solver::log::Verbosity;
use splinecontact::stages::solve::solve;
use splinecontact::stages::tag::{build_model, PairSpec};

use crate::common::grid::{block, two_bodies};
use crate::common::tempdir;

/// Tag `pairs` on `mesh` and solve `setup_yaml` through the real stages.
pub fn run_contact(mesh: &Mesh, pairs: &[PairSpec], setup_yaml: &str) -> Results {
    let model = build_model(mesh.clone(), "test", pairs).unwrap_or_else(|e| panic!("tag: {e}"));
    solve_model(&model, setup_yaml)
}

/// Solve `setup_yaml` on a contact model through the real stages (its file written
/// and read back).
pub fn solve_model(model: &splinecontact::format::sccontact::ContactModel, setup_yaml: &str) -> Results {
    let dir = tempdir();
    let c = dir.path().join("m.sccontact");
    model.write(&c).unwrap();
    let setup = SolveSetup::parse("setup", setup_yaml).unwrap_or_else(|e| panic!("{e}"));
    let out = dir.path().join("r.scres");
    let r = solve(&c, &setup, "setup", &out, None, None, Verbosity::Quiet);
    if let Err(e) = r {
        panic!("solve failed: {e}");
    }
    let res = Results::read(&out).unwrap();
    assert_eq!(res.status, RunStatus::Completed);
    res
}

pub fn pair(master_kind: MasterKind, orders: Option<[usize; 2]>, slave: &str, master: &str) -> PairSpec {
    PairSpec { name: "c".into(), slave: slave.into(), master: master.into(), master_kind, orders }
}

/// Two unit-square blocks of height 0.5 stacked (lower `nl × nl × 2` is the master,
/// upper `nu × nu × 2` the slave), linear elastic E = 1000, ν = 0.3, supported on
/// symmetry planes (x = 0: u_x = 0, y = 0: u_y = 0, both bodies), base u_z = 0, top
/// u_z = −d. The exact solution is homogeneous uniaxial stress σ in both blocks:
/// `d = σ H / E + σ / ε_N` (blocks and penalty layer in series; `H` = 1), so the
/// pressure is `σ = d / (H/E + 1/ε_N)` at every slave node (augmented Lagrangian:
/// `1/ε_N` → 0 as the penetration does).
pub fn patch_setup(enforcement: &str, eps_n: f64, d: f64) -> String {
    format!(
        "materials:\n  - {{body: lower, model: linear_elastic, E: 1000.0, nu: 0.3}}\n  - {{body: upper, model: linear_elastic, E: 1000.0, nu: 0.3}}\n\
         constraints:\n  - {{set: lower_x0, fix: [x]}}\n  - {{set: lower_y0, fix: [y]}}\n  - {{set: lower_z0, fix: [z]}}\n  - {{set: upper_x0, fix: [x]}}\n  - {{set: upper_y0, fix: [y]}}\n  - {{set: upper_z1, displacement: {{z: {}}}}}\n\
         contact:\n  - {{pair: c, eps_n: {eps_n:e}, enforcement: {enforcement}, penetration_tolerance: 1.0e-9, max_augmentations: 30}}\n\
         newton: {{residual_tolerance: 1.0e-10}}\n",
        -d
    )
}

fn stacked(nl: usize, nu: usize) -> Mesh {
    two_bodies("lower", &block([nl, nl, 2], [1.0, 1.0, 0.5], 0.0), "upper", &block([nu, nu, 2], [1.0, 1.0, 0.5], 0.0), [0.0, 0.0, 0.5])
}

pub struct Patch {
    /// max |p_i − σ| / σ over the slave nodes
    pub pointwise: f64,
    /// |Σ p_i A_i − σ A| / (σ A)
    pub total: f64,
    /// |Σ p_i A_i − base reaction| / (σ A)
    pub equilibrium: f64,
    pub augmentations: u32,
    pub iterations: usize,
}

fn patch(nl: usize, nu: usize, kind: MasterKind, orders: Option<[usize; 2]>, enforcement: &str) -> Patch {
    patch_with(nl, nu, kind, orders, enforcement, "node")
}

fn patch_with(nl: usize, nu: usize, kind: MasterKind, orders: Option<[usize; 2]>, enforcement: &str, integration: &str) -> Patch {
    let (e, eps, d) = (1000.0, 1.0e5, 1.0e-3);
    let mesh = stacked(nl, nu);
    let setup = patch_setup(enforcement, eps, d).replace("max_augmentations: 30}", &format!("max_augmentations: 30, integration: {integration}}}"));
    let sigma = if enforcement == "penalty" { d / (1.0 / e + 1.0 / eps) } else { d * e };
    patch_on(&mesh, pair(kind, orders, "upper_z0", "lower_z1"), &setup, sigma, "lower_z0", 1.0)
}

/// The patch test's figures for `spec` on `mesh` under `setup`: `sigma` the exact
/// pressure, `base` the constraint set whose reaction balances the contact force,
/// `area` the contact area.
pub fn patch_on(mesh: &Mesh, spec: PairSpec, setup: &str, sigma: f64, base: &str, area: f64) -> Patch {
    let label = format!("{:?} {:?}", spec.master_kind, spec.orders);
    let r = run_contact(mesh, &[spec], setup);
    let inc = r.increments.last().unwrap();
    let state = &inc.contact[0];
    let pressures: Vec<f64> = state.iter().map(|s| -s[1]).collect();
    assert!(state.iter().all(|s| s[3] == 1.0), "{label}: every slave node active: {state:?}");
    let pointwise = pressures.iter().map(|p| (p - sigma).abs() / sigma).fold(0.0, f64::max);
    let summary = &inc.info.contact[0];
    let total = (summary.force[2] - sigma * area).abs() / (sigma * area);
    let base_force = inc.info.reactions.iter().find(|r| r.set == base).unwrap().force[2];
    eprintln!(
        "patch {label}: σ = {sigma:.9}, pressures {:.9}..{:.9}, total force {:.12}, base {base_force:.12}, augmentations {}",
        pressures.iter().copied().fold(f64::INFINITY, f64::min),
        pressures.iter().copied().fold(0.0, f64::max),
        summary.force[2],
        summary.augmentations
    );
    Patch {
        pointwise,
        total,
        equilibrium: (base_force.abs() - summary.force[2]).abs() / (sigma * area),
        augmentations: summary.augmentations,
        iterations: inc.info.iterations.len(),
    }
}

/// Matching meshes on a flat master: the slave nodes sit on master nodes, so every
/// master kind transmits the pressure exactly: the linear problem is solved to the
/// Newton tolerance 1e-11, so 1e-9 relative is round-off plus tolerance.
#[test]
fn patch_test_matching_meshes_is_exact() {
    for (kind, orders) in [(MasterKind::Facet, None), (MasterKind::Bspline, Some([2, 2]))] {
        let p = patch(4, 4, kind, orders, "penalty");
        assert!(p.pointwise < 1e-9 && p.total < 1e-9 && p.equilibrium < 1e-9, "{kind:?}: pointwise {:e}, total {:e}, equilibrium {:e}", p.pointwise, p.total, p.equilibrium);
    }
}

/// Slave nodes that do not sit on the master's nodes (non-matching meshes, slave the
/// finer side, or a higher-order B-spline master whose basis spreads each slave
/// force over several control points): one-pass node-to-surface is not exact
/// pointwise (Zavarise & De Lorenzis 2009): the master is loaded by nodal forces
/// that are not those of a uniform pressure, and the stiff penalty layer makes the
/// slave follow the master's resulting waviness. Asserted: equilibrium (the contact
/// force equals the base reaction, to the Newton tolerance) and the pointwise
/// deviation from the exact pressure, pinned at the measured value + 20 % so a change
/// that degrades it is caught (values in docs/validation.md).
#[test]
#[allow(clippy::type_complexity)] // the table of cases
fn patch_test_one_pass_deviation_is_pinned() {
    // (lower, upper, master, orders, measured pointwise deviation, measured total deviation)
    let cases: [(usize, usize, MasterKind, Option<[usize; 2]>, f64, f64); 4] = [
        (3, 5, MasterKind::Facet, None, 1.206e-1, 1.581e-3),
        (3, 5, MasterKind::Bspline, Some([3, 3]), 3.507e-1, 1.353e-2),
        (4, 4, MasterKind::Bspline, Some([3, 3]), 3.578e-1, 2.247e-2),
        (4, 4, MasterKind::Bspline, Some([4, 4]), 4.282e-1, 2.370e-2),
    ];
    for (nl, nu, kind, orders, pointwise, total) in cases {
        let p = patch(nl, nu, kind, orders, "penalty");
        eprintln!("  {nl}/{nu} {kind:?} {orders:?}: pointwise deviation {:.4e}, total {:.4e}, total vs base {:.3e}", p.pointwise, p.total, p.equilibrium);
        assert!(p.equilibrium < 1e-9, "{kind:?} {orders:?}: contact force vs base reaction {:e}", p.equilibrium);
        assert!(p.pointwise < 1.2 * pointwise, "{kind:?} {orders:?}: pointwise {:e} above the pinned {pointwise:e}", p.pointwise);
        assert!(p.total < 1.2 * total, "{kind:?} {orders:?}: total {:e} above the pinned {total:e}", p.total);
    }
}

/// Mortar integration (`contact::mortar`) passes the contact patch test pointwise on
/// every mesh pair of the one-pass table and the master finer, with every master:
/// the traction is integrated over segments cut by the master cells, and the master
/// body receives it through its own facet trace, so a uniform pressure loads both
/// bodies with their consistent nodal forces. Linear problem solved to the Newton
/// tolerance 1e-10 on a residual of order σ h²: 1e-8 relative is round-off plus
/// tolerance (the target).
#[test]
fn patch_test_mortar_is_exact_with_every_master() {
    for_every_mortar_patch("", |label, _, p| {
        assert!(p.pointwise < 1e-8 && p.total < 1e-8 && p.equilibrium < 1e-8, "{label}: pointwise {:e}, total {:e}, equilibrium {:e}", p.pointwise, p.total, p.equilibrium);
    });
}

/// Runs the mortar patch test on every case of the mortar table (standard and dual
/// multipliers; 3/5, 4/4, 5/3; facet and B-spline orders 2–4 where the lower mesh
/// holds them) with `extra` added to the pair's integration, and hands each
/// (label, B-spline order or 0, result) to `check`.
fn for_every_mortar_patch(extra: &str, mut check: impl FnMut(&str, usize, &Patch)) {
    for multipliers in ["standard", "dual"] {
        for (nl, nu) in [(3, 5), (4, 4), (5, 3)] {
            for (kind, orders) in [(MasterKind::Facet, None), (MasterKind::Bspline, Some([2, 2])), (MasterKind::Bspline, Some([3, 3])), (MasterKind::Bspline, Some([4, 4]))] {
                if orders.is_some_and(|o| o[0] > nl + 1) {
                    continue;
                }
                let p = patch_with(nl, nu, kind, orders, "penalty", &format!("mortar, multipliers: {multipliers}{extra}"));
                let label = format!("mortar{extra} ({multipliers}) {nl}/{nu} {kind:?} {orders:?}");
                eprintln!("  {label}: pointwise {:.3e}, total {:.3e}, equilibrium {:.3e}, {} iterations", p.pointwise, p.total, p.equilibrium, p.iterations);
                check(&label, orders.map_or(0, |o| o[0]), &p);
            }
        }
    }
}

/// `transfer: balanced` (the B-spline basis recombined so that a uniform pressure
/// gives the faces' consistent forces, `contact::mortar::balance`): the patch test
/// to the quadrature of the smooth basis over the slave's segments. Measured
/// (standard / dual multipliers, 3/5, 4/4, 5/3): order 3 5.7e-4, 2.6e-3, 2.4e-4 /
/// 2.9e-4, 1.3e-3, 1.0e-4; order 4 2.7e-7, 6.7e-5, 7.0e-6 / 1.2e-7, 2.0e-5, 2.2e-6;
/// facets and order 2 ≤ 2.5e-11 (their basis is the trace). Bounds: the largest
/// measured of each order times 1.5, 1e-8 where the basis is the trace. `transfer: surface`
/// measures 0.37 on the 3/5 order-3 case: the bound fails on any transfer that
/// misses the faces' forces.
#[test]
fn patch_test_mortar_balanced_transfer_is_within_its_quadrature() {
    let mut worst = [0.0f64; 5];
    for_every_mortar_patch(", transfer: balanced", |label, order, p| {
        worst[order] = worst[order].max(p.pointwise);
        let bound = match order {
            3 => 4e-3,
            4 => 1e-4,
            _ => 1e-8,
        };
        assert!(p.pointwise < bound && p.equilibrium < 1e-8, "{label}: pointwise {:e} (bound {bound:e}), equilibrium {:e}", p.pointwise, p.equilibrium);
    });
    eprintln!("balanced transfer, worst pointwise per order (facet = 0): {worst:?}");
}

/// `transfer: balanced` with `quadrature: knot_spans`: the segments cut further by
/// the master's knot lines and integrated by 64 points per triangle, so the smooth
/// basis is integrated to far below the pressure's tolerance and the patch test
/// holds to issue 25's round-off bound, 1e-8, with every master and both multiplier
/// bases. Measured: facets and order 2 ≤ 6.4e-12, order 3 ≤ 2.6e-10, order 4 ≤ 1.6e-9
/// (with 6 points per direction instead of 8: order 4 ≤ 7.4e-9; the masters' forces
/// themselves are exact to 3.2e-12, `contact::mortar::span_tests`, and a penalty
/// pressure is ε_N g with g 1e-2 of the displacement, so the displacements' last
/// digits show 100 × larger in it). The cells' quadrature measures 2.6e-3 on the
/// 4/4 order-3 case: the bound fails without the cut.
#[test]
fn patch_test_mortar_balanced_transfer_over_knot_spans_is_exact() {
    for_every_mortar_patch(", transfer: balanced, quadrature: knot_spans", |label, _, p| {
        assert!(p.pointwise < 1e-8 && p.equilibrium < 1e-8, "{label}: pointwise {:e}, equilibrium {:e}", p.pointwise, p.equilibrium);
    });
}

/// Augmented Lagrangian on matching meshes: the Uzawa updates drive the penetration
/// below 1e-9, so the pressure tends to the impenetrable `σ = E d / H` at every node
/// (relative error ≤ ε_N·1e-9/σ = 1e-4, measured far below).
#[test]
fn augmented_lagrangian_removes_the_penalty() {
    let p = patch(4, 4, MasterKind::Facet, None, "augmented_lagrangian");
    assert!(p.augmentations >= 2, "augmentations: {}", p.augmentations);
    assert!(p.pointwise < 1e-4, "pointwise {:e}", p.pointwise);
    assert!(p.iterations < 40, "iterations {}", p.iterations);
}

/// The assembled tangent of a contact problem against central differences of the
/// assembled residual, the contact search redone at every perturbation: this checks
/// the whole chain (search, groups, scatter into K_ff) beyond the element test. A
/// wavy master (lower block's top displaced by 0.03 sin·cos) under a 4 × 4 slave
/// pushed 0.02 into it, so that every slave node is active, on the interior and the
/// edge spans, for the facet master and B-spline masters of orders 2, 3 and 4.
#[test]
fn assembled_contact_tangent_matches_finite_differences() {
    use splinecontact::solver::newton::Newton;
    use splinecontact::solver::problem::Problem;
    // frictionless, and with Coulomb friction: ε_T = 2 leaves the nodes sticking (their
    // slip from the reference foot point, ~0.05, gives ε_T·slip = 0.1 < μ t_N ≈ 6),
    // ε_T = 1e4 makes most slide (non-symmetric tangent), the central ones stick
    // and frictionless with the master-surface stabilisation (its c (u − u_pred) on the
    // master's free nodes, c = 0.5 ε_N Ā_s ≈ 31, of the order of the contact springs)
    // and frictionless with the free-body damping of the upper block (c (u − u_n) on its
    // free dofs, β = 0.5: c = 0.5 G h̄, of the order of an element's stiffness)
    let friction = [None, Some("mu: 0.3, eps_t: 2.0"), Some("mu: 0.3, eps_t: 1.0e4"), Some("stabilization: 0.5"), Some("free_body_damping")];
    for ((kind, orders), fr) in [(MasterKind::Facet, None), (MasterKind::Bspline, Some([2, 2])), (MasterKind::Bspline, Some([3, 3])), (MasterKind::Bspline, Some([4, 4]))]
        .into_iter()
        .flat_map(|k| friction.iter().map(move |f| (k, *f)))
    {
        let mut mesh = stacked(4, 3);
        for (i, p) in mesh.nodes.iter_mut().enumerate() {
            // lower body's top layer: a smooth wave (a curved master); 75 lower nodes come first
            if i < 75 && (p[2] - 0.5).abs() < 1e-12 {
                p[2] += 0.03 * (2.5 * p[0]).sin() * (1.7 * p[1] + 0.3).cos();
            }
        }
        let model = build_model(mesh.clone(), "t", &[pair(kind, orders, "upper_z0", "lower_z1")]).unwrap();
        let mut yaml = patch_setup("augmented_lagrangian", 1.0e3, 0.0);
        if let Some(f) = fr.filter(|f| *f != "free_body_damping") {
            yaml = yaml.replace("max_augmentations: 30}", &format!("max_augmentations: 30, {f}}}"));
        }
        let setup = SolveSetup::parse("s", &yaml).unwrap();
        let problem = Problem::with_contact(&model.mesh, &model.pairs, &setup, "s").unwrap();
        let mut newton = Newton::new(&problem, setup.newton.clone(), setup.linear_solver.clone()).unwrap();
        if fr == Some("free_body_damping") {
            use splinecontact::solver::free_bodies::FreeBody;
            let upper = FreeBody { name: "upper".into(), nodes: (75..mesh.nodes.len() as u32).collect(), free: vec![[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]], centroid: nalgebra::Vector3::new(0.5, 0.5, 0.75), length: 0.4 };
            newton.damp_free_bodies(vec![upper], 0.5);
            assert!(newton.free_bodies.is_some());
        }
        // the slave block shrunk by 10 % in x and y about the centre (so its edge nodes
        // project into the master's edge spans, not beyond), sheared, moved 0.02 down
        let n = mesh.nodes.len();
        let mut u = vec![0.0; 3 * n];
        for i in 75..n {
            let [x, y, _] = mesh.nodes[i];
            u[3 * i] = -0.1 * (x - 0.5) + 0.013 * y;
            u[3 * i + 1] = -0.1 * (y - 0.5);
            u[3 * i + 2] = -0.02 - 0.004 * x;
        }
        let (_, col_ptr, row_idx, values) = newton.residual_tangent_at(&u, 1.0).unwrap();
        assert!(newton.n_contact_pressed() == 16, "{kind:?}: {} slave nodes pressed", newton.n_contact_pressed());
        newton.contact[0].update_states().unwrap();
        let (stick, slip) = newton.contact[0].n_stick_slip();
        match fr {
            // nodes near the centre move least: a few stick, most slide — both branches
            Some(f) if f.contains("1.0e4") => assert!(slip >= 10 && stick + slip == 16, "{kind:?}: {stick} stick, {slip} slip"),
            Some(f) if f.contains("mu") => assert_eq!((stick, slip), (16, 0), "{kind:?}: all stick"),
            _ => {}
        }
        let free: Vec<usize> = (0..3 * n).filter(|&d| problem.dofs.free(d).is_some()).collect();
        let h = 1e-7;
        let (mut err, mut norm) = (0.0f64, 0.0f64);
        for (j, &dj) in free.iter().enumerate() {
            let mut up = u.clone();
            up[dj] += h;
            let rp = newton.residual_tangent_at(&up, 1.0).unwrap().0;
            up[dj] -= 2.0 * h;
            let rm = newton.residual_tangent_at(&up, 1.0).unwrap().0;
            // column j of K_ff
            let mut col = vec![0.0; free.len()];
            for k in col_ptr[j]..col_ptr[j + 1] {
                col[row_idx[k]] = values[k];
            }
            for (i, &di) in free.iter().enumerate() {
                let fd = (rp[di] - rm[di]) / (2.0 * h);
                err = err.max((fd - col[i]).abs());
                norm = norm.max(col[i].abs());
            }
        }
        eprintln!("assembled contact tangent {kind:?} {orders:?} {}: max |K − K_fd| / max |K| = {:.2e}", fr.unwrap_or("frictionless"), err / norm);
        // central differences, h = 1e-7 on O(1) coordinates: truncation ~h²·|r'''| and
        // round-off ~1e-16·|r|/h ≈ 1e-9 relative: 1e-6 leaves a wide margin
        assert!(err / norm < 1e-6, "{kind:?} {orders:?}: {:e}", err / norm);
    }
}


/// The symmetric tangent's Cholesky factor kept across Newton iterations
/// (`linear_solver: auto`) against a fresh factorization every iteration
/// (`cholesky`): a neo-Hookean slave block pressed 10 % into a B-spline master in 3
/// increments, augmented Lagrangian, so each increment has several Newton solves
/// whose tangents move (finite strain, contact). GMRES solves with the kept factor
/// to 1e-12, so the Newton paths are the same: the same iteration counts and
/// displacements to 1e-9 of the largest (Newton's tolerance is 1e-10; measured
/// 1e-14). A fresh factor solves directly (0 Krylov iterations), a kept one by
/// GMRES: the kept factor must actually be used, or the test shows nothing.
#[test]
fn a_kept_cholesky_factor_follows_the_fresh_factorizations_newton_path() {
    let mesh = stacked(4, 3);
    let base = patch_setup("augmented_lagrangian", 1.0e5, 0.05)
        .replace("model: linear_elastic", "model: neo_hookean")
        .replace("newton: {residual_tolerance: 1.0e-10}", "newton: {residual_tolerance: 1.0e-10}\nincrements: {count: 3}");
    let spec = || pair(MasterKind::Bspline, Some([3, 3]), "upper_z0", "lower_z1");
    let kept = run_contact(&mesh, &[spec()], &base);
    let fresh = run_contact(&mesh, &[spec()], &format!("{base}linear_solver: cholesky\n"));
    assert_eq!(kept.increments.len(), 3);
    let mut kept_solves = 0;
    for (n, (k, f)) in kept.increments.iter().zip(&fresh.increments).enumerate() {
        assert_eq!(k.info.iterations.len(), f.info.iterations.len(), "Newton iterations of increment {}", n + 1);
        assert!(f.info.iterations.iter().all(|it| it.krylov_iterations == 0));
        kept_solves += k.info.iterations.iter().filter(|it| it.krylov_iterations > 0).count();
        let scale = f.u.iter().flat_map(|u| u.iter()).fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = k.u.iter().zip(&f.u).flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs())).fold(0.0f64, f64::max);
        eprintln!("increment {}: {} Newton rows, max |u| {scale:.6e}, kept − fresh {:.2e}", n + 1, k.info.iterations.len(), diff / scale);
        assert!(diff <= 1e-9 * scale, "increment {}: {:e}", n + 1, diff / scale);
    }
    eprintln!("solves with a kept factor: {kept_solves}");
    assert!(kept_solves >= 10, "the kept factor was used in {kept_solves} solves (measured 27 of 45 rows)");
}
