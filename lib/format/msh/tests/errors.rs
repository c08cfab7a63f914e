//! One test per error kind, each on a tiny file: the message names the place and
//! the fault.

use super::*;

#[test]
fn twisted_hex_is_refused() {
    let mut m = two_hexes();
    // Swap two top nodes: the top face is crossed, Jacobians change sign.
    m.elements[3].nodes = vec![1, 2, 3, 4, 6, 5, 7, 8];
    let e = parse_err(&m.v2_ascii());
    assert!(e.starts_with("t.msh:31: element 1 is a twisted or degenerate hexahedron: its corner Jacobians [1.0, 1.0, 1.0, 1.0, -1.0, -1.0, 1.0, 1.0]"), "{e}");
    assert!(e.contains("twisted ones cannot be"), "{e}");
    let e = parse_err(&m.v4_binary());
    assert!(e.starts_with("t.msh: byte ") && e.contains("element 1 is a twisted"), "{e}");
}

#[test]
fn tetrahedra_are_refused_with_type_and_count() {
    let mut m = two_hexes();
    m.elements.push(el(40, 4, 1, 1, &[1, 2, 3, 5]));
    m.elements.push(el(41, 4, 1, 1, &[2, 3, 4, 6]));
    m.elements.push(el(42, 6, 1, 1, &[1, 2, 3, 5, 6, 7]));
    let e = parse_err(&m.v2_ascii());
    assert_eq!(
        e,
        "t.msh:33: the mesh holds 2 4-node tetrahedron elements (gmsh type 4), and also 1 6-node prism (gmsh type 6); \
         only 8-node hexahedra (gmsh type 5) are supported"
    );
    let e = parse_err(&m.v4_binary());
    assert!(e.starts_with("t.msh: byte ") && e.contains("2 4-node tetrahedron elements (gmsh type 4)"), "{e}");
}

#[test]
fn no_hexahedra_is_an_error() {
    let mut m = two_hexes();
    m.elements.truncate(3);
    let e = parse_err(&m.v4_ascii());
    assert!(e.starts_with("t.msh: the mesh holds no 8-node hexahedra (gmsh type 5)"), "{e}");
}

#[test]
fn error_truncated_file() {
    let b = two_hexes().v2_ascii();
    let cut = b.windows(9).position(|w| w == b"$EndNodes").unwrap();
    let e = parse_err(&b[..cut]);
    assert_eq!(e, "t.msh:24: expected `$EndNodes` before end of file");
    let b = two_hexes().v4_binary();
    let cut = b.windows(9).position(|w| w == b"$EndNodes").unwrap();
    let e = parse_err(&b[..cut - 5]);
    assert!(e.starts_with("t.msh: byte ") && e.ends_with("expected `$EndNodes` before end of file"), "{e}");
}

#[test]
fn error_random_bytes() {
    let b: Vec<u8> = (0..200u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8).collect();
    let e = parse_err(&b);
    assert!(e.starts_with("t.msh: not a gmsh MSH file: no $MeshFormat header"), "{e}");
}

#[test]
fn error_unsupported_version() {
    let e = parse_err(b"$MeshFormat\n3.0 0 8\n$EndMeshFormat\n");
    assert!(e.starts_with("t.msh:2: MSH version `3.0` is not supported (supported: 2.2, 4.1)"), "{e}");
    let e = parse_err(b"$MeshFormat\n4 0 8\n$EndMeshFormat\n");
    assert!(e.contains("version `4` is not supported (supported: 2.2, 4.1)"), "{e}");
}

#[test]
fn error_count_disagrees_with_data() {
    let text = String::from_utf8(two_hexes().v2_ascii()).unwrap();
    // More announced than present.
    let e = parse_err(text.replace("$Nodes\n12\n", "$Nodes\n13\n").as_bytes());
    assert_eq!(
        e,
        "t.msh:25: found `$EndNodes` where a node tag was expected: the section holds fewer entries than its counts say"
    );
    // Fewer announced than present.
    let e = parse_err(text.replace("$Nodes\n12\n", "$Nodes\n11\n").as_bytes());
    assert_eq!(e, "t.msh:24: expected `$EndNodes`, found `12`: the section holds more data than its counts say");
    // 4.1: header total against the blocks.
    let text = String::from_utf8(two_hexes().v4_ascii()).unwrap();
    let e = parse_err(text.replace("$Elements\n4 5 1 5\n", "$Elements\n4 6 1 5\n").as_bytes());
    assert!(e.ends_with("the $Elements header announces 6 elements, its 4 blocks hold 5"), "{e}");
}

#[test]
fn error_unknown_node_tag() {
    let mut m = two_hexes();
    m.elements[4].nodes[7] = 99;
    let e = parse_err(&m.v2_ascii());
    assert_eq!(e, "t.msh:32: element 2 refers to node 99, which is not in $Nodes");
    let e = parse_err(&m.v2_binary());
    assert!(e.starts_with("t.msh: byte ") && e.ends_with("element 2 refers to node 99, which is not in $Nodes"), "{e}");
}

#[test]
fn error_bad_number() {
    let text = String::from_utf8(two_hexes().v2_ascii()).unwrap();
    let e = parse_err(text.replace("\n7 1.0 1.0 1.0\n", "\n7 1.0 1,0 1.0\n").as_bytes());
    assert_eq!(e, "t.msh:19: bad number `1,0` (expected a node coordinate)");
    let e = parse_err(text.replace("\n2 5 2 2 2 ", "\n2 5x 2 2 2 ").as_bytes());
    assert_eq!(e, "t.msh:32: bad number `5x` (expected an element type)");
}

#[test]
fn error_quad_not_on_a_hex() {
    let mut m = two_hexes();
    m.elements[2].nodes = vec![6, 11, 12, 8];
    let e = parse_err(&m.v2_ascii());
    assert_eq!(e, "t.msh:30: quad 21 of physical surface `top` is not a face of any hexahedron");
}

#[test]
fn error_triangle_in_a_face_set() {
    let mut m = two_hexes();
    m.elements.insert(2, el(25, 2, 3, 5, &[5, 6, 7]));
    let e = parse_err(&m.v4_ascii());
    assert!(
        e.ends_with("physical surface `top` holds element 25, a 3-node triangle (gmsh type 2): face sets must be 4-node quads (gmsh type 3) that are faces of the hexahedra"),
        "{e}"
    );
}

#[test]
fn error_duplicate_group_name() {
    let mut m = two_hexes();
    m.names[2].2 = "left";
    let e = parse_err(&m.v2_ascii());
    assert_eq!(
        e,
        "t.msh:6: physical name `left` is given to two groups, physical surface 3 and physical volume 1: names must be unique across dimensions"
    );
}

#[test]
fn error_unknown_element_type() {
    let text = String::from_utf8(two_hexes().v2_ascii()).unwrap();
    let e = parse_err(text.replace("\n30 15 ", "\n30 76 ").as_bytes());
    assert!(e.starts_with("t.msh:28: unknown gmsh element type 76"), "{e}");
}

#[test]
fn error_missing_sections() {
    let e = parse_err(b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Comments\nhello\n$EndComments\n");
    assert_eq!(e, "t.msh: no $Nodes section");
    let e = parse_err(b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Elements\n0\n$EndElements\n");
    assert_eq!(e, "t.msh:4: $Elements section before the $Nodes section");
}
