//! Restart: continue a run from the last converged increment of a results file.
//!
//! A `.scres` carries the full state of every converged increment: the displacements,
//! and per contact pair and slave node the multiplier λ_N, the status, the foot point
//! ξ̄ and, with friction, the covariant tangential traction t_{Tα} — the history the
//! return mapping of the next increment starts from (eq. 4.7). A restart reads the
//! last increment back into the solver exactly as [`PairSolver::commit`] would have
//! left it, so the increments that follow are those the uninterrupted run would have
//! computed (the test `restart_continues_the_run_it_was_cut_from` compares them).
//!
//! By default the run continues from the file's last converged increment; it can
//! go back to an earlier one (a path to redo with smaller increments), the later
//! increments then being dropped from the new results.
//!
//! The restart file must come from the same model: the same mesh and the same
//! contact pairs (slave nodes, master net, master kind and orders). The setup may
//! differ, typically by a longer load path or more cutbacks; the increments whose
//! load factor the restart file already reached are skipped.
//!
//! [`PairSolver::commit`]: crate::contact::pair::PairSolver::commit

use std::path::{Path, PathBuf};

use crate::format::sccontact::ContactPair;
use crate::format::scres::{Increment, Results, RunStatus};
use crate::format::stage::StageError;
use crate::mesh::Mesh;

/// Why a results file cannot be restarted from.
#[derive(Debug, thiserror::Error)]
pub enum RestartError {
    #[error(transparent)]
    Read(#[from] StageError),
    #[error("{file}: cannot restart from it: {message}")]
    Mismatch { file: String, message: String },
}

/// The converged increments of a results file, checked against the model to continue.
pub struct RestartPoint {
    /// The results file read.
    pub file: PathBuf,
    /// Its converged increments, oldest first (at least one).
    pub increments: Vec<Increment>,
    /// Why its last bytes were left out, if they were (an interrupted write).
    pub tail: Option<String>,
    /// The run that wrote it was interrupted (killed, or stopped by a failed
    /// increment) after the increment continued from: it never marked itself
    /// completed there.
    pub interrupted: bool,
}

impl RestartPoint {
    /// Read `file` and check that it belongs to the model (`mesh`, `pairs`) about to
    /// be solved; continue from its converged increment number `increment` (1-based,
    /// as in its forces CSV) or, without one, from its last.
    pub fn read(file: &Path, increment: Option<usize>, mesh: &Mesh, pairs: &[ContactPair]) -> Result<Self, RestartError> {
        Self::from_results(file, Results::read(file)?, increment, mesh, pairs)
    }

    /// As [`Self::read`], from results already in memory (`file` names them in errors).
    pub fn from_results(file: &Path, mut results: Results, increment: Option<usize>, mesh: &Mesh, pairs: &[ContactPair]) -> Result<Self, RestartError> {
        let mismatch = |message: String| RestartError::Mismatch { file: file.display().to_string(), message };
        let r = &results;
        if r.mesh.nodes.len() != mesh.nodes.len() || r.mesh.hexes.len() != mesh.hexes.len() {
            return Err(mismatch(format!(
                "its mesh has {} nodes and {} hexahedra, the model has {} and {} (restart from a run of the same model)",
                r.mesh.nodes.len(),
                r.mesh.hexes.len(),
                mesh.nodes.len(),
                mesh.hexes.len()
            )));
        }
        if let Some(i) = (0..mesh.nodes.len()).find(|&i| r.mesh.nodes[i] != mesh.nodes[i] || r.mesh.node_tags.get(i) != mesh.node_tags.get(i)) {
            return Err(mismatch(format!("node {} (gmsh tag {}) differs from the model's: not the same mesh", i, mesh.node_tags.get(i).copied().unwrap_or(i as u64))));
        }
        if let Some(e) = (0..mesh.hexes.len()).find(|&e| r.mesh.hexes[e] != mesh.hexes[e]) {
            return Err(mismatch(format!("hexahedron {e} has other nodes than the model's: not the same mesh")));
        }
        if r.pairs.len() != pairs.len() {
            return Err(mismatch(format!("it has {} contact pairs, the model has {}", r.pairs.len(), pairs.len())));
        }
        for (a, b) in r.pairs.iter().zip(pairs) {
            if a.name != b.name {
                return Err(mismatch(format!("contact pair '{}' where the model has '{}'", a.name, b.name)));
            }
            if a != b {
                return Err(mismatch(format!(
                    "contact pair '{}' differs from the model's (slave nodes, master net, master kind or orders: {} {:?} in the file, {} {:?} in the model)",
                    a.name,
                    a.master_kind.name(),
                    a.orders,
                    b.master_kind.name(),
                    b.orders
                )));
            }
        }
        if results.increments.is_empty() {
            return Err(mismatch("it holds no converged increment".into()));
        }
        let interrupted = !matches!(results.status, RunStatus::Completed);
        match increment {
            Some(k) if k == 0 || k > results.increments.len() => {
                return Err(mismatch(format!("it holds converged increments 1 to {}, not increment {k}", results.increments.len())));
            }
            Some(k) => results.increments.truncate(k),
            None => {}
        }
        Ok(Self { file: file.to_path_buf(), increments: results.increments, tail: results.tail, interrupted })
    }

    /// The last converged increment: the state to continue from.
    pub fn last(&self) -> &Increment {
        // `from_results` refuses a file without increments
        &self.increments[self.increments.len() - 1]
    }

    /// Load factor of the last converged increment.
    pub fn load_factor(&self) -> f64 {
        self.last().info.load_factor
    }

    /// How many of the load factors `factors` are still to solve.
    pub fn remaining(&self, factors: &[f64]) -> usize {
        factors.len() - factors_done(factors, self.load_factor())
    }
}

/// Load factors this close (1e-12 relative, or absolute below 1) are the same: a
/// factor the setup recomputes is the one a results file stored.
fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(1.0)
}

/// How many of the (increasing) load factors `factors` a run that converged at
/// `lambda` has done.
pub fn factors_done(factors: &[f64], lambda: f64) -> usize {
    factors.iter().filter(|&&f| f < lambda || same(f, lambda)).count()
}

/// The number (1-based, as the solve log counts them) of the load factor an increment
/// converged at `lambda` belongs to: the first it does not pass (a cut-back step
/// counts toward the factor it was aiming at).
pub fn increment_number(factors: &[f64], lambda: f64) -> usize {
    (factors.iter().filter(|&&f| f < lambda && !same(f, lambda)).count() + 1).min(factors.len())
}
