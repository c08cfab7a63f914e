//! Closest-point projection onto the B-spline patch, paper eq. 2.2: the global search
//! that starts the Newton iteration of [`super::closest_point`].
//!
//! 1. **Global search** ([`SpanTree`]): branch and bound over the span boxes (each
//!    holds its span by the convex-hull property, here of the span's Bézier points);
//!    the distance to each candidate span's 3×3 precomputed samples (refitted with the
//!    tree) tightens the bound, so every span whose box is farther than the best
//!    sample is skipped.
//! 2. **Newton** ([`super::closest_point`]) from the best sample on the whole domain
//!    [0, 1]², the step length clamped to one knot span per direction; converged when
//!    every free `|r_α|/‖ā_α‖` is below `tol · max(L, ‖d‖)` (L = diagonal of the control
//!    net's box).
//! 3. **Outside** when the foot point is held on the patch's edge with the gradient
//!    pointing outward.

use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::basis::basis_funs_into;
use super::closest_point::{finish, newton, NewtonResult};
pub use super::closest_point::{Projection, ProjectionOptions};
use super::{BSplinePatch, SpanTree, SplineError, SurfacePoint, Vec3, MAX_ORDER};

/// A B-spline master surface ready for projections: the patch, a copy of the
/// current control points and the span tree fitted to them.
#[derive(Debug, Clone)]
pub struct BSplineProjector {
    patch: BSplinePatch,
    x: Vec<Vec3>,
    tree: SpanTree,
    samples: SpanSamples,
    scale: f64,
    pub options: ProjectionOptions,
}

/// Samples per direction and knot span in the global search.
pub const SAMPLES: usize = 3;

/// Below this many samples a refit runs on the calling thread
/// ([`super::refit_samples_in_chunks`]): 4,096 take about 0.1 ms on one thread.
const PARALLEL_SAMPLES: usize = 4096;

/// Surface points at the fixed parameters `lo + (i + ½)/SAMPLES · (hi − lo)` of every
/// knot span, refreshed with the tree on every [`BSplineProjector::update`] (O(na·nb)):
/// the global search then only measures distances.
#[derive(Debug, Clone)]
struct SpanSamples {
    /// Basis values per direction at the sample parameters: `[dir][span·SAMPLES + i]`.
    table: [Vec<[f64; MAX_ORDER]>; 2],
    /// `((s + nsa·t)·SAMPLES + iu)·SAMPLES + iv`.
    points: Vec<Vec3>,
}

impl SpanSamples {
    fn param(patch: &BSplinePatch, dir: usize, span: usize, i: usize) -> f64 {
        let (lo, hi) = patch.knots(dir).span_bounds(span);
        lo + (hi - lo) * (i as f64 + 0.5) / SAMPLES as f64
    }

    fn new(patch: &BSplinePatch) -> Self {
        let table = [0, 1].map(|dir| {
            let kv = patch.knots(dir);
            (0..kv.n_spans() * SAMPLES)
                .map(|k| {
                    let (s, i) = (k / SAMPLES, k % SAMPLES);
                    let mut v = [0.0; MAX_ORDER];
                    basis_funs_into(kv, s, Self::param(patch, dir, s, i), &mut v);
                    v
                })
                .collect()
        });
        let [nsa, nsb] = patch.n_spans();
        Self { table, points: vec![Vec3::zeros(); nsa * nsb * SAMPLES * SAMPLES] }
    }

    fn refit(&mut self, patch: &BSplinePatch, x: &[Vec3]) {
        let [ka, kb] = patch.orders();
        let na = patch.n_ctrl()[0];
        let nsa = patch.n_spans()[0];
        let m2 = SAMPLES * SAMPLES;
        let [tab_a, tab_b] = &self.table;
        let refit_row = |(t, row_of_spans): (usize, &mut [Vec3])| {
            for (s, out) in row_of_spans.chunks_mut(m2).enumerate() {
                for iu in 0..SAMPLES {
                    let n_a = &tab_a[s * SAMPLES + iu];
                    // rows[c] = Σ_r N_r(u) B_{s+r, t+c}
                    let mut rows = [Vec3::zeros(); MAX_ORDER];
                    for (c, row) in rows.iter_mut().enumerate().take(kb) {
                        let base = s + na * (t + c);
                        for (b, n) in x[base..base + ka].iter().zip(n_a) {
                            *row += b * *n;
                        }
                    }
                    for iv in 0..SAMPLES {
                        let n_b = &tab_b[t * SAMPLES + iv];
                        out[iu * SAMPLES + iv] = rows.iter().zip(n_b).take(kb).map(|(r, n)| r * *n).sum();
                    }
                }
            }
        };
        super::refit_samples_in_chunks(&mut self.points, nsa * m2, PARALLEL_SAMPLES, refit_row);
    }

    /// Parameter of sample `k`.
    fn xi(&self, patch: &BSplinePatch, k: usize) -> [f64; 2] {
        let nsa = patch.n_spans()[0];
        let m2 = SAMPLES * SAMPLES;
        let (span, q) = (k / m2, k % m2);
        let (s, t) = (span % nsa, span / nsa);
        [Self::param(patch, 0, s, q / SAMPLES), Self::param(patch, 1, t, q % SAMPLES)]
    }
}

impl BSplineProjector {
    /// Builds the span tree for `patch` and fits it to the control points `x`.
    pub fn new(patch: BSplinePatch, x: &[Vec3]) -> Result<Self, SplineError> {
        patch.check_control_net(x)?;
        let tree = SpanTree::with_extraction([patch.knots(0), patch.knots(1)]);
        let samples = SpanSamples::new(&patch);
        let mut s = Self { patch, x: Vec::new(), tree, samples, scale: 0.0, options: ProjectionOptions::default() };
        s.update(x)?;
        Ok(s)
    }

    /// New control point positions (same net): copies them, refits the tree and the
    /// span samples, O(na·nb).
    pub fn update(&mut self, x: &[Vec3]) -> Result<(), SplineError> {
        self.patch.check_control_net(x)?;
        self.x.clear();
        self.x.extend_from_slice(x);
        self.tree.refit(&self.x);
        self.samples.refit(&self.patch, &self.x);
        self.scale = self.tree.diagonal();
        Ok(())
    }

    pub fn patch(&self) -> &BSplinePatch {
        &self.patch
    }

    /// The current control points.
    pub fn control_points(&self) -> &[Vec3] {
        &self.x
    }

    /// Full evaluation at ξ on the current control points.
    pub fn evaluate(&self, xi: [f64; 2]) -> SurfacePoint {
        self.patch.evaluate(&self.x, xi)
    }

    /// Best sample of the global search (step 1 of the module docs).
    pub fn global_start(&self, p: &Vec3) -> [f64; 2] {
        let m2 = SAMPLES * SAMPLES;
        let nsa = self.patch.n_spans()[0];
        let mut best = (f64::INFINITY, 0usize);
        self.tree.query(p, f64::INFINITY, |[s, t], _| {
            let base = (s + nsa * t) * m2;
            for (q, y) in self.samples.points[base..base + m2].iter().enumerate() {
                let d2 = (y - p).norm_squared();
                if d2 < best.0 {
                    best = (d2, base + q);
                }
            }
            best.0
        });
        self.samples.xi(&self.patch, best.1)
    }

    /// The largest Newton step per direction: `max_step_spans` spans.
    fn max_step(&self) -> [f64; 2] {
        self.patch.n_spans().map(|n| self.options.max_step_spans / n as f64)
    }

    fn newton_from(&self, p: &Vec3, xi0: [f64; 2]) -> Projection {
        let (o, max_step) = (&self.options, self.max_step());
        let res = newton(
            |xi| self.patch.jet(&self.x, xi),
            p,
            xi0,
            ([0.0; 2], [1.0; 2]),
            max_step,
            o.tol * self.scale,
            o.max_iterations,
        );
        finish(p, &res, o.outside_tol * self.scale)
    }

    /// Closest point of the patch to `p` (global search, then Newton; if Newton on
    /// the whole domain fails — at a kink of a C⁰ patch, order 2 — a box-constrained
    /// Newton per candidate span, as for facets).
    pub fn project(&self, p: &Vec3) -> Projection {
        let xi0 = self.global_start(p);
        let res = self.newton_from(p, xi0);
        if res.converged {
            return res;
        }
        let by_span = self.project_by_spans(p);
        if by_span.converged {
            by_span
        } else {
            res
        }
    }

    /// Closest point on the patch's polynomial extension beyond its edges: Newton
    /// from `xi0` with ξ allowed up to `margin` (per direction, in parameter units)
    /// outside [0, 1]². For slave nodes just beyond the edge, whose clamped foot point
    /// would not satisfy the closest-point conditions: on the extension it does, so
    /// the contact residual and its tangent stay consistent.
    pub fn project_extended(&self, p: &Vec3, xi0: [f64; 2], margin: [f64; 2]) -> Projection {
        let (o, max_step) = (&self.options, self.max_step());
        let res = newton(|xi| self.patch.jet(&self.x, xi), p, xi0, ([-margin[0], -margin[1]], [1.0 + margin[0], 1.0 + margin[1]]), max_step, o.tol * self.scale, o.max_iterations);
        finish(p, &res, o.outside_tol * self.scale)
    }

    /// Closest point on span `span`'s polynomial, continued beyond the span (a held
    /// master element: the frozen search of a contact pair), Newton from `xi0`
    /// within the patch's domain. Where the patch is C⁰ (order 2) the spans on
    /// either side of a knot line meet at a kink; held on one of them, the residual
    /// and its tangent stay one smooth function.
    pub fn project_in_span(&self, p: &Vec3, xi0: [f64; 2], span: [usize; 2]) -> Projection {
        let (o, max_step) = (&self.options, self.max_step());
        let res = newton(|xi| self.patch.jet_in_span(&self.x, xi, span), p, xi0, ([0.0; 2], [1.0; 2]), max_step, o.tol * self.scale, o.max_iterations);
        finish(p, &res, o.outside_tol * self.scale)
    }

    /// Full evaluation at ξ with span `span`'s polynomial.
    pub fn evaluate_in_span(&self, xi: [f64; 2], span: [usize; 2]) -> SurfacePoint {
        let mut out = SurfacePoint::default();
        self.patch.evaluate_in_span_into(&self.x, xi, span, &mut out);
        out
    }

    /// Step 2 span by span: Newton bounded to each candidate span of the tree
    /// (branch and bound on the best distance found), the nearest result wins.
    fn project_by_spans(&self, p: &Vec3) -> Projection {
        let o = &self.options;
        let tol = o.tol * self.scale;
        let mut best: Option<(f64, NewtonResult)> = None;
        self.tree.query(p, f64::INFINITY, |[s, t], _| {
            let (a0, a1) = self.patch.knots(0).span_bounds(s);
            let (b0, b1) = self.patch.knots(1).span_bounds(t);
            let bounds = ([a0, b0], [a1, b1]);
            let mid = [0.5 * (a0 + a1), 0.5 * (b0 + b1)];
            let res = newton(|xi| self.patch.jet(&self.x, xi), p, mid, bounds, [a1 - a0, b1 - b0], tol, o.max_iterations);
            let d2 = (p - res.jet.x).norm_squared();
            if res.converged && best.as_ref().is_none_or(|b| d2 < b.0) {
                best = Some((d2, res));
            }
            best.as_ref().map_or(f64::INFINITY, |b| b.0)
        });
        match best {
            Some((_, res)) => finish(p, &res, o.outside_tol * self.scale),
            None => Projection { xi: [f64::NAN; 2], x_bar: Vec3::from_element(f64::NAN), g: f64::NAN, inside: false, iterations: 0, converged: false, clamped: [false; 2] },
        }
    }

    /// Newton started from a previous ξ̄ (the local minimum near it); falls back to
    /// [`Self::project`] if Newton does not converge from there.
    pub fn project_warm(&self, p: &Vec3, xi0: [f64; 2]) -> Projection {
        let res = self.newton_from(p, xi0);
        if res.converged {
            res
        } else {
            self.project(p)
        }
    }

    /// Projects every point, in parallel (rayon).
    pub fn project_all(&self, points: &[Vec3]) -> Vec<Projection> {
        points.par_iter().map(|p| self.project(p)).collect()
    }
}

/// Net of `n × n` nodes with unit spacing on the gently wavy surface
/// `z = 0.8 sin(0.3 x) cos(0.2 y)` (benchmark and tests).
pub(crate) fn wavy_square_net(n: usize) -> Vec<Vec3> {
    (0..n * n)
        .map(|k| {
            let (x, y) = ((k % n) as f64, (k / n) as f64);
            Vec3::new(x, y, 0.8 * (0.3 * x).sin() * (0.2 * y).cos())
        })
        .collect()
}

/// Deterministic points near the wavy net: uniform over the patch's (x, y) range
/// plus a 1% margin beyond the edges, heights in ±0.5 (≈ half an element) around the
/// surface sheet (splitmix64 stream).
pub(crate) fn bench_points(n: usize, n_points: usize) -> Vec<Vec3> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let span = (n - 1) as f64;
    (0..n_points)
        .map(|_| {
            let x = -0.01 * span + 1.02 * span * next();
            let y = -0.01 * span + 1.02 * span * next();
            let z = 0.8 * (0.3 * x).sin() * (0.2 * y).cos() + (next() - 0.5);
            Vec3::new(x, y, z)
        })
        .collect()
}

/// Projects `n_points` points onto a 100 × 100-node order-3 patch with
/// [`BSplineProjector::project_all`] and returns the wall time of that call
/// (setup and refit excluded).
pub fn bench_projection(n_points: usize) -> Duration {
    let n = 100;
    let x = wavy_square_net(n);
    let patch = BSplinePatch::new(n, n, 3, 3).expect("valid patch");
    let proj = BSplineProjector::new(patch, &x).expect("valid net");
    let points = bench_points(n, n_points);
    let t0 = Instant::now();
    let res = proj.project_all(&points);
    let dt = t0.elapsed();
    std::hint::black_box(&res);
    dt
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Planar, non-uniformly spaced (but affine in rows) net: the B-spline is a piece
    /// of the plane z = 0 over the rectangle [0, 4] × [0, 3].
    fn plane(order: usize) -> (BSplineProjector, f64) {
        let (na, nb) = (9, 7);
        let mut x = Vec::new();
        for j in 0..nb {
            for i in 0..na {
                let u = i as f64 / (na - 1) as f64;
                let v = j as f64 / (nb - 1) as f64;
                // monotone distortion of the spacing, edges stay straight
                let pi = std::f64::consts::PI;
                x.push(Vec3::new(4.0 * (u + 0.1 * (pi * u).sin() * v), 3.0 * (v + 0.1 * (pi * v).sin() * u), 0.0));
            }
        }
        let patch = BSplinePatch::new(na, nb, order, order).unwrap();
        (BSplineProjector::new(patch, &x).unwrap(), 5.0)
    }

    #[test]
    fn projection_onto_plane_is_orthogonal_projection() {
        for order in [2, 3, 4] {
            let (proj, scale) = plane(order);
            for k in 0..60 {
                let px = 0.05 + 3.9 * ((k * 37 % 60) as f64 / 59.0);
                let py = 0.05 + 2.9 * ((k * 11 % 60) as f64 / 59.0);
                let pz = -1.0 + 2.0 * (k as f64 / 59.0);
                let p = Vec3::new(px, py, pz);
                let r = proj.project(&p);
                assert!(r.converged && r.inside, "order {order} p={p:?}: {r:?}");
                assert!((r.x_bar - Vec3::new(px, py, 0.0)).norm() < 1e-10 * scale, "order {order} p={p:?}: {r:?}");
                let n = proj.evaluate(r.xi).n_bar;
                assert!((r.g - pz * n.z).abs() < 1e-12 && n.z.abs() > 1.0 - 1e-14);
                assert!(r.iterations <= 6, "order {order} p={p:?}: {} iterations", r.iterations);
            }
            // beyond each of the four edges: outside, foot point on the edge
            for (p, edge) in [
                (Vec3::new(-0.5, 1.5, 0.3), [Some(0.0), None]),
                (Vec3::new(4.7, 1.0, -0.3), [Some(1.0), None]),
                (Vec3::new(2.0, -0.2, 0.1), [None, Some(0.0)]),
                (Vec3::new(2.0, 3.4, 0.1), [None, Some(1.0)]),
            ] {
                let r = proj.project(&p);
                assert!(!r.inside, "order {order} p={p:?} must be outside: {r:?}");
                for (al, e) in edge.iter().enumerate() {
                    if let Some(e) = *e {
                        assert_eq!(r.xi[al], e);
                    }
                }
            }
        }
    }

    /// A held span (the frozen search): inside its span a point projects as without
    /// it; on a C⁰ patch (order 2, the wavy net's kinks) a point whose foot lies in
    /// the next span projects onto the held span's plane continued, which passes
    /// through the shared knot line's points, and the evaluation there matches the
    /// held span's polynomial, not the global one.
    #[test]
    fn a_held_span_continues_its_polynomial() {
        let n = 6;
        let x = wavy_square_net(n);
        let proj = BSplineProjector::new(BSplinePatch::new(n, n, 2, 2).unwrap(), &x).unwrap();
        let inside = Vec3::new(1.3, 2.6, 1.0);
        let free = proj.project(&inside);
        let span = proj.patch().span_of(free.xi);
        let held = proj.project_in_span(&inside, free.xi, span);
        assert!(held.converged && (held.x_bar - free.x_bar).norm() < 1e-12, "{held:?} vs {free:?}");
        // a point over the next span along ξ¹, held on this one
        let next = Vec3::new(2.4, 2.6, 1.0);
        let free_next = proj.project(&next);
        assert_eq!(proj.patch().span_of(free_next.xi)[0], span[0] + 1);
        let held_next = proj.project_in_span(&next, free.xi, span);
        assert!(held_next.converged);
        assert!(held_next.xi[0] > proj.patch().knots(0).span_bounds(span[0]).1, "the held foot lies beyond its span: {held_next:?}");
        let on_held = proj.evaluate_in_span(held_next.xi, span);
        let global = proj.evaluate(held_next.xi);
        assert!((on_held.x_bar - held_next.x_bar).norm() < 1e-12);
        assert!((global.x_bar - on_held.x_bar).norm() > 1e-6, "the held span's continuation is the global surface: no kink tested");
    }

    /// 9 × 5 nodes on a cylinder of radius R about the y axis, angle 0…π/2 along ξ¹.
    pub(crate) fn cylinder_net(r: f64) -> Vec<Vec3> {
        let (na, nb) = (9, 5);
        let mut x = Vec::new();
        for j in 0..nb {
            for i in 0..na {
                let th = std::f64::consts::FRAC_PI_2 * i as f64 / (na - 1) as f64;
                x.push(Vec3::new(r * th.cos(), 0.75 * j as f64, r * th.sin()));
            }
        }
        x
    }

    #[test]
    fn projection_onto_cylinder_is_stationary_and_global() {
        let radius = 2.0;
        let x = cylinder_net(radius);
        let patch = BSplinePatch::new(9, 5, 3, 3).unwrap();
        let proj = BSplineProjector::new(patch.clone(), &x).unwrap();
        let scale = proj.tree.diagonal();
        // dense sample of the patch for the brute-force check
        let m = 250;
        let dense: Vec<Vec3> =
            (0..=m).flat_map(|i| (0..=m).map(move |j| [i as f64 / m as f64, j as f64 / m as f64])).map(|xi| patch.point(&x, xi)).collect();
        let max_a = (0..=20)
            .flat_map(|i| (0..=20).map(move |j| [i as f64 / 20.0, j as f64 / 20.0]))
            .map(|xi| {
                let sp = patch.evaluate(&x, xi);
                sp.a_alpha[0].norm().max(sp.a_alpha[1].norm())
            })
            .fold(0.0, f64::max);
        // a sample is at most h/√2 in each parameter from the foot point: its distance
        // exceeds the true one by at most ‖ā‖_max·h/√2·√2
        let resolution = max_a * (1.0 / m as f64);
        let mut max_it = 0;
        for k in 0..80 {
            let th = 0.05 + 1.45 * (k as f64 / 79.0);
            let rr = radius + 0.8 * ((k * 7 % 13) as f64 / 12.0 - 0.5) * 2.0; // 1.2 … 2.8
            let y = 0.1 + 2.8 * ((k * 5 % 17) as f64 / 16.0);
            let p = Vec3::new(rr * th.cos(), y, rr * th.sin());
            let r = proj.project(&p);
            assert!(r.converged && r.inside, "p={p:?}: {r:?}");
            let sp = patch.evaluate(&x, r.xi);
            for al in 0..2 {
                let s = (p - sp.x_bar).dot(&sp.a_alpha[al]) / sp.a_alpha[al].norm();
                assert!(s.abs() < 1e-10 * scale, "stationarity α={al}: {s:e}");
            }
            let d = (p - r.x_bar).norm();
            let brute = dense.iter().map(|q| (q - p).norm()).fold(f64::INFINITY, f64::min);
            assert!(d <= brute + 1e-12, "Newton {d} worse than a sample {brute}");
            assert!(brute - d <= resolution, "brute {brute} vs Newton {d}, resolution {resolution}");
            // radius of the B-spline is close to R (not exact): g ≈ rr − R
            // n̄ = ā_1 × ā_2 points towards the axis for this net, so g ≈ R − r
            assert!((r.g + (rr - radius)).abs() < 0.02 * radius, "g={} R−r={}", r.g, radius - rr);
            max_it = max_it.max(r.iterations);
        }
        assert!(max_it <= 6, "Newton needed {max_it} iterations from the global start");
        // beyond the axial ends and the angular ends: outside
        for p in [
            Vec3::new(-0.6, 1.5, 2.5), // θ > π/2
            Vec3::new(2.5, 1.0, -0.6), // θ < 0
            Vec3::new(2.1, -0.4, 0.4), // y < 0
            Vec3::new(1.2, 3.5, 1.4),  // y > 3
        ] {
            let r = proj.project(&p);
            assert!(!r.inside, "p={p:?}: {r:?}");
        }
    }

    #[test]
    fn warm_start_and_update() {
        let radius = 2.0;
        let mut x = cylinder_net(radius);
        let patch = BSplinePatch::new(9, 5, 3, 3).unwrap();
        let mut proj = BSplineProjector::new(patch, &x).unwrap();
        let p = Vec3::new(1.5, 1.3, 1.6);
        let cold = proj.project(&p);
        let warm = proj.project_warm(&p, cold.xi);
        assert_eq!(warm.iterations, 0);
        assert!((warm.x_bar - cold.x_bar).norm() < 1e-12);
        // move the body rigidly: the projection follows
        let shift = Vec3::new(0.3, -0.2, 0.1);
        for q in x.iter_mut() {
            *q += shift;
        }
        proj.update(&x).unwrap();
        let moved = proj.project_warm(&(p + shift), cold.xi);
        assert!(moved.iterations == 0 && (moved.x_bar - cold.x_bar - shift).norm() < 1e-12);
        assert!((moved.g - cold.g).abs() < 1e-12);
        // wrong size is a typed error
        assert!(matches!(proj.update(&x[1..]), Err(SplineError::ControlNetSize { .. })));
    }

    #[test]
    fn bench_points_are_projected_consistently() {
        // small version of the benchmark: brute-force check on a sample of points
        let n = 20;
        let x = wavy_square_net(n);
        let patch = BSplinePatch::new(n, n, 3, 3).unwrap();
        let proj = BSplineProjector::new(patch.clone(), &x).unwrap();
        let pts = bench_points(n, 150);
        let res = proj.project_all(&pts);
        let m = 200;
        let dense: Vec<Vec3> =
            (0..=m).flat_map(|i| (0..=m).map(move |j| [i as f64 / m as f64, j as f64 / m as f64])).map(|xi| patch.point(&x, xi)).collect();
        let mut inside = 0;
        for (p, r) in pts.iter().zip(&res) {
            assert!(r.converged, "{p:?}: {r:?}");
            let d = (p - r.x_bar).norm();
            let brute = dense.iter().map(|q| (q - p).norm()).fold(f64::INFINITY, f64::min);
            assert!(d <= brute + 1e-12, "{p:?}: Newton {d} vs sample {brute}");
            if r.inside {
                inside += 1;
                assert!(r.iterations <= 6, "{p:?}: {r:?}");
            }
        }
        assert!(inside > 120);
    }

    #[test]
    #[ignore = "benchmark: run with --release --ignored --nocapture"]
    fn bench_one_million_points() {
        let x = wavy_square_net(100);
        let mut proj = BSplineProjector::new(BSplinePatch::new(100, 100, 3, 3).unwrap(), &x).unwrap();
        let t0 = Instant::now();
        proj.update(&x).unwrap();
        println!("refit of the 100×100 patch (tree + span samples): {:?}", t0.elapsed());
        let dt = bench_projection(1_000_000);
        println!("projected 1M points onto a 100×100 order-3 patch in {dt:?} ({} threads)", rayon::current_num_threads());
        assert!(dt.as_secs_f64() < 2.0, "took {dt:?}");
    }
}
