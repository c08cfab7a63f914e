//! Segmentation of a slave face by the master cells over it, and the quadrature on
//! the segments (Puso & Laursen 2004; Popp et al. 2010, "segment-based integration").
//!
//! The mortar integrals of [`super`] run over the slave face. Their integrands, the
//! slave shape functions times the master's trace basis at the projected point, are
//! polynomials inside one master cell and only continuous across its edges; a Gauss
//! rule over the whole face is therefore not exact, and the patch test fails by the
//! quadrature error. So each slave face is cut into segments, one per master cell,
//! in the face's auxiliary plane ([`FacePlane`]: through the face's centre, normal
//! to it there):
//! ```text
//! 1. the slave face's corners are projected onto the plane: a convex quadrilateral;
//! 2. the cell's four corners are carried onto the plane along their nodes'
//!    normals ([`super::trace::Trace::node_normal`], one per net node, the same for
//!    every cell around it, so the cells' images tile the plane; those lines bound
//!    the points whose foot lies in the cell, so the segment edges follow the
//!    integrand's kinks also where the faces are inclined to each other): another
//!    quadrilateral;
//! 3. the face clipped by the cell's image (Sutherland–Hodgman, both convex) is the
//!    segment, a convex polygon;
//! 4. its vertices are taken back to the face's parameter η (the projected face's
//!    bilinear map inverted by Newton, inside the face), and a fan of triangles
//!    covers the polygon in η; each gets the 7-point rule of degree 5, weights
//!    times dA₀/dη.
//! ```
//! The segments of one face share their vertices, so in η they tile the square
//! [−1, 1]² exactly, and the slave integrals (∫ Φ_s g dA₀ with g uniform, ∫ Φ_s dA₀)
//! are exact on any flat face. On flat faces with parallelogram cells and slave
//! faces, η is affine in the plane, the segment edges are exactly where the
//! integrand kinks and the integrand is of degree ≤ 4: the quadrature is exact.
//! Elsewhere (curved surfaces, cells that are not parallelograms) the segment's
//! edges are straight in η where the cell's edges are not, a quadrature choice.
//! Clipping in the plane, not in η, keeps the images of distant cell corners sound:
//! the bilinear map of a skewed face, continued far beyond the face, folds over.
//!
//! `quadrature: knot_spans` cuts each segment further, in η, by the knot lines of a
//! smooth master ([`Pieces`]; the lines come from `super::cut_by_spans`), and
//! integrates the pieces by [`collapsed_triangle_rule`] (8 × 8 points): the smooth
//! basis is one polynomial in ξ̄ per piece, analytic in x, and the rule converges
//! exponentially (`docs/theory/mortar.md`, "The master side").

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

/// The auxiliary plane of a slave face: through its centre x(0), normal to it
/// there, with an orthonormal frame; the face's corners projected onto it.
#[derive(Debug, Clone, Copy)]
pub struct FacePlane {
    origin: Vec3,
    normal: Vec3,
    frame: [Vec3; 2],
    /// The projected corners, counter-clockwise in the frame.
    pub corners: [P2; 4],
}

impl FacePlane {
    /// `None` for a degenerate face (zero tangents at its centre).
    pub fn new(x: &[Vec3; 4]) -> Option<Self> {
        let (origin, t) = face_point(x, [0.0, 0.0]);
        let normal = t[0].cross(&t[1]).try_normalize(0.0)?;
        let e1 = t[0].try_normalize(0.0)?;
        let frame = [e1, normal.cross(&e1)];
        let corners = x.map(|c| P2::new((c - origin).dot(&frame[0]), (c - origin).dot(&frame[1])));
        Some(Self { origin, normal, frame, corners })
    }

    /// Where the line `p + t d` meets the plane; `None` when it runs (nearly)
    /// parallel to it.
    pub fn meet(&self, p: &Vec3, d: &Vec3) -> Option<P2> {
        let dn = d.dot(&self.normal);
        if dn.abs() < 1e-8 * d.norm() {
            return None;
        }
        let q = p + d * ((self.origin - p).dot(&self.normal) / dn);
        Some(P2::new((q - self.origin).dot(&self.frame[0]), (q - self.origin).dot(&self.frame[1])))
    }

    /// The projected face's map η ↦ P and its Jacobian determinant.
    fn map(&self, eta: [f64; 2]) -> (P2, nalgebra::Matrix2<f64>) {
        let (n, d) = quad4(eta);
        let mut p = P2::zeros();
        let mut jac = nalgebra::Matrix2::zeros();
        for a in 0..4 {
            p += self.corners[a] * n[a];
            for c in 0..2 {
                jac[(c, 0)] += self.corners[a][c] * d[a][0];
                jac[(c, 1)] += self.corners[a][c] * d[a][1];
            }
        }
        (p, jac)
    }

    /// |dP/dη| of the projected face at η.
    pub fn jacobian(&self, eta: [f64; 2]) -> f64 {
        self.map(eta).1.determinant().abs()
    }

    /// The face parameter η of the plane point `p` (Newton from the centre); `None`
    /// when it does not converge.
    pub fn eta(&self, p: &P2) -> Option<[f64; 2]> {
        let mut eta = [0.0, 0.0];
        for _ in 0..30 {
            let (q, jac) = self.map(eta);
            let step = jac.try_inverse()? * (q - p);
            eta[0] -= step[0];
            eta[1] -= step[1];
            if !(eta[0].abs() < 4.0 && eta[1].abs() < 4.0) {
                return None;
            }
            if step.norm() < 1e-15 * (1.0 + eta[0].abs() + eta[1].abs()) {
                return Some(eta);
            }
        }
        None
    }
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
        std::mem::swap(out, scratch);
        out.clear();
        clip_half_plane(scratch, |p| cross(&(b - a), &(p - a)), out);
        if out.is_empty() {
            return;
        }
    }
}

/// One Sutherland–Hodgman pass: appends to `out` the part of the polygon `poly`
/// where `side(p) ≥ 0` (`side` affine in `p`: the crossings are interpolated).
fn clip_half_plane(poly: &[P2], side: impl Fn(&P2) -> f64, out: &mut Vec<P2>) {
    let m = poly.len();
    for i in 0..m {
        let (p, q) = (poly[i], poly[(i + 1) % m]);
        let (sp, sq) = (side(&p), side(&q));
        if sp >= 0.0 {
            out.push(p);
        }
        if (sp >= 0.0) != (sq >= 0.0) {
            let t = sp / (sp - sq);
            out.push(p + (q - p) * t);
        }
    }
}

/// The quadrature points (η, weight in η-area) of a polygon: a fan of triangles
/// from its first vertex, each with the triangle `rule` ([`TRIANGLE_7`], or
/// [`collapsed_triangle_rule`]) and its signed area (so a polygon that is not quite
/// convex, a clipped segment taken back to η, is still integrated exactly for
/// polynomials).
pub fn polygon_quadrature(poly: &[P2], rule: &[([f64; 3], f64)], mut push: impl FnMut([f64; 2], f64)) {
    for i in 1..poly.len().saturating_sub(1) {
        let (a, b, c) = (poly[0], poly[i], poly[i + 1]);
        let area = 0.5 * cross(&(b - a), &(c - a));
        for &(l, w) in rule {
            let p = a * l[0] + b * l[1] + c * l[2];
            push([p.x, p.y], w * area);
        }
    }
}

/// Gauss–Legendre points on [0, 1] and their weights, `n` of them (degree 2n − 1):
/// the roots of P_n by Newton from Chebyshev guesses.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let kf = k as f64;
                (p0, p1) = (p1, ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf);
            }
            let p = if n == 0 { 1.0 } else if n == 1 { x } else { p1 };
            let pm = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * p - pm) / (x * x - 1.0);
            let step = p / dp;
            x -= step;
            if step.abs() < 1e-16 {
                break;
            }
        }
        out.push((0.5 * (1.0 - x), 1.0 / ((1.0 - x * x) * dp * dp)));
    }
    out.reverse();
    out
}

/// A triangle rule of `n × n` points: Gauss–Legendre in both directions of the
/// square collapsed onto the triangle (Duffy), barycentric coordinates and weights
/// summing to 1; exact for polynomials of total degree 2n − 2.
pub fn collapsed_triangle_rule(n: usize) -> Vec<([f64; 3], f64)> {
    let g = gauss_legendre(n);
    let mut rule = Vec::with_capacity(n * n);
    for &(u, wu) in &g {
        for &(v, wv) in &g {
            // (u, v) ∈ [0, 1]² ↦ λ₁ = u, λ₂ = (1 − u) v; area element (1 − u), the
            // unit triangle's area ½ divided out
            let (l1, l2) = (u, (1.0 - u) * v);
            rule.push(([1.0 - l1 - l2, l1, l2], 2.0 * wu * wv * (1.0 - u)));
        }
    }
    rule
}

/// Convex polygons in one flat list (storage reused from segment to segment): the
/// pieces of a segment cut by the master's knot lines.
#[derive(Debug, Default)]
pub struct Pieces {
    points: Vec<P2>,
    ends: Vec<usize>,
    // the other side of a split, swapped in
    next_points: Vec<P2>,
    next_ends: Vec<usize>,
}

impl Pieces {
    /// One piece: `poly`.
    pub fn reset(&mut self, poly: &[P2]) {
        self.points.clear();
        self.ends.clear();
        self.points.extend_from_slice(poly);
        self.ends.push(poly.len());
    }

    pub fn len(&self) -> usize {
        self.ends.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }

    /// Piece `i`, mutable (its vertices are taken back to η in place).
    pub fn piece_mut(&mut self, i: usize) -> &mut [P2] {
        let lo = if i == 0 { 0 } else { self.ends[i - 1] };
        &mut self.points[lo..self.ends[i]]
    }

    /// Every piece split by the line through `a` and `b`, both sides kept; pieces
    /// whose doubled area is below `min_a2` are dropped (a line along a piece's edge
    /// leaves a sliver of round-off).
    pub fn split(&mut self, a: P2, b: P2, min_a2: f64) {
        self.next_points.clear();
        self.next_ends.clear();
        let mut lo = 0;
        for &hi in &self.ends {
            let poly = &self.points[lo..hi];
            lo = hi;
            for sign in [1.0, -1.0] {
                let first = self.next_points.len();
                clip_half_plane(poly, |p| sign * cross(&(b - a), &(p - a)), &mut self.next_points);
                let part = &self.next_points[first..];
                if part.len() >= 3 && signed_area2(part) > min_a2 {
                    self.next_ends.push(self.next_points.len());
                } else {
                    self.next_points.truncate(first);
                }
            }
        }
        std::mem::swap(&mut self.points, &mut self.next_points);
        std::mem::swap(&mut self.ends, &mut self.next_ends);
    }
}

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
    fn collapsed_rules_are_exact_to_their_degree() {
        // Gauss–Legendre on [0, 1]: ∫ x^d = 1/(d + 1) for d ≤ 2n − 1
        for n in 1..=10 {
            let g = gauss_legendre(n);
            for d in 0..2 * n as i32 {
                let q: f64 = g.iter().map(|(x, w)| w * x.powi(d)).sum();
                assert!((q - 1.0 / (d as f64 + 1.0)).abs() < 1e-14, "n {n}, x^{d}: {q}");
            }
        }
        // the triangle: ∫_T x^a y^b = a! b! / (a + b + 2)! for a + b ≤ 2n − 2; and not
        // beyond (the check can fail)
        let fact = |n: u32| (1..=n).map(f64::from).product::<f64>();
        for n in [3usize, 6] {
            let rule = collapsed_triangle_rule(n);
            assert_eq!(rule.len(), n * n);
            let err = |a: u32, b: u32| {
                let q: f64 = rule.iter().map(|(l, w)| 0.5 * w * l[1].powi(a as i32) * l[2].powi(b as i32)).sum();
                (q - fact(a) * fact(b) / fact(a + b + 2)).abs() / (fact(a) * fact(b) / fact(a + b + 2))
            };
            let deg = 2 * n as u32 - 2;
            for a in 0..=deg {
                for b in 0..=(deg - a) {
                    assert!(err(a, b) < 1e-13, "n {n}: x^{a} y^{b}: {:e}", err(a, b));
                }
            }
            assert!((0..=deg + 2).any(|a| err(a, deg + 2 - a) > 1e-10), "n {n}: exact beyond its degree?");
        }
    }

    #[test]
    fn splitting_by_lines_tiles_the_polygon() {
        let sq: Vec<P2> = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]].iter().map(|p| P2::new(p[0], p[1])).collect();
        let mut pieces = Pieces::default();
        pieces.reset(&sq);
        // two oblique lines through the square, and one along its edge (a sliver: dropped)
        pieces.split(P2::new(-0.3, -2.0), P2::new(0.4, 2.0), 1e-14);
        pieces.split(P2::new(-2.0, 0.25), P2::new(2.0, 0.1), 1e-14);
        pieces.split(P2::new(1.0, -3.0), P2::new(1.0, 3.0), 1e-14);
        assert_eq!(pieces.len(), 4);
        let total: f64 = (0..pieces.len()).map(|i| 0.5 * signed_area2(pieces.piece_mut(i))).sum();
        assert!((total - 4.0).abs() < 1e-14, "{total}");
        for i in 0..pieces.len() {
            let p = pieces.piece_mut(i).to_vec();
            assert!(is_convex_ccw(&p), "{p:?}");
            // every piece on one side of each line
            let c = p.iter().sum::<P2>() / p.len() as f64;
            let side = cross(&(P2::new(0.4, 2.0) - P2::new(-0.3, -2.0)), &(c - P2::new(-0.3, -2.0)));
            assert!(p.iter().all(|v| cross(&(P2::new(0.4, 2.0) - P2::new(-0.3, -2.0)), &(v - P2::new(-0.3, -2.0))) * side >= -1e-15));
        }
    }

    #[test]
    fn clipping_two_squares_gives_their_overlap() {
        let sq: Vec<P2> = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]].iter().map(|p| P2::new(p[0], p[1])).collect();
        let shifted: Vec<P2> = sq.iter().map(|p| p * 0.75 + P2::new(0.6, -0.3)).collect();
        let (mut out, mut scratch) = (Vec::new(), Vec::new());
        clip_convex(&sq, &shifted, &mut out, &mut scratch);
        // overlap: x ∈ [−0.15, 1], y ∈ [−1, 0.45]
        let area = 0.5 * signed_area2(&out);
        assert!((area - 1.15 * 1.45).abs() < 1e-14, "{area}");
        let mut total = 0.0;
        polygon_quadrature(&out, &TRIANGLE_7, |_, w| total += w);
        assert!((total - area).abs() < 1e-14);
        // disjoint
        let far: Vec<P2> = sq.iter().map(|p| p + P2::new(5.0, 0.0)).collect();
        clip_convex(&sq, &far, &mut out, &mut scratch);
        assert!(out.len() < 3 || signed_area2(&out).abs() < 1e-14);
    }

    #[test]
    fn plane_points_map_back_to_the_face_parameter() {
        // a skewed, slightly warped face: points of the face, carried along an
        // oblique direction onto its plane, return their η (also near the corners)
        let x = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.1, 0.0), Vec3::new(2.2, 1.5, 0.05), Vec3::new(-0.1, 1.2, 0.0)];
        let plane = FacePlane::new(&x).unwrap();
        assert!(signed_area2(&plane.corners) > 0.0, "corners counter-clockwise");
        for eta in [[0.3, -0.2], [-0.9, 0.8], [0.99, 0.99]] {
            let (p, _) = face_point(&x, eta);
            // the foot of p on the plane along its normal is the projected map's point
            let q = plane.meet(&p, &plane.normal).unwrap();
            let back = plane.eta(&q).unwrap();
            let (pm, _) = plane.map(back);
            assert!((pm - q).norm() < 1e-13, "{pm:?} vs {q:?}");
            // a flat face: η itself (the warp is 0.05 at one corner: η within 5e-2)
            assert!((back[0] - eta[0]).abs() < 5e-2 && (back[1] - eta[1]).abs() < 5e-2, "{back:?} vs {eta:?}");
        }
        let flat = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.1, 0.0), Vec3::new(2.2, 1.5, 0.0), Vec3::new(-0.1, 1.2, 0.0)];
        let plane = FacePlane::new(&flat).unwrap();
        for eta in [[0.3, -0.2], [-0.9, 0.8], [1.0, -1.0]] {
            let (p, _) = face_point(&flat, eta);
            let back = plane.eta(&plane.meet(&(p + Vec3::new(0.2, -0.1, 1.0) * 0.37), &Vec3::new(0.2, -0.1, 1.0)).unwrap()).unwrap();
            assert!((back[0] - eta[0]).abs() < 1e-12 && (back[1] - eta[1]).abs() < 1e-12, "{back:?} vs {eta:?}");
        }
        // a line in the plane does not meet it in one point
        assert!(plane.meet(&Vec3::new(0.5, 0.5, 1.0), &Vec3::x()).is_none());
    }
}
