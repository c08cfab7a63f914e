//! Shared finite-difference helpers for the derivative checks of this module.

use super::Vec3;

pub fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

pub fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Central difference of a vector-valued function of ξ along direction `dir`.
pub fn central_vec3(f: impl Fn([f64; 2]) -> Vec3, xi: [f64; 2], dir: usize, h: f64) -> Vec3 {
    let mut p = xi;
    let mut m = xi;
    p[dir] += h;
    m[dir] -= h;
    (f(p) - f(m)) / (2.0 * h)
}

/// Asserts `|fd − exact| ≤ tol · scale` with a labelled message.
#[track_caller]
pub fn assert_vec3_close(fd: Vec3, exact: Vec3, scale: f64, tol: f64, what: &str) {
    let err = (fd - exact).norm() / scale;
    assert!(err < tol, "{what}: FD {fd:?} vs exact {exact:?}: relative error {err:e} ≥ {tol:e}");
}
