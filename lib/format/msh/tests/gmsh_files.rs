//! gmsh's own output: `tests/data/msh/box2.geo` in the four encodings, and a
//! timing on a large file.

use super::*;

fn fixture(name: &str) -> Vec<u8> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/msh").join(name);
    match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) => panic!("{}: {e}", path.display()),
    }
}

fn outward_normal(mesh: &Mesh, f: HexFace) -> [f64; 3] {
    let x = mesh.face_nodes(f).map(|n| mesh.nodes[n as usize]);
    let a = [x[2][0] - x[0][0], x[2][1] - x[0][1], x[2][2] - x[0][2]];
    let b = [x[3][0] - x[1][0], x[3][1] - x[1][1], x[3][2] - x[1][2]];
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[test]
fn gmsh_box_is_the_same_mesh_in_all_four_encodings() {
    let files = [
        ("box2_v22_ascii.msh", "2.2 ASCII"),
        ("box2_v22_binary.msh", "2.2 binary"),
        ("box2_v41_ascii.msh", "4.1 ASCII"),
        ("box2_v41_binary.msh", "4.1 binary"),
    ];
    let mut meshes = Vec::new();
    for (file, version) in files {
        let (mesh, report) = match parse_msh(file, &fixture(file)) {
            Ok(x) => x,
            Err(e) => panic!("{e}"),
        };
        assert_eq!(report.version, version);
        assert!(report.dropped_nodes.is_empty() && report.flipped_elements.is_empty(), "{file}: {report:?}");
        assert!(report.warnings.is_empty(), "{file}: {:?}", report.warnings);
        assert_eq!((mesh.nodes.len(), mesh.hexes.len()), (27, 8), "{file}");
        assert_eq!(mesh.body_names(), vec!["block"]);
        assert_eq!(mesh.node_set_names(), vec!["origin", "edge", "base", "top", "block"]);
        assert_eq!(mesh.node_set("origin").unwrap().nodes.len(), 1);
        assert_eq!(mesh.nodes[mesh.node_set("origin").unwrap().nodes[0] as usize], [0.0, 0.0, 0.0]);
        assert_eq!(mesh.node_set("edge").unwrap().nodes.len(), 3);
        assert_eq!(mesh.node_set("base").unwrap().nodes.len(), 9);
        assert_eq!(mesh.node_set("block").unwrap().nodes.len(), 27);
        for (name, sign) in [("base", -1.0), ("top", 1.0)] {
            let set = mesh.face_set(name).unwrap();
            assert_eq!(set.faces.len(), 4, "{file} {name}");
            for &f in &set.faces {
                let n = outward_normal(&mesh, f);
                assert!(n[2] * sign > 0.0 && n[0] == 0.0 && n[1] == 0.0, "{file} {name}: {n:?}");
            }
        }
        for e in 0..mesh.hexes.len() {
            let j = crate::mesh::topology::corner_jacobians(&mesh.hex_coords(e));
            assert!(j.iter().all(|&v| v > 0.0));
        }
        meshes.push(mesh);
    }
    // gmsh writes ASCII coordinates with `%.16g`, which does not round-trip every
    // double: an ASCII coordinate is the binary one rounded to 16 significant
    // digits, and we must read exactly that value.
    let (ascii, binary) = (&meshes[0], &meshes[1]);
    for (a, b) in ascii.nodes.iter().zip(&binary.nodes) {
        for k in 0..3 {
            let printed: f64 = format!("{:.15e}", b[k]).parse().unwrap();
            assert_eq!(a[k].to_bits(), printed.to_bits(), "{} vs {}", a[k], b[k]);
        }
    }
    // Otherwise identical: connectivity, tags, sets; binary coordinates bit for bit.
    let mut ascii_with_binary_coordinates = ascii.clone();
    ascii_with_binary_coordinates.nodes = binary.nodes.clone();
    assert_eq!(&ascii_with_binary_coordinates, binary);
    assert_eq!(&meshes[2], ascii, "4.1 ASCII differs from 2.2 ASCII");
    assert_eq!(&meshes[3], binary, "4.1 binary differs from 2.2 binary");
    let bits = |m: &Mesh| m.nodes.iter().flat_map(|x| x.map(f64::to_bits)).collect::<Vec<u64>>();
    assert_eq!(bits(&meshes[3]), bits(binary));
    assert_eq!(bits(&meshes[2]), bits(ascii));
}

#[test]
fn gmsh_box_prefixes_never_panic() {
    for file in ["box2_v22_binary.msh", "box2_v41_binary.msh", "box2_v41_ascii.msh"] {
        let b = fixture(file);
        for n in 0..b.len() - 1 {
            assert!(parse_msh(file, &b[..n]).is_err(), "{file}: prefix {n}");
        }
    }
}

/// Timing on a large file: `SC_MSH_BENCH=big.msh cargo test --release --lib msh_bench -- --ignored --nocapture`.
#[test]
#[ignore]
fn msh_bench() {
    let Some(path) = std::env::var_os("SC_MSH_BENCH") else {
        return;
    };
    let bytes = std::fs::read(&path).unwrap();
    let t = std::time::Instant::now();
    let (mesh, report) = parse_msh("bench.msh", &bytes).unwrap();
    println!(
        "{}: {} nodes, {} hexes, {} face sets, {:?} ({}), warnings {:?}",
        path.to_string_lossy(),
        mesh.nodes.len(),
        mesh.hexes.len(),
        mesh.face_sets.len(),
        t.elapsed(),
        report.version,
        report.warnings
    );
}
