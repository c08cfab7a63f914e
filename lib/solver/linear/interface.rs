//! The linear-solver interface: what a backend is told (the pattern and its
//! [`Symmetry`]), what it does (`analyse`, `factor`, `solve_in_place`) and what it
//! reports ([`FactorInfo`], [`SolverTimings`], [`SolveReport`]).

use std::time::Duration;

use faer::sparse::{SymbolicSparseColMat, SymbolicSparseColMatRef};

use super::error::LinearSolverError;

/// Structure of the matrix, chosen by the caller (the tangent is symmetric
/// without friction, non-symmetric with it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Symmetry {
    /// Symmetric; both triangles are stored, the lower one is read.
    Symmetric,
    /// Non-symmetric.
    General,
}

/// The factorization actually computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Factorization {
    Llt,
    Ldlt,
    Lu,
    /// No factorization: an algebraic-multigrid preconditioner (built or kept).
    Multigrid,
}

/// What one `factor` call did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FactorInfo {
    pub method: Factorization,
    /// Wall time of this numeric factorization (including a failed `LLᵀ` before
    /// the `LDLᵀ` fallback).
    pub time: Duration,
}

/// Accumulated wall times, split by phase, and call counts.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SolverTimings {
    /// Ordering + symbolic factorization (`analyse`).
    pub symbolic: Duration,
    /// Numeric factorizations (`factor`).
    pub numeric: Duration,
    /// Triangular solves (`solve_in_place`).
    pub solve: Duration,
    pub n_symbolic: usize,
    pub n_numeric: usize,
    pub n_solve: usize,
    /// Krylov iterations over all solves (iterative backends).
    pub n_krylov: usize,
    /// Solves an iterative backend handed to its direct fallback.
    pub n_fallback: usize,
    /// `factor` calls that kept an earlier preconditioner instead of factoring.
    pub n_reused: usize,
    /// Entries of the largest Cholesky-type factor analysed (0: none, or a backend
    /// without one): its memory, 4 or 8 bytes an entry.
    pub largest_factor: usize,
}

/// What the last `solve_in_place` did, for the log.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SolveReport {
    /// Krylov iterations (0 for a direct solve).
    pub krylov_iterations: usize,
    /// Why an iterative backend solved this system by its direct fallback.
    pub fallback: Option<String>,
}

/// A sparsity pattern shared between the assembly, which owns it, and the solver
/// that analysed it (no copy of its arrays).
pub type SharedPattern = std::sync::Arc<faer::sparse::SymbolicSparseColMat<usize>>;

/// The interface every linear-solver backend implements.
pub trait LinearSolver: Send {
    /// Short name for logs, e.g. `"faer-direct"`.
    fn name(&self) -> &str;
    /// Analyses a sparsity pattern (square, CSC, both triangles, sorted rows):
    /// ordering and symbolic factorization. Call again when the pattern or the
    /// symmetry changes; invalidates the previous factorization.
    fn analyse(&mut self, pattern: SymbolicSparseColMatRef<'_, usize>, symmetry: Symmetry) -> Result<(), LinearSolverError>;
    /// `analyse`, possibly still running when it returns (beside the caller, who
    /// assembles the tangent meanwhile); its errors then come from
    /// [`Self::finish_analysis`], which `factor` calls first. A backend without
    /// a background analysis does it here. The pattern is shared, not copied: a
    /// backend that keeps it holds the `Arc`.
    fn analyse_in_background(&mut self, pattern: &SharedPattern, symmetry: Symmetry) -> Result<(), LinearSolverError> {
        self.analyse((**pattern).as_ref(), symmetry)
    }
    /// Waits for an analysis started by [`Self::analyse_in_background`]; its error,
    /// if it failed.
    fn finish_analysis(&mut self) -> Result<(), LinearSolverError> {
        Ok(())
    }
    /// Numeric factorization of the matrix with these values (pattern order).
    fn factor(&mut self, values: &[f64]) -> Result<FactorInfo, LinearSolverError>;
    /// Overwrites `rhs` with the solution of `A x = rhs`. `values` are A's, those
    /// given to the last `factor` and unchanged since: a backend whose solve applies
    /// A (GMRES with a kept or single-precision factorization) reads them here
    /// instead of keeping a copy; a direct one ignores them.
    fn solve_in_place(&mut self, values: &[f64], rhs: &mut [f64]) -> Result<(), LinearSolverError>;
    /// Accumulated timings since construction.
    fn timings(&self) -> SolverTimings;
    /// What the last `solve_in_place` did (a direct backend: nothing to say).
    fn last_solve(&self) -> SolveReport {
        SolveReport::default()
    }
    /// The relative residual the next solves may stop at, for an iterative
    /// backend (an inexact Newton's forcing term); a direct backend ignores it.
    fn set_forcing(&mut self, _eta: f64) {}
    /// The current configuration: nodal reference coordinates and the full
    /// displacement vector, before `factor` (a multigrid backend builds its
    /// rigid-body near-null space from them); others ignore it.
    fn set_configuration(&mut self, _reference: &[nalgebra::Vector3<f64>], _u: &[f64]) {}
    /// The position of each unknown's node (the free dofs in order), for an
    /// ordering that cuts the mesh by planes (`FillOrdering::Geometric`); given
    /// before the first `analyse`, kept for every later one. Others ignore it.
    fn set_unknown_coordinates(&mut self, _coordinates: std::sync::Arc<[[f64; 3]]>) {}
    /// A load increment (or a cutback's new attempt) starts: the next `factor`
    /// keeps nothing from an earlier increment (no preconditioner reused across
    /// it), so that a restart from any converged increment, which starts with
    /// nothing kept, continues bit for bit. A direct backend has nothing to drop.
    fn begin_increment(&mut self) {}
}

/// The checks every `factor(values)` makes: a pattern was analysed, `values` has one
/// finite entry per pattern entry. Returns the pattern.
pub fn check_values<'a>(pattern: Option<&'a SymbolicSparseColMat<usize>>, values: &[f64]) -> Result<&'a SymbolicSparseColMat<usize>, LinearSolverError> {
    let pattern = pattern.ok_or(LinearSolverError::Order("factor", "analyse"))?;
    let nnz = pattern.row_idx().len();
    if values.len() != nnz {
        return Err(LinearSolverError::Dimension { what: "values (pattern entries)", expected: nnz, got: values.len() });
    }
    if let Some(index) = values.iter().position(|v| !v.is_finite()) {
        return Err(LinearSolverError::NonFinite { index });
    }
    Ok(pattern)
}
