//! The finite-strain hex8 element layer: shape functions, quadrature, kinematics,
//! element internal force and tangent, follower pressure. No global assembly here.
//!
//! | module | content |
//! |--------|---------|
//! | [`hex8`] | trilinear N_a(ξ, η, ζ) and derivatives, gmsh / VTK node order |
//! | [`quadrature`] | 2×2×2 and 2×2 Gauss rules (point q nearest node q) |
//! | [`kinematics`] | F = I + ∂u/∂X, J = det F, b = F Fᵀ |
//! | [`element`] | f_int = ∫ Bᵀσ dv and its tangent, total or updated Lagrangian |
//! | [`pressure`] | follower pressure on a quad face: nodal forces and load stiffness |
//! | [`fd`] | central finite differences for derivative checks |
//!
//! Math, equations and derivations: `docs/theory.md` ("Kinematics and materials",
//! "Hex8 element") and the doc comments of each function.

pub mod element;
pub mod fd;
pub mod hex8;
pub mod kinematics;
pub mod pressure;
pub mod quadrature;

pub use element::{
    hex8_energy, hex8_gauss_stresses, hex8_min_jacobian, hex8_residual, hex8_residual_tangent, ElementError,
    ElementMatrix, ElementVector, Formulation,
};
pub use pressure::{follower_pressure_force, follower_pressure_force_stiffness, FaceMatrix, FaceVector};

#[cfg(test)]
mod tests;
