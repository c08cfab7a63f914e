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
//! K is built in 3×3 node blocks K_ab: at each Gauss point the upper ones (a ≤ b,
//! with D B_b formed once per node), the lower ones by symmetry after the last point
//! (every material here is hyperelastic, so c and ℂ have major symmetry).
//!
//! Everything is fixed-size and on the stack: no heap allocation.
#![allow(non_snake_case)]

use super::hex8::{jacobian_matrix, reference_gradients, shape_derivatives, ShapeGradients};
use super::kinematics::deformation_gradient;
use super::quadrature::{GAUSS_HEX_2X2X2, GAUSS_HEX_WEIGHTS};
use crate::material::{pull_back_tangent, stress_to_voigt, Material, MaterialError, MaterialModel, Tangent, VOIGT, voigt_index};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3, Vector6};

/// Element vector, node-major dofs.
pub type ElementVector = SVector<f64, 24>;
/// Element matrix, node-major dofs.
pub type ElementMatrix = SMatrix<f64, 24, 24>;

/// Configuration the balance of momentum is written in (the results are identical).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Formulation {
    /// Second Piola–Kirchhoff stress and material tangent over the reference volume.
    TotalLagrangian,
    /// Cauchy stress and spatial tangent over the current volume: the paper's ("written
    /// in the current configuration"), and half the tangent's arithmetic (its B is sparse).
    #[default]
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

/// One node's columns of the strain–displacement operator: `b[m][k]` is Voigt row m
/// (engineering shear rows) for the node's displacement component k.
pub type NodeB = [[f64; 3]; 6];

/// Linear strain operator of the gradients `g` (rows (∇N_a)ᵀ), engineering Voigt
/// rows, one 6×3 block per node:
/// B_a = [g_x 0 0; 0 g_y 0; 0 0 g_z; g_y g_x 0; 0 g_z g_y; g_z 0 g_x].
#[inline]
pub fn b_linear(g: &ShapeGradients) -> [NodeB; 8] {
    let mut B = [[[0.0; 3]; 6]; 8];
    for (a, b) in B.iter_mut().enumerate() {
        let (gx, gy, gz) = (g[(a, 0)], g[(a, 1)], g[(a, 2)]);
        *b = [[gx, 0.0, 0.0], [0.0, gy, 0.0], [0.0, 0.0, gz], [gy, gx, 0.0], [0.0, gz, gy], [gz, 0.0, gx]];
    }
    B
}

/// Green–Lagrange variation operator, one 6×3 block per node: row (I, J) of B0_a maps
/// δu_a to δE_IJ = ½(F_kI G_aJ + F_kJ G_aI) δu_ak (shear rows 2δE_IJ).
#[inline]
pub fn b_green_lagrange(G: &ShapeGradients, F: &Matrix3<f64>) -> [NodeB; 8] {
    let mut B = [[[0.0; 3]; 6]; 8];
    for (a, b) in B.iter_mut().enumerate() {
        for (m, &(I, J)) in VOIGT.iter().enumerate() {
            for k in 0..3 {
                b[m][k] = if I == J { F[(k, I)] * G[(a, I)] } else { F[(k, I)] * G[(a, J)] + F[(k, J)] * G[(a, I)] };
            }
        }
    }
    B
}

/// r_a += w B_aᵀ s (s the Voigt stress).
#[inline]
fn add_force(r: &mut ElementVector, B: &[NodeB; 8], s: &Vector6<f64>, w: f64) {
    for (a, ba) in B.iter().enumerate() {
        for k in 0..3 {
            let mut f = 0.0;
            for m in 0..6 {
                f += ba[m][k] * s[m];
            }
            r[3 * a + k] += w * f;
        }
    }
}

/// Upper node blocks (a ≤ b) of w [B_aᵀ D B_b + (g_a · T g_b) I]: the material and the
/// initial-stress stiffness of one Gauss point. D (the Voigt tangent) has major
/// symmetry (every material here is hyperelastic), so K_ba = K_abᵀ: the lower blocks
/// are filled once, after the last point ([`mirror_lower_blocks`]).
#[inline]
fn add_stiffness(k: &mut ElementMatrix, B: &[NodeB; 8], D: &Tangent, (g, T): (&ShapeGradients, &Matrix3<f64>), w: f64) {
    // DB_b = D B_b (6×3)
    let mut DB = [[[0.0; 3]; 6]; 8];
    for (db, bb) in DB.iter_mut().zip(B) {
        for (m, dbm) in db.iter_mut().enumerate() {
            for (n, bn) in bb.iter().enumerate() {
                let d = D[(m, n)];
                for kk in 0..3 {
                    dbm[kk] += d * bn[kk];
                }
            }
        }
    }
    // T g_b, for the initial-stress term
    let mut Tg = [Vector3::zeros(); 8];
    for (b, tg) in Tg.iter_mut().enumerate() {
        *tg = T * g.row(b).transpose();
    }
    for a in 0..8 {
        for b in a..8 {
            let mut kab = [[0.0; 3]; 3];
            for m in 0..6 {
                for i in 0..3 {
                    let bai = B[a][m][i];
                    for j in 0..3 {
                        kab[i][j] += bai * DB[b][m][j];
                    }
                }
            }
            let s = g[(a, 0)] * Tg[b][0] + g[(a, 1)] * Tg[b][1] + g[(a, 2)] * Tg[b][2];
            for (i, row) in kab.iter_mut().enumerate() {
                row[i] += s;
            }
            for (i, row) in kab.iter().enumerate() {
                for (j, v) in row.iter().enumerate() {
                    k[(3 * a + i, 3 * b + j)] += w * v;
                }
            }
        }
    }
}

/// Voigt index of the tensor index pair (k, l): `V[k][l]` ([`voigt_index`] as a table).
const V: [[usize; 3]; 3] = {
    let mut v = [[0; 3]; 3];
    let mut k = 0;
    while k < 3 {
        let mut l = 0;
        while l < 3 {
            v[k][l] = voigt_index(k, l);
            l += 1;
        }
        k += 1;
    }
    v
};

/// r_a += w σ g_a: [`add_force`] for the linear operator of `g` ([`b_linear`]), whose
/// column k holds g_l in Voigt row (k, l).
#[inline]
fn add_force_spatial(r: &mut ElementVector, g: &ShapeGradients, sigma: &Matrix3<f64>, w: f64) {
    for a in 0..8 {
        let f = sigma * g.row(a).transpose();
        for k in 0..3 {
            r[3 * a + k] += w * f[k];
        }
    }
}

/// [`add_stiffness`] for the linear operator of `g` ([`b_linear`]), using its
/// sparsity, accumulated over the Gauss points of one element:
/// K_ab[i][j] += Σ_k g_ak H_b[V(i, k)][j] + δ_ij s_ab with H_b[m][j] = w Σ_l D[m][V(j, l)] g_bl
/// and s_ab = w g_a · T g_b, a third of the dense products' work. This is the
/// updated Lagrangian tangent (and the small-strain one).
///
/// The sums run over the row node a in the innermost loops, on 8-lane arrays
/// (`kt[b][j][i][a]` = K_ab[i][j]), which the compiler turns into vector
/// instructions: 4 lanes where the CPU has AVX2 ([`hex8_residual_tangent`] picks
/// that build at run time), 2 lanes otherwise. Every lane does the same operations
/// in the same order either way (no fused multiply-add, no reduction across lanes),
/// so both builds give the same bits. All 64 blocks are summed, the upper ones
/// (a ≤ b) are kept and the lower ones mirrored ([`mirror_lower_blocks`]): K is
/// symmetric to the bit.
struct SpatialStiffness {
    kt: [[[[f64; 8]; 3]; 3]; 8],
}

impl SpatialStiffness {
    fn new() -> Self {
        Self { kt: [[[[0.0; 8]; 3]; 3]; 8] }
    }

    #[inline(always)]
    fn add(&mut self, g: &ShapeGradients, D: &Tangent, T: Option<&Matrix3<f64>>, w: f64) {
        // g by columns: gc[l][a] = g_al
        let gc: [[f64; 8]; 3] = std::array::from_fn(|l| std::array::from_fn(|a| g[(a, l)]));
        // h[m][j][b] = w Σ_l D[m][V(j, l)] g_bl
        let mut h = [[[0.0; 8]; 3]; 6];
        for (m, hm) in h.iter_mut().enumerate() {
            for (j, hmj) in hm.iter_mut().enumerate() {
                let d: [f64; 3] = std::array::from_fn(|l| w * D[(m, V[j][l])]);
                for b in 0..8 {
                    hmj[b] = d[0] * gc[0][b] + d[1] * gc[1][b] + d[2] * gc[2][b];
                }
            }
        }
        // tg[k][b] = w (T g_b)_k
        let mut tg = [[0.0; 8]; 3];
        if let Some(T) = T {
            for (k, tgk) in tg.iter_mut().enumerate() {
                let t: [f64; 3] = std::array::from_fn(|l| w * T[(k, l)]);
                for b in 0..8 {
                    tgk[b] = t[0] * gc[0][b] + t[1] * gc[1][b] + t[2] * gc[2][b];
                }
            }
        }
        for (b, ktb) in self.kt.iter_mut().enumerate() {
            for (j, ktbj) in ktb.iter_mut().enumerate() {
                for (i, col) in ktbj.iter_mut().enumerate() {
                    let hv: [f64; 3] = std::array::from_fn(|k| h[V[i][k]][j][b]);
                    for a in 0..8 {
                        col[a] += gc[0][a] * hv[0] + gc[1][a] * hv[1] + gc[2][a] * hv[2];
                    }
                }
            }
            if T.is_some() {
                add_diagonal_term(ktb, &gc, &tg, b);
            }
        }
    }

    /// [`Self::add`] for an isotropic spatial tangent `c = α (1 ⊗ 1) + β 𝕀`
    /// ([`MaterialModel::isotropic_stress_tangent`]), whose contraction with the
    /// gradients needs no Voigt products:
    /// K_ab[i][j] += w [α g_ai g_bj + β/2 (g_aj g_bi + δ_ij g_a · g_b)] + δ_ij w g_a · T g_b,
    /// two products per entry instead of three and no `h` (the Parisch blocks'
    /// element 1.8× fewer operations). The same lanes and order in every build.
    #[inline(always)]
    fn add_isotropic(&mut self, g: &ShapeGradients, alpha: f64, beta: f64, T: Option<&Matrix3<f64>>, w: f64) {
        let gc: [[f64; 8]; 3] = std::array::from_fn(|l| std::array::from_fn(|a| g[(a, l)]));
        let (wa, wh) = (w * alpha, 0.5 * w * beta);
        // tg[k][b] = w β/2 g_bk + w (T g_b)_k: the diagonal term is Σ_k g_ak tg[k][b]
        let mut tg = [[0.0; 8]; 3];
        for (k, tgk) in tg.iter_mut().enumerate() {
            for b in 0..8 {
                tgk[b] = wh * gc[k][b];
            }
        }
        if let Some(T) = T {
            for (k, tgk) in tg.iter_mut().enumerate() {
                let t: [f64; 3] = std::array::from_fn(|l| w * T[(k, l)]);
                for b in 0..8 {
                    tgk[b] += t[0] * gc[0][b] + t[1] * gc[1][b] + t[2] * gc[2][b];
                }
            }
        }
        for (b, ktb) in self.kt.iter_mut().enumerate() {
            for (j, ktbj) in ktb.iter_mut().enumerate() {
                let a_bj = wa * gc[j][b];
                for (i, col) in ktbj.iter_mut().enumerate() {
                    let h_bi = wh * gc[i][b];
                    for a in 0..8 {
                        col[a] += gc[i][a] * a_bj + gc[j][a] * h_bi;
                    }
                }
            }
            add_diagonal_term(ktb, &gc, &tg, b);
        }
    }

    /// Adds the upper node blocks (a ≤ b) into `k`.
    fn add_upper_to(&self, k: &mut ElementMatrix) {
        for (b, ktb) in self.kt.iter().enumerate() {
            for (j, ktbj) in ktb.iter().enumerate() {
                for (i, col) in ktbj.iter().enumerate() {
                    for (a, &v) in col.iter().enumerate().take(b + 1) {
                        k[(3 * a + i, 3 * b + j)] += v;
                    }
                }
            }
        }
    }
}

/// The diagonal term of the column node `b`'s blocks, K_ab[j][j] += s_ab with
/// s_ab = Σ_k g_ak tg[k][b] (`gc[k][a]` = g_ak), in [`SpatialStiffness`]'s
/// layout (`ktb[j][i][a]` = K_ab[i][j]).
#[inline(always)]
fn add_diagonal_term(ktb: &mut [[[f64; 8]; 3]; 3], gc: &[[f64; 8]; 3], tg: &[[f64; 8]; 3], b: usize) {
    let t: [f64; 3] = std::array::from_fn(|k| tg[k][b]);
    let mut s = [0.0; 8];
    for a in 0..8 {
        s[a] = gc[0][a] * t[0] + gc[1][a] * t[1] + gc[2][a] * t[2];
    }
    for (j, ktbj) in ktb.iter_mut().enumerate() {
        for (v, sa) in ktbj[j].iter_mut().zip(&s) {
            *v += sa;
        }
    }
}

/// Fills the lower node blocks (a > b) of `k` from the upper ones: K_ab = K_baᵀ.
fn mirror_lower_blocks(k: &mut ElementMatrix) {
    for b in 0..8 {
        for a in b + 1..8 {
            for i in 0..3 {
                for j in 0..3 {
                    k[(3 * a + i, 3 * b + j)] = k[(3 * b + j, 3 * a + i)];
                }
            }
        }
    }
}

#[inline(always)]
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
    // the spatial tangents' upper blocks, summed over the points (updated Lagrangian
    // and small strain; the total Lagrangian one adds into `k` itself)
    let mut spatial = SpatialStiffness::new();
    let linear = mat.is_geometrically_linear();
    let spatial_used = linear || matches!(form, Formulation::UpdatedLagrangian);
    for (q, wq) in GAUSS_HEX_WEIGHTS.iter().enumerate() {
        let (G, det0) = gauss_reference(X, q)?;
        let w = wq * det0;
        let F = deformation_gradient(&G, u);
        let err = |e| material_error(q, e);
        if linear {
            if k.is_some() {
                if let Some(iso) = mat.isotropic_stress_tangent(&F) {
                    let (sigma, alpha, beta) = iso.map_err(err)?;
                    add_force_spatial(r, &G, &sigma, w);
                    spatial.add_isotropic(&G, alpha, beta, None, w);
                    continue;
                }
                let (sigma, c) = mat.stress_tangent(&F).map_err(err)?;
                add_force_spatial(r, &G, &sigma, w);
                spatial.add(&G, &c, None, w);
            } else {
                let sigma = mat.stress(&F).map_err(err)?;
                add_force_spatial(r, &G, &sigma, w);
            }
            continue;
        }
        let J = F.determinant();
        if J.is_nan() || J <= 0.0 {
            return Err(ElementError::Inverted { gauss_point: q, J });
        }
        let Finv = F.try_inverse().ok_or(ElementError::Inverted { gauss_point: q, J })?;
        if k.is_some() && matches!(form, Formulation::UpdatedLagrangian) {
            if let Some(iso) = mat.isotropic_stress_tangent(&F) {
                let (sigma, alpha, beta) = iso.map_err(err)?;
                let g = G * Finv;
                let dv = w * J;
                add_force_spatial(r, &g, &sigma, dv);
                spatial.add_isotropic(&g, alpha, beta, Some(&sigma), dv);
                continue;
            }
        }
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
                add_force_spatial(r, &g, &sigma, dv);
                if let Some(c) = c {
                    spatial.add(&g, &c, Some(&sigma), dv);
                }
            }
            Formulation::TotalLagrangian => {
                let S = Finv * sigma * Finv.transpose() * J;
                let B0 = b_green_lagrange(&G, &F);
                add_force(r, &B0, &stress_to_voigt(&S), w);
                if let (Some(k), Some(c)) = (k.as_deref_mut(), c) {
                    let C = pull_back_tangent(&c, &Finv, J);
                    add_stiffness(k, &B0, &C, (&G, &S), w);
                }
            }
        }
    }
    if let Some(k) = k {
        if spatial_used {
            spatial.add_upper_to(k);
        }
        mirror_lower_blocks(k);
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
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above)
        return unsafe { integrate_avx2(X, u, mat, form, r, k) };
    }
    integrate(X, u, mat, form, r, Some(k))
}

/// [`integrate`] compiled for AVX2: the 8-lane sums of [`SpatialStiffness`] in 4-lane
/// vectors, with the same operations in the same order (the same bits).
///
/// # Safety
/// The CPU must have AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn integrate_avx2(
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

#[cfg(test)]
mod sparse_operator_tests {
    use super::*;

    /// The build of the element chosen at run time (AVX2 where the CPU has it) and
    /// the portable one give the same residual and tangent, bit for bit, for every
    /// material and both formulations.
    #[test]
    fn every_build_of_the_element_gives_the_same_bits() {
        use crate::material::neo_hookean::{CiarletSimo, DevVolNeoHookean};
        use crate::material::linear::LinearElastic;
        let X: [Vector3<f64>; 8] = std::array::from_fn(|a| {
            let (x, y, z) = ((a & 1) ^ ((a >> 1) & 1), (a >> 1) & 1, a >> 2);
            Vector3::new(x as f64 * 1.1 + 0.05 * z as f64, y as f64 * 0.9, z as f64 * 1.3 + 0.02 * x as f64)
        });
        let u: [Vector3<f64>; 8] = std::array::from_fn(|a| Vector3::new(0.013 * a as f64, -0.021 * (a % 3) as f64, 0.017 * (a % 2) as f64 - 0.01));
        let materials: [MaterialModel; 3] = [
            CiarletSimo::from_young_poisson(2.1e5, 0.3).unwrap().into(),
            DevVolNeoHookean::from_young_poisson(7.0e4, 0.45).unwrap().into(),
            LinearElastic::from_young_poisson(1.0e3, 0.2).unwrap().into(),
        ];
        for mat in &materials {
            for form in [Formulation::UpdatedLagrangian, Formulation::TotalLagrangian] {
                let (mut r1, mut k1, mut r2, mut k2) = (ElementVector::zeros(), ElementMatrix::zeros(), ElementVector::zeros(), ElementMatrix::zeros());
                hex8_residual_tangent(&X, &u, mat, form, &mut r1, &mut k1).unwrap();
                integrate(&X, &u, mat, form, &mut r2, Some(&mut k2)).unwrap();
                assert!(r1.iter().zip(r2.iter()).all(|(a, b)| a.to_bits() == b.to_bits()), "{mat:?} {form:?}");
                assert!(k1.iter().zip(k2.iter()).all(|(a, b)| a.to_bits() == b.to_bits()), "{mat:?} {form:?}");
            }
        }
    }

    /// The sparse products of the linear operator ([`SpatialStiffness`],
    /// [`add_force_spatial`]) equal the dense ones of [`b_linear`]'s blocks, for any
    /// gradients, symmetric tangent and stress (to round-off: 1e-14 of the entries).
    #[test]
    fn sparse_products_equal_the_dense_blocks() {
        let v = |i: usize| ((i * 7919 % 113) as f64 / 113.0 - 0.5) * 2.0;
        let g = ShapeGradients::from_fn(|a, j| v(3 * a + j + 1));
        let mut D = Tangent::from_fn(|m, n| v(40 + 6 * m + n));
        D = D + D.transpose();
        let T = Matrix3::from_fn(|i, j| v(90 + i + j));
        let w = 0.37;
        let (mut kd, mut ks) = (ElementMatrix::zeros(), ElementMatrix::zeros());
        add_stiffness(&mut kd, &b_linear(&g), &D, (&g, &T), w);
        let mut spatial = SpatialStiffness::new();
        spatial.add(&g, &D, Some(&T), w);
        spatial.add_upper_to(&mut ks);
        mirror_lower_blocks(&mut kd);
        mirror_lower_blocks(&mut ks);
        assert!((kd - ks).abs().max() < 1e-14 * kd.abs().max(), "{:e}", (kd - ks).abs().max());
        let (mut rd, mut rs) = (ElementVector::zeros(), ElementVector::zeros());
        add_force(&mut rd, &b_linear(&g), &stress_to_voigt(&T), w);
        add_force_spatial(&mut rs, &g, &T, w);
        assert!((rd - rs).abs().max() < 1e-14 * rd.abs().max());
    }

    /// The isotropic kernel ([`SpatialStiffness::add_isotropic`]) is the general
    /// one ([`SpatialStiffness::add`]) of `c = α (1 ⊗ 1) + β 𝕀`, with and without a
    /// stress, to round-off (1e-14 of the entries).
    #[test]
    fn the_isotropic_kernel_is_the_general_one_of_its_tangent() {
        use crate::material::{identity_outer, sym_identity};
        let v = |i: usize| ((i * 7919 % 113) as f64 / 113.0 - 0.5) * 2.0;
        let g = ShapeGradients::from_fn(|a, j| v(3 * a + j + 1));
        let (alpha, beta) = (1.7, 0.6);
        let c = identity_outer() * alpha + sym_identity() * beta;
        let T = Matrix3::from_fn(|i, j| v(90 + i + j));
        for stress in [None, Some(&T)] {
            let (mut general, mut iso) = (SpatialStiffness::new(), SpatialStiffness::new());
            general.add(&g, &c, stress, 0.37);
            iso.add_isotropic(&g, alpha, beta, stress, 0.37);
            let (mut kg, mut ki) = (ElementMatrix::zeros(), ElementMatrix::zeros());
            general.add_upper_to(&mut kg);
            iso.add_upper_to(&mut ki);
            assert!(kg.abs().max() > 0.1);
            assert!((kg - ki).abs().max() < 1e-14 * kg.abs().max(), "{:e}", (kg - ki).abs().max());
        }
    }
}
