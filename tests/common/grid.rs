//! Structured hex8 blocks with named sets, for solver tests.

use splinecontact::mesh::{Body, FaceSet, HexFace, Mesh, NodeSet};

/// An nx×ny×nz block of size lx×ly×lz at the origin, one body "block", node sets
/// "x0", "x1", "y0", "y1", "z0", "z1" (the six faces), "origin" (node at 0,0,0) and
/// face sets of the same six names (outward-oriented). `distort` moves interior nodes
/// by a deterministic pseudo-random fraction of the spacing.
pub fn block(n: [usize; 3], l: [f64; 3], distort: f64) -> Mesh {
    let [nx, ny, nz] = n;
    let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let mut nodes = Vec::new();
    let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % 10_000) as f64 / 10_000.0 - 0.5
    };
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let mut p = [i as f64 * l[0] / nx as f64, j as f64 * l[1] / ny as f64, k as f64 * l[2] / nz as f64];
                let interior = [i > 0 && i < nx, j > 0 && j < ny, k > 0 && k < nz];
                let h = [l[0] / nx as f64, l[1] / ny as f64, l[2] / nz as f64];
                for c in 0..3 {
                    // Move a node along c only if it is interior in c, so boundary faces stay planar.
                    if interior[c] {
                        p[c] += distort * h[c] * rnd();
                    }
                }
                nodes.push(p);
            }
        }
    }
    let mut hexes = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                hexes.push([id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)]);
            }
        }
    }
    let hex_index = |i: usize, j: usize, k: usize| (i + nx * (j + ny * k)) as u32;
    let mut node_sets = Vec::new();
    let mut face_sets = Vec::new();
    // (name, axis, at-max, local face)
    for (name, axis, max, local) in [("x0", 0, false, 5u8), ("x1", 0, true, 3), ("y0", 1, false, 2), ("y1", 1, true, 4), ("z0", 2, false, 0), ("z1", 2, true, 1)] {
        let mut ns = Vec::new();
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    let c = [i, j, k][axis];
                    if c == if max { n[axis] } else { 0 } {
                        ns.push(id(i, j, k));
                    }
                }
            }
        }
        ns.sort_unstable();
        node_sets.push(NodeSet { name: name.into(), physical_tag: 0, dim: 2, nodes: ns });
        let mut fs = Vec::new();
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let c = [i, j, k][axis];
                    if c == if max { n[axis] - 1 } else { 0 } {
                        fs.push(HexFace { element: hex_index(i, j, k), local });
                    }
                }
            }
        }
        face_sets.push(FaceSet { name: name.into(), physical_tag: 0, quad_tags: vec![0; fs.len()], faces: fs });
    }
    node_sets.push(NodeSet { name: "origin".into(), physical_tag: 0, dim: 0, nodes: vec![0] });
    one_body("block", nodes, hexes, node_sets, face_sets)
}

/// A mesh of one body `name` (physical tag 1), gmsh tags 1, 2, … for its nodes and
/// hexahedra.
pub fn one_body(name: &str, nodes: Vec<[f64; 3]>, hexes: Vec<[u32; 8]>, node_sets: Vec<NodeSet>, face_sets: Vec<FaceSet>) -> Mesh {
    let m = hexes.len();
    Mesh {
        node_tags: (1..=nodes.len() as u64).collect(),
        nodes,
        hexes,
        hex_body: vec![0; m],
        bodies: vec![Body { name: name.into(), physical_tag: 1 }],
        node_sets,
        face_sets,
        element_tags: (1..=m as u64).collect(),
    }
}

/// Add a node set `name` of the nodes for which `pred(x)` holds.
pub fn add_node_set(mesh: &mut Mesh, name: &str, pred: impl Fn(&[f64; 3]) -> bool) {
    let nodes: Vec<u32> = (0..mesh.nodes.len()).filter(|&i| pred(&mesh.nodes[i])).map(|i| i as u32).collect();
    assert!(!nodes.is_empty(), "node set {name} is empty");
    mesh.node_sets.push(NodeSet { name: name.into(), physical_tag: 0, dim: 0, nodes });
}

/// Two meshes as one with two bodies: `b` shifted by `shift`. Bodies are named
/// `name_a`, `name_b`; every set of each is prefixed (`lower_z1`, `upper_z0`, …).
pub fn two_bodies(name_a: &str, a: &Mesh, name_b: &str, b: &Mesh, shift: [f64; 3]) -> Mesh {
    let na = a.nodes.len() as u32;
    let ea = a.hexes.len() as u32;
    let mut m = Mesh {
        nodes: a.nodes.clone(),
        hexes: a.hexes.clone(),
        hex_body: vec![0; a.hexes.len()],
        bodies: vec![Body { name: name_a.into(), physical_tag: 1 }, Body { name: name_b.into(), physical_tag: 2 }],
        node_sets: Vec::new(),
        face_sets: Vec::new(),
        node_tags: Vec::new(),
        element_tags: Vec::new(),
    };
    m.nodes.extend(b.nodes.iter().map(|p| [p[0] + shift[0], p[1] + shift[1], p[2] + shift[2]]));
    m.hexes.extend(b.hexes.iter().map(|h| h.map(|n| n + na)));
    m.hex_body.extend(std::iter::repeat_n(1, b.hexes.len()));
    for (prefix, src, dn, de) in [(name_a, a, 0, 0), (name_b, b, na, ea)] {
        for s in &src.node_sets {
            m.node_sets.push(NodeSet { name: format!("{prefix}_{}", s.name), physical_tag: 0, dim: s.dim, nodes: s.nodes.iter().map(|n| n + dn).collect() });
        }
        for s in &src.face_sets {
            let faces = s.faces.iter().map(|f| HexFace { element: f.element + de, local: f.local }).collect();
            m.face_sets.push(FaceSet { name: format!("{prefix}_{}", s.name), physical_tag: 0, faces, quad_tags: s.quad_tags.clone() });
        }
    }
    m.node_tags = (1..=m.nodes.len() as u64).collect();
    m.element_tags = (1..=m.hexes.len() as u64).collect();
    m
}
