//! The master control net: a master face set ordered into a structured a × b grid
//! of node ids, the control points P_{i,j} of the B-spline patch (paper sec. 5,
//! eq. 5.2), stored `i + a·j` like [`crate::spline`].
//!
//! ## Algorithm
//! 1. All faces must lie in one body (a patch follows one body's surface).
//! 2. Every face edge (unordered node pair) is mapped to the faces that use it. An
//!    edge in more than 2 faces is a **branch** (the set is not a surface).
//! 3. Edges in exactly one face are the boundary. Each boundary node must have
//!    exactly two boundary neighbours; following them gives the boundary loops.
//!    More than one loop is a **hole** (a rectangle has one outline).
//! 4. A topological rectangle has exactly 4 **corners** (boundary nodes in exactly
//!    one face), every other boundary node in exactly 2 faces (a node in 3 faces is a
//!    re-entrant corner, e.g. of an L), and every interior node in exactly 4 faces.
//! 5. From the corner c₀ with the smallest node id, walk both boundary directions
//!    to the next corners: side 1 (direction ξ¹) gives a nodes, side 2 (ξ²) b nodes.
//!    Cell (i, j) is then the face that holds edge (i,j)–(i+1,j) and node (i,j+1);
//!    its fourth node is (i+1,j+1). Rows are filled j = 0, 1, …; every face must be
//!    used exactly once.
//! 6. Orientation: the patch normal n̄ = ā_1 × ā_2 / ‖ā_1 × ā_2‖ (eq. 4.3) must point
//!    out of the master body. [`crate::mesh::Mesh::face_nodes`] lists a face so the
//!    right-hand rule gives its outward normal, so cell (i,j) is outward when its
//!    face's node cycle is (i,j) → (i+1,j) → (i+1,j+1) → (i,j+1). If all cells run
//!    the other way, j is flipped (ā_2 → −ā_2); a mix of both is an inconsistently
//!    oriented face set and refused.

use std::collections::{BTreeMap, HashSet};

use crate::mesh::{HexFace, Mesh};

/// The ordered control net of one master face set.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ControlNet {
    /// Control points along ξ¹ (a) and ξ² (b).
    pub a: usize,
    pub b: usize,
    /// Node indices, `nodes[i + a*j]`.
    pub nodes: Vec<u32>,
}

impl ControlNet {
    /// The node at grid position (i, j).
    pub fn at(&self, i: usize, j: usize) -> u32 {
        self.nodes[i + self.a * j]
    }
}

/// Why a face set cannot be a B-spline control net. Faces are named by their gmsh
/// quad tag and the hexahedron (gmsh element tag) they bound.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NetError {
    #[error("face set '{set}' does not exist (face sets: {known})")]
    UnknownFaceSet { set: String, known: String },
    #[error("face set '{set}' is empty")]
    Empty { set: String },
    #[error("face set '{set}' spans two bodies: {face_a} is in body '{body_a}', {face_b} in body '{body_b}' (one B-spline patch follows one body)")]
    SpansTwoBodies { set: String, body_a: String, face_a: String, body_b: String, face_b: String },
    #[error("face set '{set}' branches: the edge between nodes {n0} and {n1} (gmsh tags) is shared by {count} faces: {faces} (a surface edge bounds at most 2 faces)")]
    Branch { set: String, n0: u64, n1: u64, count: usize, faces: String },
    #[error("face set '{set}' has a hole: its boundary is {loops} closed loops, not one (a rectangular patch has a single outline)")]
    Hole { set: String, loops: usize },
    #[error("face set '{set}' has a non-rectangular outline: {what}")]
    NonRectangular { set: String, what: String },
    #[error("face set '{set}' is not a regular grid: interior node {node} (gmsh tag) is in {count} faces, a structured grid has 4 ({faces})")]
    IrregularInterior { set: String, node: u64, count: usize, faces: String },
    #[error("face set '{set}' is not a structured grid: {what}")]
    NotAGrid { set: String, what: String },
    #[error("face set '{set}' is inconsistently oriented: {face} faces the other way from {other}")]
    Orientation { set: String, face: String, other: String },
}

/// "quad 17 (face 1 of hex 101)".
fn describe(mesh: &Mesh, set: &crate::mesh::FaceSet, k: usize) -> String {
    let f: HexFace = set.faces[k];
    let quad = set.quad_tags.get(k).copied().unwrap_or(0);
    let hex = mesh.element_tags.get(f.element as usize).copied().unwrap_or(f.element as u64 + 1);
    format!("quad {quad} (face {} of hex {hex})", f.local)
}

fn describe_all(mesh: &Mesh, set: &crate::mesh::FaceSet, ks: &[usize]) -> String {
    ks.iter().map(|&k| describe(mesh, set, k)).collect::<Vec<_>>().join(", ")
}

fn edge(u: u32, v: u32) -> (u32, u32) {
    (u.min(v), u.max(v))
}

/// Order the face set `name` of `mesh` into the control net (see the module docs).
pub fn control_net(mesh: &Mesh, name: &str) -> Result<ControlNet, NetError> {
    let set_name = name.to_string();
    let set = mesh
        .face_set(name)
        .ok_or_else(|| NetError::UnknownFaceSet { set: set_name.clone(), known: mesh.face_set_names().join(", ") })?;
    if set.faces.is_empty() {
        return Err(NetError::Empty { set: set_name });
    }
    let nf = set.faces.len();
    let quads: Vec<[u32; 4]> = set.faces.iter().map(|&f| mesh.face_nodes(f)).collect();
    let tag = |n: u32| mesh.node_tags.get(n as usize).copied().unwrap_or(n as u64 + 1);

    // 1. One body.
    let body_of = |k: usize| mesh.hex_body[set.faces[k].element as usize];
    if let Some(k) = (1..nf).find(|&k| body_of(k) != body_of(0)) {
        let bname = |b: u32| mesh.bodies.get(b as usize).map(|b| b.name.clone()).unwrap_or_else(|| b.to_string());
        return Err(NetError::SpansTwoBodies {
            set: set_name,
            body_a: bname(body_of(0)),
            face_a: describe(mesh, set, 0),
            body_b: bname(body_of(k)),
            face_b: describe(mesh, set, k),
        });
    }

    // 2. Edge → faces; branches.
    let mut edges: BTreeMap<(u32, u32), Vec<usize>> = BTreeMap::new();
    let mut node_faces: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
    for (k, q) in quads.iter().enumerate() {
        for c in 0..4 {
            edges.entry(edge(q[c], q[(c + 1) % 4])).or_default().push(k);
            node_faces.entry(q[c]).or_default().push(k);
        }
    }
    if let Some(((u, v), fs)) = edges.iter().find(|(_, fs)| fs.len() > 2) {
        return Err(NetError::Branch { set: set_name, n0: tag(*u), n1: tag(*v), count: fs.len(), faces: describe_all(mesh, set, fs) });
    }

    // 3. Boundary loops.
    let mut bnd: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for (&(u, v), fs) in &edges {
        if fs.len() == 1 {
            bnd.entry(u).or_default().push(v);
            bnd.entry(v).or_default().push(u);
        }
    }
    if let Some((&n, nb)) = bnd.iter().find(|(_, nb)| nb.len() != 2) {
        return Err(NetError::NonRectangular {
            set: set_name,
            what: format!("boundary node {} is where {} boundary edges meet (faces touching only at a corner: {})", tag(n), nb.len(), describe_all(mesh, set, &node_faces[&n])),
        });
    }
    let mut seen: HashSet<u32> = HashSet::new();
    let mut loops = 0;
    for &start in bnd.keys() {
        if seen.contains(&start) {
            continue;
        }
        loops += 1;
        let (mut prev, mut cur) = (start, start);
        loop {
            seen.insert(cur);
            let nb = &bnd[&cur];
            let next = if nb[0] != prev { nb[0] } else { nb[1] };
            prev = cur;
            cur = next;
            if cur == start {
                break;
            }
        }
    }
    if loops != 1 {
        return Err(NetError::Hole { set: set_name, loops });
    }

    // 4. Corners, re-entrant corners, interior valence.
    let corners: Vec<u32> = bnd.keys().copied().filter(|n| node_faces[n].len() == 1).collect();
    if let Some(n) = bnd.keys().copied().find(|n| node_faces[n].len() > 2) {
        return Err(NetError::NonRectangular {
            set: set_name,
            what: format!("boundary node {} is a re-entrant corner in {} faces ({})", tag(n), node_faces[&n].len(), describe_all(mesh, set, &node_faces[&n])),
        });
    }
    if corners.len() != 4 {
        let list: Vec<String> = corners.iter().map(|&n| tag(n).to_string()).collect();
        return Err(NetError::NonRectangular {
            set: set_name,
            what: format!("{} corner nodes (nodes in exactly one face: {}), a rectangle has 4", corners.len(), list.join(", ")),
        });
    }
    if let Some((&n, fs)) = node_faces.iter().find(|(n, fs)| !bnd.contains_key(*n) && fs.len() != 4) {
        return Err(NetError::IrregularInterior { set: set_name, node: tag(n), count: fs.len(), faces: describe_all(mesh, set, fs) });
    }

    // 5. Walk the two sides from the first corner, then fill the rows.
    let c0 = corners[0];
    let side = |first: u32| -> Vec<u32> {
        let mut out = vec![c0, first];
        let (mut prev, mut cur) = (c0, first);
        while node_faces[&cur].len() != 1 {
            let nb = &bnd[&cur];
            let next = if nb[0] != prev { nb[0] } else { nb[1] };
            prev = cur;
            cur = next;
            out.push(cur);
        }
        out
    };
    let (nb0, nb1) = (bnd[&c0][0].min(bnd[&c0][1]), bnd[&c0][0].max(bnd[&c0][1]));
    let row0 = side(nb0);
    let col0 = side(nb1);
    let (a, b) = (row0.len(), col0.len());
    let not_grid = |what: String| NetError::NotAGrid { set: set_name.clone(), what };
    if (a - 1) * (b - 1) != nf {
        return Err(not_grid(format!("its sides have {a} and {b} nodes, so a grid would have {} faces, but the set has {nf}", (a - 1) * (b - 1))));
    }
    let mut nodes = vec![u32::MAX; a * b];
    nodes[..a].copy_from_slice(&row0);
    for (j, &n) in col0.iter().enumerate() {
        nodes[a * j] = n;
    }
    let mut used = vec![false; nf];
    // cell_face[i + (a-1) j]
    let mut cell_face = vec![0usize; nf];
    for j in 0..b - 1 {
        for i in 0..a - 1 {
            let (p00, p10, p01) = (nodes[i + a * j], nodes[i + 1 + a * j], nodes[i + a * (j + 1)]);
            let candidates = edges.get(&edge(p00, p10)).map(Vec::as_slice).unwrap_or(&[]);
            let Some(&k) = candidates.iter().find(|&&k| !used[k] && quads[k].contains(&p01) && quads[k].contains(&p00)) else {
                return Err(not_grid(format!("no face continues the grid at nodes {}, {}, {}", tag(p00), tag(p10), tag(p01))));
            };
            let Some(&p11) = quads[k].iter().find(|n| ![p00, p10, p01].contains(*n)) else {
                return Err(not_grid(format!("{} is degenerate", describe(mesh, set, k))));
            };
            let slot = &mut nodes[i + 1 + a * (j + 1)];
            if *slot != u32::MAX && *slot != p11 {
                return Err(not_grid(format!("{} does not close the grid cell ({i}, {j})", describe(mesh, set, k))));
            }
            *slot = p11;
            used[k] = true;
            cell_face[i + (a - 1) * j] = k;
        }
    }

    // 6. Orientation: +1 if the face cycle runs (i,j)→(i+1,j)→…, −1 otherwise.
    let sense = |c: usize| -> i32 {
        let (i, j) = (c % (a - 1), c / (a - 1));
        let q = quads[cell_face[c]];
        let p00 = nodes[i + a * j];
        let p10 = nodes[i + 1 + a * j];
        let pos = q.iter().position(|&n| n == p00).unwrap_or(0);
        if q[(pos + 1) % 4] == p10 {
            1
        } else {
            -1
        }
    };
    let s0 = sense(0);
    if let Some(c) = (1..nf).find(|&c| sense(c) != s0) {
        return Err(NetError::Orientation { set: set_name, face: describe(mesh, set, cell_face[c]), other: describe(mesh, set, cell_face[0]) });
    }
    if s0 < 0 {
        // Flip j: row j becomes row b-1-j, so ā_2 changes sign and n̄ points outward.
        let flipped: Vec<u32> = (0..a * b).map(|p| nodes[p % a + a * (b - 1 - p / a)]).collect();
        nodes = flipped;
    }
    Ok(ControlNet { a, b, nodes })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Body, FaceSet};

    /// An nx × ny × 1 block of unit hexes, one body; every hex top face (local 1,
    /// normal +z) whose (i, j) passes `keep` goes into face set "top", and the bottom
    /// faces (local 0, normal −z) into "bottom".
    fn slab(nx: usize, ny: usize, keep: impl Fn(usize, usize) -> bool) -> Mesh {
        let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
        let mut nodes = Vec::new();
        for k in 0..2 {
            for j in 0..=ny {
                for i in 0..=nx {
                    nodes.push([i as f64, j as f64, k as f64]);
                }
            }
        }
        let mut hexes = Vec::new();
        let mut top = FaceSet { name: "top".into(), physical_tag: 1, faces: vec![], quad_tags: vec![] };
        let mut bottom = FaceSet { name: "bottom".into(), physical_tag: 2, faces: vec![], quad_tags: vec![] };
        for j in 0..ny {
            for i in 0..nx {
                let e = hexes.len() as u32;
                hexes.push([id(i, j, 0), id(i + 1, j, 0), id(i + 1, j + 1, 0), id(i, j + 1, 0), id(i, j, 1), id(i + 1, j, 1), id(i + 1, j + 1, 1), id(i, j + 1, 1)]);
                if keep(i, j) {
                    top.faces.push(HexFace { element: e, local: 1 });
                    top.quad_tags.push(1000 + e as u64);
                    bottom.faces.push(HexFace { element: e, local: 0 });
                    bottom.quad_tags.push(2000 + e as u64);
                }
            }
        }
        let m = hexes.len();
        Mesh {
            node_tags: (1..=nodes.len() as u64).collect(),
            nodes,
            hexes,
            hex_body: vec![0; m],
            bodies: vec![Body { name: "slab".into(), physical_tag: 1 }],
            node_sets: vec![],
            face_sets: vec![top, bottom],
            element_tags: (101..101 + m as u64).collect(),
        }
    }

    /// n̄ of the net's first cell, from the corner control points (ā_1 × ā_2 at ξ = 0).
    fn corner_normal(mesh: &Mesh, net: &ControlNet) -> [f64; 3] {
        let x = |n: u32| mesh.nodes[n as usize];
        let (p, q, r) = (x(net.at(0, 0)), x(net.at(1, 0)), x(net.at(0, 1)));
        let u = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let v = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
        [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    }

    #[test]
    fn structured_top_and_bottom_face_outward() {
        let m = slab(3, 2, |_, _| true);
        let top = control_net(&m, "top").unwrap();
        assert_eq!((top.a * top.b, top.nodes.len()), (12, 12));
        assert!(corner_normal(&m, &top)[2] > 0.0);
        let bottom = control_net(&m, "bottom").unwrap();
        assert!(corner_normal(&m, &bottom)[2] < 0.0, "bottom net must face −z");
        // Every cell is a face of the set, and neighbours in the net are mesh neighbours.
        for j in 0..top.b {
            for i in 0..top.a - 1 {
                let (p, q) = (m.nodes[top.at(i, j) as usize], m.nodes[top.at(i + 1, j) as usize]);
                let d: f64 = (0..3).map(|c| (p[c] - q[c]).powi(2)).sum();
                assert!((d - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn hole_is_refused() {
        let m = slab(3, 3, |i, j| !(i == 1 && j == 1));
        let e = control_net(&m, "top").unwrap_err();
        assert!(matches!(e, NetError::Hole { loops: 2, .. }), "{e}");
        assert!(e.to_string().contains("has a hole"), "{e}");
    }

    #[test]
    fn l_shape_is_refused() {
        let m = slab(2, 2, |i, j| !(i == 1 && j == 1));
        let e = control_net(&m, "top").unwrap_err().to_string();
        assert!(e.contains("non-rectangular outline") && e.contains("re-entrant corner in 3 faces"), "{e}");
        assert!(e.contains("quad 1000 (face 1 of hex 101)"), "{e}");
    }

    #[test]
    fn faces_touching_at_a_corner_are_refused() {
        let m = slab(2, 2, |i, j| i == j);
        let e = control_net(&m, "top").unwrap_err().to_string();
        assert!(e.contains("non-rectangular outline") && e.contains("4 boundary edges meet"), "{e}");
    }

    #[test]
    fn branch_is_refused() {
        // Top faces of a 2×1 slab plus the interior face between the two hexes
        // (hex 0's local face 3, x = 1): three faces on the edge (1,0,1)–(1,1,1).
        let mut m = slab(2, 1, |_, _| true);
        m.face_sets[0].faces.push(HexFace { element: 0, local: 3 });
        m.face_sets[0].quad_tags.push(77);
        let e = control_net(&m, "top").unwrap_err().to_string();
        assert!(e.contains("branches") && e.contains("3 faces") && e.contains("quad 77 (face 3 of hex 101)"), "{e}");
    }

    #[test]
    fn two_bodies_are_refused() {
        let mut m = slab(2, 1, |_, _| true);
        m.bodies.push(Body { name: "other".into(), physical_tag: 2 });
        m.hex_body[1] = 1;
        let e = control_net(&m, "top").unwrap_err().to_string();
        assert!(e.contains("spans two bodies") && e.contains("'slab'") && e.contains("'other'") && e.contains("hex 102"), "{e}");
    }

    #[test]
    fn unknown_and_empty_sets() {
        let mut m = slab(1, 1, |_, _| false);
        let e = control_net(&m, "nope").unwrap_err().to_string();
        assert!(e.contains("'nope' does not exist") && e.contains("top, bottom"), "{e}");
        m.face_sets[0].faces.clear();
        assert!(matches!(control_net(&m, "top"), Err(NetError::Empty { .. })));
    }

    #[test]
    fn inconsistent_orientation_is_refused() {
        // Hex 1 listed mirrored (nodes reversed within each layer): its local face 1
        // is still on the top plane, but wound the other way from hex 0's.
        let mut m = slab(2, 1, |_, _| true);
        let h = m.hexes[1];
        m.hexes[1] = [h[3], h[2], h[1], h[0], h[7], h[6], h[5], h[4]];
        let e = control_net(&m, "top").unwrap_err().to_string();
        assert!(e.contains("inconsistently oriented"), "{e}");
    }

    /// A surface of arbitrary quads: each quad is face 1 (nodes 4..8) of a stand-in
    /// hexahedron (only the face topology matters to the net).
    fn quad_surface(nodes: Vec<[f64; 3]>, quads: &[[u32; 4]]) -> Mesh {
        let hexes: Vec<[u32; 8]> = quads.iter().map(|q| [q[0], q[1], q[2], q[3], q[0], q[1], q[2], q[3]]).collect();
        let m = hexes.len();
        Mesh {
            node_tags: (1..=nodes.len() as u64).collect(),
            nodes,
            hexes,
            hex_body: vec![0; m],
            bodies: vec![Body { name: "b".into(), physical_tag: 1 }],
            node_sets: vec![],
            face_sets: vec![FaceSet {
                name: "s".into(),
                physical_tag: 1,
                faces: (0..m as u32).map(|e| HexFace { element: e, local: 1 }).collect(),
                quad_tags: (1..=m as u64).collect(),
            }],
            element_tags: (1..=m as u64).collect(),
        }
    }

    #[test]
    fn irregular_interior_is_refused() {
        // A 2×2 square whose top-right quad is split into three around P: the outline
        // is a rectangle with 4 corners, but P is in 3 faces and O in 5.
        let nodes = vec![
            [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [2.0, 1.0, 0.0],
            [0.0, 2.0, 0.0], [1.0, 2.0, 0.0], [2.0, 2.0, 0.0], [2.0, 1.5, 0.0], [1.5, 2.0, 0.0], [1.5, 1.5, 0.0],
        ];
        let quads = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 9, 11], [11, 9, 8, 10], [4, 11, 10, 7]];
        let m = quad_surface(nodes, &quads);
        let e = control_net(&m, "s").unwrap_err().to_string();
        assert!(e.contains("not a regular grid: interior node 5 (gmsh tag) is in 5 faces"), "{e}");
        // The regular 2×2 square on the same nodes is accepted.
        let m = quad_surface(m.nodes.clone(), &[[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]]);
        let net = control_net(&m, "s").unwrap();
        assert_eq!((net.a, net.b, net.nodes.clone()), (3, 3, (0..9).collect::<Vec<u32>>()));
    }
}
