//! Tensor-product B-spline patch over the master surface nodes, paper eqs. 5.2, 4.11–4.13, 6.3.
//!
//! With control points `B_{i,j}` (the *current* master node positions, stored at
//! `i + na·j`) and open uniform knot vectors of orders `k_a`, `k_b` (eq. 5.1):
//! ```text
//! x̄(ξ¹, ξ²) = Σ_i Σ_j Q_{i/j}(ξ) B_{i,j},      Q_{i/j} = N_{i,ka}(ξ¹) M_{j,kb}(ξ²)      (5.2, 6.3)
//! ā_α      = x̄_{,α}          = Σ Q_{i/j,α}  B_{i,j}                                     (4.13)
//! ā_{α,β}  = x̄_{,αβ}         = Σ Q_{i/j,αβ} B_{i,j}
//! ā_{α,βγ} = x̄_{,αβγ}        = Σ Q_{i/j,αβγ} B_{i,j}                                    (4.24)
//! n̄        = ā_1 × ā_2 / ‖ā_1 × ā_2‖
//! ā_αβ     = ā_α · ā_β,   ā^{αβ} = (ā_αβ)⁻¹                                              (4.11)
//! b̄_αβ     = ā_{α,β} · n̄                                                                (4.12)
//! n̄_{,α}   = −b̄_αβ ā^{βγ} ā_γ    (Weingarten)
//! ```
//! Only the `k_a·k_b` functions of the current knot span are nonzero; their control
//! point indices and values `Q`, `Q_{,α}`, `Q_{,αβ}` travel in [`SurfaceBasis`] so the
//! contact element can distribute forces to the control points (vectors N, N_α, T_α of
//! eq. 6.2 are `−Q n̄`, `−Q_{,α} n̄`, `−Q ā_α` per control point).
#![allow(non_snake_case)]

use super::basis::{basis_funs_into, ders_basis_funs_into, BasisDers};
use super::{KnotVector, Mat2, SplineError, Vec3, MAX_NODES, MAX_ORDER};

/// The nonzero tensor-product basis functions at one parameter (eq. 6.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceBasis {
    len: usize,
    nodes: [usize; MAX_NODES],
    q: [f64; MAX_NODES],
    q_alpha: [[f64; 2]; MAX_NODES],
    q_alpha_beta: [[[f64; 2]; 2]; MAX_NODES],
}

impl Default for SurfaceBasis {
    fn default() -> Self {
        Self {
            len: 0,
            nodes: [0; MAX_NODES],
            q: [0.0; MAX_NODES],
            q_alpha: [[0.0; 2]; MAX_NODES],
            q_alpha_beta: [[[0.0; 2]; 2]; MAX_NODES],
        }
    }
}

impl SurfaceBasis {
    /// Number of nonzero functions (`k_a·k_b`; 4 for a facet).
    pub fn len(&self) -> usize {
        self.len
    }
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Control point index (`i + na·j`) of each nonzero function.
    pub fn nodes(&self) -> &[usize] {
        &self.nodes[..self.len]
    }
    /// `Q_{a/b}` (eq. 6.3).
    pub fn q(&self) -> &[f64] {
        &self.q[..self.len]
    }
    /// `Q_{a/b,α}`, `[α]` per function.
    pub fn q_alpha(&self) -> &[[f64; 2]] {
        &self.q_alpha[..self.len]
    }
    /// `Q_{a/b,αβ}`, `[α][β]` per function.
    pub fn q_alpha_beta(&self) -> &[[[f64; 2]; 2]] {
        &self.q_alpha_beta[..self.len]
    }

    /// Renumber the control points (`node → map(node)`) and rescale the derivatives
    /// to a parameter `ξ_patch = lo + h ξ_local` (Q_{,α} ·= h_α, Q_{,αβ} ·= h_α h_β).
    pub(crate) fn remap_scale(&mut self, map: impl Fn(usize) -> usize, h: [f64; 2]) {
        for l in 0..self.len {
            self.nodes[l] = map(self.nodes[l]);
            for al in 0..2 {
                self.q_alpha[l][al] *= h[al];
                for be in 0..2 {
                    self.q_alpha_beta[l][al][be] *= h[al] * h[be];
                }
            }
        }
    }

    pub(crate) fn clear(&mut self) {
        self.len = 0;
    }

    pub(crate) fn push(&mut self, node: usize, q: f64, q_alpha: [f64; 2], q_alpha_beta: [[f64; 2]; 2]) {
        let l = self.len;
        self.nodes[l] = node;
        self.q[l] = q;
        self.q_alpha[l] = q_alpha;
        self.q_alpha_beta[l] = q_alpha_beta;
        self.len = l + 1;
    }
}

/// Everything the contact kinematics needs at one surface parameter ξ̄.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SurfacePoint {
    /// Parameter (ξ¹, ξ²) ∈ [0, 1]².
    pub xi: [f64; 2],
    /// x̄ (eq. 5.2).
    pub x_bar: Vec3,
    /// ā_α = x̄_{,α} (eq. 4.13).
    pub a_alpha: [Vec3; 2],
    /// ā_{α,β} = x̄_{,αβ}, symmetric in α, β.
    pub a_alpha_beta: [[Vec3; 2]; 2],
    /// ā_{α,βγ} = x̄_{,αβγ}, symmetric in all indices (eq. 4.24).
    pub a_alpha_beta_gamma: [[[Vec3; 2]; 2]; 2],
    /// n̄ = ā_1 × ā_2 / ‖ā_1 × ā_2‖ (non-finite if the net is degenerate there).
    pub n_bar: Vec3,
    /// Covariant metric ā_αβ = ā_α·ā_β (eq. 4.11).
    pub a_ab: Mat2,
    /// Contravariant metric ā^{αβ} = (ā_αβ)⁻¹.
    pub a_inv: Mat2,
    /// Curvature b̄_αβ = ā_{α,β}·n̄ (eq. 4.12).
    pub b_ab: Mat2,
    /// Nonzero basis functions and their derivatives (eqs. 6.2–6.3).
    pub basis: SurfaceBasis,
    /// Facet masters: `clamped[α]` when the foot point is held on an interior cell
    /// edge in direction α (the closest point lies on a crease of the facet set, see
    /// [`Self::hold_on_crease`]); always `[false, false]` on a B-spline patch.
    pub clamped: [bool; 2],
}

impl SurfacePoint {
    /// Fills n̄, ā_αβ, ā^{αβ}, b̄_αβ from the tangents and second derivatives.
    pub(crate) fn complete_metric(&mut self) {
        let [a1, a2] = self.a_alpha;
        let c = a1.cross(&a2);
        self.n_bar = c / c.norm();
        let g12 = a1.dot(&a2);
        self.a_ab = Mat2::new(a1.dot(&a1), g12, g12, a2.dot(&a2));
        let det = self.a_ab[(0, 0)] * self.a_ab[(1, 1)] - g12 * g12;
        self.a_inv = Mat2::new(self.a_ab[(1, 1)], -g12, -g12, self.a_ab[(0, 0)]) / det;
        self.complete_curvature();
        self.clamped = [false; 2];
    }

    /// b̄_αβ = ā_{α,β}·n̄ with the current n̄ (eq. 4.12).
    fn complete_curvature(&mut self) {
        let b = |al: usize, be: usize| self.a_alpha_beta[al][be].dot(&self.n_bar);
        self.b_ab = Mat2::new(b(0, 0), b(0, 1), b(1, 0), b(1, 1));
    }

    /// Whether the foot point is held on a crease (some ξ^α clamped).
    pub fn on_crease(&self) -> bool {
        self.clamped[0] || self.clamped[1]
    }

    /// The closest point of `x_s` lies on a crease of a facet set (an interior cell
    /// edge, `clamped[α]` in the direction it bounds, or a vertex: both), where no
    /// facet has an orthogonal projection (a point below a concave crease). The
    /// closest-point condition (x_s − x̄)·ā_α = 0 then holds only in the free
    /// directions, and the contact normal is the direction of the distance vector,
    /// `n̄ = (x_s − x̄)/g_N` with `g_N = ±‖x_s − x̄‖` signed by the side of the facet's
    /// own normal (eq. 2.2 on the facet set). b̄_αβ is recomputed with this n̄; the
    /// metric stays that of the facet. No-op when nothing is clamped or x_s lies on x̄.
    pub fn hold_on_crease(&mut self, x_s: &Vec3, clamped: [bool; 2]) {
        let d = x_s - self.x_bar;
        let len = d.norm();
        if !(clamped[0] || clamped[1]) || len == 0.0 {
            return;
        }
        let g = if d.dot(&self.n_bar) < 0.0 { -len } else { len };
        self.n_bar = d / g;
        self.clamped = clamped;
        self.complete_curvature();
    }

    /// n̄_{,α} = −b̄_αβ ā^{βγ} ā_γ (Weingarten equations), `[α]`.
    pub fn n_bar_alpha(&self) -> [Vec3; 2] {
        let w = self.b_ab * self.a_inv; // w[α][γ] = b̄_αβ ā^{βγ}
        let f = |al: usize| -(self.a_alpha[0] * w[(al, 0)] + self.a_alpha[1] * w[(al, 1)]);
        [f(0), f(1)]
    }
}

/// Position with its first and second parameter derivatives: what the projection
/// Newton iteration needs (cheaper than a full [`SurfacePoint`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jet {
    pub x: Vec3,
    pub a: [Vec3; 2],
    pub aa: [[Vec3; 2]; 2],
}

/// One B-spline patch of `na × nb` control points with orders `ka`, `kb`.
#[derive(Debug, Clone, PartialEq)]
pub struct BSplinePatch {
    knots: [KnotVector; 2],
}

impl BSplinePatch {
    /// A patch of `na × nb` control points, order `ka` along ξ¹ and `kb` along ξ²
    /// (2 ≤ k ≤ [`MAX_ORDER`], `n ≥ k` per direction).
    pub fn new(na: usize, nb: usize, ka: usize, kb: usize) -> Result<Self, SplineError> {
        Ok(Self { knots: [KnotVector::open_uniform(na, ka)?, KnotVector::open_uniform(nb, kb)?] })
    }

    /// A patch on given knot vectors (e.g. a periodic direction, see
    /// [`KnotVector::periodic_uniform`]); its control net has `kv_a.n() × kv_b.n()` points.
    pub fn with_knots(kv_a: KnotVector, kv_b: KnotVector) -> Self {
        Self { knots: [kv_a, kv_b] }
    }

    /// Control points per direction `[na, nb]`.
    pub fn n_ctrl(&self) -> [usize; 2] {
        [self.knots[0].n(), self.knots[1].n()]
    }
    /// Orders per direction `[ka, kb]`.
    pub fn orders(&self) -> [usize; 2] {
        [self.knots[0].order(), self.knots[1].order()]
    }
    /// Knot spans per direction.
    pub fn n_spans(&self) -> [usize; 2] {
        [self.knots[0].n_spans(), self.knots[1].n_spans()]
    }
    /// Knot vector of direction `alpha` (0 → ξ¹, 1 → ξ²).
    pub fn knots(&self, alpha: usize) -> &KnotVector {
        &self.knots[alpha]
    }
    /// Total number of control points `na·nb`.
    pub fn len(&self) -> usize {
        self.knots[0].n() * self.knots[1].n()
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Knot span (per direction) holding ξ.
    pub fn span_of(&self, xi: [f64; 2]) -> [usize; 2] {
        [self.knots[0].find_span(xi[0]), self.knots[1].find_span(xi[1])]
    }

    /// Checks that `x` is a finite control net of the right size.
    pub fn check_control_net(&self, x: &[Vec3]) -> Result<(), SplineError> {
        let [na, nb] = self.n_ctrl();
        if x.len() != na * nb {
            return Err(SplineError::ControlNetSize { got: x.len(), na, nb, expected: na * nb });
        }
        if let Some((index, p)) = x.iter().enumerate().find(|(_, p)| !p.iter().all(|c| c.is_finite())) {
            return Err(SplineError::NonFiniteControlPoint { index, point: [p.x, p.y, p.z] });
        }
        Ok(())
    }

    #[track_caller]
    fn assert_net(&self, x: &[Vec3]) {
        assert_eq!(x.len(), self.len(), "control net size (expected na·nb = {})", self.len());
    }

    /// x̄(ξ) only (eq. 5.2). Panics if `x.len() != na·nb`.
    pub fn point(&self, x: &[Vec3], xi: [f64; 2]) -> Vec3 {
        self.assert_net(x);
        let [sa, sb] = self.span_of(xi);
        let [ka, kb] = self.orders();
        let na = self.knots[0].n();
        let mut Na = [0.0; MAX_ORDER];
        let mut Nb = [0.0; MAX_ORDER];
        basis_funs_into(&self.knots[0], sa, xi[0], &mut Na);
        basis_funs_into(&self.knots[1], sb, xi[1], &mut Nb);
        let mut p = Vec3::zeros();
        for t in 0..kb {
            let row = &x[sa + na * (sb + t)..];
            let mut r_sum = Vec3::zeros();
            for r in 0..ka {
                r_sum += row[r] * Na[r];
            }
            p += r_sum * Nb[t];
        }
        p
    }

    /// Position and first and second derivatives at ξ (for Newton).
    pub fn jet(&self, x: &[Vec3], xi: [f64; 2]) -> Jet {
        self.jet_in_span(x, xi, self.span_of(xi))
    }

    /// [`Self::jet`] of span `[sa, sb]`'s polynomial (continued beyond the span when
    /// ξ lies outside it).
    pub fn jet_in_span(&self, x: &[Vec3], xi: [f64; 2], [sa, sb]: [usize; 2]) -> Jet {
        self.assert_net(x);
        let [ka, kb] = self.orders();
        let na = self.knots[0].n();
        let mut Da: BasisDers = [[0.0; MAX_ORDER]; 4];
        let mut Db: BasisDers = [[0.0; MAX_ORDER]; 4];
        ders_basis_funs_into(&self.knots[0], sa, xi[0], 2, &mut Da);
        ders_basis_funs_into(&self.knots[1], sb, xi[1], 2, &mut Db);
        let z = Vec3::zeros();
        let (mut p, mut a1, mut a2, mut a11, mut a12, mut a22) = (z, z, z, z, z, z);
        for t in 0..kb {
            let row = &x[sa + na * (sb + t)..];
            // partial sums along direction 1: Σ_r N^(d)_r B_rt for d = 0, 1, 2
            let (mut s0, mut s1, mut s2) = (z, z, z);
            for r in 0..ka {
                s0 += row[r] * Da[0][r];
                s1 += row[r] * Da[1][r];
                s2 += row[r] * Da[2][r];
            }
            p += s0 * Db[0][t];
            a1 += s1 * Db[0][t];
            a2 += s0 * Db[1][t];
            a11 += s2 * Db[0][t];
            a12 += s1 * Db[1][t];
            a22 += s0 * Db[2][t];
        }
        Jet { x: p, a: [a1, a2], aa: [[a11, a12], [a12, a22]] }
    }

    /// Full evaluation at ξ: x̄, ā_α, ā_{α,β}, ā_{α,βγ}, n̄, ā_αβ, ā^{αβ}, b̄_αβ and the
    /// nonzero Q_{a/b}, Q_{a/b,α}, Q_{a/b,αβ}. `x` holds the current control points
    /// (`i + na·j`); panics if `x.len() != na·nb`.
    pub fn evaluate(&self, x: &[Vec3], xi: [f64; 2]) -> SurfacePoint {
        let mut out = SurfacePoint::default();
        self.evaluate_into(x, xi, &mut out);
        out
    }

    /// [`Self::evaluate`] into a caller's buffer.
    #[allow(clippy::needless_range_loop)] // r, t, i, j are the math indices of Q = N_r M_t
    pub fn evaluate_into(&self, x: &[Vec3], xi: [f64; 2], out: &mut SurfacePoint) {
        self.evaluate_in_span_into(x, xi, self.span_of(xi), out)
    }

    /// [`Self::evaluate_into`] with span `[sa, sb]`'s polynomial.
    #[allow(clippy::needless_range_loop)]
    pub fn evaluate_in_span_into(&self, x: &[Vec3], xi: [f64; 2], [sa, sb]: [usize; 2], out: &mut SurfacePoint) {
        self.assert_net(x);
        let [ka, kb] = self.orders();
        let na = self.knots[0].n();
        let mut Da: BasisDers = [[0.0; MAX_ORDER]; 4];
        let mut Db: BasisDers = [[0.0; MAX_ORDER]; 4];
        ders_basis_funs_into(&self.knots[0], sa, xi[0], 3, &mut Da);
        ders_basis_funs_into(&self.knots[1], sb, xi[1], 3, &mut Db);
        // d[i][j] = ∂^{i+j} x̄ / ∂(ξ¹)^i ∂(ξ²)^j for i + j ≤ 3
        let mut d = [[Vec3::zeros(); 4]; 4];
        out.basis.clear();
        for t in 0..kb {
            for r in 0..ka {
                let node = (sa + r) + na * (sb + t);
                let B = x[node];
                for i in 0..4 {
                    for j in 0..4 - i {
                        d[i][j] += B * (Da[i][r] * Db[j][t]);
                    }
                }
                out.basis.push(
                    node,
                    Da[0][r] * Db[0][t],
                    [Da[1][r] * Db[0][t], Da[0][r] * Db[1][t]],
                    [[Da[2][r] * Db[0][t], Da[1][r] * Db[1][t]], [Da[1][r] * Db[1][t], Da[0][r] * Db[2][t]]],
                );
            }
        }
        out.xi = xi;
        out.x_bar = d[0][0];
        out.a_alpha = [d[1][0], d[0][1]];
        out.a_alpha_beta = [[d[2][0], d[1][1]], [d[1][1], d[0][2]]];
        // ā_{α,βγ}: the derivative count along ξ¹ is the number of zeros among (α, β, γ)
        for al in 0..2 {
            for be in 0..2 {
                for ga in 0..2 {
                    let n2 = al + be + ga;
                    out.a_alpha_beta_gamma[al][be][ga] = d[3 - n2][n2];
                }
            }
        }
        out.complete_metric();
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::super::fd;
    use super::*;

    /// A wavy, non-uniformly spaced control net (no symmetry to hide index errors).
    pub fn wavy_net(na: usize, nb: usize) -> Vec<Vec3> {
        let mut x = Vec::with_capacity(na * nb);
        for j in 0..nb {
            for i in 0..na {
                let u = i as f64 + 0.15 * (j as f64).sin();
                let v = j as f64 * 1.3 + 0.1 * (i as f64 * 0.7).cos();
                let w = 0.4 * (0.6 * u).sin() * (0.5 * v).cos() + 0.05 * u * v;
                x.push(Vec3::new(u, v, w));
            }
        }
        x
    }

    fn params() -> Vec<[f64; 2]> {
        let mut v = Vec::new();
        for i in 0..9 {
            for j in 0..7 {
                v.push([(i as f64 + 0.31) / 9.0, (j as f64 + 0.57) / 7.0]);
            }
        }
        v
    }

    /// Surface derivatives against central differences of the next lower analytic
    /// derivative. Spans are 1/m wide (m ≤ 5 here); `h = 1e-6` keeps the stencil
    /// inside one span for the chosen parameters (we skip any within 2h of a knot)
    /// and balances truncation (~h²·|x⁗| ~ 1e-12) against round-off (~ε|x|/h ~ 1e-10),
    /// relative to a derivative of size ≥ O(1): far below the 1e-6 tolerance.
    #[test]
    fn surface_derivatives_match_finite_differences() {
        let h = 1e-6;
        for (na, nb, ka, kb) in [(7, 6, 3, 3), (8, 7, 4, 3), (6, 8, 2, 5), (9, 9, 5, 4)] {
            let patch = BSplinePatch::new(na, nb, ka, kb).unwrap();
            let x = wavy_net(na, nb);
            for xi in params() {
                let near_knot = (0..2).any(|al| {
                    let kv = patch.knots(al);
                    let (lo, hi) = kv.span_bounds(kv.find_span(xi[al]));
                    xi[al] - lo < 2.0 * h || hi - xi[al] < 2.0 * h
                });
                if near_knot {
                    continue;
                }
                let sp = patch.evaluate(&x, xi);
                let tag = format!("na={na} nb={nb} ka={ka} kb={kb} xi={xi:?}");
                // scale: size of the derivatives of that order at this point (≥ 1)
                let s1 = sp.a_alpha.iter().map(|v| v.norm()).fold(1.0, f64::max);
                let s2 = sp.a_alpha_beta.iter().flatten().map(|v| v.norm()).fold(1.0, f64::max);
                let s3 = sp.a_alpha_beta_gamma.iter().flatten().flatten().map(|v| v.norm()).fold(1.0, f64::max);
                for be in 0..2 {
                    let fd_x = fd::central_vec3(|p| patch.point(&x, p), xi, be, h);
                    fd::assert_vec3_close(fd_x, sp.a_alpha[be], s1, 1e-6, &format!("a_{be} {tag}"));
                    let fd_n = fd::central_vec3(|p| patch.evaluate(&x, p).n_bar, xi, be, h);
                    fd::assert_vec3_close(fd_n, sp.n_bar_alpha()[be], 1.0, 1e-6, &format!("n_bar,{be} {tag}"));
                    for al in 0..2 {
                        let fd_a = fd::central_vec3(|p| patch.evaluate(&x, p).a_alpha[al], xi, be, h);
                        fd::assert_vec3_close(fd_a, sp.a_alpha_beta[al][be], s2, 1e-6, &format!("a_{al},{be} {tag}"));
                        for ga in 0..2 {
                            let fd_aa = fd::central_vec3(|p| patch.evaluate(&x, p).a_alpha_beta[al][be], xi, ga, h);
                            fd::assert_vec3_close(
                                fd_aa,
                                sp.a_alpha_beta_gamma[al][be][ga],
                                s3,
                                1e-6,
                                &format!("a_{al},{be}{ga} {tag}"),
                            );
                        }
                    }
                }
                // the jet agrees with the full evaluation
                let j = patch.jet(&x, xi);
                assert!((j.x - sp.x_bar).norm() < 1e-14 * s1);
                for al in 0..2 {
                    assert!((j.a[al] - sp.a_alpha[al]).norm() < 1e-13 * s1);
                    for be in 0..2 {
                        assert!((j.aa[al][be] - sp.a_alpha_beta[al][be]).norm() < 1e-13 * s2);
                    }
                }
                // Q derivatives against FD of Q (same span → same node list)
                let sp_p: Vec<SurfacePoint> = (0..2)
                    .map(|be| {
                        let mut p = xi;
                        p[be] += h;
                        patch.evaluate(&x, p)
                    })
                    .collect();
                let sp_m: Vec<SurfacePoint> = (0..2)
                    .map(|be| {
                        let mut p = xi;
                        p[be] -= h;
                        patch.evaluate(&x, p)
                    })
                    .collect();
                for be in 0..2 {
                    assert_eq!(sp_p[be].basis.nodes(), sp.basis.nodes());
                    let qs = sp.basis.q_alpha().iter().map(|q| q[be].abs()).fold(1.0, f64::max);
                    let qss = sp.basis.q_alpha_beta().iter().flatten().flatten().map(|q| q.abs()).fold(1.0, f64::max);
                    for a in 0..sp.basis.len() {
                        let fd_q = (sp_p[be].basis.q()[a] - sp_m[be].basis.q()[a]) / (2.0 * h);
                        assert!((fd_q - sp.basis.q_alpha()[a][be]).abs() < 1e-6 * qs, "Q_,{be} {tag}");
                        for al in 0..2 {
                            let fd_qa = (sp_p[be].basis.q_alpha()[a][al] - sp_m[be].basis.q_alpha()[a][al]) / (2.0 * h);
                            assert!((fd_qa - sp.basis.q_alpha_beta()[a][al][be]).abs() < 1e-6 * qss, "Q_,{al}{be} {tag}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn surface_point_identities() {
        let (na, nb) = (7, 6);
        let patch = BSplinePatch::new(na, nb, 3, 4).unwrap();
        let x = wavy_net(na, nb);
        for xi in params().into_iter().chain([[0.0, 0.0], [1.0, 1.0], [1.0, 0.3], [0.5, 1.0]]) {
            let sp = patch.evaluate(&x, xi);
            assert_eq!(sp.basis.len(), 12);
            let sum_q: f64 = sp.basis.q().iter().sum();
            assert!((sum_q - 1.0).abs() < 1e-14);
            // x̄ = Σ Q B and ā_α = Σ Q_,α B (what the contact element relies on)
            let mut xs = Vec3::zeros();
            let mut a = [Vec3::zeros(); 2];
            for (k, &node) in sp.basis.nodes().iter().enumerate() {
                xs += x[node] * sp.basis.q()[k];
                for (al, a_al) in a.iter_mut().enumerate() {
                    *a_al += x[node] * sp.basis.q_alpha()[k][al];
                }
            }
            assert!((xs - sp.x_bar).norm() < 1e-13);
            assert!((a[0] - sp.a_alpha[0]).norm() < 1e-12 && (a[1] - sp.a_alpha[1]).norm() < 1e-12);
            assert!((sp.a_ab * sp.a_inv - Mat2::identity()).norm() < 1e-12);
            assert!((sp.n_bar.norm() - 1.0).abs() < 1e-14);
            assert!(sp.n_bar.dot(&sp.a_alpha[0]).abs() < 1e-12 && sp.n_bar.dot(&sp.a_alpha[1]).abs() < 1e-12);
            assert!((sp.b_ab[(0, 1)] - sp.b_ab[(1, 0)]).abs() < 1e-14);
            assert!((patch.point(&x, xi) - sp.x_bar).norm() < 1e-13);
        }
        // corners are interpolated (open knot vectors)
        assert!((patch.point(&x, [0.0, 0.0]) - x[0]).norm() < 1e-15);
        assert!((patch.point(&x, [1.0, 0.0]) - x[na - 1]).norm() < 1e-15);
        assert!((patch.point(&x, [1.0, 1.0]) - x[na * nb - 1]).norm() < 1e-15);
    }

    #[test]
    fn control_net_validation() {
        let patch = BSplinePatch::new(4, 3, 3, 3).unwrap();
        assert_eq!(
            patch.check_control_net(&vec![Vec3::zeros(); 11]),
            Err(SplineError::ControlNetSize { got: 11, na: 4, nb: 3, expected: 12 })
        );
        let mut x = wavy_net(4, 3);
        assert!(patch.check_control_net(&x).is_ok());
        x[5].y = f64::NAN;
        assert!(matches!(patch.check_control_net(&x), Err(SplineError::NonFiniteControlPoint { index: 5, .. })));
        assert_eq!(BSplinePatch::new(3, 5, 4, 2), Err(SplineError::TooFewControlPoints { n: 3, order: 4 }));
    }
}
