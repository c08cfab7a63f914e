//! B-spline basis functions and their derivatives, paper eq. 5.3.
//!
//! Cox–de Boor recursion (eq. 5.3, order `k`, knots `x_i`):
//! ```text
//! N_{i,1}(ξ) = 1 if x_i ≤ ξ < x_{i+1}, else 0
//! N_{i,k}(ξ) = (ξ − x_i) N_{i,k−1}(ξ) / (x_{i+k−1} − x_i)
//!            + (x_{i+k} − ξ) N_{i+1,k−1}(ξ) / (x_{i+k} − x_{i+1})        (0/0 := 0)
//! ```
//! On span `s` only `N_{s}, …, N_{s+k−1}` (0-based) are nonzero. They are computed
//! together by the triangular scheme of Piegl & Tiller (The NURBS Book, A2.2/A2.3):
//! the table `ndu` holds the basis functions of every order 1…k on the span (upper
//! triangle) and the knot differences (lower triangle); derivatives follow from
//! ```text
//! N^{(d)}_{i,p} = p!/(p−d)! Σ_{j=0}^{d} a_{d,j} N_{i+j,p−d},
//! a_{0,0} = 1, a_{d,0} = a_{d−1,0}/(x_{i+p−d+1} − x_i),
//! a_{d,j} = (a_{d−1,j} − a_{d−1,j−1})/(x_{i+p+j−d+1} − x_{i+j}),
//! a_{d,d} = −a_{d−1,d−1}/(x_{i+p+1} − x_{i+d})                    (p = k − 1)
//! ```
//! Derivatives of order > p vanish. Everything works on stack arrays of
//! [`MAX_ORDER`] and writes into caller buffers: no allocation.
//!
//! ξ = 1 is evaluated on the last span (closed there), where the last basis function
//! equals 1: the patch interpolates its end control points.

use super::{KnotVector, MAX_ORDER};

/// Highest derivative order the basis routines return.
pub const MAX_DERS: usize = 3;

/// `ders[d][r]` = d-th derivative (d = 0…3) of the r-th nonzero basis function
/// `N_{first + r}` on the span (`first = kv.first_basis(span)`, r = 0…k−1).
pub type BasisDers = [[f64; MAX_ORDER]; MAX_DERS + 1];

/// Values of the `k` nonzero basis functions on span `s` at `xi` (A2.2), into
/// `out[0..k]`.
pub fn basis_funs_into(kv: &KnotVector, s: usize, xi: f64, out: &mut [f64; MAX_ORDER]) {
    let p = kv.degree();
    let u = kv.knots();
    let span = p + s;
    let inv = kv.inv_diff(s);
    let mut left = [0.0; MAX_ORDER];
    let mut right = [0.0; MAX_ORDER];
    out[0] = 1.0;
    for j in 1..=p {
        left[j] = xi - u[span + 1 - j];
        right[j] = u[span + j] - xi;
        let mut saved = 0.0;
        for r in 0..j {
            // right[r+1] + left[j−r] is the knot difference ξ_{span+r+1} − ξ_{span+1−j+r}
            let temp = out[r] * inv[j][r];
            out[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        out[j] = saved;
    }
}

/// The `k` nonzero basis functions on span `s` and their derivatives up to order
/// `n_ders ≤ 3` at `xi` (A2.3), into `ders[0..=n_ders][0..k]`. Rows above `n_ders`
/// are left untouched; derivative rows above the degree are set to zero.
pub fn ders_basis_funs_into(kv: &KnotVector, s: usize, xi: f64, n_ders: usize, ders: &mut BasisDers) {
    assert!(n_ders <= MAX_DERS, "at most {MAX_DERS} derivatives");
    let p = kv.degree();
    let u = kv.knots();
    let span = p + s;
    // ndu[r][j] (r ≤ j): the nonzero basis functions of degree j; the knot
    // differences right[r+1] + left[j−r] of the lower triangle are precomputed
    // reciprocals inv[j][r].
    let inv = kv.inv_diff(s);
    let mut ndu = [[0.0; MAX_ORDER]; MAX_ORDER];
    let mut left = [0.0; MAX_ORDER];
    let mut right = [0.0; MAX_ORDER];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = xi - u[span + 1 - j];
        right[j] = u[span + j] - xi;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = ndu[r][j - 1] * inv[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let nd = n_ders.min(p);
    let mut a = [[0.0; MAX_ORDER]; 2];
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=nd {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                let rk = rk as usize;
                a[s2][0] = a[s1][0] * inv[pk + 1][rk];
                d = a[s2][0] * ndu[rk][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if r <= pk + 1 { k - 1 } else { p - r };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) * inv[pk + 1][idx];
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] * inv[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    // multiply by p!/(p−k)!
    let mut f = p as f64;
    for (k, row) in ders.iter_mut().enumerate().take(nd + 1).skip(1) {
        for v in row.iter_mut().take(p + 1) {
            *v *= f;
        }
        f *= (p - k) as f64;
    }
    for row in ders.iter_mut().take(n_ders + 1).skip(nd + 1) {
        row[..=p].fill(0.0);
    }
}

/// Reference: eq. 5.3 literally, `N_{i,k}(ξ)` for basis function `i` (0-based) of
/// order `k` on `kv`'s knots, with 0/0 := 0 and the last nonempty interval closed
/// at ξ = 1. Exponential cost; used to check the fast routines.
pub fn cox_de_boor(kv: &KnotVector, i: usize, k: usize, xi: f64) -> f64 {
    let x = kv.knots();
    if k == 1 {
        let last_nonempty = kv.n() - 1; // [x_{n-1}, x_n) is the last nonempty interval
        let inside = x[i] <= xi && xi < x[i + 1];
        let right_end = i == last_nonempty && xi == x[i + 1];
        return if inside || right_end { 1.0 } else { 0.0 };
    }
    let mut v = 0.0;
    let d1 = x[i + k - 1] - x[i];
    if d1 > 0.0 {
        v += (xi - x[i]) * cox_de_boor(kv, i, k - 1, xi) / d1;
    }
    let d2 = x[i + k] - x[i + 1];
    if d2 > 0.0 {
        v += (x[i + k] - xi) * cox_de_boor(kv, i + 1, k - 1, xi) / d2;
    }
    v
}

#[cfg(test)]
mod tests {
    use super::super::fd;
    use super::*;

    /// Parameters spread over the domain, including the ends and exact knots.
    fn params(kv: &KnotVector) -> Vec<f64> {
        let mut v: Vec<f64> = (0..=200).map(|i| i as f64 / 200.0).collect();
        v.extend(kv.knots().iter().copied());
        v.extend([1e-12, 1.0 - 1e-12, 0.123456789, 0.987654321]);
        v
    }

    #[test]
    fn partition_of_unity_and_nonnegativity() {
        for k in 2..=5 {
            for n in [k, k + 1, 7, 12] {
                let kv = KnotVector::open_uniform(n, k).unwrap();
                for xi in params(&kv) {
                    let s = kv.find_span(xi);
                    let mut ders = [[f64::NAN; MAX_ORDER]; 4];
                    ders_basis_funs_into(&kv, s, xi, 3, &mut ders);
                    let sum: f64 = ders[0][..k].iter().sum();
                    assert!((sum - 1.0).abs() < 1e-14, "k={k} n={n} xi={xi}: Σ N = {sum}");
                    assert!(ders[0][..k].iter().all(|&v| v >= -1e-15), "k={k} n={n} xi={xi}: {:?}", &ders[0][..k]);
                    // derivatives of a partition of unity sum to zero
                    for (d, row) in ders.iter().enumerate().skip(1) {
                        let sd: f64 = row[..k].iter().sum();
                        let scale = (kv.n_spans() as f64).powi(d as i32) * 10.0;
                        assert!(sd.abs() < 1e-10 * scale, "k={k} d={d}: Σ N^({d}) = {sd}");
                    }
                    let mut vals = [0.0; MAX_ORDER];
                    basis_funs_into(&kv, s, xi, &mut vals);
                    for r in 0..k {
                        assert!((vals[r] - ders[0][r]).abs() < 1e-15);
                    }
                }
            }
        }
    }

    #[test]
    fn triangular_scheme_equals_eq_5_3() {
        for k in 2..=5 {
            let kv = KnotVector::open_uniform(9, k).unwrap();
            for xi in params(&kv) {
                let s = kv.find_span(xi);
                let mut vals = [0.0; MAX_ORDER];
                basis_funs_into(&kv, s, xi, &mut vals);
                for i in 0..kv.n() {
                    let reference = cox_de_boor(&kv, i, k, xi);
                    let fast = if (s..s + k).contains(&i) { vals[i - s] } else { 0.0 };
                    assert!((fast - reference).abs() < 1e-14, "k={k} i={i} xi={xi}: {fast} vs {reference}");
                }
            }
        }
    }

    #[test]
    fn right_end_interpolates() {
        for k in 2..=6 {
            let kv = KnotVector::open_uniform(8, k).unwrap();
            let s = kv.find_span(1.0);
            assert_eq!(s, kv.n_spans() - 1);
            let mut vals = [0.0; MAX_ORDER];
            basis_funs_into(&kv, s, 1.0, &mut vals);
            assert_eq!(vals[k - 1], 1.0);
            assert!(vals[..k - 1].iter().all(|&v| v == 0.0));
            basis_funs_into(&kv, 0, 0.0, &mut vals);
            assert_eq!(vals[0], 1.0);
        }
    }

    /// Each derivative against a central difference of the next lower analytic one.
    /// Step `h = 1e-5 Δ` (Δ = knot spacing): truncation error ~ (h/Δ)²/6 ≈ 2e-11
    /// relative, round-off ~ ε/(h/Δ) ≈ 2e-11 relative — both far below 1e-6. The
    /// stencil `ξ ± h` stays inside one span (pieces are polynomials), which is why
    /// the sample parameters keep 2h away from knots.
    #[test]
    fn derivatives_match_finite_differences() {
        for k in 2..=5 {
            let kv = KnotVector::open_uniform(10, k).unwrap();
            let delta = 1.0 / kv.n_spans() as f64;
            let h = 1e-5 * delta;
            for t in 0..97 {
                let xi = (t as f64 + 0.37) / 97.0;
                let s = kv.find_span(xi);
                let (lo, hi) = kv.span_bounds(s);
                if xi - lo < 2.0 * h || hi - xi < 2.0 * h {
                    continue;
                }
                let mut d0 = [[0.0; MAX_ORDER]; 4];
                let mut dp = d0;
                let mut dm = d0;
                ders_basis_funs_into(&kv, s, xi, 3, &mut d0);
                ders_basis_funs_into(&kv, s, xi + h, 3, &mut dp);
                ders_basis_funs_into(&kv, s, xi - h, 3, &mut dm);
                for d in 1..=3 {
                    let fd_vals: Vec<f64> = (0..k).map(|r| (dp[d - 1][r] - dm[d - 1][r]) / (2.0 * h)).collect();
                    // relative to the size of the whole derivative vector, floor at Δ^{-d}
                    let scale = fd::norm(&d0[d][..k]).max(delta.powi(-(d as i32)));
                    let err = fd::max_abs_diff(&fd_vals, &d0[d][..k]) / scale;
                    assert!(err < 1e-6, "k={k} xi={xi} d={d}: rel err {err:e}");
                }
                if k <= 3 {
                    assert!(d0[3][..k].iter().all(|&v| v == 0.0), "3rd derivative above degree vanishes");
                }
            }
        }
    }
}
