//! Our gmsh MSH reader: MSH 2.2 and 4.1, ASCII and binary, one parser per section.
//!
//! A file is a sequence of sections, each between a `$Name` line and an
//! `$EndName` line. The first must be `$MeshFormat` ([`header`]); we read
//! `$PhysicalNames` ([`physical_names`]), `$Entities` (4.1 only, [`entities`]),
//! `$Nodes` ([`nodes`]) and `$Elements` ([`elements`]), and skip every other
//! section (`$Periodic`, `$NodeData`, `$ElementData`, `$Comments`, unknown ones)
//! up to its `$End...` line. Partitioned files (`$PartitionedEntities`) are
//! refused.
//!
//! What becomes of the file ([`Mesh`]):
//! - **Hexahedra.** 8-node hexahedra (gmsh type 5) are the only volume elements.
//!   Any other volume type (tetrahedra, prisms, pyramids, 20- or 27-node
//!   hexahedra, ...) is an error naming the type and how many there are; so is a
//!   file without hexahedra.
//! - **Inverted hexahedra.** The Jacobian of the trilinear map is evaluated at the
//!   8 corners ([`corner_jacobians`](crate::mesh::topology::corner_jacobians)). A
//!   *mirrored* hexahedron (all 8 negative: node order of the wrong handedness)
//!   is reordered by swapping its bottom and top faces
//!   ([`flip_hex`](crate::mesh::topology::flip_hex)) and reported in
//!   [`ImportReport::flipped_elements`]. A *twisted* or degenerate one (mixed
//!   signs, or any zero) cannot be repaired by reordering and is refused.
//! - **Bodies.** One per physical volume holding hexahedra, in tag order
//!   ([`Mesh::bodies`], [`Mesh::hex_body`]). In MSH 2.2 an element's physical
//!   group is its first tag; in 4.1 it is the physical tag of its entity in
//!   `$Entities`. A hexahedron in several physical volumes belongs to the first
//!   (warned). Hexahedra in none (saved with `Mesh.SaveAll=1`) form a body named
//!   `unnamed_volume`, last.
//! - **Node sets.** One per physical group of any dimension: the sorted, unique
//!   nodes of its elements.
//! - **Face sets.** One per physical surface, made of 4-node quads (gmsh type 3),
//!   each matched to the hexahedron face with the same nodes; the stored
//!   [`HexFace`](crate::mesh::HexFace) has its normal out of that hexahedron. A
//!   quad on two hexahedra (an interior face) goes to the one whose outward
//!   normal agrees with the quad's node order (right-hand rule), with a warning.
//!   A quad that is no hexahedron face, or a triangle (any non-quad) in a
//!   physical surface, is an error.
//! - **Names.** From `$PhysicalNames`; an unnamed group is `physical_<dim>_<tag>`.
//!   Two groups with one name (even of different dimensions) are an error.
//! - **Nodes.** Nodes used by no hexahedron are dropped
//!   ([`ImportReport::dropped_nodes`]) and the rest renumbered in file order;
//!   coordinates are copied bit for bit (ASCII through Rust's correctly rounded
//!   `str::parse::<f64>`). gmsh node and hexahedron tags are kept
//!   ([`Mesh::node_tags`], [`Mesh::element_tags`]).
//!
//! Every error message starts with `<file>:<line>:` (ASCII) or
//! `<file>: byte <offset>:` (binary) when it has a place in the file, else with
//! `<file>:`. Malformed input never panics.

mod build;
mod cursor;
mod elements;
mod entities;
mod header;
mod nodes;
mod physical_names;
mod types;

#[cfg(test)]
mod tests;

use std::path::Path;

use crate::format::stage::read_input;
use crate::mesh::Mesh;

pub use build::UNNAMED_VOLUME;
pub use header::SUPPORTED;

use cursor::{show, Cursor};
use header::Version;

/// What the import did besides building the mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ImportReport {
    /// `"2.2 ASCII"`, `"4.1 binary"`, ...
    pub version: String,
    /// gmsh tags of the nodes used by no hexahedron, which were dropped.
    pub dropped_nodes: Vec<u64>,
    /// gmsh tags of the mirrored hexahedra that were reordered.
    pub flipped_elements: Vec<u64>,
    /// What was read but not as expected, each naming the file (and the line where
    /// there is one): printed by every caller, even when asked to be quiet.
    pub warnings: Vec<String>,
}

/// Why a file could not be read. Messages start with the place in the file.
#[derive(Debug, thiserror::Error)]
pub enum MshError {
    #[error("{path}: cannot read: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{file}: not a gmsh MSH file: no $MeshFormat header{found}")]
    NotMsh { file: String, found: String },
    #[error("{at}: MSH version {found} is not supported (supported: {supported}); re-export it from gmsh with `-format msh41` or `-format msh22`", supported = SUPPORTED)]
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

/// Sections we know and deliberately skip (no warning).
const SKIPPED: [&str; 8] = [
    "$Periodic",
    "$NodeData",
    "$ElementData",
    "$ElementNodeData",
    "$Comments",
    "$InterpolationScheme",
    "$GhostElements",
    "$Parametrizations",
];

/// Parse an MSH file held in memory; `source_name` is used in messages.
pub fn parse_msh(source_name: &str, bytes: &[u8]) -> Result<(Mesh, ImportReport), MshError> {
    let mut cur = Cursor::new(source_name, bytes);
    let header = header::parse(&mut cur)?;
    let mut names = Vec::new();
    let mut entities = None;
    let mut nodes = None;
    let mut elements = None;
    let mut warnings = Vec::new();
    loop {
        cur.skip_whitespace();
        if cur.eof() {
            break;
        }
        let at = cur.pos;
        let name = cur.rest_of_line().trim_ascii();
        let twice = |cur: &Cursor| cur.malformed(at, format!("second `{}` section (only one is supported)", show(name)));
        match name {
            b"$PhysicalNames" => physical_names::parse(&mut cur, &mut names)?,
            b"$Entities" if header.version == Version::V4_1 => {
                if entities.is_some() {
                    return Err(twice(&cur));
                }
                entities = Some(entities::parse(&mut cur)?);
            }
            b"$Nodes" => {
                if nodes.is_some() {
                    return Err(twice(&cur));
                }
                nodes = Some(nodes::parse(&mut cur, header.version)?);
            }
            b"$Elements" => {
                let Some(n) = &nodes else {
                    return Err(cur.malformed(at, "$Elements section before the $Nodes section"));
                };
                if elements.is_some() {
                    return Err(twice(&cur));
                }
                if header.version == Version::V4_1 && entities.is_none() {
                    warnings.push(format!(
                        "{}: no $Entities section before $Elements: physical groups are unknown, every hexahedron goes to `{UNNAMED_VOLUME}`",
                        cur.at(at)
                    ));
                }
                elements = Some(elements::parse(&mut cur, header.version, n, entities.as_ref())?);
            }
            b"$MeshFormat" => return Err(twice(&cur)),
            b"$PartitionedEntities" => {
                return Err(cur.malformed(at, "partitioned meshes ($PartitionedEntities) are not supported: save the mesh without partitions"));
            }
            _ if name.first() == Some(&b'$') && !name.starts_with(b"$End") => {
                let section = String::from_utf8_lossy(name).into_owned();
                if !SKIPPED.contains(&section.as_str()) {
                    warnings.push(format!("{}: skipped unknown section `{section}`", cur.at(at)));
                }
                cur.skip_section(&section)?;
            }
            _ => {
                return Err(cur.malformed(at, format!("expected a section header such as `$Nodes`, found `{}`", show(name))));
            }
        }
    }
    let nodes = nodes.ok_or(MshError::Missing { file: source_name.to_string(), section: "$Nodes" })?;
    let elements = elements.ok_or(MshError::Missing { file: source_name.to_string(), section: "$Elements" })?;
    build::build(&cur, header, nodes, elements, names, warnings)
}

/// Read and parse an MSH file; the path `-` reads standard input.
pub fn read_msh(path: &Path) -> Result<(Mesh, ImportReport), MshError> {
    let shown = path.display().to_string();
    let bytes = read_input(path).map_err(|source| MshError::Io { path: shown.clone(), source })?;
    parse_msh(&shown, &bytes)
}
