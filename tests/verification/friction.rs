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
    for (kind, orders) in [(MasterKind::Facet, None), (MasterKind::Bspline, Some([3, 3]))] {
        let r = run_contact(&mesh, &[pair(kind, orders, "upper_z0", "lower_z1")], &setup());
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
