//! Isotropic linear elasticity (small strain, geometrically linear).
#![allow(non_snake_case)]

use super::{identity_outer, lame_from_young_poisson, sym_identity, validate_lame};
use super::{Material, MaterialError, Tangent};
use nalgebra::Matrix3;

/// Hooke's law for small strains.
///
/// ε = sym(F − I) = sym(∇u),  W = λ/2 (tr ε)² + μ ε:ε,  σ = ∂W/∂ε = λ tr ε I + 2μ ε,
/// c = λ I⊗I + 2μ 𝕀 (constant; Voigt: λ + 2μ and λ in the normal block, μ on the
/// shear diagonal, acting on engineering shear strains).
///
/// Geometrically linear: the element integrates Bᵀσ over the reference volume with
/// this constant tangent and no initial-stress term, whatever the formulation. Since
/// W depends on F only through sym(F), ∂W/∂F = σ. Never fails (no J check).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearElastic {
    pub lambda: f64,
    pub mu: f64,
}

impl LinearElastic {
    /// From Lamé parameters, validated (μ > 0, λ + 2μ/3 > 0).
    pub fn from_lame(lambda: f64, mu: f64) -> Result<Self, MaterialError> {
        validate_lame(lambda, mu)?;
        Ok(Self { lambda, mu })
    }
    /// From Young's modulus and Poisson's ratio, validated (E > 0, −1 < ν < 0.5).
    pub fn from_young_poisson(E: f64, nu: f64) -> Result<Self, MaterialError> {
        let (lambda, mu) = lame_from_young_poisson(E, nu)?;
        Ok(Self { lambda, mu })
    }
    /// The constant Hooke tensor c = λ I⊗I + 2μ 𝕀.
    pub fn hooke(&self) -> Tangent {
        identity_outer() * self.lambda + sym_identity() * (2.0 * self.mu)
    }
    /// σ and the isotropic tangent's coefficients (λ, 2μ) of [`Self::hooke`].
    #[inline]
    pub fn isotropic_stress_tangent(&self, F: &Matrix3<f64>) -> Result<(Matrix3<f64>, f64, f64), MaterialError> {
        Ok((self.sigma(F), self.lambda, 2.0 * self.mu))
    }
    #[inline]
    fn sigma(&self, F: &Matrix3<f64>) -> Matrix3<f64> {
        let eps = small_strain(F);
        Matrix3::identity() * (self.lambda * eps.trace()) + eps * (2.0 * self.mu)
    }
}

/// ε = sym(F − I).
#[inline]
pub fn small_strain(F: &Matrix3<f64>) -> Matrix3<f64> {
    let H = F - Matrix3::identity();
    (H + H.transpose()) * 0.5
}

impl Material for LinearElastic {
    fn stress_tangent(&self, F: &Matrix3<f64>) -> Result<(Matrix3<f64>, Tangent), MaterialError> {
        Ok((self.sigma(F), self.hooke()))
    }
    fn stress(&self, F: &Matrix3<f64>) -> Result<Matrix3<f64>, MaterialError> {
        Ok(self.sigma(F))
    }
    fn energy(&self, F: &Matrix3<f64>) -> Result<f64, MaterialError> {
        let eps = small_strain(F);
        let tr = eps.trace();
        Ok(0.5 * self.lambda * tr * tr + self.mu * eps.norm_squared())
    }
    fn is_geometrically_linear(&self) -> bool {
        true
    }
    fn shear_modulus(&self) -> f64 {
        self.mu
    }
}
