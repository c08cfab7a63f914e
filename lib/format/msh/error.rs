//! Why a file could not be read; every message starts with the place in the file.

/// The MSH versions this reader understands.
pub const SUPPORTED: &str = "2.2, 4.1";

/// Why a file could not be read. Messages start with the place in the file.
#[derive(Debug, thiserror::Error)]
pub enum MshError {
    #[error("{path}: cannot read: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{file}: not a gmsh MSH file: no $MeshFormat header{found}")]
    NotMsh { file: String, found: String },
    #[error("{at}: MSH version `{found}` is not supported (supported: {supported}); re-export it from gmsh with `-format msh41` or `-format msh22`", supported = SUPPORTED)]
    UnsupportedVersion { at: String, found: String },
    #[error("{at}: expected `{expected}` before end of file")]
    Truncated { at: String, expected: String },
    #[error("{at}: bad number `{token}` (expected {what})")]
    BadNumber { at: String, token: String, what: String },
    #[error("{at}: {what}")]
    CountMismatch { at: String, what: String },
    #[error("{at}: element {element} refers to node {node}, which is not in $Nodes")]
    UnknownNode { at: String, element: u64, node: u64 },
    #[error("{at}: the mesh holds {count} {type_name} elements (gmsh type {type_number}){others}; only 8-node hexahedra (gmsh type 5) are supported")]
    UnsupportedElement { at: String, count: u64, type_name: String, type_number: i32, others: String },
    #[error("{file}: the mesh holds no 8-node hexahedra (gmsh type 5); gmsh saves only the elements of physical groups: put the volumes in a physical volume (or set Mesh.SaveAll=1)")]
    NoHexes { file: String },
    #[error("{at}: element {element} is a twisted or degenerate hexahedron: its corner Jacobians {jacobians:?} have mixed signs or zeros (mirrored hexahedra, all negative, are reordered; twisted ones cannot be)")]
    TwistedElement { at: String, element: u64, jacobians: [f64; 8] },
    #[error("{at}: quad {quad} of physical surface `{group}` is not a face of any hexahedron")]
    FaceNotOnHex { at: String, quad: u64, group: String },
    #[error("{at}: physical surface `{group}` holds element {element}, a {type_name} (gmsh type {type_number}): face sets must be 4-node quads (gmsh type 3) that are faces of the hexahedra")]
    NonQuadFace { at: String, group: String, element: u64, type_name: String, type_number: i32 },
    #[error("{at}: physical name `{name}` is given to two groups, {first} and {second}: names must be unique across dimensions")]
    DuplicateName { at: String, name: String, first: String, second: String },
    #[error("{file}: no {section} section")]
    Missing { file: String, section: &'static str },
    #[error("{at}: {what}")]
    Malformed { at: String, what: String },
}
