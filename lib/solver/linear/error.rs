//! What a linear solve can fail with.

/// Linear-solver failures.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinearSolverError {
    #[error(
        "the system is singular{}: is a body unconstrained? a body held only by contact needs contact or springs before first load",
        dof_text(*.dof)
    )]
    Singular {
        /// Free-dof index of the offending pivot, when known.
        dof: Option<usize>,
    },
    #[error("the matrix is not positive definite (non-positive pivot at free dof {dof}) and only LLT was allowed")]
    NotPositiveDefinite { dof: usize },
    #[error("the matrix has a non-finite value at position {index} of the values array")]
    NonFinite { index: usize },
    #[error("expected {expected} {what}, got {got}")]
    Dimension { what: &'static str, expected: usize, got: usize },
    #[error("{0} called before {1}")]
    Order(&'static str, &'static str),
    #[error("iterative solver did not converge: {iterations} iterations, relative residual {relative_residual:e}")]
    DidNotConverge { iterations: usize, relative_residual: f64 },
    #[error("faer: {0}")]
    Faer(String),
    /// An external backend's failure, with its own words (PETSc names the function).
    #[error("{0}")]
    Backend(String),
    /// The factorization would not fit in memory (checked after the symbolic analysis).
    #[error("{0}")]
    TooLarge(crate::solver::memory::TooLarge),
}

fn dof_text(dof: Option<usize>) -> String {
    match dof {
        Some(d) => format!(" (zero pivot at free dof {d})"),
        None => String::new(),
    }
}
