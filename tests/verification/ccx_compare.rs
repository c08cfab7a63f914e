//! The CalculiX comparison tool (`docs/scripts/ccx_compare.py`), so that it cannot
//! rot: both programs run the frictional crossed beams at the smallest level (2 × 2 ×
//! 30 hex8 per beam, 1,593 free dofs) and the Parisch blocks at r = 6 on the same gmsh
//! mesh, and must agree.
//! Needs `ccx` (Debian's calculix-ccx; `./test.sh` installs it when run as root).

use crate::common::{python, repo};
use std::process::Command;

/// Runs `ccx_compare.py MODEL --levels LEVEL --json`; its one row, after checking
/// that both programs finished.
fn compare(model: &str, level: &str) -> serde_yaml::Value {
    compare_with(model, level, &[])
}

/// The same with more options of the script (`--integration mortar`, `--contact surface`).
fn compare_with(model: &str, level: &str, options: &[&str]) -> serde_yaml::Value {
    let out = tempfile::tempdir().unwrap();
    let bin_dir = std::path::Path::new(env!("CARGO_BIN_EXE_sc-solve")).parent().unwrap();
    let o = Command::new(python())
        .arg(repo().join("docs/scripts/ccx_compare.py"))
        // one run of each program: the answers are checked, not the times
        .args([model, "--levels", level, "--threads", "2", "--repeat", "1", "--repeat-short", "1", "--json"])
        .args(options)
        .arg("--out")
        .arg(out.path())
        .env("SC_BIN_DIR", bin_dir)
        .output()
        .expect("python runs");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "ccx_compare.py {model} failed: {}\n{stdout}", String::from_utf8_lossy(&o.stderr));
    let rows: serde_yaml::Value = serde_yaml::from_str(&stdout).expect("JSON rows");
    let row = rows[0].clone();
    assert_eq!(row["ours"]["ok"].as_bool(), Some(true), "{model}: ours {:?}", row["ours"]);
    assert_eq!(row["ccx"]["ok"].as_bool(), Some(true), "{model}: ccx {:?}", row["ccx"]);
    row
}

fn f(v: &serde_yaml::Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

#[test]
fn crossed_beams_agree_with_calculix_at_the_smallest_level() {
    let row = &compare("crossed_beams", "2");
    assert_eq!(row["dofs"].as_u64(), Some(1593));
    // Measured: max |u| 1.33121 (ours) against 1.33164 (ccx), 3.3e-4; the support
    // reaction 1.1e-5. ccx's penalty (100 eps_N against our augmented Lagrangian),
    // its dev/vol NEO HOOKE against Ciarlet-Simo and its facet master against our
    // B-spline stay well inside the script's 1 %; a wrong load, support or contact
    // transfer is off by several %.
    let (du, dr) = (f(&row["agreement"]["max_u"]), f(&row["agreement"]["reaction_z"]));
    assert!(du < 2e-3, "max |u| differs by {du:e}");
    assert!(dr < 1e-3, "the support reaction differs by {dr:e}");
    // the full load path: 9000 N down, taken by the clamps of both beams
    let rz = f(&row["ours"]["reaction"][2]) + f(&row["ccx"]["reaction"][2]);
    assert!(rz > 2.0 * 11_000.0 && rz < 2.0 * 13_000.0, "lower beam reactions {rz}");
    // our Newton iterations (18 measured; +25 %: a regression of the solver shows)
    let its = row["ours"]["newton_iterations"].as_u64().unwrap();
    assert!((10..=23).contains(&its), "{its} Newton iterations");
}

/// Our mortar integration against CalculiX's surface-to-surface contact, on the
/// crossed beams at n = 4 (8,925 dofs): the two integrated contacts of the two
/// programs. On the paper's coarse mesh our mortar's tip deflects 13.4 % more than
/// node-to-surface's (the cantilever's reaction inside the lower beam's edge,
/// docs/validation.md); under refinement the two integrations converge to each
/// other (+3.1 % at n = 4, +0.9 % at n = 10), and at n = 4 ccx's surface-to-surface
/// agrees with our mortar. Measured: max |u| 1.49426 against 1.49208 (1.5e-3), the
/// lower beam's reaction 12133 against 12186 (4.4e-3). What differs: ccx's facet
/// master against our B-spline, its penalty (slope 100 ε_N) against our augmented
/// Lagrangian, its own increments and its dev/vol NEO HOOKE (the tolerances of the
/// node-to-surface comparison above). 0.5 % and 1 % hold both; node-to-surface is
/// 3 % from ccx's surface-to-surface here, so mixing the two pairings fails.
#[test]
fn crossed_beams_under_mortar_agree_with_calculix_surface_to_surface() {
    let row = &compare_with("crossed_beams", "4", &["--integration", "mortar", "--contact", "surface"]);
    assert_eq!(row["dofs"].as_u64(), Some(8925));
    let (du, dr) = (f(&row["agreement"]["max_u"]), f(&row["agreement"]["reaction_z"]));
    assert!(du < 5e-3, "max |u| differs by {du:e}");
    assert!(dr < 1e-2, "the support reaction differs by {dr:e}");
    // our Newton iterations (28 measured; +25 %)
    let its = row["ours"]["newton_iterations"].as_u64().unwrap();
    assert!((20..=35).contains(&its), "{its} Newton iterations");
}

/// The Parisch blocks at r = 6 (10,042 dofs), the first level where ccx, given our
/// Newton tolerance of 1e-8, cuts its increment back until it stops: its residual
/// stalls at 1.4e-7 of its average force (round-off). The script gives it R_n = 1e-6
/// there (the model's `ccx_ran`, docs/performance.md); both must then finish and agree.
#[test]
fn parisch_agrees_with_calculix_where_its_residual_floor_binds() {
    let row = &compare("parisch", "6");
    assert_eq!(row["dofs"].as_u64(), Some(10_042));
    // Measured: max |u| 0.0517704 (ours) against 0.0517699 (ccx), 9.7e-6: a flat
    // master (the B-spline over a flat grid is the plane, as ccx's facets), the same
    // penalty and one increment; what is left are the differences the deck's header
    // lists (ccx's dev/vol NEO HOOKE against Ciarlet-Simo, its tributary areas in the
    // current configuration). 1e-4 is ten times that; a wrong load or contact
    // transfer is off by percents.
    let du = f(&row["agreement"]["max_u"]);
    assert!(du < 1e-4, "max |u| differs by {du:e}");
    // the reaction is the point load, 2e6, in both (measured 2.5e-11 apart)
    let dr = f(&row["agreement"]["reaction_z"]);
    assert!(dr < 1e-8, "the support reaction differs by {dr:e}");
    // ccx converges in 3 iterations, ours in 2 (a cutback or a stall shows)
    assert_eq!(row["ccx"]["newton_iterations"].as_u64(), Some(3));
    assert_eq!(row["ours"]["newton_iterations"].as_u64(), Some(2));
}

/// The script times the two programs in turn, A B B A A B ..., each until its own
/// count (`interleaved`), so that a slow spell of the shared machine, or what one
/// program's run leaves behind, weighs on both medians alike. Fake runs (no ccx)
/// record the order: eleven short runs each come out as 5½ rounds of A B / B A; a
/// program whose runs are long stops at its three while the other goes on alone; a
/// failed run stops that program at once.
#[test]
fn the_comparison_times_the_two_programs_in_turn() {
    let snippet = r#"
import sys, types
sys.path.insert(0, sys.argv[1])
import ccx_compare
a = types.SimpleNamespace(repeat=3, repeat_below=20.0, repeat_short=11, short_below=1.0)
def case(walls):
    order = []
    def run(name):
        def once():
            k = sum(1 for o in order if o == name)
            order.append(name)
            ok, wall = walls[name](k)
            return name + str(k), ok, wall
        return once
    out = ccx_compare.interleaved([run("A"), run("B")], a)
    print("".join(order), [len(w) for _, w in out], [r for r, _ in out])
case({"A": lambda k: (True, 0.05), "B": lambda k: (True, 0.5)})
case({"A": lambda k: (True, 0.05), "B": lambda k: (True, 5.0)})
case({"A": lambda k: (k < 1, 0.05), "B": lambda k: (True, 0.5)})
"#;
    let o = Command::new(python()).arg("-c").arg(snippet).arg(repo().join("docs/scripts")).output().expect("python runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines, [
        "ABBAABBAABBAABBAABBAAB [11, 11] ['A10', 'B10']",
        "ABBAABAAAAAAAA [11, 3] ['A10', 'B2']",
        "ABBABBBBBBBBB [2, 11] ['A1', 'B10']",
    ], "{out}");
}
