//! Bounding-volume hierarchy over the charts of an [`super::Atlas`].
//!
//! Each chart's piece of surface lies in the convex hull of its support control
//! points (B-spline span, bilinear facet) or, for the Catmull–Clark limit surface,
//! within the hull of its stencil, whose boundary phantoms lie at most one edge
//! beyond the real nodes: the leaf box is the support's box, inflated by
//! `inflate × its largest extent` for the subdivision charts. The hierarchy is built
//! once from the reference positions (median split of the chart centres along the
//! longest axis) and refitted as the nodes move. The boxes, their refit and the
//! branch-and-bound walk are [`BoxTree`]'s, shared with the span tree of a patch.

use super::super::box_tree::BoxTree;
use super::super::Vec3;

/// The hierarchy; `support(c)` lists chart c's control points (positions in `x`).
/// Leaf item c is chart c.
#[derive(Debug, Clone)]
pub struct ChartTree {
    tree: BoxTree,
    inflate: f64,
}

impl ChartTree {
    pub fn new<'s>(n_charts: usize, support: &dyn Fn(usize) -> &'s [u32], x: &[Vec3], inflate: f64) -> Self {
        let centre: Vec<Vec3> = (0..n_charts)
            .map(|c| {
                let s = support(c);
                s.iter().map(|&k| x[k as usize]).sum::<Vec3>() / s.len().max(1) as f64
            })
            .collect();
        let mut ids: Vec<u32> = (0..n_charts as u32).collect();
        let mut tree = Self { tree: BoxTree::with_capacity(2 * n_charts), inflate };
        tree.build(&mut ids, &centre);
        tree.refit(support, x);
        tree
    }

    fn build(&mut self, ids: &mut [u32], centre: &[Vec3]) -> u32 {
        if ids.len() == 1 {
            return self.tree.push_leaf(ids[0]);
        }
        let me = self.tree.push_inner();
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for &c in ids.iter() {
            lo = lo.inf(&centre[c as usize]);
            hi = hi.sup(&centre[c as usize]);
        }
        let axis = (hi - lo).imax();
        let mid = ids.len() / 2;
        ids.select_nth_unstable_by(mid, |a, b| centre[*a as usize][axis].total_cmp(&centre[*b as usize][axis]));
        let (left, right) = ids.split_at_mut(mid);
        let l = self.build(left, centre);
        let r = self.build(right, centre);
        self.tree.set_children(me, [l, r]);
        me
    }

    /// Leaf boxes from the current positions, unions upwards (children follow their parent).
    pub fn refit<'s>(&mut self, support: &dyn Fn(usize) -> &'s [u32], x: &[Vec3]) {
        let inflate = self.inflate;
        self.tree.refit(|chart| {
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            for &k in support(chart as usize) {
                let p = x[k as usize];
                for c in 0..3 {
                    lo[c] = lo[c].min(p[c]);
                    hi[c] = hi[c].max(p[c]);
                }
            }
            let grow = inflate * (0..3).map(|c| hi[c] - lo[c]).fold(0.0, f64::max);
            for c in 0..3 {
                lo[c] -= grow;
                hi[c] += grow;
            }
            (lo, hi)
        });
    }

    /// Diagonal of the whole surface's box.
    pub fn diagonal(&self) -> f64 {
        self.tree.diagonal()
    }

    /// Branch and bound ([`BoxTree::query`]): `visit(chart, box_dist2)` for every
    /// chart whose box lies within the bound, nearest sibling first; `visit` returns
    /// the bound it reached.
    #[inline]
    pub fn query(&self, p: &Vec3, bound2: f64, mut visit: impl FnMut(usize, f64) -> f64) -> f64 {
        self.tree.query(p, bound2, |chart, d2| visit(chart as usize, d2))
    }
}
