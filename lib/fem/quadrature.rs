//! Gauss–Legendre rules on the reference hexahedron [−1, 1]³ and quadrilateral [−1, 1]².
//!
//! Point order follows the node order (gmsh / VTK): Gauss point q sits at
//! (ξ_q, η_q, ζ_q) = g·(ξ_a, η_a, ζ_a) of node a = q, with g = 1/√3, so Gauss point q is
//! the one nearest local node q (handy for extrapolating Gauss values to nodes).
//! All weights are 1 (reference volume 8, reference area 4).

/// 1/√3, the abscissa of the 2-point Gauss rule.
pub const G: f64 = 0.577_350_269_189_625_8;

/// Natural coordinates of the 8 hex8 nodes in gmsh / VTK order.
pub const HEX8_NODES: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// Natural coordinates of the 4 nodes of a bilinear quad (counter-clockwise).
pub const QUAD4_NODES: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// 2×2×2 Gauss points, in node order (point q nearest node q).
pub const GAUSS_HEX_2X2X2: [[f64; 3]; 8] = {
    let mut p = [[0.0; 3]; 8];
    let mut q = 0;
    while q < 8 {
        p[q] = [G * HEX8_NODES[q][0], G * HEX8_NODES[q][1], G * HEX8_NODES[q][2]];
        q += 1;
    }
    p
};

/// Weights of [`GAUSS_HEX_2X2X2`].
pub const GAUSS_HEX_WEIGHTS: [f64; 8] = [1.0; 8];

/// 2×2 Gauss points on the quad, in node order (point q nearest node q).
pub const GAUSS_QUAD_2X2: [[f64; 2]; 4] = {
    let mut p = [[0.0; 2]; 4];
    let mut q = 0;
    while q < 4 {
        p[q] = [G * QUAD4_NODES[q][0], G * QUAD4_NODES[q][1]];
        q += 1;
    }
    p
};

/// Weights of [`GAUSS_QUAD_2X2`].
pub const GAUSS_QUAD_WEIGHTS: [f64; 4] = [1.0; 4];

#[cfg(test)]
mod tests {
    use super::*;

    /// 1D moment ∫₋₁¹ ξⁿ dξ.
    fn moment(n: i32) -> f64 {
        if n % 2 == 1 {
            0.0
        } else {
            2.0 / (n as f64 + 1.0)
        }
    }

    /// The 2-point rule integrates every monomial of degree ≤ 3 per direction exactly.
    #[test]
    fn rules_integrate_cubic_monomials_exactly() {
        for i in 0..4 {
            for j in 0..4 {
                for k in 0..4 {
                    let s: f64 = GAUSS_HEX_2X2X2
                        .iter()
                        .zip(GAUSS_HEX_WEIGHTS)
                        .map(|(p, w)| w * p[0].powi(i) * p[1].powi(j) * p[2].powi(k))
                        .sum();
                    let ex = moment(i) * moment(j) * moment(k);
                    assert!((s - ex).abs() < 1e-15, "({i},{j},{k}): {s} vs {ex}");
                }
                let s: f64 = GAUSS_QUAD_2X2
                    .iter()
                    .zip(GAUSS_QUAD_WEIGHTS)
                    .map(|(p, w)| w * p[0].powi(i) * p[1].powi(j))
                    .sum();
                assert!((s - moment(i) * moment(j)).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn gauss_point_q_is_nearest_node_q() {
        for (q, p) in GAUSS_HEX_2X2X2.iter().enumerate() {
            for d in 0..3 {
                assert_eq!(p[d].signum(), HEX8_NODES[q][d]);
            }
        }
    }
}
