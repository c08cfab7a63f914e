//! The seam watch of a pair ([`super::seam`]) on a two-patch master: a floor and a
//! wall meeting in a valley (a crease between the patches), each patch of two spans
//! per direction (smooth joins between its spans).

use super::definition::ContactDefinition;
use super::pair::{PairSettings, PairSolver, SlaveStatus};
use super::seam::ChartEdge;
use super::settings::{Enforcement, Integration};
use super::{MasterNet, NetShape, PatchNet};
use crate::format::sccontact::{ContactPair, MasterKind, SlaveKind};
use crate::spline::{EdgeKind, Vec3};

/// The floor z = 0 (x, y ∈ [0, 1], normal +z) and the wall x = 1 (z ∈ [0, 1],
/// normal −x), 4 × 4 nodes each, sharing the 4 nodes of the valley line (master
/// nodes 0..28, orders [3, 3]: charts 0–3 the floor's spans, 4–7 the wall's), and
/// 4 slave nodes 28..32 at `slaves`.
fn valley(slaves: [Vec3; 4]) -> (Vec<Vec3>, PairSolver) {
    let mut x: Vec<Vec3> = Vec::new();
    for j in 0..4 {
        for i in 0..4 {
            x.push(Vec3::new(i as f64 / 3.0, j as f64 / 3.0, 0.0));
        }
    }
    for j in 0..4 {
        for i in 1..4 {
            x.push(Vec3::new(1.0, j as f64 / 3.0, i as f64 / 3.0));
        }
    }
    let floor = PatchNet { a: 4, b: 4, nodes: (0..16).collect() };
    // wall (i, j) at (1, j/3, i/3): ā_1 = +z, ā_2 = +y, n̄ = −x; column 0 is the floor's column 3
    let wall = PatchNet { a: 4, b: 4, nodes: (0..16).map(|p| if p % 4 == 0 { 3 + p } else { 16 + (p % 4 - 1) + 3 * (p / 4) }).collect() };
    x.extend_from_slice(&slaves);
    let pair = ContactPair {
        name: "c".into(),
        slave_kind: SlaveKind::NodeSet,
        slave: "s".into(),
        master: "m".into(),
        master_kind: MasterKind::Bspline,
        orders: [3, 3],
        slave_nodes: (28..32).collect(),
        net: MasterNet { nodes: (0..28).collect(), shape: NetShape::Patches(vec![floor, wall]) },
    };
    let settings = PairSettings { eps_n: 1e3, enforcement: Enforcement::Penalty, penetration_tolerance: 1e-3, max_augmentations: 0, update_halvings: 0, uzawa_relaxation: 1.0, mu: 0.0, eps_t: 0.0, stabilization: 0.0, integration: Integration::Node, multipliers: Default::default(), transfer: Default::default(), quadrature: Default::default() };
    let def = ContactDefinition { pair, settings, areas: vec![0.01; 4], slave_faces: Vec::new(), h_master: 1.0 / 3.0, eps_n_default: false, adjust: None, allow_flipped_master: false };
    let solver = PairSolver::new(&def, &x).unwrap();
    (x, solver)
}

#[test]
fn a_node_lost_at_a_seam_is_named_and_one_that_crosses_is_not() {
    let (mut x, mut pair) = valley([
        // in the valley's corner: crease contact on the floor's edge u = 1 (chart 1)
        Vec3::new(1.02, 0.4, -0.02),
        // under the floor's span edge x = 0.5 (ξ¹ = ½): a smooth join
        Vec3::new(0.5, 0.4, -0.01),
        // under the middle of a span: not on an edge
        Vec3::new(0.25, 0.4, -0.01),
        // in the corner where the valley meets the floor's boundary y = 0
        Vec3::new(1.02, 0.0, -0.02),
    ]);
    let search = |pair: &mut PairSolver, x: &[Vec3]| pair.search(|n| x[n as usize]).unwrap();
    search(&mut pair, &x);
    pair.update_states().unwrap();
    assert!(pair.status.iter().all(|&s| s == SlaveStatus::Active), "{:?}", pair.status);
    pair.commit();
    assert!(pair.seam_losses().is_empty());
    // on to the next chart, along the crease and across the smooth join: no loss
    x[28].y = 0.6;
    x[29].x = 0.55;
    search(&mut pair, &x);
    assert!(pair.seam_losses().is_empty(), "{:?}", pair.seam_losses());
    assert!(pair.foot(0).0.clamped.iter().any(|&c| c), "the corner node is in crease contact");
    // off the master beyond y = 1 in one step: the two nodes on a seam are named
    x[28..].iter_mut().for_each(|p| p.y = 1.5);
    search(&mut pair, &x);
    let lost = pair.seam_losses();
    let edges: Vec<(u32, ChartEdge)> = lost.iter().map(|l| (l.node, l.edge)).collect();
    assert_eq!(
        edges,
        vec![(28, ChartEdge { chart: 1, side: 1, kind: EdgeKind::Crease }), (29, ChartEdge { chart: 0, side: 1, kind: EdgeKind::Smooth })],
        "the nodes on an edge between charts (not the interior one, nor the one at the boundary's corner)"
    );
    assert!(lost.iter().all(|l| l.now.is_some()), "{lost:?}");
    let text = lost[0].describe(1028);
    assert!(text.contains("slave node 1028") && text.contains("side u = 1 of chart 1 (a crease)") && text.contains("on the master's boundary"), "{text}");
    assert!(lost[1].describe(1029).contains("side u = 1 of chart 0 (a smooth join)"), "{}", lost[1].describe(1029));
    // back on the master: nothing lost; a restart reads the same watch back
    x[28..].iter_mut().for_each(|p| p.y = 0.4);
    search(&mut pair, &x);
    assert!(pair.seam_losses().is_empty());
    let state: Vec<[f64; 6]> = (0..4).map(|s| [0.0, 0.0, 0.0, SlaveStatus::Active.code(), pair.foot(s).0.xi[0], pair.foot(s).0.xi[1]]).collect();
    let charts = pair.charts().expect("an atlas");
    let (_, mut restarted) = valley([x[28], x[29], x[30], x[31]]);
    restarted.restore_history(&state, &[], &charts);
    x[28..].iter_mut().for_each(|p| p.y = 1.5);
    restarted.search(|n| x[n as usize]).unwrap();
    // the two nodes now in the valley's corner (28, and 31 moved off the boundary);
    // 29 moved on into its chart, 30 never was on an edge
    let nodes: Vec<u32> = restarted.seam_losses().iter().map(|l| l.node).collect();
    assert_eq!(nodes, vec![28, 31], "{:?}", restarted.seam_losses());
}
