//! The contact element's tangent against finite differences on every master of many
//! charts: a periodic B-spline at its seam, a multi-patch B-spline next to a seam,
//! the Catmull–Clark limit surface on regular faces, next to extraordinary nodes of
//! valence 3, 5 and 6, on boundary faces and next to concave corners, and facets on
//! a free quad set.
//! Frictionless, stick and slip. The slave is re-projected on the same chart at
//! every perturbation (the element's chart is held within a Newton iterate).

use nalgebra::{DMatrix, DVector};

use super::element::{normal_contact, NormalLaw};
use super::friction::{frictional_contact, FrictionLaw};
use crate::fem::fd::{fd_jacobian, rel_err, FdStep};
use crate::spline::atlas::SheetNet;
use crate::spline::{Atlas, Mat2, SurfacePoint, Vec3};

/// Closest point on `chart` near `uv0` (Newton on (x_s − x̄)·ā_α = 0, to round-off).
fn reproject(atlas: &Atlas, chart: usize, xs: &Vec3, uv0: [f64; 2]) -> SurfacePoint {
    let mut uv = uv0;
    let mut sp = atlas.evaluate(chart, uv);
    for _ in 0..60 {
        let d = xs - sp.x_bar;
        let f = nalgebra::Vector2::new(d.dot(&sp.a_alpha[0]), d.dot(&sp.a_alpha[1]));
        let jac = Mat2::from_fn(|a, b| -sp.a_ab[(a, b)] + d.dot(&sp.a_alpha_beta[a][b]));
        let step = -jac.try_inverse().expect("regular closest-point Jacobian") * f;
        uv = [uv[0] + step[0], uv[1] + step[1]];
        sp = atlas.evaluate(chart, uv);
        if step.norm() < 1e-16 {
            break;
        }
    }
    sp
}

/// Worst relative FD error of the element on `chart` at `uv0` of `atlas` (fitted to
/// `x`), over frictionless, stick and slip laws.
fn check(name: &str, mut atlas: Atlas, x: &[Vec3], chart: usize, uv0: [f64; 2]) -> f64 {
    atlas.update(x).unwrap();
    let sp0 = atlas.evaluate(chart, uv0);
    let nodes: Vec<usize> = sp0.basis.nodes().to_vec();
    let size = sp0.a_alpha[0].norm().max(sp0.a_alpha[1].norm());
    let xs0 = sp0.x_bar - sp0.n_bar * (1e-2 * size);
    let normal = NormalLaw { lambda_n: -1.0, eps_n: 100.0, area: 0.7, touch: 0.0 };
    let back = [uv0[0] - 0.02, uv0[1] + 0.01];
    let laws: [(&str, Option<FrictionLaw>); 3] = [
        ("frictionless", None),
        ("slip", Some(FrictionLaw { mu: 0.3, eps_t: 1e3, xi_n: back, t_t_n: [0.05, -0.02], held_slip: None })),
        ("stick", Some(FrictionLaw { mu: 0.3, eps_t: 0.5, xi_n: back, t_t_n: [0.05, -0.02], held_slip: None })),
    ];
    let mut worst: f64 = 0.0;
    for (label, fr) in laws {
        let element = |xs: &Vec3, sp: &SurfacePoint, r: &mut DVector<f64>, k: &mut DMatrix<f64>| match &fr {
            None => normal_contact(xs, sp, &normal, r, k).map(|s| (s.active, false)),
            Some(f) => frictional_contact(xs, sp, &normal, f, r, k).map(|s| (s.active, s.slip)),
        };
        let (mut r, mut k) = (DVector::zeros(0), DMatrix::zeros(0, 0));
        let (active, slip) = element(&xs0, &sp0, &mut r, &mut k).unwrap();
        assert!(active, "{name}: not active");
        assert_eq!(slip, label == "slip", "{name} {label}");
        let m = 3 * (1 + nodes.len());
        let mut u = vec![0.0; m];
        for c in 0..3 {
            u[c] = xs0[c];
            for (a, &nd) in nodes.iter().enumerate() {
                u[3 * (1 + a) + c] = x[nd][c];
            }
        }
        let fd = fd_jacobian(
            |v, out| {
                let mut xp = x.to_vec();
                for (a, &nd) in nodes.iter().enumerate() {
                    xp[nd] = Vec3::new(v[3 * (1 + a)], v[3 * (1 + a) + 1], v[3 * (1 + a) + 2]);
                }
                let mut at = atlas.clone();
                at.update(&xp).unwrap();
                let xs = Vec3::new(v[0], v[1], v[2]);
                let sp = reproject(&at, chart, &xs, uv0);
                assert_eq!(sp.basis.nodes(), &nodes[..], "{name}: the perturbation changed the support");
                let (mut rr, mut kk) = (DVector::zeros(m), DMatrix::zeros(0, 0));
                element(&xs, &sp, &mut rr, &mut kk).unwrap();
                out.copy_from_slice(rr.as_slice());
            },
            &u,
            m,
            FdStep { rel_step: 1e-7, scale: 1.0 },
        );
        let e = rel_err(k.as_slice(), fd.as_slice());
        eprintln!("atlas FD {name} {label}: rel err {e:.2e} (|K| {:.3e}, {} nodes)", k.norm(), nodes.len());
        // central differences with h = 1e-7·max(|u|, 1): truncation ~h²|K'''| and
        // round-off ~ε|r|/h stay ≤ 1e-8 |K|; 1e-6 leaves two orders for the
        // re-projection's round-off (as for the single patch)
        assert!(e < 1e-6, "{name} {label}: FD rel err {e:e}");
        worst = worst.max(e);
    }
    worst
}

/// A wavy tube: `na` nodes around (radius 3), `nb` rings.
pub(crate) fn tube(na: usize, nb: usize) -> Vec<Vec3> {
    (0..na * nb)
        .map(|k| {
            let (i, j) = ((k % na) as f64, (k / na) as f64);
            let t = std::f64::consts::TAU * (i + 0.15 * j) / na as f64;
            let r = 3.0 + 0.1 * (1.3 * i + 0.7 * j).sin();
            Vec3::new(r * t.cos(), r * t.sin(), 0.8 * j + 0.05 * (2.0 * i).cos())
        })
        .collect()
}

#[test]
fn periodic_patch_at_its_seam() {
    let (na, nb) = (10, 6);
    let x = tube(na, nb);
    let nodes: Vec<u32> = (0..(na * nb) as u32).collect();
    for order in [3, 4] {
        let atlas = Atlas::splines(na * nb, &[SheetNet { a: na, b: nb, nodes: &nodes }], [order, 3], true).unwrap();
        // the last span of a row (it wraps onto nodes 0..k−2) and the first
        let last = na - 1 + na;
        check(&format!("periodic k={order} last span"), atlas.clone(), &x, last, [0.8, 0.4]);
        check(&format!("periodic k={order} first span"), atlas, &x, na, [0.15, 0.4]);
    }
}

/// An "umbrella" of `valence` sectors of m × m quads around node 0 (an extraordinary
/// node of that valence), open boundary, gently curved.
pub(crate) fn umbrella(valence: usize, m: usize) -> (Vec<Vec3>, Vec<[u32; 4]>) {
    let mut x = vec![Vec3::new(0.0, 0.0, 0.1)];
    let mut index = std::collections::HashMap::new();
    let spoke = |s: usize| {
        let t = std::f64::consts::TAU * (s % valence) as f64 / valence as f64;
        Vec3::new(t.cos(), t.sin(), 0.0)
    };
    // node (s, i, j) of sector s: i along spoke s, j along spoke s+1; (s, i, 0) is
    // spoke s, (s, 0, j) is spoke s+1 = (s+1, j, 0)
    let mut id = |s: usize, i: usize, j: usize, x: &mut Vec<Vec3>| -> u32 {
        if i == 0 && j == 0 {
            return 0;
        }
        let key = if j == 0 { (s % valence, i, 0) } else if i == 0 { ((s + 1) % valence, j, 0) } else { (s, i, j) };
        *index.entry(key).or_insert_with(|| {
            let p = spoke(s) * i as f64 + spoke(s + 1) * j as f64;
            let z = 0.1 - 0.02 * p.norm_squared() + 0.03 * (1.1 * p.x).sin() * (0.7 * p.y).cos();
            x.push(Vec3::new(p.x, p.y, z));
            x.len() as u32 - 1
        })
    };
    let mut faces = Vec::new();
    for s in 0..valence {
        for j in 0..m {
            for i in 0..m {
                faces.push([id(s, i, j, &mut x), id(s, i + 1, j, &mut x), id(s, i + 1, j + 1, &mut x), id(s, i, j + 1, &mut x)]);
            }
        }
    }
    (x, faces)
}

#[test]
fn subdivision_regular_extraordinary_and_boundary_faces() {
    for valence in [3, 5, 6] {
        let (x, faces) = umbrella(valence, 3);
        let atlas = Atlas::subdivision(x.len(), faces.clone()).unwrap();
        // face 0 of sector 0 touches the extraordinary node at (u, v) = (0, 0)
        check(&format!("subdivision valence {valence} near the node"), atlas.clone(), &x, 0, [0.06, 0.04]);
        check(&format!("subdivision valence {valence} next face"), atlas.clone(), &x, 1, [0.5, 0.3]);
        // the sector's far corner face lies on the open boundary
        check(&format!("subdivision valence {valence} boundary face"), atlas.clone(), &x, 8, [0.6, 0.7]);
        // an interior face away from the node: the regular bicubic patch
        if valence == 5 {
            check("subdivision regular face", atlas, &x, 4, [0.45, 0.55]);
        }
    }
}

/// An L (a 4 × 4 grid of faces without its 2 × 2 corner block) and a plus (the 3 × 3
/// block without its corner faces), lifted: the Catmull–Clark master next to a
/// concave corner (a boundary node in 3 faces, the corner rule), and on the plus's
/// centre face, whose four corners are such nodes (split in quarters).
#[test]
fn subdivision_next_to_concave_corners() {
    let lifted = |i: usize, j: usize| {
        let (a, b) = (i as f64, j as f64);
        Vec3::new(a + 0.05 * b, b, 0.2 * (0.7 * a).sin() + 0.15 * (0.9 * b + 0.3).cos())
    };
    let grid = |n: usize, keep: &dyn Fn(usize, usize) -> bool| {
        let x: Vec<Vec3> = (0..n * n).map(|k| lifted(k % n, k / n)).collect();
        let id = |i: usize, j: usize| (i + n * j) as u32;
        let mut faces = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                if keep(i, j) {
                    faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
                }
            }
        }
        (x, faces)
    };
    let (x, faces) = grid(5, &|i, j| i < 2 || j < 2);
    let atlas = Atlas::subdivision(x.len(), faces.clone()).unwrap();
    // face (1, 1) is face 5 and has the concave node (2, 2) at its corner 2
    assert_eq!(faces[5][2], 12);
    check("subdivision next to a concave corner", atlas.clone(), &x, 5, [0.93, 0.96]);
    check("subdivision on a face along the corner's edge", atlas, &x, 6, [0.1, 0.8]);
    let (x, faces) = grid(4, &|i, j| i == 1 || j == 1);
    let atlas = Atlas::subdivision(x.len(), faces.clone()).unwrap();
    // the centre face (1, 1) is face 2 of the plus
    assert_eq!(faces[2], [5, 6, 10, 9]);
    check("subdivision, plus centre quarter", atlas.clone(), &x, 2, [0.3, 0.45]);
    check("subdivision, plus centre near a corner", atlas, &x, 2, [0.97, 0.95]);
}

#[test]
fn multipatch_next_to_a_seam_and_free_facets() {
    // two 5 × 4 grids sharing the column i = 4 of the first = i = 0 of the second,
    // folded 30° along it
    let (a, b) = (5, 4);
    let mut x = Vec::new();
    for j in 0..b {
        for i in 0..a {
            x.push(Vec3::new(i as f64, j as f64 + 0.1 * (i as f64).sin(), 0.05 * (j as f64).cos()));
        }
    }
    let fold = 30f64.to_radians();
    let mut second = Vec::new();
    for j in 0..b {
        for i in 0..a {
            if i == 0 {
                second.push((4 + a * j) as u32);
            } else {
                x.push(Vec3::new(4.0 + i as f64 * fold.cos(), j as f64, -(i as f64) * fold.sin() + 0.03 * (i * j) as f64));
                second.push(x.len() as u32 - 1);
            }
        }
    }
    let first: Vec<u32> = (0..(a * b) as u32).collect();
    let atlas = Atlas::splines(x.len(), &[SheetNet { a, b, nodes: &first }, SheetNet { a, b, nodes: &second }], [3, 3], false).unwrap();
    // patch 0 has 3 × 2 spans: chart 2 (span (2, 0)) has the seam at u = 1
    assert_eq!(atlas.edge(2, 1), crate::spline::EdgeKind::Crease);
    check("multipatch span at the seam", atlas.clone(), &x, 2, [0.85, 0.5]);
    check("multipatch second patch", atlas, &x, 6, [0.2, 0.6]);
    let (xu, faces) = umbrella(5, 2);
    check("free facets", Atlas::facets(xu.len(), faces.clone()), &xu, 0, [0.3, 0.6]);
    check("free facets", Atlas::facets(xu.len(), faces), &xu, 3, [0.7, 0.2]);
}

/// A held knot span (the frozen search on a C⁰ patch, order 2 along ξ¹): the foot
/// point lies a fifth of a span beyond the held span's end, on its polynomial
/// continued across the knot line, where the neighbouring span meets it at a kink.
/// The element sees one smooth map there, and its tangent is that map's.
#[test]
fn held_span_beyond_a_c0_knot_line() {
    let (na, nb) = (7, 5);
    let x: Vec<Vec3> = tube(na + 3, nb).into_iter().enumerate().filter(|(k, _)| k % (na + 3) < na).map(|(_, p)| p).collect();
    let nodes: Vec<u32> = (0..(na * nb) as u32).collect();
    let atlas = Atlas::splines(na * nb, &[SheetNet { a: na, b: nb, nodes: &nodes }], [2, 3], false).unwrap();
    // chart 2 + (na − 1)·1: the third span along ξ¹ in the second row of spans
    let chart = 2 + (na - 1);
    check("order 2 held span, beyond its end", atlas.clone(), &x, chart, [1.2, 0.4]);
    check("order 2 held span, before its start", atlas, &x, chart, [-0.2, 0.6]);
}
