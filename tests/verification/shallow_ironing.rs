//! Large sliding: the shallow ironing (pipelines/shallow_ironing.yaml, μ = 0.3, and
//! shallow_ironing_frictionless.yaml; mesh meshes/shallow_ironing.geo) with the cubic
//! B-spline master (orders [2, 4], the sliding direction cubic), on the published load
//! path up to t = 1.5: pressed 1 over t ∈ [0, 1], then slid 5 of the published 10 (the
//! force check of the published results is at t = 1.5). The test pipeline is the shipped one
//! with the [2, 4] chain's stages only, its setup unchanged but `increments` ending at
//! t = 1.5 with the same step (150 of the 200 increments). Pinned: V(1.5) inside the
//! published band and to the measured value, H/V (frictionless: H ≈ 0), the
//! tangential / normal contact force, the V oscillation over the sliding, and the
//! Newton corrections and cutbacks. docs/validation.md, "Shallow ironing", has the
//! table these numbers come from. The facet master reaches the end of the sliding only with
//! the master-surface stabilisation and a penalty (the facet chains of both
//! pipelines, run here to their end, t = 2, and pinned at t = 1.5):
//! docs/validation.md says what was tried.

use serde_yaml::{Mapping, Value};

use splinecontact::format::scres::{Results, RunStatus};
use splinecontact::post::oscillation::oscillation;

use super::sliding::{history, newton_and_cutbacks, History};
use crate::common::{repo, run, stderr, staged_meshes};

/// The indenter slides 10 over t ∈ [1, 2]; the foundation's element length along x is 12 / 60.
const SLIDE: f64 = 10.0;
const ELEMENT: f64 = 0.2;
/// Steady sliding in the shortened run: travel [2, 5] (t ∈ [1.2, 1.5]; the force
/// history settles within 1 mm of the start of sliding, docs/validation.md).
const STEADY: (f64, f64) = (2.0, 5.0);

/// The shipped pipeline `name` reduced to its `chain` ("b4": the B-spline [2, 4]
/// master; "facet") stages (import, tag, solve), ending at t = 1.5 when `shortened`
/// (else at the shipped t = 2).
fn derived_pipeline(name: &str, chain: &str, shortened: bool) -> String {
    let path = repo().join(format!("pipelines/{name}.yaml"));
    let text = std::fs::read_to_string(&path).unwrap();
    // serde_yaml resolves the `&ironing_setup` anchor and its aliases into copies
    let mut doc: Value = serde_yaml::from_str(&text).unwrap();
    let stages = doc.get_mut("stages").and_then(Value::as_sequence_mut).unwrap();
    stages.retain(|stage| {
        let (kind, body) = stage.as_mapping().unwrap().iter().next().unwrap();
        let io = |k: &str| body.get(k).and_then(Value::as_str).unwrap_or("").to_string();
        match kind.as_str().unwrap() {
            "import" => true,
            "tag" | "solve" => io("output").contains(&format!("-{chain}.")),
            _ => false, // export, plot
        }
    });
    let mut n_solves = 0;
    for stage in stages.iter_mut() {
        if let Some(setup) = stage.get_mut("solve").and_then(|s| s.get_mut("setup")) {
            let inc = setup.get_mut("increments").and_then(Value::as_mapping_mut).unwrap();
            // the published step, 0.01 of t (200 increments over [0, 2])
            assert_eq!(inc.get("count").and_then(Value::as_u64), Some(200), "{name}: increments");
            n_solves += 1;
            if !shortened {
                continue;
            }
            let mut m = Mapping::new();
            m.insert("count".into(), 150.into());
            m.insert("end".into(), 1.5.into());
            m.insert("max_cutbacks".into(), inc.get("max_cutbacks").cloned().unwrap_or(6.into()));
            *inc = m;
        }
    }
    assert_eq!(n_solves, 1, "{name}: one {chain} solve stage");
    serde_yaml::to_string(&doc).unwrap()
}

/// Runs the derived pipeline of `name`: the sliding's histories (travel
/// 10 (t − 1), V = −R_y, H = R_x on the indenter top) and the results.
fn solve(name: &str, chain: &str) -> (History, Results) {
    let run = solve_pipeline(name, chain, &derived_pipeline(name, chain, true));
    assert!((run.0.s.last().unwrap() - 5.0).abs() < 1e-9, "{name}: the run ends at t = 1.5");
    run
}

/// Runs `pipeline` (derived from `name`, solving its `chain`) in a scratch copy.
fn solve_pipeline(name: &str, chain: &str, pipeline: &str) -> (History, Results) {
    let stem = format!("{name}-{chain}");
    let dir = staged_meshes(&["shallow_ironing.msh"]);
    std::fs::write(dir.path().join("pipelines/test.yaml"), pipeline).unwrap();
    let o = run("sc-pipeline", &["-q", "pipelines/test.yaml"], dir.path());
    assert!(o.status.success(), "{name}: {}", stderr(&o));
    let out = dir.path().join("pipelines/out");
    let h = history(&out.join(format!("{stem}.forces.csv")), "indenter_top", "y", 1.0, SLIDE);
    let results = Results::read(&out.join(format!("{stem}.scres"))).unwrap();
    assert_eq!(results.status, RunStatus::Completed, "{name}");
    (h, results)
}

/// Checks every run shares against its pins; V and H at the end (t = 1.5).
fn check(name: &str, (r, results): &(History, Results), pin: &Pin) -> (f64, f64) {
    let (v, h) = (*r.v.last().unwrap(), *r.h.last().unwrap());
    let osc = oscillation(&r.s, &r.v, ELEMENT, STEADY.0, STEADY.1).unwrap();
    let (its, cut) = newton_and_cutbacks(results);
    eprintln!("{name}: V(1.5) {v:.2}, H(1.5) {h:.3}, H/V {:.4}, V oscillation {:.3e} (p2p {:.3e}), {its} Newton corrections, {cut} cutbacks", h / v, osc.rms, osc.peak_to_peak);
    // published at t = 1.5 (six codes, docs/validation/shallow-ironing.md): V between 337 and 421 N/mm
    assert!((337.0..=421.0).contains(&v), "{name}: V(1.5) = {v} outside the published 337–421");
    // 1 %: the mesh, load path and tolerances are fixed (the full pipeline gives the
    // same to 0.1 N/mm); a change of the master's geometry or of the contact element
    // moves it by several N/mm
    assert!((v / pin.v_15 - 1.0).abs() < 0.01, "{name}: V(1.5) = {v} (pinned {})", pin.v_15);
    assert!((osc.rms / pin.v_rms - 1.0).abs() < pin.rms_band, "{name}: V oscillation {:.3e} (pinned {:.3e} ± {:.0} %)", osc.rms, pin.v_rms, 100.0 * pin.rms_band);
    assert!(its as f64 <= 1.25 * pin.newton as f64 + 2.0, "{name}: {its} Newton corrections (pinned {})", pin.newton);
    assert!(cut as f64 <= 1.25 * pin.cutbacks as f64 + 2.0, "{name}: {cut} cutbacks (pinned {})", pin.cutbacks);
    (v, h)
}

#[test]
fn shallow_ironing_frictionless_bspline() {
    let name = "shallow_ironing_frictionless";
    let (v, h) = check(name, &solve(name, "b4"), &PIN_FRICTIONLESS);
    // frictionless: H only from the normal force's tilt, which cancels between the
    // indenter's flanks in steady sliding (measured 1.1e-4 of V at t = 1.5)
    assert!(h.abs() < 1e-3 * v, "{name}: H/V = {}", h / v);
}

#[test]
fn shallow_ironing_coulomb_bspline() {
    let name = "shallow_ironing";
    let run = solve(name, "b4");
    let (v, h) = check(name, &run, &PIN_COULOMB);
    let r = &run.0;
    // the published H/V at t = 1.5 is 0.30–0.53
    assert!((0.30..=0.53).contains(&(h / v)), "{name}: H/V(1.5) = {} outside the published 0.30–0.53", h / v);
    // Steady sliding, every pressed node slides: Σ|T| = μ Σ|N| exactly (return
    // mapping); the vector sums differ from μ by the spread of the normals along the
    // arc: measured 0.3000 at t = 1.5 (the force on a slave is −A_s t_T; 0.301–0.302
    // with the exact first variation of eq. 4.10, docs/theory.md), within 0.005 of μ. H/V adds the tilt of the normal
    // force on the indenter (the foundation piles up ahead of it): measured 0.306–0.320
    // over the travel [2, 5], within [0.3, 0.33].
    for (i, s) in r.s.iter().enumerate() {
        if (STEADY.0..=STEADY.1).contains(s) {
            assert!((r.t_over_n[i] - 0.3).abs() < 0.005, "{name}: tangential / normal contact force {} at travel {s}", r.t_over_n[i]);
            let hv = r.h[i] / r.v[i];
            assert!((0.30..=0.33).contains(&hv), "{name}: H/V = {hv} at travel {s}");
        }
    }
}

/// Pins (2026-11-23): V(1.5) ±1 % (above); V oscillation RMS over the travel [2, 5]
/// ±30 % unless a pin says otherwise (a difference of nearly equal forces, 1e-4 of V, that moves with the Newton
/// tolerance and the platform's rounding, but by factors with the master's
/// smoothness); Newton corrections and cutbacks + 25 % (+2: the facet runs snap over
/// creases, and a snap's path moves with the platform's rounding).
struct Pin {
    v_15: f64,
    v_rms: f64,
    /// the relative band of `v_rms` (0.3; wider where a chain's oscillation is known
    /// to move with the last bits of its Newton path)
    rms_band: f64,
    newton: usize,
    cutbacks: u32,
}

const PIN_FRICTIONLESS: Pin = Pin { v_15: 397.6, v_rms: 1.50e-4, rms_band: 0.3, newton: 1143, cutbacks: 0 };
const PIN_COULOMB: Pin = Pin { v_15: 399.9, v_rms: 1.08e-4, rms_band: 0.3, newton: 1155, cutbacks: 0 };

/// The facet master's chain of pipelines/shallow_ironing_frictionless.yaml (penalty,
/// master-surface stabilisation `stabilization: 0.15`; without it the facet run
/// stops as sliding starts, docs/validation.md), on the same mesh and load path up to
/// t = 1.5.
#[test]
fn shallow_ironing_frictionless_facet_stabilized() {
    let name = "shallow_ironing_frictionless";
    // target ratio measured 0.039 (1.50e-4 against 3.87e-3)
    let (v, h, _) = solve_facet(name, &PIN_FACET_FRICTIONLESS, &PIN_FRICTIONLESS);
    // Frictionless, yet the faceted crater resists the sliding: the nodes snap over
    // the creases and the energy they release is dissipated (`H_LIMIT`).
    assert!(h.abs() < H_LIMIT * v, "{name}: H/V(1.5) = {}", h / v);
}

/// The default penalty ε_N = 25 G/h of this pair: G of the foundation (E = 689.6,
/// ν = 0.32), h = 0.4696 the master net's mean edge (0.2 along x, 1 along z), as the
/// solve log prints it.
const DEFAULT_EPS_N: f64 = 13905.704099821765;

/// The "usable without tuning": with the augmented Lagrangian the answer does
/// not depend on the default penalty. The B-spline [2, 4] chain with μ = 0.3 and twice
/// the default ε_N, to t = 1.2 (pressing and 2 mm of sliding), against the default's
/// V and H/V at t = 1.2 (measured in the shipped pipeline: 395.27, 0.3147).
/// Measured to t = 1.5 with ε_N × ½ / × 2: V(1.2) 395.27 / 395.33, H/V(1.2)
/// 0.3146 / 0.3148, V(1.5) 399.95 / 399.99 against 399.89 (docs/validation.md).
/// Tolerance: Uzawa stops at a penetration of 1e-3 h = 4.7e-4 mm; the foundation's
/// stiffness under the indenter, ~400 N/mm, turns that into 0.2 N (5e-4 of V): 0.1 %
/// on V, 0.002 on H/V.
#[test]
fn shallow_ironing_default_penalty_does_not_matter() {
    let name = "shallow_ironing";
    let (r, _) = solve_pipeline(name, "b4", &to_t12(name, "eps_n", (2.0 * DEFAULT_EPS_N).into()));
    assert!((r.s.last().unwrap() - 2.0).abs() < 1e-9, "the run ends at t = 1.2");
    let (v, h) = (*r.v.last().unwrap(), *r.h.last().unwrap());
    eprintln!("{name}, B-spline [2, 4], 2 × default ε_N: V(1.2) {v:.2}, H/V(1.2) {:.4}", h / v);
    assert!((v / 395.27 - 1.0).abs() < 1e-3, "V(1.2) = {v} with 2 × the default ε_N (default: 395.27)");
    assert!((h / v - 0.3147).abs() < 2e-3, "H/V(1.2) = {} with 2 × the default ε_N (default: 0.3147)", h / v);
}

/// The B-spline [2, 4] chain of `name` ended at t = 1.2 (pressing and 2 mm of
/// sliding, 120 increments), its contact entry given `key: value`.
fn to_t12(name: &str, key: &str, value: Value) -> String {
    let mut doc: Value = serde_yaml::from_str(&with_contact(&derived_pipeline(name, "b4", true), &[(key, value)])).unwrap();
    let inc = solve_setup(&mut doc).get_mut("increments").and_then(Value::as_mapping_mut).unwrap();
    inc.insert("count".into(), 120.into());
    inc.insert("end".into(), 1.2.into());
    serde_yaml::to_string(&doc).unwrap()
}

/// The setup of the (one) solve stage of a pipeline document.
fn solve_setup(doc: &mut Value) -> &mut Value {
    let stages = doc.get_mut("stages").and_then(Value::as_sequence_mut).unwrap();
    stages.iter_mut().find_map(|s| s.get_mut("solve")).and_then(|s| s.get_mut("setup")).unwrap()
}

/// `pipeline` with `entries` (key, value) added to its solve stage's contact entry.
fn with_contact(pipeline: &str, entries: &[(&str, Value)]) -> String {
    let mut doc: Value = serde_yaml::from_str(pipeline).unwrap();
    let contact = solve_setup(&mut doc).get_mut("contact").and_then(Value::as_sequence_mut).unwrap();
    let entry = contact[0].as_mapping_mut().unwrap();
    for (key, value) in entries {
        entry.insert((*key).into(), value.clone());
    }
    serde_yaml::to_string(&doc).unwrap()
}

/// The facet chain of `name` as shipped: it must reach the end of the sliding (t = 2;
/// a shipped pipeline runs to its end), and up to t = 1.5 it is checked against its
/// pins (the increments up to 1.5 are those of a run ended there); the issue's
/// target: the cubic B-spline master's V oscillation (`bspline`, held by the B-spline
/// test on the same mesh and load path) at most 1/5 of the facets'; the stabilisation
/// small. V(1.5), H(1.5) and the history to t = 1.5.
fn solve_facet(name: &str, pin: &Pin, bspline: &Pin) -> (f64, f64, History) {
    let (full, mut results) = solve_pipeline(name, "facet", &derived_pipeline(name, "facet", false));
    assert!((full.s.last().unwrap() - SLIDE).abs() < 1e-9, "{name}: the facet chain ends at t = 2");
    check_stabilization(&results);
    results.increments.retain(|i| i.info.load_factor <= 1.5 + 1e-9);
    let run = (full.until(5.0), results);
    let (v, h) = check(&format!("{name}-facet"), &run, pin);
    let (r, _) = run;
    let osc = oscillation(&r.s, &r.v, ELEMENT, STEADY.0, STEADY.1).unwrap().rms;
    assert!(bspline.v_rms <= 0.2 * osc, "{name}: B-spline [2, 4] V oscillation {:.3e} vs facet {osc:.3e}", bspline.v_rms);
    (v, h, r)
}

/// The stabilisation is reported and stays small against the contact force in every
/// sliding increment (`STAB_LIMIT`).
fn check_stabilization(results: &Results) {
    for inc in results.increments.iter().filter(|i| i.info.load_factor > 1.0 + 1e-9) {
        let c = &inc.info.contact[0];
        let f = (c.force[0].powi(2) + c.force[1].powi(2) + c.force[2].powi(2)).sqrt();
        assert!(c.stabilization_force > 0.0 && c.stabilization_force <= STAB_LIMIT * f, "t = {}: stabilisation force {:.3e} against a contact force {f:.3e}", inc.info.load_factor, c.stabilization_force);
    }
}

/// The facet chain of pipelines/shallow_ironing.yaml (μ = 0.3; penalty, master-surface
/// stabilisation 0.2 and friction on creases; docs/validation.md), to t = 2, pinned at
/// t = 1.5.
#[test]
fn shallow_ironing_coulomb_facet_stabilized() {
    let name = "shallow_ironing";
    // target ratio measured 0.017 (1.08e-4 against 6.34e-3)
    let (v, h, r) = solve_facet(name, &PIN_FACET_COULOMB, &PIN_COULOMB);
    assert!((0.30..=0.53).contains(&(h / v)), "{name}: H/V(1.5) = {} outside the published 0.30–0.53", h / v);
    // Every pressed node slides in steady sliding and the facets' normals are straight
    // lines in z: Σ|T| = μ Σ|N| to the return mapping's round-off (measured 0.3000 over
    // the travel [2, 5]). H/V swings more than the B-spline master's (0.306–0.344:
    // the snaps over the creases add resistance), so it is held to the published band.
    for (i, s) in r.s.iter().enumerate() {
        if (STEADY.0..=STEADY.1).contains(s) {
            assert!((r.t_over_n[i] - 0.3).abs() < 1e-3, "{name}: tangential / normal contact force {} at travel {s}", r.t_over_n[i]);
            let hv = r.h[i] / r.v[i];
            assert!((0.30..=0.53).contains(&hv), "{name}: H/V = {hv} at travel {s}");
        }
    }
}

/// The facet master's pins (2026-11-23), tolerances as above. Its V(1.5) lies 3.0 %
/// under the B-spline [2, 4] master's with the same penalty and no stabilisation
/// (382.8; 376.3 with the same stabilisation): the penalty's penetration and the
/// stabilisation's share of the load (docs/validation.md).
const PIN_FACET_FRICTIONLESS: Pin = Pin { v_15: 371.50, v_rms: 3.87e-3, rms_band: 0.3, newton: 747, cutbacks: 0 };
/// With μ = 0.3, tolerances as above: V(1.5) inside the published band, 7.0 % under
/// the B-spline [2, 4] master's (399.9; the penalty and the stabilisation, as without
/// friction), stabilisation η = 0.2. Its 4 cutbacks before t = 1.5 make the
/// stabilisation of those increments 4–16 times stiffer (it follows the step,
/// docs/theory/robustness.md): re-pinned when it started to, from V(1.5) 371.70,
/// oscillation 3.73e-3, 759 corrections, 4 cutbacks with a constant one. Re-pinned
/// when the updated Lagrangian became the default (the same answers to round-off):
/// from V(1.5) 371.88, oscillation 5.12e-3, 774 corrections, 4 cutbacks. Where this
/// chain snaps over the facets' creases, and so how often it cuts back, moves with
/// the last bits of the Newton path; the B-spline chains do not cut back at all.
/// Its oscillation, four times measured after changes that moved only round-off
/// (the element's sums: an isotropic tangent contracted directly; the formulation;
/// the stabilisation's step), was 3.66e-3 (2 cutbacks), 3.73e-3 (4), 5.12e-3 (4) and
/// 6.34e-3 (10) with V(1.5) 371.70–371.88: the band is their spread, centred,
/// 4.8e-3 ± 45 % (2.6e-3–7.0e-3), and still fails an oscillation halved or doubled
/// (the B-spline chains', 1e-4, are 40 times smaller).
const PIN_FACET_COULOMB: Pin = Pin { v_15: 371.68, v_rms: 4.8e-3, rms_band: 0.45, newton: 761, cutbacks: 10 };
/// ‖f_stab‖ / ‖F_contact‖ over the sliding: measured at most 0.045 (at the slide's
/// start, where the extrapolated pressing motion turns into sliding; ~0.02 after).
const STAB_LIMIT: f64 = 0.07;
/// |H| / V at t = 1.5 with a frictionless facet master: measured 0.023, from the
/// snaps over the creases (the B-spline master: 1.1e-4); twice that.
const H_LIMIT: f64 = 0.05;

/// `pipeline` with the solve stage's contact pair under `integration: mortar` and the
/// mortar `transfer`.
fn mortar(pipeline: &str, transfer: &str) -> String {
    with_contact(pipeline, &[("integration", "mortar".into()), ("transfer", transfer.into())])
}

/// Issue 25's "large sliding is not worse", measured: the B-spline [2, 4] chains under
/// mortar integration (standard multipliers; the same pipelines, to t = 1.5), against
/// their node-to-surface pins. V(1.5) within 1 % of node-to-surface's (the same master
/// and load path; the integration moves the penetration's distribution, not the
/// load); the V oscillation and the Newton corrections pinned at their measured values
/// (tolerances of [`check`]). Not met, and so recorded in
/// docs/validation/shallow-ironing.md: the "oscillation no worse" (measured
/// 2.4× node-to-surface's frictionless, 7.5× with μ = 0.3) and "corrections within
/// 30 %" (2.1× and 1.8×). The frictional chain only: the frictionless one
/// (about a minute of the suite's budget on 2 cores) was measured once, 2026-11-26:
/// V(1.5) 394.94, V oscillation 3.577e-4, 2355 corrections, no cutback.
#[test]
fn shallow_ironing_mortar_bspline() {
    mortar_runs(&[("shallow_ironing", "trace", &PIN_MORTAR_COULOMB, &PIN_COULOMB)]);
}

/// The same with `transfer: surface` (the master's forces through the B-spline
/// basis, a symmetric tangent; the patch test is then exact with facets only):
/// smoother and cheaper than the trace transfer. Measured against node-to-surface:
/// frictionless oscillation × 1.61, corrections × 1.31; with μ = 0.3 oscillation × 0.96,
/// corrections × 1.25 (within the 30 %).
#[test]
fn shallow_ironing_mortar_bspline_surface_transfer() {
    mortar_runs(&[("shallow_ironing_frictionless", "surface", &PIN_MORTAR_SURFACE_FRICTIONLESS, &PIN_FRICTIONLESS), ("shallow_ironing", "surface", &PIN_MORTAR_SURFACE_COULOMB, &PIN_COULOMB)]);
}

/// Runs `(pipeline, transfer, mortar pin, node-to-surface pin)` under mortar.
fn mortar_runs(cases: &[(&str, &str, &Pin, &Pin)]) {
    for &(name, transfer, pin, node) in cases {
        let run = solve_pipeline(name, "b4", &mortar(&derived_pipeline(name, "b4", true), transfer));
        let name = &format!("{name}, {transfer}");
        assert!((run.0.s.last().unwrap() - 5.0).abs() < 1e-9, "{name}: the run ends at t = 1.5");
        let (v, _) = check(&format!("{name} mortar"), &run, pin);
        assert!((v / node.v_15 - 1.0).abs() < 0.01, "{name} mortar: V(1.5) = {v} against node-to-surface {}", node.v_15);
        let (its, _) = newton_and_cutbacks(&run.1);
        let osc = oscillation(&run.0.s, &run.0.v, ELEMENT, STEADY.0, STEADY.1).unwrap().rms;
        eprintln!("{name} mortar against node-to-surface: V oscillation × {:.2}, Newton corrections × {:.2}", osc / node.v_rms, its as f64 / node.newton as f64);
    }
}

/// Measured (the frictionless one 2026-11-26, the frictional ones 2026-11-27, friction
/// transferred by the mortar weights), standard multipliers, segmentation held below
/// 1e-5.
const PIN_MORTAR_COULOMB: Pin = Pin { v_15: 397.78, v_rms: 8.055e-4, rms_band: 0.3, newton: 2050, cutbacks: 0 };
const PIN_MORTAR_SURFACE_FRICTIONLESS: Pin = Pin { v_15: 395.99, v_rms: 2.419e-4, rms_band: 0.3, newton: 1501, cutbacks: 0 };
const PIN_MORTAR_SURFACE_COULOMB: Pin = Pin { v_15: 398.97, v_rms: 1.036e-4, rms_band: 0.3, newton: 1449, cutbacks: 0 };

/// Frictionless sliding under mortar with `transfer: surface` and `uzawa_relaxation:
/// 1.5`, to t = 1.5: the "corrections within 30 %" against the plain
/// node-to-surface pin (measured 1226 against 1143, × 1.07; 1.25 × node-to-surface
/// with the same ω, 978). The ripple is pinned as measured (2.90e-4, × 1.9 node's):
/// it alternates increment by increment at the master's element length, and a
/// 10 × tighter penetration tolerance doubles it for both integrations (node
/// 2.97e-4, mortar 5.23e-4), so it is not the Uzawa loop's stopping point
/// (docs/validation/shallow-ironing.md).
#[test]
fn mortar_surface_transfer_over_relaxed_takes_the_corrections_of_node_to_surface() {
    let name = "shallow_ironing_frictionless";
    let pipeline = with_contact(&mortar(&derived_pipeline(name, "b4", true), "surface"), &[("uzawa_relaxation", 1.5.into())]);
    let run = solve_pipeline(name, "b4", &pipeline);
    assert!((run.0.s.last().unwrap() - 5.0).abs() < 1e-9, "{name}: the run ends at t = 1.5");
    let (v, _) = check(&format!("{name}, surface, ω = 1.5, mortar"), &run, &PIN_MORTAR_SURFACE_RELAXED);
    assert!((v / PIN_FRICTIONLESS.v_15 - 1.0).abs() < 0.01, "V(1.5) = {v} against node-to-surface {}", PIN_FRICTIONLESS.v_15);
    let (its, _) = newton_and_cutbacks(&run.1);
    assert!(its as f64 <= 1.3 * PIN_FRICTIONLESS.newton as f64, "{its} Newton corrections against node-to-surface's {}", PIN_FRICTIONLESS.newton);
}

/// Frictionless sliding under mortar with `transfer: surface` and dual multipliers
/// (`multipliers: dual`), to t = 1.5: both of issue 25's sliding targets, held as
/// such: the V oscillation no larger than node-to-surface's (measured 1.292e-4
/// against 1.50e-4, × 0.86) and the corrections within 30 % (1272 against 1143,
/// × 1.11). The dual basis makes each node's weighted gap its own gap on a flat
/// face (docs/validation/hertz.md), so the slave side is node-to-surface's; the
/// master receives the forces through the B-spline basis, integrated. With
/// standard multipliers the same run ripples × 1.61 ([`shallow_ironing_mortar_bspline_surface_transfer`]).
#[test]
fn frictionless_sliding_under_dual_mortar_is_as_smooth_as_node_to_surface() {
    let name = "shallow_ironing_frictionless";
    let pipeline = with_contact(&mortar(&derived_pipeline(name, "b4", true), "surface"), &[("multipliers", "dual".into())]);
    let run = solve_pipeline(name, "b4", &pipeline);
    assert!((run.0.s.last().unwrap() - 5.0).abs() < 1e-9, "{name}: the run ends at t = 1.5");
    let (v, _) = check(&format!("{name}, surface, dual, mortar"), &run, &PIN_MORTAR_SURFACE_DUAL);
    assert!((v / PIN_FRICTIONLESS.v_15 - 1.0).abs() < 0.01, "V(1.5) = {v} against node-to-surface {}", PIN_FRICTIONLESS.v_15);
    let osc = oscillation(&run.0.s, &run.0.v, ELEMENT, STEADY.0, STEADY.1).unwrap().rms;
    assert!(osc <= PIN_FRICTIONLESS.v_rms, "V oscillation {osc:.3e} against node-to-surface's {:.3e}", PIN_FRICTIONLESS.v_rms);
    let (its, _) = newton_and_cutbacks(&run.1);
    assert!(its as f64 <= 1.3 * PIN_FRICTIONLESS.newton as f64, "{its} Newton corrections against node-to-surface's {}", PIN_FRICTIONLESS.newton);
}

/// `transfer: balanced` (the B-spline basis recombined near the master's edges so
/// that a uniform pressure gives the faces' forces; the contact patch test to its
/// quadrature, `patch_test_mortar_balanced_transfer_is_within_its_quadrature`): the
/// sliding of the surface transfer. Both of issue 25's sliding targets, held as
/// targets: with friction (standard multipliers) and frictionless (dual), no more
/// ripple than node-to-surface's and corrections within 30 % of its. Measured
/// (2026-11-27): × 0.96 and × 1.26 with friction, × 0.86 and × 1.19 frictionless.
#[test]
fn balanced_transfer_slides_as_smoothly_as_node_to_surface() {
    for (name, multipliers, pin, node) in [("shallow_ironing", "standard", &PIN_MORTAR_BALANCED_COULOMB, &PIN_COULOMB), ("shallow_ironing_frictionless", "dual", &PIN_MORTAR_BALANCED_DUAL, &PIN_FRICTIONLESS)] {
        let pipeline = with_contact(&mortar(&derived_pipeline(name, "b4", true), "balanced"), &[("multipliers", multipliers.into())]);
        let run = solve_pipeline(name, "b4", &pipeline);
        let label = format!("{name}, balanced, {multipliers}, mortar");
        assert!((run.0.s.last().unwrap() - 5.0).abs() < 1e-9, "{label}: the run ends at t = 1.5");
        let (v, _) = check(&label, &run, pin);
        assert!((v / node.v_15 - 1.0).abs() < 0.01, "{label}: V(1.5) = {v} against node-to-surface {}", node.v_15);
        let osc = oscillation(&run.0.s, &run.0.v, ELEMENT, STEADY.0, STEADY.1).unwrap().rms;
        assert!(osc <= node.v_rms, "{label}: V oscillation {osc:.3e} against node-to-surface's {:.3e}", node.v_rms);
        let (its, _) = newton_and_cutbacks(&run.1);
        assert!(its as f64 <= 1.3 * node.newton as f64, "{label}: {its} Newton corrections against node-to-surface's {}", node.newton);
    }
}

/// Measured (2026-11-27), `transfer: balanced`: with friction, standard multipliers;
/// frictionless, dual.
const PIN_MORTAR_BALANCED_COULOMB: Pin = Pin { v_15: 399.02, v_rms: 1.038e-4, rms_band: 0.3, newton: 1458, cutbacks: 0 };
const PIN_MORTAR_BALANCED_DUAL: Pin = Pin { v_15: 396.82, v_rms: 1.292e-4, rms_band: 0.3, newton: 1355, cutbacks: 0 };

/// Measured (2026-11-27), frictionless, `transfer: surface`, `multipliers: dual`.
const PIN_MORTAR_SURFACE_DUAL: Pin = Pin { v_15: 396.82, v_rms: 1.292e-4, rms_band: 0.3, newton: 1272, cutbacks: 0 };

/// Measured (2026-11-26), frictionless, `transfer: surface`, `uzawa_relaxation: 1.5`.
const PIN_MORTAR_SURFACE_RELAXED: Pin = Pin { v_15: 396.03, v_rms: 2.901e-4, rms_band: 0.3, newton: 1226, cutbacks: 0 };

/// `uzawa_relaxation: 1.5` (docs/theory/contact.md, "Over-relaxation") against the
/// plain update on the frictional B-spline [2, 4] chain to t = 1.2 (pressing and 2 mm
/// of sliding), node-to-surface. The converged answers agree within what the
/// penetration tolerance allows (1e-3 h = 4.7e-4 mm against ~400 N/mm under the
/// indenter: 0.2 N, 5e-4 of V; measured 1.0e-4), and the over-relaxed run needs at
/// most 90 % of the plain run's Newton corrections (measured 83 %: 154 → 112 Uzawa
/// updates).
#[test]
fn uzawa_over_relaxation_saves_updates() {
    let name = "shallow_ironing";
    let run = |omega: f64| solve_pipeline(name, "b4", &to_t12(name, "uzawa_relaxation", omega.into()));
    let (plain, relaxed) = (run(1.0), run(1.5));
    let (v1, h1) = (*plain.0.v.last().unwrap(), *plain.0.h.last().unwrap());
    let (v2, h2) = (*relaxed.0.v.last().unwrap(), *relaxed.0.h.last().unwrap());
    let ((its1, cut1), (its2, cut2)) = (newton_and_cutbacks(&plain.1), newton_and_cutbacks(&relaxed.1));
    eprintln!("ω = 1: V(1.2) {v1:.3}, H/V {:.4}, {its1} corrections; ω = 1.5: V(1.2) {v2:.3}, H/V {:.4}, {its2} corrections ({:.2} ×)", h1 / v1, h2 / v2, its2 as f64 / its1 as f64);
    assert!((v2 / v1 - 1.0).abs() < 1e-3, "V(1.2): {v2} over-relaxed against {v1}");
    assert!((h2 / v2 - h1 / v1).abs() < 2e-3, "H/V(1.2): {} over-relaxed against {}", h2 / v2, h1 / v1);
    assert_eq!((cut1, cut2), (0, 0), "cutbacks");
    assert!((its2 as f64) <= 0.9 * its1 as f64, "{its2} Newton corrections over-relaxed against {its1}");
}
