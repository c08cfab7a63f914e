//! The input of the limit surface: a quad control mesh, and what can be wrong with it.

/// A quad control mesh: faces list node indices `0..n_nodes`, each face's node cycle
/// giving its outward normal by the right-hand rule (consistent orientation).
#[derive(Debug, Clone, PartialEq)]
pub struct QuadControlMesh {
    pub n_nodes: usize,
    pub faces: Vec<[u32; 4]>,
}

/// Everything that can be wrong with a control mesh for the limit surface.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SubdivisionError {
    #[error("face {face} names node {node}, but the mesh has {n_nodes} nodes")]
    NodeOutOfRange { face: usize, node: u32, n_nodes: usize },
    #[error("face {face} lists node {node} twice")]
    RepeatedNode { face: usize, node: u32 },
    #[error("edge {nodes:?} is shared by {} faces {faces:?} (a manifold surface has at most 2)", faces.len())]
    NonManifoldEdge { nodes: [u32; 2], faces: Vec<usize> },
    #[error("faces {faces:?} both traverse edge {nodes:?} in the same direction (inconsistent orientation)")]
    InconsistentOrientation { nodes: [u32; 2], faces: [usize; 2] },
    #[error("the {faces} faces around node {node} do not form one fan (a fan of {fan} found): non-manifold vertex")]
    NonManifoldVertex { node: u32, faces: usize, fan: usize },
    #[error("interior node {node} has valence {valence}; Catmull–Clark needs at least 3")]
    ValenceTooLow { node: u32, valence: usize },
    #[error("interior node {node} has valence {valence} above the supported {max} (2N+8 ≤ 36 nodes)")]
    ValenceTooHigh { node: u32, valence: usize, max: usize },
    #[error("face {face} depends on {nodes} nodes, more than the {max} a basis can hold")]
    SupportTooLarge { face: usize, nodes: usize, max: usize },
    #[error(
        "the faces around the corners of face {face} do not form a Catmull–Clark stencil \
         (a mesh too small or folded onto itself there)"
    )]
    StencilIncomplete { face: usize },
    #[error("{got} control points for a mesh of {expected} nodes")]
    ControlPointCount { got: usize, expected: usize },
    #[error("control point {index} is not finite: {point:?}")]
    NonFiniteControlPoint { index: usize, point: [f64; 3] },
}
