//! Forward-mode dual numbers `a + b ε` (ε² = 0): evaluating a formula on duals gives
//! its value and its exact directional derivative. The frictional contact tangent is
//! built this way (one direction per element dof) from the residual, whose own
//! formulas contain the analytical first variation of ξ̄ (see `docs/theory.md`,
//! "Friction: the tangent by forward differentiation").

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};

/// `v + d ε`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Dual {
    /// Value.
    pub v: f64,
    /// Derivative along the seeded direction.
    pub d: f64,
}

impl Dual {
    pub const ZERO: Dual = Dual { v: 0.0, d: 0.0 };

    pub fn new(v: f64, d: f64) -> Self {
        Self { v, d }
    }

    pub fn cst(v: f64) -> Self {
        Self { v, d: 0.0 }
    }

    pub fn sqrt(self) -> Self {
        let s = self.v.sqrt();
        Self { v: s, d: self.d / (2.0 * s) }
    }
}

impl Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual { v: self.v + o.v, d: self.d + o.d }
    }
}
impl AddAssign for Dual {
    fn add_assign(&mut self, o: Dual) {
        self.v += o.v;
        self.d += o.d;
    }
}
impl Sub for Dual {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual { v: self.v - o.v, d: self.d - o.d }
    }
}
impl Mul for Dual {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual { v: self.v * o.v, d: self.d * o.v + self.v * o.d }
    }
}
impl Mul<f64> for Dual {
    type Output = Dual;
    fn mul(self, o: f64) -> Dual {
        Dual { v: self.v * o, d: self.d * o }
    }
}
impl Div for Dual {
    type Output = Dual;
    fn div(self, o: Dual) -> Dual {
        Dual { v: self.v / o.v, d: (self.d * o.v - self.v * o.d) / (o.v * o.v) }
    }
}
impl Neg for Dual {
    type Output = Dual;
    fn neg(self) -> Dual {
        Dual { v: -self.v, d: -self.d }
    }
}

/// A 3-vector of duals.
pub type D3 = [Dual; 3];

pub fn d3(v: &nalgebra::Vector3<f64>, d: &nalgebra::Vector3<f64>) -> D3 {
    [Dual::new(v[0], d[0]), Dual::new(v[1], d[1]), Dual::new(v[2], d[2])]
}

pub fn dot(a: &D3, b: &D3) -> Dual {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: &D3, b: &D3) -> D3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

pub fn scale(a: &D3, s: Dual) -> D3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub fn sub(a: &D3, b: &D3) -> D3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn add(a: &D3, b: &D3) -> D3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Inverse of a symmetric-or-not 2×2 matrix `[[a, b], [c, d]]` of duals; `None` if
/// singular.
pub fn inv2(m: [[Dual; 2]; 2]) -> Option<[[Dual; 2]; 2]> {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    if det.v == 0.0 || !det.v.is_finite() {
        return None;
    }
    Some([[m[1][1] / det, -m[0][1] / det], [-m[1][0] / det, m[0][0] / det]])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// d/dx of sqrt(x² + 3x) / (x + 1) at x = 2 against the closed form.
    #[test]
    fn derivative_of_a_composite() {
        let x = Dual::new(2.0, 1.0);
        let f = (x * x + x * 3.0).sqrt() / (x + Dual::cst(1.0));
        let g = |x: f64| (x * x + 3.0 * x).sqrt() / (x + 1.0);
        let fd = (g(2.0 + 1e-6) - g(2.0 - 1e-6)) / 2e-6;
        assert!((f.v - g(2.0)).abs() < 1e-15);
        assert!((f.d - fd).abs() < 1e-8, "{} vs {fd}", f.d);
        let m = inv2([[x, Dual::cst(1.0)], [Dual::cst(0.5), x * x]]).unwrap();
        // (M⁻¹)' = −M⁻¹ M' M⁻¹, M' = [[1, 0], [0, 2x]]
        let mv = nalgebra::Matrix2::new(2.0, 1.0, 0.5, 4.0).try_inverse().unwrap();
        let dm = -mv * nalgebra::Matrix2::new(1.0, 0.0, 0.0, 4.0) * mv;
        for i in 0..2 {
            for j in 0..2 {
                assert!((m[i][j].v - mv[(i, j)]).abs() < 1e-15 && (m[i][j].d - dm[(i, j)]).abs() < 1e-14);
            }
        }
    }
}
