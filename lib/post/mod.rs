//! Post-processing of converged states: stress measures and nodal fields.
pub mod contact_pressure;
pub mod oscillation;
pub mod stresses;
