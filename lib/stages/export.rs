//! `sc-export`: any stage file → VTK for ParaView, or a human-readable YAML dump.

use std::path::Path;

use super::StageRunError;
use crate::format::stage::{write_atomic_with, StageFile};
use crate::format::{scmesh, vtk};

/// Output formats of `sc-export`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ExportFormat {
    /// One `.vtu` unstructured grid (a mesh).
    Vtu,
    /// A `.pvd` time series with one `.vtu` per converged increment (results files).
    Pvd,
    /// Every record of the stage file, human-readable.
    Yaml,
}

impl ExportFormat {
    /// The format implied by an output file's extension.
    pub fn from_extension(path: &Path) -> Option<Self> {
        match path.extension()?.to_str()? {
            "vtu" => Some(Self::Vtu),
            "pvd" => Some(Self::Pvd),
            "yaml" | "yml" => Some(Self::Yaml),
            _ => None,
        }
    }
}

/// Export `input` to `output` in `format` (or the one implied by the extension).
/// Returns one line describing what was written.
pub fn export(input: &Path, output: &Path, format: Option<ExportFormat>) -> Result<String, StageRunError> {
    let format = match format.or_else(|| ExportFormat::from_extension(output)) {
        Some(f) => f,
        None => {
            return Err(StageRunError::Usage(format!(
                "{}: cannot tell the output format from the extension; use .vtu, .pvd or .yaml, or give --format",
                output.display()
            )))
        }
    };
    let file = StageFile::read(input, None)?;
    match format {
        ExportFormat::Yaml => {
            write_atomic_with(output, |w| file.dump_yaml(w))?;
            Ok(format!("wrote {} ({} {}.{} as YAML)", output.display(), file.format, file.major, file.minor))
        }
        ExportFormat::Vtu => match file.format.as_str() {
            scmesh::FORMAT => {
                if file.major != scmesh::MAJOR {
                    // Re-read through the checked path for the proper version message.
                    StageFile::read(input, Some((scmesh::FORMAT, scmesh::MAJOR)))?;
                }
                let mesh = scmesh::from_stage(&file)?;
                let (n, m) = (mesh.nodes.len(), mesh.hexes.len());
                vtk::mesh_grid(&mesh).write_vtu(output)?;
                Ok(format!("wrote {} ({n} points, {m} hexahedra)", output.display()))
            }
            other => Err(StageRunError::Usage(format!("{}: a '{other}' file cannot be exported as .vtu (supported: scmesh)", input.display()))),
        },
        ExportFormat::Pvd => Err(StageRunError::Usage(format!(
            "{}: a '{}' file holds no time series; .pvd is written for results files (use .vtu for a mesh)",
            input.display(),
            file.format
        ))),
    }
}
