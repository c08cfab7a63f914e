//! Slave nodes that stop at a seam (issue 26): "a slave node sliding across a seam
//! goes on without a jump in the active set, and the log names it if it cannot".
//!
//! On an atlas master a node whose foot point reaches the edge of its chart goes on
//! to the chart across it: the search finds it there, or holds it on a crease
//! (docs/theory/masters.md, "Projection"). The only edge a node may leave the master
//! through is the surface's boundary. So a node that was active at the last
//! converged increment with its foot point on an edge between two charts (smooth or
//! crease), and that a search then finds off the master, did not cross: its
//! projection failed, or it ended up beyond the boundary without passing the
//! charts between. [`SeamWatch`] remembers those nodes at every commit, checks them
//! at every search, and the solver log names the ones the converged search lost.

use super::master::Projector;
use crate::spline::atlas::EdgeKind;
use crate::spline::Projection;

/// A foot point this close (in the chart's parameter, a chart being 1 wide) to an
/// edge lies on it: a node held there by the box of the closest-point iteration
/// sits on it exactly, an orthogonal foot point within the iteration's tolerance.
const ON_EDGE: f64 = 1e-6;

/// The chart sides, in [`crate::spline::atlas::SIDES`] order.
const SIDE_NAMES: [&str; 4] = ["u = 0", "u = 1", "v = 0", "v = 1"];

/// An edge of a chart: the chart, its side (u = 0, u = 1, v = 0, v = 1) and what
/// lies across it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChartEdge {
    pub chart: usize,
    pub side: usize,
    pub kind: EdgeKind,
}

impl std::fmt::Display for ChartEdge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = match self.kind {
            EdgeKind::Smooth => "a smooth join",
            EdgeKind::Crease => "a crease",
            EdgeKind::Boundary => "the master's boundary",
        };
        write!(f, "side {} of chart {} ({kind})", SIDE_NAMES[self.side], self.chart)
    }
}

/// A node the last search lost at a seam.
#[derive(Debug, Clone, PartialEq)]
pub struct SeamLoss {
    /// Its position among the pair's slave nodes, and its mesh node.
    pub slave: usize,
    pub node: u32,
    /// The edge its foot point lay on at the last converged increment.
    pub edge: ChartEdge,
    /// What the search found instead: the chart it ended on (its projection
    /// converged, held on the master's boundary there) or none (the projection did
    /// not converge).
    pub now: Option<usize>,
}

impl SeamLoss {
    /// The log's words for it, the node named by its gmsh tag `node_tag`.
    pub fn describe(&self, node_tag: u64) -> String {
        let now = match self.now {
            Some(c) => format!("the search finds its foot point on the master's boundary (chart {c})"),
            None => "its closest-point projection did not converge".to_string(),
        };
        format!("slave node {node_tag} was in contact with its foot point on {} and did not cross it: {now}, so it is out of contact", self.edge)
    }
}

/// The active nodes on an edge between charts at the last commit, and those of them
/// the last search found off the master ([`SeamLoss`]). Empty on masters other than
/// an atlas.
#[derive(Debug, Clone, Default)]
pub struct SeamWatch {
    watched: Vec<(usize, ChartEdge)>,
    lost: Vec<SeamLoss>,
}

impl SeamWatch {
    /// After a converged increment (or the increment a restart reads back): every
    /// slave's `(active, chart, foot point)`. Watches the active nodes whose foot
    /// point lies on a chart edge joined to another chart and on no edge of the
    /// master's boundary (a node at a boundary corner may leave the master there).
    pub fn commit(&mut self, projector: &Projector, feet: impl Iterator<Item = (bool, usize, [f64; 2])>) {
        self.watched.clear();
        self.lost.clear();
        let Projector::Atlas(pr) = projector else { return };
        let atlas = pr.atlas();
        for (s, (active, chart, xi)) in feet.enumerate() {
            if !active || chart >= atlas.n_charts() || !xi.iter().all(|v| v.is_finite()) {
                continue;
            }
            let mut joined = None;
            let mut boundary = false;
            for (al, &u) in xi.iter().enumerate() {
                let side = if u <= ON_EDGE {
                    2 * al
                } else if u >= 1.0 - ON_EDGE {
                    2 * al + 1
                } else {
                    continue;
                };
                match atlas.edge(chart, side) {
                    EdgeKind::Boundary => boundary = true,
                    kind => joined = joined.or(Some(ChartEdge { chart, side, kind })),
                }
            }
            if let (Some(edge), false) = (joined, boundary) {
                self.watched.push((s, edge));
            }
        }
    }

    /// After a search: the watched nodes it finds off the master (no converged
    /// projection inside it). `slaves` are the pair's slave mesh nodes, `cells` the
    /// search's master elements (`[chart, 0]` on an atlas).
    pub fn check(&mut self, slaves: &[u32], projections: &[Projection], cells: &[Option<[usize; 2]>]) {
        self.lost.clear();
        for &(s, edge) in &self.watched {
            let p = &projections[s];
            if p.converged && p.inside {
                continue;
            }
            let now = if p.converged { cells[s].map(|c| c[0]) } else { None };
            self.lost.push(SeamLoss { slave: s, node: slaves[s], edge, now });
        }
    }

    /// The nodes the last search lost at a seam.
    pub fn lost(&self) -> &[SeamLoss] {
        &self.lost
    }

    /// How many nodes are watched (active on an edge between charts at the last
    /// commit).
    pub fn n_watched(&self) -> usize {
        self.watched.len()
    }
}
