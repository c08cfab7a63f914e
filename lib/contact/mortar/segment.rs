//! Segmentation of a slave face by the master cells over it, and the quadrature on
//! the segments (Puso & Laursen 2004; Popp et al. 2010, "segment-based integration").
//!
//! The mortar integrals of [`super`] run over the slave face. Their integrands, the
//! slave shape functions times the master's trace basis at the projected point, are
//! polynomials inside one master cell and only continuous across its edges; a Gauss
//! rule over the whole face is therefore not exact, and the patch test fails by the
//! quadrature error. So each slave face is cut into segments, one per master cell:
//! ```text
//! 1. the cell's four corners, carried along the cell's normal onto the slave face,
//!    give a quadrilateral in the face's parameter square [−1, 1]² (where the
//!    normal line through a corner meets the face: those lines bound the points
//!    whose foot lies in the cell, so the segment edges follow the integrand's kinks
//!    also where the faces are inclined to each other);
//! 2. the square clipped by that quadrilateral (Sutherland–Hodgman, both convex) is
//!    the segment, a convex polygon;
//! 3. a fan of triangles covers it; each gets the 7-point rule of degree 5.
//! ```
//! On flat faces with parallelogram cells the segment edges are exactly where the
//! integrand kinks and the integrand is of degree ≤ 4 in η: the quadrature is exact.
//! On curved surfaces the segmentation is a quadrature choice, accurate to the
//! curvature of the cells' edges within one face.

use nalgebra::Vector2;

use crate::spline::Vec3;

/// Point of the slave face's parameter plane η ∈ [−1, 1]².
pub type P2 = Vector2<f64>;

/// The 7-point rule of degree 5 on a triangle (Radon 1948; Dunavant 1985):
/// barycentric coordinates and weights summing to 1 (multiply by the area).
pub const TRIANGLE_7: [([f64; 3], f64); 7] = {
    // a = (6 ∓ √15)/21, weights (155 ∓ √15)/1200, √15 = 3.872983346207417
    const S15: f64 = 3.872_983_346_207_417;
    const A1: f64 = (6.0 - S15) / 21.0;
    const A2: f64 = (6.0 + S15) / 21.0;
    const W1: f64 = (155.0 - S15) / 1200.0;
    const W2: f64 = (155.0 + S15) / 1200.0;
    [
        ([1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0], 9.0 / 40.0),
        ([A1, A1, 1.0 - 2.0 * A1], W1),
        ([A1, 1.0 - 2.0 * A1, A1], W1),
        ([1.0 - 2.0 * A1, A1, A1], W1),
        ([A2, A2, 1.0 - 2.0 * A2], W2),
        ([A2, 1.0 - 2.0 * A2, A2], W2),
        ([1.0 - 2.0 * A2, A2, A2], W2),
    ]
};

/// Bilinear shape functions of the 4-node face at η (corners in cycle order
/// (−1,−1), (1,−1), (1,1), (−1,1)) and their η-derivatives.
pub fn quad4(eta: [f64; 2]) -> ([f64; 4], [[f64; 2]; 4]) {
    let [s, t] = eta;
    let c = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
    let mut n = [0.0; 4];
    let mut d = [[0.0; 2]; 4];
    for a in 0..4 {
        let [sa, ta] = c[a];
        n[a] = 0.25 * (1.0 + sa * s) * (1.0 + ta * t);
        d[a] = [0.25 * sa * (1.0 + ta * t), 0.25 * ta * (1.0 + sa * s)];
    }
    (n, d)
}

/// Position and tangents of the face at η.
pub fn face_point(x: &[Vec3; 4], eta: [f64; 2]) -> (Vec3, [Vec3; 2]) {
    let (n, d) = quad4(eta);
    let mut p = Vec3::zeros();
    let mut t = [Vec3::zeros(); 2];
    for a in 0..4 {
        p += x[a] * n[a];
        t[0] += x[a] * d[a][0];
        t[1] += x[a] * d[a][1];
    }
    (p, t)
}

/// Area element |∂x/∂η¹ × ∂x/∂η²| of the face at η.
pub fn face_jacobian(x: &[Vec3; 4], eta: [f64; 2]) -> f64 {
    let (_, t) = face_point(x, eta);
    t[0].cross(&t[1]).norm()
}

/// The face parameter η where the line `p + t d` meets the face (Newton on
/// x(η) − p − t d = 0 in (η¹, η², t), from the centre). `None` when it does not
/// converge (the line parallel to the face).
pub fn ray_bilinear(x: &[Vec3; 4], p: &Vec3, d: &Vec3) -> Option<[f64; 2]> {
    let (mut eta, mut t) = ([0.0, 0.0], 0.0);
    for _ in 0..30 {
        let (q, tg) = face_point(x, eta);
        let f = q - p - d * t;
        let jac = nalgebra::Matrix3::from_columns(&[tg[0], tg[1], -d]);
        let step = jac.try_inverse()? * f;
        eta[0] -= step[0];
        eta[1] -= step[1];
        t -= step[2];
        if !(eta[0].is_finite() && eta[1].is_finite()) || eta[0].abs() > 1e6 || eta[1].abs() > 1e6 {
            return None;
        }
        if step.norm() < 1e-14 * (1.0 + eta[0].abs() + eta[1].abs() + t.abs()) {
            return Some(eta);
        }
    }
    None
}

/// Twice the signed area of a polygon (positive: counter-clockwise).
pub fn signed_area2(poly: &[P2]) -> f64 {
    let n = poly.len();
    (0..n).map(|i| cross(&poly[i], &poly[(i + 1) % n])).sum()
}

fn cross(a: &P2, b: &P2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// Whether a counter-clockwise polygon is strictly convex (every turn to the left).
pub fn is_convex_ccw(poly: &[P2]) -> bool {
    let n = poly.len();
    (0..n).all(|i| {
        let (a, b, c) = (poly[i], poly[(i + 1) % n], poly[(i + 2) % n]);
        cross(&(b - a), &(c - b)) > 0.0
    })
}

/// Sutherland–Hodgman: `subject` clipped by the convex counter-clockwise polygon
/// `clip`, written into `out` (`scratch` is working storage).
pub fn clip_convex(subject: &[P2], clip: &[P2], out: &mut Vec<P2>, scratch: &mut Vec<P2>) {
    out.clear();
    out.extend_from_slice(subject);
    let n = clip.len();
    for e in 0..n {
        let (a, b) = (clip[e], clip[(e + 1) % n]);
        let side = |p: &P2| cross(&(b - a), &(p - a));
        std::mem::swap(out, scratch);
        out.clear();
        let m = scratch.len();
        for i in 0..m {
            let (p, q) = (scratch[i], scratch[(i + 1) % m]);
            let (sp, sq) = (side(&p), side(&q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                let t = sp / (sp - sq);
                out.push(p + (q - p) * t);
            }
        }
        if out.is_empty() {
            return;
        }
    }
}

/// The quadrature points (η, weight in η-area) of a convex polygon: a fan of
/// triangles from its first vertex, each with [`TRIANGLE_7`].
pub fn polygon_quadrature(poly: &[P2], mut push: impl FnMut([f64; 2], f64)) {
    for i in 1..poly.len().saturating_sub(1) {
        let (a, b, c) = (poly[0], poly[i], poly[i + 1]);
        let area = 0.5 * cross(&(b - a), &(c - a));
        if area <= 0.0 {
            continue;
        }
        for (l, w) in TRIANGLE_7 {
            let p = a * l[0] + b * l[1] + c * l[2];
            push([p.x, p.y], w * area);
        }
    }
}

/// The slave face's parameter square, counter-clockwise.
pub const SQUARE: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_rule_is_exact_to_degree_five() {
        // ∫_T x^a y^b over the unit triangle = a! b! / (a + b + 2)!
        let fact = |n: u32| (1..=n).map(f64::from).product::<f64>();
        for a in 0..=5u32 {
            for b in 0..=(5 - a) {
                let q: f64 = TRIANGLE_7.iter().map(|(l, w)| 0.5 * w * l[1].powi(a as i32) * l[2].powi(b as i32)).sum();
                let exact = fact(a) * fact(b) / fact(a + b + 2);
                assert!((q - exact).abs() < 1e-15, "x^{a} y^{b}: {q} vs {exact}");
            }
        }
    }

    #[test]
    fn clipping_two_squares_gives_their_overlap() {
        let sq: Vec<P2> = SQUARE.iter().map(|p| P2::new(p[0], p[1])).collect();
        let shifted: Vec<P2> = sq.iter().map(|p| p * 0.75 + P2::new(0.6, -0.3)).collect();
        let (mut out, mut scratch) = (Vec::new(), Vec::new());
        clip_convex(&sq, &shifted, &mut out, &mut scratch);
        // overlap: x ∈ [−0.15, 1], y ∈ [−1, 0.45]
        let area = 0.5 * signed_area2(&out);
        assert!((area - 1.15 * 1.45).abs() < 1e-14, "{area}");
        let mut total = 0.0;
        polygon_quadrature(&out, |_, w| total += w);
        assert!((total - area).abs() < 1e-14);
        // disjoint
        let far: Vec<P2> = sq.iter().map(|p| p + P2::new(5.0, 0.0)).collect();
        clip_convex(&sq, &far, &mut out, &mut scratch);
        assert!(out.len() < 3 || signed_area2(&out).abs() < 1e-14);
    }

    #[test]
    fn a_line_meets_the_face_at_its_parameter() {
        // a warped face, lines through its points in an oblique direction (also
        // beyond the square, where master corners lie)
        let x = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.1, 0.0), Vec3::new(2.2, 1.5, 0.2), Vec3::new(-0.1, 1.2, 0.1)];
        let d = Vec3::new(0.2, -0.1, 1.0);
        for eta in [[0.3, -0.2], [-0.9, 0.8], [1.4, -1.3]] {
            let (p, _) = face_point(&x, eta);
            let back = ray_bilinear(&x, &(p + d * 0.37), &d).unwrap();
            assert!((back[0] - eta[0]).abs() < 1e-12 && (back[1] - eta[1]).abs() < 1e-12, "{back:?} vs {eta:?}");
        }
        // a line in the face's plane does not meet it in one point
        let flat = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        assert!(ray_bilinear(&flat, &Vec3::new(0.5, 0.5, 1.0), &Vec3::x()).is_none());
    }
}
