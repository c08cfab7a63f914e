//! Global assembly: dof numbering with Dirichlet elimination ([`dofs`]), the
//! sparsity pattern of `K_ff` built once ([`pattern`]), the element colouring
//! ([`colouring`]), and the parallel, deterministic element scatter ([`scatter`]).

pub mod colouring;
pub mod dofs;
pub mod pattern;
pub mod scatter;

pub use dofs::{DofError, DofMap, DOFS_PER_NODE};
pub use pattern::{NodeGroups, Pattern, PatternError, HEX_DOFS, HEX_ENTRIES, NO_SLOT};
pub use scatter::{Assembled, Assembly, AssemblyError, AssemblyTimings, ElementFailure, HexMatrix, HexVector};
