//! The linear-solver interface and the faer direct backend.
//!
//! **One small interface.** Every backend (the sparse direct one here; the
//! PETSc/AMG Krylov one under MPI, `solver::petsc`) implements [`LinearSolver`]:
//! `analyse(pattern, symmetry)` once per sparsity pattern, `factor(values)` once
//! per Newton iteration (for an iterative backend: build the preconditioner),
//! `solve_in_place(values, rhs)` per right-hand side (the values of the last
//! `factor` again, which a Krylov backend applies without keeping a copy). The values are always in the CSC
//! order of the pattern given to `analyse` (the order of
//! [`crate::assembly::Pattern`] and [`crate::assembly::Assembly::values`]); a
//! distributed backend would receive the locally owned columns in the same form.
//!
//! | file | concept |
//! |------|---------|
//! | [`interface`] | the [`LinearSolver`] trait and what it reports |
//! | [`error`] | [`LinearSolverError`] |
//! | [`faer_direct`] | the faer backend: ordering and symbolic factorization once, `LLᵀ` → `LDLᵀ` or `LU` per Newton iteration, the singularity check |
//! | [`supernodal`] | the factor's supernodal structure, faer's computed on the supervariable (node) graph |
//! | [`tree_cholesky`] | the numeric supernodal `LLᵀ`, parallel over the elimination tree, into faer's factor layout |
//! | [`tree_solve`] | the triangular solves with that factor, parallel over the same tree |

pub mod dense_kernels;
pub mod error;
pub mod faer_direct;
pub mod supernodal;
pub mod tree_cholesky;
pub mod tree_solve;
pub mod interface;

pub use error::LinearSolverError;
pub use faer_direct::{FactorPrecision, FaerDirect, FaerDirectOptions, SymmetricStrategy, PARALLEL_SUPERNODE, SINGLE_PIVOT_FLOOR};
pub use interface::{check_values, FactorInfo, Factorization, LinearSolver, SharedPattern, SolveReport, SolverTimings, Symmetry};
