//! Large sliding: the 3D ironing pipelines (pipelines/ironing3d.yaml, μ = 0.3, and
//! ironing3d_frictionless.yaml; mesh meshes/ironing3d.geo) run as shipped, each with
//! the facet, B-spline [3, 3] and B-spline [4, 4] masters on the same mesh and load
//! path, and their plot stage. Pinned: the force-history oscillation over the steady
//! sliding phase (the metric of lib/post/oscillation.rs: RMS about a one-element moving average,
//! relative to the mean vertical force), the friction ratio, and the Newton
//! iterations and cutbacks of every master. docs/validation.md, "3D ironing", has
//! the table these numbers come from.

use splinecontact::format::scres::{Increment, PairSummary, Results, RunStatus};
use splinecontact::post::oscillation::oscillation;

use super::sliding::{history, newton_and_cutbacks, History};
use crate::common::{gmsh_mesh, repo, run, staged_meshes, staged_pipeline, stderr};

/// The die slides 4 over t ∈ [0.2, 1.2]; the slab's element length along x is 9 / 20.
const TRAVEL: f64 = 4.0;
const SLIDE_START: f64 = 0.2;
const ELEMENT: f64 = 0.45;
/// Steady sliding: the travel [1, 3] (the contact zone, ~1.5 wide, is clear of the
/// slab's ends and of the start of sliding).
const STEADY: (f64, f64) = (1.0, 3.0);

/// RMS of the horizontal force about its one-element moving average, relative to the
/// mean vertical force (H itself is near zero when frictionless).
fn h_ripple(h: &History) -> f64 {
    let o = oscillation(&h.s, &h.h, ELEMENT, STEADY.0, STEADY.1).unwrap();
    let v = oscillation(&h.s, &h.v, ELEMENT, STEADY.0, STEADY.1).unwrap();
    o.rms * o.mean.abs() / v.mean
}

/// Run a shipped pipeline in a copy of meshes/ and pipelines/; the histories and
/// results of its three masters.
fn run_ironing(name: &str) -> (tempfile::TempDir, Vec<(&'static str, History, Results)>) {
    let dir = staged_pipeline(name, &["ironing3d.msh"]);
    let masters = run_staged(&dir, name);
    (dir, masters)
}

/// Run `pipelines/<name>.yaml` staged in `dir`; the histories and results of its
/// three masters.
fn run_staged(dir: &tempfile::TempDir, name: &str) -> Vec<(&'static str, History, Results)> {
    run_masters(dir, name, &MASTERS)
}

/// The masters every 3D ironing pipeline solves (its output files' `<name>-<master>.`).
const MASTERS: [&str; 3] = ["facet", "b3", "b4"];

/// [`run_staged`] for the pipeline's `masters` (the stages and plot series of the
/// others are dropped from it first).
fn run_masters(dir: &tempfile::TempDir, name: &str, masters: &[&'static str]) -> Vec<(&'static str, History, Results)> {
    let path = dir.path().join(format!("pipelines/{name}.yaml"));
    let mut doc: serde_yaml::Value = serde_yaml::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let kept = |file: &str| MASTERS.iter().all(|m| !file.contains(&format!("{name}-{m}.")) || masters.contains(m));
    let stages = doc.get_mut("stages").and_then(serde_yaml::Value::as_sequence_mut).unwrap();
    stages.retain(|stage| stage.get("tag").or_else(|| stage.get("solve")).and_then(|s| s.get("output")).and_then(serde_yaml::Value::as_str).is_none_or(kept));
    for panel in stages.iter_mut().filter_map(|s| s.get_mut("plot")).flat_map(|p| p.get_mut("panels").and_then(serde_yaml::Value::as_sequence_mut).unwrap().iter_mut()) {
        panel.get_mut("series").and_then(serde_yaml::Value::as_sequence_mut).unwrap().retain(|s| s.get("input").and_then(serde_yaml::Value::as_str).is_some_and(kept));
    }
    std::fs::write(&path, serde_yaml::to_string(&doc).unwrap()).unwrap();
    let o = run("sc-pipeline", &["-q", &format!("pipelines/{name}.yaml")], dir.path());
    assert!(o.status.success(), "{name}: {}", stderr(&o));
    let out = dir.path().join("pipelines/out");
    let png = std::fs::read(out.join(format!("{name}_forces.png"))).unwrap();
    assert!(png.starts_with(b"\x89PNG") && png.len() > 20_000, "{name}: the plot stage's PNG");
    masters
        .iter()
        .copied()
        .map(|m| {
            let h = history(&out.join(format!("{name}-{m}.forces.csv")), "die_top", "z", SLIDE_START, TRAVEL);
            let r = Results::read(&out.join(format!("{name}-{m}.scres"))).unwrap();
            assert_eq!(r.status, RunStatus::Completed, "{name}-{m}");
            (m, h, r)
        })
        .collect()
}

/// Pins (2026-11-23, die of 72 × 6 elements): (master, V oscillation RMS, H ripple RMS / V, Newton corrections,
/// cutbacks). Oscillation figures ±30 %: they are differences of nearly equal forces
/// (1e-4–1e-3 of V) and move with the Newton tolerance and the platform's rounding,
/// but a change of the master's geometry or of the contact element moves them by
/// factors. Corrections: measured + 25 % (+2); cutbacks: measured + 2.
struct Pin {
    master: &'static str,
    v_rms: f64,
    h_rms: f64,
    newton: usize,
    cutbacks: u32,
}

fn check(name: &str, masters: &[(&'static str, History, Results)], pins: &[Pin]) {
    for ((m, h, r), pin) in masters.iter().zip(pins) {
        assert_eq!(*m, pin.master);
        let v = oscillation(&h.s, &h.v, ELEMENT, STEADY.0, STEADY.1).unwrap();
        let hr = h_ripple(h);
        let (its, cut) = newton_and_cutbacks(r);
        eprintln!("{name}-{m}: V mean {:.5}, V oscillation {:.3e} (p2p {:.3e}), H ripple / V {hr:.3e}, {its} Newton corrections, {cut} cutbacks", v.mean, v.rms, v.peak_to_peak);
        assert!((v.rms / pin.v_rms - 1.0).abs() < 0.3, "{name}-{m}: V oscillation {:.3e} (pinned {:.3e})", v.rms, pin.v_rms);
        assert!((hr / pin.h_rms - 1.0).abs() < 0.3, "{name}-{m}: H ripple {hr:.3e} (pinned {:.3e})", pin.h_rms);
        assert!(its as f64 <= 1.25 * pin.newton as f64 + 2.0, "{name}-{m}: {its} Newton corrections (pinned {})", pin.newton);
        assert!(cut <= pin.cutbacks + 2, "{name}-{m}: {cut} cutbacks (pinned {})", pin.cutbacks);
    }
}

#[test]
fn ironing3d_frictionless_facet_against_bspline() {
    let (_dir, masters) = run_ironing("ironing3d_frictionless");
    check("frictionless", &masters, &PINS_FRICTIONLESS);
    // the cubic B-spline master: V and H ripple at most 1/5 of the facets' (the
    // issue's target; measured 0.086 and 0.14 — the quadratic one gives 0.47 and 0.36)
    let v_rms: Vec<f64> = masters.iter().map(|(_, h, _)| oscillation(&h.s, &h.v, ELEMENT, STEADY.0, STEADY.1).unwrap().rms).collect();
    let ripple: Vec<f64> = masters.iter().map(|(_, h, _)| h_ripple(h)).collect();
    assert!(v_rms[2] <= 0.2 * v_rms[0], "B-spline [4, 4] V oscillation {:.3e} vs facet {:.3e}", v_rms[2], v_rms[0]);
    assert!(ripple[2] <= 0.2 * ripple[0], "B-spline [4, 4] H ripple {:.3e} vs facet {:.3e}", ripple[2], ripple[0]);
    for (m, h, _) in &masters {
        // frictionless steady sliding: H ≈ 0 (measured |mean H| / V ≤ 2e-9, facet; it was
        // 4e-4 with the 36-element die): 1e-5 leaves room for the Newton tolerance (1e-8 of the reactions)
        let hm = oscillation(&h.s, &h.h, ELEMENT, STEADY.0, STEADY.1).unwrap().mean;
        let vm = oscillation(&h.s, &h.v, ELEMENT, STEADY.0, STEADY.1).unwrap().mean;
        assert!(hm.abs() < 1e-5 * vm, "{m}: mean H / V = {}", hm / vm);
    }
}

#[test]
fn ironing3d_coulomb_facet_against_bspline() {
    let (_dir, masters) = run_ironing("ironing3d");
    check("mu 0.3", &masters, &PINS_COULOMB);
    // the cubic B-spline master: V and H ripple at most 1/5 of the facets' (the
    // issue's target; measured 0.15 and 0.13 — the quadratic one gives 0.30 and 0.35)
    let v_rms: Vec<f64> = masters.iter().map(|(_, h, _)| oscillation(&h.s, &h.v, ELEMENT, STEADY.0, STEADY.1).unwrap().rms).collect();
    let ripple: Vec<f64> = masters.iter().map(|(_, h, _)| h_ripple(h)).collect();
    assert!(v_rms[2] <= 0.2 * v_rms[0], "B-spline [4, 4] V oscillation {:.3e} vs facet {:.3e}", v_rms[2], v_rms[0]);
    assert!(ripple[2] <= 0.2 * ripple[0], "B-spline [4, 4] H ripple {:.3e} vs facet {:.3e}", ripple[2], ripple[0]);
    for (m, h, _) in &masters {
        // Steady sliding, every active node slides: H/V → μ = 0.3; measured 0.2943
        // (B4) – 0.2958 (facet): the die's shell flexes, the normal force tilts, and
        // the slab ahead of the die is lifted: within 0.01 of μ.
        let hm = oscillation(&h.s, &h.h, ELEMENT, STEADY.0, STEADY.1).unwrap().mean;
        let vm = oscillation(&h.s, &h.v, ELEMENT, STEADY.0, STEADY.1).unwrap().mean;
        assert!((hm / vm - 0.3).abs() < 0.01, "{m}: H/V = {}", hm / vm);
        // Σ|T| = μ Σ|N| exactly (return mapping); |ΣT| / |ΣN| differs from μ by the
        // spread of the nodes' normals and sliding directions: measured 0.3000
        // (B4) – 0.3003 (facet, whose normals jump): within 1 % of μ.
        for (s, r) in h.s.iter().zip(&h.t_over_n) {
            if (STEADY.0..=STEADY.1).contains(s) {
                assert!((r - 0.3).abs() < 0.003, "{m}: tangential / normal contact force = {r} at travel {s}");
            }
        }
    }
}

/// Exact enforcement on a die no denser than the master: the shipped frictionless
/// pipeline with the die remeshed at 18 elements around its half circle (slave nodes
/// 0.52 apart against the master's 0.45; shipped: 72, 0.13 apart) and the contact
/// line without `enforcement: penalty`, i.e. the augmented Lagrangian at its default
/// tolerance. The 25 pressed slave nodes stay the same during the slide, and the cubic
/// master's ripple is 1/10 of the facets' in V and 1/60 in H (docs/validation.md, "The
/// die's node spacing under exact enforcement"; with the shipped die every master
/// ripples by 1.5–2e-3 under exact enforcement, and the comparison is made with the
/// penalty).
#[test]
fn ironing3d_augmented_lagrangian_on_a_coarse_die() {
    let name = "ironing3d_frictionless";
    let dir = staged_meshes(&[]);
    let flags = ["-format", "msh41", "-setnumber", "ndt", "18"];
    gmsh_mesh(&repo().join("meshes/ironing3d.geo"), &dir.path().join("meshes/ironing3d.msh"), &flags);
    let yaml = std::fs::read_to_string(repo().join(format!("pipelines/{name}.yaml"))).unwrap();
    let penalty = "{pair: contact, enforcement: penalty}";
    assert_eq!(yaml.matches(penalty).count(), 1, "the shipped pipeline's contact line changed: {penalty}");
    std::fs::write(dir.path().join(format!("pipelines/{name}.yaml")), yaml.replace(penalty, "{pair: contact}")).unwrap();
    let masters = run_staged(&dir, name);
    check("augmented Lagrangian, 18-element die", &masters, &PINS_AUGMENTED_COARSE_DIE);
    fn pair(i: &Increment) -> &PairSummary {
        &i.info.contact[0]
    }
    for (m, _, r) in &masters {
        // the Uzawa loop ran (the pipeline edit took: the penalty reports none; measured
        // 63 facet, 13 B4 — the multipliers carried over from the last increment leave
        // little to update) and met its tolerance, 1e-3 of the master's mean edge
        // (0.51), at every increment
        let augmentations: u32 = r.increments.iter().map(|i| pair(i).augmentations).sum();
        assert!(augmentations >= 5, "{m}: {augmentations} augmentations");
        for i in &r.increments {
            let p = pair(i);
            assert!(p.penetration_converged && p.max_penetration <= 5.2e-4, "{m}: penetration {:.3e} at t = {}", p.max_penetration, i.info.load_factor);
        }
        // the same 25 slave nodes (5 rows of 5) pressed all along the steady slide
        for i in r.increments.iter().filter(|i| (STEADY.0..=STEADY.1).contains(&(TRAVEL * (i.info.load_factor - SLIDE_START)))) {
            assert_eq!(pair(i).active, 25, "{m}: pressed slave nodes at t = {}", i.info.load_factor);
        }
    }
    let v_rms: Vec<f64> = masters.iter().map(|(_, h, _)| oscillation(&h.s, &h.v, ELEMENT, STEADY.0, STEADY.1).unwrap().rms).collect();
    let ripple: Vec<f64> = masters.iter().map(|(_, h, _)| h_ripple(h)).collect();
    // the target, 1/5, met by the cubic master (measured 0.099 and 0.017) and
    // missed by the quadratic one in V (0.28; H 0.11)
    assert!(v_rms[2] <= 0.2 * v_rms[0], "B-spline [4, 4] V oscillation {:.3e} vs facet {:.3e}", v_rms[2], v_rms[0]);
    assert!(ripple[2] <= 0.2 * ripple[0], "B-spline [4, 4] H ripple {:.3e} vs facet {:.3e}", ripple[2], ripple[0]);
}

const PINS_FRICTIONLESS: [Pin; 3] = [
    Pin { master: "facet", v_rms: 1.22e-3, h_rms: 2.18e-3, newton: 291, cutbacks: 0 },
    Pin { master: "b3", v_rms: 5.74e-4, h_rms: 7.91e-4, newton: 240, cutbacks: 0 },
    Pin { master: "b4", v_rms: 1.05e-4, h_rms: 2.99e-4, newton: 240, cutbacks: 0 },
];

const PINS_COULOMB: [Pin; 3] = [
    Pin { master: "facet", v_rms: 1.27e-3, h_rms: 2.09e-3, newton: 336, cutbacks: 2 },
    Pin { master: "b3", v_rms: 3.86e-4, h_rms: 7.39e-4, newton: 296, cutbacks: 2 },
    Pin { master: "b4", v_rms: 1.96e-4, h_rms: 2.65e-4, newton: 290, cutbacks: 0 },
];

const PINS_AUGMENTED_COARSE_DIE: [Pin; 3] = [
    Pin { master: "facet", v_rms: 3.87e-3, h_rms: 1.19e-2, newton: 797, cutbacks: 0 },
    Pin { master: "b3", v_rms: 1.10e-3, h_rms: 1.28e-3, newton: 375, cutbacks: 0 },
    Pin { master: "b4", v_rms: 3.82e-4, h_rms: 2.06e-4, newton: 294, cutbacks: 0 },
];

/// The frictional ironing under `integration: mortar` (the constraint integrated over
/// the die's faces, `docs/theory/mortar.md`), against the node-to-surface pins: large
/// sliding must not get worse. Measured and pinned like the node-to-surface runs
/// ([`Pin`]); docs/validation/ironing3d.md, "Under mortar integration", has the table.
/// The facet and cubic masters: each mortar run takes about 100 s of the test suite's
/// budget on 2 cores, and the quadratic master's rows, measured once, sit between
/// theirs (the table).
#[test]
fn ironing3d_coulomb_under_mortar() {
    ironing3d_under_mortar("integration: mortar", &PINS_MORTAR);
}

/// The same with `transfer: balanced` (the master's forces through the B-spline
/// basis, recombined near the slab's edges so that a uniform pressure gives the
/// faces' forces; the contact patch test to its quadrature): issue 25's "large
/// sliding is not worse" on the 3D ironing with friction, held as the target itself
/// (no more ripple than node-to-surface's in V and H, corrections within 30 %).
/// Measured against node-to-surface: V 0.92×, H 0.81×, corrections 1.04×; the
/// `transfer: surface` run of the table (V 0.93×, H 0.81×, 1.05×) within 2 %. The
/// facet master's basis is its trace, so its run is [`ironing3d_coulomb_under_mortar`]'s
/// and is not repeated; the cubic master only.
#[test]
fn ironing3d_coulomb_under_mortar_balanced_transfer() {
    let masters = ironing3d_under_mortar_of("ironing3d", "integration: mortar, transfer: balanced", &PINS_MORTAR_BALANCED);
    sliding_is_not_worse(&masters, &PINS_COULOMB[2]);
}

/// Issue 25's "large sliding is not worse" for each of `masters` against the
/// node-to-surface pin `node`: no more ripple in V and H, corrections within 30 %.
fn sliding_is_not_worse(masters: &[(&'static str, History, Results)], node: &Pin) {
    for (m, h, r) in masters {
        assert_eq!(*m, node.master);
        let v = oscillation(&h.s, &h.v, ELEMENT, STEADY.0, STEADY.1).unwrap().rms;
        let (its, _) = newton_and_cutbacks(r);
        assert!(v <= node.v_rms && h_ripple(h) <= node.h_rms, "{m}: V oscillation {v:.3e}, H ripple {:.3e} against node-to-surface {:.3e}, {:.3e}", h_ripple(h), node.v_rms, node.h_rms);
        assert!(its as f64 <= 1.3 * node.newton as f64, "{m}: {its} Newton corrections against node-to-surface {}", node.newton);
    }
}

/// The frictionless ironing under mortar with `transfer: surface`, the cubic master:
/// issue 25's "large sliding is not worse" frictionless. Measured against
/// node-to-surface ([`PINS_FRICTIONLESS`]): V oscillation 0.70×, H ripple 0.80×,
/// Newton corrections 1.03× (docs/validation/ironing3d.md). Pinned like the others,
/// and held to the target itself: no more ripple than node-to-surface's, corrections
/// within 30 %.
#[test]
fn ironing3d_frictionless_under_mortar_surface_transfer() {
    let masters = ironing3d_under_mortar_of("ironing3d_frictionless", "integration: mortar, transfer: surface", &PINS_MORTAR_SURFACE_FRICTIONLESS);
    sliding_is_not_worse(&masters, &PINS_FRICTIONLESS[2]);
}

/// The frictional ironing with `mortar` added to its contact entry, against the
/// node-to-surface pins ([`PINS_COULOMB`]) and pinned itself (`pins`).
fn ironing3d_under_mortar(mortar: &str, pins: &[Pin]) {
    ironing3d_under_mortar_of("ironing3d", mortar, pins);
}

/// The 3D ironing `name` (frictional or frictionless) with `mortar` added to its
/// contact entry, against its node-to-surface pins and pinned itself (`pins`).
fn ironing3d_under_mortar_of(name: &str, mortar: &str, pins: &[Pin]) -> Vec<(&'static str, History, Results)> {
    let (entry, node_pins) = match name {
        "ironing3d" => ("pair: contact, mu: 0.3, enforcement: penalty", &PINS_COULOMB),
        _ => ("pair: contact, enforcement: penalty", &PINS_FRICTIONLESS),
    };
    let dir = staged_pipeline(name, &["ironing3d.msh"]);
    let path = dir.path().join(format!("pipelines/{name}.yaml"));
    let yaml = std::fs::read_to_string(&path).unwrap();
    let edited = yaml.replace(&format!("{{{entry}}}"), &format!("{{{entry}, {mortar}}}"));
    assert!(edited.contains(mortar), "{name}: no contact line to change");
    std::fs::write(&path, edited).unwrap();
    let masters = run_masters(&dir, name, &pins.iter().map(|p| p.master).collect::<Vec<_>>());
    for (m, h, r) in &masters {
        let node = node_pins.iter().find(|p| p.master == *m).unwrap();
        let v = oscillation(&h.s, &h.v, ELEMENT, STEADY.0, STEADY.1).unwrap();
        let (its, cut) = newton_and_cutbacks(r);
        eprintln!(
            "{mortar}, {m}: V mean {:.5}, V oscillation {:.3e} (node {:.3e}: {:.2}×), H ripple / V {:.3e} (node {:.3e}: {:.2}×), {its} Newton corrections (node {}: {:.2}×), {cut} cutbacks",
            v.mean,
            v.rms,
            node.v_rms,
            v.rms / node.v_rms,
            h_ripple(h),
            node.h_rms,
            h_ripple(h) / node.h_rms,
            node.newton,
            its as f64 / node.newton as f64
        );
    }
    check(&format!("{name}, {mortar}"), &masters, pins);
    masters
}

/// Measured under mortar (2026-11-27, friction transferred by the mortar weights);
/// the same margins as [`PINS_COULOMB`]. Against node-to-surface: facets 0.79× (V)
/// and 0.65× (H), the cubic B-spline 1.53× and 2.20×; Newton corrections 1.18× and
/// 1.03×.
const PINS_MORTAR: [Pin; 2] = [
    Pin { master: "facet", v_rms: 1.008e-3, h_rms: 1.366e-3, newton: 398, cutbacks: 0 },
    Pin { master: "b4", v_rms: 3.008e-4, h_rms: 5.836e-4, newton: 299, cutbacks: 0 },
];

/// Measured under mortar with `transfer: balanced` (2026-11-27); the same margins.
const PINS_MORTAR_BALANCED: [Pin; 1] = [Pin { master: "b4", v_rms: 1.811e-4, h_rms: 2.159e-4, newton: 302, cutbacks: 0 }];

/// Measured frictionless under mortar with `transfer: surface` (2026-11-27).
const PINS_MORTAR_SURFACE_FRICTIONLESS: [Pin; 1] = [Pin { master: "b4", v_rms: 7.379e-5, h_rms: 2.386e-4, newton: 246, cutbacks: 0 }];
