//! The results stage file, `.scres` (format `scres`, version 1.0): the mesh, the
//! setup that produced it, and the full state of every converged increment
//! (displacements, Cauchy stress at the Gauss points, reactions, convergence
//! history), so that a run can be inspected, exported or restarted from it.
//!
//! The solver rewrites the file atomically after every converged increment, so the
//! file on disk always holds every increment converged so far and never a partial one.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::scmesh;
use super::stage::{write_atomic, StageError, StageFile, StageWriter};
use crate::mesh::Mesh;

pub const FORMAT: &str = "scres";
pub const MAJOR: u32 = 1;
pub const MINOR: u32 = 0;

/// One Newton iteration, as logged.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IterationLog {
    pub iteration: u32,
    /// ‖R_free‖ / reference force.
    pub residual: f64,
    /// |Δu · R| / (Δu₀ · R₀).
    pub energy: f64,
    pub seconds_assembly: f64,
    pub seconds_factor: f64,
    pub seconds_solve: f64,
}

/// Reaction force summed over a constrained node set.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Reaction {
    pub set: String,
    pub force: [f64; 3],
}

/// What is known of one converged increment besides its arrays.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IncrementInfo {
    pub load_factor: f64,
    /// Attempts that were cut back before this increment converged.
    pub cutbacks: u32,
    pub iterations: Vec<IterationLog>,
    pub reactions: Vec<Reaction>,
    pub seconds_output: f64,
}

/// How the run ended (so far).
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum RunStatus {
    Running,
    Completed,
    Stopped { reason: String },
}

/// One converged increment.
#[derive(Debug, Clone, PartialEq)]
pub struct Increment {
    pub info: IncrementInfo,
    /// Displacement of every node.
    pub u: Vec<[f64; 3]>,
    /// Cauchy stress at the 8 Gauss points of every hexahedron, row-major 3×3.
    pub stress: Vec<[[f64; 9]; 8]>,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ResultsMeta {
    source: String,
    /// `running`, `completed`, or `stopped: {reason: ...}` (not a YAML `!tag`).
    #[serde(with = "serde_yaml::with::singleton_map")]
    status: RunStatus,
    /// The solve setup, as given (YAML text).
    setup: String,
    increments: Vec<IncrementInfo>,
}

/// A results file in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Results {
    pub mesh: Mesh,
    pub source: String,
    pub setup: String,
    pub status: RunStatus,
    pub increments: Vec<Increment>,
}

impl Results {
    pub fn encode(&self) -> Vec<u8> {
        let mut w = StageWriter::new(FORMAT, MAJOR, MINOR);
        let meta = ResultsMeta {
            source: self.source.clone(),
            status: self.status.clone(),
            setup: self.setup.clone(),
            increments: self.increments.iter().map(|i| i.info.clone()).collect(),
        };
        w.meta(&serde_yaml::to_string(&meta).expect("results metadata serialises"));
        w.meta(&scmesh::mesh_meta_yaml(&self.mesh, &self.source));
        scmesh::write_mesh_records(&mut w, &self.mesh, "mesh/");
        let (n, m) = (self.mesh.nodes.len() as u64, self.mesh.hexes.len() as u64);
        for (k, inc) in self.increments.iter().enumerate() {
            let u: Vec<f64> = inc.u.iter().flatten().copied().collect();
            w.f64s(&format!("inc/{k}/u"), &[n, 3], &u);
            let s: Vec<f64> = inc.stress.iter().flatten().flatten().copied().collect();
            w.f64s(&format!("inc/{k}/stress"), &[m, 8, 9], &s);
        }
        w.finish()
    }

    /// Write atomically.
    pub fn write(&self, path: &Path) -> Result<(), StageError> {
        write_atomic(path, &self.encode())
    }

    pub fn from_stage(f: &StageFile) -> Result<Self, StageError> {
        let meta: ResultsMeta = f.meta_as()?;
        let mesh_meta = f.meta.get(1).ok_or_else(|| f.invalid("META", "the mesh metadata record is missing"))?;
        let mesh = scmesh::read_mesh_records(f, "mesh/", mesh_meta)?;
        let mut increments = Vec::with_capacity(meta.increments.len());
        for (k, info) in meta.increments.into_iter().enumerate() {
            let u = f.f64s(&format!("inc/{k}/u"), Some(3))?;
            if u.len() != 3 * mesh.nodes.len() {
                return Err(f.invalid(&format!("inc/{k}/u"), format!("expected {} nodes", mesh.nodes.len())));
            }
            let name = format!("inc/{k}/stress");
            let s = f.f64s(&name, None)?;
            if s.len() != 72 * mesh.hexes.len() {
                return Err(f.invalid(&name, format!("expected {} hexahedra × 8 Gauss points × 9", mesh.hexes.len())));
            }
            let stress = s
                .chunks_exact(72)
                .map(|c| std::array::from_fn(|q| std::array::from_fn(|i| c[9 * q + i])))
                .collect();
            increments.push(Increment { info, u: u.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(), stress });
        }
        Ok(Self { mesh, source: meta.source, setup: meta.setup, status: meta.status, increments })
    }

    pub fn read(path: &Path) -> Result<Self, StageError> {
        Self::from_stage(&StageFile::read(path, Some((FORMAT, MAJOR)))?)
    }
}
