//! Bounding-volume hierarchy over the knot spans of a patch (or the cells of a facet net).
//!
//! Convex-hull property: on knot span (s, t) only the `k_a × k_b` control points
//! `B_{i,j}`, `s ≤ i < s + k_a`, `t ≤ j < t + k_b` carry nonzero basis functions, which
//! are nonnegative and sum to one, so that piece of surface lies in their convex hull
//! and hence in the axis-aligned box of those control points. For order 2 this is the
//! box of a bilinear facet's four nodes. No further inflation is needed.
//!
//! The hierarchy follows the structured span grid: a node covers a rectangle of spans
//! and is split at the middle of its longer side, down to single spans. Its topology
//! depends only on the grid, so when the control points move the tree is *refitted*
//! (leaf boxes recomputed, unions propagated upwards, O(spans)) — cheap enough to do
//! once per Newton iteration of the solver.
//!
//! [`SpanTree::query`] visits, nearest box first, every span whose box is within the
//! current distance bound of a point; the visitor tightens the bound as it finds
//! surface points (branch and bound). The boxes, their refit and the walk are
//! [`BoxTree`]'s, shared with the charts of an atlas.

use super::basis::basis_funs_into;
use super::box_tree::BoxTree;
use super::{KnotVector, Vec3, MAX_ORDER};

/// A rectangle of spans `[s0, s1) × [t0, t1)`.
type Rect = [u32; 4];

/// The two halves of a rectangle of spans, split at the middle of its longer side;
/// `None` for a single span.
fn halves([s0, s1, t0, t1]: Rect) -> Option<(Rect, Rect)> {
    if s1 - s0 <= 1 && t1 - t0 <= 1 {
        None
    } else if s1 - s0 >= t1 - t0 {
        let m = (s0 + s1) / 2;
        Some(([s0, m, t0, t1], [m, s1, t0, t1]))
    } else {
        let m = (t0 + t1) / 2;
        Some(([s0, s1, t0, m], [s0, s1, m, t1]))
    }
}

/// AABB hierarchy over an `ns_a × ns_b` grid of spans, span (s, t) bounding control
/// points `s..s+ka` × `t..t+kb` of an `na × nb` net (`na = ns_a + ka − 1`).
#[derive(Debug, Clone, PartialEq)]
pub struct SpanTree {
    n_spans: [usize; 2],
    window: [usize; 2],
    na: usize,
    /// The boxes; leaf item `s + ns_a·t` is span (s, t).
    tree: BoxTree,
    /// Optional Bézier extraction per direction: `[dir][span][r][i]`, the Bézier
    /// point i of a span is `Σ_r E[r][i] B_r` (see [`Self::with_extraction`]).
    extraction: Option<[Vec<Extraction>; 2]>,
}

/// k×k Bézier extraction matrix of one span in one direction (`[r][i]`).
pub type Extraction = [[f64; MAX_ORDER]; MAX_ORDER];

impl SpanTree {
    /// Topology for `n_spans` spans per direction, each spanning `window` control
    /// points per direction (the orders `[ka, kb]`). Boxes are empty until
    /// [`Self::refit`].
    pub fn new(n_spans: [usize; 2], window: [usize; 2]) -> Self {
        assert!(n_spans[0] > 0 && n_spans[1] > 0, "at least one span per direction");
        let na = n_spans[0] + window[0] - 1;
        let mut tree = Self { n_spans, window, na, tree: BoxTree::with_capacity(2 * n_spans[0] * n_spans[1]), extraction: None };
        tree.build([0, n_spans[0] as u32, 0, n_spans[1] as u32]);
        tree
    }

    /// Like [`Self::new`] for a B-spline patch, with tighter leaf boxes: each span's
    /// piece is a Bézier patch whose control points (Bézier extraction,
    /// `N_r = Σ_i E_ri B_i` with B_i the Bernstein polynomials of the span) lie in the
    /// convex hull of the span's B-spline control points and still enclose the
    /// piece — the box of the Bézier points is never larger and usually about half
    /// as wide per direction.
    pub fn with_extraction(knots: [&KnotVector; 2]) -> Self {
        let mut tree = Self::new([knots[0].n_spans(), knots[1].n_spans()], [knots[0].order(), knots[1].order()]);
        tree.extraction = Some(knots.map(|kv| (0..kv.n_spans()).map(|s| extraction(kv, s)).collect()));
        tree
    }

    fn build(&mut self, rect: Rect) -> u32 {
        match halves(rect) {
            None => self.tree.push_leaf(rect[0] + self.n_spans[0] as u32 * rect[2]),
            Some((a, b)) => {
                let id = self.tree.push_inner();
                let children = [self.build(a), self.build(b)];
                self.tree.set_children(id, children);
                id
            }
        }
    }

    /// Spans per direction.
    pub fn n_spans(&self) -> [usize; 2] {
        self.n_spans
    }

    /// Recomputes every box from the current control points `x` (`i + na·j`).
    #[allow(clippy::needless_range_loop)] // i, j, r, c: the indices of the extraction sums
    pub fn refit(&mut self, x: &[Vec3]) {
        let Self { n_spans, window: [ka, kb], na, tree, extraction } = self;
        let (ns_a, ka, kb, na) = (n_spans[0], *ka, *kb, *na);
        assert_eq!(x.len(), na * (n_spans[1] + kb - 1), "control net size");
        tree.refit(|item| {
            let (s, t) = (item as usize % ns_a, item as usize / ns_a);
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            if let Some([ea, eb]) = extraction {
                let (ea, eb) = (&ea[s], &eb[t]);
                // rows[i][c] = Σ_r E^a_ri B_{s+r, t+c}; Bézier point (i, j) = Σ_c E^b_cj rows[i][c]
                let mut rows = [[Vec3::zeros(); MAX_ORDER]; MAX_ORDER];
                for (i, row) in rows.iter_mut().enumerate().take(ka) {
                    for (c, v) in row.iter_mut().enumerate().take(kb) {
                        let base = s + na * (t + c);
                        for (r, b) in x[base..base + ka].iter().enumerate() {
                            *v += b * ea[r][i];
                        }
                    }
                }
                for row in rows.iter().take(ka) {
                    for j in 0..kb {
                        let mut q = Vec3::zeros();
                        for (c, v) in row.iter().enumerate().take(kb) {
                            q += v * eb[c][j];
                        }
                        for c in 0..3 {
                            lo[c] = lo[c].min(q[c]);
                            hi[c] = hi[c].max(q[c]);
                        }
                    }
                }
                // pad for the round-off of the extraction
                let pad = 1e-12 * (0..3).map(|c| hi[c] - lo[c]).fold(0.0, f64::max);
                for c in 0..3 {
                    lo[c] -= pad;
                    hi[c] += pad;
                }
            } else {
                for j in t..t + kb {
                    for p in &x[s + na * j..s + na * j + ka] {
                        for c in 0..3 {
                            lo[c] = lo[c].min(p[c]);
                            hi[c] = hi[c].max(p[c]);
                        }
                    }
                }
            }
            (lo, hi)
        });
    }

    /// Diagonal of the box around the whole net (a length scale for tolerances).
    pub fn diagonal(&self) -> f64 {
        self.tree.diagonal()
    }

    /// Box `(lo, hi)` of span `(s, t)`'s control points (a walk down the tree).
    pub fn span_box(&self, span: [usize; 2]) -> (Vec3, Vec3) {
        let (s, t) = (span[0] as u32, span[1] as u32);
        let (mut id, mut rect) = (0, [0, self.n_spans[0] as u32, 0, self.n_spans[1] as u32]);
        while let Some((a, b)) = halves(rect) {
            let [l, r] = self.tree.children(id).expect("an inner node");
            (id, rect) = if (a[0]..a[1]).contains(&s) && (a[2]..a[3]).contains(&t) { (l, a) } else { (r, b) };
        }
        self.tree.node_box(id)
    }

    /// Branch-and-bound walk ([`BoxTree::query`]): calls `visit(span, box_dist2)` for
    /// each span whose box lies within `sqrt(bound2)` of `p`, nearest box first among
    /// siblings; `visit` returns a squared distance bound it has achieved (e.g. to a
    /// surface sample) and the walk keeps the smallest. Returns the final bound.
    #[inline]
    pub fn query(&self, p: &Vec3, bound2: f64, mut visit: impl FnMut([usize; 2], f64) -> f64) -> f64 {
        let ns_a = self.n_spans[0];
        self.tree.query(p, bound2, |item, d2| visit([item as usize % ns_a, item as usize / ns_a], d2))
    }
}

/// Bézier extraction of span `s`: solves `N(u_q) = Bern(u_q) Eᵀ` at k points.
fn extraction(kv: &KnotVector, s: usize) -> Extraction {
    let k = kv.order();
    let p = k - 1;
    let (lo, hi) = kv.span_bounds(s);
    let mut m_b = nalgebra::DMatrix::<f64>::zeros(k, k);
    let mut m_n = nalgebra::DMatrix::<f64>::zeros(k, k);
    for q in 0..k {
        let tau = (q as f64 + 0.5) / k as f64;
        let mut vals = [0.0; MAX_ORDER];
        basis_funs_into(kv, s, lo + (hi - lo) * tau, &mut vals);
        let mut binom = 1.0;
        for i in 0..k {
            m_b[(q, i)] = binom * tau.powi(i as i32) * (1.0 - tau).powi((p - i) as i32);
            binom = binom * (p - i) as f64 / (i + 1) as f64;
            m_n[(q, i)] = vals[i];
        }
    }
    let e_t = m_b.lu().solve(&m_n).expect("Bernstein collocation matrix is regular");
    let mut e = [[0.0; MAX_ORDER]; MAX_ORDER];
    for r in 0..k {
        for i in 0..k {
            e[r][i] = e_t[(i, r)];
        }
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    fn net(na: usize, nb: usize) -> Vec<Vec3> {
        (0..na * nb).map(|k| {
            let (i, j) = ((k % na) as f64, (k / na) as f64);
            Vec3::new(i, j, (0.7 * i).sin() * (0.4 * j).cos())
        }).collect()
    }

    #[test]
    fn leaf_boxes_hold_their_window_and_query_is_exhaustive() {
        let (na, nb, ka, kb) = (11, 8, 3, 4);
        let x = net(na, nb);
        let mut tree = SpanTree::new([na - ka + 1, nb - kb + 1], [ka, kb]);
        tree.refit(&x);
        for s in 0..na - ka + 1 {
            for t in 0..nb - kb + 1 {
                let (lo, hi) = tree.span_box([s, t]);
                for j in t..t + kb {
                    for i in s..s + ka {
                        let p = x[i + na * j];
                        assert!((0..3).all(|c| lo[c] <= p[c] && p[c] <= hi[c]));
                    }
                }
            }
        }
        // an infinite bound visits every span exactly once
        let mut seen = vec![0; (na - ka + 1) * (nb - kb + 1)];
        tree.query(&Vec3::new(3.0, 2.0, 5.0), f64::INFINITY, |[s, t], _| {
            seen[s + (na - ka + 1) * t] += 1;
            f64::INFINITY
        });
        assert!(seen.iter().all(|&c| c == 1));
        // a tight bound prunes: only spans whose box is within the bound are visited
        let p = Vec3::new(3.2, 2.1, 0.0);
        let mut visited = 0;
        tree.query(&p, 0.25, |span, d2| {
            visited += 1;
            let (lo, hi) = tree.span_box(span);
            let clamp = Vec3::new(p.x.clamp(lo.x, hi.x), p.y.clamp(lo.y, hi.y), p.z.clamp(lo.z, hi.z));
            assert!(((clamp - p).norm_squared() - d2).abs() < 1e-12 && d2 <= 0.25);
            0.25
        });
        assert!(visited > 0 && visited < seen.len());
        // refit follows moving control points
        let moved: Vec<Vec3> = x.iter().map(|p| p + Vec3::new(0.0, 0.0, 10.0)).collect();
        tree.refit(&moved);
        let (lo, _) = tree.span_box([0, 0]);
        assert!(lo.z > 8.0);
    }

    #[test]
    fn bezier_boxes_are_tighter_and_still_hold_the_surface() {
        use super::super::BSplinePatch;
        for (ka, kb) in [(3, 3), (4, 2), (5, 4)] {
            let (na, nb) = (10, 9);
            let x = net(na, nb);
            let patch = BSplinePatch::new(na, nb, ka, kb).unwrap();
            let mut loose = SpanTree::new(patch.n_spans(), [ka, kb]);
            let mut tight = SpanTree::with_extraction([patch.knots(0), patch.knots(1)]);
            loose.refit(&x);
            tight.refit(&x);
            let (mut vol_l, mut vol_t) = (0.0, 0.0);
            for s in 0..patch.n_spans()[0] {
                for t in 0..patch.n_spans()[1] {
                    let (ll, lh) = loose.span_box([s, t]);
                    let (tl, th) = tight.span_box([s, t]);
                    assert!((0..3).all(|c| tl[c] >= ll[c] - 1e-10 && th[c] <= lh[c] + 1e-10), "inside the hull box (up to the pad)");
                    vol_l += (lh - ll).iter().product::<f64>();
                    vol_t += (th - tl).iter().product::<f64>();
                    let ((a0, a1), (b0, b1)) = (patch.knots(0).span_bounds(s), patch.knots(1).span_bounds(t));
                    for i in 0..=8 {
                        for j in 0..=8 {
                            let xi = [a0 + (a1 - a0) * i as f64 / 8.0, b0 + (b1 - b0) * j as f64 / 8.0];
                            let q = patch.point(&x, xi);
                            assert!((0..3).all(|c| tl[c] <= q[c] && q[c] <= th[c]), "ka={ka} kb={kb} span ({s},{t}) {xi:?}");
                        }
                    }
                }
            }
            assert!(vol_t < 0.5 * vol_l, "ka={ka} kb={kb}: {vol_t} vs {vol_l}");
        }
    }
}
