//! Closest-point projection onto an [`Atlas`] (eq. 2.2 on a surface of many charts).
//!
//! 1. Every chart carries `S × S` surface samples, refreshed with the tree. The tree
//!    finds the nearest sample (distances only; the chart of the last search seeds
//!    the bound), then, nearest box first, every chart that can hold a point closer
//!    than the best found so far; on each, a box-constrained Newton iteration over the
//!    unit square (the one of [`crate::spline::projection`]), started from the chart's
//!    nearest sample, finds the chart's closest point. The nearest wins; two as near
//!    as each other within 1e-10 of the surface's size (a node on their shared edge)
//!    are a tie, which the lower chart number wins, so round-off does not choose.
//! 2. Hysteresis, as for the single facet net: the chart `prev` of the last search is
//!    kept while its foot point is no farther than the best by 1e-6 of the surface's
//!    size (1e-4 where both are orthogonal projections), so a node on a shared edge
//!    does not flip between charts from one Newton iterate to the next.
//! 3. A foot point held on a chart edge without satisfying the closest-point
//!    condition there is read by what lies across that edge ([`EdgeKind`]):
//!    - the surface's boundary: the node is outside (`inside = false`);
//!    - a crease (facet edges, seams between patches): crease contact, the normal
//!      along the distance vector, `g = ±‖x_s − x̄‖` (see
//!      [`SurfacePoint::hold_on_crease`]);
//!    - a smooth join: nothing, the neighbouring chart holds the orthogonal foot point.


use super::super::closest_point::{newton, NewtonResult};
use super::super::{Projection, ProjectionOptions, SplineError, SurfacePoint, Vec3};
use super::tree::ChartTree;
use super::{Atlas, EdgeKind};

/// An atlas with its chart tree, fitted to the current master node positions.
#[derive(Debug, Clone)]
pub struct AtlasProjector {
    atlas: Atlas,
    tree: ChartTree,
    /// `samples[S² c + i + S j]` = x̄ of chart c at ((i + ½)/S, (j + ½)/S).
    samples: Vec<Vec3>,
    scale: f64,
    pub options: ProjectionOptions,
}

const UNIT: ([f64; 2], [f64; 2]) = ([0.0; 2], [1.0; 2]);
/// Samples per direction and chart.
const S: usize = 3;
/// Below this many samples a refit runs on the calling thread
/// ([`super::super::refit_samples_in_chunks`]; a chart's jet costs about ten times a
/// B-spline patch's sample: about 0.1 ms in all).
const PARALLEL_SAMPLES: usize = 512;
/// Foot points on two charts whose distances differ by no more than this fraction
/// of the surface's size are a tie (broken by the chart number).
const TIE: f64 = 1e-10;

fn sample_uv(k: usize) -> [f64; 2] {
    [((k % S) as f64 + 0.5) / S as f64, ((k / S) as f64 + 0.5) / S as f64]
}

impl AtlasProjector {
    pub fn new(mut atlas: Atlas, x: &[Vec3]) -> Result<Self, SplineError> {
        atlas.update(x)?;
        // the limit surface lies in its stencil's hull (non-negative basis); a margin
        // of a tenth of a box guards the phantom-folded boundary faces
        let inflate = if atlas.is_subdivision() { 0.1 } else { 0.0 };
        let tree = ChartTree::new(atlas.n_charts(), &|c| atlas.support(c), x, inflate);
        let scale = tree.diagonal();
        let mut s = Self { samples: vec![Vec3::zeros(); S * S * atlas.n_charts()], atlas, tree, scale, options: ProjectionOptions::default() };
        s.refit_samples();
        Ok(s)
    }

    fn refit_samples(&mut self) {
        let atlas = &self.atlas;
        let refit_chart = |(c, out): (usize, &mut [Vec3])| {
            for (k, y) in out.iter_mut().enumerate() {
                *y = atlas.jet(c, sample_uv(k)).x;
            }
        };
        super::super::refit_samples_in_chunks(&mut self.samples, S * S, PARALLEL_SAMPLES, refit_chart);
    }

    /// The nearest sample of `chart` to `p`: (squared distance, its (u, v)).
    fn nearest_sample(&self, p: &Vec3, chart: usize) -> (f64, [f64; 2]) {
        let mut best = (f64::INFINITY, [0.5; 2]);
        for (k, y) in self.samples[S * S * chart..S * S * (chart + 1)].iter().enumerate() {
            let d2 = (y - p).norm_squared();
            if d2 < best.0 {
                best = (d2, sample_uv(k));
            }
        }
        best
    }

    /// New master node positions: refits the chart tree, O(charts).
    pub fn update(&mut self, x: &[Vec3]) -> Result<(), SplineError> {
        self.atlas.update(x)?;
        let atlas = &self.atlas;
        self.tree.refit(&|c| atlas.support(c), x);
        self.scale = self.tree.diagonal();
        self.refit_samples();
        Ok(())
    }

    pub fn atlas(&self) -> &Atlas {
        &self.atlas
    }

    pub fn evaluate(&self, chart: usize, uv: [f64; 2]) -> SurfacePoint {
        self.atlas.evaluate(chart, uv)
    }

    fn newton_on(&self, p: &Vec3, chart: usize, (lo, hi): ([f64; 2], [f64; 2])) -> NewtonResult {
        let mid = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        self.newton_from(p, chart, mid, (lo, hi))
    }

    fn newton_from(&self, p: &Vec3, chart: usize, start: [f64; 2], (lo, hi): ([f64; 2], [f64; 2])) -> NewtonResult {
        let o = &self.options;
        let step = [(hi[0] - lo[0]).max(1.0), (hi[1] - lo[1]).max(1.0)];
        newton(|uv| self.atlas.jet(chart, uv), p, start, (lo, hi), step, o.tol * self.scale, o.max_iterations)
    }

    /// Whether (p − x̄)·ā_α = 0 holds in each direction.
    fn orthogonal_in(&self, p: &Vec3, res: &NewtonResult) -> [bool; 2] {
        let d = p - res.jet.x;
        let tol = self.options.tol * self.scale;
        [0, 1].map(|al| d.dot(&res.jet.a[al]).abs() <= (1e-8 * d.norm() + 8.0 * tol) * res.jet.a[al].norm())
    }

    fn orthogonal(&self, p: &Vec3, res: &NewtonResult) -> bool {
        self.orthogonal_in(p, res).iter().all(|&o| o)
    }

    /// Closest point of the surface to `p`, and its chart.
    pub fn project(&self, p: &Vec3) -> (Projection, usize) {
        self.project_keeping(p, None)
    }

    /// The closest point on `chart` alone, from `uv0`, when Newton finds it strictly
    /// inside the chart with p − x̄ orthogonal to the surface; otherwise `None` (the
    /// caller then searches all charts). A local foot point next to a known one:
    /// mortar quadrature points start from their face corner's or their own last
    /// chart, where most of them stay.
    pub fn project_on_chart_interior(&self, p: &Vec3, chart: usize, uv0: [f64; 2]) -> Option<Projection> {
        if chart >= self.atlas.n_charts() {
            return None;
        }
        let start = uv0.map(|u| if u.is_finite() { u.clamp(0.0, 1.0) } else { 0.5 });
        let res = self.newton_from(p, chart, start, UNIT);
        let interior = res.xi.iter().all(|&u| u > 0.0 && u < 1.0);
        (res.converged && interior && self.orthogonal(p, &res)).then(|| self.finish(p, &res, chart, UNIT))
    }

    /// Closest point with hysteresis on the chart `prev` (module docs, steps 1–3).
    pub fn project_keeping(&self, p: &Vec3, prev: Option<usize>) -> (Projection, usize) {
        let prev = prev.filter(|&c| c < self.atlas.n_charts());
        // the nearest sample: an upper bound on the distance, and where to start
        let mut seed = (f64::INFINITY, 0usize, [0.5; 2]);
        if let Some(c) = prev {
            let (d2, uv) = self.nearest_sample(p, c);
            seed = (d2, c, uv);
        }
        self.tree.query(p, seed.0, |chart, _| {
            let (d2, uv) = self.nearest_sample(p, chart);
            if d2 < seed.0 {
                seed = (d2, chart, uv);
            }
            seed.0
        });
        let mut best: Option<(f64, NewtonResult, usize)> = None;
        if seed.0.is_finite() {
            let res = self.newton_from(p, seed.1, seed.2, UNIT);
            best = Some(((p - res.jet.x).norm_squared(), res, seed.1));
        }
        // Two charts as near as each other within TIE · size (a node on the edge
        // between them): the lower chart number wins, whatever round-off says, so
        // the choice does not depend on the order of the search or on the last bits
        // of the positions (a restart meets the uninterrupted run's choice).
        let tie = TIE * self.scale;
        let widen = |d2: f64| (d2.sqrt() + tie).powi(2) * (1.0 + 1e-12);
        // a chart can hold a closer point only if its box is within the best distance
        // (a hair wider: round-off in the samples' distances, and the tie)
        let bound = widen(best.as_ref().map_or(f64::INFINITY, |b| b.0.min(seed.0)));
        self.tree.query(p, bound, |chart, _| {
            if chart != seed.1 {
                let (_, uv) = self.nearest_sample(p, chart);
                let res = self.newton_from(p, chart, uv, UNIT);
                let d2 = (p - res.jet.x).norm_squared();
                let wins = |b: &(f64, NewtonResult, usize)| {
                    let (d, db) = (d2.sqrt(), b.0.sqrt());
                    if (d - db).abs() <= tie {
                        chart < b.2
                    } else {
                        d < db
                    }
                };
                if best.as_ref().is_none_or(wins) {
                    best = Some((d2, res, chart));
                }
            }
            best.as_ref().map_or(f64::INFINITY, |b| widen(b.0))
        });
        let Some((d2, mut res, mut chart)) = best else {
            let nan = Projection { xi: [f64::NAN; 2], x_bar: Vec3::from_element(f64::NAN), g: f64::NAN, inside: false, iterations: 0, converged: false, clamped: [false; 2] };
            return (nan, 0);
        };
        if let Some(c) = prev.filter(|&c| c != chart && c < self.atlas.n_charts()) {
            let kept = self.newton_on(p, c, UNIT);
            let slack = if self.orthogonal(p, &kept) && self.orthogonal(p, &res) { 1e-4 * self.scale } else { 1e-6 * self.scale };
            if kept.converged && (p - kept.jet.x).norm() <= d2.sqrt() + slack {
                res = kept;
                chart = c;
            }
        }
        (self.finish(p, &res, chart, UNIT), chart)
    }

    /// The projection with the chart held (a frozen search): on facets and at seams,
    /// Newton on the chart's polynomial continued one chart width beyond each crease
    /// edge (not beyond the surface's boundary), a node in crease contact kept on its
    /// edge (`crease[α] = Some(u^α)`); on smooth charts the regular search. A node
    /// that leaves the continued range gets the regular search.
    pub fn project_on_chart(&self, p: &Vec3, chart: usize, crease: [Option<f64>; 2]) -> (Projection, usize) {
        let mut lo = [0.0; 2];
        let mut hi = [1.0; 2];
        let mut any = false;
        for al in 0..2 {
            if let Some(u) = crease[al] {
                (lo[al], hi[al]) = (u, u);
                continue;
            }
            if self.atlas.edge(chart, 2 * al) == EdgeKind::Crease {
                lo[al] = -1.0;
                any = true;
            }
            if self.atlas.edge(chart, 2 * al + 1) == EdgeKind::Crease {
                hi[al] = 2.0;
                any = true;
            }
        }
        if !any && crease == [None; 2] {
            return self.project_keeping(p, Some(chart));
        }
        let res = self.newton_on(p, chart, (lo, hi));
        let ortho = self.orthogonal_in(p, &res);
        if res.converged && (0..2).all(|al| ortho[al] || crease[al].is_some()) {
            (self.finish(p, &res, chart, (lo, hi)), chart)
        } else {
            self.project_keeping(p, Some(chart))
        }
    }

    /// Closest point on `chart`'s polynomial continued up to `margin` beyond its
    /// boundary edges (for nodes just past the surface's edge, see
    /// [`crate::spline::BSplineProjector::project_extended`]).
    pub fn project_extended(&self, p: &Vec3, chart: usize, margin: [f64; 2]) -> Projection {
        let mut lo = [0.0; 2];
        let mut hi = [1.0; 2];
        // a Catmull–Clark face does not continue beyond its edges
        let margin = if self.atlas.is_subdivision() { [0.0; 2] } else { margin };
        for al in 0..2 {
            if self.atlas.edge(chart, 2 * al) == EdgeKind::Boundary {
                lo[al] -= margin[al];
            }
            if self.atlas.edge(chart, 2 * al + 1) == EdgeKind::Boundary {
                hi[al] += margin[al];
            }
        }
        let res = self.newton_on(p, chart, (lo, hi));
        self.finish(p, &res, chart, (lo, hi))
    }

    /// The [`Projection`] of a Newton result on `chart` over the box `(lo, hi)`
    /// (module docs, step 3).
    fn finish(&self, p: &Vec3, res: &NewtonResult, chart: usize, (lo, hi): ([f64; 2], [f64; 2])) -> Projection {
        let cur = &res.jet;
        let c = cur.a[0].cross(&cur.a[1]);
        let n_bar = c / c.norm();
        let d = p - cur.x;
        let mut g = d.dot(&n_bar);
        let ortho = self.orthogonal_in(p, res);
        let tol_out = self.options.outside_tol * self.scale;
        let mut outside = false;
        let mut clamped = [false; 2];
        for al in 0..2 {
            let s = d.dot(&cur.a[al]) / cur.a[al].norm();
            let held = if res.xi[al] <= lo[al] && s < 0.0 {
                Some((2 * al, lo[al] == 0.0))
            } else if res.xi[al] >= hi[al] && s > 0.0 {
                Some((2 * al + 1, hi[al] == 1.0))
            } else {
                None
            };
            let Some((side, on_edge)) = held else { continue };
            let kind = if on_edge { self.atlas.edge(chart, side) } else { EdgeKind::Boundary };
            match kind {
                EdgeKind::Boundary => outside |= s.abs() > tol_out,
                EdgeKind::Crease => clamped[al] = res.converged && !ortho[al],
                EdgeKind::Smooth => {}
            }
        }
        if clamped[0] || clamped[1] {
            let len = d.norm();
            g = if g < 0.0 { -len } else { len };
        }
        Projection { xi: res.xi, x_bar: cur.x, g, inside: !outside, iterations: res.iterations, converged: res.converged, clamped }
    }

    /// The parameter on `to` of the point at `uv` on chart `from`: exact between
    /// charts of one spline patch (its patch parameter), otherwise the closest point
    /// of x̄(from, uv) on `to`'s polynomial continued over one chart width.
    pub fn transfer(&self, from: usize, uv: [f64; 2], to: usize) -> [f64; 2] {
        if from == to {
            return uv;
        }
        if let (Some((pa, xi)), Some((pb, _))) = (self.atlas.patch_parameter(from, uv), self.atlas.patch_parameter(to, [0.5; 2])) {
            if pa == pb {
                return self.atlas.chart_parameter(to, xi);
            }
        }
        if let Some(uv2) = self.atlas.adjacent_parameter(from, uv, to) {
            return uv2;
        }
        let x = self.atlas.jet(from, uv).x;
        let bounds = if self.atlas.is_subdivision() { UNIT } else { ([-1.0; 2], [2.0; 2]) };
        self.newton_on(&x, to, bounds).xi
    }
}
