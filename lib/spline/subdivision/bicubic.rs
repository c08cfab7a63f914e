//! The uniform bicubic B-spline patch over a 4×4 control grid: what Catmull–Clark
//! subdivision converges to on every face whose four corners have valence 4.
//!
//! On `[0,1]²` with grid points `P_{ij}`, `i, j = −1…2`:
//! ```text
//! x(s, t) = Σ_i Σ_j B_i(s) B_j(t) P_{ij}
//! B_{−1}(s) = (1−s)³/6,  B_0(s) = (3s³ − 6s² + 4)/6,
//! B_1(s) = (−3s³ + 3s² + 3s + 1)/6,  B_2(s) = s³/6
//! ```
//! Weights are stored by *derivative row* `r`, the partial derivative
//! `∂^{i+j}/∂s^i ∂t^j` with `(i, j) = `[`ORDERS`]`[r]`: rows 0…5 are what the Newton
//! jet needs, rows 6…9 the third derivatives.

use super::super::MAX_NODES;

/// Number of derivative rows: value, 2 first, 3 second, 4 third derivatives.
pub(super) const N_ROWS: usize = 10;
/// Rows up to second order (value, first, second derivatives).
pub(super) const N_ROWS_JET: usize = 6;
/// `(i, j)`: row `r` holds `∂^{i+j}/∂s^i ∂t^j`.
pub(super) const ORDERS: [(usize, usize); N_ROWS] =
    [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2), (3, 0), (2, 1), (1, 2), (0, 3)];

/// Weight table: `w[r][k]` for derivative row `r` and stencil point `k`.
pub(super) type Rows = [[f64; MAX_NODES]; N_ROWS];

/// The row holding `∂^{i+j}/∂s^i ∂t^j` (i + j ≤ 3).
pub(super) fn row_of(i: usize, j: usize) -> usize {
    let order = i + j;
    // rows of order p start at p(p+1)/2 and run over j = 0…p
    order * (order + 1) / 2 + j
}

/// `d[p][k]`: p-th derivative (p = 0…3) of the uniform cubic B-spline `B_{k−1}` at `s`.
pub(super) fn cubic(s: f64) -> [[f64; 4]; 4] {
    let r = 1.0 - s;
    let s2 = s * s;
    let s3 = s2 * s;
    [
        [r * r * r / 6.0, (3.0 * s3 - 6.0 * s2 + 4.0) / 6.0, (-3.0 * s3 + 3.0 * s2 + 3.0 * s + 1.0) / 6.0, s3 / 6.0],
        [-r * r / 2.0, (3.0 * s2 - 4.0 * s) / 2.0, (-3.0 * s2 + 2.0 * s + 1.0) / 2.0, s2 / 2.0],
        [r, 3.0 * s - 2.0, 1.0 - 3.0 * s, s],
        [-1.0, 3.0, -3.0, 1.0],
    ]
}

/// Tensor-product weights at `(s, t)` for rows `0..n_rows`, grid point `(i, j)` at
/// column `(i+1) + 4(j+1)`.
pub(super) fn weights_into(st: [f64; 2], n_rows: usize, w: &mut Rows) {
    let bs = cubic(st[0]);
    let bt = cubic(st[1]);
    for (r, &(i, j)) in ORDERS.iter().enumerate().take(n_rows) {
        for b in 0..4 {
            for a in 0..4 {
                w[r][a + 4 * b] = bs[i][a] * bt[j][b];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_are_numbered_by_order() {
        for (r, &(i, j)) in ORDERS.iter().enumerate() {
            assert_eq!(row_of(i, j), r);
        }
    }

    /// Each derivative against a central difference of the one below: h = 1e-5,
    /// cubic pieces so the truncation error h²/6·|B⁗| is zero and round-off ~ε/h ≈ 1e-11.
    #[test]
    fn cubic_derivatives_match_finite_differences() {
        let h = 1e-5;
        for s in [0.1, 0.37, 0.5, 0.93] {
            let d = cubic(s);
            let (p, m) = (cubic(s + h), cubic(s - h));
            let sum: f64 = d[0].iter().sum();
            assert!((sum - 1.0).abs() < 1e-15);
            for o in 1..4 {
                for k in 0..4 {
                    let fd = (p[o - 1][k] - m[o - 1][k]) / (2.0 * h);
                    assert!((fd - d[o][k]).abs() < 1e-9, "order {o} k {k}: {fd} vs {}", d[o][k]);
                }
            }
        }
    }
}
