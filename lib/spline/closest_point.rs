//! The closest point on one smooth map: the box-constrained Newton iteration of the
//! closest-point projection (paper eq. 2.2), shared by the B-spline patch, the facet
//! net and the atlas charts.
//!
//! For a (slave) point x find ξ̄ minimising
//! ```text
//! f(ξ) = ½ ‖x − x̄(ξ)‖²,   ξ in a box                                            (2.2)
//! ```
//! Stationarity (the roots of the first derivative): with d = x − x̄(ξ),
//! ```text
//! r_α   = ∂f/∂ξ^α   = −d·ā_α = 0
//! H_αβ  = ∂²f/∂ξ^α∂ξ^β = ā_α·ā_β − d·ā_{α,β}   (= ā_αβ − g b̄_αβ at the solution, g = d·n̄)
//! ```
//! Newton step `H Δξ = −r` (the Gauss–Newton matrix ā_αβ replaces H where H is not
//! positive definite, i.e. beyond a centre of curvature), the step length clamped per
//! direction, box constraints by an active set (a bound whose gradient points out of
//! the box fixes that coordinate) plus projection, and an Armijo backtracking line
//! search on f. Converged when every free `|r_α|/‖ā_α‖` is below the tolerance.
//!
//! The result is **outside** when ξ̄ sits on the domain boundary and the gradient
//! points outward there (`d·ā_α < 0` at ξ^α = 0, `> 0` at ξ^α = 1): the unconstrained
//! foot point would lie beyond the patch edge. g = (x − x̄)·n̄ is the signed distance
//! along n̄ (negative = penetration, eq. 4.3).

use super::patch::Jet;
use super::Vec3;

/// Result of projecting one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// ξ̄ ∈ [0, 1]².
    pub xi: [f64; 2],
    /// x̄(ξ̄).
    pub x_bar: Vec3,
    /// Signed distance g = (x − x̄)·n̄.
    pub g: f64,
    /// False when the foot point would lie beyond a patch edge (see module docs).
    pub inside: bool,
    /// Newton steps taken (0 if the start already satisfied the tolerance).
    pub iterations: usize,
    /// Whether the stationarity tolerance was reached.
    pub converged: bool,
    /// Facet sets: ξ^α held on an interior cell edge (the closest point lies on a
    /// crease, g = ±‖x − x̄‖; see [`crate::spline::SurfacePoint::hold_on_crease`]).
    pub clamped: [bool; 2],
}

/// Tunables of the projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectionOptions {
    /// Relative stationarity tolerance (times `max(L, ‖x − x̄‖)`).
    pub tol: f64,
    /// Relative tolerance on `|d·ā_α|/‖ā_α‖` deciding "gradient points outward".
    pub outside_tol: f64,
    pub max_iterations: usize,
    /// Largest Newton step, in knot spans per direction.
    pub max_step_spans: f64,
}

impl Default for ProjectionOptions {
    fn default() -> Self {
        Self { tol: 1e-12, outside_tol: 1e-10, max_iterations: 30, max_step_spans: 1.0 }
    }
}

/// Outcome of the box-constrained Newton iteration.
#[derive(Debug, Clone, Copy)]
pub(crate) struct NewtonResult {
    pub xi: [f64; 2],
    pub jet: Jet,
    pub iterations: usize,
    pub converged: bool,
}

fn clamp2(xi: [f64; 2], lo: [f64; 2], hi: [f64; 2]) -> [f64; 2] {
    [xi[0].clamp(lo[0], hi[0]), xi[1].clamp(lo[1], hi[1])]
}

/// Minimises ½‖p − x(ξ)‖² over the box `[lo, hi]` from `xi0`. `jet` evaluates the
/// surface and its first two derivatives; `tol_len` is the absolute stationarity
/// tolerance on `|d·ā_α|/‖ā_α‖`; `max_step` limits `|Δξ^α|`.
pub(crate) fn newton(
    jet: impl Fn([f64; 2]) -> Jet,
    p: &Vec3,
    xi0: [f64; 2],
    bounds: ([f64; 2], [f64; 2]),
    max_step: [f64; 2],
    tol_len: f64,
    max_iterations: usize,
) -> NewtonResult {
    let (lo, hi) = bounds;
    let mut xi = clamp2(xi0, lo, hi);
    let mut cur = jet(xi);
    let mut f = 0.5 * (p - cur.x).norm_squared();
    for it in 0..=max_iterations {
        let d = p - cur.x;
        let r = [-d.dot(&cur.a[0]), -d.dot(&cur.a[1])];
        let norm_a = [cur.a[0].norm(), cur.a[1].norm()];
        let free = [0, 1].map(|al| !((xi[al] <= lo[al] && r[al] > 0.0) || (xi[al] >= hi[al] && r[al] < 0.0)));
        // round-off floor: d = p − x̄ is only known to ~ε‖p‖
        let tol = tol_len.max(1e-14 * d.norm()).max(32.0 * f64::EPSILON * p.norm());
        // round-off in f = ½‖d‖² is ~ε‖d‖(‖p‖ + ‖x̄‖), which near the solution exceeds
        // the decrease a Newton step can bring: steps within it are accepted
        let f_slack = 8.0 * f64::EPSILON * d.norm() * (p.norm() + cur.x.norm());
        if (0..2).all(|al| !free[al] || r[al].abs() <= tol * norm_a[al]) {
            return NewtonResult { xi, jet: cur, iterations: it, converged: true };
        }
        if it == max_iterations {
            break;
        }

        let g = [[cur.a[0].dot(&cur.a[0]), cur.a[0].dot(&cur.a[1])], [cur.a[0].dot(&cur.a[1]), cur.a[1].dot(&cur.a[1])]];
        let mut h = g;
        for (al, row) in h.iter_mut().enumerate() {
            for (be, v) in row.iter_mut().enumerate() {
                *v -= d.dot(&cur.aa[al][be]);
            }
        }
        let solve = |m: [[f64; 2]; 2]| -> Option<[f64; 2]> {
            match free {
                [true, true] => {
                    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
                    (m[0][0] > 0.0 && det > 1e-14 * m[0][0] * m[1][1].abs()).then(|| {
                        [(-r[0] * m[1][1] + r[1] * m[0][1]) / det, (-r[1] * m[0][0] + r[0] * m[1][0]) / det]
                    })
                }
                [true, false] => (m[0][0] > 0.0).then(|| [-r[0] / m[0][0], 0.0]),
                [false, true] => (m[1][1] > 0.0).then(|| [0.0, -r[1] / m[1][1]]),
                [false, false] => None,
            }
        };
        let mut accepted = false;
        for m in [h, g] {
            let Some(mut step) = solve(m) else { continue };

            let shrink = (0..2).map(|al| max_step[al] / step[al].abs().max(1e-300)).fold(1.0, f64::min);
            step = [step[0] * shrink, step[1] * shrink];
            let mut t = 1.0;
            for _ in 0..40 {
                let trial = clamp2([xi[0] + t * step[0], xi[1] + t * step[1]], lo, hi);
                let jt = jet(trial);
                let ft = 0.5 * (p - jt.x).norm_squared();
                let slope = r[0] * (trial[0] - xi[0]) + r[1] * (trial[1] - xi[1]);
                if trial == xi {
                    break; // the step vanished in round-off
                }
                // Armijo with the round-off allowance
                if ft <= f + 1e-4 * slope.min(0.0) + f_slack {
                    xi = trial;
                    cur = jt;
                    f = ft;
                    accepted = true;
                    break;
                }
                t *= 0.5;
            }
            if accepted {
                break;
            }
        }
        if !accepted {
            // no descent possible any more: stationary up to round-off
            return NewtonResult { xi, jet: cur, iterations: it, converged: false };
        }
    }
    NewtonResult { xi, jet: cur, iterations: max_iterations, converged: false }
}

/// Outside test at a constrained minimum: ξ̄ on the boundary of `[0, 1]²` with
/// the gradient pointing out of the domain.
pub(crate) fn is_outside(p: &Vec3, xi: [f64; 2], cur: &Jet, tol_len: f64) -> bool {
    let d = p - cur.x;
    (0..2).any(|al| {
        let s = d.dot(&cur.a[al]) / cur.a[al].norm();
        (xi[al] <= 0.0 && s < -tol_len) || (xi[al] >= 1.0 && s > tol_len)
    })
}

/// Builds the [`Projection`] from a Newton result.
pub(crate) fn finish(p: &Vec3, res: &NewtonResult, outside_tol_len: f64) -> Projection {
    let cur = &res.jet;
    let c = cur.a[0].cross(&cur.a[1]);
    let n_bar = c / c.norm();
    Projection {
        xi: res.xi,
        x_bar: cur.x,
        g: (p - cur.x).dot(&n_bar),
        inside: !is_outside(p, res.xi, cur, outside_tol_len),
        iterations: res.iterations,
        converged: res.converged,
        clamped: [false; 2],
    }
}
