//! Hex8 topology: the local faces of the 8-node hexahedron and the signed volume
//! test used to detect inverted elements.
//!
//! Node order is gmsh's (identical to VTK_HEXAHEDRON):
//! ```text
//!        7-------6
//!       /|      /|        ζ
//!      4-------5 |        |  η
//!      | 3-----|-2        | /
//!      |/      |/         |/
//!      0-------1          +---- ξ
//! ```


/// Local faces of the hexahedron, each listed so that the right-hand rule gives the
/// outward normal: ζ=-1, ζ=+1, η=-1, ξ=+1, η=+1, ξ=-1.
pub const HEX_FACES: [[usize; 4]; 6] = [
    [0, 3, 2, 1],
    [4, 5, 6, 7],
    [0, 1, 5, 4],
    [1, 2, 6, 5],
    [2, 3, 7, 6],
    [3, 0, 4, 7],
];

/// Global node indices of local face `local` of `hex`, outward-oriented.
pub fn hex_face_nodes(hex: &[u32; 8], local: usize) -> [u32; 4] {
    HEX_FACES[local].map(|a| hex[a])
}

/// Local face of `hex` whose node set equals `quad` (in any order), if any.
pub fn find_local_face(hex: &[u32; 8], quad: &[u32; 4]) -> Option<usize> {
    let mut q = *quad;
    q.sort_unstable();
    (0..6).find(|&f| {
        let mut h = hex_face_nodes(hex, f);
        h.sort_unstable();
        h == q
    })
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn triple(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// Jacobian determinant of the trilinear map at each of the 8 corners
/// (det of the three edge vectors leaving the corner in ξ, η, ζ order).
/// All positive for a valid hexahedron in gmsh order; all negative for a mirrored one.
pub fn corner_jacobians(x: &[[f64; 3]; 8]) -> [f64; 8] {
    // For each corner: neighbours along +ξ, +η, +ζ directions (in the corner's own frame).
    const NB: [[usize; 3]; 8] = [
        [1, 3, 4],
        [2, 0, 5],
        [3, 1, 6],
        [0, 2, 7],
        [7, 5, 0],
        [4, 6, 1],
        [5, 7, 2],
        [6, 4, 3],
    ];
    let mut out = [0.0; 8];
    for (c, nb) in NB.iter().enumerate() {
        out[c] = triple(sub(x[nb[0]], x[c]), sub(x[nb[1]], x[c]), sub(x[nb[2]], x[c]));
    }
    out
}

/// Reorder a mirrored hexahedron (all corner Jacobians negative) into a valid one by
/// swapping its bottom and top faces.
pub fn flip_hex(hex: &[u32; 8]) -> [u32; 8] {
    [hex[4], hex[5], hex[6], hex[7], hex[0], hex[1], hex[2], hex[3]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_cube() -> [[f64; 3]; 8] {
        [
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [1., 0., 1.],
            [1., 1., 1.],
            [0., 1., 1.],
        ]
    }

    #[test]
    fn unit_cube_corner_jacobians_are_one() {
        for j in corner_jacobians(&unit_cube()) {
            assert!((j - 1.0).abs() < 1e-15, "{j}");
        }
    }

    #[test]
    fn flipped_cube_is_negative_and_flip_restores_it() {
        let x = unit_cube();
        let h: [u32; 8] = [0, 1, 2, 3, 4, 5, 6, 7];
        let f = flip_hex(&h);
        let xf = f.map(|n| x[n as usize]);
        assert!(corner_jacobians(&xf).iter().all(|&j| j < 0.0));
        let back = flip_hex(&f).map(|n| x[n as usize]);
        assert!(corner_jacobians(&back).iter().all(|&j| j > 0.0));
    }

    #[test]
    fn faces_point_outward() {
        let x = unit_cube();
        let centre = [0.5, 0.5, 0.5];
        let h: [u32; 8] = [0, 1, 2, 3, 4, 5, 6, 7];
        for f in 0..6 {
            let n = hex_face_nodes(&h, f).map(|i| x[i as usize]);
            let a = sub(n[1], n[0]);
            let b = sub(n[3], n[0]);
            let normal = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
            let out = sub(n[0], centre);
            let d = normal[0] * out[0] + normal[1] * out[1] + normal[2] * out[2];
            assert!(d > 0.0, "face {f} points inward");
        }
    }

    #[test]
    fn find_local_face_any_order() {
        let h: [u32; 8] = [10, 11, 12, 13, 14, 15, 16, 17];
        assert_eq!(find_local_face(&h, &[15, 11, 12, 16]), Some(3));
        assert_eq!(find_local_face(&h, &[10, 11, 12, 17]), None);
    }
}
