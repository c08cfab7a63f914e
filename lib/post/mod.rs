//! Post-processing of converged states: stress measures and nodal fields.
pub mod stresses;
pub mod oscillation;
