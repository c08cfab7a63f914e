//! gmsh → sc-import → sc-export → meshio, on real gmsh output in every MSH flavour.

use crate::common::*;

/// gmsh meshes the Parisch .geo to one MSH flavour; we import and export it; meshio
/// reads both files and finds bit-identical points and identical hex connectivity.
fn round_trip(flags: &[&str], tag: &str) {
    let dir = tempdir();
    let msh = dir.path().join(format!("parisch-{tag}.msh"));
    gmsh_mesh(&repo().join("meshes/parisch.geo"), &msh, flags);
    let scmesh = dir.path().join("m.scmesh");
    let o = run("sc-import", &[msh.to_str().unwrap(), "-o", scmesh.to_str().unwrap()], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("50 nodes, 13 hexahedra"), "{err}");
    let vtu = dir.path().join("m.vtu");
    let o = run("sc-export", &[scmesh.to_str().unwrap(), "-o", vtu.to_str().unwrap()], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let o = python_script("compare_msh_vtu.py", &[&msh, &vtu]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "meshio check failed: {}{}", out, String::from_utf8_lossy(&o.stderr));
    assert!(out.contains("\"hexes\": 13") && out.contains("\"points\": 50"), "{out}");
}

#[test]
fn round_trip_msh22_ascii() {
    round_trip(&["-format", "msh22"], "22a");
}

#[test]
fn round_trip_msh22_binary() {
    round_trip(&["-format", "msh22", "-bin"], "22b");
}

#[test]
fn round_trip_msh41_ascii() {
    round_trip(&["-format", "msh41"], "41a");
}

#[test]
fn round_trip_msh41_binary() {
    round_trip(&["-format", "msh41", "-bin"], "41b");
}

/// The committed mesh pipes through stdin/stdout: import - | export - as YAML.
#[test]
fn stdin_stdout_pipe_and_yaml_dump() {
    let dir = tempdir();
    let msh = std::fs::read(repo().join("meshes/parisch.msh")).unwrap();
    let import = std::process::Command::new(env!("CARGO_BIN_EXE_sc-import"))
        .args(["-", "-o", "-", "--quiet"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write;
    import.stdin.as_ref().unwrap().write_all(&msh).unwrap();
    let scmesh = import.wait_with_output().unwrap();
    assert!(scmesh.status.success());
    assert!(scmesh.stdout.starts_with(b"splinecontact scmesh 1."));
    let mut export = std::process::Command::new(env!("CARGO_BIN_EXE_sc-export"))
        .args(["-", "--format", "yaml", "-o", "-"])
        .current_dir(dir.path())
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    export.stdin.take().unwrap().write_all(&scmesh.stdout).unwrap();
    let yaml = export.wait_with_output().unwrap();
    assert!(yaml.status.success());
    let text = String::from_utf8(yaml.stdout).unwrap();
    // The dump is YAML a user (and a YAML parser) can read: the node count and the
    // load node's coordinates (0, 0, 22) appear.
    assert!(text.contains("format: scmesh") && text.contains("nodes: 50") && text.contains("hexes: 13"), "{text}");
    assert!(text.contains("name: load_node"), "{text}");
    assert!(text.contains("[0.0, 0.0, 22.0]"), "{text}");
}
