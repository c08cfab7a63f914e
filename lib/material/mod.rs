//! Constitutive models: one trait, [`Material`], three models and the enum
//! [`MaterialModel`] the solver configuration holds.
//!
//! | model | energy | Cauchy stress | module |
//! |-------|--------|---------------|--------|
//! | [`CiarletSimo`] | W = λ/2 [½(J²−1) − ln J] + μ/2 [(I_c − 3) − 2 ln J] (eq. 8.1) | σ = λ/(2J)(J²−1) I + μ/J (b − I) (eq. 3.3) | [`neo_hookean`] |
//! | [`DevVolNeoHookean`] | W = μ/2 (Ī₁ − 3) + K/2 (J − 1)², Ī₁ = J^{-2/3} tr b (eqs. 8.2, 8.3) | σ = μ J^{-5/3} dev b + K (J − 1) I | [`neo_hookean`] |
//! | [`LinearElastic`] | W = λ/2 (tr ε)² + μ ε:ε, ε = sym(F − I) | σ = λ tr ε I + 2μ ε | [`linear`] |
//!
//! ## Spatial tangent and Voigt convention
//! Every model returns its Cauchy stress σ and its *spatial* elasticity tensor c, the
//! push-forward of the material tangent ℂ = 2 ∂S/∂C (S the second Piola–Kirchhoff stress):
//!
//! c_ijkl = J⁻¹ F_iI F_jJ F_kK F_lL ℂ_IJKL,
//!
//! equivalently the tensor of the Truesdell rate of Kirchhoff stress, L_v τ = J c : d
//! (d the rate of deformation). With it the updated-Lagrangian tangent is
//! ∫ Bᵀ c B + (∇N_a · σ ∇N_b) I dv (see `fem::element`). For the geometrically linear
//! model c is the constant Hooke tensor and ε replaces d.
//!
//! c is stored as a [`Tangent`] = `SMatrix<f64, 6, 6>` in Voigt order
//! **xx, yy, zz, xy, yz, xz** ([`VOIGT`]): `c[(m, n)] = c_ijkl` with m ↔ (i, j), n ↔ (k, l),
//! i.e. *plain tensor components*, no factors. It therefore maps engineering strains
//! (ε_xx, ε_yy, ε_zz, 2ε_xy, 2ε_yz, 2ε_xz), see [`strain_to_voigt`], to tensor stresses
//! (σ_xx, …, σ_xy, σ_yz, σ_xz), see [`stress_to_voigt`]. [`tangent_component`] reads it as
//! the 3×3×3×3 tensor c_ijkl.
//!
//! ## Symbols used in the tangents
//! - I⊗I: (I⊗I)_ijkl = δ_ij δ_kl, in Voigt: ones in the upper-left 3×3 block ([`outer`]).
//! - 𝕀: the symmetric fourth-order identity, 𝕀_ijkl = ½(δ_ik δ_jl + δ_il δ_jk), in Voigt
//!   diag(1, 1, 1, ½, ½, ½) ([`sym_identity`]).
//! - 𝕀_{C⁻¹}: (𝕀_{C⁻¹})_IJKL = ½(C⁻¹_IK C⁻¹_JL + C⁻¹_IL C⁻¹_JK) = −∂C⁻¹/∂C; its push-forward
//!   J⁻¹ F F F F 𝕀_{C⁻¹} = J⁻¹ 𝕀.
#![allow(non_snake_case)]

pub mod linear;
pub mod model;
pub mod neo_hookean;

pub use linear::LinearElastic;
pub use model::MaterialModel;
pub use neo_hookean::{CiarletSimo, DevVolNeoHookean};

use nalgebra::{Matrix3, SMatrix, Vector6};

/// Spatial elasticity tensor in Voigt form (order xx, yy, zz, xy, yz, xz; plain tensor
/// components, see the module docs).
pub type Tangent = SMatrix<f64, 6, 6>;

/// Voigt order: index m ↔ tensor index pair (i, j).
pub const VOIGT: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)];

/// Voigt index of the tensor index pair (i, j) (either order).
pub const fn voigt_index(i: usize, j: usize) -> usize {
    const MAP: [[usize; 3]; 3] = [[0, 3, 5], [3, 1, 4], [5, 4, 2]];
    MAP[i][j]
}

/// c_ijkl read from the Voigt matrix (the 3×3×3×3 view of a [`Tangent`]).
pub fn tangent_component(c: &Tangent, i: usize, j: usize, k: usize, l: usize) -> f64 {
    c[(voigt_index(i, j), voigt_index(k, l))]
}

/// Errors of material construction and evaluation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MaterialError {
    #[error("Young's modulus E = {E} must be positive")]
    InvalidYoungsModulus { E: f64 },
    #[error("Poisson's ratio nu = {nu} must satisfy -1 < nu < 0.5 (nu = 0.5, incompressible, is not supported by these compressible models)")]
    InvalidPoissonRatio { nu: f64 },
    #[error("shear modulus mu = {mu} must be positive")]
    InvalidShearModulus { mu: f64 },
    #[error("bulk modulus K = lambda + 2 mu / 3 = {kappa} must be positive (equivalently nu < 0.5)")]
    InvalidBulkModulus { kappa: f64 },
    #[error("non-positive volume ratio J = det F = {J}: the material is inverted")]
    NonPositiveJacobian { J: f64 },
}

/// Lamé parameters (λ, μ) from Young's modulus and Poisson's ratio, validated:
/// λ = Eν / ((1 + ν)(1 − 2ν)), μ = E / (2(1 + ν)).
pub fn lame_from_young_poisson(E: f64, nu: f64) -> Result<(f64, f64), MaterialError> {
    // Written so that NaN fails too.
    if !(E > 0.0 && E.is_finite()) {
        return Err(MaterialError::InvalidYoungsModulus { E });
    }
    if !(nu > -1.0 && nu < 0.5) {
        return Err(MaterialError::InvalidPoissonRatio { nu });
    }
    Ok((E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))))
}

/// Checks Lamé parameters: μ > 0 and K = λ + 2μ/3 > 0, which is the same as E > 0 and
/// −1 < ν < 0.5.
pub fn validate_lame(lambda: f64, mu: f64) -> Result<(), MaterialError> {
    if !(mu > 0.0 && mu.is_finite()) {
        return Err(MaterialError::InvalidShearModulus { mu });
    }
    let kappa = lambda + 2.0 * mu / 3.0;
    if !(kappa > 0.0 && kappa.is_finite()) {
        return Err(MaterialError::InvalidBulkModulus { kappa });
    }
    Ok(())
}

/// A hyperelastic (or linear elastic) material point.
///
/// `F` is the deformation gradient F = I + ∂u/∂X. Finite-strain models return
/// [`MaterialError::NonPositiveJacobian`] when J = det F ≤ 0.
pub trait Material: Sync {
    /// Cauchy stress σ and spatial tangent c (Voigt, see the module docs).
    fn stress_tangent(&self, F: &Matrix3<f64>) -> Result<(Matrix3<f64>, Tangent), MaterialError>;
    /// Cauchy stress σ only.
    fn stress(&self, F: &Matrix3<f64>) -> Result<Matrix3<f64>, MaterialError>;
    /// Strain energy per unit reference volume W(F).
    fn energy(&self, F: &Matrix3<f64>) -> Result<f64, MaterialError>;
    /// True for small-strain models: the element then uses ε = sym(∇u), the reference
    /// volume and a constant tangent, whatever the formulation.
    fn is_geometrically_linear(&self) -> bool;
    /// Shear modulus μ (stress scale, used for tolerances and reports).
    fn shear_modulus(&self) -> f64;
}

/// (A ⊗ B)_ijkl = A_ij B_kl in Voigt form (A, B symmetric).
pub fn outer(A: &Matrix3<f64>, B: &Matrix3<f64>) -> Tangent {
    let a = stress_to_voigt(A);
    let b = stress_to_voigt(B);
    a * b.transpose()
}

/// I ⊗ I in Voigt form.
pub fn identity_outer() -> Tangent {
    let mut c = Tangent::zeros();
    for m in 0..3 {
        for n in 0..3 {
            c[(m, n)] = 1.0;
        }
    }
    c
}

/// The symmetric fourth-order identity 𝕀_ijkl = ½(δ_ik δ_jl + δ_il δ_jk) in Voigt form:
/// diag(1, 1, 1, ½, ½, ½).
pub fn sym_identity() -> Tangent {
    Tangent::from_diagonal(&Vector6::new(1.0, 1.0, 1.0, 0.5, 0.5, 0.5))
}

/// Symmetric tensor → Voigt vector of its components (σ_xx, σ_yy, σ_zz, σ_xy, σ_yz, σ_xz).
pub fn stress_to_voigt(s: &Matrix3<f64>) -> Vector6<f64> {
    Vector6::new(s[(0, 0)], s[(1, 1)], s[(2, 2)], s[(0, 1)], s[(1, 2)], s[(0, 2)])
}

/// Voigt stress vector → symmetric tensor.
pub fn voigt_to_stress(v: &Vector6<f64>) -> Matrix3<f64> {
    Matrix3::new(v[0], v[3], v[5], v[3], v[1], v[4], v[5], v[4], v[2])
}

/// Engineering-strain Voigt vector of sym(H): (H_xx, H_yy, H_zz, H_xy + H_yx, H_yz + H_zy, H_xz + H_zx).
pub fn strain_to_voigt(H: &Matrix3<f64>) -> Vector6<f64> {
    Vector6::new(
        H[(0, 0)],
        H[(1, 1)],
        H[(2, 2)],
        H[(0, 1)] + H[(1, 0)],
        H[(1, 2)] + H[(2, 1)],
        H[(0, 2)] + H[(2, 0)],
    )
}

/// c : sym(H), i.e. (c : H)_ij = c_ijkl H_kl for any (not necessarily symmetric) H.
pub fn tangent_apply(c: &Tangent, H: &Matrix3<f64>) -> Matrix3<f64> {
    voigt_to_stress(&(c * strain_to_voigt(H)))
}

/// Pull-back of a spatial tangent to the material one:
/// ℂ_IJKL = J F⁻¹_Ii F⁻¹_Jj F⁻¹_Kk F⁻¹_Ll c_ijkl, computed as ℂ = J T c Tᵀ with the
/// 6×6 transformation T of a symmetric tensor A ↦ F⁻¹ A F⁻ᵀ acting on Voigt components:
/// T[(IJ), (ii)] = F⁻¹_Ii F⁻¹_Ji and T[(IJ), (ij)] = F⁻¹_Ii F⁻¹_Jj + F⁻¹_Ij F⁻¹_Ji (i ≠ j).
pub fn pull_back_tangent(c: &Tangent, Finv: &Matrix3<f64>, J: f64) -> Tangent {
    let T = push_matrix(Finv);
    (T * c * T.transpose()) * J
}

/// Push-forward of a material tangent: c_ijkl = J⁻¹ F_iI F_jJ F_kK F_lL ℂ_IJKL.
pub fn push_forward_tangent(C: &Tangent, F: &Matrix3<f64>, J: f64) -> Tangent {
    let T = push_matrix(F);
    (T * C * T.transpose()) / J
}

/// 6×6 matrix of the map A ↦ M A Mᵀ on Voigt (tensor-component) vectors of symmetric A.
fn push_matrix(M: &Matrix3<f64>) -> Tangent {
    let mut T = Tangent::zeros();
    for (r, &(I, J)) in VOIGT.iter().enumerate() {
        for (s, &(i, j)) in VOIGT.iter().enumerate() {
            T[(r, s)] = if i == j {
                M[(I, i)] * M[(J, i)]
            } else {
                M[(I, i)] * M[(J, j)] + M[(I, j)] * M[(J, i)]
            };
        }
    }
    T
}

#[cfg(test)]
pub(crate) mod tests;
