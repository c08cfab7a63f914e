//! Every shipped pipeline runs (in a copy of the repository layout, so the tests
//! never write into the checkout).

use std::path::Path;

use crate::common::*;

fn copy_tree(from: &Path, to: &Path, sub: &str) {
    let src = from.join(sub);
    let dst = to.join(sub);
    std::fs::create_dir_all(&dst).unwrap();
    for e in std::fs::read_dir(&src).unwrap() {
        let e = e.unwrap();
        if e.file_type().unwrap().is_file() {
            std::fs::copy(e.path(), dst.join(e.file_name())).unwrap();
        }
    }
}

fn staged_repo() -> tempfile::TempDir {
    let dir = tempdir();
    copy_tree(&repo(), dir.path(), "meshes");
    copy_tree(&repo(), dir.path(), "pipelines");
    dir
}

#[test]
fn parisch_pipeline_imports_and_exports() {
    let dir = staged_repo();
    // Run from another folder: paths resolve against the YAML, not the cwd.
    let o = run("sc-pipeline", &["pipelines/parisch.yaml"], dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("[1/7] import") && err.contains("[2/7] tag") && err.contains("[3/7] check") && err.contains("[4/7] solve") && err.contains("[7/7] export") && err.contains("pipeline finished"), "{err}");
    assert!(err.contains("pair contact: 9 slave nodes (face set 'upper_bottom') against master 'lower_top', 4 × 4 grid, bspline orders [3, 3]"), "{err}");
    for f in ["parisch_contact.vtu", "parisch_contact_contact_surface.vtu", "parisch_contact_contact_net.vtu"] {
        assert!(dir.path().join("pipelines/out").join(f).is_file(), "{f} missing");
    }
    let vtu = dir.path().join("pipelines/out/parisch.vtu");
    let o = python_script("compare_msh_vtu.py", &[&dir.path().join("meshes/parisch.msh"), &vtu]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn parisch_from_geo_pipeline_runs_gmsh() {
    let dir = staged_repo();
    let path = format!("{}:{}", gmsh().parent().unwrap().display(), std::env::var("PATH").unwrap_or_default());
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_sc-pipeline"))
        .arg("pipelines/parisch-from-geo.yaml")
        .current_dir(dir.path())
        .env("PATH", path)
        .env_remove("GMSH")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.path().join("pipelines/out/parisch-gmsh.vtu").is_file());
}

#[test]
fn gmsh_stage_without_gmsh_says_so() {
    let dir = staged_repo();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_sc-pipeline"))
        .arg("pipelines/parisch-from-geo.yaml")
        .current_dir(dir.path())
        .env("PATH", "/nonexistent")
        .env_remove("GMSH")
        .output()
        .unwrap();
    assert_fails(&o, 1, &["stage 1 (gmsh) failed", "gmsh is not installed"], &dir.path().join("pipelines/out/parisch-gmsh.msh"));
}

#[test]
fn pipeline_stops_at_first_failing_stage() {
    let dir = staged_repo();
    std::fs::write(
        dir.path().join("pipelines/broken.yaml"),
        "version: 1\nstages:\n  - import: {input: ../meshes/missing.msh, output: out/a.scmesh}\n  - export: {input: out/a.scmesh, output: out/a.vtu}\n",
    )
    .unwrap();
    let o = run("sc-pipeline", &["pipelines/broken.yaml"], dir.path());
    assert_fails(&o, 1, &["stage 1 (import) failed", "missing.msh"], &dir.path().join("pipelines/out/a.scmesh"));
    assert!(!stderr(&o).contains("[2/2]"), "second stage must not run");
}

/// Every shipped pipeline parses (stage keys, setups, aliases) and the meshes its
/// import stages read are in the repository: the long benchmark pipelines (ironing)
/// are not run by the tests, but a typo in them is caught here.
#[test]
fn every_shipped_pipeline_parses_and_finds_its_meshes() {
    use splinecontact::format::pipeline::{resolve, Pipeline, Stage};
    let dir = repo().join("pipelines");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_none_or(|x| x != "yaml") {
            continue;
        }
        let p = Pipeline::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut meshed = Vec::new();
        for stage in &p.stages {
            match stage {
                Stage::Gmsh(s) => meshed.push(resolve(&dir, &s.output)),
                Stage::Import(s) => {
                    let msh = resolve(&dir, &s.input);
                    assert!(msh.is_file() || meshed.contains(&msh), "{}: imports {} which is not in the repository", path.display(), msh.display());
                }
                _ => {}
            }
        }
        n += 1;
    }
    assert!(n >= 13, "found {n} pipelines");
}

/// Warnings are said even with `-q` (which silences everything else): an import
/// warning (an unknown MSH section, skipped), a solver warning (the augmented
/// Lagrangian allowed one update against a tolerance it cannot reach) and an export
/// warning (the sc-export test in `solve.rs`); each names its file or pair.
#[test]
fn warnings_survive_quiet() {
    let dir = staged_pipeline("parisch", &["parisch.msh"]);
    let msh = dir.path().join("meshes/parisch.msh");
    let mut bytes = std::fs::read(&msh).unwrap();
    bytes.extend_from_slice(b"$Custom\nnot for us\n$EndCustom\n");
    std::fs::write(&msh, bytes).unwrap();
    let yaml = dir.path().join("pipelines/parisch.yaml");
    let text = std::fs::read_to_string(&yaml).unwrap();
    let penalty = "{pair: contact, eps_n: 1.0e5, enforcement: penalty}";
    assert!(text.contains(penalty), "the shipped pipeline's contact line changed");
    let unreachable = "{pair: contact, eps_n: 1.0e5, enforcement: augmented_lagrangian, penetration_tolerance: 1.0e-14, max_augmentations: 1}";
    std::fs::write(&yaml, text.replace(penalty, unreachable)).unwrap();

    let o = run("sc-pipeline", &["-q", "pipelines/parisch.yaml"], dir.path());
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert!(lines.iter().all(|l| l.starts_with("warning: ")), "only warnings when quiet: {err}");
    assert!(lines.iter().any(|l| l.contains("parisch.msh") && l.contains("$Custom")), "the import warning: {err}");
    assert!(lines.iter().any(|l| l.contains("pair 'contact' still penetrates") && l.contains("after 1 augmentations")), "the solver warning: {err}");

    let o = run("sc-import", &["meshes/parisch.msh", "-o", "p.scmesh", "-q"], dir.path());
    assert!(o.status.success() && stderr(&o).starts_with("sc-import: warning: ") && stderr(&o).contains("$Custom"), "{}", stderr(&o));
    // without -q the summary comes first, then the same warning
    let o = run("sc-import", &["meshes/parisch.msh", "-o", "p.scmesh"], dir.path());
    assert!(stderr(&o).starts_with("read ") && stderr(&o).contains("sc-import: warning: "), "{}", stderr(&o));
}

/// Two pipelines writing into one output folder at once: the second refuses at its
/// first write there, naming the first (its process and pipeline), and writes
/// nothing; the first completes with whole files; once it has ended the folder is
/// free again (its lock is gone) and the second runs.
#[test]
fn a_second_pipeline_into_the_same_folder_refuses() {
    let dir = staged_pipeline("crossed_beams", &["crossed_beams.msh"]);
    let yaml = dir.path().join("pipelines/crossed_beams.yaml");
    // a load path of 150 increments keeps the first pipeline busy for seconds
    let text = std::fs::read_to_string(&yaml).unwrap().replace("increments: {count: 3,", "increments: {count: 150,");
    std::fs::write(&yaml, text).unwrap();
    let lock = dir.path().join("pipelines/out").join(splinecontact::folder_lock::LOCK_NAME);
    let mut first = std::process::Command::new(env!("CARGO_BIN_EXE_sc-pipeline"))
        .args(["pipelines/crossed_beams.yaml", "-q"])
        .current_dir(dir.path())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while !lock.exists() {
        assert!(start.elapsed().as_secs() < 30, "the first pipeline never locked its output folder");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let second = run("sc-pipeline", &["pipelines/crossed_beams.yaml", "-q"], dir.path());
    let err = stderr(&second);
    let still_running = first.try_wait().unwrap().is_none();
    assert_eq!(second.status.code(), Some(1), "{err}");
    assert!(err.contains(&format!("another sc-pipeline (process {}, running pipelines/crossed_beams.yaml)", first.id())), "{err}");
    assert!(still_running, "the first pipeline ended before the second was refused: the test proves nothing");
    assert!(first.wait().unwrap().success());
    assert!(!lock.exists(), "the lock outlived its pipeline");
    let r = splinecontact::format::scres::Results::read(&dir.path().join("pipelines/out/crossed_beams.scres")).unwrap();
    assert_eq!((r.status, r.increments.len() >= 150, r.tail), (splinecontact::format::scres::RunStatus::Completed, true, None));
    let again = run("sc-pipeline", &["pipelines/crossed_beams.yaml", "-q"], dir.path());
    assert!(again.status.success(), "{}", stderr(&again));
}
