//! A hierarchy of axis-aligned boxes and its branch-and-bound walk: the global
//! search of the closest-point projection (eq. 2.2) over the knot spans of a patch
//! ([`super::SpanTree`]) and over the charts of an atlas
//! ([`super::atlas::tree::ChartTree`]).
//!
//! The owner builds the topology (nodes pushed parent first, children after it) and
//! says what box each leaf item has; this holds the nodes, refits the inner boxes as
//! the unions of their children's (one reverse sweep, O(nodes)), and walks: every
//! leaf whose box lies within the current distance bound of a point is visited,
//! nearest box first among siblings, and the visitor tightens the bound as it finds
//! surface points.

use super::Vec3;

/// The `item` of an inner node.
const INNER: u32 = u32::MAX;

/// Deepest hierarchy a walk can take (a walk holds at most one node per level).
const STACK: usize = 128;

#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// A leaf: the owner's item (span, chart); an inner node: [`INNER`].
    item: u32,
    /// An inner node's two children.
    children: [u32; 2],
}

impl Node {
    /// Squared distance from `p` to the box (0 inside).
    #[inline]
    fn dist2(&self, p: &[f64; 3]) -> f64 {
        let mut d2 = 0.0;
        for ((lo, hi), p) in self.lo.iter().zip(&self.hi).zip(p) {
            let d = (lo - p).max(0.0).max(p - hi);
            d2 += d * d;
        }
        d2
    }
}

/// The boxes; node 0 is the root.
#[derive(Debug, Clone, PartialEq)]
pub struct BoxTree {
    nodes: Vec<Node>,
}

impl BoxTree {
    /// No nodes yet, room for `n`.
    pub fn with_capacity(n: usize) -> Self {
        Self { nodes: Vec::with_capacity(n) }
    }

    fn push(&mut self, item: u32) -> u32 {
        self.nodes.push(Node { lo: [f64::INFINITY; 3], hi: [f64::NEG_INFINITY; 3], item, children: [u32::MAX; 2] });
        self.nodes.len() as u32 - 1
    }

    /// Appends the leaf of `item` (empty box until [`Self::refit`]); its node id.
    pub fn push_leaf(&mut self, item: u32) -> u32 {
        self.push(item)
    }

    /// Appends an inner node, its children to follow ([`Self::set_children`]); its node id.
    pub fn push_inner(&mut self) -> u32 {
        self.push(INNER)
    }

    pub fn set_children(&mut self, id: u32, children: [u32; 2]) {
        self.nodes[id as usize].children = children;
    }

    /// The children of inner node `id` (`None` for a leaf).
    pub fn children(&self, id: u32) -> Option<[u32; 2]> {
        let n = &self.nodes[id as usize];
        (n.item == INNER).then_some(n.children)
    }

    /// The box `(lo, hi)` of node `id`.
    pub fn node_box(&self, id: u32) -> (Vec3, Vec3) {
        let n = &self.nodes[id as usize];
        (Vec3::from(n.lo), Vec3::from(n.hi))
    }

    /// Recomputes every box: a leaf's is `leaf_box(item)` = `(lo, hi)`, an inner
    /// node's the union of its children's (stored after it: one reverse sweep).
    pub fn refit(&mut self, mut leaf_box: impl FnMut(u32) -> ([f64; 3], [f64; 3])) {
        for id in (0..self.nodes.len()).rev() {
            let n = self.nodes[id];
            let (lo, hi) = if n.item != INNER {
                leaf_box(n.item)
            } else {
                let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                for ch in n.children {
                    let ch = &self.nodes[ch as usize];
                    for c in 0..3 {
                        lo[c] = lo[c].min(ch.lo[c]);
                        hi[c] = hi[c].max(ch.hi[c]);
                    }
                }
                (lo, hi)
            };
            self.nodes[id].lo = lo;
            self.nodes[id].hi = hi;
        }
    }

    /// Diagonal of the root box (a length scale for tolerances).
    pub fn diagonal(&self) -> f64 {
        let r = &self.nodes[0];
        ((r.hi[0] - r.lo[0]).powi(2) + (r.hi[1] - r.lo[1]).powi(2) + (r.hi[2] - r.lo[2]).powi(2)).sqrt()
    }

    /// Branch-and-bound walk: calls `visit(item, box_dist2)` for each leaf whose box
    /// lies within `sqrt(bound2)` of `p`, nearest box first among siblings; `visit`
    /// returns a squared distance bound it has achieved (e.g. to a surface sample)
    /// and the walk keeps the smallest. Returns the final bound.
    #[inline]
    pub fn query(&self, p: &Vec3, mut bound2: f64, mut visit: impl FnMut(u32, f64) -> f64) -> f64 {
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
            if n.item != INNER {
                bound2 = bound2.min(visit(n.item, d2));
                continue;
            }
            let [c0, c1] = n.children;
            let (d0, d1) = (self.nodes[c0 as usize].dist2(&p), self.nodes[c1 as usize].dist2(&p));
            // push the farther child first so the nearer one is visited first
            let (near, far) = if d0 <= d1 { ((c0, d0), (c1, d1)) } else { ((c1, d1), (c0, d0)) };
            if far.1 <= bound2 {
                stack[top] = far;
                top += 1;
            }
            if near.1 <= bound2 {
                stack[top] = near;
                top += 1;
            }
        }
        bound2
    }
}
