//! A C⁰ seam between two B-spline patches under sliding (issue 26), against the
//! same surface as one patch: the contact force on a block slid across the seam.
//!
//! The master is the outer face of a 120° arc of the tube of `tube.rs` (r ∈ [2, 3],
//! 17 nodes at θ_j = −60° + 7.5° j, z ∈ [0, 1]): one open 17 × 3 grid, order 3
//! around and 2 along z. As one patch (`patch`) its middle span is centred on the
//! node at θ = 0, where the surface lies at (3/4 + cos 7.5°/4)·3 = 2.99358, inside
//! the node polygon. Split at that node's column into two 9 × 3 grids (`multipatch`),
//! the two patches' open knots interpolate the seam node: the surface there passes
//! through r = 3 with a kink of 7.5° (each patch ends along its last chord). Away from the seam (two spans and more) the two
//! surfaces are the same, since the interior spans of both see the uniform basis.
//!
//! sc-tag reads such a pair of grids, which together make one grid, as one grid
//! (the separatrices that cut a face set into grids start only at irregular nodes),
//! so `multipatch` gives one patch here: the test splits the grid's net itself.
//!
//! The block (E = 1e3, 24 elements along y over 2.4, its bottom flat) rests on the
//! single patch's top, is pressed 0.02 and slid 0.8 along y in 45 increments: the
//! contact strip stays under the top, at the seam, while the block's slave nodes
//! (0.1 apart) pass it. Facets on the same mesh are the baseline. The block spans
//! z ∈ [0.2, 0.7], where its figures were measured; a row of slave nodes on the
//! single patch's knot line z = 0.5 (ξ² is linear, C⁰ there) has its own test,
//! `a_row_of_slave_nodes_on_an_interior_knot_line_converges`.

use super::contact::{pair, solve_model};
use super::tube::{ring, slide_figures};
use crate::common::grid::{block, two_bodies};
use splinecontact::contact::{MasterNet, NetShape, PatchNet};
use splinecontact::format::sccontact::MasterKind;
use splinecontact::mesh::Mesh;

/// The arc under the block, block resting on the single patch's top.
fn model_mesh() -> Mesh {
    let angles: Vec<f64> = (0..17).map(|j| (-60.0 + 7.5 * j as f64).to_radians()).collect();
    let arc = ring(&angles, false, 2, 2, 2.0, 3.0, 1.0);
    let b = block([3, 24, 2], [0.6, 2.4, 0.5], 0.0);
    let x_top = 3.0 * (0.75 + 0.25 * (7.5f64).to_radians().cos());
    two_bodies("tube", &arc, "block", &b, [x_top, -1.63, 0.2])
}

/// The grid `net` split along its grid line through the nodes at y = 0 into two
/// grids sharing that line.
fn split_at_y0(net: &MasterNet, mesh: &Mesh) -> MasterNet {
    let NetShape::Grid { a, b } = net.shape else { panic!("one grid expected, got {}", net.describe()) };
    let y = |p: usize| mesh.nodes[net.nodes[p] as usize][1];
    let grid = |i0: usize, i1: usize, j0: usize, j1: usize| PatchNet {
        a: i1 - i0,
        b: j1 - j0,
        nodes: (j0..j1).flat_map(|j| (i0..i1).map(move |i| (i + a * j) as u32)).collect(),
    };
    let patches = if let Some(i) = (0..a).find(|&i| (0..b).all(|j| y(i + a * j).abs() < 1e-9)) {
        vec![grid(0, i + 1, 0, b), grid(i, a, 0, b)]
    } else if let Some(j) = (0..b).find(|&j| (0..a).all(|i| y(i + a * j).abs() < 1e-9)) {
        vec![grid(0, a, 0, j + 1), grid(0, a, j, b)]
    } else {
        panic!("no grid line at y = 0");
    };
    MasterNet { nodes: net.nodes.clone(), shape: NetShape::Patches(patches) }
}

fn setup() -> String {
    // press 0.02 in −x over t ∈ [0, 0.2] (5 increments), then slide 0.8 in +y over
    // t ∈ [0.2, 2] (45 increments)
    super::tube::setup()
        .replace("[[0, 0], [1, 1], [2, 1]]", "[[0, 0], [0.2, 1], [2, 1]]")
        .replace("[[0, 0], [1, 0], [2, 1]]", "[[0, 0], [0.2, 0], [2, 1]]")
        .replace("increments: {count: 42, end: 2.0}", "increments: {count: 50, end: 2.0}")
}

#[test]
fn a_seam_between_two_patches_against_one_patch() {
    let mesh = model_mesh();
    let spec = |kind| pair(kind, if kind == MasterKind::Facet { None } else { Some([3, 2]) }, "block_x0", "tube_outer");
    let one = splinecontact::stages::tag::build_model(mesh.clone(), "t", &[spec(MasterKind::Patch)]).unwrap();
    assert_eq!(one.pairs[0].net.describe(), "17 × 3 grid");
    // sc-tag: `multipatch` on one grid is one patch (no irregular node to cut from)
    let forced = splinecontact::stages::tag::build_model(mesh.clone(), "t", &[spec(MasterKind::Multipatch)]).unwrap();
    assert_eq!(forced.pairs[0].net.describe(), "1 grids (17 × 3)");
    let mut two = one.clone();
    two.pairs[0].net = split_at_y0(&one.pairs[0].net, &mesh);
    assert_eq!(two.pairs[0].net.describe(), "2 grids (9 × 3, 9 × 3)");
    let facets = splinecontact::stages::tag::build_model(mesh.clone(), "t", &[spec(MasterKind::Facet)]).unwrap();
    let mut figures = Vec::new();
    for (name, model) in [("one patch", &one), ("two patches", &two), ("facets", &facets)] {
        let (mean, spread, osc) = slide_figures(&solve_model(model, &setup()), (0.2, 2.0, 0.8), (0.1, 0.7));
        eprintln!("{name}: mean F_x {mean:.5}, max |F_x − mean|/mean {spread:.3e}, oscillation rms {:.3e} p2p {:.3e} ({} samples)", osc.rms, osc.peak_to_peak, osc.samples);
        figures.push((mean, spread, osc.rms));
    }
    // Measured (45 slide increments, ripple about a 0.2 moving average over travel
    // 0.1–0.7): one patch F_x 9.457, spread 0.50 %, ripple RMS 2.15e-3 (p2p 6.7e-3);
    // two patches 9.441, 1.27 %, 6.09e-3 (p2p 1.9e-2); facets 10.25, 0.29 %,
    // 4.5e-4. The figures come from a deterministic solve; ±10 % on the ripples
    // leaves room for round-off in the solver and the search, not for another
    // surface. The seam triples the ripple (2.8 × measured; asserted ≥ 2 ×) and
    // leaves the mean force within 0.5 % (0.17 % measured): the two surfaces differ
    // only within a span of the seam.
    let [(m1, s1, r1), (m2, s2, r2), (_, _, rf)] = [figures[0], figures[1], figures[2]];
    let near = |x: f64, pinned: f64| (x - pinned).abs() <= 0.1 * pinned;
    assert!(s1 < 0.01 && near(r1, 2.154e-3), "one patch: spread {s1}, ripple RMS {r1}");
    assert!(s2 < 0.02 && near(r2, 6.093e-3), "two patches: spread {s2}, ripple RMS {r2}");
    assert!(r2 >= 2.0 * r1, "the seam's ripple {r2} against one patch's {r1}");
    assert!((m2 - m1).abs() <= 5e-3 * m1, "mean force: two patches {m2}, one patch {m1}");
    assert!(near(rf, 4.495e-4), "facets: ripple RMS {rf}");
}

/// A row of slave nodes exactly on the single patch's interior knot line z = 0.5
/// (order 2 along z: C⁰ there): the block at z ∈ [0.25, 0.75], symmetric about that
/// line, is pressed and slid. The row stays on the knot line, where the basis
/// derivatives are one-sided and the iterates' round-off picks the span; the
/// frozen search holds each slave's span once the configuration cycles (or at
/// `search_updates`), and the solve converges without a cutback. Before, the press
/// stopped in its first increment after 10 cutbacks (the configuration cycling).
#[test]
fn a_row_of_slave_nodes_on_an_interior_knot_line_converges() {
    let angles: Vec<f64> = (0..17).map(|j| (-60.0 + 7.5 * j as f64).to_radians()).collect();
    let arc = ring(&angles, false, 2, 2, 2.0, 3.0, 1.0);
    let b = block([3, 24, 2], [0.6, 2.4, 0.5], 0.0);
    let x_top = 3.0 * (0.75 + 0.25 * (7.5f64).to_radians().cos());
    let mesh = two_bodies("tube", &arc, "block", &b, [x_top, -1.63, 0.25]);
    let spec = pair(MasterKind::Patch, Some([3, 2]), "block_x0", "tube_outer");
    let model = splinecontact::stages::tag::build_model(mesh, "t", &[spec]).unwrap();
    let r = solve_model(&model, &setup().replace("increments: {count: 50, end: 2.0}", "increments: {count: 15, end: 0.6}"));
    let cutbacks: u32 = r.increments.iter().map(|i| i.info.cutbacks).sum();
    let its: usize = r.increments.iter().map(|i| i.info.iterations.len() - 1).sum();
    eprintln!("knot-line row: {} increments, {cutbacks} cutbacks, {its} Newton corrections", r.increments.len());
    assert_eq!(cutbacks, 0);
}
