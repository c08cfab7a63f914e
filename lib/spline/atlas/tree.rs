//! Bounding-volume hierarchy over the charts of an [`super::Atlas`].
//!
//! Each chart's piece of surface lies in the convex hull of its support control
//! points (B-spline span, bilinear facet) or, for the Catmull–Clark limit surface,
//! within the hull of its stencil, whose boundary phantoms lie at most one edge
//! beyond the real nodes: the leaf box is the support's box, inflated by
//! `inflate × its largest extent` for the subdivision charts. The hierarchy is built
//! once from the reference positions (median split of the chart centres along the
//! longest axis) and refitted as the nodes move.

use super::super::Vec3;

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// Leaf: the chart; inner: `u32::MAX`.
    chart: u32,
    children: [u32; 2],
}

impl Node {
    #[allow(clippy::needless_range_loop)] // c is the coordinate index of three arrays
    fn dist2(&self, p: &[f64; 3]) -> f64 {
        let mut d2 = 0.0;
        for c in 0..3 {
            let d = (self.lo[c] - p[c]).max(0.0).max(p[c] - self.hi[c]);
            d2 += d * d;
        }
        d2
    }
}

/// The hierarchy; `support(c)` lists chart c's control points (positions in `x`).
#[derive(Debug, Clone)]
pub struct ChartTree {
    nodes: Vec<Node>,
    inflate: f64,
}

const STACK: usize = 128;

impl ChartTree {
    pub fn new<'s>(n_charts: usize, support: &dyn Fn(usize) -> &'s [u32], x: &[Vec3], inflate: f64) -> Self {
        let centre: Vec<Vec3> = (0..n_charts)
            .map(|c| {
                let s = support(c);
                s.iter().map(|&k| x[k as usize]).sum::<Vec3>() / s.len().max(1) as f64
            })
            .collect();
        let mut ids: Vec<u32> = (0..n_charts as u32).collect();
        let mut tree = Self { nodes: Vec::with_capacity(2 * n_charts), inflate };
        tree.build(&mut ids, &centre);
        tree.refit(support, x);
        tree
    }

    fn build(&mut self, ids: &mut [u32], centre: &[Vec3]) -> u32 {
        let me = self.nodes.len() as u32;
        self.nodes.push(Node { lo: [0.0; 3], hi: [0.0; 3], chart: u32::MAX, children: [u32::MAX; 2] });
        if ids.len() == 1 {
            self.nodes[me as usize].chart = ids[0];
            return me;
        }
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
        self.nodes[me as usize].children = [l, r];
        me
    }

    /// Leaf boxes from the current positions, unions upwards (children follow their parent).
    pub fn refit<'s>(&mut self, support: &dyn Fn(usize) -> &'s [u32], x: &[Vec3]) {
        for id in (0..self.nodes.len()).rev() {
            let n = self.nodes[id];
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            if n.chart != u32::MAX {
                for &k in support(n.chart as usize) {
                    let p = x[k as usize];
                    for c in 0..3 {
                        lo[c] = lo[c].min(p[c]);
                        hi[c] = hi[c].max(p[c]);
                    }
                }
                let grow = self.inflate * (0..3).map(|c| hi[c] - lo[c]).fold(0.0, f64::max);
                for c in 0..3 {
                    lo[c] -= grow;
                    hi[c] += grow;
                }
            } else {
                for ch in n.children {
                    let m = &self.nodes[ch as usize];
                    for c in 0..3 {
                        lo[c] = lo[c].min(m.lo[c]);
                        hi[c] = hi[c].max(m.hi[c]);
                    }
                }
            }
            self.nodes[id].lo = lo;
            self.nodes[id].hi = hi;
        }
    }

    /// Diagonal of the whole surface's box.
    pub fn diagonal(&self) -> f64 {
        let r = &self.nodes[0];
        (0..3).map(|c| (r.hi[c] - r.lo[c]).powi(2)).sum::<f64>().sqrt()
    }

    /// Branch and bound: `visit(chart, box_dist2)` for every chart whose box lies
    /// within the bound, nearest sibling first; `visit` returns the bound it reached.
    pub fn query(&self, p: &Vec3, mut bound2: f64, mut visit: impl FnMut(usize, f64) -> f64) -> f64 {
        let p = [p.x, p.y, p.z];
        let mut stack = [(0u32, 0.0f64); STACK];
        stack[0] = (0, self.nodes[0].dist2(&p));
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let (id, d2) = stack[top];
            if d2 > bound2 {
                continue;
            }
            let n = &self.nodes[id as usize];
            if n.chart != u32::MAX {
                bound2 = bound2.min(visit(n.chart as usize, d2));
                continue;
            }
            let [c0, c1] = n.children;
            let (d0, d1) = (self.nodes[c0 as usize].dist2(&p), self.nodes[c1 as usize].dist2(&p));
            let (near, far) = if d0 <= d1 { ((c0, d0), (c1, d1)) } else { ((c1, d1), (c0, d0)) };
            if far.1 <= bound2 && top < STACK {
                stack[top] = far;
                top += 1;
            }
            if near.1 <= bound2 && top < STACK {
                stack[top] = near;
                top += 1;
            }
        }
        bound2
    }
}
