//! Why the solver fails: setting it up ([`SetupFailure`]: a mesh too large for the
//! assembly's numbering, a linear solver that does not fit the problem, the build or
//! the number of MPI ranks), or solving one increment ([`IncrementFailure`]: an
//! element inverted at an iterate, a linear solve, a contact element, divergence, a
//! contact configuration that keeps cycling, or the iteration limit). An increment's
//! failure says at which Newton iteration it happened; the load stepping
//! (`increments.rs`) retries the increment shorter.

use crate::assembly::{AssemblyError, PatternError};
use crate::contact::law::ContactElementError;
use crate::contact::pair::PairError;
use crate::fem::element::ElementError;
use crate::solver::linear::LinearSolverError;

/// Why an increment did not converge.
#[derive(Debug, Clone, thiserror::Error)]
pub enum IncrementFailure {
    #[error("iteration {iteration}: element {element} inverted or failed ({error})")]
    Element { iteration: u32, element: usize, error: ElementError },
    #[error("did not converge in {iteration} iterations: relative residual {residual:.3e}, energy {energy:.3e}")]
    NotConverged { iteration: u32, residual: f64, energy: f64 },
    #[error("iteration {iteration}: diverged (relative residual {residual:.3e})")]
    Diverged { iteration: u32, residual: f64 },
    #[error("iteration {iteration}: linear solver: {error}")]
    Linear { iteration: u32, error: LinearSolverError },
    /// The linear solver's first analysis, run in the background while the first
    /// tangent was assembled, failed: an error of the setup, which no cutback mends.
    #[error("linear solver: {error}")]
    Setup { error: LinearSolverError },
    #[error("iteration {iteration}: contact pair '{pair}', slave node {node_tag}: {error}")]
    Contact { iteration: u32, pair: String, node_tag: u64, error: ContactElementError },
    #[error("iteration {iteration}: {message}")]
    ContactSetup { iteration: u32, message: String },
    #[error("iteration {iteration}: the contact configuration cycles between {} states (relative residual {residual:.3e}): slave nodes {nodes} alternate between in and out of contact, between master elements or in and out of crease contact", period_name(*.period))]
    ContactCycling { iteration: u32, residual: f64, nodes: String, period: u32 },
}

/// "two", "three", "four" (the cycle lengths Newton detects, `cycles.rs`).
fn period_name(p: u32) -> &'static str {
    match p {
        2 => "two",
        3 => "three",
        _ => "four",
    }
}

/// Setting the solver up failed (a mesh too large for the assembly's numbering, …).
#[derive(Debug, thiserror::Error)]
pub enum SetupFailure {
    #[error(transparent)]
    Pattern(#[from] PatternError),
    #[error(transparent)]
    Assembly(#[from] AssemblyError),
    #[error(transparent)]
    Linear(#[from] LinearSolverError),
    #[error(transparent)]
    Contact(#[from] PairError),
    #[error("linear_solver: {0} needs a symmetric tangent, and this problem's is not ({1}): use auto or lu")]
    NotSymmetric(&'static str, &'static str),
    #[error("linear_solver: petsc needs sc-solve built with the PETSc backend (cargo build --release --features petsc, with PETSc and MPI installed: docs/performance.md); this build has only faer's solvers: use auto or direct")]
    PetscNotBuilt,
    #[error("{0} MPI ranks need the PETSc backend (linear_solver: petsc or auto); linear_solver: {1} runs on one process: start it without mpirun")]
    DirectUnderMpi(usize, &'static str),
}
