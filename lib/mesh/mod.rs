//! The finite element mesh shared by every stage: nodes, 8-node hexahedra grouped
//! into bodies (one per gmsh physical volume), named node sets and face sets.
//!
//! Indices are 0-based positions into `nodes` / `hexes`; the original gmsh tags are
//! kept beside them (`node_tags`, `element_tags`) so every message and every output
//! can be traced back to the `.msh` file the user wrote.

pub mod topology;

pub use topology::{hex_face_nodes, HEX_FACES};

/// A point or vector in 3D, `[x, y, z]`.
pub type Vec3 = [f64; 3];

/// One body: a gmsh physical volume, i.e. a set of hexahedra with one material.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    pub name: String,
    /// gmsh physical tag of the volume group (0 if it had none).
    pub physical_tag: i32,
}

/// A named set of nodes (from any gmsh physical group).
#[derive(Debug, Clone, PartialEq)]
pub struct NodeSet {
    pub name: String,
    /// gmsh physical tag and dimension of the group it came from.
    pub physical_tag: i32,
    pub dim: u8,
    /// Sorted, unique node indices.
    pub nodes: Vec<u32>,
}

/// A face of a hexahedron: `local` indexes [`HEX_FACES`]; the face normal points
/// out of `element`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct HexFace {
    pub element: u32,
    pub local: u8,
}

/// A named set of hexahedron faces (from a gmsh physical surface of quads).
#[derive(Debug, Clone, PartialEq)]
pub struct FaceSet {
    pub name: String,
    pub physical_tag: i32,
    pub faces: Vec<HexFace>,
    /// gmsh element tag of the quad each face came from (same order as `faces`).
    pub quad_tags: Vec<u64>,
}

/// The whole mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Reference coordinates.
    pub nodes: Vec<Vec3>,
    /// Hexahedra in gmsh / VTK_HEXAHEDRON node order (bottom face 0-1-2-3
    /// counter-clockwise seen from above, then top face 4-5-6-7).
    pub hexes: Vec<[u32; 8]>,
    /// Body index of each hexahedron.
    pub hex_body: Vec<u32>,
    pub bodies: Vec<Body>,
    pub node_sets: Vec<NodeSet>,
    pub face_sets: Vec<FaceSet>,
    /// gmsh node tag of each node.
    pub node_tags: Vec<u64>,
    /// gmsh element tag of each hexahedron.
    pub element_tags: Vec<u64>,
}

impl Mesh {
    pub fn node_set(&self, name: &str) -> Option<&NodeSet> {
        self.node_sets.iter().find(|s| s.name == name)
    }

    pub fn face_set(&self, name: &str) -> Option<&FaceSet> {
        self.face_sets.iter().find(|s| s.name == name)
    }

    pub fn body(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Nodes of a face, ordered so that their right-hand rule gives the outward normal.
    pub fn face_nodes(&self, f: HexFace) -> [u32; 4] {
        hex_face_nodes(&self.hexes[f.element as usize], f.local as usize)
    }

    /// The element coordinates of hexahedron `e`.
    pub fn hex_coords(&self, e: usize) -> [Vec3; 8] {
        self.hexes[e].map(|n| self.nodes[n as usize])
    }

    /// Names of all sets of a kind, for error messages ("expected one of ...").
    pub fn node_set_names(&self) -> Vec<&str> {
        self.node_sets.iter().map(|s| s.name.as_str()).collect()
    }

    pub fn face_set_names(&self) -> Vec<&str> {
        self.face_sets.iter().map(|s| s.name.as_str()).collect()
    }

    pub fn body_names(&self) -> Vec<&str> {
        self.bodies.iter().map(|s| s.name.as_str()).collect()
    }
}
