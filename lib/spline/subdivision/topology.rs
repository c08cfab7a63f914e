//! The quad control mesh's topology: directed edges → faces, the ordered ring of
//! faces around every node, and the checks the limit surface needs (every face has
//! four distinct nodes, every edge has one or two faces, the two faces of an interior
//! edge traverse it in opposite directions, the faces around a node form one fan).
//!
//! Ring order around node `v`: the face after `F` (with `v` at corner `c`) is the face
//! holding the directed edge `v → F[c+3]`, the twin of `F`'s edge `F[c+3] → v`. A node
//! whose fan does not close is a *boundary* node; its ring then runs from the face
//! whose edge `v → F[c+1]` has no twin to the face whose edge `F[c+3] → v` has none.

use std::collections::{BTreeMap, HashMap};

use super::control_mesh::{QuadControlMesh, SubdivisionError};

/// One node's incident faces in ring order, each with the node's corner in it.
#[derive(Debug, Clone)]
pub(super) struct Ring {
    pub faces: Vec<(usize, usize)>,
    pub boundary: bool,
}

/// Directed-edge map and node rings of a validated [`QuadControlMesh`].
#[derive(Debug)]
pub(super) struct Topology {
    /// Directed edge `(a, b)` → (face, corner of `a`), with `face[corner + 1] = b`.
    half_edges: HashMap<(u32, u32), (usize, usize)>,
    /// Ring of every node (empty for nodes in no face).
    pub rings: Vec<Ring>,
}

impl Topology {
    pub fn new(mesh: &QuadControlMesh) -> Result<Self, SubdivisionError> {
        for (f, face) in mesh.faces.iter().enumerate() {
            for (c, &a) in face.iter().enumerate() {
                if a as usize >= mesh.n_nodes {
                    return Err(SubdivisionError::NodeOutOfRange { face: f, node: a, n_nodes: mesh.n_nodes });
                }
                if face[c + 1..].contains(&a) {
                    return Err(SubdivisionError::RepeatedNode { face: f, node: a });
                }
            }
        }
        // undirected edge → faces holding it, in face order (BTreeMap: the first error
        // reported is the same on every run)
        let mut edges: BTreeMap<(u32, u32), Vec<usize>> = BTreeMap::new();
        for (f, face) in mesh.faces.iter().enumerate() {
            for c in 0..4 {
                let (a, b) = (face[c], face[(c + 1) % 4]);
                edges.entry((a.min(b), a.max(b))).or_default().push(f);
            }
        }
        for (&(a, b), faces) in &edges {
            if faces.len() > 2 {
                return Err(SubdivisionError::NonManifoldEdge { nodes: [a, b], faces: faces.clone() });
            }
        }
        let mut half_edges = HashMap::with_capacity(4 * mesh.faces.len());
        for (f, face) in mesh.faces.iter().enumerate() {
            for c in 0..4 {
                let key = (face[c], face[(c + 1) % 4]);
                if let Some(&(g, _)) = half_edges.get(&key) {
                    return Err(SubdivisionError::InconsistentOrientation { nodes: [key.0, key.1], faces: [g, f] });
                }
                half_edges.insert(key, (f, c));
            }
        }
        let mut incident: Vec<Vec<(usize, usize)>> = vec![Vec::new(); mesh.n_nodes];
        for (f, face) in mesh.faces.iter().enumerate() {
            for (c, &a) in face.iter().enumerate() {
                incident[a as usize].push((f, c));
            }
        }
        let mut topo = Self { half_edges, rings: Vec::with_capacity(mesh.n_nodes) };
        for (v, inc) in incident.iter().enumerate() {
            let ring = topo.walk_ring(mesh, v as u32, inc)?;
            topo.rings.push(ring);
        }
        Ok(topo)
    }

    /// The face holding directed edge `a → b` and the corner of `a` in it.
    pub fn half_edge(&self, a: u32, b: u32) -> Option<(usize, usize)> {
        self.half_edges.get(&(a, b)).copied()
    }

    /// Orders the faces around `v` (see the module docs); one fan or an error.
    fn walk_ring(&self, mesh: &QuadControlMesh, v: u32, inc: &[(usize, usize)]) -> Result<Ring, SubdivisionError> {
        let Some(&first) = inc.first() else {
            return Ok(Ring { faces: Vec::new(), boundary: false });
        };
        // the previous face holds F[c+1] → v, the twin of F's edge v → F[c+1]
        let prev = |(f, c): (usize, usize)| {
            let b = mesh.faces[f][(c + 1) % 4];
            self.half_edge(b, v).map(|(g, cb)| (g, (cb + 1) % 4))
        };
        let next = |(f, c): (usize, usize)| {
            let b = mesh.faces[f][(c + 3) % 4];
            self.half_edge(v, b)
        };
        let mut start = first;
        let mut boundary = false;
        for _ in 0..inc.len() {
            match prev(start) {
                Some(p) if p == first => break,
                Some(p) => start = p,
                None => {
                    boundary = true;
                    break;
                }
            }
        }
        let mut faces = vec![start];
        let mut cur = start;
        while let Some(n) = next(cur) {
            if n == start {
                break;
            }
            if faces.len() > inc.len() {
                break;
            }
            faces.push(n);
            cur = n;
        }
        if faces.len() != inc.len() {
            return Err(SubdivisionError::NonManifoldVertex { node: v, faces: inc.len(), fan: faces.len() });
        }
        Ok(Ring { faces, boundary })
    }
}
