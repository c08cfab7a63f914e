//! Solvers: the linear-solver interface and its faer direct backend ([`linear`]),
//! fill-reducing orderings ([`ordering`]), GMRES ([`gmres`]), an inexact Newton's
//! forcing terms ([`forcing`]) and the frictional
//! tangent's symmetric-part-preconditioned solver ([`symmetric_part`]),
//! the damping of bodies only contact holds ([`free_bodies`]), the static problem ([`problem`]) and its load curves ([`amplitude`]), Newton–Raphson for one increment ([`newton`]),
//! the augmented Lagrangian's Uzawa loop ([`uzawa`]), the master-surface
//! stabilisation ([`stabilization`]), load
//! stepping with cutbacks ([`increments`]), restarting from a results file ([`restart`]), what the user sees ([`log`]), the wall-clock times it records ([`clock`]), and a
//! timing benchmark on a clamped elastic cube ([`bench`]).

pub mod amplitude;
pub mod bench;
pub mod block_rows;
pub mod clock;
pub mod forcing;
pub mod free_bodies;
pub mod gmres;
pub mod increments;
pub mod linear;
pub mod log;
pub mod memory;
pub mod newton;
pub mod ordering;
#[cfg(feature = "petsc")]
pub mod petsc;
pub mod problem;
pub mod ranks;
pub mod restart;
pub mod stabilization;
pub mod symmetric_part;
pub mod uzawa;

pub use linear::{
    FactorInfo, FaerDirect, FaerDirectOptions, Factorization, LinearSolver, LinearSolverError, SolveReport, SolverTimings, SymmetricStrategy, Symmetry,
};
