//! The same control net read as bilinear 4-node facets (the classic Lagrangian
//! contact surface, sec. 5.2), for comparison with the B-spline patch.
//!
//! Cell (i, j), `0 ≤ i < na − 1`, `0 ≤ j < nb − 1`, covers
//! `ξ¹ ∈ [i/(na−1), (i+1)/(na−1)]`, `ξ² ∈ [j/(nb−1), (j+1)/(nb−1)]` — exactly the knot
//! spans of an order-2 open uniform patch, so both share one global parameter and the
//! order-2 B-spline *is* this facet set. With local coordinates
//! `s = (na−1)ξ¹ − i`, `t = (nb−1)ξ² − j ∈ [0, 1]` and nodes `x_00, x_10, x_01, x_11`:
//! ```text
//! x̄       = (1−s)(1−t) x_00 + s(1−t) x_10 + (1−s)t x_01 + st x_11
//! ā_1     = ma [(1−t)(x_10 − x_00) + t(x_11 − x_01)],      ma = na − 1
//! ā_2     = mb [(1−s)(x_01 − x_00) + s(x_11 − x_10)],      mb = nb − 1
//! ā_{1,2} = ma mb (x_00 − x_10 − x_01 + x_11)   (twist), ā_{1,1} = ā_{2,2} = 0
//! b̄_12    = ā_{1,2}·n̄,  b̄_11 = b̄_22 = 0;   third derivatives vanish
//! ```
//! The normal is continuous inside a cell and jumps across cell edges.
//! ξ on a cell edge belongs to the cell on its upper side (the last cell is closed),
//! as for knot spans.
#![allow(non_snake_case)]

use rayon::prelude::*;

use super::patch::Jet;
use super::closest_point::{finish, newton, NewtonResult, Projection, ProjectionOptions};
use super::{KnotVector, SpanTree, SplineError, SurfacePoint, Vec3};

/// Bilinear facets over an `na × nb` net (control points `i + na·j`).
#[derive(Debug, Clone, PartialEq)]
pub struct FacetSurface {
    /// Order-2 knot vectors: their spans are the cells (used for the cell search).
    cells: [KnotVector; 2],
}

impl FacetSurface {
    pub fn new(na: usize, nb: usize) -> Result<Self, SplineError> {
        Ok(Self { cells: [KnotVector::open_uniform(na, 2)?, KnotVector::open_uniform(nb, 2)?] })
    }

    /// Nodes per direction `[na, nb]`.
    pub fn n_ctrl(&self) -> [usize; 2] {
        [self.cells[0].n(), self.cells[1].n()]
    }

    /// Cells per direction `[na − 1, nb − 1]`.
    pub fn n_cells(&self) -> [usize; 2] {
        [self.cells[0].n_spans(), self.cells[1].n_spans()]
    }

    /// Cell holding ξ.
    pub fn cell_of(&self, xi: [f64; 2]) -> [usize; 2] {
        [self.cells[0].find_span(xi[0]), self.cells[1].find_span(xi[1])]
    }

    /// Parameter box `(lo, hi)` of a cell.
    pub fn cell_bounds(&self, cell: [usize; 2]) -> ([f64; 2], [f64; 2]) {
        let (a0, a1) = self.cells[0].span_bounds(cell[0]);
        let (b0, b1) = self.cells[1].span_bounds(cell[1]);
        ([a0, b0], [a1, b1])
    }

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

    /// Node indices `[x_00, x_10, x_01, x_11]`, local coordinates (s, t) and the
    /// scale factors (ma, mb) of ξ in `cell`.
    fn local(&self, x: &[Vec3], cell: [usize; 2], xi: [f64; 2]) -> ([usize; 4], [f64; 2], [f64; 2]) {
        let [na, nb] = self.n_ctrl();
        assert_eq!(x.len(), na * nb, "control net size (expected na·nb = {})", na * nb);
        let m = [(na - 1) as f64, (nb - 1) as f64];
        let (lo, _) = self.cell_bounds(cell);
        let st = [(xi[0] - lo[0]) * m[0], (xi[1] - lo[1]) * m[1]];
        let n00 = cell[0] + na * cell[1];
        ([n00, n00 + 1, n00 + na, n00 + na + 1], st, m)
    }

    /// Position and derivatives of `cell`'s bilinear map at ξ (ξ may lie on or
    /// beyond the cell's edges: the cell's own polynomial is used).
    pub fn jet_in_cell(&self, x: &[Vec3], cell: [usize; 2], xi: [f64; 2]) -> Jet {
        let (n, [s, t], [ma, mb]) = self.local(x, cell, xi);
        let [x00, x10, x01, x11] = n.map(|k| x[k]);
        let p = x00 * ((1.0 - s) * (1.0 - t)) + x10 * (s * (1.0 - t)) + x01 * ((1.0 - s) * t) + x11 * (s * t);
        let a1 = ((x10 - x00) * (1.0 - t) + (x11 - x01) * t) * ma;
        let a2 = ((x01 - x00) * (1.0 - s) + (x11 - x10) * s) * mb;
        let twist = (x00 - x10 - x01 + x11) * (ma * mb);
        Jet { x: p, a: [a1, a2], aa: [[Vec3::zeros(), twist], [twist, Vec3::zeros()]] }
    }

    /// x̄(ξ) on the cell holding ξ.
    pub fn point(&self, x: &[Vec3], xi: [f64; 2]) -> Vec3 {
        self.jet_in_cell(x, self.cell_of(xi), xi).x
    }

    /// Full evaluation on the cell holding ξ (see [`Self::evaluate_in_cell_into`]).
    pub fn evaluate(&self, x: &[Vec3], xi: [f64; 2]) -> SurfacePoint {
        let mut out = SurfacePoint::default();
        self.evaluate_in_cell_into(x, self.cell_of(xi), xi, &mut out);
        out
    }

    /// [`SurfacePoint`] of `cell` at ξ: N = the 4 bilinear shape functions (order
    /// `x_00, x_10, x_01, x_11`, as the order-2 B-spline), their ξ-derivatives,
    /// curvature from the twist term only, third derivatives zero.
    pub fn evaluate_in_cell_into(&self, x: &[Vec3], cell: [usize; 2], xi: [f64; 2], out: &mut SurfacePoint) {
        let J = self.jet_in_cell(x, cell, xi);
        let (nodes, [s, t], [ma, mb]) = self.local(x, cell, xi);
        out.xi = xi;
        out.x_bar = J.x;
        out.a_alpha = J.a;
        out.a_alpha_beta = J.aa;
        out.a_alpha_beta_gamma = [[[Vec3::zeros(); 2]; 2]; 2];
        out.basis.clear();
        let q = [(1.0 - s) * (1.0 - t), s * (1.0 - t), (1.0 - s) * t, s * t];
        let q1 = [-(1.0 - t) * ma, (1.0 - t) * ma, -t * ma, t * ma];
        let q2 = [-(1.0 - s) * mb, -s * mb, (1.0 - s) * mb, s * mb];
        let q12 = [1.0, -1.0, -1.0, 1.0].map(|v| v * ma * mb);
        for k in 0..4 {
            out.basis.push(nodes[k], q[k], [q1[k], q2[k]], [[0.0, q12[k]], [q12[k], 0.0]]);
        }
        out.complete_metric();
    }
}

/// The facet set ready for projections: closest point over the candidate cells of
/// the span tree (one box-constrained Newton per cell, pruned by the best distance).
#[derive(Debug, Clone)]
pub struct FacetProjector {
    facets: FacetSurface,
    x: Vec<Vec3>,
    tree: SpanTree,
    scale: f64,
    pub options: ProjectionOptions,
    /// Whether a node in a dead zone is in contact with the crease (edge or vertex,
    /// the default, frictional pairs too: `contact::friction` carries the tangential
    /// traction across the crease) or, with `false`, with the continued plane of its
    /// kept facet (kept for comparison in tests).
    pub crease_contact: bool,
}

impl FacetProjector {
    pub fn new(facets: FacetSurface, x: &[Vec3]) -> Result<Self, SplineError> {
        facets.check_control_net(x)?;
        let tree = SpanTree::new(facets.n_cells(), [2, 2]);
        let mut s = Self { facets, x: Vec::new(), tree, scale: 0.0, options: ProjectionOptions::default(), crease_contact: true };
        s.update(x)?;
        Ok(s)
    }

    /// New node positions: copies them and refits the tree.
    pub fn update(&mut self, x: &[Vec3]) -> Result<(), SplineError> {
        self.facets.check_control_net(x)?;
        self.x.clear();
        self.x.extend_from_slice(x);
        self.tree.refit(&self.x);
        self.scale = self.tree.diagonal();
        Ok(())
    }

    pub fn facets(&self) -> &FacetSurface {
        &self.facets
    }

    /// Evaluation at ξ on the current nodes.
    pub fn evaluate(&self, xi: [f64; 2]) -> SurfacePoint {
        self.facets.evaluate(&self.x, xi)
    }

    /// Closest point of the facet set to `p`.
    pub fn project(&self, p: &Vec3) -> Projection {
        self.project_keeping(p, None).0
    }

    /// Bounded Newton on one cell.
    fn in_cell(&self, p: &Vec3, cell: [usize; 2]) -> NewtonResult {
        let (lo, hi) = self.facets.cell_bounds(cell);
        self.newton_on_map(p, cell, lo, hi, [hi[0] - lo[0], hi[1] - lo[1]])
    }

    /// Newton on `cell`'s bilinear map over the box ξ ∈ [lo, hi] (which may reach
    /// beyond the cell), started at its middle, steps at most `max_step` per direction.
    fn newton_on_map(&self, p: &Vec3, cell: [usize; 2], lo: [f64; 2], hi: [f64; 2], max_step: [f64; 2]) -> NewtonResult {
        let o = &self.options;
        let mid = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        newton(|xi| self.facets.jet_in_cell(&self.x, cell, xi), p, mid, (lo, hi), max_step, o.tol * self.scale, o.max_iterations)
    }

    /// Closest point of the facet set to `p` (eq. 2.2: on a facet, or on a crease
    /// where no facet has an orthogonal projection) and the cell it lies on, with
    /// hysteresis: the cell `prev` (used at the last search) is kept while its foot
    /// point is no farther than the best by 1e-6 of the net's size. A node on the
    /// shared edge of two facets (a crease) then keeps one facet and its normal
    /// instead of flipping between them from one Newton iterate to the next.
    pub fn project_keeping(&self, p: &Vec3, prev: Option<[usize; 2]>) -> (Projection, [usize; 2]) {
        let mut best: Option<(f64, NewtonResult, [usize; 2])> = None;
        self.tree.query(p, f64::INFINITY, |cell, _| {
            let res = self.in_cell(p, cell);
            let d2 = (p - res.jet.x).norm_squared();
            if best.as_ref().is_none_or(|b| d2 < b.0) {
                best = Some((d2, res, cell));
            }
            best.as_ref().map_or(f64::INFINITY, |b| b.0)
        });
        let (d2, mut res, mut cell) = best.expect("the tree has at least one cell");
        if let Some(c) = prev.filter(|&c| c != cell) {
            let kept = self.in_cell(p, c);
            // Where the orthogonal ranges of two facets overlap (a penetrating node
            // below a convex crease) both foot points are local closest points whose
            // distances differ by little; keeping the previous one while it is within
            // 1e-4 of the net's size stops the node from switching facets (and its gap
            // from jumping) at every Newton iterate. A foot point held on the cell's
            // edge is kept only within round-off.
            let slack = if self.orthogonal(p, &kept) { 1e-4 * self.scale } else { 1e-6 * self.scale };
            if kept.converged && (p - kept.jet.x).norm() <= d2.sqrt() + slack {
                res = kept;
                cell = c;
            }
        }
        // Dead zone: the closest point lies on an interior crease, where no facet has
        // an orthogonal projection (a point below a concave crease, above a convex
        // one). The contact is then with the crease itself (its edge, or a vertex):
        // g = ±‖p − x̄‖ along the distance vector, which turns continuously from one
        // facet's normal to the next's as the node crosses the zone (a continued facet
        // plane makes the gap jump where the node reaches the neighbour's range).
        // Without crease contact (frictional pairs), a kept facet's plane is continued
        // until the node reaches the orthogonal range of a neighbour.
        if !self.crease_contact {
            if let Some(kept) = prev.filter(|_| self.on_interior_crease(p, &res)) {
                for c in [kept, cell] {
                    let ext = self.newton_on_continued_cell(p, c, [None; 2]);
                    if ext.converged && self.orthogonal(p, &ext) {
                        res = ext;
                        cell = c;
                        break;
                    }
                }
            }
        }
        (self.finish_facet(p, &res), cell)
    }

    /// The directions in which the foot point is held on a cell edge shared with
    /// another cell (a bound where ξ is not on the patch's edge): a crease.
    fn crease_directions(&self, p: &Vec3, res: &NewtonResult) -> [bool; 2] {
        let ortho = self.orthogonal_in(p, res);
        [0, 1].map(|al| res.converged && !ortho[al] && res.xi[al] > 1e-12 && res.xi[al] < 1.0 - 1e-12)
    }

    fn on_interior_crease(&self, p: &Vec3, res: &NewtonResult) -> bool {
        self.crease_directions(p, res).iter().any(|&c| c)
    }

    /// Bounded Newton on `cell`'s bilinear map continued one cell width beyond each
    /// edge it shares with another cell (not beyond the patch's edges: a node there is
    /// outside, or within the edge tolerance, `PairSolver::search`); in a direction
    /// with `crease[α] = Some(ξ^α)` the foot point is held at that ξ^α.
    fn newton_on_continued_cell(&self, p: &Vec3, cell: [usize; 2], crease: [Option<f64>; 2]) -> NewtonResult {
        let (mut lo, mut hi) = self.facets.cell_bounds(cell);
        let width = [hi[0] - lo[0], hi[1] - lo[1]];
        for al in 0..2 {
            if let Some(edge) = crease[al] {
                (lo[al], hi[al]) = (edge, edge);
            } else {
                lo[al] = (lo[al] - width[al]).max(0.0);
                hi[al] = (hi[al] + width[al]).min(1.0);
            }
        }
        // a held direction has an empty box; the steps stay bounded by the cell width
        self.newton_on_map(p, cell, lo, hi, width)
    }

    /// The [`Projection`] of a Newton result on a cell: `clamped[α]` where the foot
    /// point is held on a cell edge shared with another cell (a crease), and there
    /// the signed distance g = ±‖p − x̄‖ (sign of the facet's normal side). Without
    /// crease contact, the plain projection (g along the cell's normal).
    fn finish_facet(&self, p: &Vec3, res: &NewtonResult) -> Projection {
        let mut pr = finish(p, res, self.options.outside_tol * self.scale);
        if !self.crease_contact {
            return pr;
        }
        pr.clamped = self.crease_directions(p, res);
        if pr.clamped[0] || pr.clamped[1] {
            let len = (p - res.jet.x).norm();
            pr.g = if pr.g < 0.0 { -len } else { len };
        }
        pr
    }

    /// Whether the foot point satisfies the closest-point condition (p − x̄)·ā_α = 0
    /// in each direction α (not held on a box bound).
    fn orthogonal_in(&self, p: &Vec3, res: &NewtonResult) -> [bool; 2] {
        let d = p - res.jet.x;
        let tol = self.options.tol * self.scale;
        [0, 1].map(|al| d.dot(&res.jet.a[al]).abs() <= (1e-8 * d.norm() + 8.0 * tol) * res.jet.a[al].norm())
    }

    fn orthogonal(&self, p: &Vec3, res: &NewtonResult) -> bool {
        self.orthogonal_in(p, res).iter().all(|&o| o)
    }

    /// Closest point on `cell`'s bilinear map extended beyond the patch edge by up to
    /// `margin` (parameter units) — see [`crate::spline::BSplineProjector::project_extended`].
    pub fn project_extended(&self, p: &Vec3, cell: [usize; 2], margin: [f64; 2]) -> Projection {
        let (mut lo, mut hi) = self.facets.cell_bounds(cell);
        let n = self.facets.n_cells();
        for al in 0..2 {
            if cell[al] == 0 {
                lo[al] -= margin[al];
            }
            if cell[al] + 1 == n[al] {
                hi[al] += margin[al];
            }
        }
        self.finish_facet(p, &self.newton_on_map(p, cell, lo, hi, [hi[0] - lo[0], hi[1] - lo[1]]))
    }

    /// Closest point on `cell`'s bilinear map continued over one cell width beyond
    /// each of its interior edges: the projection with the master element held fixed (a
    /// frozen search, see `PairSolver::freeze`). Across a crease the foot point then
    /// moves on the continued plane of its facet instead of jumping to the
    /// neighbour's, so the contact residual stays differentiable while Newton
    /// finishes the iterate. A node held in crease contact (`crease[α] = Some(ξ^α)`,
    /// its foot point on that cell edge) keeps ξ^α there and moves only along the
    /// crease, so its gap stays the distance to that edge (or vertex).
    ///
    /// A node that has left the continued map's range (its foot point held on the
    /// range's bound: it moved more than a cell away) is not held: it gets the
    /// regular search, as a held node could otherwise pass undetected through
    /// another facet.
    pub fn project_on_cell(&self, p: &Vec3, cell: [usize; 2], crease: [Option<f64>; 2]) -> (Projection, [usize; 2]) {
        let res = self.newton_on_continued_cell(p, cell, crease);
        let ortho = self.orthogonal_in(p, &res);
        if res.converged && (0..2).all(|al| ortho[al] || crease[al].is_some()) {
            (self.finish_facet(p, &res), cell)
        } else {
            self.project_keeping(p, Some(cell))
        }
    }

    /// Evaluation at ξ on a given cell (the one [`Self::project_keeping`] returned).
    pub fn evaluate_in_cell(&self, xi: [f64; 2], cell: [usize; 2]) -> SurfacePoint {
        let mut out = SurfacePoint::default();
        self.facets.evaluate_in_cell_into(&self.x, cell, xi, &mut out);
        out
    }

    /// Projects every point, in parallel (rayon).
    pub fn project_all(&self, points: &[Vec3]) -> Vec<Projection> {
        points.par_iter().map(|p| self.project(p)).collect()
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::super::patch::tests::wavy_net;
    use super::super::BSplinePatch;
    use super::*;

    /// A 7 × 3 valley net extruded along y (unit spacing, n̄ = +z): z = 0.1 (x − 3)²,
    /// creases at x = 1 … 5; at x = 4 the slopes 0.1 and 0.3 meet (0.197 rad).
    pub(crate) fn valley_net() -> (usize, usize, Vec<Vec3>) {
        let (na, nb) = (7, 3);
        let x = (0..na * nb)
            .map(|k| {
                let (i, j) = ((k % na) as f64, (k / na) as f64);
                Vec3::new(i, j, 0.1 * (i - 3.0).powi(2))
            })
            .collect();
        (na, nb, x)
    }

    #[test]
    fn order_two_bspline_is_the_facet_set() {
        let (na, nb) = (7, 6);
        let x = wavy_net(na, nb);
        let patch = BSplinePatch::new(na, nb, 2, 2).unwrap();
        let facets = FacetSurface::new(na, nb).unwrap();
        let mut xis: Vec<[f64; 2]> = Vec::new();
        for i in 0..=37 {
            for j in 0..=23 {
                xis.push([i as f64 / 37.0, j as f64 / 23.0]);
            }
        }
        // exact cell borders and the domain corners
        for i in 0..na {
            for j in 0..nb {
                xis.push([i as f64 / (na - 1) as f64, j as f64 / (nb - 1) as f64]);
            }
        }
        let close = |a: Vec3, b: Vec3, s: f64| (a - b).norm() <= 1e-14 * s;
        for xi in xis {
            let b = patch.evaluate(&x, xi);
            let f = facets.evaluate(&x, xi);
            let s = 1.0 + b.x_bar.norm();
            let sa = (na * nb) as f64; // derivative magnitudes grow with the cell count
            assert!(close(b.x_bar, f.x_bar, s), "{xi:?}: {:?} vs {:?}", b.x_bar, f.x_bar);
            for al in 0..2 {
                assert!(close(b.a_alpha[al], f.a_alpha[al], sa), "a_{al} at {xi:?}");
                for be in 0..2 {
                    assert!(close(b.a_alpha_beta[al][be], f.a_alpha_beta[al][be], sa * sa), "a_{al},{be} at {xi:?}");
                }
            }
            assert!(close(b.n_bar, f.n_bar, 1.0), "n at {xi:?}");
            assert!((b.b_ab - f.b_ab).norm() <= 1e-14 * sa * sa);
            assert_eq!(b.basis.nodes(), f.basis.nodes());
            for k in 0..4 {
                assert!((b.basis.q()[k] - f.basis.q()[k]).abs() <= 1e-14);
                for al in 0..2 {
                    assert!((b.basis.q_alpha()[k][al] - f.basis.q_alpha()[k][al]).abs() <= 1e-14 * sa);
                    for be in 0..2 {
                        assert!((b.basis.q_alpha_beta()[k][al][be] - f.basis.q_alpha_beta()[k][al][be]).abs() <= 1e-14 * sa * sa);
                    }
                }
            }
            assert!(b.a_alpha_beta_gamma.iter().flatten().flatten().all(|v| v.norm() == 0.0));
        }
    }

    #[test]
    fn cylinder_normals_bspline_continuous_facets_jump() {
        let radius = 2.0;
        let x = super::super::projection::tests::cylinder_net(radius);
        let (na, nb) = (9, 5);
        let dtheta = std::f64::consts::FRAC_PI_2 / (na - 1) as f64;
        let patch = BSplinePatch::new(na, nb, 3, 3).unwrap();
        let facets = FacetSurface::new(na, nb).unwrap();
        let eps = 1e-9;
        let kv = patch.knots(0);
        // B-spline: across every interior knot (span border) and every facet border
        let mut borders: Vec<f64> = (1..kv.n_spans()).map(|s| kv.span_bounds(s).0).collect();
        borders.extend((1..na - 1).map(|i| i as f64 / (na - 1) as f64));
        for &xb in &borders {
            for &eta in &[0.0, 0.3, 0.5, 1.0] {
                let n_minus = patch.evaluate(&x, [xb - eps, eta]).n_bar;
                let n_plus = patch.evaluate(&x, [xb + eps, eta]).n_bar;
                assert!((n_plus - n_minus).norm() < 1e-6, "B-spline normal jumps at ξ¹={xb}: {:e}", (n_plus - n_minus).norm());
            }
        }
        // facets: the normal turns by the facet angle Δθ across each cell border
        let jump_expected = 2.0 * (dtheta / 2.0).sin();
        for i in 1..na - 1 {
            let xb = i as f64 / (na - 1) as f64;
            for &eta in &[0.0, 0.3, 0.5, 1.0] {
                let n_minus = facets.evaluate(&x, [xb - eps, eta]).n_bar;
                let n_plus = facets.evaluate(&x, [xb + eps, eta]).n_bar;
                let jump = (n_plus - n_minus).norm();
                assert!(jump > 0.9 * jump_expected, "facet normal jump {jump} at ξ¹={xb}");
                assert!((jump - jump_expected).abs() < 1e-6, "facet jump {jump} vs 2 sin(Δθ/2) = {jump_expected}");
            }
        }
    }

    /// Below a concave crease (a valley, n̄ = +z) a point swept across the dead zone:
    /// with crease contact its foot point stays on the crease (ξ¹ clamped), g = −‖d‖
    /// equals minus the distance to the facet set (brute force) everywhere, and g is
    /// continuous; with continued planes (`crease_contact: false`) g jumps where the point
    /// reaches the next facet's range.
    #[test]
    fn dead_zone_gap_is_continuous_with_crease_contact() {
        let (na, nb, x) = valley_net();
        let facets = FacetSurface::new(na, nb).unwrap();
        // the net is extruded along y and the points lie at y = 1 (ξ² = ½): brute force
        // over that line, spacing 1e-5 in x (distance error ≤ 1e-10 near the crease)
        let m = 600_000;
        let dense: Vec<Vec3> = (0..=m).map(|i| facets.point(&x, [i as f64 / m as f64, 0.5])).collect();
        // the crease x = 4 (slopes 0.1 and 0.3: 0.197 rad); 0.1 below it the dead zone
        // spans x ∈ 4 + 0.1·[−0.0995, 0.287]·(…) ≈ [3.99, 4.029]
        for crease_contact in [true, false] {
            let mut proj = FacetProjector::new(facets.clone(), &x).unwrap();
            proj.crease_contact = crease_contact;
            let (mut prev, mut last_g, mut jumps, mut clamped) = (None, f64::NAN, 0.0f64, 0);
            for k in 0..=120 {
                let p = Vec3::new(3.97 + 0.08 * k as f64 / 120.0, 1.0, 0.0);
                let (pr, cell) = proj.project_keeping(&p, prev);
                prev = Some(cell);
                assert!(pr.inside && pr.converged, "{p:?}");
                if pr.clamped[0] {
                    clamped += 1;
                    assert!(crease_contact && (pr.xi[0] - 4.0 / 6.0).abs() < 1e-12 && !pr.clamped[1]);
                    let brute = dense.iter().map(|q| (q - p).norm()).fold(f64::INFINITY, f64::min);
                    // kept from the previous search within the hysteresis 1e-6 L
                    // (L ≈ 6.4, the net's diagonal); searched afresh: exact
                    assert!((-pr.g - brute).abs() < 1e-5, "{p:?}: g {} vs distance {brute}", pr.g);
                    assert!((-proj.project(&p).g - brute).abs() < 1e-9, "{p:?}: fresh search vs distance {brute}");
                    assert!((pr.g + (p - pr.x_bar).norm()).abs() < 1e-14);
                }
                if k > 0 {
                    jumps = jumps.max((pr.g - last_g).abs());
                }
                last_g = pr.g;
            }
            // step 0.08/120 = 6.7e-4 in x: a continuous g changes by at most that
            eprintln!("crease contact {crease_contact}: {clamped} of 121 on the crease, largest step in g {jumps:.2e}");
            if crease_contact {
                assert!(clamped > 10 && jumps < 1e-3, "{clamped} {jumps}");
            } else {
                assert!(clamped == 0 && jumps > 2e-3, "{clamped} {jumps}");
            }
        }
    }

    #[test]
    fn facet_projection_plane_cylinder_and_outside() {
        let radius = 2.0;
        let x = super::super::projection::tests::cylinder_net(radius);
        let facets = FacetSurface::new(9, 5).unwrap();
        let proj = FacetProjector::new(facets.clone(), &x).unwrap();
        // brute force over the facet set
        let m = 250;
        let dense: Vec<Vec3> = (0..=m)
            .flat_map(|i| (0..=m).map(move |j| [i as f64 / m as f64, j as f64 / m as f64]))
            .map(|xi| facets.point(&x, xi))
            .collect();
        for k in 0..50 {
            let th = 0.05 + 1.45 * (k as f64 / 49.0);
            let rr = 1.3 + 1.4 * ((k * 7 % 11) as f64 / 10.0);
            let p = Vec3::new(rr * th.cos(), 0.1 + 2.8 * ((k * 3 % 13) as f64 / 12.0), rr * th.sin());
            let r = proj.project(&p);
            assert!(r.inside, "{p:?}: {r:?}");
            let d = (p - r.x_bar).norm();
            let brute = dense.iter().map(|q| (q - p).norm()).fold(f64::INFINITY, f64::min);
            assert!(d <= brute + 1e-12 && brute - d < 0.02, "{p:?}: {d} vs {brute}");
            // inside a cell the foot point is an orthogonal projection onto that facet
            let cell = facets.cell_of(r.xi);
            let (lo, hi) = facets.cell_bounds(cell);
            let interior = (0..2).all(|al| r.xi[al] > lo[al] + 1e-9 && r.xi[al] < hi[al] - 1e-9);
            if interior {
                let sp = proj.evaluate(r.xi);
                assert!((p - r.x_bar).cross(&sp.n_bar).norm() < 1e-10, "{p:?}: not along the normal");
            }
        }
        for p in [Vec3::new(-0.6, 1.5, 2.5), Vec3::new(2.1, -0.4, 0.4), Vec3::new(1.2, 3.5, 1.4)] {
            assert!(!proj.project(&p).inside, "{p:?}");
        }
        let ok = proj.project_all(&[Vec3::new(1.5, 1.0, 1.5)]);
        // n̄ = ā_1 × ā_2 points towards the axis for this net: a point outside the radius has g < 0
        assert!(ok[0].inside && ok[0].g < 0.0);
    }
}
