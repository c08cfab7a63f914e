//! Tests of the whole reader on tiny meshes written in all four encodings
//! (2.2/4.1 × ASCII/binary) by a small writer below, and on gmsh's own output
//! in `tests/data/msh/`.

use super::*;
use crate::mesh::HexFace;

/// One element of a test model: MSH 2.2 takes `physical` as its first tag, MSH
/// 4.1 takes it from the entity `(dim of type, entity)`.
#[derive(Clone)]
struct El {
    tag: u64,
    ty: i32,
    physical: i32,
    entity: i32,
    nodes: Vec<u64>,
}

#[derive(Clone)]
struct Model {
    names: Vec<(u8, i32, &'static str)>,
    nodes: Vec<(u64, [f64; 3])>,
    elements: Vec<El>,
    /// Extra physical tags of MSH 4.1 entities: (dim, entity, physical).
    extra_physicals: Vec<(u8, i32, i32)>,
}

fn el(tag: u64, ty: i32, physical: i32, entity: i32, nodes: &[u64]) -> El {
    El { tag, ty, physical, entity, nodes: nodes.to_vec() }
}

fn dim_of(ty: i32) -> u8 {
    types::element_type(ty).map(|t| t.dim).unwrap_or(3)
}

fn push_names(out: &mut Vec<u8>, m: &Model) {
    if m.names.is_empty() {
        return;
    }
    out.extend_from_slice(format!("$PhysicalNames\n{}\n", m.names.len()).as_bytes());
    for (d, t, n) in &m.names {
        out.extend_from_slice(format!("{d} {t} \"{n}\"\n").as_bytes());
    }
    out.extend_from_slice(b"$EndPhysicalNames\n");
}

impl Model {
    fn v2_ascii(&self) -> Vec<u8> {
        let mut o = b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n".to_vec();
        push_names(&mut o, self);
        o.extend_from_slice(format!("$Nodes\n{}\n", self.nodes.len()).as_bytes());
        for (t, x) in &self.nodes {
            o.extend_from_slice(format!("{t} {:?} {:?} {:?}\n", x[0], x[1], x[2]).as_bytes());
        }
        o.extend_from_slice(format!("$EndNodes\n$Elements\n{}\n", self.elements.len()).as_bytes());
        for e in &self.elements {
            let nodes: Vec<String> = e.nodes.iter().map(|n| n.to_string()).collect();
            o.extend_from_slice(format!("{} {} 2 {} {} {}\n", e.tag, e.ty, e.physical, e.entity, nodes.join(" ")).as_bytes());
        }
        o.extend_from_slice(b"$EndElements\n");
        o
    }

    fn v2_binary(&self) -> Vec<u8> {
        let mut o = b"$MeshFormat\n2.2 1 8\n".to_vec();
        o.extend_from_slice(&1i32.to_le_bytes());
        o.extend_from_slice(b"\n$EndMeshFormat\n");
        push_names(&mut o, self);
        o.extend_from_slice(format!("$Nodes\n{}\n", self.nodes.len()).as_bytes());
        for (t, x) in &self.nodes {
            o.extend_from_slice(&(*t as i32).to_le_bytes());
            x.iter().for_each(|v| o.extend_from_slice(&v.to_le_bytes()));
        }
        o.extend_from_slice(format!("\n$EndNodes\n$Elements\n{}\n", self.elements.len()).as_bytes());
        // One block per element: legal, and exercises the block loop.
        for e in &self.elements {
            for v in [e.ty, 1, 2, e.tag as i32, e.physical, e.entity] {
                o.extend_from_slice(&v.to_le_bytes());
            }
            e.nodes.iter().for_each(|&n| o.extend_from_slice(&(n as i32).to_le_bytes()));
        }
        o.extend_from_slice(b"\n$EndElements\n");
        o
    }

    /// Entities (dim, tag) → physical tags, in first-use order.
    fn entities(&self) -> Vec<(u8, i32, Vec<i32>)> {
        let mut out: Vec<(u8, i32, Vec<i32>)> = Vec::new();
        for e in &self.elements {
            let d = dim_of(e.ty);
            match out.iter_mut().find(|x| x.0 == d && x.1 == e.entity) {
                Some(x) => {
                    if e.physical != 0 && !x.2.contains(&e.physical) {
                        x.2.push(e.physical)
                    }
                }
                None => out.push((d, e.entity, if e.physical != 0 { vec![e.physical] } else { vec![] })),
            }
        }
        for &(d, entity, p) in &self.extra_physicals {
            if let Some(x) = out.iter_mut().find(|x| x.0 == d && x.1 == entity) {
                x.2.push(p);
            }
        }
        out
    }

    /// Element blocks (dim, entity, type, elements) in first-use order.
    fn blocks(&self) -> Vec<(u8, i32, i32, Vec<&El>)> {
        let mut out: Vec<(u8, i32, i32, Vec<&El>)> = Vec::new();
        for e in &self.elements {
            let d = dim_of(e.ty);
            match out.iter_mut().find(|b| b.0 == d && b.1 == e.entity && b.2 == e.ty) {
                Some(b) => b.3.push(e),
                None => out.push((d, e.entity, e.ty, vec![e])),
            }
        }
        out
    }

    fn v4_ascii(&self) -> Vec<u8> {
        let mut o = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n".to_vec();
        push_names(&mut o, self);
        let ents = self.entities();
        let count = |d: u8| ents.iter().filter(|e| e.0 == d).count();
        o.extend_from_slice(format!("$Entities\n{} {} {} {}\n", count(0), count(1), count(2), count(3)).as_bytes());
        for d in 0..4u8 {
            for (_, tag, phys) in ents.iter().filter(|e| e.0 == d) {
                let bbox = if d == 0 { "0 0 0" } else { "0 0 0 1 1 1" };
                let p: Vec<String> = phys.iter().map(|p| p.to_string()).collect();
                let bound = if d == 0 { "" } else { " 0" };
                o.extend_from_slice(format!("{tag} {bbox} {} {}{bound}\n", phys.len(), p.join(" ")).as_bytes());
            }
        }
        o.extend_from_slice(b"$EndEntities\n");
        let n = self.nodes.len();
        o.extend_from_slice(format!("$Nodes\n1 {n} 1 {n}\n3 1 0 {n}\n").as_bytes());
        for (t, _) in &self.nodes {
            o.extend_from_slice(format!("{t}\n").as_bytes());
        }
        for (_, x) in &self.nodes {
            o.extend_from_slice(format!("{:?} {:?} {:?}\n", x[0], x[1], x[2]).as_bytes());
        }
        let blocks = self.blocks();
        o.extend_from_slice(format!("$EndNodes\n$Elements\n{} {} 1 {}\n", blocks.len(), self.elements.len(), self.elements.len()).as_bytes());
        for (d, ent, ty, els) in &blocks {
            o.extend_from_slice(format!("{d} {ent} {ty} {}\n", els.len()).as_bytes());
            for e in els {
                let nodes: Vec<String> = e.nodes.iter().map(|n| n.to_string()).collect();
                o.extend_from_slice(format!("{} {}\n", e.tag, nodes.join(" ")).as_bytes());
            }
        }
        o.extend_from_slice(b"$EndElements\n");
        o
    }

    fn v4_binary(&self) -> Vec<u8> {
        let mut o = b"$MeshFormat\n4.1 1 8\n".to_vec();
        o.extend_from_slice(&1i32.to_le_bytes());
        o.extend_from_slice(b"\n$EndMeshFormat\n");
        push_names(&mut o, self);
        let i = |o: &mut Vec<u8>, v: i32| o.extend_from_slice(&v.to_le_bytes());
        let z = |o: &mut Vec<u8>, v: u64| o.extend_from_slice(&v.to_le_bytes());
        let f = |o: &mut Vec<u8>, v: f64| o.extend_from_slice(&v.to_le_bytes());
        let ents = self.entities();
        o.extend_from_slice(b"$Entities\n");
        for d in 0..4u8 {
            z(&mut o, ents.iter().filter(|e| e.0 == d).count() as u64);
        }
        for d in 0..4u8 {
            for (_, tag, phys) in ents.iter().filter(|e| e.0 == d) {
                i(&mut o, *tag);
                for _ in 0..if d == 0 { 3 } else { 6 } {
                    f(&mut o, 0.5);
                }
                z(&mut o, phys.len() as u64);
                phys.iter().for_each(|&p| i(&mut o, p));
                if d > 0 {
                    z(&mut o, 1);
                    i(&mut o, -1);
                }
            }
        }
        o.extend_from_slice(b"\n$EndEntities\n$Nodes\n");
        let n = self.nodes.len() as u64;
        [1, n, 1, n].iter().for_each(|&v| z(&mut o, v));
        i(&mut o, 3);
        i(&mut o, 1);
        i(&mut o, 0);
        z(&mut o, n);
        self.nodes.iter().for_each(|(t, _)| z(&mut o, *t));
        self.nodes.iter().for_each(|(_, x)| x.iter().for_each(|&v| f(&mut o, v)));
        o.extend_from_slice(b"\n$EndNodes\n$Elements\n");
        let blocks = self.blocks();
        let ne = self.elements.len() as u64;
        [blocks.len() as u64, ne, 1, ne].iter().for_each(|&v| z(&mut o, v));
        for (d, ent, ty, els) in &blocks {
            i(&mut o, i32::from(*d));
            i(&mut o, *ent);
            i(&mut o, *ty);
            z(&mut o, els.len() as u64);
            for e in els {
                z(&mut o, e.tag);
                e.nodes.iter().for_each(|&v| z(&mut o, v));
            }
        }
        o.extend_from_slice(b"\n$EndElements\n");
        o
    }

    fn all(&self) -> [(&'static str, Vec<u8>); 4] {
        [
            ("2.2 ASCII", self.v2_ascii()),
            ("2.2 binary", self.v2_binary()),
            ("4.1 ASCII", self.v4_ascii()),
            ("4.1 binary", self.v4_binary()),
        ]
    }
}

/// Two unit hexahedra side by side along x, with named volumes `left` and
/// `right`, the physical surface `top` (two quads at z = 1) and the physical
/// point `corner` (node 1).
fn two_hexes() -> Model {
    Model {
        names: vec![(3, 1, "left"), (3, 2, "right"), (2, 3, "top"), (0, 4, "corner")],
        nodes: vec![
            (1, [0., 0., 0.]),
            (2, [1., 0., 0.]),
            (3, [1., 1., 0.]),
            (4, [0., 1., 0.]),
            (5, [0., 0., 1.]),
            (6, [1., 0., 1.]),
            (7, [1., 1., 1.]),
            (8, [0., 1., 1.]),
            (9, [2., 0., 0.]),
            (10, [2., 1., 0.]),
            (11, [2., 0., 1.]),
            (12, [2., 1., 1.]),
        ],
        elements: vec![
            el(30, 15, 4, 1, &[1]),
            el(20, 3, 3, 5, &[5, 6, 7, 8]),
            el(21, 3, 3, 5, &[6, 11, 12, 7]),
            el(1, 5, 1, 1, &[1, 2, 3, 4, 5, 6, 7, 8]),
            el(2, 5, 2, 2, &[2, 9, 10, 3, 6, 11, 12, 7]),
        ],
        extra_physicals: Vec::new(),
    }
}

fn parse_ok(bytes: &[u8]) -> (Mesh, ImportReport) {
    match parse_msh("t.msh", bytes) {
        Ok(x) => x,
        Err(e) => panic!("{e}\n{}", String::from_utf8_lossy(bytes)),
    }
}

fn parse_err(bytes: &[u8]) -> String {
    match parse_msh("t.msh", bytes) {
        Ok(_) => panic!("expected an error for\n{}", String::from_utf8_lossy(bytes)),
        Err(e) => e.to_string(),
    }
}

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

// ---- one test per error kind ----

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
    assert!(e.starts_with("t.msh:2: MSH version 3.0 is not supported (supported: 2.2, 4.1)"), "{e}");
    let e = parse_err(b"$MeshFormat\n4 0 8\n$EndMeshFormat\n");
    assert!(e.contains("version 4 is not supported (supported: 2.2, 4.1)"), "{e}");
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

/// Every strict prefix of a valid file is an error, never a panic; so is every
/// single-byte corruption of a binary file (an error or, rarely, a valid mesh).
#[test]
fn prefixes_and_corruptions_never_panic() {
    for (version, bytes) in two_hexes().all() {
        let end = bytes.len() - 1; // the file minus its final newline is still valid
        for n in 0..end {
            if parse_msh("t.msh", &bytes[..n]).is_ok() {
                panic!("{version}: prefix of {n} bytes parsed");
            }
        }
        if version.ends_with("binary") {
            for i in 0..bytes.len() {
                for flip in [0xffu8, 0x80, 0x01] {
                    let mut b = bytes.clone();
                    b[i] ^= flip;
                    let _ = parse_msh("t.msh", &b);
                }
            }
        }
    }
}

// ---- gmsh's own output: tests/data/msh/box2.geo in the four encodings ----

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
