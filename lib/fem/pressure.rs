//! Follower pressure on one bilinear quadrilateral face (4 nodes, current positions).
//!
//! The face is x(ξ, η) = Σ_a N_a(ξ, η) x_a with N_a = ¼(1 + ξ_a ξ)(1 + η_a η), nodes
//! counter-clockwise seen from outside ([`crate::mesh::HEX_FACES`] order), so that
//! n da = x_,ξ × x_,η dξ dη is the outward area element. A pressure p > 0 pushes
//! against the outward normal:
//!
//! f_a = −∫ p N_a n da = −p Σ_q w_q N_a(ξ_q) (x_,ξ × x_,η)(ξ_q)   (2×2 Gauss).
//!
//! **Load stiffness.** With x_,ξ = Σ_b N_b,ξ x_b, a variation δx_b changes the area
//! vector by N_b,ξ δx_b × x_,η + x_,ξ × N_b,η δx_b = (N_b,η \[x_,ξ\]_× − N_b,ξ \[x_,η\]_×) δx_b,
//! with \[v\]_× w = v × w. Hence
//!
//! K_ab = ∂f_a/∂x_b = −p Σ_q w_q N_a (N_b,η \[x_,ξ\]_× − N_b,ξ \[x_,η\]_×),
//!
//! non-symmetric for one face (its skew part cancels only over a closed surface, or on
//! a loaded boundary whose edges are fixed). As f is an *external* force, the Newton
//! tangent of the residual f_int − f_ext receives −K.
//!
//! The 2×2 rule is exact here: n da is quadratic per direction, N_a n da cubic.
//! Dofs are node-major, (x_0x, x_0y, x_0z, x_1x, …).
#![allow(non_snake_case)]

use super::quadrature::{GAUSS_QUAD_2X2, GAUSS_QUAD_WEIGHTS, QUAD4_NODES};
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Face force vector (12 dofs).
pub type FaceVector = SVector<f64, 12>;
/// Face load stiffness (12 × 12).
pub type FaceMatrix = SMatrix<f64, 12, 12>;

/// Bilinear values N_a and derivatives (N_a,ξ, N_a,η) at (ξ, η).
#[inline]
pub fn quad4_shape(xi: &[f64; 2]) -> ([f64; 4], [[f64; 2]; 4]) {
    let mut n = [0.0; 4];
    let mut d = [[0.0; 2]; 4];
    for (a, na) in QUAD4_NODES.iter().enumerate() {
        let (s, t) = (1.0 + na[0] * xi[0], 1.0 + na[1] * xi[1]);
        n[a] = 0.25 * s * t;
        d[a] = [0.25 * na[0] * t, 0.25 * na[1] * s];
    }
    (n, d)
}

/// Tangent vectors (x_,ξ, x_,η) of the face at (ξ, η).
#[inline]
fn tangents(x: &[Vector3<f64>; 4], d: &[[f64; 2]; 4]) -> (Vector3<f64>, Vector3<f64>) {
    let mut t = (Vector3::zeros(), Vector3::zeros());
    for a in 0..4 {
        t.0 += x[a] * d[a][0];
        t.1 += x[a] * d[a][1];
    }
    t
}

/// Nodal forces f_a = −∫ p N_a n da of a follower pressure `p` on the current face `x`.
pub fn follower_pressure_force(x: &[Vector3<f64>; 4], p: f64) -> FaceVector {
    let mut f = FaceVector::zeros();
    for (xi, w) in GAUSS_QUAD_2X2.iter().zip(GAUSS_QUAD_WEIGHTS) {
        let (n, d) = quad4_shape(xi);
        let (x_xi, x_eta) = tangents(x, &d);
        let da = x_xi.cross(&x_eta) * (-p * w);
        for (a, na) in n.iter().enumerate() {
            f.fixed_rows_mut::<3>(3 * a).axpy(*na, &da, 1.0);
        }
    }
    f
}

/// Nodal forces `f` and load stiffness `k` = ∂f/∂x (both overwritten) of a follower
/// pressure `p` on the current face `x`.
pub fn follower_pressure_force_stiffness(x: &[Vector3<f64>; 4], p: f64, f: &mut FaceVector, k: &mut FaceMatrix) {
    f.fill(0.0);
    k.fill(0.0);
    for (xi, w) in GAUSS_QUAD_2X2.iter().zip(GAUSS_QUAD_WEIGHTS) {
        let (n, d) = quad4_shape(xi);
        let (x_xi, x_eta) = tangents(x, &d);
        let da = x_xi.cross(&x_eta) * (-p * w);
        let (S_xi, S_eta) = (x_xi.cross_matrix(), x_eta.cross_matrix());
        for (a, na) in n.iter().enumerate() {
            f.fixed_rows_mut::<3>(3 * a).axpy(*na, &da, 1.0);
            for (b, db) in d.iter().enumerate() {
                let m: Matrix3<f64> = (S_xi * db[1] - S_eta * db[0]) * (-p * w * na);
                let mut block = k.fixed_view_mut::<3, 3>(3 * a, 3 * b);
                block += m;
            }
        }
    }
}
