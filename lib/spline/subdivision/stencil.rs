//! The control stencil of one face: the faces around its four corners as a small
//! *local mesh* whose points are linear combinations of real control nodes, with
//! phantom points across open boundaries, and the ordered stencils read from it.
//!
//! **Phantom points (the boundary rule).** Across a boundary edge `a → b` of the real
//! face `F`, the phantom face is `(b, a, φ_F(a), φ_F(b))` with
//! ```text
//! φ_F(v) = 2 v − w,     w = the neighbour of v in F that is not across the edge
//! ```
//! and at a convex corner `c` of `F = (c, a, d, b′)` (a node in one face) the diagonal
//! phantom `4c − 2a − 2b′ + d` closes the fourth face `(c, 2c − a, ·, 2c − b′)`. Every
//! boundary node then has four faces around it, so a face touching the boundary is an
//! ordinary face of the extended mesh; if its corners are regular it is the uniform
//! bicubic B-spline patch, whose boundary curve is the cubic B-spline of the boundary
//! nodes (`(φ + 4v + w)/6 = v` on the control polygon) and which passes through convex
//! corners. A boundary node in three or more faces (a concave corner or a boundary
//! extraordinary vertex) has no such extension; its faces are evaluated by
//! [`super::boundary_vertex`].
//!
//! **Stencil order around a corner of valence N** (Stam 1998, fig. 1, in our own
//! numbering): the corner is point 0; ring face `i` is `(0, e_i, f_i, e_{i+1})` with
//! edge neighbours `e_i = 1 + 2i` and diagonal points `f_i = 2 + 2i`, face 0 being the
//! stencil's own face with its parameter `s` along `0 → e_0` and `t` along `0 → e_1`.
//! The seven points `o_0 … o_6 = 2N+1 … 2N+7` complete the rings of the other three
//! corners; for N = 4 they sit at the grid positions (2,−1), (2,0), (2,1), (2,2), (1,2),
//! (0,2), (−1,2) of [`GRID_OF_RING`].

use std::collections::HashMap;

use super::topology::{Ring, Topology};
use super::control_mesh::{QuadControlMesh, SubdivisionError};

/// Grid position `(i, j)` (−1…2 each, the regular patch over `[0,1]²`) of the 16
/// stencil points of a valence-4 corner, in stencil order.
pub(super) const GRID_OF_RING: [(i32, i32); 16] = [
    (0, 0),
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (-1, -1),
    (0, -1),
    (1, -1),
    (2, -1),
    (2, 0),
    (2, 1),
    (2, 2),
    (1, 2),
    (0, 2),
    (-1, 2),
];

/// Index `(i+1) + 4(j+1)` of the bicubic tensor-product weight of stencil point `k`.
pub(super) fn grid_index(k: usize) -> usize {
    let (i, j) = GRID_OF_RING[k];
    ((i + 1) + 4 * (j + 1)) as usize
}

/// A small quad mesh whose points are linear combinations (dense, over `n_base`
/// base points) of base points: real control nodes, or a canonical stencil.
#[derive(Debug, Clone)]
pub(super) struct LocalMesh {
    pub n_base: usize,
    /// `points[p][b]`: weight of base point `b` in point `p`.
    pub points: Vec<Vec<f64>>,
    pub faces: Vec<[usize; 4]>,
    /// Directed edge → (face, corner of its first point).
    half_edges: HashMap<(usize, usize), (usize, usize)>,
}

/// A corner whose ring is not complete in the local mesh (a bug, not a user error:
/// the local mesh always holds every face around the corners it is asked about).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct OpenRing;

/// Which points and edges of a local mesh lie on the surface's open boundary (the
/// true boundary, not where the local mesh is cut off), and the rule of each boundary
/// point: a *corner* stays where it is (v′ = v), any other boundary point follows the
/// cubic B-spline curve of the boundary, v′ = (l + 6v + r)/8.
#[derive(Debug, Clone, Default)]
pub(super) struct Boundary {
    /// Boundary point → whether it is a corner.
    pub points: HashMap<usize, bool>,
    /// Boundary edges, as (smaller, larger) point index.
    pub edges: std::collections::HashSet<(usize, usize)>,
}

impl Boundary {
    pub fn is_edge(&self, a: usize, b: usize) -> bool {
        self.edges.contains(&(a.min(b), a.max(b)))
    }
}

impl LocalMesh {
    pub fn new(n_base: usize, points: Vec<Vec<f64>>, faces: Vec<[usize; 4]>) -> Self {
        let mut half_edges = HashMap::with_capacity(4 * faces.len());
        for (f, face) in faces.iter().enumerate() {
            for c in 0..4 {
                half_edges.insert((face[c], face[(c + 1) % 4]), (f, c));
            }
        }
        Self { n_base, points, faces, half_edges }
    }

    /// The face holding directed edge `a → b` and the corner of `a` in it.
    pub fn half_edge(&self, a: usize, b: usize) -> Option<(usize, usize)> {
        self.half_edges.get(&(a, b)).copied()
    }

    /// The faces around corner `corner` of `face`, in ring order starting with `face`
    /// (each with the centre's corner in it), if the ring closes.
    pub fn ring(&self, face: usize, corner: usize) -> Result<Vec<(usize, usize)>, OpenRing> {
        let v = self.faces[face][corner];
        let mut ring = vec![(face, corner)];
        loop {
            let (f, c) = *ring.last().expect("ring starts non-empty");
            let e_next = self.faces[f][(c + 3) % 4];
            let next = self.half_edge(v, e_next).ok_or(OpenRing)?;
            if next == (face, corner) {
                return Ok(ring);
            }
            if ring.len() > self.faces.len() {
                return Err(OpenRing);
            }
            ring.push(next);
        }
    }

    /// The faces around corner `corner` of `face` in ring order (the order of
    /// [`Topology`]: a boundary fan runs from the face whose edge `v → F[c+1]` has no
    /// twin to the face whose edge `F[c+3] → v` has none), and whether the ring closes.
    pub fn fan(&self, face: usize, corner: usize) -> (Vec<(usize, usize)>, bool) {
        if let Ok(ring) = self.ring(face, corner) {
            return (ring, true);
        }
        let v = self.faces[face][corner];
        // back to the first face: the previous face holds F[c+1] → v
        let mut start = (face, corner);
        for _ in 0..self.faces.len() {
            let (f, c) = start;
            match self.half_edge(self.faces[f][(c + 1) % 4], v) {
                Some((g, cb)) => start = (g, (cb + 1) % 4),
                None => break,
            }
        }
        let mut fan = vec![start];
        while fan.len() <= self.faces.len() {
            let (f, c) = *fan.last().expect("fan starts non-empty");
            match self.half_edge(v, self.faces[f][(c + 3) % 4]) {
                Some(next) => fan.push(next),
                None => break,
            }
        }
        (fan, false)
    }

    /// The far ends `(l, r)` of the two edges that bound the open fan around corner
    /// `corner` of `face` ([`Self::fan`]): `v → l` in its first face, `r → v` in its
    /// last (on a boundary, v's neighbours along it).
    pub fn fan_ends(&self, face: usize, corner: usize) -> (usize, usize) {
        let (fan, _) = self.fan(face, corner);
        let ((g0, c0), (g1, c1)) = (fan[0], fan[fan.len() - 1]);
        (self.faces[g0][(c0 + 1) % 4], self.faces[g1][(c1 + 3) % 4])
    }

    /// Valence of corner `corner` of `face` (its number of faces).
    pub fn valence(&self, face: usize, corner: usize) -> Result<usize, OpenRing> {
        self.ring(face, corner).map(|r| r.len())
    }

    /// The `2N+8` stencil points (indices into `points`) of `face` around its corner
    /// `corner` of valence N, in the order of the module docs: `s` runs along
    /// `corner → corner+1`, `t` along `corner → corner−1`.
    pub fn stencil(&self, face: usize, corner: usize) -> Result<Vec<usize>, OpenRing> {
        let ring = self.ring(face, corner)?;
        let n = ring.len();
        let mut st = Vec::with_capacity(2 * n + 8);
        st.push(self.faces[face][corner]);
        for &(f, c) in &ring {
            st.push(self.faces[f][(c + 1) % 4]); // e_i
            st.push(self.faces[f][(c + 2) % 4]); // f_i
        }
        let (e0, f0, e1) = (st[1], st[2], st[3]);
        let f1 = st[4];
        let f_last = st[2 * n];
        // the far corners (c+2, c+3) of the face holding directed edge a → b
        let far = |a: usize, b: usize| -> Result<(usize, usize), OpenRing> {
            let (g, c) = self.half_edge(a, b).ok_or(OpenRing)?;
            Ok((self.faces[g][(c + 2) % 4], self.faces[g][(c + 3) % 4]))
        };
        let (o0, o1) = far(e0, f_last)?;
        let (o1b, o2) = far(f0, e0)?;
        let (o3, o4) = far(f0, o2)?;
        let (o4b, o5) = far(e1, f0)?;
        let (o5b, o6) = far(f1, e1)?;
        if o1 != o1b || o4 != o4b || o5 != o5b {
            return Err(OpenRing);
        }
        st.extend([o0, o1, o2, o3, o4, o5, o6]);
        Ok(st)
    }
}

/// A quad net the local mesh is read from: the global control mesh, or a subdivided
/// local mesh near a boundary node in three or more faces ([`super::boundary_vertex`]).
/// Only the rings of the asked face's corners are read, and those must be complete.
pub(super) trait Net {
    /// The node cycle of face `g`.
    fn quad(&self, g: usize) -> [u32; 4];
    /// The faces around node `v` in ring order (see [`Topology`]).
    fn ring(&self, v: u32) -> std::borrow::Cow<'_, Ring>;
    /// Whether some face holds the directed edge `a → b`.
    fn has_edge(&self, a: u32, b: u32) -> bool;
}

/// The global control mesh with its topology.
pub(super) struct GlobalNet<'a> {
    pub mesh: &'a QuadControlMesh,
    pub topo: &'a Topology,
}

impl Net for GlobalNet<'_> {
    fn quad(&self, g: usize) -> [u32; 4] {
        self.mesh.faces[g]
    }
    fn ring(&self, v: u32) -> std::borrow::Cow<'_, Ring> {
        std::borrow::Cow::Borrowed(&self.topo.rings[v as usize])
    }
    fn has_edge(&self, a: u32, b: u32) -> bool {
        self.topo.half_edge(a, b).is_some()
    }
}

/// What a point of a face's local mesh is, before it becomes a combination of nodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum PointKey {
    Node(u32),
    /// `2v − w`: node `v` reflected through itself away from `w`.
    Reflect { v: u32, w: u32 },
    /// `4c − 2a − 2b + d` at the convex corner `c` of face `(c, a, d, b)`.
    Diagonal { c: u32, a: u32, b: u32, d: u32 },
}

/// The local mesh of real face `face`: every real face around its four corners plus
/// the phantom faces around its boundary corners. Its base points are the face's
/// *support* (the real nodes it depends on), returned in order of first appearance.
pub(super) fn local_mesh<N: Net>(net: &N, face: usize) -> Result<(LocalMesh, Vec<u32>), SubdivisionError> {
    let mut keys: Vec<PointKey> = Vec::new();
    let mut index: HashMap<PointKey, usize> = HashMap::new();
    let mut faces: Vec<[usize; 4]> = Vec::new();
    let mut seen_faces: Vec<[usize; 4]> = Vec::new();
    let mut add_face = |quad: [PointKey; 4], keys: &mut Vec<PointKey>, faces: &mut Vec<[usize; 4]>| {
        let mut idx = [0; 4];
        for (slot, key) in idx.iter_mut().zip(quad) {
            *slot = *index.entry(key).or_insert_with(|| {
                keys.push(key);
                keys.len() - 1
            });
        }
        // the same face reached from two corners has the same node cycle
        let first = (0..4).min_by_key(|&c| idx[c]).unwrap_or(0);
        let mut cycle = idx;
        cycle.rotate_left(first);
        if !seen_faces.contains(&cycle) {
            seen_faces.push(cycle);
            faces.push(idx);
        }
    };
    // the real face first, so it is face 0 of the local mesh
    let quad = net.quad(face);
    add_face(quad.map(PointKey::Node), &mut keys, &mut faces);
    for &v in &quad {
        let ring = net.ring(v);
        let ring = ring.as_ref();
        if ring.boundary && ring.faces.len() > 2 {
            // no phantom extension: such faces are evaluated by `boundary_vertex`
            return Err(SubdivisionError::StencilIncomplete { face });
        }
        for &(g, _) in &ring.faces {
            add_face(net.quad(g).map(PointKey::Node), &mut keys, &mut faces);
        }
        if !ring.boundary {
            continue;
        }
        for &(g, c) in &ring.faces {
            let q = net.quad(g);
            let at = |k: usize| q[(c + k) % 4];
            // boundary edges of g at v: v → q[c+1] and q[c+3] → v
            for (a_corner, is_boundary) in [
                (c, !net.has_edge(at(1), v)),
                ((c + 3) % 4, !net.has_edge(v, at(3))),
            ] {
                if !is_boundary {
                    continue;
                }
                // boundary edge a → b of g, a at a_corner
                let a = q[a_corner];
                let b = q[(a_corner + 1) % 4];
                let phi_a = PointKey::Reflect { v: a, w: q[(a_corner + 3) % 4] };
                let phi_b = PointKey::Reflect { v: b, w: q[(a_corner + 2) % 4] };
                add_face([PointKey::Node(b), PointKey::Node(a), phi_a, phi_b], &mut keys, &mut faces);
            }
            if ring.faces.len() == 1 {
                // convex corner: (c, 2c − a, diagonal, 2c − b′)
                let (a, d, b) = (at(1), at(2), at(3));
                add_face(
                    [
                        PointKey::Node(v),
                        PointKey::Reflect { v, w: a },
                        PointKey::Diagonal { c: v, a, b, d },
                        PointKey::Reflect { v, w: b },
                    ],
                    &mut keys,
                    &mut faces,
                );
            }
        }
    }
    // support: the real nodes in order of first appearance
    let mut support: Vec<u32> = Vec::new();
    let col = |n: u32, support: &mut Vec<u32>| match support.iter().position(|&s| s == n) {
        Some(i) => i,
        None => {
            support.push(n);
            support.len() - 1
        }
    };
    let mut terms: Vec<Vec<(usize, f64)>> = Vec::with_capacity(keys.len());
    for key in &keys {
        let t = match *key {
            PointKey::Node(n) => vec![(col(n, &mut support), 1.0)],
            PointKey::Reflect { v, w } => vec![(col(v, &mut support), 2.0), (col(w, &mut support), -1.0)],
            PointKey::Diagonal { c, a, b, d } => vec![
                (col(c, &mut support), 4.0),
                (col(a, &mut support), -2.0),
                (col(b, &mut support), -2.0),
                (col(d, &mut support), 1.0),
            ],
        };
        terms.push(t);
    }
    let n_base = support.len();
    let points = terms
        .into_iter()
        .map(|t| {
            let mut p = vec![0.0; n_base];
            for (b, w) in t {
                p[b] += w;
            }
            p
        })
        .collect();
    Ok((LocalMesh::new(n_base, points, faces), support))
}
