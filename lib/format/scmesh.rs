//! The mesh stage file, `.scmesh` (format `scmesh`, version 1.0), and the mesh
//! records every later stage file embeds under a prefix (`mesh/`), so that any
//! stage file is self-contained.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::stage::{write_atomic, StageError, StageFile, StageWriter};
use crate::mesh::{Body, FaceSet, HexFace, Mesh, NodeSet};

pub const FORMAT: &str = "scmesh";
pub const MAJOR: u32 = 1;
pub const MINOR: u32 = 0;

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshMeta {
    /// Where the mesh came from (the .msh path as given to sc-import).
    source: String,
    nodes: u64,
    hexes: u64,
    bodies: Vec<BodyMeta>,
    node_sets: Vec<SetMeta>,
    face_sets: Vec<SetMeta>,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct BodyMeta {
    name: String,
    physical_tag: i32,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SetMeta {
    name: String,
    physical_tag: i32,
    #[serde(default)]
    dim: u8,
    size: u64,
}

/// Append the mesh records to `w`, their names prefixed with `prefix`
/// (`""` for a `.scmesh`, `"mesh/"` inside later stage files). The metadata is
/// returned as YAML so the caller can place it in its own META record.
pub fn write_mesh_records(w: &mut StageWriter, mesh: &Mesh, prefix: &str) -> String {
    let n = mesh.nodes.len() as u64;
    let m = mesh.hexes.len() as u64;
    let flat: Vec<f64> = mesh.nodes.iter().flatten().copied().collect();
    w.f64s(&format!("{prefix}nodes"), &[n, 3], &flat);
    w.u64s(&format!("{prefix}node_tags"), &[n], &mesh.node_tags);
    let hx: Vec<u32> = mesh.hexes.iter().flatten().copied().collect();
    w.u32s(&format!("{prefix}hexes"), &[m, 8], &hx);
    w.u32s(&format!("{prefix}hex_body"), &[m], &mesh.hex_body);
    w.u64s(&format!("{prefix}element_tags"), &[m], &mesh.element_tags);
    for (i, s) in mesh.node_sets.iter().enumerate() {
        w.u32s(&format!("{prefix}node_set/{i}"), &[s.nodes.len() as u64], &s.nodes);
    }
    for (i, s) in mesh.face_sets.iter().enumerate() {
        let f: Vec<u32> = s.faces.iter().flat_map(|f| [f.element, f.local as u32]).collect();
        w.u32s(&format!("{prefix}face_set/{i}"), &[s.faces.len() as u64, 2], &f);
        w.u64s(&format!("{prefix}face_set/{i}/quad_tags"), &[s.quad_tags.len() as u64], &s.quad_tags);
    }
    String::new()
}

fn mesh_meta(mesh: &Mesh, source: &str) -> MeshMeta {
    MeshMeta {
        source: source.to_string(),
        nodes: mesh.nodes.len() as u64,
        hexes: mesh.hexes.len() as u64,
        bodies: mesh.bodies.iter().map(|b| BodyMeta { name: b.name.clone(), physical_tag: b.physical_tag }).collect(),
        node_sets: mesh
            .node_sets
            .iter()
            .map(|s| SetMeta { name: s.name.clone(), physical_tag: s.physical_tag, dim: s.dim, size: s.nodes.len() as u64 })
            .collect(),
        face_sets: mesh
            .face_sets
            .iter()
            .map(|s| SetMeta { name: s.name.clone(), physical_tag: s.physical_tag, dim: 2, size: s.faces.len() as u64 })
            .collect(),
    }
}

/// Serialise the mesh metadata (names, counts) as YAML for a META record.
pub fn mesh_meta_yaml(mesh: &Mesh, source: &str) -> String {
    serde_yaml::to_string(&mesh_meta(mesh, source)).expect("mesh metadata serialises")
}

/// Rebuild a mesh from the records under `prefix` and its metadata YAML.
pub fn read_mesh_records(f: &StageFile, prefix: &str, meta_yaml: &str) -> Result<Mesh, StageError> {
    let meta: MeshMeta = serde_yaml::from_str(meta_yaml).map_err(|e| f.invalid(&format!("{prefix}META"), e.to_string()))?;
    let name = |s: &str| format!("{prefix}{s}");
    let nodes: Vec<[f64; 3]> = f.f64s(&name("nodes"), Some(3))?.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let hexes: Vec<[u32; 8]> = f
        .u32s(&name("hexes"), Some(8))?
        .chunks_exact(8)
        .map(|c| c.try_into().expect("8 columns"))
        .collect();
    let hex_body = f.u32s(&name("hex_body"), None)?.to_vec();
    let node_tags = f.u64s(&name("node_tags"), None)?.to_vec();
    let element_tags = f.u64s(&name("element_tags"), None)?.to_vec();
    let n = nodes.len();
    if meta.nodes != n as u64 || meta.hexes != hexes.len() as u64 {
        return Err(f.invalid(&name("nodes"), format!("metadata says {} nodes and {} hexes, arrays hold {} and {}", meta.nodes, meta.hexes, n, hexes.len())));
    }
    if hex_body.len() != hexes.len() || element_tags.len() != hexes.len() || node_tags.len() != n {
        return Err(f.invalid(&name("hex_body"), "per-element or per-node arrays have inconsistent lengths"));
    }
    if let Some((e, h)) = hexes.iter().enumerate().find(|(_, h)| h.iter().any(|&v| v as usize >= n)) {
        return Err(f.invalid(&name("hexes"), format!("hexahedron {e} refers to node {:?}, but there are {n} nodes", h)));
    }
    if let Some(e) = hex_body.iter().position(|&b| b as usize >= meta.bodies.len()) {
        return Err(f.invalid(&name("hex_body"), format!("hexahedron {e} is in body {}, but there are {} bodies", hex_body[e], meta.bodies.len())));
    }
    let mut node_sets = Vec::new();
    for (i, s) in meta.node_sets.iter().enumerate() {
        let nodes = f.u32s(&name(&format!("node_set/{i}")), None)?.to_vec();
        if nodes.iter().any(|&v| v as usize >= n) {
            return Err(f.invalid(&name(&format!("node_set/{i}")), format!("node set '{}' refers to a node beyond {n}", s.name)));
        }
        node_sets.push(NodeSet { name: s.name.clone(), physical_tag: s.physical_tag, dim: s.dim, nodes });
    }
    let mut face_sets = Vec::new();
    for (i, s) in meta.face_sets.iter().enumerate() {
        let raw = f.u32s(&name(&format!("face_set/{i}")), Some(2))?;
        let faces: Vec<HexFace> = raw.chunks_exact(2).map(|c| HexFace { element: c[0], local: c[1] as u8 }).collect();
        if faces.iter().any(|fc| fc.element as usize >= hexes.len() || fc.local >= 6) {
            return Err(f.invalid(&name(&format!("face_set/{i}")), format!("face set '{}' refers to a face that does not exist", s.name)));
        }
        let quad_tags = f.u64s(&name(&format!("face_set/{i}/quad_tags")), None)?.to_vec();
        face_sets.push(FaceSet { name: s.name.clone(), physical_tag: s.physical_tag, faces, quad_tags });
    }
    Ok(Mesh {
        nodes,
        hexes,
        hex_body,
        bodies: meta.bodies.into_iter().map(|b| Body { name: b.name, physical_tag: b.physical_tag }).collect(),
        node_sets,
        face_sets,
        node_tags,
        element_tags,
    })
}

/// Encode a `.scmesh` file.
pub fn encode(mesh: &Mesh, source: &str) -> Vec<u8> {
    let mut w = StageWriter::new(FORMAT, MAJOR, MINOR);
    w.meta(&mesh_meta_yaml(mesh, source));
    write_mesh_records(&mut w, mesh, "");
    w.finish()
}

/// Write a `.scmesh` file atomically (`-` for standard output).
pub fn write(path: &Path, mesh: &Mesh, source: &str) -> Result<(), StageError> {
    write_atomic(path, &encode(mesh, source))
}

/// Decode a parsed `.scmesh` file.
pub fn from_stage(f: &StageFile) -> Result<Mesh, StageError> {
    let meta = f.meta.first().ok_or_else(|| f.invalid("META", "missing"))?.clone();
    read_mesh_records(f, "", &meta)
}

/// Read a `.scmesh` file (`-` for standard input).
pub fn read(path: &Path) -> Result<Mesh, StageError> {
    from_stage(&StageFile::read(path, Some((FORMAT, MAJOR)))?)
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn two_hex_mesh() -> Mesh {
        let mut nodes = Vec::new();
        for k in 0..2 {
            for j in 0..2 {
                for i in 0..3 {
                    nodes.push([i as f64 * 0.1 + 1.0 / 3.0, j as f64, k as f64]);
                }
            }
        }
        let id = |i: u32, j: u32, k: u32| i + 3 * j + 6 * k;
        let hex = |i: u32| [id(i, 0, 0), id(i + 1, 0, 0), id(i + 1, 1, 0), id(i, 1, 0), id(i, 0, 1), id(i + 1, 0, 1), id(i + 1, 1, 1), id(i, 1, 1)];
        Mesh {
            nodes,
            hexes: vec![hex(0), hex(1)],
            hex_body: vec![0, 1],
            bodies: vec![Body { name: "left".into(), physical_tag: 1 }, Body { name: "right".into(), physical_tag: 2 }],
            node_sets: vec![NodeSet { name: "base".into(), physical_tag: 3, dim: 2, nodes: vec![0, 1, 2, 3, 4, 5] }],
            face_sets: vec![FaceSet { name: "top".into(), physical_tag: 4, faces: vec![HexFace { element: 0, local: 1 }], quad_tags: vec![17] }],
            node_tags: (1..=12).collect(),
            element_tags: vec![101, 102],
        }
    }

    #[test]
    fn mesh_round_trip() {
        let m = two_hex_mesh();
        let b = encode(&m, "x.msh");
        let f = StageFile::parse("m.scmesh", &b, Some((FORMAT, MAJOR))).unwrap();
        assert_eq!(from_stage(&f).unwrap(), m);
    }
}
