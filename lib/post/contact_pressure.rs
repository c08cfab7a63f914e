//! The contact pressure per slave face: the mean over the face of the traction field
//! the slave nodes' pressures interpolate,
//! ```text
//! p_f = ∫_f Σ_l N_l p_l dA₀ / ∫_f dA₀        (reference area, bilinear N_l, 2 × 2 Gauss)
//! ```
//! With mortar integration (`contact::mortar`) this is the mean of the traction field
//! t_h = Σ_s N_s t_s that the method imposes; node-to-surface gives the same average
//! of its nodal pressures. Under a uniform pressure both equal it face by face when
//! the method passes the patch test.

use crate::fem::quadrature::{GAUSS_QUAD_2X2, QUAD4_NODES};
use crate::mesh::Mesh;

/// The mean pressure of every face of `faces` (mesh node ids, cycle order), from the
/// nodal pressures `p(node)` and the reference coordinates of `mesh`.
pub fn face_pressures(mesh: &Mesh, faces: &[[u32; 4]], p: impl Fn(u32) -> f64) -> Vec<f64> {
    faces
        .iter()
        .map(|f| {
            let x: [nalgebra::Vector3<f64>; 4] = f.map(|n| nalgebra::Vector3::from(mesh.nodes[n as usize]));
            let (mut force, mut area) = (0.0, 0.0);
            for gp in GAUSS_QUAD_2X2 {
                let (mut d1, mut d2) = (nalgebra::Vector3::zeros(), nalgebra::Vector3::zeros());
                let mut value = 0.0;
                for a in 0..4 {
                    let [s, t] = QUAD4_NODES[a];
                    value += 0.25 * (1.0 + s * gp[0]) * (1.0 + t * gp[1]) * p(f[a]);
                    d1 += x[a] * (0.25 * s * (1.0 + t * gp[1]));
                    d2 += x[a] * (0.25 * t * (1.0 + s * gp[0]));
                }
                let da = d1.cross(&d2).norm(); // Gauss weight 1
                force += value * da;
                area += da;
            }
            if area > 0.0 {
                force / area
            } else {
                f64::NAN
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_linear_field_averages_to_its_centre_value_and_a_uniform_one_to_itself() {
        let mut mesh = Mesh::default();
        // a trapezoid in the plane z = 1 (non-parallelogram: the area weights matter)
        mesh.nodes = vec![[0.0, 0.0, 1.0], [2.0, 0.0, 1.0], [1.5, 1.0, 1.0], [0.5, 1.0, 1.0]];
        let faces = [[0, 1, 2, 3]];
        let uniform = face_pressures(&mesh, &faces, |_| 3.5);
        assert!((uniform[0] - 3.5).abs() < 1e-14);
        // p = x: the mean over the trapezoid is its centroid's x = 1 (symmetric about x = 1)
        let linear = face_pressures(&mesh, &faces, |n| mesh.nodes[n as usize][0]);
        assert!((linear[0] - 1.0).abs() < 1e-14, "{}", linear[0]);
        // p = y at the nodes: the bilinear field's mean is not the node average (0.5)
        // but the area-weighted one: ∫y dA / A = (1/3)(b + 2a)/(a + b)·h with a = 1, b = 2 → 4/9
        let y = face_pressures(&mesh, &faces, |n| mesh.nodes[n as usize][1]);
        assert!((y[0] - 4.0 / 9.0).abs() < 1e-14, "{}", y[0]);
    }
}
