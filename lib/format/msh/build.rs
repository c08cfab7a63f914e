//! From the parsed sections to a [`Mesh`]: names, bodies, node and face sets,
//! node compaction.

use std::collections::{BTreeSet, HashMap};

use super::cursor::Cursor;
use super::elements::{Elements, Group};
use super::header::Header;
use super::nodes::Nodes;
use super::physical_names::PhysicalName;
use super::types::element_type;
use super::error::MshError;
use crate::mesh::topology::{find_local_face, hex_face_nodes};
use crate::mesh::{Body, FaceSet, HexFace, Mesh, NodeSet};

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

/// Name of the body holding hexahedra that belong to no physical volume.
pub const UNNAMED_VOLUME: &str = "unnamed_volume";

const DIM_WORD: [&str; 4] = ["point", "curve", "surface", "volume"];

fn describe_group(dim: u8, tag: i32) -> String {
    format!("physical {} {tag}", DIM_WORD[usize::from(dim.min(3))])
}

/// Does the quad's node order run the same way round as the (outward) hex face?
/// `None` when the quad is not a cyclic ordering of the face at all.
fn same_orientation(face: [u32; 4], quad: [u32; 4]) -> Option<bool> {
    let p = face.iter().position(|&n| n == quad[0])?;
    let f = |k: usize| face[(p + k) % 4];
    if quad[1] == f(1) && quad[2] == f(2) && quad[3] == f(3) {
        Some(true)
    } else if quad[1] == f(3) && quad[2] == f(2) && quad[3] == f(1) {
        Some(false)
    } else {
        None
    }
}

/// Node → hexahedra incidence in compressed rows, for the nodes in `wanted` only
/// (the first node of each quad is enough to find its hexahedra).
struct Incidence {
    start: Vec<usize>,
    hexes: Vec<u32>,
}

impl Incidence {
    fn new(n_nodes: usize, hexes: &[[u32; 8]], wanted: &[bool]) -> Self {
        let mut start = vec![0usize; n_nodes + 1];
        for h in hexes {
            for &n in h {
                if wanted[n as usize] {
                    start[n as usize + 1] += 1;
                }
            }
        }
        for i in 0..n_nodes {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut list = vec![0u32; start[n_nodes]];
        for (e, h) in hexes.iter().enumerate() {
            for &n in h {
                if wanted[n as usize] {
                    list[fill[n as usize]] = e as u32;
                    fill[n as usize] += 1;
                }
            }
        }
        Self { start, hexes: list }
    }

    fn of(&self, node: u32) -> &[u32] {
        &self.hexes[self.start[node as usize]..self.start[node as usize + 1]]
    }
}

pub(super) fn build(
    cur: &Cursor,
    header: Header,
    nodes: Nodes,
    elements: Elements,
    names: Vec<PhysicalName>,
    located: Vec<String>,
) -> Result<(Mesh, ImportReport), MshError> {
    let file = cur.file;
    // `located` name their file and line already; these are of the whole file
    let Elements { mut hexes, hex_tags, hex_volume, flipped, groups, mut warnings, .. } = elements;
    if hexes.is_empty() {
        return Err(MshError::NoHexes { file: file.to_string() });
    }

    // Groups: every (dim, tag) named in $PhysicalNames or used by an element.
    let group_of: HashMap<(u8, i32), &Group> = groups.iter().map(|g| ((g.dim, g.tag), g)).collect();
    let keys: BTreeSet<(u8, i32)> = names.iter().map(|n| (n.dim, n.tag)).chain(group_of.keys().copied()).collect();
    let name_of = |dim: u8, tag: i32| -> String {
        names
            .iter()
            .find(|n| n.dim == dim && n.tag == tag)
            .map_or_else(|| format!("physical_{dim}_{tag}"), |n| n.name.clone())
    };
    let offset_of = |dim: u8, tag: i32| names.iter().find(|n| n.dim == dim && n.tag == tag).map(|n| n.offset);
    let mut taken: HashMap<String, (u8, i32)> = HashMap::new();
    for &(dim, tag) in &keys {
        let name = name_of(dim, tag);
        if let Some(&(d0, t0)) = taken.get(&name) {
            let at = offset_of(dim, tag).map_or_else(|| file.to_string(), |o| cur.at(o));
            return Err(MshError::DuplicateName {
                at,
                name,
                first: describe_group(d0, t0),
                second: describe_group(dim, tag),
            });
        }
        taken.insert(name, (dim, tag));
    }

    // Bodies: one per physical volume holding hexahedra, by tag; unnamed last.
    let mut volume_tags: Vec<i32> = Vec::new();
    let mut last = None;
    for &v in &hex_volume {
        if last != Some(v) && !volume_tags.contains(&v) {
            volume_tags.push(v);
        }
        last = Some(v);
    }
    volume_tags.sort_unstable();
    if volume_tags.first() == Some(&0) {
        volume_tags.remove(0);
        volume_tags.push(0);
    }
    let mut bodies = Vec::with_capacity(volume_tags.len());
    for &tag in &volume_tags {
        let name = if tag == 0 { UNNAMED_VOLUME.to_string() } else { name_of(3, tag) };
        if tag == 0 {
            if let Some(&(d, t)) = taken.get(UNNAMED_VOLUME) {
                return Err(MshError::DuplicateName {
                    at: file.to_string(),
                    name,
                    first: describe_group(d, t),
                    second: "the body of hexahedra in no physical volume".to_string(),
                });
            }
            warnings.push(format!(
                "{} hexahedra belong to no physical volume: they form the body `{UNNAMED_VOLUME}`",
                hex_volume.iter().filter(|&&v| v == 0).count()
            ));
        }
        bodies.push(Body { name, physical_tag: tag });
    }
    for &(dim, tag) in &keys {
        if dim == 3 && !volume_tags.contains(&tag) {
            warnings.push(format!(
                "physical volume `{}` (tag {tag}) holds no hexahedra: it gives a node set but no body",
                name_of(dim, tag)
            ));
        }
    }
    let body_of = |v: i32| volume_tags.iter().position(|&t| t == v).unwrap_or(0) as u32;
    let mut last = (i32::MIN, 0u32);
    let hex_body: Vec<u32> = hex_volume
        .iter()
        .map(|&v| {
            if v != last.0 {
                last = (v, body_of(v));
            }
            last.1
        })
        .collect();

    // Face sets (before compaction: quads and hexes share the file's node indices).
    let n_old = nodes.tags.len();
    let mut incidence: Option<Incidence> = None;
    let mut face_sets = Vec::new();
    for &(dim, tag) in keys.iter().filter(|k| k.0 == 2) {
        let name = name_of(dim, tag);
        let Some(group) = group_of.get(&(dim, tag)) else {
            warnings.push(format!("physical surface `{name}` (tag {tag}) holds no elements: its face set is empty"));
            face_sets.push(FaceSet { name, physical_tag: tag, faces: Vec::new(), quad_tags: Vec::new() });
            continue;
        };
        if let Some((element, number, offset)) = group.non_quad {
            let type_name = element_type(number).map_or_else(|| format!("type {number}"), |t| t.describe());
            return Err(MshError::NonQuadFace { at: cur.at(offset), group: name, element, type_name, type_number: number });
        }
        let inc = incidence.get_or_insert_with(|| {
            let mut wanted = vec![false; n_old];
            for g in groups.iter().filter(|g| g.dim == 2) {
                for q in &g.quads {
                    wanted[q.nodes[0] as usize] = true;
                }
            }
            Incidence::new(n_old, &hexes, &wanted)
        });
        let mut faces = Vec::with_capacity(group.quads.len());
        let mut quad_tags = Vec::with_capacity(group.quads.len());
        let mut interior = 0usize;
        let mut example = None;
        for q in &group.quads {
            let mut candidates = inc.of(q.nodes[0]).iter().filter_map(|&e| {
                find_local_face(&hexes[e as usize], &q.nodes).map(|local| HexFace { element: e, local: local as u8 })
            });
            let Some(first) = candidates.next() else {
                return Err(MshError::FaceNotOnHex { at: cur.at(q.offset), quad: q.tag, group: name });
            };
            let rest: Vec<HexFace> = candidates.collect();
            let chosen = if rest.is_empty() {
                first
            } else {
                interior += 1;
                let all: Vec<HexFace> = std::iter::once(first).chain(rest).collect();
                let agreeing: Vec<HexFace> = all
                    .iter()
                    .copied()
                    .filter(|f| {
                        same_orientation(hex_face_nodes(&hexes[f.element as usize], f.local as usize), q.nodes) == Some(true)
                    })
                    .collect();
                let chosen = if agreeing.len() == 1 { agreeing[0] } else { first };
                example.get_or_insert_with(|| {
                    let tags: Vec<u64> = all.iter().map(|f| hex_tags[f.element as usize]).collect();
                    (q.tag, tags, hex_tags[chosen.element as usize], agreeing.len() == 1)
                });
                chosen
            };
            faces.push(chosen);
            quad_tags.push(q.tag);
        }
        if let Some((quad, tags, chosen, by_orientation)) = example {
            let how = if by_orientation {
                "whose outward normal agrees with the quad's node order (right-hand rule)"
            } else {
                "listed first (the node order did not single one out)"
            };
            warnings.push(format!(
                "physical surface `{name}`: {interior} quads are interior faces shared by several hexahedra \
                 (e.g. quad {quad} between elements {tags:?}, attached to element {chosen}); each was attached to the hexahedron {how}"
            ));
        }
        if faces.is_empty() {
            warnings.push(format!("physical surface `{name}` (tag {tag}) holds no quads: its face set is empty"));
        }
        face_sets.push(FaceSet { name, physical_tag: tag, faces, quad_tags });
    }

    // Compaction: keep the nodes of hexahedra, in file order.
    let mut new_index = vec![u32::MAX; n_old];
    for h in &hexes {
        for &n in h {
            new_index[n as usize] = 0;
        }
    }
    let mut kept_coords = Vec::with_capacity(n_old);
    let mut node_tags = Vec::with_capacity(n_old);
    let mut dropped_nodes = Vec::new();
    let mut next = 0u32;
    for (i, slot) in new_index.iter_mut().enumerate() {
        if *slot == u32::MAX {
            dropped_nodes.push(nodes.tags[i]);
        } else {
            *slot = next;
            next += 1;
            kept_coords.push(nodes.coords[i]);
            node_tags.push(nodes.tags[i]);
        }
    }
    if !dropped_nodes.is_empty() {
        warnings.push(format!("{} nodes used by no hexahedron were dropped", dropped_nodes.len()));
    }

    // Node sets: one per physical group of any dimension.
    let mut stamp = vec![0u32; n_old];
    let mut node_sets = Vec::with_capacity(keys.len());
    for (k, &(dim, tag)) in keys.iter().enumerate() {
        let name = name_of(dim, tag);
        let mark = k as u32 + 1;
        let mut set = Vec::new();
        let mut left_out = 0usize;
        if let Some(g) = group_of.get(&(dim, tag)) {
            let hex_nodes = g.hexes.iter().flat_map(|&e| hexes[e as usize]);
            for n in g.nodes.iter().copied().chain(hex_nodes) {
                if stamp[n as usize] != mark {
                    stamp[n as usize] = mark;
                    match new_index[n as usize] {
                        u32::MAX => left_out += 1,
                        i => set.push(i),
                    }
                }
            }
        }
        set.sort_unstable();
        if left_out > 0 {
            warnings.push(format!(
                "node set `{name}`: {left_out} of its nodes are used by no hexahedron and were left out"
            ));
        }
        if set.is_empty() {
            warnings.push(format!("node set `{name}` ({}) is empty", describe_group(dim, tag)));
        }
        node_sets.push(NodeSet { name, physical_tag: tag, dim, nodes: set });
    }

    for h in &mut hexes {
        for n in h.iter_mut() {
            *n = new_index[*n as usize];
        }
    }

    if !flipped.is_empty() {
        let shown: Vec<u64> = flipped.iter().take(10).copied().collect();
        warnings.push(format!(
            "{} mirrored hexahedra (all corner Jacobians negative) were reordered (top and bottom faces swapped): elements {shown:?}{}",
            flipped.len(),
            if flipped.len() > 10 { " ..." } else { "" }
        ));
    }

    let mesh = Mesh {
        nodes: kept_coords,
        hexes,
        hex_body,
        bodies,
        node_sets,
        face_sets,
        node_tags,
        element_tags: hex_tags,
    };
    let warnings = located.into_iter().chain(warnings.into_iter().map(|w| format!("{file}: {w}"))).collect();
    let report = ImportReport { version: header.describe(), dropped_nodes, flipped_elements: flipped, warnings };
    Ok((mesh, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation() {
        let f = [1, 2, 3, 4];
        assert_eq!(same_orientation(f, [3, 4, 1, 2]), Some(true));
        assert_eq!(same_orientation(f, [1, 4, 3, 2]), Some(false));
        assert_eq!(same_orientation(f, [1, 3, 2, 4]), None);
    }
}
