//! One mesh in every encoding: the same nodes, elements and names, coordinates
//! bit for bit, big-endian binary, skipped sections.

use super::*;

#[test]
fn two_hexes_with_physical_names_in_all_encodings() {
    let m = two_hexes();
    let mut first: Option<Mesh> = None;
    for (version, bytes) in m.all() {
        let (mesh, report) = parse_ok(&bytes);
        assert_eq!(report.version, version);
        assert!(report.dropped_nodes.is_empty() && report.flipped_elements.is_empty());
        assert!(report.warnings.is_empty(), "{version}: {:?}", report.warnings);
        assert_eq!(mesh.nodes.len(), 12);
        assert_eq!(mesh.hexes, vec![[0, 1, 2, 3, 4, 5, 6, 7], [1, 8, 9, 2, 5, 10, 11, 6]]);
        assert_eq!(mesh.element_tags, vec![1, 2]);
        assert_eq!(mesh.node_tags, (1..=12).collect::<Vec<u64>>());
        assert_eq!(mesh.body_names(), vec!["left", "right"]);
        assert_eq!(mesh.bodies[1].physical_tag, 2);
        assert_eq!(mesh.hex_body, vec![0, 1]);
        assert_eq!(mesh.node_set_names(), vec!["corner", "top", "left", "right"]);
        let right = mesh.node_set("right").unwrap();
        assert_eq!((right.dim, right.physical_tag), (3, 2));
        assert_eq!(right.nodes, vec![1, 2, 5, 6, 8, 9, 10, 11]);
        assert_eq!(mesh.node_set("top").unwrap().nodes, vec![4, 5, 6, 7, 10, 11]);
        match &first {
            None => first = Some(mesh),
            Some(f) => assert_eq!(f, &mesh, "{version}"),
        }
    }
}

#[test]
fn coordinates_are_bit_exact() {
    let mut m = two_hexes();
    m.nodes[11].1 = [2.0000000000000004, 0.1 + 0.2, 1.0 + 1e-15];
    for (version, bytes) in m.all() {
        let (mesh, _) = parse_ok(&bytes);
        let x = mesh.nodes[11];
        assert_eq!(x.map(f64::to_bits), m.nodes[11].1.map(f64::to_bits), "{version}");
    }
}

#[test]
fn other_sections_are_skipped() {
    let mut b = two_hexes().v4_ascii();
    b.extend_from_slice(b"$NodeData\n1\n\"u\"\n1\n0.0\n3\n0\n1\n1\n1 0.5\n$EndNodeData\n$Custom\n$EndNodeData\n$EndCustom\n");
    let (mesh, report) = parse_ok(&b);
    assert_eq!(mesh.hexes.len(), 2);
    assert_eq!(report.warnings.len(), 1, "{:?}", report.warnings);
    assert!(report.warnings[0].contains("skipped unknown section `$Custom`"));
}

#[test]
fn big_endian_binary() {
    // Swap every binary number of a tiny 2.2 file written big-endian by hand.
    let m = two_hexes();
    let mut o = b"$MeshFormat\n2.2 1 8\n".to_vec();
    o.extend_from_slice(&1i32.to_be_bytes());
    o.extend_from_slice(b"\n$EndMeshFormat\n");
    o.extend_from_slice(format!("$Nodes\n{}\n", m.nodes.len()).as_bytes());
    for (t, x) in &m.nodes {
        o.extend_from_slice(&(*t as i32).to_be_bytes());
        x.iter().for_each(|v| o.extend_from_slice(&v.to_be_bytes()));
    }
    o.extend_from_slice(b"\n$EndNodes\n$Elements\n2\n");
    for v in [5, 2, 2] {
        o.extend_from_slice(&i32::to_be_bytes(v));
    }
    for e in &m.elements[3..] {
        for v in [e.tag as i32, e.physical, e.entity].into_iter().chain(e.nodes.iter().map(|&n| n as i32)) {
            o.extend_from_slice(&v.to_be_bytes());
        }
    }
    o.extend_from_slice(b"\n$EndElements\n");
    let (mesh, _) = parse_ok(&o);
    let (reference, _) = parse_ok(&m.v2_ascii());
    assert_eq!(mesh.nodes, reference.nodes);
    assert_eq!(mesh.hexes, reference.hexes);
}
