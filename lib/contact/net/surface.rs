//! A master face set as a quad surface: its faces (node cycles that give the outward
//! normal by the right-hand rule), which faces share each edge and each node, and the
//! checks every master layout needs: one body, no branching edge, no collapsed face,
//! one consistent orientation, and boundary loops.
//!
//! Faces are named by their gmsh quad tag and the hexahedron they bound, nodes by
//! their gmsh tags, so every error points at the mesh the user made.

use std::collections::{BTreeMap, BTreeSet};

use super::types::NetError;
use crate::mesh::{FaceSet, HexFace, Mesh};

/// An unordered edge.
pub(super) fn edge(u: u32, v: u32) -> (u32, u32) {
    (u.min(v), u.max(v))
}

/// A face set (or a part of it) with its edge and node adjacency.
pub(super) struct Surface<'m> {
    pub mesh: &'m Mesh,
    pub set: &'m FaceSet,
    /// Face `k` is `set.faces[ids[k]]`.
    pub ids: Vec<usize>,
    /// Node cycle of face `k` (mesh node indices, outward by the right-hand rule).
    pub quads: Vec<[u32; 4]>,
    /// Unordered edge → the faces that use it.
    pub edges: BTreeMap<(u32, u32), Vec<usize>>,
    /// Node → the faces that use it.
    pub node_faces: BTreeMap<u32, Vec<usize>>,
}

impl<'m> Surface<'m> {
    /// The face set `name`: it must exist, be non-empty and lie in one body, and no
    /// face may repeat a node.
    pub fn of_set(mesh: &'m Mesh, name: &str) -> Result<Self, NetError> {
        let set = mesh
            .face_set(name)
            .ok_or_else(|| NetError::UnknownFaceSet { set: name.to_string(), known: mesh.face_set_names().join(", ") })?;
        if set.faces.is_empty() {
            return Err(NetError::Empty { set: name.to_string() });
        }
        let s = Self::build(mesh, set, (0..set.faces.len()).collect());
        let nf = s.quads.len();
        let body_of = |k: usize| mesh.hex_body[set.faces[k].element as usize];
        if let Some(k) = (1..nf).find(|&k| body_of(k) != body_of(0)) {
            let bname = |b: u32| mesh.bodies.get(b as usize).map(|b| b.name.clone()).unwrap_or_else(|| b.to_string());
            return Err(NetError::SpansTwoBodies {
                set: s.name(),
                body_a: bname(body_of(0)),
                face_a: s.describe(0),
                body_b: bname(body_of(k)),
                face_b: s.describe(k),
            });
        }
        if let Some(k) = (0..nf).find(|&k| {
            let q = s.quads[k];
            (0..4).any(|c| (c + 1..4).any(|d| q[c] == q[d]))
        }) {
            return Err(NetError::Degenerate { set: s.name(), face: s.describe(k) });
        }
        if let Some(((u, v), fs)) = s.edges.iter().find(|(_, fs)| fs.len() > 2) {
            return Err(NetError::Branch { set: s.name(), n0: s.tag(*u), n1: s.tag(*v), count: fs.len(), faces: s.describe_all(fs) });
        }
        Ok(s)
    }

    /// The faces `ids` (positions in the set) of the same face set.
    pub fn subset(&self, faces: &[usize]) -> Self {
        Self::build(self.mesh, self.set, faces.iter().map(|&k| self.ids[k]).collect())
    }

    fn build(mesh: &'m Mesh, set: &'m FaceSet, ids: Vec<usize>) -> Self {
        let quads: Vec<[u32; 4]> = ids.iter().map(|&k| mesh.face_nodes(set.faces[k])).collect();
        let mut edges: BTreeMap<(u32, u32), Vec<usize>> = BTreeMap::new();
        let mut node_faces: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
        for (k, q) in quads.iter().enumerate() {
            for c in 0..4 {
                edges.entry(edge(q[c], q[(c + 1) % 4])).or_default().push(k);
                node_faces.entry(q[c]).or_default().push(k);
            }
        }
        Self { mesh, set, ids, quads, edges, node_faces }
    }

    pub fn name(&self) -> String {
        self.set.name.clone()
    }

    /// gmsh tag of node `n`.
    pub fn tag(&self, n: u32) -> u64 {
        self.mesh.node_tags.get(n as usize).copied().unwrap_or(n as u64 + 1)
    }

    /// "quad 17 (face 1 of hex 101)".
    pub fn describe(&self, k: usize) -> String {
        let i = self.ids[k];
        let f: HexFace = self.set.faces[i];
        let quad = self.set.quad_tags.get(i).copied().unwrap_or(0);
        let hex = self.mesh.element_tags.get(f.element as usize).copied().unwrap_or(f.element as u64 + 1);
        format!("quad {quad} (face {} of hex {hex})", f.local)
    }

    pub fn describe_all(&self, ks: &[usize]) -> String {
        ks.iter().map(|&k| self.describe(k)).collect::<Vec<_>>().join(", ")
    }

    /// Every interior edge is run in opposite directions by its two faces (one
    /// orientation for the whole surface).
    pub fn check_orientation(&self) -> Result<(), NetError> {
        let mut directed: BTreeMap<(u32, u32), usize> = BTreeMap::new();
        for (k, q) in self.quads.iter().enumerate() {
            for c in 0..4 {
                if let Some(&other) = directed.get(&(q[c], q[(c + 1) % 4])) {
                    return Err(NetError::Orientation { set: self.name(), face: self.describe(k), other: self.describe(other) });
                }
                directed.insert((q[c], q[(c + 1) % 4]), k);
            }
        }
        Ok(())
    }

    /// Whether `n` lies on an edge used by one face only.
    pub fn is_boundary(&self, n: u32) -> bool {
        self.node_faces[&n].iter().any(|&k| {
            let q = self.quads[k];
            let c = q.iter().position(|&m| m == n).unwrap_or(0);
            self.edges[&edge(n, q[(c + 1) % 4])].len() == 1 || self.edges[&edge(n, q[(c + 3) % 4])].len() == 1
        })
    }

    /// Number of faces at node `n` (its valence on a manifold quad surface).
    pub fn valence(&self, n: u32) -> usize {
        self.node_faces[&n].len()
    }

    /// The nodes joined to `n` by an edge.
    pub fn neighbours(&self, n: u32) -> BTreeSet<u32> {
        let mut out = BTreeSet::new();
        for &k in &self.node_faces[&n] {
            let q = self.quads[k];
            let c = q.iter().position(|&m| m == n).unwrap_or(0);
            out.insert(q[(c + 1) % 4]);
            out.insert(q[(c + 3) % 4]);
        }
        out
    }

    /// Boundary node → its boundary neighbours.
    pub fn boundary_adjacency(&self) -> BTreeMap<u32, Vec<u32>> {
        let mut bnd: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
        for (&(u, v), fs) in &self.edges {
            if fs.len() == 1 {
                bnd.entry(u).or_default().push(v);
                bnd.entry(v).or_default().push(u);
            }
        }
        bnd
    }

    /// The faces at every node form one fan (a node where two pieces of the surface
    /// only touch is not a manifold point), so every boundary node has exactly two
    /// boundary neighbours.
    pub fn check_vertex_fans(&self) -> Result<(), NetError> {
        for (&n, fs) in &self.node_faces {
            // Faces at n joined through the edges at n.
            let mut reached = vec![fs[0]];
            let mut grown = true;
            while grown {
                grown = false;
                for &k in fs {
                    if reached.contains(&k) {
                        continue;
                    }
                    let q = self.quads[k];
                    let c = q.iter().position(|&m| m == n).unwrap_or(0);
                    let shares = [q[(c + 1) % 4], q[(c + 3) % 4]].iter().any(|&m| self.edges[&edge(n, m)].iter().any(|f| reached.contains(f)));
                    if shares {
                        reached.push(k);
                        grown = true;
                    }
                }
            }
            if reached.len() != fs.len() {
                return Err(NetError::NonManifoldVertex { set: self.name(), node: self.tag(n), faces: self.describe_all(fs) });
            }
        }
        Ok(())
    }

    /// The closed boundary loops (each a node cycle), after [`Self::check_vertex_fans`].
    pub fn boundary_loops(&self) -> Vec<Vec<u32>> {
        let bnd = self.boundary_adjacency();
        let mut seen: BTreeSet<u32> = BTreeSet::new();
        let mut loops = Vec::new();
        for &start in bnd.keys() {
            if seen.contains(&start) {
                continue;
            }
            let mut lp = Vec::new();
            let (mut prev, mut cur) = (u32::MAX, start);
            loop {
                seen.insert(cur);
                lp.push(cur);
                let nb = &bnd[&cur];
                let next = if nb[0] != prev { nb[0] } else { nb[nb.len() - 1] };
                prev = cur;
                cur = next;
                if cur == start || seen.contains(&cur) {
                    break;
                }
            }
            loops.push(lp);
        }
        loops
    }
}
