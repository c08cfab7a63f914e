//! Solvers: the linear-solver interface and its faer direct backend
//! ([`linear`]), and a timing benchmark on a clamped elastic cube ([`bench`]).

pub mod bench;
pub mod linear;

pub use linear::{
    FactorInfo, FaerDirect, FaerDirectOptions, Factorization, LinearSolver, LinearSolverError, SolverTimings, SymmetricStrategy, Symmetry,
};
