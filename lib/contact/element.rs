//! Frictionless node-to-surface contact of one slave node against the master surface
//! (paper secs. 4, 4.1, 6; Wriggers, *Computational Contact Mechanics*, 2006, ch. 9.3).
//!
//! Unknowns of the element: `u = [x_s; x_1 … x_n]` (slave node, then the `n = n_c`
//! control points with nonzero basis `Q_A` at the projection ξ̄, in the order of
//! [`SurfaceBasis::nodes`](crate::spline::SurfaceBasis::nodes)), length `3(1 + n)`.
//!
//! Sign convention (documented also in `docs/theory.md`, "Frictionless node-to-surface
//! contact"):
//! ```text
//! g_N = (x_s − x̄(ξ̄))·n̄                  negative = penetration           (4.3)
//! t_N = min(0, λ_N + ε_N g_N)             λ_N ≤ 0, t_N ≤ 0 compressive
//! active ⇔ λ_N + ε_N g_N < 0
//! r   = t_N A_s N,     N = [n̄; −Q_1 n̄; …; −Q_n n̄] = ∂g_N/∂u            (6.2)
//! K   = ∂r/∂u = ε_N A_s N Nᵀ + t_N A_s ∂²g_N/∂u²   (active; r = K = 0 otherwise)
//! ```
//! `r` is the contact contribution to the *internal* force vector (`δΠ_c = t_N δg_N A_s`):
//! the force exerted on the slave node is `−r_s = −t_N A_s n̄`, along +n̄ (out of the
//! master) when compressive. With `T_α = [ā_α; −Q_A ā_α]`, `N_α = [0; −Q_{A,α} n̄]`,
//! `m_αβ = ā_αβ − g_N b̄_αβ`, `D = m⁻¹` and `Δξ̄^α = D^{αβ} (T_β − g_N N_β)·Δu`:
//! ```text
//! ∂²g_N = N_α ⊗ Δξ̄^α + ā^{αβ} T_β ⊗ N_α − ā^{αγ} b̄_γβ T_α ⊗ Δξ̄^β
//! ```
//! (rows: δu, columns: Δu; symmetric, it is the Hessian of g_N). The derivation is in
//! `docs/theory.md`; the tests check `K` against central differences of `r` with the
//! slave node re-projected at every perturbation.

use nalgebra::{DMatrix, DVector};

use crate::spline::{BSplinePatch, FacetSurface, SurfacePoint, Vec3};

/// Outcome of one slave-node evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactState {
    /// Normal gap g_N = (x_s − x̄)·n̄ (negative = penetration).
    pub g_n: f64,
    /// Contact pressure t_N = min(0, λ_N + ε_N g_N) (≤ 0; compressive).
    pub t_n: f64,
    /// Whether λ_N + ε_N g_N < 0 (the node carries force).
    pub active: bool,
}

/// The master surface kind: the B-spline patch or the bilinear facets over the same net.
#[derive(Debug, Clone, Copy)]
pub enum MasterSurface<'a> {
    BSpline(&'a BSplinePatch),
    Facet(&'a FacetSurface),
}

impl MasterSurface<'_> {
    /// [`SurfacePoint`] at ξ̄ from the full control net `x_all`, and the `n_c` control
    /// points with nonzero basis there (order of `sp.basis.nodes()`): the inputs of
    /// [`normal_contact`].
    pub fn evaluate_local(&self, x_all: &[Vec3], xi: [f64; 2]) -> (SurfacePoint, Vec<Vec3>) {
        let sp = match self {
            MasterSurface::BSpline(p) => p.evaluate(x_all, xi),
            MasterSurface::Facet(f) => f.evaluate(x_all, xi),
        };
        let xm = sp.basis.nodes().iter().map(|&k| x_all[k]).collect();
        (sp, xm)
    }
}

/// Residual `r` (length `3(1 + n_c)`) and consistent tangent `K = ∂r/∂u` of one
/// slave node `xs` in frictionless contact with the master, penalty / augmented
/// Lagrangian law `t_N = min(0, λ_N + ε_N g_N)` (see module docs for the sign
/// convention). `xm` are the `n_c` control points of `sp.basis.nodes()` and `sp` is the
/// surface point at the converged closest-point projection ξ̄ (built from `xm`);
/// `area` is the slave node's tributary area A_s. `r` and `k` are resized if needed
/// and overwritten; both are zero when the node is inactive.
#[allow(clippy::too_many_arguments)]
pub fn normal_contact(
    xs: &Vec3,
    xm: &[Vec3],
    sp: &SurfacePoint,
    lambda_n: f64,
    eps_n: f64,
    area: f64,
    r: &mut DVector<f64>,
    k: &mut DMatrix<f64>,
) -> ContactState {
    let nc = sp.basis.len();
    assert_eq!(xm.len(), nc, "normal_contact: one master point per nonzero basis function");
    let m = 3 * (1 + nc);
    if r.len() != m {
        *r = DVector::zeros(m);
    } else {
        r.fill(0.0);
    }
    if k.shape() != (m, m) {
        *k = DMatrix::zeros(m, m);
    } else {
        k.fill(0.0);
    }
    let n = sp.n_bar;
    let g = (xs - sp.x_bar).dot(&n);
    let trial = lambda_n + eps_n * g;
    if trial >= 0.0 {
        return ContactState { g_n: g, t_n: 0.0, active: false };
    }
    let t = trial;
    let q = sp.basis.q();
    let qa = sp.basis.q_alpha();
    // N, T_α, N_α as full vectors (small: 3(1+n_c) ≤ 111)
    let mut nv = DVector::zeros(m);
    let mut tv = [DVector::zeros(m), DVector::zeros(m)];
    let mut na = [DVector::zeros(m), DVector::zeros(m)];
    for c in 0..3 {
        nv[c] = n[c];
        for al in 0..2 {
            tv[al][c] = sp.a_alpha[al][c];
        }
        for a in 0..nc {
            let i = 3 * (1 + a) + c;
            nv[i] = -q[a] * n[c];
            for al in 0..2 {
                tv[al][i] = -q[a] * sp.a_alpha[al][c];
                na[al][i] = -qa[a][al] * n[c];
            }
        }
    }
    // Δξ̄^α = D^{αβ} (T_β − g N_β)·Δu,  D = (ā_αβ − g b̄_αβ)⁻¹
    let mm = sp.a_ab - sp.b_ab * g;
    let d = mm.try_inverse().expect("normal_contact: singular ā_αβ − g b̄_αβ (slave at a focal point)");
    let w = [&tv[0] - &na[0] * g, &tv[1] - &na[1] * g];
    let dxi = [&w[0] * d[(0, 0)] + &w[1] * d[(0, 1)], &w[0] * d[(1, 0)] + &w[1] * d[(1, 1)]];
    let ai = sp.a_inv;
    let c = ai * sp.b_ab; // c[(α, β)] = ā^{αγ} b̄_γβ
    // Hessian of g_N
    let mut h = DMatrix::zeros(m, m);
    for al in 0..2 {
        h.ger(1.0, &na[al], &dxi[al], 1.0);
        for be in 0..2 {
            h.ger(ai[(al, be)], &tv[be], &na[al], 1.0);
            h.ger(-c[(al, be)], &tv[al], &dxi[be], 1.0);
        }
    }
    r.copy_from(&(&nv * (t * area)));
    k.copy_from(&(h * (t * area)));
    k.ger(eps_n * area, &nv, &nv, 1.0);
    ContactState { g_n: g, t_n: t, active: true }
}
