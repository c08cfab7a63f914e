//! The same input gives the same bytes: the shipped frictional crossed beams
//! (`pipelines/crossed_beams.yaml`: import, tag, an augmented-Lagrangian solve with
//! Coulomb friction and GMRES, export) run three times — with 1 thread, with 2, and
//! with 2 again, the large blocks then from the system allocator instead of huge
//! pages (`SC_HUGE_PAGES=0`, lib/os/large_pages.rs) — write byte-identical stage
//! files, `.vtu`/`.pvd` series and CSVs under `SC_REPRODUCIBLE=1` (which records
//! the wall-clock times as 0). Without it,
//! the per-iteration `seconds_*` and the increments' `seconds_output` are the only
//! difference.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use crate::common::*;

/// Run the pipeline staged in `dir` with `threads` rayon threads; every file it
/// wrote, by name.
fn run_pipeline(dir: &Path, threads: &str, reproducible: bool) -> BTreeMap<String, Vec<u8>> {
    run_pipeline_with(dir, threads, reproducible, true)
}

/// [`run_pipeline`], the large blocks on huge pages or not (`SC_HUGE_PAGES=0`).
fn run_pipeline_with(dir: &Path, threads: &str, reproducible: bool, huge_pages: bool) -> BTreeMap<String, Vec<u8>> {
    let out = dir.join("pipelines/out");
    let _ = std::fs::remove_dir_all(&out);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_sc-pipeline"));
    cmd.args(["pipelines/crossed_beams.yaml", "-q"]).current_dir(dir).env("RAYON_NUM_THREADS", threads);
    if !huge_pages {
        cmd.env("SC_HUGE_PAGES", "0");
    } else {
        cmd.env_remove("SC_HUGE_PAGES");
    }
    if reproducible {
        cmd.env("SC_REPRODUCIBLE", "1");
    } else {
        cmd.env_remove("SC_REPRODUCIBLE");
    }
    let o = cmd.output().expect("sc-pipeline runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::read_dir(&out).unwrap().map(|e| e.unwrap()).map(|e| (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).unwrap())).collect()
}

fn differing(a: &BTreeMap<String, Vec<u8>>, b: &BTreeMap<String, Vec<u8>>) -> Vec<String> {
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>(), "the runs wrote different files");
    a.iter().filter(|(k, v)| b[*k] != **v).map(|(k, _)| k.clone()).collect()
}

#[test]
fn same_input_same_bytes_with_one_and_two_threads() {
    let dir = staged_pipeline("crossed_beams", &["crossed_beams.msh"]);
    let one = run_pipeline(dir.path(), "1", true);
    let two = run_pipeline(dir.path(), "2", true);
    let again = run_pipeline_with(dir.path(), "2", true, false);
    for ext in [".scmesh", ".sccontact", ".scres", ".vtu", ".pvd", ".forces.csv", ".convergence.csv"] {
        assert!(one.keys().any(|k| k.ends_with(ext)), "no {ext} written");
    }
    assert_eq!(differing(&two, &again), Vec::<String>::new(), "two runs with 2 threads differ (the second without huge pages)");
    assert_eq!(differing(&one, &two), Vec::<String>::new(), "1 and 2 threads differ");
    eprintln!("{} files, {} bytes, identical in three runs (1, 2, 2 threads, the last without huge pages)", one.len(), one.values().map(Vec::len).sum::<usize>());
}

/// Without `SC_REPRODUCIBLE` only the wall-clock times differ: the YAML dumps of
/// the two results files agree on every line but the `seconds_*` ones, and every
/// `.vtu` is byte-identical.
#[test]
fn only_the_wall_clock_times_differ_by_default() {
    let dir = staged_pipeline("crossed_beams", &["crossed_beams.msh"]);
    let a = run_pipeline(dir.path(), "2", false);
    let b = run_pipeline(dir.path(), "2", false);
    for name in differing(&a, &b) {
        assert!(name.ends_with(".scres") || name.ends_with(".convergence.csv"), "{name} differs");
    }
    let dump = |bytes: &[u8]| {
        let f = splinecontact::format::stage::StageFile::parse("r", bytes, None).unwrap();
        let mut out = Vec::new();
        f.dump_yaml(&mut out).unwrap();
        String::from_utf8(out).unwrap().lines().filter(|l| !l.contains("seconds_")).map(str::to_string).collect::<Vec<_>>()
    };
    assert_eq!(dump(&a["crossed_beams.scres"]), dump(&b["crossed_beams.scres"]));
}

/// `newton.residual_first` (on by default) changes the cost of an iterate, not its
/// numbers: the shipped crossed beams, whose augmented-Lagrangian solves converge
/// quadratically, check several converged iterates by their residual alone, and
/// every displacement, multiplier, friction state, reaction and residual in the
/// results equals, bit for bit, that of the same run with it off.
#[test]
fn the_residual_first_check_changes_no_number() {
    let dir = staged_pipeline("crossed_beams", &["crossed_beams.msh"]);
    let run = |residual_first: bool| {
        let yaml = dir.path().join("pipelines/crossed_beams.yaml");
        let text = std::fs::read_to_string(&yaml).unwrap();
        let newton = "newton: {max_iterations: 25, residual_tolerance: 1.0e-8, energy_tolerance: 1.0e-12";
        assert!(text.contains(newton), "the shipped pipeline's newton line changed");
        let set = format!("{newton}, residual_first: {residual_first}");
        let patched = text.replace(&format!("{newton}, residual_first: true"), newton).replace(&format!("{newton}, residual_first: false"), newton).replace(newton, &set);
        std::fs::write(&yaml, patched).unwrap();
        let out = dir.path().join("pipelines/out");
        let _ = std::fs::remove_dir_all(&out);
        let o = Command::new(env!("CARGO_BIN_EXE_sc-pipeline")).args(["pipelines/crossed_beams.yaml"]).current_dir(dir.path()).env("SC_REPRODUCIBLE", "1").output().unwrap();
        let log = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(o.status.success(), "{log}");
        let bytes = std::fs::read(out.join("crossed_beams.scres")).unwrap();
        let f = splinecontact::format::stage::StageFile::parse("r", &bytes, None).unwrap();
        let mut dump = Vec::new();
        f.dump_yaml(&mut dump).unwrap();
        // the setup the results record names the option itself; nothing else may differ
        let lines: Vec<String> = String::from_utf8(dump).unwrap().lines().filter(|l| !l.contains("residual_first")).map(str::to_string).collect();
        (lines, log)
    };
    let (on, log_on) = run(true);
    let (off, log_off) = run(false);
    let checks = log_on
        .lines()
        .find_map(|l| l.split_once("assembly: ").and_then(|(_, r)| r.split_whitespace().next()).and_then(|n| n.parse::<usize>().ok()))
        .unwrap_or_else(|| panic!("no residual-first line in the log:\n{log_on}"));
    assert!(checks >= 3, "only {checks} iterates were checked residual first:\n{log_on}");
    assert!(!log_off.contains("assembled residual first"), "{log_off}");
    assert_eq!(on.len(), off.len());
    for (a, b) in on.iter().zip(&off) {
        assert_eq!(a, b, "the results differ");
    }
    eprintln!("{checks} iterates checked residual first; {} lines of results identical", on.len());
}
