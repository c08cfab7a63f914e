//! The two compressible neo-Hookean forms of the paper (section 8).
//!
//! Notation: F deformation gradient, J = det F, b = F Fᵀ (left Cauchy–Green),
//! C = Fᵀ F, I_c = tr b = tr C, S second Piola–Kirchhoff stress, σ = J⁻¹ F S Fᵀ Cauchy,
//! ℂ = 2 ∂S/∂C, c = J⁻¹ F F F F ℂ (push-forward; module docs of [`crate::material`]).
//! Used throughout: ∂J/∂C = ½ J C⁻¹, ∂I_c/∂C = I, ∂C⁻¹/∂C = −𝕀_{C⁻¹}, and the
//! push-forwards F I Fᵀ = b, F C⁻¹ Fᵀ = I, J⁻¹ F F F F (C⁻¹⊗C⁻¹) = J⁻¹ I⊗I,
//! J⁻¹ F F F F 𝕀_{C⁻¹} = J⁻¹ 𝕀, J⁻¹ F F F F (I⊗C⁻¹) = J⁻¹ b⊗I.
//!
//! A volumetric energy U(J) alone gives S = J U'(J) C⁻¹, σ = p I with p = U'(J), and
//! ℂ = J(p + J p') C⁻¹⊗C⁻¹ − 2 J p 𝕀_{C⁻¹}, hence
//! **c_vol = (p + J p') I⊗I − 2 p 𝕀**.
#![allow(non_snake_case)]

use super::{identity_outer, lame_from_young_poisson, outer, sym_identity, validate_lame};
use super::{Material, MaterialError, Tangent};
use nalgebra::Matrix3;

#[inline]
fn check_J(F: &Matrix3<f64>) -> Result<f64, MaterialError> {
    let J = F.determinant();
    if J > 0.0 {
        Ok(J)
    } else {
        Err(MaterialError::NonPositiveJacobian { J })
    }
}

/// Ciarlet–Simo neo-Hookean material, the model of the paper.
///
/// **Energy** (eq. 8.1):
/// W = λ/2 [½(J² − 1) − ln J] + μ/2 [(I_c − 3) − 2 ln J].
///
/// **Stress.** S = 2 ∂W/∂C = λ/2 (J² − 1) C⁻¹ + μ (I − C⁻¹); pushed forward,
/// σ = J⁻¹ F S Fᵀ = λ/(2J) (J² − 1) I + μ/J (b − I) (eq. 3.3).
///
/// **Spatial tangent.** Write S = a(J) C⁻¹ + μ I with a = λ/2 (J² − 1) − μ. Then
/// ℂ = 2 ∂S/∂C = 2 a'(J) C⁻¹ ⊗ ∂J/∂C + 2a ∂C⁻¹/∂C = a' J C⁻¹⊗C⁻¹ − 2a 𝕀_{C⁻¹}, with a' J = λ J², so
/// ℂ = λ J² C⁻¹⊗C⁻¹ + (2μ − λ(J² − 1)) 𝕀_{C⁻¹}.
/// Push-forward (C⁻¹ → I, factor J⁻¹):
///
/// **c = λ J I⊗I + (2μ − λ(J² − 1))/J 𝕀.**
///
/// At F = I it reduces to Hooke's λ I⊗I + 2μ 𝕀.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CiarletSimo {
    pub lambda: f64,
    pub mu: f64,
}

impl CiarletSimo {
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
}

impl Material for CiarletSimo {
    fn stress_tangent(&self, F: &Matrix3<f64>) -> Result<(Matrix3<f64>, Tangent), MaterialError> {
        let J = check_J(F)?;
        let (l, m) = (self.lambda, self.mu);
        let sigma = self.sigma(F, J);
        let c = identity_outer() * (l * J) + sym_identity() * ((2.0 * m - l * (J * J - 1.0)) / J);
        Ok((sigma, c))
    }
    fn stress(&self, F: &Matrix3<f64>) -> Result<Matrix3<f64>, MaterialError> {
        let J = check_J(F)?;
        Ok(self.sigma(F, J))
    }
    fn energy(&self, F: &Matrix3<f64>) -> Result<f64, MaterialError> {
        let J = check_J(F)?;
        let Ic = F.norm_squared();
        let lnJ = J.ln();
        Ok(0.5 * self.lambda * (0.5 * (J * J - 1.0) - lnJ) + 0.5 * self.mu * ((Ic - 3.0) - 2.0 * lnJ))
    }
    fn is_geometrically_linear(&self) -> bool {
        false
    }
    fn shear_modulus(&self) -> f64 {
        self.mu
    }
}

impl CiarletSimo {
    /// σ and the isotropic tangent's coefficients (α, β) of [`Material::stress_tangent`]'s c.
    #[inline]
    pub fn isotropic_stress_tangent(&self, F: &Matrix3<f64>) -> Result<(Matrix3<f64>, f64, f64), MaterialError> {
        let J = check_J(F)?;
        let (l, m) = (self.lambda, self.mu);
        Ok((self.sigma(F, J), l * J, (2.0 * m - l * (J * J - 1.0)) / J))
    }

    #[inline]
    fn sigma(&self, F: &Matrix3<f64>, J: f64) -> Matrix3<f64> {
        let b = F * F.transpose();
        let I = Matrix3::identity();
        I * (self.lambda / (2.0 * J) * (J * J - 1.0)) + (b - I) * (self.mu / J)
    }
}

/// Deviatoric/volumetric neo-Hookean material: the ANSYS and CalculiX form
/// (`*HYPERELASTIC, NEO HOOKE` with C10 = μ/2, D1 = 2/K).
///
/// **Energy** (eqs. 8.2, 8.3):
/// W = μ/2 (Ī₁ − 3) + K/2 (J − 1)², Ī₁ = J^{-2/3} I_c, K = λ + 2μ/3.
///
/// **Stress.** Volumetric part U = K/2 (J − 1)²: p = U' = K (J − 1). Isochoric part:
/// S_iso = 2 ∂/∂C [μ/2 J^{-2/3} I_c] = μ J^{-2/3} (I − I_c/3 C⁻¹), pushed forward
/// σ_iso = μ J^{-5/3} (b − I_c/3 I) = μ J^{-5/3} dev b. So
/// σ = μ J^{-5/3} dev b + K (J − 1) I.
///
/// **Spatial tangent.** Volumetric, with p = K(J − 1), p' = K (module docs):
/// c_vol = K(2J − 1) I⊗I − 2K(J − 1) 𝕀.
/// Isochoric, using ∂J^{-2/3}/∂C = −⅓ J^{-2/3} C⁻¹:
/// ℂ_iso = 2 ∂S_iso/∂C = 2μ J^{-2/3} [−⅓ I⊗C⁻¹ − ⅓ C⁻¹⊗I + I_c/9 C⁻¹⊗C⁻¹ + I_c/3 𝕀_{C⁻¹}],
/// pushed forward (I → b, C⁻¹ → I, factor J⁻¹):
///
/// **c_iso = 2μ J^{-5/3} [ I_c/3 𝕀 + I_c/9 I⊗I − ⅓ (b⊗I + I⊗b) ],  c = c_iso + c_vol.**
///
/// At F = I: c = (K − 2μ/3) I⊗I + 2μ 𝕀 = λ I⊗I + 2μ 𝕀 (Hooke).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DevVolNeoHookean {
    pub mu: f64,
    /// Bulk modulus K.
    pub kappa: f64,
}

impl DevVolNeoHookean {
    /// From shear and bulk moduli, validated (μ > 0, K > 0).
    pub fn new(mu: f64, kappa: f64) -> Result<Self, MaterialError> {
        if !(mu > 0.0 && mu.is_finite()) {
            return Err(MaterialError::InvalidShearModulus { mu });
        }
        if !(kappa > 0.0 && kappa.is_finite()) {
            return Err(MaterialError::InvalidBulkModulus { kappa });
        }
        Ok(Self { mu, kappa })
    }
    /// From Lamé parameters: K = λ + 2μ/3 (eq. 8.3).
    pub fn from_lame(lambda: f64, mu: f64) -> Result<Self, MaterialError> {
        validate_lame(lambda, mu)?;
        Ok(Self {
            mu,
            kappa: lambda + 2.0 * mu / 3.0,
        })
    }
    /// From Young's modulus and Poisson's ratio, validated (E > 0, −1 < ν < 0.5).
    pub fn from_young_poisson(E: f64, nu: f64) -> Result<Self, MaterialError> {
        let (lambda, mu) = lame_from_young_poisson(E, nu)?;
        Self::from_lame(lambda, mu)
    }
    /// CalculiX constants: C10 = μ/2, D1 = 2/K.
    pub fn calculix_c10_d1(&self) -> (f64, f64) {
        (0.5 * self.mu, 2.0 / self.kappa)
    }

    #[inline]
    fn sigma_parts(&self, F: &Matrix3<f64>, J: f64) -> (Matrix3<f64>, Matrix3<f64>, f64, f64) {
        let b = F * F.transpose();
        let Ic = b.trace();
        let I = Matrix3::identity();
        let J53 = J.powf(-5.0 / 3.0);
        let sigma = (b - I * (Ic / 3.0)) * (self.mu * J53) + I * (self.kappa * (J - 1.0));
        (sigma, b, Ic, J53)
    }
}

impl Material for DevVolNeoHookean {
    fn stress_tangent(&self, F: &Matrix3<f64>) -> Result<(Matrix3<f64>, Tangent), MaterialError> {
        let J = check_J(F)?;
        let (sigma, b, Ic, J53) = self.sigma_parts(F, J);
        let I = Matrix3::identity();
        let (m, k) = (self.mu, self.kappa);
        let II = identity_outer();
        let Is = sym_identity();
        let c_iso = (Is * (Ic / 3.0) + II * (Ic / 9.0) - (outer(&b, &I) + outer(&I, &b)) / 3.0) * (2.0 * m * J53);
        let c_vol = II * (k * (2.0 * J - 1.0)) - Is * (2.0 * k * (J - 1.0));
        Ok((sigma, c_iso + c_vol))
    }
    fn stress(&self, F: &Matrix3<f64>) -> Result<Matrix3<f64>, MaterialError> {
        let J = check_J(F)?;
        Ok(self.sigma_parts(F, J).0)
    }
    fn energy(&self, F: &Matrix3<f64>) -> Result<f64, MaterialError> {
        let J = check_J(F)?;
        let I1bar = J.powf(-2.0 / 3.0) * F.norm_squared();
        Ok(0.5 * self.mu * (I1bar - 3.0) + 0.5 * self.kappa * (J - 1.0) * (J - 1.0))
    }
    fn is_geometrically_linear(&self) -> bool {
        false
    }
    fn shear_modulus(&self) -> f64 {
        self.mu
    }
}
