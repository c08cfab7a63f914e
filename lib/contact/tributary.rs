//! Tributary areas A_s of the slave nodes (paper eq. 6.1): the share of the slave
//! surface each node stands for, so the nodal force t_N A_s integrates the pressure.
//!
//! ```text
//! A_s = Σ_faces ∫_face N_s dA        (bilinear N_s of the 4-node face, reference
//!                                    configuration, 2×2 Gauss: exact for a
//!                                    parallelogram, where it is a quarter of the face)
//! ```
//! The areas are taken in the reference configuration and held fixed (so t_N is a
//! nominal traction and A_s carries no derivative into the tangent). A slave given as
//! a node set has no faces: each node then has A_s = 1, and ε_N is a force per unit
//! penetration.

use nalgebra::Vector3;

use crate::fem::quadrature::{GAUSS_QUAD_2X2, QUAD4_NODES};
use crate::mesh::Mesh;

/// The tributary area of every node of `slave_nodes` (sorted) from the faces of
/// `face_set`, or 1 per node when `face_set` is `None`.
pub fn tributary_areas(mesh: &Mesh, slave_nodes: &[u32], face_set: Option<&str>) -> Vec<f64> {
    let Some(fs) = face_set.and_then(|name| mesh.face_set(name)) else {
        return vec![1.0; slave_nodes.len()];
    };
    let mut areas = vec![0.0; slave_nodes.len()];
    for &f in &fs.faces {
        let nodes = mesh.face_nodes(f);
        let x: [Vector3<f64>; 4] = std::array::from_fn(|a| Vector3::from(mesh.nodes[nodes[a] as usize]));
        for gp in GAUSS_QUAD_2X2 {
            let (mut d1, mut d2) = (Vector3::zeros(), Vector3::zeros());
            let mut n = [0.0; 4];
            for a in 0..4 {
                let [s, t] = QUAD4_NODES[a];
                n[a] = 0.25 * (1.0 + s * gp[0]) * (1.0 + t * gp[1]);
                d1 += x[a] * (0.25 * s * (1.0 + t * gp[1]));
                d2 += x[a] * (0.25 * t * (1.0 + s * gp[0]));
            }
            let da = d1.cross(&d2).norm(); // Gauss weight 1
            for a in 0..4 {
                if let Ok(i) = slave_nodes.binary_search(&nodes[a]) {
                    areas[i] += n[a] * da;
                }
            }
        }
    }
    areas
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Body, FaceSet, HexFace};

    /// Two unit-height hexes side by side, top faces 2 × 1 and 1 × 1 (a trapezoid
    /// would need the 2×2 rule; rectangles give quarters).
    #[test]
    fn quarters_of_rectangles_sum_to_the_area() {
        let xs = [0.0, 2.0, 3.0];
        let mut nodes = Vec::new();
        for z in [0.0, 1.0] {
            for y in [0.0, 1.0] {
                for &x in &xs {
                    nodes.push([x, y, z]);
                }
            }
        }
        let id = |i: u32, j: u32, k: u32| i + 3 * j + 6 * k;
        let hex = |i: u32| [id(i, 0, 0), id(i + 1, 0, 0), id(i + 1, 1, 0), id(i, 1, 0), id(i, 0, 1), id(i + 1, 0, 1), id(i + 1, 1, 1), id(i, 1, 1)];
        let mesh = Mesh {
            nodes,
            hexes: vec![hex(0), hex(1)],
            hex_body: vec![0, 0],
            bodies: vec![Body { name: "b".into(), physical_tag: 1 }],
            node_sets: vec![],
            face_sets: vec![FaceSet { name: "top".into(), physical_tag: 2, faces: vec![HexFace { element: 0, local: 1 }, HexFace { element: 1, local: 1 }], quad_tags: vec![1, 2] }],
            node_tags: (1..=12).collect(),
            element_tags: vec![1, 2],
        };
        let top: Vec<u32> = (6..12).collect();
        let a = tributary_areas(&mesh, &top, Some("top"));
        let expect = [0.5, 0.75, 0.25, 0.5, 0.75, 0.25];
        for (got, want) in a.iter().zip(expect) {
            assert!((got - want).abs() < 1e-14, "{a:?}");
        }
        assert_eq!(tributary_areas(&mesh, &top, None), vec![1.0; 6]);
    }
}
