//! The node-to-surface element with Coulomb friction (eqs. 4.2–4.10, 6.2; the law in
//! [`super::friction`]) evaluated on forward-mode dual numbers, for its exact tangent.
//!
//! **Tangent.** K = ∂r/∂u, non-symmetric in slip. Instead of transcribing the
//! paper's eqs. 4.19–4.22 (whose printed indices are inconsistent), K is the exact
//! derivative of `r` by forward-mode dual numbers: for every element dof j the
//! inputs are seeded with their derivative along e_j — x_s, x_A, and ξ̄ through its
//! first variation ∂ξ̄/∂u (eq. 4.10) — and the surface quantities with theirs
//! (x̄' = Q_A x_A' + ā_α ξ̄^α', ā_α' = Q_{A,α} x_A' + ā_{α,β} ξ̄^β', Q_A' = Q_{A,α} ξ̄^α').
//! Evaluating `r` on these duals gives
//! column j of K to round-off, including every metric, curvature and return-mapping
//! term. Cost O(m²) for an element of m dofs, like the analytical form.
//!
//! **Crease contact** (facet masters, [`SurfacePoint::on_crease`]): the foot point is
//! held on a cell edge or vertex in the clamped directions, n̄ = (x_s − x̄)/g_N and
//! g_N = ±‖x_s − x̄‖; ξ̄ varies only in the free directions, `D` restricted to them
//! (see `docs/theory.md`, "Facet dead zones: crease contact"). The frictionless
//! element routes such a node here with [`FrictionLaw::NONE`]. With friction the
//! tangential part uses the tangent vectors projected normal to n̄, ã_α = ā_α −
//! (ā_α·n̄) n̄, and the inverse of their metric, so the friction force turns
//! with n̄ across the dead zone ("Friction on a crease").

use nalgebra::{DMatrix, DVector};

use super::dual::{cross, d3, dot, inv2, scale, sub, Dual, D3};
use super::law::{ContactElementError, FrictionLaw, FrictionState, NormalLaw};
use crate::spline::{SurfacePoint, Vec3, MAX_NODES};

/// The element's dofs: `3(1 + n_c)` ≤ this.
const MAX_DOFS: usize = 3 * (1 + MAX_NODES);

/// Inverse of the 2×2 matrix `m` restricted to the free directions (rows and
/// columns of clamped directions zero): on a crease ξ̄ moves only along it. `None` if
/// singular.
fn inv_free(m: [[Dual; 2]; 2], clamped: [bool; 2]) -> Option<[[Dual; 2]; 2]> {
    match clamped {
        [false, false] => inv2(m),
        [true, true] => Some([[Dual::ZERO; 2]; 2]),
        [c0, _] => {
            let al = usize::from(c0);
            let mut out = [[Dual::ZERO; 2]; 2];
            if m[al][al].v == 0.0 || !m[al][al].v.is_finite() {
                return None;
            }
            out[al][al] = Dual::cst(1.0) / m[al][al];
            Some(out)
        }
    }
}

/// The element, by dual numbers. `given_t_n`: the tangential part alone for that
/// normal pressure (see [`tangential_contact`](super::friction::tangential_contact));
/// then `dr_dtn` receives ∂r/∂t_N. Without it the node is pressed
/// (λ_N + ε_N g_N < 0): the callers hand open and touching nodes, and frictionless
/// ones off a crease, to the analytical [`normal_contact`](super::element::normal_contact).
#[allow(clippy::too_many_arguments)]
pub(super) fn evaluate(
    xs: &Vec3,
    sp: &SurfacePoint,
    normal: &NormalLaw,
    friction: &FrictionLaw,
    given_t_n: Option<f64>,
    r: &mut DVector<f64>,
    mut k: Option<&mut DMatrix<f64>>,
    mut dr_dtn: Option<&mut DVector<f64>>,
) -> Result<FrictionState, ContactElementError> {
    let nc = sp.basis.len();
    let m = 3 * (1 + nc);
    let g0 = (xs - sp.x_bar).dot(&sp.n_bar);
    let crease = sp.on_crease();
    if let Some(t) = given_t_n {
        if r.len() != m {
            *r = DVector::zeros(m);
        }
        r.fill(0.0);
        if let Some(k) = k.as_deref_mut() {
            *k = DMatrix::zeros(m, m);
        }
        if let Some(d) = dr_dtn.as_deref_mut() {
            *d = DVector::zeros(m);
        }
        if t >= 0.0 || friction.mu == 0.0 && friction.eps_t == 0.0 {
            return Ok(FrictionState { g_n: g0, t_n: t.min(0.0), active: t < 0.0, t_t: [0.0; 2], t_t_vector: Vec3::zeros(), slip: false, slave_force: Vec3::zeros() });
        }
    }
    if r.len() != m {
        *r = DVector::zeros(m);
    }
    if let Some(k) = k.as_deref_mut() {
        if k.shape() != (m, m) {
            *k = DMatrix::zeros(m, m);
        }
    }
    let first = if k.is_some() { 0 } else { m };
    // First variation of ξ̄ (eq. 4.10) in floats: w_β = T_β − g N_β, δξ̄ = D w.
    let q = sp.basis.q();
    let qa = sp.basis.q_alpha();
    // (on a crease, sp.clamped: ξ̄ moves only in the free directions, D restricted to them)
    let m0 = sp.a_ab - sp.b_ab * g0;
    let d0 = inv_free([[Dual::cst(m0[(0, 0)]), Dual::cst(m0[(0, 1)])], [Dual::cst(m0[(1, 0)]), Dual::cst(m0[(1, 1)])]], sp.clamped)
        .map(|d| nalgebra::Matrix2::new(d[0][0].v, d[0][1].v, d[1][0].v, d[1][1].v))
        .ok_or(ContactElementError::FocalPoint { g_n: g0 })?;
    let mut w = [[0.0; MAX_DOFS]; 2];
    for c in 0..3 {
        for be in 0..2 {
            w[be][c] = sp.a_alpha[be][c];
            for a in 0..nc {
                w[be][3 * (1 + a) + c] = -q[a] * sp.a_alpha[be][c] + g0 * qa[a][be] * sp.n_bar[c];
            }
        }
    }
    let mut state = None;
    // j < m: seed direction e_j; j = m: values only (the residual and the state);
    // j = m + 1 (a given t_N with dr_dtn): seed t_N alone
    let last = if given_t_n.is_some() && dr_dtn.is_some() { m + 1 } else { m };
    for j in first..=last {
        let (slave_dir, master_dir) = if j < 3 {
            (Some(j), None)
        } else if j < m {
            (None, Some(((j - 3) / 3, j % 3)))
        } else {
            (None, None)
        };
        let dxi: [f64; 2] = if j < m { [d0[(0, 0)] * w[0][j] + d0[(0, 1)] * w[1][j], d0[(1, 0)] * w[0][j] + d0[(1, 1)] * w[1][j]] } else { [0.0; 2] };
        // seeded surface quantities
        let e = |c: usize| {
            let mut v = Vec3::zeros();
            v[c] = 1.0;
            v
        };
        let dxs = slave_dir.map_or(Vec3::zeros(), e);
        let qd: [Dual; MAX_NODES] = std::array::from_fn(|a| if a < nc { Dual::new(q[a], qa[a][0] * dxi[0] + qa[a][1] * dxi[1]) } else { Dual::ZERO });
        let mut dx_bar = sp.a_alpha[0] * dxi[0] + sp.a_alpha[1] * dxi[1];
        let mut da = [sp.a_alpha_beta[0][0] * dxi[0] + sp.a_alpha_beta[0][1] * dxi[1], sp.a_alpha_beta[1][0] * dxi[0] + sp.a_alpha_beta[1][1] * dxi[1]];
        if let Some((a, c)) = master_dir {
            dx_bar[c] += q[a];
            for al in 0..2 {
                da[al][c] += qa[a][al];
            }
        }
        let x_s = d3(xs, &dxs);
        let x_bar = d3(&sp.x_bar, &dx_bar);
        let a_al = [d3(&sp.a_alpha[0], &da[0]), d3(&sp.a_alpha[1], &da[1])];
        // n̄, g_N, metric (eqs. 4.3, 4.11); on a crease n̄ = (x_s − x̄)/g_N
        let n = if crease {
            let dist = sub(&x_s, &x_bar);
            let sign = if g0 < 0.0 { -1.0 } else { 1.0 };
            scale(&dist, Dual::cst(sign) / dot(&dist, &dist).sqrt())
        } else {
            let cr = cross(&a_al[0], &a_al[1]);
            scale(&cr, Dual::cst(1.0) / dot(&cr, &cr).sqrt())
        };
        let g = dot(&sub(&x_s, &x_bar), &n);
        // Friction on a crease: the tangent vectors projected normal to n = d/g_N carry
        // the tangential traction (metric, return mapping, transfer), so the friction
        // force turns with n across the dead zone (docs/theory.md, "Friction on a crease")
        let crease_friction = crease && friction.mu > 0.0;
        let a_t = if crease_friction { [0, 1].map(|al| sub(&a_al[al], &scale(&n, dot(&a_al[al], &n)))) } else { a_al };
        let met = [[dot(&a_t[0], &a_t[0]), dot(&a_t[0], &a_t[1])], [dot(&a_t[1], &a_t[0]), dot(&a_t[1], &a_t[1])]];
        let met_inv = inv2(met).ok_or(ContactElementError::FocalPoint { g_n: g0 })?;
        // normal law (eq. 4.2), or the given pressure
        let t_n = match given_t_n {
            Some(t) => Dual::new(t, if j == m + 1 { 1.0 } else { 0.0 }),
            None => Dual::cst(normal.lambda_n) + g * normal.eps_n,
        };
        // the normal part of r (a given pressure: the caller's)
        let t_nn = if given_t_n.is_some() { Dual::ZERO } else { t_n };
        // trial tangential traction and return mapping (eqs. 4.6–4.8)
        let xi = [Dual::new(sp.xi[0], dxi[0]), Dual::new(sp.xi[1], dxi[1])];
        let slip_xi = [xi[0] - Dual::cst(friction.xi_n[0]), xi[1] - Dual::cst(friction.xi_n[1])];
        let tr = [0, 1].map(|al| Dual::cst(friction.t_t_n[al]) + (met[al][0] * slip_xi[0] + met[al][1] * slip_xi[1]) * friction.eps_t);
        let norm2 = tr[0] * met_inv[0][0] * tr[0] + tr[0] * met_inv[0][1] * tr[1] + tr[1] * met_inv[1][0] * tr[0] + tr[1] * met_inv[1][1] * tr[1];
        let limit = -t_n * friction.mu; // μ|t_N|, t_N < 0
        let slip = norm2.v > 0.0 && friction.held_slip.unwrap_or(norm2.v.sqrt() > limit.v);
        let t_t = if slip {
            let nrm = norm2.sqrt();
            [tr[0] * limit / nrm, tr[1] * limit / nrm]
        } else {
            tr
        };
        // Transfer (docs/theory.md, "Friction: the transfer"): δξ̄^α = ā^{αβ} T_β, eq. 4.10
        // at g_N = 0, so t_Tα δξ̄^α = t_T·(δx_s − Q_A δx_A) with the traction vector
        // t_T = t_Tα ā^{αβ} ā_β: the friction force on the slave is −A_s t_T itself and
        // stays continuous where the curvature b̄ jumps (the knots of an order-3
        // master). On a crease the metric is the projected one, the tangent normal to n.
        let t_up = [met_inv[0][0] * t_t[0] + met_inv[0][1] * t_t[1], met_inv[1][0] * t_t[0] + met_inv[1][1] * t_t[1]];
        let t_vec: D3 = [0, 1, 2].map(|c| t_up[0] * a_t[0][c] + t_up[1] * a_t[1][c]);
        // r = A (t_N N + t_Tα ā^{αβ} T_β), assembled per node block
        let area = normal.area;
        let mut put = |i: usize, v: Dual| {
            if j < m {
                if let Some(k) = k.as_deref_mut() {
                    k[(i, j)] = v.d * area;
                }
            } else if j == m {
                r[i] = v.v * area;
            } else if let Some(d) = dr_dtn.as_deref_mut() {
                d[i] = v.d * area;
            }
        };
        // slave block: N_s = n̄, T_β,s = ā_β
        for c in 0..3 {
            put(c, t_nn * n[c] + t_vec[c]);
        }
        // control point A: N_A = −Q_A n̄, T_β,A = −Q_A ā_β
        for (a, &q_a) in qd.iter().enumerate().take(nc) {
            for c in 0..3 {
                put(3 * (1 + a) + c, -q_a * (t_nn * n[c] + t_vec[c]));
            }
        }
        if j == m {
            state = Some(FrictionState {
                g_n: g.v,
                t_n: t_n.v,
                active: true,
                t_t: [t_t[0].v, t_t[1].v],
                t_t_vector: Vec3::new(t_vec[0].v, t_vec[1].v, t_vec[2].v),
                slip,
                slave_force: Vec3::zeros(),
            });
        }
    }
    let mut state = state.expect("the value pass ran");
    state.slave_force = -Vec3::new(r[0], r[1], r[2]);
    Ok(state)
}
