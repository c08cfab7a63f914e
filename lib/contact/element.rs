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
//! (rows: δu, columns: Δu; symmetric, it is the Hessian of g_N). A node in contact
//! with a crease of a facet master (`sp.clamped`) is evaluated by the dual-number
//! element of [`super::dual_element`] with no friction. The derivation is in
//! `docs/theory.md`; the tests check `K` against central differences of `r` with the
//! slave node re-projected at every perturbation.

use nalgebra::{DMatrix, DVector, DVectorView};

pub use super::law::{ContactElementError, ContactState, NormalLaw};
use super::law::FrictionLaw;
use crate::spline::{BSplinePatch, FacetSurface, SurfacePoint, Vec3, MAX_NODES};

/// Largest element size `3(1 + n_c)`.
const MAX_DOFS: usize = 3 * (1 + MAX_NODES);

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

/// `r` and `k` zeroed at size `m` and `m × m` (storage kept when the size fits).
pub(crate) fn zero_element(r: &mut DVector<f64>, k: &mut DMatrix<f64>, m: usize) {
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
}

/// The first `m` entries of a stack buffer as a vector view.
fn view(v: &[f64; MAX_DOFS], m: usize) -> DVectorView<'_, f64> {
    DVectorView::from_slice(&v[..m], m)
}

/// Residual `r` (length `3(1 + n_c)`) and consistent tangent `K = ∂r/∂u` of one
/// slave node `xs` in frictionless contact with the master, penalty / augmented
/// Lagrangian law `t_N = min(0, λ_N + ε_N g_N)` (see module docs for the sign
/// convention). `sp` is the surface point at the converged closest-point projection
/// ξ̄ (its basis lists the `n_c` control points the element couples to). `r` and `k`
/// are resized if needed and overwritten; both are zero when the node is open (and
/// `k` holds only ε_N A_s N Nᵀ when it is touching, see [`NormalLaw::touch`]).
/// No heap allocation when `r` and `k` already have the right size.
pub fn normal_contact(
    xs: &Vec3,
    sp: &SurfacePoint,
    law: &NormalLaw,
    r: &mut DVector<f64>,
    k: &mut DMatrix<f64>,
) -> Result<ContactState, ContactElementError> {
    let nc = sp.basis.len();
    let m = 3 * (1 + nc);
    zero_element(r, k, m);
    let n = sp.n_bar;
    let g = (xs - sp.x_bar).dot(&n); // eq. 4.3
    let trial = law.lambda_n + law.eps_n * g; // eq. 4.2
    let touching = trial <= law.eps_n * law.touch;
    if trial >= 0.0 && !touching {
        return Ok(ContactState { g_n: g, t_n: 0.0, active: false });
    }
    let q = sp.basis.q();
    let qa = sp.basis.q_alpha();
    // N = ∂g_N/∂u (eq. 6.2), T_α = [ā_α; −Q_A ā_α], N_α = [0; −Q_{A,α} n̄]; stack buffers
    let mut nv = [0.0; MAX_DOFS];
    let mut tv = [[0.0; MAX_DOFS]; 2];
    let mut na = [[0.0; MAX_DOFS]; 2];
    #[allow(clippy::needless_range_loop)] // c: Cartesian index, a: basis index, al: α
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
    let a_s = law.area;
    if trial >= 0.0 {
        // touching, not pressed: closed-branch stiffness only
        k.ger(law.eps_n * a_s, &view(&nv, m), &view(&nv, m), 1.0);
        return Ok(ContactState { g_n: g, t_n: 0.0, active: false });
    }
    if sp.on_crease() {
        // contact with a crease of a facet set: the normal follows the distance
        // vector, ξ̄ moves only along the crease (see `super::dual_element`)
        let st = super::dual_element::evaluate(xs, sp, law, &FrictionLaw::NONE, None, r, Some(k), None)?;
        return Ok(ContactState { g_n: st.g_n, t_n: st.t_n, active: st.active });
    }
    let t = trial;
    // Δξ̄^α = D^{αβ} (T_β − g N_β)·Δu,  D = (ā_αβ − g b̄_αβ)⁻¹
    let mm = sp.a_ab - sp.b_ab * g;
    let d = mm.try_inverse().ok_or(ContactElementError::FocalPoint { g_n: g })?;
    let mut dxi = [[0.0; MAX_DOFS]; 2];
    for i in 0..m {
        let w = [tv[0][i] - g * na[0][i], tv[1][i] - g * na[1][i]];
        for al in 0..2 {
            dxi[al][i] = d[(al, 0)] * w[0] + d[(al, 1)] * w[1];
        }
    }
    let ai = sp.a_inv;
    let c = ai * sp.b_ab; // c[(α, β)] = ā^{αγ} b̄_γβ
    // K = t_N A_s ∂²g_N + ε_N A_s N Nᵀ (eq. 6.5), ∂²g_N as in the module docs
    let ta = t * a_s;
    for al in 0..2 {
        k.ger(ta, &view(&na[al], m), &view(&dxi[al], m), 1.0);
        for be in 0..2 {
            k.ger(ta * ai[(al, be)], &view(&tv[be], m), &view(&na[al], m), 1.0);
            k.ger(-ta * c[(al, be)], &view(&tv[al], m), &view(&dxi[be], m), 1.0);
        }
    }
    k.ger(law.eps_n * a_s, &view(&nv, m), &view(&nv, m), 1.0);
    for i in 0..m {
        r[i] = ta * nv[i]; // eq. 6.2: r = t_N A_s N
    }
    Ok(ContactState { g_n: g, t_n: t, active: true })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::fem::fd::{fd_jacobian, rel_err, FdStep};
    use crate::spline::Mat2;

    /// Cylindrical (radius 4 about the ξ²-parallel axis), wavy control net with unit
    /// control-point spacing: curvature in both directions and a non-orthogonal
    /// parametrisation (the rows are sheared).
    /// A test master that owns its surface: facets (order 0) or a B-spline patch of
    /// equal orders in both directions over an na × nb net.
    pub(crate) enum TestMaster {
        BSpline(BSplinePatch),
        Facet(FacetSurface),
    }

    impl TestMaster {
        pub(crate) fn new(na: usize, nb: usize, order: usize) -> Self {
            if order == 0 {
                Self::Facet(FacetSurface::new(na, nb).unwrap())
            } else {
                Self::BSpline(BSplinePatch::new(na, nb, order, order).unwrap())
            }
        }

        pub(crate) fn surface(&self) -> MasterSurface<'_> {
            match self {
                Self::BSpline(p) => MasterSurface::BSpline(p),
                Self::Facet(f) => MasterSurface::Facet(f),
            }
        }
    }

    pub(crate) fn curved_net(na: usize, nb: usize) -> Vec<Vec3> {
        let rad = 4.0;
        let mut x = Vec::with_capacity(na * nb);
        for j in 0..nb {
            for i in 0..na {
                let th = (i as f64 + 0.2 * j as f64) / rad;
                let y = j as f64 + 0.15 * (i as f64 * 0.9).sin();
                let w = 0.12 * (0.8 * y).sin();
                x.push(Vec3::new((rad + w) * th.sin(), y, (rad + w) * th.cos() - rad));
            }
        }
        x
    }

    /// Closest point near `xi0` by Newton on f_α = (x_s − x̄)·ā_α = 0,
    /// ∂f_α/∂ξ^β = −ā_αβ + (x_s − x̄)·ā_{α,β}; converged to round-off.
    pub(crate) fn reproject(surf: &MasterSurface, x_all: &[Vec3], xs: &Vec3, xi0: [f64; 2]) -> [f64; 2] {
        let mut xi = xi0;
        for _ in 0..50 {
            let (sp, _) = surf.evaluate_local(x_all, xi);
            let d = xs - sp.x_bar;
            let f = nalgebra::Vector2::new(d.dot(&sp.a_alpha[0]), d.dot(&sp.a_alpha[1]));
            let jac = Mat2::from_fn(|a, b| -sp.a_ab[(a, b)] + d.dot(&sp.a_alpha_beta[a][b]));
            let step = -jac.try_inverse().unwrap() * f;
            xi[0] += step[0];
            xi[1] += step[1];
            if step.norm() < 1e-17 {
                break;
            }
        }
        xi
    }

    /// The element's unknowns `u = [x_s; x_A]` (A over `nodes`).
    pub(crate) fn element_dofs(xs: &Vec3, x_all: &[Vec3], nodes: &[usize]) -> Vec<f64> {
        let mut u = vec![0.0; 3 * (1 + nodes.len())];
        for c in 0..3 {
            u[c] = xs[c];
            for (a, &nd) in nodes.iter().enumerate() {
                u[3 * (1 + a) + c] = x_all[nd][c];
            }
        }
        u
    }

    /// The slave position and the whole net with the element's unknowns set to `v`.
    pub(crate) fn with_element_dofs(v: &[f64], x_all: &[Vec3], nodes: &[usize]) -> (Vec3, Vec<Vec3>) {
        let mut x = x_all.to_vec();
        for (a, &nd) in nodes.iter().enumerate() {
            x[nd] = Vec3::new(v[3 * (1 + a)], v[3 * (1 + a) + 1], v[3 * (1 + a) + 2]);
        }
        (Vec3::new(v[0], v[1], v[2]), x)
    }

    /// Central differences of an element residual over u = [x_s; x_A] (the control
    /// points of `nodes`), the slave re-projected near `xi0` at every perturbation;
    /// `residual(x_s, sp, r)` evaluates the element at the perturbed state. h = 1e-7 ×
    /// max(|u_j|, 1): truncation ~h² × (third derivative) ≈ 1e-14 |K|, round-off
    /// ~ε|r|/h ≈ 1e-9 |r|, projection round-off ~1e-16 in ξ̄ → 1e-9, all ≪ 1e-6 of K.
    pub(crate) fn fd_element(surf: &MasterSurface, x_all: &[Vec3], nodes: &[usize], xs0: &Vec3, xi0: [f64; 2], residual: impl Fn(&Vec3, &SurfacePoint, &mut DVector<f64>)) -> DMatrix<f64> {
        let m = 3 * (1 + nodes.len());
        let u = element_dofs(xs0, x_all, nodes);
        fd_jacobian(
            |v, out| {
                let (xs, x) = with_element_dofs(v, x_all, nodes);
                let xi = reproject(surf, &x, &xs, xi0);
                let (sp, _) = surf.evaluate_local(&x, xi);
                assert_eq!(sp.basis.nodes(), nodes, "perturbation left the span");
                let mut rr = DVector::zeros(m);
                residual(&xs, &sp, &mut rr);
                out.copy_from_slice(rr.as_slice());
            },
            &u,
            m,
            FdStep { rel_step: 1e-7, scale: 1.0 },
        )
    }

    struct Case {
        name: String,
        surf_kind: (usize, usize, usize), // (na, nb, order); order 0 = facet
        xi0: [f64; 2],
    }

    /// Runs one geometry with the laws (λ_N, ε_N) below and returns the worst FD error.
    fn check_case(case: &Case) -> f64 {
        let (na, nb, order) = case.surf_kind;
        let master = TestMaster::new(na, nb, order);
        let surf = master.surface();
        let x_all = curved_net(na, nb);
        let size = 1.0; // control point spacing = element size
        let (sp0, xm0) = surf.evaluate_local(&x_all, case.xi0);
        let nodes: Vec<usize> = sp0.basis.nodes().to_vec();
        let nc = nodes.len();
        let g0 = -1e-2 * size;
        let xs0 = sp0.x_bar + sp0.n_bar * g0;
        let area = 0.7;
        let mut worst: f64 = 0.0;
        // (λ_N, ε_N): pure penalty, augmented, and fixed multiplier (ε = 0: K is the
        // geometric part t_N A_s ∂²g_N alone, so the curvature terms are tested bare)
        for (lambda, eps) in [(0.0, 1e3), (-2.0, 50.0), (-1.0, 0.0)] {
            let (mut r, mut k) = (DVector::zeros(0), DMatrix::zeros(0, 0));
            let st = normal_contact(&xs0, &sp0, &NormalLaw { lambda_n: lambda, eps_n: eps, area, touch: 0.0 }, &mut r, &mut k).unwrap();
            assert!(st.active && (st.g_n - g0).abs() < 1e-14, "{}: {st:?}", case.name);
            assert!((st.t_n - (lambda + eps * g0)).abs() < 1e-12);
            // action = reaction: Σ_nodes f = 0; moment about the origin Σ x × f = t A g n̄ × n̄ = 0
            let mut f = Vec3::zeros();
            let mut mom = Vec3::zeros();
            for a in 0..=nc {
                let fa = Vec3::new(r[3 * a], r[3 * a + 1], r[3 * a + 2]);
                let xa = if a == 0 { xs0 } else { xm0[a - 1] };
                f += fa;
                mom += xa.cross(&fa);
            }
            let scale = (st.t_n * area).abs();
            assert!(f.norm() < 1e-12 * scale, "{}: force sum {f:?}", case.name);
            assert!(mom.norm() < 1e-10 * scale * 10.0, "{}: moment {mom:?}", case.name);
            assert!((&k - k.transpose()).norm() < 1e-10 * k.norm(), "{}: K not symmetric", case.name);
            let fd = fd_element(&surf, &x_all, &nodes, &xs0, case.xi0, |xs, sp, rr| {
                let mut kk = DMatrix::zeros(0, 0);
                normal_contact(xs, sp, &NormalLaw { lambda_n: lambda, eps_n: eps, area, touch: 0.0 }, rr, &mut kk).unwrap();
            });
            let e = rel_err(k.as_slice(), fd.as_slice());
            eprintln!("FD {} λ={lambda} ε={eps}: rel err {e:.2e} (|K|={:.3e})", case.name, k.norm());
            assert!(e < 1e-6, "{} λ={lambda} ε={eps}: FD rel err {e:e}", case.name);
            if eps == 0.0 {
                // the curvature terms matter: dropping b̄_αβ must break the FD match
                let mut flat = sp0;
                flat.b_ab = Mat2::zeros();
                let (mut r2, mut k2) = (DVector::zeros(0), DMatrix::zeros(0, 0));
                normal_contact(&xs0, &flat, &NormalLaw { lambda_n: lambda, eps_n: eps, area, touch: 0.0 }, &mut r2, &mut k2).unwrap();
                let e_flat = rel_err(k2.as_slice(), fd.as_slice());
                eprintln!("   without b̄_αβ terms: rel err {e_flat:.2e}");
                assert!(e_flat > 1e-3, "{}: curvature terms too small to be tested ({e_flat:e})", case.name);
            }
            worst = worst.max(e);
        }
        worst
    }

    fn mid(s: usize, m: usize) -> f64 {
        (s as f64 + 0.37) / m as f64
    }

    #[test]
    fn tangent_matches_finite_differences() {
        let (na, nb) = (7, 6);
        let mut cases = Vec::new();
        // facet: cells = spans of order 2 (na − 1 × nb − 1)
        for (order, label) in [(0, "facet"), (2, "bspline k=2"), (3, "bspline k=3"), (4, "bspline k=4")] {
            let k = order.max(2);
            let (ma, mb) = (na - k + 1, nb - k + 1);
            cases.push(Case {
                name: format!("{label} interior"),
                surf_kind: (na, nb, order),
                xi0: [mid(ma / 2, ma), mid(mb / 2, mb)],
            });
            cases.push(Case {
                name: format!("{label} edge span"),
                surf_kind: (na, nb, order),
                xi0: [mid(0, ma), mid(mb - 1, mb)],
            });
        }
        for c in &cases {
            check_case(c);
        }
    }

    #[test]
    fn inactive_gives_zero() {
        let patch = BSplinePatch::new(6, 5, 3, 3).unwrap();
        let surf = MasterSurface::BSpline(&patch);
        let x = curved_net(6, 5);
        let (sp, _) = surf.evaluate_local(&x, [0.4, 0.6]);
        let (mut r, mut k) = (DVector::from_element(3, 1.0), DMatrix::from_element(2, 2, 1.0));
        // open gap, no multiplier
        let st = normal_contact(&(sp.x_bar + sp.n_bar * 0.01), &sp, &NormalLaw { lambda_n: 0.0, eps_n: 1e3, area: 1.0, touch: 0.0 }, &mut r, &mut k).unwrap();
        assert!(!st.active && st.t_n == 0.0 && (st.g_n - 0.01).abs() < 1e-14);
        assert_eq!(r.len(), 3 * (1 + 9));
        assert!(r.iter().all(|&v| v == 0.0) && k.iter().all(|&v| v == 0.0) && k.nrows() == 30);
        // penetration but a tensile multiplier outweighs it (augmented Lagrangian release)
        let st = normal_contact(&(sp.x_bar - sp.n_bar * 0.01), &sp, &NormalLaw { lambda_n: 20.0, eps_n: 1e3, area: 1.0, touch: 0.0 }, &mut r, &mut k).unwrap();
        assert!(!st.active && r.iter().all(|&v| v == 0.0));
        // compressive: slave pushed along +n̄ (force on it = −r_s)
        let st = normal_contact(&(sp.x_bar - sp.n_bar * 0.01), &sp, &NormalLaw { lambda_n: 0.0, eps_n: 1e3, area: 2.0, touch: 0.0 }, &mut r, &mut k).unwrap();
        assert!(st.active && (st.t_n + 10.0).abs() < 1e-9);
        let f_s = -Vec3::new(r[0], r[1], r[2]);
        assert!((f_s - sp.n_bar * 20.0).norm() < 1e-9);
    }

    /// A touching node (trial within ε_N·touch of zero) carries no force but the
    /// closed-branch stiffness ε_N A_s N Nᵀ; a node beyond the touch band nothing.
    #[test]
    fn touching_node_has_penalty_stiffness_only() {
        let patch = BSplinePatch::new(6, 5, 3, 3).unwrap();
        let x = curved_net(6, 5);
        let (sp, _) = MasterSurface::BSpline(&patch).evaluate_local(&x, [0.4, 0.6]);
        let law = NormalLaw { lambda_n: 0.0, eps_n: 1e3, area: 2.0, touch: 1e-6 };
        let (mut r, mut k) = (DVector::zeros(0), DMatrix::zeros(0, 0));
        let st = normal_contact(&(sp.x_bar + sp.n_bar * 5e-7), &sp, &law, &mut r, &mut k).unwrap();
        assert!(!st.active && st.t_n == 0.0);
        assert!(r.iter().all(|&v| v == 0.0));
        // K = ε A N Nᵀ: K_ss = ε A n̄ n̄ᵀ
        for i in 0..3 {
            for j in 0..3 {
                assert!((k[(i, j)] - 2e3 * sp.n_bar[i] * sp.n_bar[j]).abs() < 1e-9);
            }
        }
        let st = normal_contact(&(sp.x_bar + sp.n_bar * 2e-6), &sp, &law, &mut r, &mut k).unwrap();
        assert!(!st.active && k.iter().all(|&v| v == 0.0));
    }

    /// A slave at the centre of curvature of the master: a typed error, not a panic.
    #[test]
    fn focal_point_is_an_error() {
        let patch = BSplinePatch::new(7, 6, 3, 3).unwrap();
        let x = curved_net(7, 6);
        let (mut sp, _) = MasterSurface::BSpline(&patch).evaluate_local(&x, [0.43, 0.57]);
        // make ā_αβ − g b̄_αβ singular at g = −1: b̄ = −ā
        sp.b_ab = -sp.a_ab;
        let law = NormalLaw { lambda_n: 0.0, eps_n: 1e3, area: 1.0, touch: 0.0 };
        let (mut r, mut k) = (DVector::zeros(0), DMatrix::zeros(0, 0));
        let e = normal_contact(&(sp.x_bar - sp.n_bar), &sp, &law, &mut r, &mut k).unwrap_err();
        assert!(matches!(e, ContactElementError::FocalPoint { .. }), "{e}");
        assert!(e.to_string().contains("centre of curvature"));
    }

    /// The element's ξ̄ input agrees with the production projector on the patch.
    #[test]
    fn projector_gives_same_foot_point() {
        let patch = BSplinePatch::new(7, 6, 3, 3).unwrap();
        let x = curved_net(7, 6);
        let surf = MasterSurface::BSpline(&patch);
        let (sp, _) = surf.evaluate_local(&x, [0.43, 0.57]);
        let xs = sp.x_bar - sp.n_bar * 0.01;
        let proj = crate::spline::BSplineProjector::new(patch.clone(), &x).unwrap().project(&xs);
        assert!(proj.converged);
        assert!((proj.xi[0] - 0.43).abs() < 1e-10 && (proj.xi[1] - 0.57).abs() < 1e-10, "{:?}", proj.xi);
        assert!((proj.g + 0.01).abs() < 1e-12);
    }
}
