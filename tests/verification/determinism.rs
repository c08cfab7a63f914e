//! The same input gives the same bytes: the shipped frictional crossed beams
//! (`pipelines/crossed_beams.yaml`: import, tag, an augmented-Lagrangian solve with
//! Coulomb friction and GMRES, export) run three times — with 1 thread, with 2, and
//! with 2 again — write byte-identical stage files, `.vtu`/`.pvd` series and CSVs
//! under `SC_REPRODUCIBLE=1` (which records the wall-clock times as 0). Without it,
//! the per-iteration `seconds_*` and the increments' `seconds_output` are the only
//! difference.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

use crate::common::*;

/// Run the pipeline staged in `dir` with `threads` rayon threads; every file it
/// wrote, by name.
fn run_pipeline(dir: &Path, threads: &str, reproducible: bool) -> BTreeMap<String, Vec<u8>> {
    let out = dir.join("pipelines/out");
    let _ = std::fs::remove_dir_all(&out);
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_sc-pipeline"));
    cmd.args(["pipelines/crossed_beams.yaml", "-q"]).current_dir(dir).env("RAYON_NUM_THREADS", threads);
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
    let again = run_pipeline(dir.path(), "2", true);
    for ext in [".scmesh", ".sccontact", ".scres", ".vtu", ".pvd", ".forces.csv", ".convergence.csv"] {
        assert!(one.keys().any(|k| k.ends_with(ext)), "no {ext} written");
    }
    assert_eq!(differing(&two, &again), Vec::<String>::new(), "two runs with 2 threads differ");
    assert_eq!(differing(&one, &two), Vec::<String>::new(), "1 and 2 threads differ");
    eprintln!("{} files, {} bytes, identical in three runs (1, 2, 2 threads)", one.len(), one.values().map(Vec::len).sum::<usize>());
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
