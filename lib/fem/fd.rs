//! Central finite differences, the one helper every derivative check uses
//! (materials, element, pressure, and later the contact element and the global tangent).
//!
//! Step: h_j = `rel_step` · max(|x_j|, `scale`); error O(h²) truncation + O(ε_mach/h)
//! round-off, so `rel_step` ≈ 1e-5…1e-6 gives about 1e-9 relative accuracy on smooth
//! functions. Heap-allocating (tests only, not hot paths).

use nalgebra::{DMatrix, DVector};

/// Options of the finite-difference step.
#[derive(Debug, Clone, Copy)]
pub struct FdStep {
    /// Relative step.
    pub rel_step: f64,
    /// Magnitude below which the step is `rel_step · scale` (typical size of x).
    pub scale: f64,
}

impl Default for FdStep {
    fn default() -> Self {
        Self {
            rel_step: 1e-6,
            scale: 1.0,
        }
    }
}

impl FdStep {
    fn h(&self, xj: f64) -> f64 {
        self.rel_step * xj.abs().max(self.scale)
    }
}

/// ∂f/∂x_j by central differences, f: Rⁿ → R.
pub fn fd_gradient(mut f: impl FnMut(&[f64]) -> f64, x: &[f64], step: FdStep) -> DVector<f64> {
    let mut xp = x.to_vec();
    DVector::from_fn(x.len(), |j, _| {
        let h = step.h(x[j]);
        xp[j] = x[j] + h;
        let fp = f(&xp);
        xp[j] = x[j] - h;
        let fm = f(&xp);
        xp[j] = x[j];
        (fp - fm) / (2.0 * h)
    })
}

/// Jacobian ∂f_i/∂x_j by central differences, f: Rⁿ → Rᵐ written into its second argument
/// (length `m`).
pub fn fd_jacobian(mut f: impl FnMut(&[f64], &mut [f64]), x: &[f64], m: usize, step: FdStep) -> DMatrix<f64> {
    let n = x.len();
    let mut xp = x.to_vec();
    let (mut fp, mut fm) = (vec![0.0; m], vec![0.0; m]);
    let mut jac = DMatrix::zeros(m, n);
    for j in 0..n {
        let h = step.h(x[j]);
        xp[j] = x[j] + h;
        f(&xp, &mut fp);
        xp[j] = x[j] - h;
        f(&xp, &mut fm);
        xp[j] = x[j];
        for i in 0..m {
            jac[(i, j)] = (fp[i] - fm[i]) / (2.0 * h);
        }
    }
    jac
}

/// Relative error ‖a − b‖_F / ‖b‖_F (absolute if ‖b‖_F = 0), for any matrix shapes
/// given as equally long slices (nalgebra storage is column-major in both).
pub fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    rel_err_floor(a, b, 0.0)
}

/// ‖a − b‖_F / max(‖b‖_F, floor): relative error that stays meaningful when b vanishes
/// (e.g. the stress at F = I, with `floor` the stress scale μ).
pub fn rel_err_floor(a: &[f64], b: &[f64], floor: f64) -> f64 {
    assert_eq!(a.len(), b.len(), "rel_err: length mismatch");
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
    let nb: f64 = b.iter().map(|y| y * y).sum::<f64>().sqrt().max(floor);
    if nb > 0.0 {
        d / nb
    } else {
        d
    }
}

/// Deterministic pseudo-random numbers for tests (64-bit LCG, Knuth MMIX
/// constants), values in [-1, 1); no external crate, same sequence everywhere.
pub struct Lcg(pub u64);

impl Lcg {
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64) / ((1u64 << 53) as f64) * 2.0 - 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fd_of_known_functions() {
        let x = [0.3, -1.2, 2.0];
        let g = fd_gradient(|x| x[0] * x[1].sin() + x[2].powi(3), &x, FdStep::default());
        let ex = [x[1].sin(), x[0] * x[1].cos(), 3.0 * x[2] * x[2]];
        assert!(rel_err(g.as_slice(), &ex) < 1e-9);
        let jac = fd_jacobian(
            |x, out| {
                out[0] = x[0] * x[1];
                out[1] = x[2].exp();
            },
            &x,
            2,
            FdStep::default(),
        );
        let ex = DMatrix::from_row_slice(2, 3, &[x[1], x[0], 0.0, 0.0, 0.0, x[2].exp()]);
        assert!(rel_err(jac.as_slice(), ex.as_slice()) < 1e-9);
    }
}
