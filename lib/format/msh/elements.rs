//! `$Elements`: element tags, types, node tags, and (in MSH 2.2) physical tags.
//!
//! MSH 2.2 ASCII, one element per line:
//! ```text
//! $Elements
//! number-of-elements
//! elm-number elm-type number-of-tags tag ... node-number-list
//! $EndElements
//! ```
//! The first tag is the physical group (0 or absent: none), the second the
//! elementary entity. MSH 2.2 binary groups elements of one type with the same
//! number of tags after a header `elm-type number-of-elements number-of-tags`
//! (3 int), each element then being `elm-number tag... node...` (int).
//!
//! MSH 4.1, in blocks (one per entity and type):
//! ```text
//! $Elements
//! numEntityBlocks numElements minElementTag maxElementTag   (size_t)
//! entityDim entityTag elementType numElementsInBlock        (int int int size_t)
//!   elementTag nodeTag ...                                  (size_t)
//! $EndElements
//! ```
//! The physical groups of a 4.1 element are those of its entity (`$Entities`).
//!
//! While reading, each 8-node hexahedron is checked for inversion (see
//! [`super::parse_msh`]), elements of physical groups feed the group's node list
//! and, for physical surfaces, its quads; other volume types are counted for the
//! error that refuses them.

use std::collections::hash_map::Entry;
use std::collections::{BTreeMap, HashMap};

use super::cursor::Cursor;
use super::entities::EntityPhysicals;
use super::header::Version;
use super::nodes::Nodes;
use super::types::{element_type, ElementType, HEX8, QUAD4};
use super::MshError;
use crate::mesh::topology::{corner_jacobians, flip_hex};

/// A 4-node quadrangle of a physical surface.
#[derive(Debug, Clone)]
pub(super) struct Quad {
    pub tag: u64,
    /// Node indices (file order), in the quad's own order.
    pub nodes: [u32; 4],
    pub offset: usize,
}

/// The elements of one physical group `(dim, tag)`.
#[derive(Debug, Clone)]
pub(super) struct Group {
    pub dim: u8,
    pub tag: i32,
    /// Node indices of its elements other than hexahedra, with repeats.
    pub nodes: Vec<u32>,
    /// Its hexahedra (indices into [`Elements::hexes`]).
    pub hexes: Vec<u32>,
    /// Its quads (physical surfaces only).
    pub quads: Vec<Quad>,
    /// First element of a physical surface that is not a 4-node quad: (tag, type, offset).
    pub non_quad: Option<(u64, i32, usize)>,
}

/// An element being read: where it starts, its tag and type.
#[derive(Debug, Clone, Copy)]
struct Element {
    offset: usize,
    tag: u64,
    ty: ElementType,
}

/// Everything the `$Elements` section gives.
#[derive(Debug, Default)]
pub(super) struct Elements {
    /// Hexahedra as node indices (file order), already reordered when mirrored.
    pub hexes: Vec<[u32; 8]>,
    pub hex_tags: Vec<u64>,
    /// Physical volume tag of each hexahedron, 0 for none.
    pub hex_volume: Vec<i32>,
    /// Tags of mirrored hexahedra that were reordered.
    pub flipped: Vec<u64>,
    pub groups: Vec<Group>,
    group_index: HashMap<(u8, i32), usize>,
    /// The group looked up last: consecutive elements share their groups.
    last_group: Option<((u8, i32), usize)>,
    /// Volume elements other than hex8: type → (count, offset of the first).
    unsupported: BTreeMap<i32, (u64, usize)>,
    /// MSH 2.2 only: sorted nodes → hexahedron, to keep a hexahedron written
    /// once per physical group only once.
    seen: Option<HashMap<[u32; 8], u32>>,
    /// Repeated hexahedra: count and the first (tag, tag of the first copy).
    repeated: (u64, Option<(u64, u64)>),
    pub warnings: Vec<String>,
    /// Node indices of the element being read.
    buf: Vec<u32>,
}

impl Elements {
    fn group(&mut self, dim: u8, tag: i32) -> &mut Group {
        let i = match self.last_group {
            Some((key, i)) if key == (dim, tag) => i,
            _ => {
                let n = self.groups.len();
                let i = *self.group_index.entry((dim, tag)).or_insert(n);
                if i == n {
                    self.groups.push(Group {
                        dim,
                        tag,
                        nodes: Vec::new(),
                        hexes: Vec::new(),
                        quads: Vec::new(),
                        non_quad: None,
                    });
                }
                self.last_group = Some(((dim, tag), i));
                i
            }
        };
        &mut self.groups[i]
    }

    /// Read `ty.nodes` node tags and map them to indices into `self.buf`.
    fn read_nodes(
        &mut self,
        cur: &mut Cursor,
        nodes: &Nodes,
        ty: &ElementType,
        element: u64,
        offset: usize,
        v2_binary_ints: bool,
    ) -> Result<(), MshError> {
        self.buf.clear();
        for _ in 0..ty.nodes {
            let node = if v2_binary_ints {
                let at = cur.pos;
                let t = cur.bin_i32()?;
                u64::try_from(t).map_err(|_| cur.malformed(at, format!("element {element}: negative node tag {t}")))?
            } else {
                cur.size_t("a node tag")?
            };
            let index = nodes.map.get(node).ok_or_else(|| MshError::UnknownNode { at: cur.at(offset), element, node })?;
            self.buf.push(index);
        }
        Ok(())
    }

    /// File one element whose nodes are in `self.buf`; `dim` is the dimension of
    /// its physical groups.
    fn add(&mut self, cur: &Cursor, nodes: &Nodes, element: Element, dim: u8, physicals: &[i32]) -> Result<(), MshError> {
        let Element { offset, tag, ty } = element;
        if ty.number == HEX8 {
            let mut hex = [0u32; 8];
            hex.copy_from_slice(&self.buf[..8]);
            let x = hex.map(|n| nodes.coords[n as usize]);
            let jacobians = corner_jacobians(&x);
            let valid = jacobians.iter().all(|&j| j > 0.0);
            if !valid {
                if jacobians.iter().all(|&j| j < 0.0) {
                    hex = flip_hex(&hex);
                    self.flipped.push(tag);
                } else {
                    return Err(MshError::TwistedElement { at: cur.at(offset), element: tag, jacobians });
                }
            }
            let mut index = self.hexes.len() as u32;
            if let Some(seen) = &mut self.seen {
                let mut key = hex;
                key.sort_unstable();
                match seen.entry(key) {
                    Entry::Occupied(e) => {
                        index = *e.get();
                        self.repeated.0 += 1;
                        let first = self.hex_tags[index as usize];
                        self.repeated.1.get_or_insert((tag, first));
                    }
                    Entry::Vacant(v) => {
                        v.insert(index);
                    }
                }
            }
            if index as usize == self.hexes.len() {
                self.hexes.push(hex);
                self.hex_tags.push(tag);
                self.hex_volume.push(physicals.first().copied().unwrap_or(0));
            }
            for &p in physicals {
                let g = self.group(dim, p);
                if g.hexes.last() != Some(&index) {
                    g.hexes.push(index);
                }
            }
            return Ok(());
        } else if ty.dim == 3 {
            let e = self.unsupported.entry(ty.number).or_insert((0, offset));
            e.0 += 1;
            return Ok(());
        }
        let is_quad = ty.number == QUAD4;
        let buf = std::mem::take(&mut self.buf);
        for &p in physicals {
            let g = self.group(dim, p);
            g.nodes.extend_from_slice(&buf);
            if dim == 2 {
                if is_quad {
                    g.quads.push(Quad { tag, nodes: [buf[0], buf[1], buf[2], buf[3]], offset });
                } else if g.non_quad.is_none() {
                    g.non_quad = Some((tag, ty.number, offset));
                }
            }
        }
        self.buf = buf;
        Ok(())
    }

    /// After the section: refuse other volume types, summarise repeats.
    fn finish(&mut self, cur: &Cursor) -> Result<(), MshError> {
        if let Some((&number, &(count, offset))) = self.unsupported.iter().next() {
            let describe = |n: i32| element_type(n).map_or_else(|| format!("type {n}"), |t| t.describe());
            let others: Vec<String> = self
                .unsupported
                .iter()
                .skip(1)
                .map(|(&n, &(c, _))| format!("{c} {} (gmsh type {n})", describe(n)))
                .collect();
            let others = if others.is_empty() { String::new() } else { format!(", and also {}", others.join(", ")) };
            return Err(MshError::UnsupportedElement {
                at: cur.at(offset),
                count,
                type_name: describe(number),
                type_number: number,
                others,
            });
        }
        if let (n, Some((tag, first))) = self.repeated {
            self.warnings.push(format!(
                "{n} hexahedra repeat an earlier one with the same nodes (e.g. element {tag} repeats element {first}): \
                 MSH 2.2 writes an element once per physical group; each is kept once, in the body of its first physical volume"
            ));
        }
        Ok(())
    }
}

pub(super) fn parse(
    cur: &mut Cursor,
    version: Version,
    nodes: &Nodes,
    entities: Option<&EntityPhysicals>,
) -> Result<Elements, MshError> {
    cur.section_end = "$EndElements";
    let mut out = Elements::default();
    match version {
        Version::V2_2 => {
            out.seen = Some(HashMap::new());
            if cur.binary {
                parse_v2_binary(cur, nodes, &mut out)?;
            } else {
                parse_v2_ascii(cur, nodes, &mut out)?;
            }
        }
        Version::V4_1 => parse_v4(cur, nodes, entities, &mut out)?,
    }
    cur.expect_end()?;
    out.finish(cur)?;
    Ok(out)
}

fn known_type(cur: &Cursor, offset: usize, number: i32) -> Result<ElementType, MshError> {
    element_type(number).ok_or_else(|| {
        cur.malformed(offset, format!("unknown gmsh element type {number} (this reader knows types 1-33, 36-66, 71-75, 79-105, 118-124)"))
    })
}

/// The physical group of an MSH 2.2 element: its first tag, unless absent or 0.
fn physical_v2(tags: &[i32]) -> &[i32] {
    match tags.first() {
        Some(&p) if p != 0 => &tags[..1],
        _ => &[],
    }
}

fn parse_v2_ascii(cur: &mut Cursor, nodes: &Nodes, out: &mut Elements) -> Result<(), MshError> {
    let count = cur.ascii_u64("the number of elements")?;
    let mut tags: Vec<i32> = Vec::new();
    for _ in 0..count {
        cur.skip_whitespace();
        let offset = cur.pos;
        let tag = cur.ascii_u64("an element number")?;
        let type_at = cur.pos;
        let ty = cur.ascii_i32("an element type")?;
        let ty = known_type(cur, type_at, ty)?;
        let num_tags = cur.ascii_u64("the number of tags")?;
        tags.clear();
        for _ in 0..num_tags {
            tags.push(cur.ascii_i32("an element tag")?);
        }
        out.read_nodes(cur, nodes, &ty, tag, offset, false)?;
        out.add(cur, nodes, Element { offset, tag, ty }, ty.dim, physical_v2(&tags))?;
    }
    Ok(())
}

fn parse_v2_binary(cur: &mut Cursor, nodes: &Nodes, out: &mut Elements) -> Result<(), MshError> {
    let count = cur.ascii_u64("the number of elements")?;
    cur.finish_line()?;
    let mut read = 0u64;
    let mut tags: Vec<i32> = Vec::new();
    while read < count {
        let block_at = cur.pos;
        let ty = cur.bin_i32()?;
        let ty = known_type(cur, block_at, ty)?;
        let in_block = cur.bin_i32()?;
        let num_tags = cur.bin_i32()?;
        let (Ok(in_block), Ok(num_tags)) = (u64::try_from(in_block), usize::try_from(num_tags)) else {
            return Err(cur.malformed(block_at, format!("element block header with negative counts ({in_block} elements, {num_tags} tags)")));
        };
        if read + in_block > count {
            return Err(MshError::CountMismatch {
                at: cur.at(block_at),
                what: format!(
                    "element blocks hold more than the {count} elements announced (at least {})",
                    read + in_block
                ),
            });
        }
        for _ in 0..in_block {
            let offset = cur.pos;
            let t = cur.bin_i32()?;
            let tag = u64::try_from(t).map_err(|_| cur.malformed(offset, format!("negative element number {t}")))?;
            tags.clear();
            for _ in 0..num_tags {
                tags.push(cur.bin_i32()?);
            }
            out.read_nodes(cur, nodes, &ty, tag, offset, true)?;
            out.add(cur, nodes, Element { offset, tag, ty }, ty.dim, physical_v2(&tags))?;
        }
        read += in_block;
    }
    Ok(())
}

fn parse_v4(
    cur: &mut Cursor,
    nodes: &Nodes,
    entities: Option<&EntityPhysicals>,
    out: &mut Elements,
) -> Result<(), MshError> {
    let header_at = cur.pos;
    let num_blocks = cur.size_t("the number of element blocks")?;
    let num_elements = cur.size_t("the number of elements")?;
    let _min_tag = cur.size_t("the minimum element tag")?;
    let _max_tag = cur.size_t("the maximum element tag")?;
    let mut read = 0u64;
    let mut warned: Vec<(u8, i32)> = Vec::new();
    for _ in 0..num_blocks {
        let block_at = cur.pos;
        let entity_dim = cur.int("an entity dimension")?;
        let entity_tag = cur.int("an entity tag")?;
        let type_at = cur.pos;
        let ty = cur.int("an element type")?;
        let ty = known_type(cur, type_at, ty)?;
        let in_block = cur.size_t("the number of elements in the block")?;
        if entity_dim != i32::from(ty.dim) {
            return Err(cur.malformed(
                block_at,
                format!(
                    "element block of entity (dimension {entity_dim}, tag {entity_tag}) holds {} elements (gmsh type {}), of dimension {}",
                    ty.describe(),
                    ty.number,
                    ty.dim
                ),
            ));
        }
        let dim = ty.dim;
        let physicals: Vec<i32> = match entities {
            Some(e) => e.get(&(dim, entity_tag)).cloned().ok_or_else(|| {
                cur.malformed(block_at, format!("element block refers to entity (dimension {dim}, tag {entity_tag}), which is not in $Entities"))
            })?,
            None => Vec::new(),
        };
        if ty.number == HEX8 && physicals.len() > 1 && !warned.contains(&(dim, entity_tag)) {
            warned.push((dim, entity_tag));
            out.warnings.push(format!(
                "volume entity {entity_tag} belongs to several physical volumes {physicals:?}: its hexahedra go to the body of the first, {}, and to the node sets of all",
                physicals[0]
            ));
        }
        if cur.binary {
            // The block is `in_block × (1 + nodes)` size_t: take it whole.
            let width = cur.size_t;
            let record = (1 + ty.nodes) * width;
            let start = cur.pos;
            let bytes = usize::try_from(in_block)
                .ok()
                .and_then(|n| n.checked_mul(record))
                .filter(|&b| b <= cur.bytes.len() - start)
                .ok_or_else(|| cur.truncated())?;
            let block = cur.take(bytes)?;
            for (k, rec) in block.chunks_exact(record).enumerate() {
                let offset = start + k * record;
                let tag = cur.decode_size_t(rec);
                out.buf.clear();
                for word in rec[width..].chunks_exact(width) {
                    let node = cur.decode_size_t(word);
                    let index = nodes.map.get(node).ok_or_else(|| MshError::UnknownNode { at: cur.at(offset), element: tag, node })?;
                    out.buf.push(index);
                }
                out.add(cur, nodes, Element { offset, tag, ty }, dim, &physicals)?;
            }
        } else {
            for _ in 0..in_block {
                let offset = cur.pos;
                let tag = cur.size_t("an element tag")?;
                out.read_nodes(cur, nodes, &ty, tag, offset, false)?;
                out.add(cur, nodes, Element { offset, tag, ty }, dim, &physicals)?;
            }
        }
        read += in_block;
    }
    if read != num_elements {
        return Err(MshError::CountMismatch {
            at: cur.at(header_at),
            what: format!("the $Elements header announces {num_elements} elements, its {num_blocks} blocks hold {read}"),
        });
    }
    Ok(())
}
