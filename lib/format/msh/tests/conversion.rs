//! What becomes of the file: bodies, node and face sets from the physical groups,
//! mirrored hexahedra reordered, unused nodes dropped, interior quads placed.

use super::*;

#[test]
fn physical_surface_of_quads_gives_hex_faces() {
    let mut m = two_hexes();
    // A side quad written against the outward normal of its hexahedron: still the
    // same face, normal out of the hexahedron (η = -1, local 2).
    m.elements.push(el(22, 3, 6, 7, &[2, 6, 11, 9]));
    m.names.push((2, 6, "front right"));
    for (version, bytes) in m.all() {
        let (mesh, _) = parse_ok(&bytes);
        let top = mesh.face_set("top").unwrap();
        assert_eq!(top.faces, vec![HexFace { element: 0, local: 1 }, HexFace { element: 1, local: 1 }], "{version}");
        assert_eq!(top.quad_tags, vec![20, 21]);
        let front = mesh.face_set("front right").unwrap();
        assert_eq!(front.faces, vec![HexFace { element: 1, local: 2 }]);
        assert_eq!(mesh.face_nodes(front.faces[0]), [1, 8, 10, 5]);
    }
}

#[test]
fn physical_point_gives_a_node_set() {
    for (_, bytes) in two_hexes().all() {
        let (mesh, _) = parse_ok(&bytes);
        let corner = mesh.node_set("corner").unwrap();
        assert_eq!((corner.dim, corner.physical_tag, corner.nodes.as_slice()), (0, 4, &[0u32][..]));
    }
}

#[test]
fn unnamed_groups_and_unnamed_volume() {
    let mut m = two_hexes();
    m.names.retain(|n| n.2 != "top");
    m.elements[4].physical = 0;
    for (version, bytes) in m.all() {
        let (mesh, report) = parse_ok(&bytes);
        assert_eq!(mesh.body_names(), vec!["left", UNNAMED_VOLUME], "{version}");
        assert_eq!(mesh.hex_body, vec![0, 1]);
        assert!(mesh.face_set("physical_2_3").is_some());
        assert!(report.warnings.iter().any(|w| w.contains("no physical volume")), "{:?}", report.warnings);
        // every warning names the file
        assert!(report.warnings.iter().all(|w| w.starts_with("t.msh")), "{:?}", report.warnings);
    }
}

#[test]
fn mirrored_hex_is_reordered_and_reported() {
    let mut m = two_hexes();
    m.elements[4].nodes = vec![6, 11, 12, 7, 2, 9, 10, 3];
    for (version, bytes) in m.all() {
        let (mesh, report) = parse_ok(&bytes);
        assert_eq!(report.flipped_elements, vec![2], "{version}");
        assert!(report.warnings.iter().any(|w| w.contains("reordered")), "{:?}", report.warnings);
        assert_eq!(mesh.hexes[1], [1, 8, 9, 2, 5, 10, 11, 6]);
        // The top quad now matches the reordered hexahedron's top face.
        assert_eq!(mesh.face_set("top").unwrap().faces[1], HexFace { element: 1, local: 1 });
    }
}

#[test]
fn unused_node_is_dropped_and_indices_compacted() {
    let mut m = two_hexes();
    m.nodes.insert(3, (1_000_000, [9., 9., 9.]));
    m.nodes.push((77, [5., 5., 5.]));
    for (version, bytes) in m.all() {
        if version.starts_with("2.2 binary") {
            continue; // int tags: 1_000_000 fits, but keep the sparse map test to 3 encodings
        }
        let (mesh, report) = parse_ok(&bytes);
        assert_eq!(report.dropped_nodes, vec![1_000_000, 77], "{version}");
        assert_eq!(mesh.nodes.len(), 12);
        assert_eq!(mesh.node_tags, (1..=12).collect::<Vec<u64>>());
        assert_eq!(mesh.hexes[0], [0, 1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(mesh.nodes[3], [0., 1., 0.]);
    }
}

#[test]
fn node_set_members_without_a_hex_are_left_out() {
    let mut m = two_hexes();
    m.nodes.push((50, [7., 7., 7.]));
    m.elements[0].nodes = vec![50];
    let (mesh, report) = parse_ok(&m.v4_ascii());
    assert!(mesh.node_set("corner").unwrap().nodes.is_empty());
    assert_eq!(report.dropped_nodes, vec![50]);
    assert!(report.warnings.iter().any(|w| w.contains("node set `corner`: 1 of its nodes")), "{:?}", report.warnings);
}

#[test]
fn interior_quad_goes_to_the_hex_its_normal_leaves() {
    let mut m = two_hexes();
    // The shared face x = 1, ordered with the normal along +x: out of hex 1 (local 3).
    m.elements.push(el(23, 3, 8, 9, &[2, 3, 7, 6]));
    m.names.push((2, 8, "interface"));
    // Reversed: out of hex 2 (local 5).
    m.elements.push(el(24, 3, 10, 11, &[2, 6, 7, 3]));
    m.names.push((2, 10, "interface reversed"));
    for (version, bytes) in m.all() {
        let (mesh, report) = parse_ok(&bytes);
        assert_eq!(mesh.face_set("interface").unwrap().faces, vec![HexFace { element: 0, local: 3 }], "{version}");
        assert_eq!(mesh.face_set("interface reversed").unwrap().faces, vec![HexFace { element: 1, local: 5 }]);
        assert!(report.warnings.iter().any(|w| w.contains("`interface`: 1 quads are interior faces")), "{:?}", report.warnings);
    }
}

#[test]
fn hex_in_two_physical_volumes_goes_to_the_first() {
    // MSH 2.2 repeats the element once per physical group; MSH 4.1 lists two
    // physical tags on its entity.
    let mut m = two_hexes();
    m.names.push((3, 9, "also left"));
    let mut v2 = m.clone();
    let mut copy = v2.elements[3].clone();
    copy.physical = 9;
    copy.tag = 3;
    v2.elements.push(copy);
    let mut v4 = m.clone();
    v4.extra_physicals.push((3, 1, 9));
    for (version, bytes, warning) in [
        ("2.2 ASCII", v2.v2_ascii(), "repeat an earlier one"),
        ("2.2 binary", v2.v2_binary(), "repeat an earlier one"),
        ("4.1 ASCII", v4.v4_ascii(), "several physical volumes"),
        ("4.1 binary", v4.v4_binary(), "several physical volumes"),
    ] {
        let (mesh, report) = parse_ok(&bytes);
        assert_eq!(mesh.hexes.len(), 2, "{version}");
        assert_eq!(mesh.element_tags, vec![1, 2]);
        assert_eq!(mesh.body_names(), vec!["left", "right"]);
        assert_eq!(mesh.node_set("also left").unwrap().nodes, vec![0, 1, 2, 3, 4, 5, 6, 7]);
        assert!(report.warnings.iter().any(|w| w.contains(warning)), "{version}: {:?}", report.warnings);
    }
}
