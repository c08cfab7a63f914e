//! Coulomb friction at the structural level (issue: friction): a stiff block pressed
//! on a stiff base, then pushed sideways and back, against the one-dimensional
//! elastic-slip / Coulomb-slider law the return mapping implements.

use splinecontact::format::sccontact::MasterKind;

use super::contact::{pair, run_contact};
use crate::common::grid::{block, two_bodies};

const E: f64 = 1.0e7;
const EPS_N: f64 = 1.0e4;
const EPS_T: f64 = 1.0e3;
const MU: f64 = 0.3;
/// Press depth and the largest push.
const DZ: f64 = 1.0e-3;
const UX: f64 = 1.0e-2;

/// Upper block 0.5 × 0.5 × 0.25 (2 × 2 × 1 hex8) on the middle of a 1 × 1 × 0.5 base
/// (2 × 2 × 1); base clamped; the upper top driven: u_z = −DZ on t ∈ [0, 1], then
/// u_x = +UX on [1, 2] and back to −UX on [2, 4] (load curves), u_y = 0.
fn setup() -> String {
    setup_with(EPS_N, EPS_T, UX)
}

fn setup_with(eps_n: f64, eps_t: f64, ux: f64) -> String {
    format!(
        "materials:\n  - {{body: lower, model: neo_hookean, E: {E:e}, nu: 0.3}}\n  - {{body: upper, model: neo_hookean, E: {E:e}, nu: 0.3}}\n\
         curves:\n  - {{name: press, points: [[0, 0], [1, 1]]}}\n  - {{name: push, points: [[1, 0], [2, 1], [4, -1]]}}\n\
         constraints:\n  - {{set: lower_z0, fix: [x, y, z]}}\n  - {{set: upper_z1, displacement: {{z: {}}}, curve: press, fix: [y]}}\n  - {{set: upper_z1, displacement: {{x: {ux:e}}}, curve: push}}\n\
         contact:\n  - {{pair: c, eps_n: {eps_n:e}, enforcement: penalty, mu: {MU}, eps_t: {eps_t:e}}}\n\
         increments: {{count: 40, end: 4.0}}\n",
        -DZ
    )
}

#[test]
fn stick_slip_and_reversal_follow_the_coulomb_law() {
    let mesh = two_bodies("lower", &block([2, 2, 1], [1.0, 1.0, 0.5], 0.0), "upper", &block([2, 2, 1], [0.5, 0.5, 0.25], 0.0), [0.25, 0.25, 0.5]);
    // node-to-surface and mortar integration (friction at the nodes, bounded by the
    // mortar pressure): the same one-dimensional law
    for (kind, orders, integration) in [(MasterKind::Facet, None, "node"), (MasterKind::Bspline, Some([3, 3]), "node"), (MasterKind::Facet, None, "mortar"), (MasterKind::Bspline, Some([3, 3]), "mortar")] {
        let yaml = setup().replace("enforcement: penalty", &format!("enforcement: penalty, integration: {integration}"));
        let r = run_contact(&mesh, &[pair(kind, orders, "upper_z0", "lower_z1")], &yaml);
        let kind = format!("{kind:?} {integration}");
        assert_eq!(r.increments.len(), 40, "{kind:?}: every increment converged without cutback");
        // One-dimensional reference: spring ε_T·A in series with a Coulomb slider of
        // capacity μN, driven by the top's u_x (the blocks are ~1000× stiffer than the
        // penalty layers, so the slip is the top's displacement to ~1e-3).
        let area = 0.25;
        let mut s_p = 0.0; // plastic slip
        let mut worst: f64 = 0.0;
        let (mut sticks, mut slips) = (0, 0);
        for inc in &r.increments {
            let t = inc.info.load_factor;
            let ux = if t <= 1.0 { 0.0 } else if t <= 2.0 { UX * (t - 1.0) } else { UX * (1.0 - (t - 2.0)) };
            let s = &inc.info.contact[0];
            let fr = s.friction.as_ref().expect("frictional pair summary");
            // normal and tangential parts of the force on the slave (upper) block
            let tang = fr.tangential_force;
            let n = s.force[2] - tang[2];
            let h = tang[0]; // opposes the block's motion
            let mut h_ref = -EPS_T * area * (ux - s_p);
            if h_ref.abs() > MU * n {
                h_ref = h_ref.signum() * MU * n;
                s_p = ux + h_ref / (EPS_T * area);
            }
            let err = (h - h_ref).abs() / (MU * n.max(1e-300));
            if t > 1.0 {
                worst = worst.max(err);
                if fr.slip > 0 {
                    slips += 1;
                    // sliding: |T| = μ N (every node slides; the base's surface tilts by its
                    // elastic strain, ~1e-6, so nodal directions differ by that much)
                    let tn = (tang[0].powi(2) + tang[1].powi(2) + tang[2].powi(2)).sqrt();
                    assert!((tn - MU * n).abs() < 1e-6 * MU * n, "{kind:?} t = {t}: |T| = {tn} vs μN = {}", MU * n);
                    assert_eq!(fr.stick, 0, "{kind:?} t = {t}: a rigid block slides as a whole");
                } else {
                    sticks += 1;
                }
            }
            eprintln!("{kind:?} t = {t:.2}: u_x {ux:+.4e}, N {n:.6}, H {h:+.6}, reference {h_ref:+.6}, stick {} slip {}", fr.stick, fr.slip);
        }
        // stick until ε_T A u_x = μN (u_x* = 3e-3 = 0.3 UX), slip beyond; on the way
        // back stick for 2 u_x* then slide the other way: both phases occur
        assert!(sticks >= 6 && slips >= 10, "{kind:?}: {sticks} stick and {slips} slip increments");
        // 1 % of μN: the blocks' elastic shear and compression (E / ε_T·h ≈ 1e3)
        assert!(worst < 1e-2, "{kind:?}: tangential force off the Coulomb law by {worst:e} μN");
    }
}

/// Tangential augmentation: the same path (push to 2e-3) with the augmented
/// Lagrangian (tolerance 1e-7 on penetration and on elastic slip), penalties
/// ε_N = ε_T = 1e8 — above the blocks' stiffness, so each Uzawa update contracts the
/// violation by ~1/5 (a penalty 1000× softer than the body would need thousands).
/// While the block sticks, the penalty run's elastic slip (= H / (ε_T A)) is driven
/// below 1e-7 by Uzawa updates of t_{T,n}; sliding keeps every node at μ|t_N|.
#[test]
fn augmented_lagrangian_removes_the_elastic_slip() {
    let mesh = two_bodies("lower", &block([2, 2, 1], [1.0, 1.0, 0.5], 0.0), "upper", &block([2, 2, 1], [0.5, 0.5, 0.25], 0.0), [0.25, 0.25, 0.5]);
    let base = setup_with(1.0e8, 1.0e8, 2.0e-3);
    let yaml = base.replace("enforcement: penalty", "enforcement: augmented_lagrangian, penetration_tolerance: 1.0e-7, max_augmentations: 30");
    let penalty = run_contact(&mesh, &[pair(MasterKind::Bspline, Some([3, 3]), "upper_z0", "lower_z1")], &base);
    let r = run_contact(&mesh, &[pair(MasterKind::Bspline, Some([3, 3]), "upper_z0", "lower_z1")], &yaml);
    let (mut stick_al, mut slip_al) = (0, 0);
    for (inc, pen) in r.increments.iter().zip(&penalty.increments) {
        let (s, sp) = (&inc.info.contact[0], &pen.info.contact[0]);
        let (fr, frp) = (s.friction.as_ref().unwrap(), sp.friction.as_ref().unwrap());
        eprintln!("t = {:.2}: elastic slip AL {:.2e} (penalty {:.2e}), stick {} slip {}, augmentations {}", inc.info.load_factor, fr.elastic_slip, frp.elastic_slip, fr.stick, fr.slip, s.augmentations);
        assert!(s.penetration_converged && s.max_penetration <= 1e-7 && fr.elastic_slip <= 1e-7, "t = {}: {s:?}", inc.info.load_factor);
        if fr.stick > 0 && inc.info.load_factor > 1.0 {
            stick_al += 1;
            assert!(s.augmentations >= 1);
        }
        if fr.slip > 0 && fr.stick == 0 {
            // the whole block slides (pressing alone makes the corners slip: Poisson)
            slip_al += 1;
            let tang = fr.tangential_force;
            let tn = (tang[0].powi(2) + tang[1].powi(2) + tang[2].powi(2)).sqrt();
            let n = s.force[2] - tang[2];
            // every node at μ|t_N|; their directions differ slightly (the stiff
            // penalties let the blocks' shear show), so the resultant is a bit below μN
            assert!(tn <= MU * n * (1.0 + 1e-9) && tn > 0.99 * MU * n, "|T| = {tn}, μN = {}", MU * n);
        }
    }
    // the penalty run's elastic slip reaches μ t_N / ε_T before sliding
    let max_penalty = penalty.increments.iter().map(|i| i.info.contact[0].friction.as_ref().unwrap().elastic_slip).fold(0.0, f64::max);
    assert!(max_penalty > 1e-5, "penalty elastic slip {max_penalty:e}");
    assert!(stick_al >= 10 && slip_al >= 1, "{stick_al} stick, {slip_al} slip increments");
}

/// What ParaView shows: the frictional results exported as a .pvd carry the
/// tangential traction, slip and stick/slip state on the slave nodes (meshio reads
/// them; `check_pvd.py` checks their consistency).
#[test]
fn friction_fields_in_the_pvd() {
    let mesh = two_bodies("lower", &block([2, 2, 1], [1.0, 1.0, 0.5], 0.0), "upper", &block([2, 2, 1], [0.5, 0.5, 0.25], 0.0), [0.25, 0.25, 0.5]);
    let r = run_contact(&mesh, &[pair(MasterKind::Bspline, Some([3, 3]), "upper_z0", "lower_z1")], &setup());
    let dir = crate::common::tempdir();
    let (res, pvd) = (dir.path().join("f.scres"), dir.path().join("f.pvd"));
    r.write(&res).unwrap();
    splinecontact::stages::export::export(&res, &pvd, None).unwrap();
    let o = crate::common::python_script("check_pvd.py", &[&pvd]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{out}{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_yaml::Value = serde_yaml::from_str(out.trim()).unwrap();
    // last step (t = 4): the block slides back, all 9 slave nodes slipping at μ t_N
    assert_eq!(j["contact"]["friction"]["slip"].as_u64(), Some(9), "{out}");
    let t_max = j["contact"]["friction"]["max_traction"].as_f64().unwrap();
    let p_max = j["contact"]["slave_pressures"].as_sequence().unwrap().iter().map(|v| v.as_f64().unwrap()).fold(0.0, f64::max);
    assert!(t_max <= MU * p_max * (1.0 + 1e-6) && t_max > 0.9 * MU * p_max, "traction {t_max} vs μ p_max {}", MU * p_max);
}

/// Cut the run of `yaml` after increment `cut` (its results file truncated there,
/// status stopped), continue it with `sc-solve --restart`, and continue it again
/// after `forget` erased part of the stored history: (full, continued, forgetful).
fn cut_and_continue(yaml: &str, cut: usize, forget: impl Fn(&mut splinecontact::format::scres::Increment)) -> [splinecontact::format::scres::Results; 3] {
    let mesh = two_bodies("lower", &block([2, 2, 1], [1.0, 1.0, 0.5], 0.0), "upper", &block([2, 2, 1], [0.5, 0.5, 0.25], 0.0), [0.25, 0.25, 0.5]);
    cut_and_continue_on(mesh, &pair(MasterKind::Bspline, Some([3, 3]), "upper_z0", "lower_z1"), yaml, cut, forget)
}

/// [`cut_and_continue`] on any model: `mesh` tagged with `spec`.
pub(super) fn cut_and_continue_on(mesh: splinecontact::mesh::Mesh, spec: &splinecontact::stages::tag::PairSpec, yaml: &str, cut: usize, forget: impl Fn(&mut splinecontact::format::scres::Increment)) -> [splinecontact::format::scres::Results; 3] {
    use splinecontact::format::scres::{Results, RunStatus};
    use splinecontact::format::setup::SolveSetup;
    use splinecontact::solver::log::Verbosity;
    use splinecontact::stages::solve::{solve, Restart};
    use splinecontact::stages::tag::build_model;

    let dir = crate::common::tempdir();
    let model = build_model(mesh, "test", std::slice::from_ref(spec)).unwrap();
    let c = dir.path().join("m.sccontact");
    model.write(&c).unwrap();
    let s = SolveSetup::parse("setup", yaml).unwrap();
    let count = s.load_factors("setup").unwrap().len();
    let run = |out: &str, restart: Option<&std::path::Path>| {
        let out = dir.path().join(out);
        if let Err(e) = solve(&c, &s, "setup", &out, None, restart.map(|file| Restart { file, increment: None }), Verbosity::Quiet) {
            panic!("{}: {e}", out.display());
        }
        let r = Results::read(&out).unwrap();
        assert_eq!((r.status.clone(), r.increments.len()), (RunStatus::Completed, count), "{}", out.display());
        r
    };
    let full = run("full.scres", None);
    let mut cut_run = full.clone();
    cut_run.increments.truncate(cut);
    cut_run.status = RunStatus::Stopped { reason: "cut by the test".into() };
    let cut_path = dir.path().join("cut.scres");
    cut_run.write(&cut_path).unwrap();
    let continued = run("continued.scres", Some(&cut_path));
    let origin = continued.restart.as_ref().expect("the restart origin is recorded");
    assert_eq!((origin.increments as usize, origin.load_factor), (cut, full.increments[cut - 1].info.load_factor));
    // the restart file's increments open the history, bit for bit (NaN marks what
    // does not apply, e.g. iteration 0's energy, so compare bits, not values)
    let bits = |r: &Results| -> Vec<u64> {
        r.increments[..cut].iter().flat_map(|i| i.u.iter().flatten().chain(i.contact.iter().flatten().flatten()).chain(i.friction.iter().flatten().flatten()).map(|v| v.to_bits())).collect()
    };
    assert!(bits(&continued) == bits(&full), "the restart file's increments open the history");
    assert!(continued.increments[..cut].iter().zip(&full.increments[..cut]).all(|(a, b)| a.charts == b.charts), "the restart file's charts open the history");
    forget(&mut cut_run.increments[cut - 1]);
    cut_run.write(&cut_path).unwrap();
    let forgetful = run("forgetful.scres", Some(&cut_path));
    [full, continued, forgetful]
}

/// Largest displacement difference over the increments after `cut`, relative to the
/// largest displacement.
pub(super) fn u_difference(a: &splinecontact::format::scres::Results, b: &splinecontact::format::scres::Results, cut: usize) -> f64 {
    let scale = b.increments.iter().flat_map(|i| i.u.iter().flatten()).fold(0.0f64, |m, v| m.max(v.abs()));
    a.increments[cut..].iter().zip(&b.increments[cut..]).flat_map(|(x, y)| x.u.iter().flatten().zip(y.u.iter().flatten()).map(|(p, q)| (p - q).abs())).fold(0.0f64, f64::max) / scale
}

/// Largest tangential-force difference over the increments after `cut`, in μN.
fn h_difference(a: &splinecontact::format::scres::Results, b: &splinecontact::format::scres::Results, cut: usize) -> f64 {
    let h = |i: &splinecontact::format::scres::Increment| i.info.contact[0].friction.as_ref().unwrap().tangential_force[0];
    a.increments[cut..].iter().zip(&b.increments[cut..]).map(|(x, y)| (h(x) - h(y)).abs() / (MU * y.info.contact[0].force[2])).fold(0.0, f64::max)
}

/// Restart (`sc-solve --restart`), penalty path of the first test: cut at t = 2.4,
/// where the block sticks after sliding and reversing, so its tangential traction is
/// the stored t_{Tα,n} plus the elastic increment (eq. 4.7). The continued run
/// computes the increments the uninterrupted run computed.
///
/// Tolerance 1e-9 of the largest displacement and of μN: the state read back is
/// bit-exact, but the continued run's first closest-point projection starts afresh,
/// so its Newton iterates could differ at the projection and Newton tolerances
/// (measured: 0, bit for bit). The control: with t_{Tα,n} zeroed in the restart
/// file the tangential force is off by more than 0.1 μN, so the comparison sees the
/// history.
#[test]
fn restart_continues_the_run_it_was_cut_from() {
    const CUT: usize = 24;
    let [full, continued, forgetful] = cut_and_continue(&setup(), CUT, |inc| {
        for row in inc.friction[0].iter_mut() {
            row[6] = 0.0;
            row[7] = 0.0;
        }
    });
    let at_cut = &full.increments[CUT - 1].info.contact[0];
    assert_eq!(at_cut.friction.as_ref().map(|f| (f.stick, f.slip)), Some((9, 0)), "t = 2.4 sticks: {at_cut:?}");
    let (du, dh) = (u_difference(&continued, &full, CUT), h_difference(&continued, &full, CUT));
    let miss = h_difference(&forgetful, &full, CUT);
    eprintln!("penalty: continued run off by {du:.3e} max |u|, {dh:.3e} μN; without t_T,n: {miss:.3} μN");
    assert!(du <= 1e-9 && dh <= 1e-9, "continued run differs: {du:e} of max |u|, {dh:e} μN");
    for (a, b) in continued.increments[CUT..].iter().zip(&full.increments[CUT..]) {
        let (fa, fb) = (a.info.contact[0].friction.as_ref().unwrap(), b.info.contact[0].friction.as_ref().unwrap());
        assert_eq!((fa.stick, fa.slip), (fb.stick, fb.slip), "t = {}", a.info.load_factor);
    }
    assert!(miss > 0.1, "the comparison does not see the friction history ({miss:e} μN)");
}

/// Restart with the augmented Lagrangian (the path of the second test, ε_N = ε_T =
/// 1e8, tolerance 1e-7), cut at t = 2.4: the Uzawa loop continues from the stored
/// λ_N and t_{Tα,n}, so the continued run needs the same augmentations, increment
/// by increment, and reaches the same state (tolerance 1e-9 as above). The
/// control: with λ_N zeroed the first increment after the cut needs more
/// augmentations (the multipliers are rebuilt from zero).
///
/// Bit for bit, though the frictional solves are GMRES solves preconditioned by a
/// factorization kept from iteration to iteration: each increment factors its
/// preconditioner afresh (`LinearSolver::begin_increment`), as the restart does, so
/// the continued run repeats the uninterrupted run's operations (measured: 0). A
/// forgotten multiplier leaves the state off by up to the penetration tolerance
/// (1e-7) until the Uzawa loop rebuilds it.
#[test]
fn restart_keeps_the_augmented_lagrangian_multipliers() {
    const CUT: usize = 24;
    let yaml = setup_with(1.0e8, 1.0e8, 2.0e-3).replace("enforcement: penalty", "enforcement: augmented_lagrangian, penetration_tolerance: 1.0e-7, max_augmentations: 30");
    let [full, continued, forgetful] = cut_and_continue(&yaml, CUT, |inc| {
        for row in inc.contact[0].iter_mut() {
            row[2] = 0.0;
        }
    });
    let aug = |r: &splinecontact::format::scres::Results| r.increments[CUT..].iter().map(|i| i.info.contact[0].augmentations).collect::<Vec<_>>();
    let du = u_difference(&continued, &full, CUT);
    eprintln!("augmented Lagrangian: continued run off by {du:.3e} max |u|; augmentations {:?}, continued {:?}, without λ_N {:?}", aug(&full), aug(&continued), aug(&forgetful));
    assert!(du == 0.0, "continued run differs by {du:e} of max |u|");
    assert_eq!(aug(&continued), aug(&full));
    assert!(aug(&forgetful)[0] > aug(&full)[0], "the comparison does not see the multipliers");
}

/// The restart under mortar integration (issue 25: restart, friction history and
/// multipliers as under `node`): the augmented-Lagrangian path above with
/// `integration: mortar`, cut at t = 2.4. The mortar multipliers are nodal and the
/// friction history stays the node's, so the results file carries them in the same
/// columns: the continued run repeats the uninterrupted one bit for bit, as under
/// `node` (measured: 0), with the same augmentations, and a run with λ_N zeroed in
/// the file needs more. (The mortar search keeps, per slave node, the trace cell it
/// was located in, which a restart does not have; the integration sums its
/// quadrature points in cell order, so that state no longer changes the sums: before,
/// the continued run was off by 9.4e-10 of max |u|.)
#[test]
fn restart_under_mortar_keeps_the_multipliers() {
    const CUT: usize = 24;
    let yaml = setup_with(1.0e8, 1.0e8, 2.0e-3).replace("enforcement: penalty", "enforcement: augmented_lagrangian, penetration_tolerance: 1.0e-7, max_augmentations: 30, integration: mortar");
    let [full, continued, forgetful] = cut_and_continue(&yaml, CUT, |inc| {
        for row in inc.contact[0].iter_mut() {
            row[2] = 0.0;
        }
    });
    let aug = |r: &splinecontact::format::scres::Results| r.increments[CUT..].iter().map(|i| i.info.contact[0].augmentations).collect::<Vec<_>>();
    let du = u_difference(&continued, &full, CUT);
    eprintln!("mortar, augmented Lagrangian: continued run off by {du:.3e} max |u|; augmentations {:?}, continued {:?}, without λ_N {:?}", aug(&full), aug(&continued), aug(&forgetful));
    assert!(du == 0.0, "continued run differs by {du:e} of max |u|");
    assert_eq!(aug(&continued), aug(&full));
    assert!(aug(&forgetful)[0] > aug(&full)[0], "the comparison does not see the multipliers");
}
