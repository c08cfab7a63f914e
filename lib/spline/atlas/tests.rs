//! The atlas reproduces the single patch and the facet net where they apply, closes
//! smoothly over a periodic seam, and meets in creases at seams between patches.

use super::*;
use crate::spline::projection::{bench_points, wavy_square_net};
use crate::spline::{BSplineProjector, FacetProjector, FacetSurface};

fn grid_faces(na: usize, nb: usize) -> Vec<[u32; 4]> {
    let id = |i: usize, j: usize| (i + na * j) as u32;
    (0..nb - 1).flat_map(|j| (0..na - 1).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])).collect()
}

/// Σ_k Q_k x_k = x̄, Σ Q_{k,α} x_k = ā_α, Σ Q_{k,αβ} x_k = ā_{α,β}: the basis is
/// numbered and scaled like the geometry.
#[allow(clippy::needless_range_loop)] // α, β are the tensor indices
fn basis_reproduces_geometry(sp: &SurfacePoint, x: &[Vec3]) {
    let b = &sp.basis;
    let mut p = Vec3::zeros();
    let mut a = [Vec3::zeros(); 2];
    let mut aa = [[Vec3::zeros(); 2]; 2];
    for (k, &n) in b.nodes().iter().enumerate() {
        p += x[n] * b.q()[k];
        for al in 0..2 {
            a[al] += x[n] * b.q_alpha()[k][al];
            for be in 0..2 {
                aa[al][be] += x[n] * b.q_alpha_beta()[k][al][be];
            }
        }
    }
    let scale = 1.0 + sp.x_bar.norm();
    assert!((p - sp.x_bar).norm() < 1e-12 * scale, "x̄ {p} vs {}", sp.x_bar);
    for al in 0..2 {
        assert!((a[al] - sp.a_alpha[al]).norm() < 1e-11 * scale, "ā_{al}");
        for be in 0..2 {
            assert!((aa[al][be] - sp.a_alpha_beta[al][be]).norm() < 1e-10 * scale, "ā_{al},{be}");
        }
    }
}

#[test]
fn facet_atlas_matches_the_facet_net() {
    let n = 6;
    let x = wavy_square_net(n);
    let ap = AtlasProjector::new(Atlas::facets(n * n, grid_faces(n, n)), &x).unwrap();
    let fp = FacetProjector::new(FacetSurface::new(n, n).unwrap(), &x).unwrap();
    let mut compared = 0;
    for p in bench_points(n, 300) {
        let (a, chart) = ap.project(&p);
        let b = fp.project(&p);
        assert!(a.converged && b.converged);
        // same foot point, gap, inside flag and crease state
        assert!((a.x_bar - b.x_bar).norm() < 1e-9, "{p}: {a:?} vs {b:?}");
        assert!((a.g - b.g).abs() < 1e-9, "{p}: {} vs {}", a.g, b.g);
        assert_eq!((a.inside, a.clamped.iter().any(|&c| c)), (b.inside, b.clamped.iter().any(|&c| c)), "{p}");
        basis_reproduces_geometry(&ap.evaluate(chart, a.xi), &x);
        compared += 1;
    }
    assert_eq!(compared, 300);
}

#[test]
fn one_open_patch_matches_the_patch_projector() {
    let n = 7;
    let x = wavy_square_net(n);
    let nodes: Vec<u32> = (0..(n * n) as u32).collect();
    for order in [2, 3, 4] {
        let atlas = Atlas::splines(n * n, &[SheetNet { a: n, b: n, nodes: &nodes }], [order, order], false).unwrap();
        let ap = AtlasProjector::new(atlas, &x).unwrap();
        let bp = BSplineProjector::new(BSplinePatch::new(n, n, order, order).unwrap(), &x).unwrap();
        let mut inside = 0;
        for p in bench_points(n, 200) {
            let (a, chart) = ap.project(&p);
            let b = bp.project(&p);
            if !(a.converged && b.converged && a.inside && b.inside) || order == 2 {
                continue;
            }
            inside += 1;
            assert!((a.x_bar - b.x_bar).norm() < 1e-9, "order {order}, {p}: {a:?} vs {b:?}");
            assert!((a.g - b.g).abs() < 1e-9);
            let sa = ap.evaluate(chart, a.xi);
            let sb = bp.evaluate(b.xi);
            assert!((sa.n_bar - sb.n_bar).norm() < 1e-9, "order {order}: n̄");
            // a chart is one knot span of width h = 1/(n − k + 1): b̄_αβ scales by h²
            let h = 1.0 / (n - order + 1) as f64;
            assert!((sa.b_ab - sb.b_ab * (h * h)).norm() < 1e-9 * (1.0 + sa.b_ab.norm()), "order {order}: b̄_αβ {} vs {}", sa.b_ab, sb.b_ab * (h * h));
            basis_reproduces_geometry(&sa, &x);
        }
        if order > 2 {
            assert!(inside > 150, "order {order}: {inside} points compared");
        }
    }
}

/// `na` nodes around a unit circle, `nb` rings along z.
fn tube(na: usize, nb: usize) -> Vec<Vec3> {
    (0..na * nb)
        .map(|k| {
            let t = std::f64::consts::TAU * (k % na) as f64 / na as f64;
            Vec3::new(t.cos(), t.sin(), (k / na) as f64 * 0.5)
        })
        .collect()
}

#[test]
fn a_periodic_patch_is_smooth_across_its_seam() {
    let (na, nb) = (8, 4);
    let x = tube(na, nb);
    let nodes: Vec<u32> = (0..(na * nb) as u32).collect();
    let atlas = Atlas::splines(na * nb, &[SheetNet { a: na, b: nb, nodes: &nodes }], [4, 3], true).unwrap();
    assert_eq!(atlas.n_charts(), 8 * 2);
    let ap = AtlasProjector::new(atlas, &x).unwrap();
    let at = ap.atlas();
    for t in 0..2 {
        let (last, first) = (7 + 8 * t, 8 * t);
        assert_eq!((at.edge(first, 0), at.edge(last, 1)), (EdgeKind::Smooth, EdgeKind::Smooth));
        for v in [0.0, 0.3, 1.0] {
            // C² across the seam: position, first and second derivatives agree
            let (a, b) = (at.jet(last, [1.0, v]), at.jet(first, [0.0, v]));
            assert!((a.x - b.x).norm() < 1e-14 && (a.a[0] - b.a[0]).norm() < 1e-13 && (a.aa[0][0] - b.aa[0][0]).norm() < 1e-12, "{a:?} vs {b:?}");
            basis_reproduces_geometry(&at.evaluate(first, [0.0, v]), &x);
        }
    }
    // The periodic cubic of a regular 8-gon is a near-circle inside it: radius
    // (2 + cos 45°... ) — at a node (4 + 2 cos(π/4))/6 = 0.9024, mid-span 0.9007
    // (by the uniform cubic B-spline weights 1/6, 4/6, 1/6 and 1/48, 23/48, 23/48, 1/48).
    let r_node = (4.0 + 2.0 * (std::f64::consts::PI / 4.0).cos()) / 6.0;
    for k in 0..16 {
        let th = std::f64::consts::TAU * k as f64 / 16.0;
        let p = Vec3::new(1.5 * th.cos(), 1.5 * th.sin(), 0.7);
        let (pr, _) = ap.project(&p);
        assert!(pr.converged && pr.inside && pr.clamped == [false; 2], "θ {th}: {pr:?}");
        let r = (pr.x_bar.x.powi(2) + pr.x_bar.y.powi(2)).sqrt();
        // by symmetry the foot point lies on the ray through p
        assert!((pr.x_bar.y.atan2(pr.x_bar.x) - p.y.atan2(p.x)).abs() < 1e-9, "θ {th}");
        assert!((pr.g - (1.5 - r)).abs() < 1e-12 && (r - r_node).abs() < 2e-3, "θ {th}: r {r}");
        if k % 2 == 0 {
            assert!((r - r_node).abs() < 1e-12, "node radius {r} vs {r_node}");
        }
    }
}

/// Three patches on the faces x = n, y = n, z = n of a cube corner.
fn box_corner(n: usize) -> (Vec<Vec3>, Vec<Vec<u32>>) {
    let mut x: Vec<Vec3> = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut nets = Vec::new();
    for (ax, (u, v)) in [(0usize, (1usize, 2usize)), (1, (2, 0)), (2, (0, 1))] {
        let mut net = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let mut p = [0usize; 3];
                p[ax] = n;
                p[u] = i;
                p[v] = j;
                let id = *index.entry(p).or_insert_with(|| {
                    x.push(Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
                    x.len() as u32 - 1
                });
                net.push(id);
            }
        }
        nets.push(net);
    }
    (x, nets)
}

#[test]
fn seams_between_patches_are_creases() {
    let n = 3;
    let (x, nets) = box_corner(n);
    let sheets: Vec<SheetNet> = nets.iter().map(|nodes| SheetNet { a: n + 1, b: n + 1, nodes }).collect();
    let atlas = Atlas::splines(x.len(), &sheets, [3, 3], false).unwrap();
    // each patch: 2 × 2 spans; the sides at i = n and j = n are seams
    assert_eq!(atlas.n_charts(), 12);
    for p in 0..3 {
        let last = 4 * p + 3;
        assert_eq!([atlas.edge(last, 1), atlas.edge(last, 3), atlas.edge(4 * p, 0), atlas.edge(4 * p, 2)], [EdgeKind::Crease, EdgeKind::Crease, EdgeKind::Boundary, EdgeKind::Boundary]);
        assert_eq!(atlas.edge(4 * p, 1), EdgeKind::Smooth);
    }
    let ap = AtlasProjector::new(atlas, &x).unwrap();
    // Beyond the corner: crease contact with the corner point (open knots interpolate it).
    let corner = Vec3::repeat(n as f64);
    let p = corner + Vec3::new(0.3, 0.2, 0.25);
    let (pr, chart) = ap.project(&p);
    assert!(pr.converged && pr.inside && pr.clamped == [true, true], "{pr:?}");
    assert!((pr.x_bar - corner).norm() < 1e-10 && (pr.g - (p - corner).norm()).abs() < 1e-10);
    basis_reproduces_geometry(&ap.evaluate(chart, pr.xi), &x);
    // Above the middle of a face: an orthogonal projection, no crease.
    let (pr, _) = ap.project(&Vec3::new(n as f64 + 0.4, 1.1, 1.3));
    assert!(pr.inside && pr.clamped == [false; 2] && (pr.g - 0.4).abs() < 1e-12, "{pr:?}");
}

#[test]
fn friction_history_moves_between_charts() {
    let (na, nb) = (8, 4);
    let x = tube(na, nb);
    let nodes: Vec<u32> = (0..(na * nb) as u32).collect();
    let ap = AtlasProjector::new(Atlas::splines(na * nb, &[SheetNet { a: na, b: nb, nodes: &nodes }], [3, 3], true).unwrap(), &x).unwrap();
    let at = ap.atlas();
    // across the seam: u = 0.9 on the last span is u = −0.1 on the first
    let uv = ap.transfer(7, [0.9, 0.4], 0);
    assert!((uv[0] + 0.1).abs() < 1e-12 && (uv[1] - 0.4).abs() < 1e-12, "{uv:?}");
    // the same patch parameter (the point itself differs by the continuation of span
    // 0's polynomial back over 0.1 span: a jump of the quadratic's second derivative)
    let (pa, xa) = at.patch_parameter(7, [0.9, 0.4]).unwrap();
    let (pb, xb) = at.patch_parameter(0, uv).unwrap();
    assert!(pa == pb && ((xa[0] - xb[0]).abs() - 1.0).abs() < 1e-12 && (xa[1] - xb[1]).abs() < 1e-12);
    assert!((at.jet(7, [0.9, 0.4]).x - at.jet(0, uv).x).norm() < 1e-2);
    // facets: through the continued bilinear map
    let m = 5;
    let xf = wavy_square_net(m);
    let fp = AtlasProjector::new(Atlas::facets(m * m, grid_faces(m, m)), &xf).unwrap();
    let uv = fp.transfer(0, [0.8, 0.5], 1);
    // (the closest point on the neighbour's continued plane: the same place up to the
    // kink between the two facets of the wavy net)
    assert!((uv[0] + 0.2).abs() < 2e-3 && (uv[1] - 0.5).abs() < 1e-3, "{uv:?}");
}

/// What a projection costs on each master over the same 100 × 100 wavy net, one
/// thread, the best of three rounds: the atlas (chart tree) on facets, order-3
/// splines and the Catmull–Clark surface, and the patch and facet projectors (span
/// tree). `cargo test --release --lib bench_projection_per_master -- --ignored --nocapture`
#[test]
#[ignore = "benchmark: run with --release --ignored --nocapture"]
fn bench_projection_per_master() {
    let n = 100;
    let x = wavy_square_net(n);
    let nodes: Vec<u32> = (0..(n * n) as u32).collect();
    let pts = bench_points(n, 100_000);
    let time = |name: &str, project: &dyn Fn(&Vec3) -> f64| {
        let best = (0..3)
            .map(|_| {
                let t0 = std::time::Instant::now();
                let g: f64 = pts.iter().map(project).sum();
                std::hint::black_box(g);
                t0.elapsed()
            })
            .min()
            .unwrap();
        println!("{name}: {:.3} µs per point", best.as_secs_f64() * 1e6 / pts.len() as f64);
    };
    let facets = AtlasProjector::new(Atlas::facets(n * n, grid_faces(n, n)), &x).unwrap();
    time("atlas, facets", &|p| facets.project(p).0.g);
    let splines = AtlasProjector::new(Atlas::splines(n * n, &[SheetNet { a: n, b: n, nodes: &nodes }], [3, 3], false).unwrap(), &x).unwrap();
    time("atlas, splines [3, 3]", &|p| splines.project(p).0.g);
    let cc = AtlasProjector::new(Atlas::subdivision(n * n, grid_faces(n, n)).unwrap(), &x).unwrap();
    time("atlas, subdivision", &|p| cc.project(p).0.g);
    let patch = BSplineProjector::new(BSplinePatch::new(n, n, 3, 3).unwrap(), &x).unwrap();
    time("patch [3, 3]", &|p| patch.project(p).g);
    let facet_net = FacetProjector::new(FacetSurface::new(n, n).unwrap(), &x).unwrap();
    time("facet net", &|p| facet_net.project(p).g);
    // the walks alone, bounded by the nearest box and a quarter of an edge
    let faces = grid_faces(n, n);
    let chart_tree = super::tree::ChartTree::new(faces.len(), &|c| &faces[c][..], &x, 0.0);
    time("chart tree walk", &|p| chart_tree.query(p, f64::INFINITY, |_, d2| d2 + 0.25));
    let mut span_tree = crate::spline::SpanTree::new([n - 1, n - 1], [2, 2]);
    span_tree.refit(&x);
    time("span tree walk", &|p| span_tree.query(p, f64::INFINITY, |_, d2| d2 + 0.25));
}
