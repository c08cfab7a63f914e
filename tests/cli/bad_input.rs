//! Bad input: each case asserts the error text, a non-zero exit code, and that no
//! output file (nor a temporary) exists afterwards.

use std::path::Path;

use crate::common::*;

fn import_fails(content: &[u8], code: i32, needles: &[&str]) {
    let dir = tempdir();
    let input = dir.path().join("bad.msh");
    std::fs::write(&input, content).unwrap();
    let out = dir.path().join("out.scmesh");
    let o = run("sc-import", &["bad.msh", "-o", "out.scmesh"], dir.path());
    assert_fails(&o, code, needles, &out);
}

fn parisch() -> Vec<u8> {
    std::fs::read(repo().join("meshes/parisch.msh")).unwrap()
}

#[test]
fn truncated_msh() {
    let b = parisch();
    import_fails(&b[..b.len() / 2], 2, &["bad.msh"]);
}

#[test]
fn random_bytes() {
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    let bytes: Vec<u8> = (0..4096)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u8
        })
        .collect();
    import_fails(&bytes, 2, &["bad.msh", "MeshFormat"]);
}

#[test]
fn missing_end_nodes() {
    let text = String::from_utf8(parisch()).unwrap().replace("$EndNodes\n", "");
    import_fails(text.as_bytes(), 2, &["bad.msh", "$EndNodes"]);
}

#[test]
fn wrong_version_header() {
    let text = String::from_utf8(parisch()).unwrap().replacen("4.1 0 8", "3.0 0 8", 1);
    import_fails(text.as_bytes(), 2, &["bad.msh", "3.0", "2.2", "4.1"]);
}

#[test]
fn tetrahedral_mesh_is_refused() {
    let dir = tempdir();
    let geo = dir.path().join("tets.geo");
    std::fs::write(&geo, "SetFactory(\"OpenCASCADE\");\nBox(1) = {0,0,0,1,1,1};\nPhysical Volume(\"solid\") = {1};\nMesh.MeshSizeMax = 0.5;\n").unwrap();
    let msh = dir.path().join("tets.msh");
    gmsh_mesh(&geo, &msh, &["-format", "msh41"]);
    let out = dir.path().join("tets.scmesh");
    let o = run("sc-import", &["tets.msh", "-o", "tets.scmesh"], dir.path());
    assert_fails(&o, 2, &["tets.msh", "tetrahedr", "hexahedr"], &out);
}

#[test]
fn existing_output_survives_a_failed_import() {
    let dir = tempdir();
    std::fs::write(dir.path().join("bad.msh"), b"garbage").unwrap();
    let out = dir.path().join("keep.scmesh");
    std::fs::write(&out, b"previous").unwrap();
    let o = run("sc-import", &["bad.msh", "-o", "keep.scmesh"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(std::fs::read(&out).unwrap(), b"previous");
}

#[test]
fn truncated_scmesh_export() {
    let dir = tempdir();
    let o = run("sc-import", &[repo().join("meshes/parisch.msh").to_str().unwrap(), "-o", "m.scmesh"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let b = std::fs::read(dir.path().join("m.scmesh")).unwrap();
    std::fs::write(dir.path().join("cut.scmesh"), &b[..b.len() - 100]).unwrap();
    let o = run("sc-export", &["cut.scmesh", "-o", "cut.vtu"], dir.path());
    assert_fails(&o, 2, &["cut.scmesh", "truncated"], &dir.path().join("cut.vtu"));
}

#[test]
fn newer_major_version_scmesh_export() {
    let dir = tempdir();
    let o = run("sc-import", &[repo().join("meshes/parisch.msh").to_str().unwrap(), "-o", "m.scmesh"], dir.path());
    assert!(o.status.success());
    let mut b = std::fs::read(dir.path().join("m.scmesh")).unwrap();
    b[21] = b'9'; // "splinecontact scmesh 1.0" -> "... 9.0"
    std::fs::write(dir.path().join("new.scmesh"), &b).unwrap();
    let o = run("sc-export", &["new.scmesh", "-o", "new.vtu"], dir.path());
    assert_fails(&o, 2, &["new.scmesh", "version 9.0", "reads scmesh 1.x"], &dir.path().join("new.vtu"));
}

fn pipeline_fails(yaml: &str, needles: &[&str]) {
    let dir = tempdir();
    std::fs::write(dir.path().join("p.yaml"), yaml).unwrap();
    let o = run("sc-pipeline", &["p.yaml"], dir.path());
    assert_fails(&o, 2, needles, Path::new(&dir.path().join("out.scmesh")));
}

#[test]
fn pipeline_unknown_key() {
    pipeline_fails("version: 1\nstages:\n  - import:\n      input: a.msh\n      outptu: out.scmesh\n", &["p.yaml", "outptu", "line 5"]);
}

#[test]
fn pipeline_restart_increment_without_restart() {
    pipeline_fails(
        "version: 1\nstages:\n  - solve: {input: m.scmesh, output: out.scmesh, setup_file: s.yaml, restart_increment: 3}\n",
        &["p.yaml: solve stage 1: `restart_increment` needs `restart`"],
    );
}

#[test]
fn pipeline_wrong_type() {
    pipeline_fails("version: 1\nstages:\n  - gmsh: {geo: a.geo, output: out.scmesh, binary: 3}\n", &["p.yaml", "line 3"]);
}

/// A contact setup that does not fit the contact model: each mistake is named with
/// the setup file, exit code 2, and no results file is written.
#[test]
fn contact_setup_mistakes() {
    let dir = tempdir();
    std::fs::copy(repo().join("meshes/parisch.msh"), dir.path().join("p.msh")).unwrap();
    assert!(run("sc-import", &["p.msh", "-o", "p.scmesh"], dir.path()).status.success());
    let o = run("sc-tag", &["p.scmesh", "--pair", "contact:upper_bottom:lower_top", "-o", "p.sccontact"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let base = "materials:\n  - {body: upper, model: neo_hookean, E: 1.0e9, nu: 0.3}\n  - {body: lower, model: neo_hookean, E: 1.0e10, nu: 0.3}\nconstraints:\n  - {set: lower_base, fix: [x, y, z]}\n";
    let cases: [(&str, &str, &[&str]); 12] = [
        ("contact:\n  - {pair: contact, eps_n: 0.0}\n", "p.sccontact", &["bad.yaml", "eps_n must be a positive number, found 0"]),
        ("contact:\n  - {pair: contact, eps_n: 1.0e5, mu: -0.2, eps_t: 1.0}\n", "p.sccontact", &["bad.yaml", "mu must be zero or positive"]),
        ("contact:\n  - {pair: contact, eps_n: 1.0e5, stabilization: -0.1}\n", "p.sccontact", &["bad.yaml", "contact pair 'contact'", "stabilization must be zero or positive, found -0.1"]),
        ("contact:\n  - {pair: contact, eps_n: 1.0e5, uzawa_relaxation: 2.0}\n", "p.sccontact", &["bad.yaml", "contact pair 'contact'", "uzawa_relaxation must lie in [1, 2)", "found 2"]),
        ("contact:\n  - {pair: contact, eps_n: 1.0e5, mu: 0.2, eps_t: 0.0}\n", "p.sccontact", &["bad.yaml", "eps_t must be a positive number"]),
        ("contact:\n  - {pair: contact, eps_n: 1.0e5, mu: 0.2, eps_t: 1.0}\nlinear_solver: cholesky\n", "p.sccontact", &["cholesky needs a symmetric tangent", "friction", "use auto or lu"]),
        ("contact:\n  - {pair: contact, eps_n: 1.0e5}\nloads:\n  - {set: load_node, force: [0, 0, -1], curve: ramp2}\n", "p.sccontact", &["bad.yaml", "load 1 uses curve 'ramp2', which `curves` does not define (it has: none)"]),
        ("", "p.sccontact", &["bad.yaml", "contact pair 'contact' has no entry under `contact` (give at least `- {pair: contact}`)"]),
        ("contact:\n  - {pair: contakt, eps_n: 1.0e5}\n", "p.sccontact", &["bad.yaml", "contact pair 'contakt' does not exist", "contact"]),
        ("contact:\n  - {pair: contact, eps_n: -1.0}\n", "p.sccontact", &["bad.yaml", "eps_n must be a positive number"]),
        ("contact:\n  - {pair: contact, eps_n: 1.0e5, penetration_tolerance: 1.0e-3, penetration_tolerance_relative: 1.0e-3}\n", "p.sccontact", &["bad.yaml", "not both"]),
        ("contact:\n  - {pair: contact, eps_n: 1.0e5}\n", "p.scmesh", &["bad.yaml", "the input has no contact pairs", ".sccontact"]),
    ];
    for (contact, input, needles) in cases {
        std::fs::write(dir.path().join("bad.yaml"), format!("{base}{contact}")).unwrap();
        let o = run("sc-solve", &[input, "--setup", "bad.yaml", "-o", "r.scres"], dir.path());
        assert_fails(&o, 2, needles, &dir.path().join("r.scres"));
    }
}
