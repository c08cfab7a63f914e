//! One contact pair as the solve will meet it at its start: every slave node projected
//! onto the master with the solve's own search ([`PairSolver::search`], eq. 2.2), the
//! initial gaps g_N (eq. 4.3), which nodes penetrate beyond the tolerance, which way
//! the master faces ([`super::orientation`]), and what the `adjust` moves.
#![allow(non_snake_case)] // paper notation: X (reference coordinates)

use nalgebra::Vector3;

use super::orientation::{behind, interior_points, master_cells_inward, Orientation};
use crate::contact::adjust::PairAdjustment;
use crate::contact::pair::{PairError, PairSolver};
use crate::contact::settings::PairSettings;
use crate::mesh::Mesh;
use crate::solver::problem::ContactDefinition;

type V3 = Vector3<f64>;

/// Why a projection failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FailReason {
    /// Newton on the closest-point conditions did not converge (nor span by span).
    NotConverged,
    /// No candidate foot point with a finite distance (a degenerate or non-finite net).
    NoFootPoint,
    /// Converged, but the master normal there is not finite (ā_1 × ā_2 = 0: a
    /// collapsed net cell).
    DegenerateNormal,
}

impl FailReason {
    pub fn word(self) -> &'static str {
        match self {
            Self::NotConverged => "not_converged",
            Self::NoFootPoint => "no_foot_point",
            Self::DegenerateNormal => "degenerate_normal",
        }
    }
    pub fn explain(self) -> &'static str {
        match self {
            Self::NotConverged => "the closest-point Newton did not converge",
            Self::NoFootPoint => "no foot point at a finite distance",
            Self::DegenerateNormal => "the master normal is not defined there (a collapsed net cell)",
        }
    }
}

/// Where a slave node projects.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Projected {
    /// On the master (inside the patch, or within the edge tolerance of it): it can
    /// come into contact.
    Inside,
    /// Its foot point lies beyond a patch edge: no contact.
    Outside,
    Failed(FailReason),
}

impl Projected {
    pub fn word(self) -> &'static str {
        match self {
            Self::Inside => "inside",
            Self::Outside => "outside",
            Self::Failed(_) => "failed",
        }
    }
    /// 1 inside, 0 outside, −1 failed.
    pub fn code(self) -> i32 {
        match self {
            Self::Inside => 1,
            Self::Outside => 0,
            Self::Failed(_) => -1,
        }
    }
}

/// The flag of a slave node: its most pressing finding.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Flag {
    Ok = 0,
    Outside = 1,
    Adjusted = 2,
    Penetrating = 3,
    Failed = 4,
    Behind = 5,
}

impl Flag {
    pub fn word(self) -> &'static str {
        match self {
            Self::Ok => "ok",
            Self::Outside => "outside",
            Self::Adjusted => "adjusted",
            Self::Penetrating => "penetrating",
            Self::Failed => "failed",
            Self::Behind => "behind",
        }
    }
}

/// One slave node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlaveRow {
    /// Node index and gmsh tag.
    pub node: u32,
    pub tag: u64,
    /// Reference position (as in the model, before any adjust).
    pub x: V3,
    pub projected: Projected,
    /// g_N (eq. 4.3); for an outside node the signed distance to its foot point on
    /// the edge; NaN when no foot point was found.
    pub g_n: f64,
    /// ξ̄ (NaN when failed) and n̄ at the foot point (NaN when not defined).
    pub xi: [f64; 2],
    pub n_bar: V3,
    /// Inside and −g_N above the pair's penetration tolerance.
    pub penetrating: bool,
    /// The orientation vote: the slave body beside it lies behind the master
    /// (`None`: did not vote).
    pub behind: Option<bool>,
    /// How far `adjust` moves it (0: not moved).
    pub adjust_move: f64,
    /// g_N the solve starts from (after every pair's adjust).
    pub g_n_adjusted: f64,
}

impl SlaveRow {
    pub fn flag(&self) -> Flag {
        if self.behind == Some(true) {
            Flag::Behind
        } else if matches!(self.projected, Projected::Failed(_)) {
            Flag::Failed
        } else if self.penetrating && self.adjust_move == 0.0 {
            Flag::Penetrating
        } else if self.adjust_move > 0.0 {
            Flag::Adjusted
        } else if self.projected == Projected::Outside {
            Flag::Outside
        } else {
            Flag::Ok
        }
    }
}

/// The check of one pair.
#[derive(Debug, Clone)]
pub struct PairCheck {
    pub name: String,
    /// "face set upper_bottom" / "node set s".
    pub slave: String,
    pub master: String,
    pub master_kind: &'static str,
    pub orders: [usize; 2],
    pub net: String,
    pub rows: Vec<SlaveRow>,
    /// h (mean master net edge), the capture distance 0.5 h and the edge tolerance.
    pub h_master: f64,
    pub capture: f64,
    pub edge_tolerance: f64,
    /// Whether ε_N (in `settings`) is the default 25 G/h.
    pub eps_n_default: bool,
    pub orientation: Orientation,
    pub allow_flipped_master: bool,
    /// The setup's adjust of this pair (None: off).
    pub adjustment: Option<PairAdjustment>,
    /// The pair's settings as the solve resolves them (penalty, enforcement,
    /// penetration tolerance, integration, friction).
    pub settings: PairSettings,
    /// Mortar: the slave faces integrated.
    pub slave_faces: usize,
    /// `transfer: balanced`: master nodes where the basis is recombined, of how many,
    /// and max |M q − f| / max f (`contact::mortar::balance`).
    pub balance: Option<(usize, usize, f64)>,
}

fn range(v: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    v.fold(None, |acc, x| match acc {
        None => Some((x, x)),
        Some((lo, hi)) => Some((lo.min(x), hi.max(x))),
    })
}

impl PairCheck {
    /// (inside, outside, failed) counts.
    pub fn counts(&self) -> (usize, usize, usize) {
        let c = |p: fn(&Projected) -> bool| self.rows.iter().filter(|r| p(&r.projected)).count();
        (c(|p| *p == Projected::Inside), c(|p| *p == Projected::Outside), c(|p| matches!(p, Projected::Failed(_))))
    }

    /// Failed projections by reason.
    pub fn failures(&self) -> Vec<(FailReason, usize)> {
        let mut out: Vec<(FailReason, usize)> = Vec::new();
        for r in &self.rows {
            if let Projected::Failed(why) = r.projected {
                match out.iter_mut().find(|(w, _)| *w == why) {
                    Some((_, n)) => *n += 1,
                    None => out.push((why, 1)),
                }
            }
        }
        out
    }

    /// The range of g_N over the nodes on the master.
    pub fn gap_range(&self) -> Option<(f64, f64)> {
        range(self.rows.iter().filter(|r| r.projected == Projected::Inside && r.g_n.is_finite()).map(|r| r.g_n))
    }

    /// The touch band 10⁻⁸ h: |g_N| within it is touching (round-off), neither open
    /// nor penetrating (`NormalLaw::touch`).
    pub fn touch(&self) -> f64 {
        1e-8 * self.h_master
    }

    /// Nodes on the master touching it (|g_N| ≤ [`Self::touch`]).
    pub fn touching(&self) -> usize {
        self.rows.iter().filter(|r| r.projected == Projected::Inside && r.g_n.abs() <= self.touch()).count()
    }

    /// The range of the penetration −g_N over the penetrating nodes on the master
    /// (g_N < −touch), and their count.
    pub fn penetration_range(&self) -> Option<(f64, f64, usize)> {
        let touch = self.touch();
        let pen: Vec<f64> = self.rows.iter().filter(|r| r.projected == Projected::Inside && r.g_n < -touch).map(|r| -r.g_n).collect();
        range(pen.iter().copied()).map(|(lo, hi)| (lo, hi, pen.len()))
    }

    /// The nodes penetrating beyond the tolerance.
    pub fn penetrating(&self) -> Vec<&SlaveRow> {
        self.rows.iter().filter(|r| r.penetrating).collect()
    }

    /// Penetrating beyond the tolerance and not removed by the adjust.
    pub fn penetrating_after_adjust(&self) -> Vec<&SlaveRow> {
        self.rows.iter().filter(|r| r.penetrating && r.adjust_move == 0.0).collect()
    }

    /// The master faces away from the slave body and the setup does not allow it.
    pub fn refused(&self) -> bool {
        self.orientation.flipped() && !self.allow_flipped_master
    }
}

/// A slave node's projection as the check reads it.
#[derive(Debug, Clone, Copy)]
struct Foot {
    projected: Projected,
    g_n: f64,
    xi: [f64; 2],
    n_bar: V3,
    x_bar: V3,
}

/// The projections of one pair's slave nodes at the coordinates `X`, as the solve's
/// search makes them.
fn project(def: &ContactDefinition, X: &[V3]) -> Result<(PairSolver, Vec<Foot>), PairError> {
    let mut solver = PairSolver::new(def, X)?;
    solver.search(|n| X[n as usize])?;
    let out = (0..solver.slaves.len())
        .map(|s| {
            let (p, sp) = solver.foot(s);
            let n_ok = sp.n_bar.iter().all(|v| v.is_finite());
            let projected = if !p.converged {
                Projected::Failed(if p.g.is_finite() { FailReason::NotConverged } else { FailReason::NoFootPoint })
            } else if !n_ok {
                Projected::Failed(FailReason::DegenerateNormal)
            } else if solver.usable(s) {
                Projected::Inside
            } else {
                Projected::Outside
            };
            let n_bar = if p.converged && n_ok { sp.n_bar } else { V3::from_element(f64::NAN) };
            Foot { projected, g_n: p.g, xi: p.xi, n_bar, x_bar: p.x_bar }
        })
        .collect();
    Ok((solver, out))
}

/// Check the pair `def` of `mesh` at its reference coordinates; `X_solve` are the
/// coordinates the solve starts from (after the adjust of every pair), `adjustment`
/// this pair's adjust.
pub fn check_pair(mesh: &Mesh, def: &ContactDefinition, X_solve: &[V3], adjustment: Option<&PairAdjustment>) -> Result<PairCheck, PairError> {
    let X: Vec<V3> = mesh.nodes.iter().map(|p| V3::new(p[0], p[1], p[2])).collect();
    let (solver, proj) = project(def, &X)?;
    let moved_any = X_solve.iter().zip(&X).any(|(a, b)| a != b);
    let after = if moved_any { Some(project(def, X_solve)?.1) } else { None };
    let pair = &def.pair;
    let interior = interior_points(&X, &mesh.hexes, &pair.slave_nodes);
    let tol = def.settings.penetration_tolerance;
    let mut orientation = Orientation::default();
    let (cells_inward, cells) = master_cells_inward(mesh, &X, pair);
    orientation.cells = cells;
    orientation.cells_inward = cells_inward;
    let mut rows = Vec::with_capacity(pair.slave_nodes.len());
    for (s, &node) in pair.slave_nodes.iter().enumerate() {
        let Foot { projected, g_n, xi, n_bar, x_bar } = proj[s];
        let vote = if projected == Projected::Inside { behind(&interior[s], &x_bar, &n_bar) } else { None };
        if let Some(b) = vote {
            orientation.voters += 1;
            orientation.behind += b as usize;
        }
        let adjust_move = adjustment.and_then(|a| a.moved.iter().find(|m| m.node == node)).map_or(0.0, |m| m.displacement.norm());
        rows.push(SlaveRow {
            node,
            tag: mesh.node_tags.get(node as usize).copied().unwrap_or(node as u64),
            x: X[node as usize],
            projected,
            g_n,
            xi: if matches!(projected, Projected::Failed(FailReason::NoFootPoint)) { [f64::NAN; 2] } else { xi },
            n_bar,
            penetrating: projected == Projected::Inside && -g_n > tol,
            behind: vote,
            adjust_move,
            g_n_adjusted: after.as_ref().map_or(g_n, |a| a[s].g_n),
        });
    }
    let slave = match pair.slave_kind {
        crate::format::sccontact::SlaveKind::FaceSet => format!("face set {}", pair.slave),
        crate::format::sccontact::SlaveKind::NodeSet => format!("node set {}", pair.slave),
    };
    Ok(PairCheck {
        name: pair.name.clone(),
        slave,
        master: pair.master.clone(),
        master_kind: pair.master_kind.name(),
        orders: pair.orders,
        net: pair.net.describe(),
        rows,
        h_master: def.h_master,
        capture: solver.capture(),
        edge_tolerance: solver.edge_tolerance(),
        eps_n_default: def.eps_n_default,
        orientation,
        allow_flipped_master: def.allow_flipped_master,
        adjustment: adjustment.cloned(),
        settings: def.settings,
        slave_faces: solver.mortar().map_or(0, |m| m.n_faces()),
        balance: solver.mortar().and_then(|m| m.balance()).map(|b| (b.region, pair.net.nodes.len(), b.defect)),
    })
}
