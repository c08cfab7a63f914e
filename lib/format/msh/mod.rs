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
//! What becomes of the file ([`Mesh`](crate::mesh::Mesh)):
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
//!   ([`Mesh::bodies`](crate::mesh::Mesh::bodies), [`Mesh::hex_body`](crate::mesh::Mesh::hex_body)). In MSH 2.2 an element's physical
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
//!   ([`Mesh::node_tags`](crate::mesh::Mesh::node_tags), [`Mesh::element_tags`](crate::mesh::Mesh::element_tags)).
//!
//! Every error message starts with `<file>:<line>:` (ASCII) or
//! `<file>: byte <offset>:` (binary) when it has a place in the file, else with
//! `<file>:`. Malformed input never panics.
//!
//! | file | concept |
//! |------|---------|
//! | `read` | the file read section by section, then the mesh built ([`parse_msh`], [`read_msh`]) |
//! | `cursor` | the position in the file, ASCII or binary, and the place every message names |
//! | `header` | `$MeshFormat`: version, encoding, byte order, word sizes |
//! | `physical_names` | `$PhysicalNames` |
//! | `entities` | `$Entities` (4.1): the physical groups of each entity |
//! | `nodes` | `$Nodes` |
//! | `elements` | `$Elements` |
//! | `types` | the gmsh element types: number → name, dimension, nodes |
//! | `build` | the [`Mesh`](crate::mesh::Mesh) from the sections, and the [`ImportReport`] |
//! | `error` | [`MshError`], and the versions read ([`SUPPORTED`]) |

mod build;
mod cursor;
mod elements;
mod error;
mod entities;
mod header;
mod nodes;
mod physical_names;
mod read;
mod types;

pub use build::{ImportReport, UNNAMED_VOLUME};
pub use error::{MshError, SUPPORTED};
pub use read::{parse_msh, read_msh};

#[cfg(test)]
mod tests;
