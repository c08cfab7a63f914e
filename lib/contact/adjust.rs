//! Adjust: close small initial gaps and overlaps before the first increment by moving
//! slave nodes onto the master, stress-free (Abaqus `*CONTACT PAIR, ADJUST`, ANSYS
//! `ICONT`).
//!
//! For a pair with `adjust: δ`, every slave node whose closest-point projection
//! (eq. 2.2) lies on the master (inside the patch, or within the edge tolerance of
//! it, exactly as the solve's search decides) with
//! ```text
//! 0 < |g_N| ≤ δ,    g_N = (X_s − x̄)·n̄     (eq. 4.3, reference configuration)
//! ```
//! gets the reference position of its foot point, `X_s ← x̄(ξ̄) = X_s − g_N n̄`. The
//! reference coordinates themselves change, so the moved node carries no strain and no
//! stress: the elements around it are simply a little longer or shorter than meshed.
//! Its new gap is zero up to the projection's tolerance (a flat master: round-off).
//! The projection of every slave node is taken before any is moved; pairs are
//! adjusted in the setup's order, each against the coordinates the pairs before it
//! left. A move that would invert an element (det J₀ ≤ 0 at a Gauss point) is
//! refused: the adjust distance is then larger than the elements can take.
#![allow(non_snake_case)] // paper notation: X (reference coordinates)

use nalgebra::Vector3;

use super::pair::{PairError, PairSolver};
use crate::fem::hex8::reference_gradients;
use crate::fem::quadrature::GAUSS_HEX_2X2X2;
use super::definition::ContactDefinition;

/// One slave node that the adjust moved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MovedNode {
    /// Node index (0-based, into the mesh).
    pub node: u32,
    /// Its gap g_N before the move (negative: it overlapped the master).
    pub g_n: f64,
    /// The move, X_new − X_old = −g_N n̄ (length |g_N|).
    pub displacement: Vector3<f64>,
}

/// What the adjust did to one pair.
#[derive(Debug, Clone, PartialEq)]
pub struct PairAdjustment {
    pub pair: String,
    /// The adjust distance δ.
    pub distance: f64,
    /// The moved slave nodes, in the pair's slave order.
    pub moved: Vec<MovedNode>,
}

impl PairAdjustment {
    /// The largest move (0 when nothing moved) and its node.
    pub fn largest(&self) -> Option<&MovedNode> {
        self.moved.iter().max_by(|a, b| a.g_n.abs().total_cmp(&b.g_n.abs()))
    }
}

/// The adjust could not be applied.
#[derive(Debug, thiserror::Error)]
pub enum AdjustError {
    #[error("contact pair '{pair}': adjust must be a positive length (or absent), found {distance}")]
    Distance { pair: String, distance: f64 },
    #[error(transparent)]
    Master(#[from] PairError),
    #[error(
        "contact pair '{pair}': adjust {distance:e} moves slave node {node_tag} by {moved:.4e} onto the master, which inverts hexahedron {element_tag} (det J₀ ≤ 0): give a smaller adjust, or fix the mesh so the bodies meet"
    )]
    Inverts { pair: String, distance: f64, node_tag: u64, moved: f64, element_tag: u64 },
}

/// Adjust the slave nodes of the pair `def` by up to `distance`, changing `X` (the
/// reference coordinates of all nodes). `hexes`, `node_tags`, `element_tags` name the
/// culprits of a refused move.
pub fn adjust_pair(def: &ContactDefinition, distance: f64, X: &mut [Vector3<f64>], hexes: &[[u32; 8]], node_tags: &[u64], element_tags: &[u64]) -> Result<PairAdjustment, AdjustError> {
    let pair = &def.pair.name;
    if !(distance.is_finite() && distance > 0.0) {
        return Err(AdjustError::Distance { pair: pair.clone(), distance });
    }
    let mut solver = PairSolver::new(def, X)?;
    solver.search(|n| X[n as usize])?;
    let mut moved = Vec::new();
    for (s, &node) in solver.slaves.iter().enumerate() {
        let (proj, point) = solver.foot(s);
        if !solver.usable(s) || proj.g.is_nan() || proj.g.abs() > distance || proj.g == 0.0 {
            continue;
        }
        // x_s − x̄ = g_N n̄ at the closest point (eq. 4.3): the foot point is X_s − g_N n̄
        let displacement = proj.x_bar - X[node as usize];
        debug_assert!((displacement + point.n_bar * proj.g).norm() <= 1e-6 * (proj.g.abs() + def.h_master));
        moved.push(MovedNode { node, g_n: proj.g, displacement });
    }
    let before: Vec<Vector3<f64>> = moved.iter().map(|m| X[m.node as usize]).collect();
    for m in &moved {
        X[m.node as usize] += m.displacement;
    }
    if !moved.is_empty() {
        let touched: std::collections::HashSet<u32> = moved.iter().map(|m| m.node).collect();
        for (e, hex) in hexes.iter().enumerate() {
            if !hex.iter().any(|n| touched.contains(n)) {
                continue;
            }
            let Xe: [Vector3<f64>; 8] = std::array::from_fn(|a| X[hex[a] as usize]);
            if GAUSS_HEX_2X2X2.iter().any(|q| reference_gradients(&Xe, q).is_none()) {
                let culprit = moved.iter().filter(|m| hex.contains(&m.node)).max_by(|a, b| a.g_n.abs().total_cmp(&b.g_n.abs())).copied().unwrap_or(moved[0]);
                // leave X as it was
                for (m, x) in moved.iter().zip(&before) {
                    X[m.node as usize] = *x;
                }
                return Err(AdjustError::Inverts {
                    pair: pair.clone(),
                    distance,
                    node_tag: node_tags.get(culprit.node as usize).copied().unwrap_or(culprit.node as u64),
                    moved: culprit.g_n.abs(),
                    element_tag: element_tags.get(e).copied().unwrap_or(e as u64),
                });
            }
        }
    }
    Ok(PairAdjustment { pair: pair.clone(), distance, moved })
}
