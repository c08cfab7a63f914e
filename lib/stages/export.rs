//! `sc-export`: any stage file → VTK for ParaView, or a human-readable YAML dump.

use std::path::Path;

use super::StageRunError;
use crate::format::stage::{write_atomic_with, StageFile};
use crate::format::scres::Results;
use crate::format::{scmesh, scres, vtk};
use crate::post::stresses;

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
    let file = StageFile::read_known(input, &[(scmesh::FORMAT, scmesh::MAJOR), (scres::FORMAT, scres::MAJOR)])?;
    match format {
        ExportFormat::Yaml => {
            write_atomic_with(output, |w| file.dump_yaml(w))?;
            Ok(format!("wrote {} ({} {}.{} as YAML)", output.display(), file.format, file.major, file.minor))
        }
        ExportFormat::Vtu => match file.format.as_str() {
            scmesh::FORMAT => {
                let mesh = scmesh::from_stage(&file)?;
                let (n, m) = (mesh.nodes.len(), mesh.hexes.len());
                vtk::mesh_grid(&mesh).write_vtu(output)?;
                Ok(format!("wrote {} ({n} points, {m} hexahedra)", output.display()))
            }
            other => Err(StageRunError::Usage(format!("{}: a '{other}' file cannot be exported as .vtu (supported: scmesh)", input.display()))),
        },
        ExportFormat::Pvd => match file.format.as_str() {
            scres::FORMAT => {
                let results = Results::from_stage(&file)?;
                write_results_pvd(&results, output)
            }
            other => Err(StageRunError::Usage(format!(
                "{}: a '{other}' file holds no time series; .pvd is written for results files (use .vtu for a mesh)",
                input.display()
            ))),
        },
    }
}

/// One `.vtu` per converged increment beside the `.pvd` (`<stem>_<k>.vtu`, k = 0 is
/// the undeformed state), and the `.pvd` indexing them by load factor.
pub fn write_results_pvd(results: &Results, output: &Path) -> Result<String, StageRunError> {
    let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "results".into());
    let dir = output.parent().filter(|p| !p.as_os_str().is_empty()).map(Path::to_path_buf).unwrap_or_default();
    let mesh = &results.mesh;
    let mut entries = Vec::new();
    let zero = scres::Increment {
        info: scres::IncrementInfo { load_factor: 0.0, cutbacks: 0, iterations: vec![], reactions: vec![], seconds_output: 0.0 },
        u: vec![[0.0; 3]; mesh.nodes.len()],
        stress: vec![[[0.0; 9]; 8]; mesh.hexes.len()],
    };
    for (k, inc) in std::iter::once(&zero).chain(results.increments.iter()).enumerate() {
        let name = format!("{stem}_{k}.vtu");
        let mut g = vtk::mesh_grid(mesh);
        g.point_data.push(vtk::Field::vector_f64("displacement", inc.u.iter().flatten().copied().collect()));
        let elem = stresses::element_average(&inc.stress);
        let nodal = stresses::nodal_average(mesh, &elem);
        push_stress_fields(&mut g.point_data, &nodal);
        push_stress_fields(&mut g.cell_data, &elem);
        g.write_vtu(&dir.join(&name))?;
        entries.push((inc.info.load_factor, name));
    }
    vtk::write_pvd(output, &entries)?;
    Ok(format!("wrote {} ({} increments + the undeformed state)", output.display(), results.increments.len()))
}

fn push_stress_fields(fields: &mut Vec<vtk::Field>, s: &[stresses::Tensor9]) {
    fields.push(vtk::Field::tensor_f64("stress", s.iter().flatten().copied().collect()));
    fields.push(vtk::Field::scalar_f64("von_mises", s.iter().map(stresses::von_mises).collect()));
    let p: Vec<[f64; 3]> = s.iter().map(stresses::principal).collect();
    fields.push(vtk::Field::scalar_f64("principal_max", p.iter().map(|p| p[2]).collect()));
    fields.push(vtk::Field::scalar_f64("principal_min", p.iter().map(|p| p[0]).collect()));
}
