//! Open (clamped) uniform knot vectors, paper eq. 5.1 and sec. 5.2.
//!
//! For `n` control points and order `k` (degree `p = k − 1`) the knot vector
//!
//! ```text
//! Ξ = [ξ_1 … ξ_{n+k}] = [0,…,0, 1/m, 2/m, …, (m−1)/m, 1,…,1],   m = n − k + 1
//!                        └ k ┘                         └ k ┘
//! ```
//! has `n + k` knots, the end knots repeated `k` times (open: the surface
//! interpolates its corner control points and behaves at the border as in the
//! middle) and `n − k` uniform interior knots of multiplicity 1, so the basis is
//! C^{k−2} across every interior knot (sec. 5.1). The parameter domain is `[0, 1]`,
//! cut into `m = n − k + 1` knot spans ("elements").
//!
//! A **periodic** direction (a tube closed on itself, [`KnotVector::periodic_uniform`])
//! uses the unclamped uniform knots `ξ_j = (j − p)/n` of `n` wrapped control points:
//! `n + p` basis functions over `n` spans of the domain `[0, 1]`, basis function
//! `i ≥ n` belonging to control point `i − n`. The curve is C^{k−2} everywhere,
//! the seam included.
//!
//! Knots are stored 0-based: `knots[0..k] = 0`, `knots[n..n+k] = 1`, and span `s`
//! (0-based, `0 ≤ s < m`) is `[knots[k−1+s], knots[k+s])`. The last span is closed,
//! so ξ = 1 belongs to span `m − 1`.

use super::{SplineError, MAX_ORDER};

/// An open uniform knot vector for `n` control points of order `k`.
#[derive(Debug, Clone, PartialEq)]
pub struct KnotVector {
    n: usize,
    order: usize,
    knots: Vec<f64>,
    /// Per span s, `inv_diff[s][j][r] = 1 / (ξ_{p+s+r+1} − ξ_{p+s+1−j+r})` for
    /// `0 ≤ r < j ≤ p`: the reciprocal knot differences of the triangular basis scheme
    /// (independent of ξ, never zero on a nonempty span), so evaluation needs no
    /// division.
    inv_diff: Vec<[[f64; MAX_ORDER]; MAX_ORDER]>,
}

impl KnotVector {
    /// Builds the open uniform knot vector (eq. 5.1) for `n` control points and
    /// order `k` (≥ 2, ≤ [`MAX_ORDER`], `n ≥ k`).
    pub fn open_uniform(n: usize, order: usize) -> Result<Self, SplineError> {
        check_order(n, order)?;
        let m = n - order + 1;
        let mut knots = Vec::with_capacity(n + order);
        knots.extend(std::iter::repeat_n(0.0, order));
        knots.extend((1..m).map(|s| s as f64 / m as f64));
        knots.extend(std::iter::repeat_n(1.0, order));
        debug_assert_eq!(knots.len(), n + order);
        let inv_diff = inv_diffs(&knots, order, m);
        Ok(Self { n, order, knots, inv_diff })
    }

    /// The unclamped uniform knot vector of a closed row of `n` control points of
    /// order `k`: `n + k − 1` basis functions (the last `k − 1` are the first
    /// control points again) and `n` spans on `[0, 1]` (`n ≥ k`).
    pub fn periodic_uniform(n: usize, order: usize) -> Result<Self, SplineError> {
        check_order(n, order)?;
        let p = order - 1;
        let n_basis = n + p;
        let knots: Vec<f64> = (0..n_basis + order).map(|j| (j as f64 - p as f64) / n as f64).collect();
        let inv_diff = inv_diffs(&knots, order, n);
        Ok(Self { n: n_basis, order, knots, inv_diff })
    }

    /// Number of control points (basis functions) `n`.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Order `k` (degree + 1).
    pub fn order(&self) -> usize {
        self.order
    }

    /// Degree `p = k − 1`.
    pub fn degree(&self) -> usize {
        self.order - 1
    }

    /// The `n + k` knots.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Number of nonempty knot spans `m = n − k + 1`.
    pub fn n_spans(&self) -> usize {
        self.n - self.order + 1
    }

    /// Parameter interval `[ξ_lo, ξ_hi]` of span `s`.
    pub fn span_bounds(&self, s: usize) -> (f64, f64) {
        let i = self.order - 1 + s;
        (self.knots[i], self.knots[i + 1])
    }

    /// Span (0-based) holding `xi`: `s` with `knots[k−1+s] ≤ ξ < knots[k+s]`, the last
    /// span closed at ξ = 1. Parameters outside `[0, 1]` map to the first/last span
    /// (evaluation then extends that span's polynomial). O(1): the knots are uniform.
    pub fn find_span(&self, xi: f64) -> usize {
        let m = self.n_spans();
        if xi.is_nan() || xi <= 0.0 {
            return 0;
        }
        if xi >= 1.0 {
            return m - 1;
        }
        let mut s = ((xi * m as f64) as usize).min(m - 1);
        // Guard the floor against rounding so that the half-open rule holds exactly.
        let k1 = self.order - 1;
        while s > 0 && xi < self.knots[k1 + s] {
            s -= 1;
        }
        while s + 1 < m && xi >= self.knots[k1 + s + 1] {
            s += 1;
        }
        s
    }

    /// Reciprocal knot differences of span `s` (see the field docs).
    pub(crate) fn inv_diff(&self, s: usize) -> &[[f64; MAX_ORDER]; MAX_ORDER] {
        &self.inv_diff[s]
    }

    /// Index of the first basis function that is nonzero on span `s`; the nonzero
    /// ones are `first_basis(s) .. first_basis(s) + k` (Piegl & Tiller: `span − p`).
    pub fn first_basis(&self, s: usize) -> usize {
        s
    }
}

/// Order 2 … [`MAX_ORDER`], and at least `order` control points.
fn check_order(n: usize, order: usize) -> Result<(), SplineError> {
    if order < 2 {
        return Err(SplineError::OrderTooLow { order });
    }
    if order > MAX_ORDER {
        return Err(SplineError::OrderTooHigh { order, max: MAX_ORDER });
    }
    if n < order {
        return Err(SplineError::TooFewControlPoints { n, order });
    }
    Ok(())
}

/// The reciprocal knot differences of each of `spans` spans (see `inv_diff`).
fn inv_diffs(knots: &[f64], order: usize, spans: usize) -> Vec<[[f64; MAX_ORDER]; MAX_ORDER]> {
    let p = order - 1;
    (0..spans)
        .map(|s| {
            let span = p + s;
            let mut t = [[0.0; MAX_ORDER]; MAX_ORDER];
            for (j, row) in t.iter_mut().enumerate().take(p + 1).skip(1) {
                for (r, v) in row.iter_mut().enumerate().take(j) {
                    *v = 1.0 / (knots[span + r + 1] - knots[span + 1 + r - j]);
                }
            }
            t
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn open_uniform_layout() {
        let kv = KnotVector::open_uniform(5, 3).unwrap();
        assert_eq!(kv.knots(), &[0.0, 0.0, 0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0, 1.0, 1.0]);
        assert_eq!(kv.n_spans(), 3);
        assert_eq!(kv.span_bounds(1), (1.0 / 3.0, 2.0 / 3.0));
        // order 2 = bilinear: knots at the nodes
        let kv = KnotVector::open_uniform(4, 2).unwrap();
        assert_eq!(kv.knots(), &[0.0, 0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0, 1.0]);
        // n == k: one Bézier span
        let kv = KnotVector::open_uniform(4, 4).unwrap();
        assert_eq!(kv.knots(), &[0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]);
        assert_eq!(kv.n_spans(), 1);
    }

    #[test]
    fn validation_errors() {
        assert_eq!(KnotVector::open_uniform(3, 4), Err(SplineError::TooFewControlPoints { n: 3, order: 4 }));
        assert_eq!(KnotVector::open_uniform(5, 1), Err(SplineError::OrderTooLow { order: 1 }));
        assert_eq!(KnotVector::open_uniform(9, 7), Err(SplineError::OrderTooHigh { order: 7, max: MAX_ORDER }));
        let msg = KnotVector::open_uniform(3, 4).unwrap_err().to_string();
        assert!(msg.contains("a 3-node row cannot carry order 4"), "{msg}");
    }

    #[test]
    fn span_search_half_open_and_right_end() {
        let kv = KnotVector::periodic_uniform(6, 3).unwrap();
        assert_eq!((kv.n(), kv.n_spans(), kv.span_bounds(0), kv.span_bounds(5)), (8, 6, (0.0, 1.0 / 6.0), (5.0 / 6.0, 1.0)));
        assert_eq!(kv.find_span(0.5), 3);
        let kv = KnotVector::open_uniform(9, 3).unwrap(); // 7 spans
        let m = kv.n_spans();
        assert_eq!(m, 7);
        assert_eq!(kv.find_span(0.0), 0);
        assert_eq!(kv.find_span(1.0), m - 1);
        assert_eq!(kv.find_span(-0.5), 0);
        assert_eq!(kv.find_span(1.5), m - 1);
        for s in 0..m {
            let (lo, hi) = kv.span_bounds(s);
            assert_eq!(kv.find_span(lo), s, "left end of span {s} belongs to it");
            assert_eq!(kv.find_span(0.5 * (lo + hi)), s);
            let below_hi = f64::from_bits(hi.to_bits() - 1);
            assert_eq!(kv.find_span(below_hi), s);
        }
        // every exact knot value from the stored vector maps consistently
        for (i, &u) in kv.knots().iter().enumerate().skip(2).take(m) {
            assert_eq!(kv.find_span(u), (i - 2).min(m - 1));
        }
    }
}
