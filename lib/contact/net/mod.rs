//! The master control net: how the nodes of a master face set become the control
//! points of the master surface (paper sec. 5, eq. 5.2).
//!
//! The paper orders the master nodes into one structured a × b grid. Real masters
//! are also closed (a tube), made of several grids (a box corner, an L) or free quad
//! meshes with extraordinary nodes (a sphere). [`smooth_net`] reads which one a face
//! set is, for the B-spline orders asked for, and orders it ([`master_net`] orders it
//! as one shape asked for):
//!
//! | shape | file | surface built on it |
//! |-------|------|---------------------|
//! | [`NetShape::Grid`] | [`grid`] | one B-spline patch, open knots (the paper), or bilinear facets |
//! | [`NetShape::Periodic`] | [`periodic`] | one B-spline patch, periodic knots along ξ¹ |
//! | [`NetShape::Patches`] | [`patches`] | one open B-spline patch per grid, C⁰ at the seams |
//! | [`NetShape::Quads`] | [`surface`] | the Catmull–Clark limit surface, or bilinear facets |
//!
//! [`types`] holds the nets and the errors, [`read`] the choice among the shapes,
//! [`surface`] the checks every shape shares: one body, no branching edge, no
//! collapsed face, one orientation. Every cell of every shape is listed so that the
//! right-hand rule on its node cycle gives the normal out of the master body.

mod grid;
mod patches;
mod periodic;
mod read;
mod surface;
mod types;

pub use read::{check_subdivision, control_net, master_net, smooth_net};
pub use types::{ControlNet, MasterNet, NetChoice, NetError, NetShape, PatchNet, SmoothNet, SmoothNetError};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Body, FaceSet, HexFace, Mesh};

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

    /// Every cell of `net` is one of `quads` (mesh node ids) with the same cyclic order.
    fn cells_match(net: &MasterNet, quads: &[[u32; 4]]) {
        let cells = net.cells();
        assert_eq!(cells.len(), quads.len());
        for c in cells {
            let m = c.map(|k| net.nodes[k as usize]);
            let ok = quads.iter().any(|q| (0..4).any(|r| (0..4).all(|t| q[(t + r) % 4] == m[t])));
            assert!(ok, "cell {m:?} is no face of the set in its orientation");
        }
    }

    /// A tube: `na` nodes around, `nb` along z, quads outward.
    fn tube(na: usize, nb: usize) -> (Mesh, Vec<[u32; 4]>) {
        let mut nodes = Vec::new();
        for j in 0..nb {
            for i in 0..na {
                let t = std::f64::consts::TAU * i as f64 / na as f64;
                nodes.push([t.cos(), t.sin(), j as f64]);
            }
        }
        let id = |i: usize, j: usize| (i % na + na * j) as u32;
        let quads: Vec<[u32; 4]> = (0..nb - 1).flat_map(|j| (0..na).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])).collect();
        (quad_surface(nodes, &quads), quads)
    }

    /// The smooth master of a face set for orders [3, 3], which must be B-spline patches.
    fn bspline_net(m: &Mesh, name: &str) -> MasterNet {
        match smooth_net(m, name, [3, 3]) {
            Ok(SmoothNet::Bspline(net)) => net,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_tube_is_a_closed_grid() {
        let (m, quads) = tube(8, 4);
        assert!(matches!(control_net(&m, "s"), Err(NetError::Hole { loops: 2, .. })));
        let net = bspline_net(&m, "s");
        assert_eq!(net.shape, NetShape::Periodic { a: 8, b: 4 });
        assert_eq!(net.describe(), "8 × 4 grid closed along ξ¹");
        cells_match(&net, &quads);
        // Reversed faces (an inward-listed tube) still give outward cells.
        let rev: Vec<[u32; 4]> = quads.iter().map(|q| [q[0], q[3], q[2], q[1]]).collect();
        let m = quad_surface(m.nodes.clone(), &rev);
        let net = master_net(&m, "s", NetChoice::Periodic).unwrap();
        cells_match(&net, &rev);
        // A rectangle is not closed.
        let m = slab(3, 2, |_, _| true);
        let e = master_net(&m, "top", NetChoice::Periodic).unwrap_err().to_string();
        assert!(e.contains("is not a closed grid: its boundary is 1 closed loops"), "{e}");
    }

    #[test]
    fn an_l_is_three_grids() {
        let m = slab(4, 4, |i, j| i < 2 || j < 2);
        let quads: Vec<[u32; 4]> = m.face_sets[0].faces.iter().map(|&f| m.face_nodes(f)).collect();
        let net = bspline_net(&m, "top");
        let NetShape::Patches(ps) = &net.shape else { panic!("{:?}", net.shape) };
        // The re-entrant node (2,2) cuts along x = 2 and y = 2: 2×2, 2×2 and 2×2 cells.
        let mut dims: Vec<[usize; 2]> = ps.iter().map(|p| [p.a, p.b]).collect();
        dims.sort_unstable();
        assert_eq!(dims, vec![[3, 3], [3, 3], [3, 3]]);
        cells_match(&net, &quads);
        assert_eq!(net.nodes.len(), 21);
        // Grids too small for the orders: not patches; the Catmull–Clark surface
        // takes it, its re-entrant node a corner in 3 faces.
        let Ok(SmoothNet::Subdivision(sub)) = smooth_net(&m, "top", [4, 4]) else { panic!("an L of 3 × 3 grids gets the Catmull–Clark master for orders 4") };
        assert_eq!(sub.nodes.len(), 21);
        // One grid too small is refused, not taken as something else.
        let m = slab(2, 3, |_, _| true);
        let e = smooth_net(&m, "top", [4, 4]).unwrap_err();
        assert!(matches!(&e, SmoothNetError::Orders { net, .. } if net.nodes.len() == 12 && net.grid().is_some()), "{e:?}");
    }

    /// Three faces of the cube [0, n]³ at the corner (n, n, n): x = n, y = n, z = n.
    fn box_corner(n: usize) -> (Mesh, Vec<[u32; 4]>) {
        let mut nodes: Vec<[f64; 3]> = Vec::new();
        let mut index = std::collections::HashMap::new();
        let mut id = |p: [usize; 3]| -> u32 {
            *index.entry(p).or_insert_with(|| {
                nodes.push(p.map(|c| c as f64));
                nodes.len() as u32 - 1
            })
        };
        let mut quads = Vec::new();
        for (ax, (u, v)) in [(0usize, (1usize, 2usize)), (1, (2, 0)), (2, (0, 1))] {
            for j in 0..n {
                for i in 0..n {
                    let at = |di: usize, dj: usize| {
                        let mut p = [0; 3];
                        p[ax] = n;
                        p[u] = i + di;
                        p[v] = j + dj;
                        p
                    };
                    // (u, v, ax) is right-handed, so this cycle faces +ax (outward).
                    quads.push([id(at(0, 0)), id(at(1, 0)), id(at(1, 1)), id(at(0, 1))]);
                }
            }
        }
        (quad_surface(nodes, &quads), quads)
    }

    #[test]
    fn a_box_corner_is_three_grids() {
        let (m, quads) = box_corner(3);
        let net = bspline_net(&m, "s");
        assert_eq!(net.describe(), "3 grids (4 × 4, 4 × 4, 4 × 4)");
        cells_match(&net, &quads);
        assert_eq!(net.nodes.len(), 3 * 16 - 3 * 4 + 1);
        // The same surface as quads.
        let q = master_net(&m, "s", NetChoice::Quads).unwrap();
        cells_match(&q, &quads);
        assert!(master_net(&m, "s", NetChoice::Grid).is_err());
    }

    #[test]
    fn quads_and_their_errors() {
        // The split square of `irregular_interior_is_refused` is any-quad surface.
        let nodes = vec![
            [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [2.0, 1.0, 0.0],
            [0.0, 2.0, 0.0], [1.0, 2.0, 0.0], [2.0, 2.0, 0.0], [2.0, 1.5, 0.0], [1.5, 2.0, 0.0], [1.5, 1.5, 0.0],
        ];
        let quads = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 9, 11], [11, 9, 8, 10], [4, 11, 10, 7]];
        let m = quad_surface(nodes.clone(), &quads);
        let net = master_net(&m, "s", NetChoice::Quads).unwrap();
        assert_eq!(net.describe(), "6 quads on 12 nodes");
        cells_match(&net, &quads);
        // Two faces touching at one node.
        let m = slab(2, 2, |i, j| i == j);
        let e = master_net(&m, "top", NetChoice::Quads).unwrap_err().to_string();
        assert!(e.contains("not a manifold surface at node 14 (gmsh tag)") && e.contains("quad 1000"), "{e}");
        // One face turned over.
        let mut q2 = quads;
        q2[5] = [4, 7, 10, 11];
        let m = quad_surface(nodes, &q2);
        let e = master_net(&m, "s", NetChoice::Quads).unwrap_err().to_string();
        assert!(e.contains("inconsistently oriented") && e.contains("quad 6"), "{e}");
    }
}
