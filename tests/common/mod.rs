//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod grid;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Run one of our binaries with `args` in `dir`.
pub fn run(bin: &str, args: &[&str], dir: &Path) -> Output {
    let exe = match bin {
        "sc-import" => env!("CARGO_BIN_EXE_sc-import"),
        "sc-export" => env!("CARGO_BIN_EXE_sc-export"),
        "sc-pipeline" => env!("CARGO_BIN_EXE_sc-pipeline"),
        "sc-solve" => env!("CARGO_BIN_EXE_sc-solve"),
        "sc-tag" => env!("CARGO_BIN_EXE_sc-tag"),
        "sc-plot" => env!("CARGO_BIN_EXE_sc-plot"),
        "sc-check" => env!("CARGO_BIN_EXE_sc-check"),
        other => panic!("unknown binary {other}"),
    };
    Command::new(exe).args(args).current_dir(dir).output().expect("binary runs")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Assert a failed run: the exit code, a message containing every `needle`, and
/// that `output` was not created (no half-written file, no temporary left).
pub fn assert_fails(o: &Output, code: i32, needles: &[&str], output: &Path) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(code), "exit code; stderr:\n{err}");
    for n in needles {
        assert!(err.contains(n), "stderr lacks {n:?}:\n{err}");
    }
    assert!(!output.exists(), "{} exists after a failed run", output.display());
    if let Some(dir) = output.parent() {
        let leftovers: Vec<_> = std::fs::read_dir(dir)
            .map(|d| d.filter_map(|e| e.ok()).map(|e| e.file_name().to_string_lossy().into_owned()).filter(|n| n.ends_with(".tmp")).collect())
            .unwrap_or_default();
        assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    }
}

/// The Python with meshio and gmsh: `$SC_PYTHON`, else `.venv/bin/python`.
/// Missing is a failure, not a skip: run the tests through `./test.sh`.
pub fn python() -> PathBuf {
    if let Some(p) = std::env::var_os("SC_PYTHON") {
        return PathBuf::from(p);
    }
    let venv = repo().join(".venv/bin/python");
    assert!(venv.is_file(), "no Python with meshio/gmsh: run the tests with ./test.sh (it creates .venv)");
    venv
}

/// The gmsh executable next to that Python (the PyPI wheel's console script).
pub fn gmsh() -> PathBuf {
    let py = python();
    let g = py.parent().expect("venv bin").join("gmsh");
    if g.is_file() {
        g
    } else {
        PathBuf::from("gmsh")
    }
}

/// Mesh `geo` with gmsh into `out` with extra CLI flags (e.g. `-format msh22`).
pub fn gmsh_mesh(geo: &Path, out: &Path, flags: &[&str]) {
    // The PyPI gmsh script starts with `#!/usr/bin/env python`: the venv must come first on PATH.
    let path = format!("{}:{}", python().parent().expect("venv bin").display(), std::env::var("PATH").unwrap_or_default());
    let o = Command::new(gmsh()).arg(geo).arg("-3").args(flags).arg("-o").arg(out).env("PATH", path).output().expect("gmsh runs");
    assert!(o.status.success() && out.is_file(), "gmsh failed: {}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
}

/// Run `tests/py/<script>` with the test Python; scripts that read results files find
/// this build's `sc-export` through `$SC_EXPORT`.
pub fn python_script(script: &str, args: &[&Path]) -> Output {
    Command::new(python())
        .arg(repo().join("tests/py").join(script))
        .args(args)
        .env("SC_EXPORT", env!("CARGO_BIN_EXE_sc-export"))
        .output()
        .expect("python runs")
}

pub fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

/// A scratch copy of the repository layout for running a pipeline without writing
/// into the checkout: `meshes/` with the named meshes of the repository, and an
/// empty `pipelines/` to put the pipeline in.
pub fn staged_meshes(meshes: &[&str]) -> tempfile::TempDir {
    let dir = tempdir();
    for d in ["meshes", "pipelines"] {
        std::fs::create_dir_all(dir.path().join(d)).unwrap();
    }
    for m in meshes {
        std::fs::copy(repo().join("meshes").join(m), dir.path().join("meshes").join(m)).unwrap();
    }
    dir
}

/// [`staged_meshes`], plus the shipped `pipelines/<name>.yaml`.
pub fn staged_pipeline(name: &str, meshes: &[&str]) -> tempfile::TempDir {
    let dir = staged_meshes(meshes);
    let yaml = format!("pipelines/{name}.yaml");
    std::fs::copy(repo().join(&yaml), dir.path().join(&yaml)).unwrap();
    dir
}
