//! Finite-strain kinematics at a point of a hex8.
//!
//! | symbol | definition | Rust |
//! |--------|------------|------|
//! | F | F = I + ∂u/∂X = I + Σ_a u_a ⊗ ∇_X N_a | [`deformation_gradient`] |
//! | J | J = det F = dv/dV | [`volume_ratio`] |
//! | b | b = F Fᵀ (left Cauchy–Green, eq. 3.3) | [`left_cauchy_green`] |
//! | C | C = Fᵀ F (right Cauchy–Green) | [`right_cauchy_green`] |
//! | ∇_x N_a | F⁻ᵀ ∇_X N_a (spatial gradients) | [`spatial_gradients`] |
#![allow(non_snake_case)]

use super::hex8::ShapeGradients;
use nalgebra::{Matrix3, Vector3};

/// F = I + Σ_a u_a ⊗ ∇_X N_a, with `G` the reference gradients (row a = (∇_X N_a)ᵀ).
#[inline]
pub fn deformation_gradient(G: &ShapeGradients, u: &[Vector3<f64>; 8]) -> Matrix3<f64> {
    let mut F = Matrix3::identity();
    for (a, ua) in u.iter().enumerate() {
        F += ua * G.row(a);
    }
    F
}

/// J = det F.
#[inline]
pub fn volume_ratio(F: &Matrix3<f64>) -> f64 {
    F.determinant()
}

/// b = F Fᵀ.
#[inline]
pub fn left_cauchy_green(F: &Matrix3<f64>) -> Matrix3<f64> {
    F * F.transpose()
}

/// C = Fᵀ F.
#[inline]
pub fn right_cauchy_green(F: &Matrix3<f64>) -> Matrix3<f64> {
    F.transpose() * F
}

/// Spatial gradients ∇_x N_a = F⁻ᵀ ∇_X N_a, i.e. rows G F⁻¹.
#[inline]
pub fn spatial_gradients(G: &ShapeGradients, Finv: &Matrix3<f64>) -> ShapeGradients {
    G * Finv
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::hex8::{reference_gradients, HEX8_NODES};

    #[test]
    fn affine_field_gives_its_gradient() {
        let X = HEX8_NODES.map(|p| Vector3::new(p[0] + 0.1 * p[1] * p[2], p[1], 1.3 * p[2] + 0.2 * p[0]));
        let A = Matrix3::new(1.2, 0.1, -0.3, 0.05, 0.9, 0.2, 0.0, -0.4, 1.1);
        let u = X.map(|x| (A - Matrix3::identity()) * x + Vector3::new(0.3, -1.0, 2.0));
        let (G, _) = reference_gradients(&X, &[0.2, -0.5, 0.7]).unwrap();
        let F = deformation_gradient(&G, &u);
        assert!((F - A).norm() < 1e-14);
        assert!((volume_ratio(&F) - A.determinant()).abs() < 1e-14);
        assert!((left_cauchy_green(&F) - A * A.transpose()).norm() < 1e-14);
        assert!((right_cauchy_green(&F) - A.transpose() * A).norm() < 1e-14);
        // Spatial gradients are the gradients w.r.t. the current positions.
        let x: [Vector3<f64>; 8] = std::array::from_fn(|a| X[a] + u[a]);
        let (g_direct, _) = reference_gradients(&x, &[0.2, -0.5, 0.7]).unwrap();
        let g = spatial_gradients(&G, &F.try_inverse().unwrap());
        assert!((g - g_direct).norm() < 1e-13);
    }
}
