//! A file read section by section: the header first, then every section by its
//! own parser (or skipped), then the mesh built from what they read.

use std::path::Path;

use super::build::{self, ImportReport, UNNAMED_VOLUME};
use super::cursor::{show, Cursor};
use super::error::MshError;
use super::header::{self, Version};
use super::{elements, entities, nodes, physical_names};
use crate::format::stage::read_input;
use crate::mesh::Mesh;

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
