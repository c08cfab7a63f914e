//! `sc-import`: gmsh MSH → `.scmesh`.

use std::path::Path;

use super::StageRunError;
use crate::format::msh::{read_msh, ImportReport};
use crate::format::scmesh;
use crate::mesh::Mesh;

/// Read a gmsh mesh (`-` = stdin) and write it as `.scmesh` (`-` = stdout).
pub fn import(input: &Path, output: &Path) -> Result<(Mesh, ImportReport), StageRunError> {
    let (mesh, report) = read_msh(input)?;
    scmesh::write(output, &mesh, &input.display().to_string())?;
    Ok((mesh, report))
}

/// A human summary of an import, one fact per line. The report's warnings are not
/// in it: callers print them even when asked to be quiet.
pub fn summary(input: &Path, mesh: &Mesh, report: &ImportReport) -> Vec<String> {
    let mut out = vec![format!(
        "read {} (MSH {}): {} nodes, {} hexahedra",
        input.display(),
        report.version,
        mesh.nodes.len(),
        mesh.hexes.len()
    )];
    out.push(format!("bodies: {}", mesh.body_names().join(", ")));
    out.push(format!("node sets: {}", mesh.node_sets.iter().map(|s| format!("{} ({})", s.name, s.nodes.len())).collect::<Vec<_>>().join(", ")));
    out.push(format!("face sets: {}", mesh.face_sets.iter().map(|s| format!("{} ({})", s.name, s.faces.len())).collect::<Vec<_>>().join(", ")));
    if !report.dropped_nodes.is_empty() {
        out.push(format!("dropped {} nodes used by no hexahedron (gmsh tags {})", report.dropped_nodes.len(), list(&report.dropped_nodes)));
    }
    if !report.flipped_elements.is_empty() {
        out.push(format!(
            "reordered {} mirrored hexahedra (negative Jacobian) by swapping bottom and top faces (gmsh tags {})",
            report.flipped_elements.len(),
            list(&report.flipped_elements)
        ));
    }
    out
}

fn list(tags: &[u64]) -> String {
    let shown: Vec<String> = tags.iter().take(20).map(|t| t.to_string()).collect();
    if tags.len() > 20 {
        format!("{}, … and {} more", shown.join(", "), tags.len() - 20)
    } else {
        shown.join(", ")
    }
}
