//! Trilinear 8-node hexahedron.
//!
//! Node order is gmsh's = VTK_HEXAHEDRON's (see [`crate::mesh::topology`]), natural
//! coordinates (ξ_a, η_a, ζ_a) in [`HEX8_NODES`]:
//!
//! N_a(ξ, η, ζ) = ⅛ (1 + ξ_a ξ)(1 + η_a η)(1 + ζ_a ζ),
//! ∂N_a/∂ξ = ⅛ ξ_a (1 + η_a η)(1 + ζ_a ζ), and cyclically.
//!
//! The isoparametric map X(ξ) = Σ_a N_a(ξ) X_a has Jacobian matrix
//! J₀ = ∂X/∂ξ = Σ_a X_a ⊗ ∇_ξ N_a, and reference gradients ∇_X N_a = J₀⁻ᵀ ∇_ξ N_a.
//! Gradients of all 8 shape functions are stored as the rows of an 8×3 matrix
//! ([`ShapeGradients`]): row a = (∇N_a)ᵀ.
#![allow(non_snake_case)]

pub use super::quadrature::HEX8_NODES;
use nalgebra::{Matrix3, SMatrix, Vector3};

/// Gradients of the 8 shape functions, row a = (∇N_a)ᵀ (w.r.t. ξ, X or x).
pub type ShapeGradients = SMatrix<f64, 8, 3>;

/// Shape function values N_a(ξ), a = 0..8.
#[inline]
pub fn shape(xi: &[f64; 3]) -> [f64; 8] {
    let mut n = [0.0; 8];
    for (a, na) in HEX8_NODES.iter().enumerate() {
        n[a] = 0.125 * (1.0 + na[0] * xi[0]) * (1.0 + na[1] * xi[1]) * (1.0 + na[2] * xi[2]);
    }
    n
}

/// Natural derivatives ∂N_a/∂ξ_j, row a.
#[inline]
pub fn shape_derivatives(xi: &[f64; 3]) -> ShapeGradients {
    let mut d = ShapeGradients::zeros();
    for (a, na) in HEX8_NODES.iter().enumerate() {
        let f = [1.0 + na[0] * xi[0], 1.0 + na[1] * xi[1], 1.0 + na[2] * xi[2]];
        d[(a, 0)] = 0.125 * na[0] * f[1] * f[2];
        d[(a, 1)] = 0.125 * na[1] * f[0] * f[2];
        d[(a, 2)] = 0.125 * na[2] * f[0] * f[1];
    }
    d
}

/// Jacobian matrix of the isoparametric map, (J₀)_ij = ∂x_i/∂ξ_j = Σ_a x_ai ∂N_a/∂ξ_j,
/// for nodal positions `x` (reference or current).
#[inline]
pub fn jacobian_matrix(x: &[Vector3<f64>; 8], dN_dxi: &ShapeGradients) -> Matrix3<f64> {
    let mut J0 = Matrix3::zeros();
    for (a, xa) in x.iter().enumerate() {
        J0 += xa * dN_dxi.row(a);
    }
    J0
}

/// Reference gradients ∇_X N_a (rows) and det J₀ at natural point `xi`.
/// Returns `None` if det J₀ ≤ 0 (degenerate or mirrored element).
#[inline]
pub fn reference_gradients(X: &[Vector3<f64>; 8], xi: &[f64; 3]) -> Option<(ShapeGradients, f64)> {
    let dN = shape_derivatives(xi);
    let J0 = jacobian_matrix(X, &dN);
    let det = J0.determinant();
    if det.is_nan() || det <= 0.0 {
        return None;
    }
    // Row a: (∇_X N_a)ᵀ = (∇_ξ N_a)ᵀ J₀⁻¹.
    let J0inv = J0.try_inverse()?;
    Some((dN * J0inv, det))
}

/// Volume of a hexahedron (2×2×2 Gauss points, exact for the trilinear map; a
/// Gauss point with det J ≤ 0 counts nothing).
pub fn hex8_volume(x: &[Vector3<f64>; 8]) -> f64 {
    super::quadrature::GAUSS_HEX_2X2X2.iter().map(|xi| reference_gradients(x, xi).map_or(0.0, |(_, det)| det)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn volume_of_a_sheared_brick() {
        // the reference element [−1, 1]³ mapped to a 2 × 3 × 0.5 brick, sheared in x
        let x: [Vector3<f64>; 8] = std::array::from_fn(|a| {
            let [r, s, t] = HEX8_NODES[a];
            let (px, py, pz) = (1.0 + r, 1.5 * (1.0 + s), 0.25 * (1.0 + t));
            Vector3::new(px + 0.4 * pz, py, pz)
        });
        assert!((hex8_volume(&x) - 3.0).abs() < 1e-14, "{}", hex8_volume(&x));
    }

    #[test]
    fn kronecker_delta_and_partition_of_unity() {
        for (b, xb) in HEX8_NODES.iter().enumerate() {
            let n = shape(xb);
            for (a, na) in n.iter().enumerate() {
                assert_eq!(*na, if a == b { 1.0 } else { 0.0 });
            }
        }
        let xi = [0.3, -0.7, 0.45];
        assert!((shape(&xi).iter().sum::<f64>() - 1.0).abs() < 1e-15);
        let d = shape_derivatives(&xi);
        for j in 0..3 {
            assert!(d.column(j).sum().abs() < 1e-15);
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let xi = [0.3, -0.7, 0.45];
        let d = shape_derivatives(&xi);
        let h = 1e-6;
        for j in 0..3 {
            let (mut p, mut m) = (xi, xi);
            p[j] += h;
            m[j] -= h;
            let (np, nm) = (shape(&p), shape(&m));
            for a in 0..8 {
                let fd = (np[a] - nm[a]) / (2.0 * h);
                assert!((fd - d[(a, j)]).abs() < 1e-10, "a={a} j={j}");
            }
        }
    }

    /// Node order check against the mesh module: the map of the unit cube in gmsh
    /// order is the identity up to a shift, so det J₀ = 1/8 and ∇_X N_a = 2 ∇_ξ N_a.
    #[test]
    fn unit_cube_in_gmsh_order_has_positive_jacobian() {
        let X = HEX8_NODES.map(|p| Vector3::new(p[0] + 1.0, p[1] + 1.0, p[2] + 1.0) * 0.5);
        let (G, det) = reference_gradients(&X, &[0.1, 0.2, -0.3]).unwrap();
        assert!((det - 0.125).abs() < 1e-15);
        assert!((G - shape_derivatives(&[0.1, 0.2, -0.3]) * 2.0).norm() < 1e-14);
        let corners = crate::mesh::topology::corner_jacobians(&X.map(|v| [v.x, v.y, v.z]));
        assert!(corners.iter().all(|&j| j > 0.0));
    }
}
