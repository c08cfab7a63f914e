//! The shipped contact pipelines as regression tests with physical checks: Hertz
//! (`pipelines/hertz.yaml`) against the closed form, and the curved master
//! (`pipelines/curved.yaml`, `pipelines/curved-facet.yaml`), B-spline against facets.
//! Each pipeline runs as a user runs it, in a copy of the repository's meshes and
//! pipelines; `tests/py/hertz.py` and `tests/py/curved.py` (meshio) read the results.

use std::path::Path;

use crate::common::{python_script, repo, run, stderr, staged_meshes, staged_pipeline, tempdir};
use splinecontact::format::scres::Results;

fn staged(pipeline: &str) -> tempfile::TempDir {
    let dir = staged_meshes(&["hertz.msh", "curved.msh", "curved-nby3.msh"]);
    std::fs::copy(repo().join("pipelines").join(pipeline), dir.path().join("pipelines").join(pipeline)).unwrap();
    let o = run("sc-pipeline", &[&format!("pipelines/{pipeline}")], dir.path());
    assert!(o.status.success(), "{pipeline}: {}", stderr(&o));
    dir
}

/// One JSON line of a script, as YAML (JSON is YAML).
fn json(script: &str, args: &[&Path]) -> Vec<serde_yaml::Value> {
    let o = python_script(script, args);
    assert!(o.status.success(), "{script}: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).lines().filter(|l| l.starts_with('{')).map(|l| serde_yaml::from_str(l).unwrap()).collect()
}

fn f(v: &serde_yaml::Value, path: &[&str]) -> f64 {
    let mut v = v;
    for k in path {
        v = &v[*k];
    }
    v.as_f64().unwrap_or_else(|| panic!("{path:?} is not a number: {v:?}"))
}

/// Hertz, plane strain, refine 1 (slave h = 0.062 at the contact, b/h ≈ 11), B-spline
/// [2, 3] and facet masters. Closed form from the measured load P ≈ 10. Tolerances
/// (docs/validation.md, "Hertz"): the peak pressure is 0.95 % low and stays 1.0 % low
/// under refinement 2 and 4 — the finite-strain material (linear elastic: +0.11 % to
/// +0.15 %) — so |p0 error| < 1.5 %; the half-width by the fitted ellipse is within
/// 0.2 % (±0.8 % at refine 2, 4), asserted < 1.5 %, and Hertz's b must fall between
/// the last active and the first open slave node. Newton corrections pinned (28, +4).
#[test]
fn hertz_against_the_closed_form() {
    let dir = staged("hertz.yaml");
    for stem in ["hertz", "hertz-facet"] {
        let j = &json("hertz.py", &[&dir.path().join(format!("pipelines/out/{stem}.pvd"))])[0];
        eprintln!("{stem}: P {:.4}, p0 err {:+.4}, b_fit err {:+.4}, newton {}", f(j, &["P"]), f(j, &["p0_err"]), f(j, &["b_fit_err"]), f(j, &["newton"]));
        assert!((f(j, &["P"]) - 10.0).abs() < 0.05, "{stem}: P = {}", f(j, &["P"]));
        assert!((f(j, &["P"]) - f(j, &["P_contact"])).abs() < 1e-8 * 10.0, "{stem}: reaction vs contact force");
        assert!(f(j, &["p0_err"]).abs() < 0.015, "{stem}: p0 error {}", f(j, &["p0_err"]));
        assert!(f(j, &["b_fit_err"]).abs() < 0.015, "{stem}: b error {}", f(j, &["b_fit_err"]));
        assert_eq!(j["b_hertz_in_bracket"].as_bool(), Some(true), "{stem}");
        assert!(f(j, &["max_penetration"]) < 1e-6, "{stem}: penetration above the tolerance");
        assert!(f(j, &["newton"]) <= 32.0, "{stem}: {} Newton corrections", f(j, &["newton"]));
    }
}

/// `pipelines/hertz.yaml` with both bodies linear elastic (Hertz's theory; the
/// neo-Hookean floor of ~1 % is gone) and `integration` set on the pair, run like
/// [`staged`]; the facet solve is cut (the B-spline master only, for time).
fn staged_hertz_linear(integration: &str) -> tempfile::TempDir {
    let dir = staged_meshes(&["hertz.msh"]);
    let yaml = std::fs::read_to_string(repo().join("pipelines/hertz.yaml")).unwrap();
    let edit = |y: &str, old: &str, new: &str, n: usize| {
        assert_eq!(y.matches(old).count(), n, "pipelines/hertz.yaml: {old:?}");
        y.replace(old, new)
    };
    let y = edit(&yaml, "model: neo_hookean,", "model: linear_elastic,", 2);
    let y = edit(&y, "max_augmentations: 20}", &format!("max_augmentations: 20, integration: {integration}}}"), 1);
    let cut = y.find("  - solve:\n      input: out/hertz-facet.sccontact").expect("the facet solve");
    std::fs::write(dir.path().join("pipelines/hertz.yaml"), &y[..cut]).unwrap();
    let o = run("sc-pipeline", &["pipelines/hertz.yaml"], dir.path());
    assert!(o.status.success(), "hertz.yaml, linear, {integration}: {}", stderr(&o));
    dir
}

/// Hertz, linear elastic, refine 1, B-spline master [2, 3]: the whole pressure
/// profile against the closed form (issue 25), node-to-surface and mortar
/// (docs/validation/hertz.md, "Node-to-surface and mortar"). Profile errors
/// |p_fe − p_hertz| / p0 on the slave line's reference x (tests/py/hertz.py): RMS over
/// x ≤ 2b and max of the exported nodal pressure, and (mortar) the RMS of the nodal
/// force per tributary area. Measured (2026-11-25): node RMS 0.01055, max 0.03778;
/// mortar RMS 0.04491, max 0.13475, force per area 0.02956; the max at the last
/// active node x = 0.631 (b = 0.683) in both. Pinned to ±2 %: the solution is
/// converged far tighter (penetration < 1e-6 against a 0.06 element, Newton's
/// relative residual 1e-8), so only a change of the method (integration, edge,
/// active set, load) moves them by that much; it is then to be measured again, not
/// loosened (a pin moved by 4 % makes it fail, checked).
/// At this refinement mortar is NOT below node-to-surface (4.3 × in RMS, 2.8 × by the
/// force per area; at refine 4 the two are equal, docs), and the test asserts that
/// relation too: when mortar's error drops below node's it fails, and the doc's
/// statement has to change with it.
#[test]
fn hertz_profile_node_and_mortar() {
    // (integration, RMS, max, force-per-area RMS), measured
    let cases = [("node", 0.01055, 0.03778, 0.01055), ("mortar", 0.04491, 0.13475, 0.02956)];
    let mut rms = Vec::new();
    for (integration, rms0, max0, frms0) in cases {
        let dir = staged_hertz_linear(integration);
        let j = &json("hertz.py", &[&dir.path().join("pipelines/out/hertz.pvd")])[0];
        let (r, m, fr) = (f(j, &["profile_rms_err"]), f(j, &["profile_max_err"]), f(j, &["profile_force_rms_err"]));
        eprintln!("{integration}: P {:.4}, p0 err {:+.4}, b_fit err {:+.4}, profile rms {r:.5} max {m:.5} force-rms {fr:.5}, newton {}",
            f(j, &["P"]), f(j, &["p0_err"]), f(j, &["b_fit_err"]), f(j, &["newton"]));
        assert_eq!(j["integration"].as_str(), Some(integration));
        assert!((f(j, &["P"]) - 10.05).abs() < 0.02, "{integration}: P = {}", f(j, &["P"]));
        assert!(f(j, &["max_penetration"]) < 1e-6, "{integration}: penetration above the tolerance");
        for (what, got, measured) in [("RMS", r, rms0), ("max", m, max0), ("force-per-area RMS", fr, frms0)] {
            assert!((got / measured - 1.0).abs() < 0.02, "{integration}: profile {what} error {got} (measured {measured})");
        }
        rms.push((r, fr));
    }
    // refine 1: mortar's nodal pressure is further from Hertz than node-to-surface's
    // (by 4.3 ×), and so is its force per area (2.8 ×)
    assert!(rms[1].0 > 2.0 * rms[0].0 && rms[1].1 > 1.5 * rms[0].1, "mortar against node: {rms:?}");
}

/// Curved master. On the shipped mesh the B-spline masters [3, 3] and [4, 4] solve
/// (the facet master cannot: a pad node row sits on a concave crease, see
/// curved-facet.yaml); on the base with 3 elements along y, facets and B-spline [3, 3]
/// side by side. Asserted: the symmetric problem stays symmetric with the smooth
/// master (lateral force ≈ 0) while facets put a spurious lateral force and a pressure
/// spike on the apex ridge; contact force, Newton corrections and the centreline
/// second difference pinned at the measured values (force to 1e-4: Newton and Uzawa
/// tolerances are far tighter; iterations +4; smoothness +20 %).
#[test]
fn curved_master_bspline_against_facets() {
    let dir = staged("curved.yaml");
    let out = |s: &str| dir.path().join(format!("pipelines/out/{s}.pvd"));
    let runs = json("curved.py", &[&out("curved"), &out("curved-b44")]);
    let dir2 = staged("curved-facet.yaml");
    let out2 = |s: &str| dir2.path().join(format!("pipelines/out/{s}.pvd"));
    let runs2 = json("curved.py", &[&out2("curved-facet"), &out2("curved-nby3")]);
    // (label, run, F_z, Newton total, d2 interior max)
    let cases = [
        ("B-spline [3,3]", &runs[0], 1583.547, 40.0, 0.248),
        ("B-spline [4,4]", &runs[1], 1483.790, 27.0, 0.443),
        // 35 before the line search (2026-11-23), 46 with it: the facets' residual
        // rises at every crease crossing and the search shortens those steps
        ("facet, nby 3", &runs2[0], 1631.366, 46.0, 0.845),
        ("B-spline [3,3], nby 3", &runs2[1], 1623.349, 29.0, 0.239),
    ];
    for (label, j, fz, newton, d2) in cases {
        let force: Vec<f64> = j["contact_force"].as_sequence().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        let d2_got = f(j, &["centreline", "d2_interior_max"]);
        eprintln!("{label}: F = {force:?}, Newton {}, d2 max {d2_got:.3}", f(j, &["newton_total"]));
        assert_eq!(j["completed"].as_bool(), Some(true), "{label}");
        assert!((force[2] - fz).abs() < 1e-4 * fz, "{label}: F_z = {}", force[2]);
        assert!(f(j, &["newton_total"]) <= newton + 4.0, "{label}: {} Newton corrections", f(j, &["newton_total"]));
        assert!(d2_got < 1.2 * d2, "{label}: d2 {d2_got}");
        assert_eq!(j["centreline"]["unimodal"].as_bool(), Some(true), "{label}");
        if label.starts_with("facet") {
            // the ridge node takes one facet's normal: a lateral force in a symmetric problem
            assert!(force[0].abs() > 1e-2 * force[2], "{label}: F_x = {}", force[0]);
        } else {
            assert!(force[0].abs() < 1e-6 * force[2], "{label}: F_x = {}", force[0]);
        }
    }
    // same mesh, the smooth master's pressure is smoother than the facets'
    assert!(f(&runs2[1], &["centreline", "d2_interior_max"]) < 0.5 * f(&runs2[0], &["centreline", "d2_interior_max"]));
}

/// The facet master on the shipped curved mesh: a pad node sits over a concave crease
/// of the indented base, where plain node-to-facet contact has no equilibrium (see
/// curved-facet.yaml). Without the stabilisation (`newton: {search_updates: 0,
/// line_search: false}`) and without the damped Uzawa update (`update_halvings: 0`)
/// Newton must say so — a period-2 cycle of the contact configuration, naming the
/// node — instead of iterating to the limit, and the solve stops with exit code 3
/// after its cutbacks. With the damped update (the default) the unstabilised solve
/// gets through: each full update makes the pad nodes over the crease cycle, half of
/// it does not (measured: 7 increments, 2 cutbacks, 114 corrections). With the
/// stabilisation too (the defaults: facets held on their continued planes, line
/// search) it converges without a cutback (measured: 5 increments, 80 corrections).
#[test]
fn facet_on_a_concave_crease_reports_the_cycling_node() {
    let dir = tempdir();
    std::fs::copy(repo().join("meshes/curved.msh"), dir.path().join("c.msh")).unwrap();
    assert!(run("sc-import", &["c.msh", "-o", "c.scmesh"], dir.path()).status.success());
    assert!(run("sc-tag", &["c.scmesh", "--pair", "contact:pad_bottom:base_top:facet", "-o", "c.sccontact"], dir.path()).status.success());
    let setup = "materials:\n  - {body: base, model: neo_hookean, E: 1000.0, nu: 0.3}\n  - {body: pad, model: neo_hookean, E: 1000.0, nu: 0.3}\n\
constraints:\n  - {set: base_bottom, fix: [x, y, z]}\n  - {set: pad_top, fix: [x, y], displacement: {z: -0.4}}\n\
contact:\n  - {pair: contact, eps_n: 1.0e5, enforcement: augmented_lagrangian, penetration_tolerance: 1.0e-5}\n\
increments: {count: 5, max_cutbacks: 1}\n";
    let undamped = setup.replace("penetration_tolerance: 1.0e-5}", "penetration_tolerance: 1.0e-5, update_halvings: 0}");
    assert_ne!(undamped, setup);
    std::fs::write(dir.path().join("s.yaml"), format!("{undamped}newton: {{search_updates: 0, line_search: false}}\n")).unwrap();
    let o = run("sc-solve", &["c.sccontact", "--setup", "s.yaml", "-o", "r.scres"], dir.path());
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(err.contains("the contact configuration cycles between two states"), "{err}");
    // the named nodes are pad nodes over the crease row (measured: 163, 168, 173 at
    // the first cycle, 163 after the cutback; 168 before crease contact)
    let named = err.rsplit("slave nodes ").next().unwrap().split(" alternate").next().unwrap();
    let tags: Vec<u32> = named.split(", ").map(|t| t.parse().unwrap()).collect();
    assert!(!tags.is_empty() && tags.iter().all(|t| [163, 168, 173].contains(t)), "{err}");
    // within a few iterations, not at max_iterations
    assert!(!err.contains("did not converge in 25 iterations"), "{err}");
    // and it points at what can help a facet master (docs/pipelines.md)
    assert!(err.contains("pair 'contact' has a facet master") && err.contains("`stabilization: 0.15`"), "{err}");
    // the damped Uzawa update (the default), still unstabilised: through to the end
    std::fs::write(dir.path().join("s1.yaml"), format!("{setup}newton: {{search_updates: 0, line_search: false}}\n")).unwrap();
    let o = run("sc-solve", &["c.sccontact", "--setup", "s1.yaml", "-o", "r1.scres"], dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("Newton failed after the Uzawa update") && err.contains("solving again with 0.5 of the update"), "{err}");
    let r = Results::read(&dir.path().join("r1.scres")).unwrap();
    assert_eq!(r.increments.last().map(|i| i.info.load_factor), Some(1.0));
    assert!(r.increments.iter().all(|i| i.info.contact[0].penetration_converged), "penetration above the tolerance");
    assert!(r.increments.iter().map(|i| i.info.cutbacks).sum::<u32>() <= 4, "cutbacks (measured 2)");
    // stabilised (the defaults): converges, every increment, no cutback
    std::fs::write(dir.path().join("s2.yaml"), setup).unwrap();
    let o = run("sc-solve", &["c.sccontact", "--setup", "s2.yaml", "-o", "r2.scres"], dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let r = Results::read(&dir.path().join("r2.scres")).unwrap();
    assert_eq!(r.increments.len(), 5);
    assert_eq!(r.increments.iter().map(|i| i.info.cutbacks).sum::<u32>(), 0);
    let its: usize = r.increments.iter().map(|i| i.info.iterations.len() - 1).sum();
    assert!(its <= 100, "{its} Newton corrections (measured 80)");
}

/// 3D Hertz (issue 26, `pipelines/hertz3d.yaml`): a stiff ball pressed onto a soft
/// block, the ball's surface the master as a free quad mesh with extraordinary nodes,
/// once as the Catmull–Clark limit surface (`bspline` → subdivision) and once as
/// facets, on the same mesh; `docs/scripts/hertz3d.py` compares the block's nodal
/// pressures with the closed form for the measured force.
/// Measured (refine 1, slave spacing 0.15, a ≈ 0.885, 113 active nodes):
/// subdivision p0 +1.09 %, a_fit −0.53 %, profile RMS 0.0171; facets p0 +5.80 %,
/// a_fit −0.49 %, RMS 0.0213. Refined 1.4 × (slave spacing 0.109, 220 active nodes;
/// docs/validation/masters.md): subdivision p0 +0.57 %, a_fit −0.19 %, RMS 0.0134;
/// facets p0 +3.69 %, a_fit −0.29 %, RMS 0.0147. The subdivision peak error halves
/// (about h²), the facets' falls more slowly and stays 6 × larger: it is the faceted
/// sphere's kink under the peak. Asserted: the subdivision peak within 3 % (about 3 ×
/// its refine-1 error, which refinement only lowers), the facets' peak error at least
/// twice the subdivision's, both contact radii within 2 % (0.5 % measured, the fit's
/// O(h) floor), the subdivision profile closer to Hertz than the facets', and the RMS
/// pinned to ±5 % (a change of method moves it by more; it is then to be measured again).
#[test]
fn hertz3d_subdivision_master_beats_facets() {
    let dir = staged_pipeline("hertz3d", &["hertz3d.msh"]);
    let o = run("sc-pipeline", &["pipelines/hertz3d.yaml"], dir.path());
    assert!(o.status.success(), "hertz3d.yaml: {}", stderr(&o));
    assert!(stderr(&o).contains("subdivision orders [4, 4]"), "sc-tag's choice: {}", stderr(&o));
    let mut got = Vec::new();
    for stem in ["hertz3d", "hertz3d-facet"] {
        let scres = dir.path().join(format!("pipelines/out/{stem}.scres"));
        let e1 = Path::new("--E1");
        let (v1, e2, v2) = (Path::new("2e5"), Path::new("--E2"), Path::new("200"));
        let j = json("../../docs/scripts/hertz3d.py", &[&scres, e1, v1, e2, v2]).remove(0);
        eprintln!("{stem}: F {:.4}, p0 err {:+.4}, a_fit err {:+.4}, rms {:.5}, active {}", f(&j, &["F"]), f(&j, &["p0_err"]), f(&j, &["a_fit_err"]), f(&j, &["profile_rms_err"]), f(&j, &["active"]));
        assert!((f(&j, &["F"]) - 25.4).abs() < 0.5, "{stem}: F = {}", f(&j, &["F"]));
        assert!(f(&j, &["a_fit_err"]).abs() < 0.02, "{stem}: contact radius error {}", f(&j, &["a_fit_err"]));
        got.push((f(&j, &["p0_err"]), f(&j, &["profile_rms_err"])));
    }
    let ((p_cc, rms_cc), (p_f, rms_f)) = (got[0], got[1]);
    assert!(p_cc.abs() < 0.03, "subdivision: peak pressure error {p_cc}");
    assert!(p_f.abs() > 2.0 * p_cc.abs(), "facets {p_f} against subdivision {p_cc}");
    assert!(rms_cc < rms_f, "profile RMS: subdivision {rms_cc}, facets {rms_f}");
    assert!((rms_cc / 0.01705 - 1.0).abs() < 0.05, "subdivision profile RMS {rms_cc} (measured 0.01705)");
}

/// A punch on an unstructured block (`pipelines/punch.yaml`, issue 26): the block's
/// top, meshed by gmsh with all hexahedra but unstructured (interior nodes of valence
/// 3–6, boundary nodes in 1 and 3 faces), is the master, so sc-tag takes the
/// Catmull–Clark surface; the same mesh is solved with facets too. Reference:
/// CalculiX 2.20 on the same mesh (`tests/ccx/deck.py pipelines/punch.yaml --run`),
/// which converges to t = 0.25 and then stops ("increment size smaller than
/// minimum"): punch reaction 7.3282 there. Asserted:
/// - both complete without a cutback; every slave node active at the end; the
///   contact force balances the punch's reaction (1e-6: the Newton tolerance);
/// - facets at t = 0.25 within 0.5 % of ccx (measured +0.07 %; ccx's penalty slope
///   1e7 against our augmented Lagrangian to 1e-5 of penetration, 0.1 % of the
///   indentation);
/// - the Catmull–Clark master 5.2 % above ccx at t = 0.25 (±1 %): the smoothed
///   master's offset where the block's top bends sharply under the punch's edges
///   (the limit surface does not pass through the nodes). A single B-spline patch
///   on a structured version of the block gives the same, +8.7 % over facets, and the
///   forced subdivision master equals it there (docs/validation/masters.md);
/// - the Catmull–Clark master needs no more Newton corrections than the facets
///   (measured 76 against 131).
#[test]
fn punch_on_an_unstructured_block_has_a_catmull_clark_master() {
    let dir = staged_pipeline("punch", &["punch.msh"]);
    let o = run("sc-pipeline", &["pipelines/punch.yaml"], dir.path());
    assert!(o.status.success(), "punch.yaml: {}", stderr(&o));
    assert!(stderr(&o).contains("354 quads on 383 nodes, subdivision orders [4, 4]"), "sc-tag's choice: {}", stderr(&o));
    const CCX_AT_QUARTER: f64 = 7.3282;
    let mut corrections = Vec::new();
    let mut at_quarter = Vec::new();
    for stem in ["punch", "punch-facet"] {
        let r = Results::read(&dir.path().join(format!("pipelines/out/{stem}.scres"))).unwrap();
        assert_eq!(r.increments.len(), 4, "{stem}");
        for inc in &r.increments {
            assert_eq!(inc.info.cutbacks, 0, "{stem}: cutbacks at t = {}", inc.info.load_factor);
            let punch = inc.info.reactions.iter().find(|x| x.set == "punch_top").unwrap().force[2];
            let contact = inc.info.contact[0].force[2];
            assert!((contact + punch).abs() < 1e-6 * punch.abs(), "{stem} t = {}: contact {contact} against the punch's reaction {punch}", inc.info.load_factor);
        }
        assert_eq!(r.increments.last().unwrap().info.contact[0].active, 81, "{stem}: every slave node active");
        corrections.push(r.increments.iter().map(|i| i.info.iterations.len() - 1).sum::<usize>());
        at_quarter.push(-r.increments[0].info.reactions.iter().find(|x| x.set == "punch_top").unwrap().force[2]);
    }
    let (cc, facet) = (at_quarter[0] / CCX_AT_QUARTER - 1.0, at_quarter[1] / CCX_AT_QUARTER - 1.0);
    eprintln!("punch at t = 0.25 against ccx {CCX_AT_QUARTER}: Catmull–Clark {:.4} ({:+.2} %), facets {:.4} ({:+.2} %); Newton corrections {corrections:?}", at_quarter[0], 100.0 * cc, at_quarter[1], 100.0 * facet);
    assert!(facet.abs() < 0.005, "facets against ccx: {facet:+e}");
    assert!((cc - 0.052).abs() < 0.01, "Catmull–Clark against ccx: {cc:+e} (measured +0.052)");
    assert!(corrections[0] <= corrections[1], "Newton corrections: Catmull–Clark {}, facets {}", corrections[0], corrections[1]);
}
