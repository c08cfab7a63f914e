//! Internal force vector and tangent stiffness of one hex8 (2×2×2 Gauss).
//!
//! Degrees of freedom are node-major: (u_0x, u_0y, u_0z, u_1x, …, u_7z); X are the
//! reference positions, u the nodal displacements, x = X + u.
//!
//! ## Updated Lagrangian (current configuration)
//! f_a = ∫_{φ(Ω)} σ ∇_x N_a dv = Σ_q w_q det J₀ J σ g_a  (eq. 3.4, g_a = F⁻ᵀ ∇_X N_a),
//! K_ab = ∫ [ B_aᵀ c B_b + (g_a · σ g_b) I ] dv,
//! with c the spatial tangent of the material and B_a the 6×3 linear strain operator of
//! g_a in engineering Voigt form (rows xx, yy, zz, xy, yz, xz):
//! B_a = [g_x 0 0; 0 g_y 0; 0 0 g_z; g_y g_x 0; 0 g_z g_y; g_z 0 g_x].
//! The first term is the material stiffness, the second the geometric (initial-stress) one.
//!
//! ## Total Lagrangian (reference configuration)
//! S = J F⁻¹ σ F⁻ᵀ, ℂ = pull-back of c (ℂ_IJKL = J F⁻¹_Ii F⁻¹_Jj F⁻¹_Kk F⁻¹_Ll c_ijkl),
//! f_a = ∫_Ω F S ∇_X N_a dV,
//! K_ab = ∫ [ B0_aᵀ ℂ B0_b + (G_a · S G_b) I ] dV,
//! G_a = ∇_X N_a, and B0_a the variation of the Green–Lagrange strain,
//! δE_IJ = ½ (F_kI G_aJ + F_kJ G_aI) δu_ak (engineering shear rows doubled).
//! Both formulations are the same discrete operator (F S G_a = J σ g_a, and the
//! pull-back identity), so they agree to round-off; tested.
//!
//! ## Geometrically linear materials
//! ε = sym(∇_X u), f_a = ∫_Ω σ G_a dV, K_ab = ∫ B_aᵀ c B_b dV with B of G_a, for either
//! formulation (the formulation argument is ignored).
//!
//! Everything is fixed-size and on the stack: no heap allocation.
#![allow(non_snake_case)]

use super::hex8::{jacobian_matrix, reference_gradients, shape_derivatives, ShapeGradients};
use super::kinematics::deformation_gradient;
use super::quadrature::{GAUSS_HEX_2X2X2, GAUSS_HEX_WEIGHTS};
use crate::material::{pull_back_tangent, stress_to_voigt, Material, MaterialError, MaterialModel, VOIGT};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Element vector, node-major dofs.
pub type ElementVector = SVector<f64, 24>;
/// Element matrix, node-major dofs.
pub type ElementMatrix = SMatrix<f64, 24, 24>;
/// Strain–displacement operator (6 Voigt rows, 24 dofs).
pub type BMatrix = SMatrix<f64, 6, 24>;

/// Configuration the balance of momentum is written in (the results are identical).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Formulation {
    /// Second Piola–Kirchhoff stress and material tangent over the reference volume.
    #[default]
    TotalLagrangian,
    /// Cauchy stress and spatial tangent over the current volume.
    UpdatedLagrangian,
}

/// Errors of one element evaluation (the solver adds the element id).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ElementError {
    /// J = det F ≤ 0 at a Gauss point (finite-strain materials only).
    #[error("inverted element: J = det F = {J:e} <= 0 at Gauss point {gauss_point}")]
    Inverted { gauss_point: usize, J: f64 },
    /// det(∂X/∂ξ) ≤ 0 at a Gauss point of the reference configuration: mirrored node
    /// order or collapsed hexahedron (a mesh problem, not a deformation one).
    #[error("degenerate reference element: det(dX/dxi) = {det:e} <= 0 at Gauss point {gauss_point} (mirrored node order or collapsed hexahedron)")]
    DegenerateReference { gauss_point: usize, det: f64 },
    /// Any other material failure at a Gauss point.
    #[error("material failure at Gauss point {gauss_point}: {source}")]
    Material { gauss_point: usize, source: MaterialError },
}

fn material_error(gauss_point: usize, e: MaterialError) -> ElementError {
    match e {
        MaterialError::NonPositiveJacobian { J } => ElementError::Inverted { gauss_point, J },
        source => ElementError::Material { gauss_point, source },
    }
}

/// Reference gradients at Gauss point q, or the typed error.
#[inline]
fn gauss_reference(X: &[Vector3<f64>; 8], q: usize) -> Result<(ShapeGradients, f64), ElementError> {
    reference_gradients(X, &GAUSS_HEX_2X2X2[q]).ok_or_else(|| {
        let det = jacobian_matrix(X, &shape_derivatives(&GAUSS_HEX_2X2X2[q])).determinant();
        ElementError::DegenerateReference { gauss_point: q, det }
    })
}

/// Linear strain operator of the gradients `g` (rows (∇N_a)ᵀ), engineering Voigt rows.
#[inline]
pub fn b_matrix_linear(g: &ShapeGradients) -> BMatrix {
    let mut B = BMatrix::zeros();
    for a in 0..8 {
        let (gx, gy, gz) = (g[(a, 0)], g[(a, 1)], g[(a, 2)]);
        let c = 3 * a;
        B[(0, c)] = gx;
        B[(1, c + 1)] = gy;
        B[(2, c + 2)] = gz;
        B[(3, c)] = gy;
        B[(3, c + 1)] = gx;
        B[(4, c + 1)] = gz;
        B[(4, c + 2)] = gy;
        B[(5, c)] = gz;
        B[(5, c + 2)] = gx;
    }
    B
}

/// Green–Lagrange variation operator: row (I, J) of B0_a maps δu_a to
/// δE_IJ = ½(F_kI G_aJ + F_kJ G_aI) δu_ak (shear rows 2δE_IJ).
#[inline]
pub fn b_matrix_green_lagrange(G: &ShapeGradients, F: &Matrix3<f64>) -> BMatrix {
    let mut B = BMatrix::zeros();
    for a in 0..8 {
        for k in 0..3 {
            for (m, &(I, J)) in VOIGT.iter().enumerate() {
                B[(m, 3 * a + k)] = if I == J {
                    F[(k, I)] * G[(a, I)]
                } else {
                    F[(k, I)] * G[(a, J)] + F[(k, J)] * G[(a, I)]
                };
            }
        }
    }
    B
}

/// Adds the initial-stress term w (g_a · T g_b) δ_ik to K.
#[inline]
fn add_geometric(k: &mut ElementMatrix, g: &ShapeGradients, T: &Matrix3<f64>, w: f64) {
    let gT = g * T; // row a: g_aᵀ T
    for a in 0..8 {
        for b in 0..8 {
            let s = w * (gT.row(a) * g.row(b).transpose())[(0, 0)];
            for i in 0..3 {
                k[(3 * a + i, 3 * b + i)] += s;
            }
        }
    }
}

fn integrate(
    X: &[Vector3<f64>; 8],
    u: &[Vector3<f64>; 8],
    mat: &MaterialModel,
    form: Formulation,
    r: &mut ElementVector,
    mut k: Option<&mut ElementMatrix>,
) -> Result<(), ElementError> {
    r.fill(0.0);
    if let Some(k) = k.as_deref_mut() {
        k.fill(0.0);
    }
    let linear = mat.is_geometrically_linear();
    for (q, wq) in GAUSS_HEX_WEIGHTS.iter().enumerate() {
        let (G, det0) = gauss_reference(X, q)?;
        let w = wq * det0;
        let F = deformation_gradient(&G, u);
        let err = |e| material_error(q, e);
        if linear {
            let B = b_matrix_linear(&G);
            if let Some(k) = k.as_deref_mut() {
                let (sigma, c) = mat.stress_tangent(&F).map_err(err)?;
                r.gemv_tr(w, &B, &stress_to_voigt(&sigma), 1.0);
                k.gemm_tr(w, &B, &(c * B), 1.0);
            } else {
                let sigma = mat.stress(&F).map_err(err)?;
                r.gemv_tr(w, &B, &stress_to_voigt(&sigma), 1.0);
            }
            continue;
        }
        let J = F.determinant();
        if J.is_nan() || J <= 0.0 {
            return Err(ElementError::Inverted { gauss_point: q, J });
        }
        let Finv = F.try_inverse().ok_or(ElementError::Inverted { gauss_point: q, J })?;
        let (sigma, c) = if k.is_some() {
            let (s, c) = mat.stress_tangent(&F).map_err(err)?;
            (s, Some(c))
        } else {
            (mat.stress(&F).map_err(err)?, None)
        };
        match form {
            Formulation::UpdatedLagrangian => {
                let g = G * Finv;
                let dv = w * J;
                let B = b_matrix_linear(&g);
                r.gemv_tr(dv, &B, &stress_to_voigt(&sigma), 1.0);
                if let (Some(k), Some(c)) = (k.as_deref_mut(), c) {
                    k.gemm_tr(dv, &B, &(c * B), 1.0);
                    add_geometric(k, &g, &sigma, dv);
                }
            }
            Formulation::TotalLagrangian => {
                let S = Finv * sigma * Finv.transpose() * J;
                let B0 = b_matrix_green_lagrange(&G, &F);
                r.gemv_tr(w, &B0, &stress_to_voigt(&S), 1.0);
                if let (Some(k), Some(c)) = (k.as_deref_mut(), c) {
                    let C = pull_back_tangent(&c, &Finv, J);
                    k.gemm_tr(w, &B0, &(C * B0), 1.0);
                    add_geometric(k, &G, &S, w);
                }
            }
        }
    }
    Ok(())
}

/// Internal force vector `r` = f_int = ∫ Bᵀσ dv and tangent `k` = ∂f_int/∂u of one
/// hex8 (both overwritten). `form` is ignored for geometrically linear materials.
pub fn hex8_residual_tangent(
    X: &[Vector3<f64>; 8],
    u: &[Vector3<f64>; 8],
    mat: &MaterialModel,
    form: Formulation,
    r: &mut ElementVector,
    k: &mut ElementMatrix,
) -> Result<(), ElementError> {
    integrate(X, u, mat, form, r, Some(k))
}

/// Internal force vector only (overwritten); cheaper than [`hex8_residual_tangent`].
pub fn hex8_residual(
    X: &[Vector3<f64>; 8],
    u: &[Vector3<f64>; 8],
    mat: &MaterialModel,
    form: Formulation,
    r: &mut ElementVector,
) -> Result<(), ElementError> {
    integrate(X, u, mat, form, r, None)
}

/// Strain energy of the element, Σ_q w_q det J₀ W(F_q) (its gradient is the internal
/// force vector; used in tests and available for line searches).
pub fn hex8_energy(X: &[Vector3<f64>; 8], u: &[Vector3<f64>; 8], mat: &MaterialModel) -> Result<f64, ElementError> {
    let mut e = 0.0;
    for (q, wq) in GAUSS_HEX_WEIGHTS.iter().enumerate() {
        let (G, det0) = gauss_reference(X, q)?;
        let F = deformation_gradient(&G, u);
        e += wq * det0 * mat.energy(&F).map_err(|e| material_error(q, e))?;
    }
    Ok(e)
}

/// Cauchy stress at the 8 Gauss points, in Gauss order (point q nearest local node q,
/// see [`crate::fem::quadrature`]). For geometrically linear materials: the small-strain σ.
pub fn hex8_gauss_stresses(
    X: &[Vector3<f64>; 8],
    u: &[Vector3<f64>; 8],
    mat: &MaterialModel,
) -> Result<[Matrix3<f64>; 8], ElementError> {
    let mut out = [Matrix3::zeros(); 8];
    for (q, s) in out.iter_mut().enumerate() {
        let (G, _) = gauss_reference(X, q)?;
        let F = deformation_gradient(&G, u);
        *s = mat.stress(&F).map_err(|e| material_error(q, e))?;
    }
    Ok(out)
}

/// Strain energy ∫ W(F) dV of the element (reference volume, 2×2×2 Gauss points).
pub fn hex8_strain_energy(X: &[Vector3<f64>; 8], u: &[Vector3<f64>; 8], mat: &MaterialModel) -> Result<f64, ElementError> {
    let mut w = 0.0;
    for q in 0..8 {
        let (G, det0) = gauss_reference(X, q)?;
        let F = deformation_gradient(&G, u);
        w += mat.energy(&F).map_err(|e| material_error(q, e))? * det0;
    }
    Ok(w)
}

/// Smallest volume ratio J = det F = det(∂x/∂ξ) / det(∂X/∂ξ) over the 8 Gauss points
/// (may be ≤ 0: this is the inversion check, it does not fail on it). Fails only on
/// a degenerate reference element.
pub fn hex8_min_jacobian(X: &[Vector3<f64>; 8], u: &[Vector3<f64>; 8]) -> Result<f64, ElementError> {
    let x: [Vector3<f64>; 8] = std::array::from_fn(|a| X[a] + u[a]);
    let mut min = f64::INFINITY;
    for (q, xi) in GAUSS_HEX_2X2X2.iter().enumerate() {
        let dN = shape_derivatives(xi);
        let det0 = jacobian_matrix(X, &dN).determinant();
        if det0.is_nan() || det0 <= 0.0 {
            return Err(ElementError::DegenerateReference {
                gauss_point: q,
                det: det0,
            });
        }
        min = min.min(jacobian_matrix(&x, &dN).determinant() / det0);
    }
    Ok(min)
}
