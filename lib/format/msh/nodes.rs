//! `$Nodes`: node tags and coordinates.
//!
//! MSH 2.2:
//! ```text
//! $Nodes
//! number-of-nodes                 (ASCII, also in binary files)
//! node-number x y z               (binary: int, 3 double)
//! ...
//! $EndNodes
//! ```
//! MSH 4.1, in blocks (one per entity); tags first, then coordinates:
//! ```text
//! $Nodes
//! numEntityBlocks numNodes minNodeTag maxNodeTag      (size_t)
//! entityDim entityTag parametric numNodesInBlock      (int int int size_t)
//!   nodeTag                                           (size_t) × numNodesInBlock
//!   x y z [u [v [w]]]                                 (double) × numNodesInBlock
//! ...
//! $EndNodes
//! ```
//! `u v w` are present when `parametric` is 1, one per entity dimension; we skip them.
//!
//! Tags are arbitrary positive integers, possibly sparse and unordered: they map
//! to 0-based indices in file order through [`TagMap`].

use std::collections::HashMap;

use super::cursor::Cursor;
use super::header::Version;
use super::MshError;
use crate::mesh::Vec3;

/// gmsh node tag → 0-based index in file order.
#[derive(Debug)]
pub(super) enum TagMap {
    /// `index[tag]`, `u32::MAX` for tags not present: when tags are dense enough.
    Dense(Vec<u32>),
    Sparse(HashMap<u64, u32>),
}

impl TagMap {
    /// Build the map; `Err(tag)` for a tag that appears twice.
    pub fn build(tags: &[u64]) -> Result<Self, u64> {
        let max = tags.iter().copied().max().unwrap_or(0);
        let dense_limit = 4 * tags.len() as u64 + 1024;
        if max <= dense_limit {
            let mut index = vec![u32::MAX; max as usize + 1];
            for (i, &t) in tags.iter().enumerate() {
                let slot = &mut index[t as usize];
                if *slot != u32::MAX {
                    return Err(t);
                }
                *slot = i as u32;
            }
            Ok(Self::Dense(index))
        } else {
            let mut index = HashMap::with_capacity(tags.len());
            for (i, &t) in tags.iter().enumerate() {
                if index.insert(t, i as u32).is_some() {
                    return Err(t);
                }
            }
            Ok(Self::Sparse(index))
        }
    }

    #[inline]
    pub fn get(&self, tag: u64) -> Option<u32> {
        match self {
            Self::Dense(v) => usize::try_from(tag).ok().and_then(|t| v.get(t)).copied().filter(|&i| i != u32::MAX),
            Self::Sparse(m) => m.get(&tag).copied(),
        }
    }
}

/// The nodes of the file, in file order.
#[derive(Debug)]
pub(super) struct Nodes {
    pub tags: Vec<u64>,
    pub coords: Vec<Vec3>,
    pub map: TagMap,
}

pub(super) fn parse(cur: &mut Cursor, version: Version) -> Result<Nodes, MshError> {
    cur.section_end = "$EndNodes";
    let section = cur.pos;
    let (tags, coords) = match version {
        Version::V2_2 => parse_v2(cur)?,
        Version::V4_1 => parse_v4(cur)?,
    };
    cur.expect_end()?;
    if tags.len() >= u32::MAX as usize {
        return Err(cur.malformed(section, format!("{} nodes are more than this reader indexes (u32)", tags.len())));
    }
    let map = TagMap::build(&tags)
        .map_err(|t| cur.malformed(section, format!("node tag {t} appears twice in the $Nodes section")))?;
    Ok(Nodes { tags, coords, map })
}

type TagsAndCoords = (Vec<u64>, Vec<Vec3>);

fn parse_v2(cur: &mut Cursor) -> Result<TagsAndCoords, MshError> {
    let count = cur.ascii_u64("the number of nodes")?;
    if cur.binary {
        cur.finish_line()?;
    }
    let cap = cur.capacity(count, if cur.binary { 28 } else { 8 });
    let mut tags = Vec::with_capacity(cap);
    let mut coords = Vec::with_capacity(cap);
    for _ in 0..count {
        let at = cur.pos;
        let tag = if cur.binary {
            let t = cur.bin_i32()?;
            u64::try_from(t).map_err(|_| cur.malformed(at, format!("negative node tag {t}")))?
        } else {
            cur.ascii_u64("a node tag")?
        };
        let x = [cur.coordinate()?, cur.coordinate()?, cur.coordinate()?];
        tags.push(tag);
        coords.push(x);
    }
    Ok((tags, coords))
}

fn parse_v4(cur: &mut Cursor) -> Result<TagsAndCoords, MshError> {
    let header_at = cur.pos;
    let num_blocks = cur.size_t("the number of node blocks")?;
    let num_nodes = cur.size_t("the number of nodes")?;
    let _min_tag = cur.size_t("the minimum node tag")?;
    let _max_tag = cur.size_t("the maximum node tag")?;
    let cap = cur.capacity(num_nodes, if cur.binary { 32 } else { 8 });
    let mut tags = Vec::with_capacity(cap);
    let mut coords = Vec::with_capacity(cap);
    for _ in 0..num_blocks {
        let block_at = cur.pos;
        let entity_dim = cur.int("an entity dimension")?;
        let _entity_tag = cur.int("an entity tag")?;
        let parametric = cur.int("the parametric flag")?;
        let n = cur.size_t("the number of nodes in the block")?;
        let extra = match (parametric, entity_dim) {
            (0, 0..=3) => 0,
            (1, 0..=3) => entity_dim as usize,
            _ => {
                return Err(cur.malformed(
                    block_at,
                    format!("node block with entity dimension {entity_dim} and parametric flag {parametric}: expected dimension 0-3 and flag 0 or 1"),
                ))
            }
        };
        if cur.binary {
            read_v4_binary_block(cur, n, 3 + extra, &mut tags, &mut coords)?;
            continue;
        }
        let first = tags.len();
        for _ in 0..n {
            tags.push(cur.size_t("a node tag")?);
        }
        for _ in first..tags.len() {
            coords.push([cur.coordinate()?, cur.coordinate()?, cur.coordinate()?]);
            for _ in 0..extra {
                cur.double("a parametric coordinate")?;
            }
        }
    }
    if tags.len() as u64 != num_nodes {
        return Err(MshError::CountMismatch {
            at: cur.at(header_at),
            what: format!(
                "the $Nodes header announces {num_nodes} nodes, its {num_blocks} blocks hold {}",
                tags.len()
            ),
        });
    }
    Ok((tags, coords))
}

/// A binary 4.1 node block, read as two slices: `n` size_t tags, then `n ×
/// values` doubles (x y z and any parametric coordinates).
fn read_v4_binary_block(
    cur: &mut Cursor,
    n: u64,
    values: usize,
    tags: &mut Vec<u64>,
    coords: &mut Vec<Vec3>,
) -> Result<(), MshError> {
    let remaining = cur.bytes.len() - cur.pos;
    let n = usize::try_from(n)
        .ok()
        .filter(|&n| n.checked_mul(cur.size_t + 8 * values).is_some_and(|b| b <= remaining))
        .ok_or_else(|| cur.truncated())?;
    let tag_bytes = cur.take(n * cur.size_t)?;
    tags.extend(tag_bytes.chunks_exact(cur.size_t).map(|w| cur.decode_size_t(w)));
    let start = cur.pos;
    let record = 8 * values;
    let coord_bytes = cur.take(n * record)?;
    for (k, rec) in coord_bytes.chunks_exact(record).enumerate() {
        let x = [cur.decode_f64(rec), cur.decode_f64(&rec[8..]), cur.decode_f64(&rec[16..])];
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return Err(cur.malformed(start + k * record + 8 * i, format!("node coordinate {} is not a finite number", x[i])));
        }
        coords.push(x);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tag_maps() {
        let d = TagMap::build(&[5, 3, 9]).unwrap();
        assert!(matches!(d, TagMap::Dense(_)));
        assert_eq!((d.get(5), d.get(3), d.get(9), d.get(4), d.get(100)), (Some(0), Some(1), Some(2), None, None));
        let s = TagMap::build(&[1 << 40, 2]).unwrap();
        assert!(matches!(s, TagMap::Sparse(_)));
        assert_eq!((s.get(1 << 40), s.get(2), s.get(3)), (Some(0), Some(1), None));
        assert_eq!(TagMap::build(&[1, 2, 1]).unwrap_err(), 1);
    }

    #[test]
    fn v4_parametric_nodes_and_bit_exact_coordinates() {
        let text = b"1 2 1 2\n1 1 1 2\n1\n2\n0.1 0.2 0.3 0.5\n1e-300 -0 3.0000000000000004 0.25\n$EndNodes\n";
        let mut c = Cursor::new("t.msh", text);
        let n = parse(&mut c, Version::V4_1).unwrap();
        assert_eq!(n.tags, vec![1, 2]);
        assert_eq!(n.coords[0], [0.1, 0.2, 0.3]);
        assert_eq!(n.coords[1][0].to_bits(), 1e-300f64.to_bits());
        assert_eq!(n.coords[1][1].to_bits(), (-0.0f64).to_bits());
        assert_eq!(n.coords[1][2].to_bits(), 3.0000000000000004f64.to_bits());
    }

    #[test]
    fn v4_block_sum_must_match_header() {
        let text = b"1 3 1 3\n3 1 0 2\n1\n2\n0 0 0\n1 1 1\n$EndNodes\n";
        let mut c = Cursor::new("t.msh", text);
        let e = parse(&mut c, Version::V4_1).unwrap_err().to_string();
        assert_eq!(e, "t.msh:1: the $Nodes header announces 3 nodes, its 1 blocks hold 2");
    }

    #[test]
    fn duplicate_node_tag() {
        let mut c = Cursor::new("t.msh", b"2\n1 0 0 0\n1 1 1 1\n$EndNodes\n");
        let e = parse(&mut c, Version::V2_2).unwrap_err().to_string();
        assert_eq!(e, "t.msh:1: node tag 1 appears twice in the $Nodes section");
    }

    #[test]
    fn non_finite_coordinate() {
        let mut c = Cursor::new("t.msh", b"1\n1 0 nan 0\n$EndNodes\n");
        let e = parse(&mut c, Version::V2_2).unwrap_err().to_string();
        assert_eq!(e, "t.msh:2: bad number `nan` (expected a finite node coordinate)");
    }
}
