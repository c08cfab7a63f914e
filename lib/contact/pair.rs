//! One contact pair during the solve: the master surface following its body, the
//! closest-point projection of every slave node onto it (eq. 2.2), the multipliers
//! λ_N of the augmented Lagrangian and their Uzawa update (sec. 4), and the contact
//! element of each slave node that carries or may carry force.
//!
//! Per Newton iterate the solver calls, in order:
//! 1. [`PairSolver::search`]: move the control net to the current node positions,
//!    project every slave node (span tree + Newton, near-linear in the number of
//!    slaves), evaluate the master at each foot point;
//! 2. [`PairSolver::push_groups`]: the node group `[slave, control points with
//!    nonzero basis at ξ̄]` of every slave that is inside the patch and within the
//!    capture distance (or holds a multiplier) — the contact elements of the
//!    sparsity pattern, which changes only when such a list changes;
//! 3. [`PairSolver::element`]: residual and tangent of one group (eq. 6.2, 6.5).
//!
//! After Newton converges, [`PairSolver::update_states`] records g_N, t_N and the
//! active set, and [`PairSolver::augment`] performs the Uzawa update λ_N ← t_N.

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use super::element::{normal_contact, ContactElementError, NormalLaw};
use super::friction::{friction_state, frictional_contact, tangential_state, FrictionLaw};
use crate::format::sccontact::MasterKind;
use super::definition::ContactDefinition;
pub use super::settings::PairSettings;
use super::settings::{Enforcement, Integration};
use super::master::Projector;
use super::seam::{SeamLoss, SeamWatch};
use super::mortar::element::{mortar_contact, NodeFriction};
use super::mortar::{Mortar, MortarError};
use crate::spline::{Projection, SplineError, SurfacePoint, Vec3};

/// Where a slave node stands after the last search / state update.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlaveStatus {
    /// The foot point lies beyond the patch edge (or the projection failed): no contact.
    Outside,
    /// Inside, λ_N + ε_N g_N ≥ 0: no pressure.
    Open,
    /// Inside, λ_N + ε_N g_N < 0: t_N < 0.
    Active,
}

impl SlaveStatus {
    /// The code written to results files: −1 outside, 0 open, 1 active.
    pub fn code(self) -> f64 {
        match self {
            Self::Outside => -1.0,
            Self::Open => 0.0,
            Self::Active => 1.0,
        }
    }
}

/// One slave's contact configuration ([`PairSolver::configuration`]): its mesh node,
/// whether it is pressed, the first control point carrying it (its master element)
/// and whether it is in crease contact, per direction.
pub type SlaveConfiguration = (u32, bool, u32, [bool; 2]);

/// The closest-point projection of one slave at `xs` (the body of
/// [`PairSolver::search`]): its projection, surface point and facet cell.
fn project_slave(projector: &Projector, frozen: bool, edge_tolerance: f64, xs: &Vec3, proj: &mut Projection, sp: &mut SurfacePoint, cell: &mut Option<[usize; 2]>) {
    let (pr, c) = if frozen { projector.project_frozen(xs, *cell, proj) } else { projector.project(xs, *cell) };
    *proj = pr;
    *cell = c;
    if proj.converged {
        *sp = projector.evaluate(proj.xi, c);
    }
    // Beyond the edge by less than the edge tolerance (a slave edge flush with the
    // master's): project onto the surface's extension, where the closest-point
    // conditions hold, and keep the node in contact.
    if proj.converged && !proj.inside {
        let d = xs - proj.x_bar;
        let overhang = if proj.clamped.iter().any(|&c| c) {
            // on a crease the distance vector also leans across it: measure only
            // along the directions held on the patch edge
            (0..2).filter(|&al| proj.xi[al] <= 0.0 || proj.xi[al] >= 1.0).map(|al| d.dot(&sp.a_alpha[al]).abs() / sp.a_alpha[al].norm()).fold(0.0, f64::max)
        } else {
            (d - sp.n_bar * d.dot(&sp.n_bar)).norm()
        };
        if overhang <= edge_tolerance {
            let margin = [0, 1].map(|al| 2.0 * edge_tolerance / sp.a_alpha[al].norm().max(1e-300));
            let ext = projector.project_extended(xs, proj.xi, c, margin);
            if ext.converged {
                *proj = Projection { inside: true, ..ext };
                *sp = projector.evaluate(proj.xi, c);
            }
        }
    }
    if proj.converged {
        sp.hold_on_crease(xs, proj.clamped);
    }
}

/// A pair that cannot be set up.
#[derive(Debug, thiserror::Error)]
pub enum PairError {
    #[error("contact pair '{pair}': master surface: {source}")]
    Master { pair: String, source: SplineError },
    #[error("contact pair '{pair}': {source}")]
    Mortar { pair: String, source: MortarError },
    #[error("contact pair '{pair}': `integration: mortar` needs a master of one grid; this master is a {net} (use `integration: node`)")]
    MortarNeedsGrid { pair: String, net: String },
    #[error("contact pair '{pair}': exchanging the search results between MPI ranks: {message}")]
    Exchange { pair: String, message: String },
}

/// A search shared by several MPI ranks ([`PairSolver::search_shared`]): each
/// projects the slave nodes `mine` says are its own, and `exchange` sums a buffer
/// over the ranks (every rank passes the same length).
pub struct SearchShare<'a> {
    pub mine: &'a (dyn Fn(u32) -> bool + Sync),
    pub exchange: &'a mut dyn FnMut(&mut [f64]) -> Result<(), String>,
}

/// Numbers per slave in the buffer a shared search exchanges.
const PACKED: usize = 14;

/// A slave's search result as numbers, for the exchange between ranks (exact: the
/// other ranks add zeros).
fn pack(p: &Projection, cell: Option<[usize; 2]>, out: &mut [f64]) {
    let b = |v: bool| f64::from(u8::from(v));
    let [c0, c1] = cell.unwrap_or([0, 0]);
    out.copy_from_slice(&[
        p.xi[0],
        p.xi[1],
        p.x_bar.x,
        p.x_bar.y,
        p.x_bar.z,
        p.g,
        b(p.inside),
        p.iterations as f64,
        b(p.converged),
        b(p.clamped[0]),
        b(p.clamped[1]),
        b(cell.is_some()),
        c0 as f64,
        c1 as f64,
    ]);
}

/// The inverse of [`pack`].
fn unpack(v: &[f64]) -> (Projection, Option<[usize; 2]>) {
    let p = Projection {
        xi: [v[0], v[1]],
        x_bar: Vec3::new(v[2], v[3], v[4]),
        g: v[5],
        inside: v[6] != 0.0,
        iterations: v[7] as usize,
        converged: v[8] != 0.0,
        clamped: [v[9] != 0.0, v[10] != 0.0],
    };
    (p, (v[11] != 0.0).then_some([v[12] as usize, v[13] as usize]))
}

/// The state of one pair.
pub struct PairSolver {
    pub name: String,
    pub settings: PairSettings,
    pub master_kind: MasterKind,
    /// Mesh node of every control point, `i + a·j`.
    net: Vec<u32>,
    projector: Projector,
    x_net: Vec<Vec3>,
    /// Slave node ids (sorted) and their tributary areas A_s (eq. 6.1).
    pub slaves: Vec<u32>,
    pub areas: Vec<f64>,
    /// λ_N of this increment's current Uzawa iterate, and of the last converged increment.
    pub lambda_n: Vec<f64>,
    lambda_committed: Vec<f64>,
    /// Last search: projections, surface points at ξ̄, slave positions.
    pub projections: Vec<Projection>,
    points: Vec<SurfacePoint>,
    /// Facet masters: the cell of each foot point (kept at ties, see
    /// [`FacetProjector::project_keeping`]).
    cells: Vec<Option<[usize; 2]>>,
    x_slave: Vec<Vec3>,
    /// After [`Self::update_states`]: t_N and the status of every slave.
    pub t_n: Vec<f64>,
    pub status: Vec<SlaveStatus>,
    /// Mean edge length of the master net in the reference configuration.
    pub h_master: f64,
    /// Slaves inside the patch closer than this (or holding λ_N < 0) get a group.
    capture: f64,
    /// See [`NormalLaw::touch`].
    touch: f64,
    /// Largest tangential overhang beyond the patch edge still in contact.
    edge_tolerance: f64,
    /// Uzawa updates made in the current increment.
    pub augmentations: u32,
    /// The search holds every slave's master element (see [`Self::freeze`]).
    frozen: bool,
    /// Frictional pairs, while frozen: each slave's return-mapping branch (slip).
    held_slip: Vec<Option<bool>>,
    /// Friction history (eq. 4.7): the converged foot point ξ̄_n and covariant
    /// tangential traction t_{Tα,n} of the last increment (zero when not in contact).
    xi_n: Vec<[f64; 2]>,
    t_t_n: Vec<[f64; 2]>,
    /// ξ̄_n as committed; `xi_n` also takes, within an increment, the first foot
    /// point of a node that had none (NaN: never on the patch, or off it at the last
    /// commit), so its slip is measured from where it first touched.
    xi_n_committed: Vec<[f64; 2]>,
    t_t_n_committed: Vec<[f64; 2]>,
    /// Atlas masters: the chart ξ̄_n and t_{Tα,n} are expressed on (`usize::MAX`:
    /// the chart of the next search); the search moves the history to the chart the
    /// node is on ([`Projector::transfer_history`]).
    chart_n: Vec<usize>,
    chart_n_committed: Vec<usize>,
    /// After [`Self::update_states`], frictional pairs: t_Tα, the traction vector,
    /// slip (else stick), the force on the slave node.
    pub t_t: Vec<[f64; 2]>,
    pub t_t_vector: Vec<Vec3>,
    pub slipping: Vec<bool>,
    pub slave_force: Vec<Vec3>,
    /// The buffer of a shared search (storage reused).
    exchange: Vec<f64>,
    /// `integration: mortar`: the segment-to-segment integration of the gaps.
    mortar: Option<Mortar>,
    /// Atlas masters: the active nodes on an edge between charts at the last
    /// commit, and those the last search lost there ([`super::seam`]).
    seams: SeamWatch,
    /// Mortar: the segmentation is held (the quadrature points keep their slave
    /// parameters and master cells; only their foot points follow), see
    /// [`Self::hold_segmentation`].
    segmentation_held: bool,
}

/// A snapshot of the multipliers an Uzawa update sets ([`PairSolver::multipliers`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Multipliers {
    pub lambda_n: Vec<f64>,
    pub xi_n: Vec<[f64; 2]>,
    pub t_t_n: Vec<[f64; 2]>,
}

impl Multipliers {
    /// A damped Uzawa update: `before + θ (after − before)`, between the iterate an
    /// update started from and the one it set (θ = 1: the full update). A foot point
    /// ξ̄_n without a `before` (NaN: the node first touched in this update) is taken as
    /// `after` set it.
    pub fn between(before: &Self, after: &Self, theta: f64) -> Self {
        let mix = |b: f64, a: f64| if b.is_finite() { b + theta * (a - b) } else { a };
        let mix2 = |b: &[f64; 2], a: &[f64; 2]| [mix(b[0], a[0]), mix(b[1], a[1])];
        Self {
            lambda_n: before.lambda_n.iter().zip(&after.lambda_n).map(|(b, a)| mix(*b, *a)).collect(),
            xi_n: before.xi_n.iter().zip(&after.xi_n).map(|(b, a)| mix2(b, a)).collect(),
            t_t_n: before.t_t_n.iter().zip(&after.t_t_n).map(|(b, a)| mix2(b, a)).collect(),
        }
    }
}

impl PairSolver {
    /// `x_ref` are the reference coordinates of all mesh nodes.
    pub fn new(def: &ContactDefinition, x_ref: &[Vec3]) -> Result<Self, PairError> {
        let pair = &def.pair;
        let err = |source| PairError::Master { pair: pair.name.clone(), source };
        let x_net: Vec<Vec3> = pair.net.nodes.iter().map(|&n| x_ref[n as usize]).collect();
        let projector = Projector::for_net(pair.master_kind, pair.orders, &pair.net, &x_net).map_err(err)?;
        let h_master = def.h_master;
        let settings = def.settings;
        let areas = def.areas.clone();
        let n = pair.slave_nodes.len();
        let mortar = match settings.integration {
            Integration::Node => None,
            Integration::Mortar => Some(
                Mortar::new(
                    &def.slave_faces,
                    &pair.slave_nodes,
                    x_ref,
                    pair.net.grid().map(|g| [g.a, g.b]).ok_or_else(|| PairError::MortarNeedsGrid { pair: pair.name.clone(), net: pair.net.describe() })?,
                    &pair.net.nodes,
                    settings.multipliers,
                    settings.transfer,
                )
                    .map_err(err)?
                    .map_err(|source| PairError::Mortar { pair: pair.name.clone(), source })?,
            ),
        };
        Ok(Self {
            name: pair.name.clone(),
            settings,
            master_kind: pair.master_kind,
            net: pair.net.nodes.clone(),
            projector,
            x_net,
            slaves: pair.slave_nodes.clone(),
            areas,
            lambda_n: vec![0.0; n],
            lambda_committed: vec![0.0; n],
            projections: vec![Projection { xi: [0.0; 2], x_bar: Vec3::zeros(), g: f64::INFINITY, inside: false, iterations: 0, converged: false, clamped: [false; 2] }; n],
            points: vec![SurfacePoint::default(); n],
            cells: vec![None; n],
            x_slave: vec![Vec3::zeros(); n],
            t_n: vec![0.0; n],
            status: vec![SlaveStatus::Outside; n],
            h_master,
            capture: 0.5 * h_master,
            touch: 1e-8 * h_master,
            edge_tolerance: 1e-3 * h_master,
            augmentations: 0,
            frozen: false,
            held_slip: vec![None; n],
            xi_n: vec![[f64::NAN; 2]; n],
            xi_n_committed: vec![[f64::NAN; 2]; n],
            t_t_n_committed: vec![[0.0; 2]; n],
            t_t_n: vec![[0.0; 2]; n],
            chart_n: vec![usize::MAX; n],
            chart_n_committed: vec![usize::MAX; n],
            t_t: vec![[0.0; 2]; n],
            t_t_vector: vec![Vec3::zeros(); n],
            slipping: vec![false; n],
            slave_force: vec![Vec3::zeros(); n],
            exchange: Vec::new(),
            mortar,
            segmentation_held: false,
            seams: SeamWatch::default(),
        })
    }

    /// Closest-point search at the current positions `x(node)` of all nodes.
    pub fn search(&mut self, x: impl Fn(u32) -> Vec3 + Sync) -> Result<(), PairError> {
        self.search_shared(x, None)
    }

    /// [`Self::search`], shared by several MPI ranks when `share` is given: each rank
    /// projects only its own slave nodes, and the ranks exchange the results, so
    /// every rank ends with every slave's projection (bit for bit the one a single
    /// rank computes: the master surface is the same on all, and a projection
    /// depends only on it, on the slave's position and on the slave's last result).
    pub fn search_shared(&mut self, x: impl Fn(u32) -> Vec3 + Sync, share: Option<SearchShare<'_>>) -> Result<(), PairError> {
        for (xn, &node) in self.x_net.iter_mut().zip(&self.net) {
            *xn = x(node);
        }
        self.projector.update(&self.x_net).map_err(|source| PairError::Master { pair: self.name.clone(), source })?;
        let projector = &self.projector;
        let edge_tolerance = self.edge_tolerance;
        let frozen = self.frozen;
        self.x_slave.iter_mut().zip(&self.slaves).for_each(|(xs, &node)| *xs = x(node));
        let mine = share.as_ref().map(|s| s.mine);
        let is_mine = |node: u32| mine.is_none_or(|m| m(node));
        self.projections
            .par_iter_mut()
            .zip(self.points.par_iter_mut())
            .zip(self.cells.par_iter_mut())
            .zip(self.x_slave.par_iter())
            .zip(self.slaves.par_iter())
            .with_min_len(64)
            .for_each(|((((proj, sp), cell), xs), &node)| {
                if is_mine(node) {
                    project_slave(projector, frozen, edge_tolerance, xs, proj, sp, cell);
                }
            });
        if let Some(share) = share {
            let n = self.slaves.len();
            self.exchange.clear();
            self.exchange.resize(PACKED * n, 0.0);
            for s in (0..n).filter(|&s| is_mine(self.slaves[s])) {
                pack(&self.projections[s], self.cells[s], &mut self.exchange[PACKED * s..PACKED * (s + 1)]);
            }
            (share.exchange)(&mut self.exchange).map_err(|message| PairError::Exchange { pair: self.name.clone(), message })?;
            let exchange = &self.exchange;
            self.projections
                .par_iter_mut()
                .zip(self.points.par_iter_mut())
                .zip(self.cells.par_iter_mut())
                .zip(self.x_slave.par_iter())
                .zip(self.slaves.par_iter())
                .enumerate()
                .with_min_len(64)
                .for_each(|(s, ((((proj, sp), cell), xs), &node))| {
                    if is_mine(node) {
                        return;
                    }
                    (*proj, *cell) = unpack(&exchange[PACKED * s..PACKED * (s + 1)]);
                    if proj.converged {
                        // what the owner's search left in its surface point
                        *sp = projector.evaluate(proj.xi, *cell);
                        sp.hold_on_crease(xs, proj.clamped);
                    }
                });
        }
        if let Some(mortar) = self.mortar.as_mut().filter(|_| self.segmentation_held) {
            mortar.refresh(&self.projector, &self.x_net, &self.x_slave, &self.projections, &self.points, &self.areas).map_err(|source| PairError::Master { pair: self.name.clone(), source })?;
        } else if let Some(mortar) = &mut self.mortar {
            mortar.integrate(&self.projector, &self.x_net, &self.x_slave, &self.projections, &self.points, &self.areas).map_err(|source| PairError::Master { pair: self.name.clone(), source })?;
        }
        for s in 0..self.slaves.len() {
            if self.xi_n[s][0].is_nan() && self.usable(s) {
                self.xi_n[s] = self.projections[s].xi;
                self.chart_n[s] = self.chart(s);
            } else if self.projector.is_atlas() && self.usable(s) && self.chart_n[s] != self.chart(s) {
                if self.chart_n[s] != usize::MAX {
                    (self.xi_n[s], self.t_t_n[s]) = self.projector.transfer_history(self.chart_n[s], self.xi_n[s], self.t_t_n[s], self.chart(s));
                }
                self.chart_n[s] = self.chart(s);
            }
        }
        self.seams.check(&self.slaves, &self.projections, &self.cells);
        Ok(())
    }

    /// Hold every slave's master element (facet cell) in the following searches, until
    /// [`Self::release`]: the projection stays on that element's continued map. Newton
    /// calls it when the configuration keeps changing (a slave flipping between the
    /// facets of a crease makes the residual non-differentiable there and Newton
    /// cycles); with the elements held, the remaining iterations see one smooth
    /// residual and converge, and the next solve searches afresh (the "segment
    /// update" limit of FEBio and others). B-spline masters have no elements to hold.
    ///
    /// With friction the return mapping's branch of every pressed slave (stick or
    /// slip, eq. 4.8 at the last search) is held as well, so a node at the slip
    /// threshold cannot switch branch from one iterate to the next (a kink in the
    /// residual). The state converged with held branches violates the slip
    /// criterion of such a node by no more than the last iterates moved it. (It did
    /// not remove the relative-residual floor of ~3e-7 measured on the 3D ironing
    /// pressed 1.4 with friction: that stall has another cause, not yet found.)
    pub fn freeze(&mut self) {
        self.frozen = true;
        self.segmentation_held = self.mortar.is_some();
        if self.settings.frictional() {
            for s in 0..self.slaves.len() {
                self.held_slip[s] = None;
                if self.pressed(s) && (self.mortar.is_none() || self.mortar_friction(s)) {
                    self.held_slip[s] = None;
                    if let Ok(st) = self.node_friction_state(s) {
                        self.held_slip[s] = Some(st.slip);
                    }
                }
            }
        }
    }

    /// Let the search choose master elements (and the return mapping its branch) again.
    pub fn release(&mut self) {
        self.frozen = false;
        self.segmentation_held = false;
        self.held_slip.iter_mut().for_each(|h| *h = None);
    }

    /// Mortar integration: keep the segmentation of the last search until
    /// [`Self::release`]. The segments follow the master cells, so they move with the
    /// configuration, and the tangent takes them as fixed (a quadrature choice):
    /// near the solution that small inconsistency stalls Newton at a relative
    /// residual of ~1e-7 (measured on Hertz). Held, the residual is the smooth
    /// function the tangent differentiates, and Newton finishes quadratically. Whether
    /// this pair has a segmentation to hold.
    pub fn hold_segmentation(&mut self) -> bool {
        let hold = self.mortar.is_some() && !self.segmentation_held;
        self.segmentation_held |= self.mortar.is_some();
        hold
    }

    /// The master net's mesh nodes (control points of a B-spline master, facet corners).
    pub fn net_nodes(&self) -> &[u32] {
        &self.net
    }

    /// The stiffness c = η ε_N Ā_s of the master-surface stabilisation, Ā_s the slave
    /// nodes' mean tributary area (0 when the pair has none).
    pub fn stabilization_stiffness(&self) -> f64 {
        if self.settings.stabilization <= 0.0 || self.areas.is_empty() {
            return 0.0;
        }
        let mean_area = self.areas.iter().sum::<f64>() / self.areas.len() as f64;
        self.settings.stabilization * self.settings.eps_n * mean_area
    }

    /// Whether freezing holds anything (facet and atlas masters: their elements and
    /// crease contact; frictional pairs).
    pub fn can_freeze(&self) -> bool {
        matches!(self.projector, Projector::Facet(_) | Projector::Atlas(_)) || self.settings.frictional() || self.mortar.is_some()
    }

    /// The slave has a foot point on the patch: inside, or beyond an edge by less
    /// than the edge tolerance (1e-3 of the master's mean edge, measured tangentially)
    /// and then on the patch's extension (see [`Self::search`]): a slave edge flush
    /// with the master edge must not flicker in and out of contact by round-off or by
    /// a lateral strain difference.
    ///
    /// Under mortar integration: some quadrature point of the node's faces lies over
    /// the master (and the node's own projection converged, for its contact frame).
    pub fn usable(&self, s: usize) -> bool {
        let p = &self.projections[s];
        let inside = match &self.mortar {
            Some(m) => m.covered[s] > 0.0,
            None => p.inside,
        };
        inside && p.converged && self.points[s].n_bar.iter().all(|v| v.is_finite())
    }

    /// The gap of slave `s` at the last search: g_N of its projection (eq. 4.3), or
    /// the weighted gap ĝ_s under mortar integration.
    pub fn gap(&self, s: usize) -> f64 {
        match &self.mortar {
            Some(m) => m.gap[s],
            None => self.projections[s].g,
        }
    }

    /// The closest-point projection of slave `s` at the last search and the master
    /// surface at its foot point (n̄, ā_α; meaningful when the projection converged).
    pub fn foot(&self, s: usize) -> (&Projection, &SurfacePoint) {
        (&self.projections[s], &self.points[s])
    }

    /// The capture distance: a slave inside the patch closer than this gets a contact
    /// element (0.5 h, h the master net's mean edge length).
    pub fn capture(&self) -> f64 {
        self.capture
    }

    /// The edge tolerance of the search (10⁻³ h, see [`Self::usable`]).
    pub fn edge_tolerance(&self) -> f64 {
        self.edge_tolerance
    }

    /// Appends the node group of every slave that needs a contact element now, and
    /// tells `owner` its slave index.
    pub fn push_groups(&self, groups: &mut crate::assembly::NodeGroups, mut owner: impl FnMut(usize)) {
        for s in 0..self.slaves.len() {
            if !self.usable(s) || (self.gap(s) >= self.capture && self.lambda_n[s] >= 0.0) {
                continue;
            }
            if let Some(m) = &self.mortar {
                groups.push_iter(m.element_nodes(s).iter().copied());
                owner(s);
                continue;
            }
            groups.push_iter(std::iter::once(self.slaves[s]).chain(self.points[s].basis.nodes().iter().map(|&k| self.net[k])));
            owner(s);
        }
    }

    /// λ_N + ε_N g_N of slave `s` at the last search (eq. 4.2): pressed when < 0.
    fn trial(&self, s: usize) -> f64 {
        self.lambda_n[s] + self.settings.eps_n * self.gap(s)
    }

    /// Inside the patch and pressed into it at the last search.
    fn pressed(&self, s: usize) -> bool {
        self.usable(s) && self.trial(s) < 0.0
    }

    /// Atlas masters: the chart of every slave's foot point (`u32::MAX`: none), as the
    /// results file stores it for a restart; `None` on other masters.
    pub fn charts(&self) -> Option<Vec<u32>> {
        self.projector.is_atlas().then(|| (0..self.slaves.len()).map(|s| if self.usable(s) { self.chart(s) as u32 } else { u32::MAX }).collect())
    }

    /// The atlas chart of slave `s`'s foot point (`usize::MAX` on other masters).
    fn chart(&self, s: usize) -> usize {
        if self.projector.is_atlas() {
            self.cells[s].map_or(usize::MAX, |c| c[0])
        } else {
            usize::MAX
        }
    }

    fn normal_law(&self, s: usize) -> NormalLaw {
        NormalLaw { lambda_n: self.lambda_n[s], eps_n: self.settings.eps_n, area: self.areas[s], touch: self.touch }
    }

    /// The friction law of slave `s`: its history ξ̄_n, t_{Tα,n} (ξ̄_n is set at the
    /// first search that finds the node on the patch, see `xi_n_committed`).
    fn friction_law(&self, s: usize) -> FrictionLaw {
        FrictionLaw { mu: self.settings.mu, eps_t: self.settings.eps_t, xi_n: self.xi_n[s], t_t_n: self.t_t_n[s], held_slip: self.held_slip[s] }
    }

    /// Under mortar integration, whether slave `s` carries friction at its node: a
    /// frictional pair and the node's own foot point inside the master (where the
    /// closest-point conditions, and so the convective slip, hold).
    fn mortar_friction(&self, s: usize) -> bool {
        self.mortar.is_some() && self.settings.frictional() && self.projections[s].inside && self.projections[s].converged
    }

    /// The friction state of slave `s` at the last search (the return mapping,
    /// without the tangent): node-to-surface, or at the node with the mortar pressure.
    fn node_friction_state(&self, s: usize) -> Result<crate::contact::friction::FrictionState, ContactElementError> {
        if self.mortar.is_some() {
            tangential_state(&self.x_slave[s], &self.points[s], self.trial(s).min(0.0), &self.normal_law(s), &self.friction_law(s))
        } else {
            friction_state(&self.x_slave[s], &self.points[s], &self.normal_law(s), &self.friction_law(s))
        }
    }

    /// The contact element of slave `s` (group nodes `[slave, control points]`).
    pub fn element(&self, s: usize, r: &mut DVector<f64>, k: &mut DMatrix<f64>) -> Result<(), ContactElementError> {
        if let Some(m) = &self.mortar {
            let law = self.friction_law(s);
            let friction = self.mortar_friction(s).then_some(NodeFriction { foot: &self.points[s], law: &law });
            return mortar_contact(m, s, &self.projector, &self.x_slave, &self.normal_law(s), friction, r, k).map(|_| ());
        }
        if self.settings.frictional() {
            frictional_contact(&self.x_slave[s], &self.points[s], &self.normal_law(s), &self.friction_law(s), r, k).map(|_| ())
        } else {
            normal_contact(&self.x_slave[s], &self.points[s], &self.normal_law(s), r, k).map(|_| ())
        }
    }

    /// t_N and status of every slave at the last search; for frictional pairs also
    /// the tangential traction and stick/slip.
    pub fn update_states(&mut self) -> Result<(), (u32, ContactElementError)> {
        for s in 0..self.slaves.len() {
            self.t_t[s] = [0.0; 2];
            self.t_t_vector[s] = Vec3::zeros();
            self.slipping[s] = false;
            self.slave_force[s] = Vec3::zeros();
            if !self.usable(s) {
                self.t_n[s] = 0.0;
                self.status[s] = SlaveStatus::Outside;
                continue;
            }
            let trial = self.trial(s);
            self.t_n[s] = trial.min(0.0);
            self.status[s] = if trial < 0.0 { SlaveStatus::Active } else { SlaveStatus::Open };
            if self.mortar.is_some() && trial < 0.0 {
                self.slave_force[s] = self.normal_force(s);
                if self.mortar_friction(s) {
                    let st = self.node_friction_state(s).map_err(|e| (self.slaves[s], e))?;
                    self.t_t[s] = st.t_t;
                    self.t_t_vector[s] = st.t_t_vector;
                    self.slipping[s] = st.slip;
                    self.slave_force[s] += st.slave_force;
                }
                continue;
            }
            if trial < 0.0 {
                self.slave_force[s] = self.points[s].n_bar * (-self.t_n[s] * self.areas[s]);
                if self.settings.frictional() {
                    let st = friction_state(&self.x_slave[s], &self.points[s], &self.normal_law(s), &self.friction_law(s)).map_err(|e| (self.slaves[s], e))?;
                    self.t_t[s] = st.t_t;
                    self.t_t_vector[s] = st.t_t_vector;
                    self.slipping[s] = st.slip;
                    self.slave_force[s] = st.slave_force;
                }
            }
        }
        Ok(())
    }

    /// Start the friction history from the current search (the reference
    /// configuration, before the first increment).
    pub fn init_history(&mut self) {
        for s in 0..self.slaves.len() {
            if self.usable(s) {
                self.xi_n[s] = self.projections[s].xi;
                self.chart_n[s] = self.chart(s);
            }
        }
        self.xi_n_committed.copy_from_slice(&self.xi_n);
        self.chart_n_committed.copy_from_slice(&self.chart_n);
    }

    /// Slip increment of slave `s` in this increment, (ξ̄ − ξ̄_n)^α ā_α.
    pub fn slip_increment(&self, s: usize) -> Vec3 {
        if self.status[s] == SlaveStatus::Outside || self.xi_n[s][0].is_nan() {
            return Vec3::zeros();
        }
        let law = self.friction_law(s);
        let xi = self.projections[s].xi;
        let a = &self.points[s].a_alpha;
        a[0] * (xi[0] - law.xi_n[0]) + a[1] * (xi[1] - law.xi_n[1])
    }

    /// The mesh nodes of the control points that carry slave `s`'s contact element
    /// (its master side; empty when it has no foot point on the master).
    pub fn master_nodes_of(&self, s: usize) -> impl Iterator<Item = u32> + '_ {
        let nodes = if self.usable(s) { self.points[s].basis.nodes() } else { &[] };
        nodes.iter().map(|&k| self.net[k])
    }

    /// The contact frame at slave `s`'s foot point at the last search: n̄ and two
    /// unit tangents orthogonal to it and to each other (ā_1 normalised, n̄ × it).
    pub fn contact_frame(&self, s: usize) -> (Vec3, [Vec3; 2]) {
        let sp = &self.points[s];
        let t1 = sp.a_alpha[0].normalize();
        (sp.n_bar, [t1, sp.n_bar.cross(&t1)])
    }

    /// Slaves sticking and slipping (active ones, frictional pairs).
    pub fn n_stick_slip(&self) -> (usize, usize) {
        let slip = self.slipping.iter().filter(|&&b| b).count();
        (self.n_active() - slip, slip)
    }

    /// Number of active slaves (after [`Self::update_states`]).
    pub fn n_active(&self) -> usize {
        self.status.iter().filter(|&&s| s == SlaveStatus::Active).count()
    }

    /// Number of slaves with a positive trial pressure at the last search (a cheap
    /// count for progress lines, before the states are updated).
    pub fn n_pressed(&self) -> usize {
        (0..self.slaves.len()).filter(|&s| self.pressed(s)).count()
    }

    /// The contact configuration at the last search, one entry per slave: whether it
    /// is pressed, which control points carry it (its first basis node) and, on an
    /// atlas master, whether it is in crease contact (per direction) — what changes
    /// when the active set, the master element under a node or its crease state
    /// changes. (A single grid's facet net leaves the crease state out; its figures
    /// are measured so. With it, the frictional facet shallow ironing's ripple halves
    /// and the concave-crease test names more nodes, a change to measure on its own.)
    pub fn configuration(&self, out: &mut Vec<SlaveConfiguration>) {
        let atlas = self.projector.is_atlas();
        for s in 0..self.slaves.len() {
            let pressed = self.pressed(s);
            let first = if self.usable(s) { self.points[s].basis.nodes().first().map_or(u32::MAX, |&k| self.net[k]) } else { u32::MAX };
            let crease = if atlas { self.projections[s].clamped } else { [false; 2] };
            out.push((self.slaves[s], pressed, first, crease));
        }
    }

    /// Slaves whose closest-point projection failed at the last search (treated as
    /// out of contact), and the first of them.
    pub fn failed_projections(&self) -> (usize, Option<u32>) {
        let failed: Vec<u32> = (0..self.slaves.len()).filter(|&s| !self.projections[s].converged).map(|s| self.slaves[s]).collect();
        (failed.len(), failed.first().copied())
    }

    /// Largest penetration −g_N over the active slaves (0 if none).
    pub fn max_penetration(&self) -> f64 {
        (0..self.slaves.len()).filter(|&s| self.status[s] == SlaveStatus::Active).map(|s| -self.gap(s)).fold(0.0, f64::max)
    }

    /// The fraction α ∈ (0, 1] of a Newton correction `du(node)` that carries no
    /// unpressed slave deeper than `depth · h_master` past the master, and the slave
    /// node that decides it (`None` when the full correction does). A slave that is
    /// not pressed has no contact stiffness in the tangent that made the correction,
    /// so nothing in it stops the node at the master: at first contact the linear
    /// predictor drives whole faces through the other body (see docs/theory.md,
    /// "Penetration step limit"). The gap is linearised at the last search,
    /// Δg = n̄·(Δx_s − Σ_A N_A Δx_A) (the variation of eq. 2.2's gap).
    pub fn step_limit(&self, du: impl Fn(u32) -> Vec3, depth: f64) -> Option<(f64, u32)> {
        let allowed = depth * self.h_master;
        let mut limit: Option<(f64, u32)> = None;
        for s in 0..self.slaves.len() {
            if !self.usable(s) || self.pressed(s) {
                continue;
            }
            let g = self.projections[s].g;
            let sp = &self.points[s];
            let mut dx = du(self.slaves[s]);
            for (&k, &q) in sp.basis.nodes().iter().zip(sp.basis.q()) {
                dx -= du(self.net[k]) * q;
            }
            let g_new = g + sp.n_bar.dot(&dx);
            if g_new >= -allowed || g <= -allowed {
                continue;
            }
            let alpha = (g + allowed) / (g - g_new);
            if limit.is_none_or(|(a, _)| alpha < a) {
                limit = Some((alpha, self.slaves[s]));
            }
        }
        limit
    }

    /// Largest elastic slip ‖t_T − t_{T,n}‖ / ε_T of a sticking node (0 without
    /// friction): the tangential constraint violation the augmentation removes.
    pub fn max_elastic_slip(&self) -> f64 {
        if !self.settings.frictional() {
            return 0.0;
        }
        (0..self.slaves.len())
            .filter(|&s| self.status[s] == SlaveStatus::Active && !self.slipping[s])
            .map(|s| {
                let d = [self.t_t[s][0] - self.t_t_n[s][0], self.t_t[s][1] - self.t_t_n[s][1]];
                let ai = self.points[s].a_inv;
                (d[0] * ai[(0, 0)] * d[0] + 2.0 * d[0] * ai[(0, 1)] * d[1] + d[1] * ai[(1, 1)] * d[1]).max(0.0).sqrt() / self.settings.eps_t
            })
            .fold(0.0, f64::max)
    }

    /// Whether another Uzawa update is due (augmented Lagrangian, penetration or
    /// elastic slip of a sticking node above the tolerance, updates left).
    pub fn needs_augmentation(&self) -> bool {
        let tol = self.settings.penetration_tolerance;
        self.settings.enforcement == Enforcement::AugmentedLagrangian
            && (self.max_penetration() > tol || self.max_elastic_slip() > tol)
            && self.augmentations < self.settings.max_augmentations
    }

    /// Uzawa update (sec. 4): λ_N ← t_N = min(0, λ_N + ε_N g_N); with friction the
    /// tangential multiplier too (eq. 4.7's Δλ_T): a sticking node keeps its anchor ξ̄_n
    /// and takes t_{T,n} ← t_T, so the next solve drives its elastic slip to zero; a
    /// sliding node's slip is plastic: it is re-anchored, ξ̄_n ← ξ̄, t_{T,n} ← t_T.
    pub fn augment(&mut self) {
        self.lambda_n.copy_from_slice(&self.t_n);
        if self.settings.frictional() {
            for s in 0..self.slaves.len() {
                if self.status[s] != SlaveStatus::Active {
                    continue;
                }
                self.t_t_n[s] = self.t_t[s];
                if self.slipping[s] {
                    self.xi_n[s] = self.projections[s].xi;
                    self.chart_n[s] = self.chart(s);
                }
            }
        }
        self.augmentations += 1;
    }

    /// The multipliers an Uzawa update sets: λ_N and, with friction, ξ̄_n and t_{Tα,n}.
    pub fn multipliers(&self) -> Multipliers {
        Multipliers { lambda_n: self.lambda_n.clone(), xi_n: self.xi_n.clone(), t_t_n: self.t_t_n.clone() }
    }

    /// Set the multipliers (a damped update: [`Multipliers::between`]).
    pub fn set_multipliers(&mut self, m: &Multipliers) {
        self.lambda_n.copy_from_slice(&m.lambda_n);
        self.xi_n.copy_from_slice(&m.xi_n);
        self.t_t_n.copy_from_slice(&m.t_t_n);
    }

    /// Total force the master exerts on the slave body (Σ −r_s over the slaves):
    /// normal Σ −t_N A_s n̄ plus, with friction, the tangential part.
    pub fn total_force(&self) -> Vec3 {
        self.slave_force.iter().sum()
    }

    /// The tangential part of [`Self::total_force`] (zero without friction).
    pub fn tangential_force(&self) -> Vec3 {
        (0..self.slaves.len())
            .filter(|&s| self.status[s] == SlaveStatus::Active)
            .map(|s| self.slave_force[s] - self.normal_force(s))
            .sum()
    }

    /// The normal part of the force on the slave body through slave `s`:
    /// −t_N A_s n̄, or −t_s ∫ N_s n̄ dA under mortar integration.
    fn normal_force(&self, s: usize) -> Vec3 {
        match &self.mortar {
            Some(m) => m.slave_force(s, &self.projector) * (-self.t_n[s]),
            None => self.points[s].n_bar * (-self.t_n[s] * self.areas[s]),
        }
    }

    /// The increment converged: keep its multipliers and, with friction, the history
    /// (ξ̄_n ← ξ̄; t_{Tα,n} ← t_Tα for active nodes, 0 for the others: a node that
    /// leaves contact forgets its traction).
    pub fn commit(&mut self) {
        self.lambda_committed.copy_from_slice(&self.lambda_n);
        self.augmentations = 0;
        for s in 0..self.slaves.len() {
            // off the patch: forget the foot point, the next one found starts afresh
            self.xi_n[s] = if self.status[s] == SlaveStatus::Outside { [f64::NAN; 2] } else { self.projections[s].xi };
            self.t_t_n[s] = if self.status[s] == SlaveStatus::Active { self.t_t[s] } else { [0.0; 2] };
            self.chart_n[s] = self.chart(s);
        }
        self.xi_n_committed.copy_from_slice(&self.xi_n);
        self.t_t_n_committed.copy_from_slice(&self.t_t_n);
        self.chart_n_committed.copy_from_slice(&self.chart_n);
        self.seams.commit(&self.projector, (0..self.slaves.len()).map(|s| (self.status[s] == SlaveStatus::Active, self.chart_n[s], self.xi_n[s])));
    }

    /// Slave nodes the last search lost at a seam between charts (atlas masters:
    /// active at the last commit on an edge between charts, off the master now).
    pub fn seam_losses(&self) -> &[SeamLoss] {
        self.seams.lost()
    }

    /// A restart: the converged history of an increment as a results file stores it
    /// (`state` rows [`CONTACT_STATE_COLUMNS`], `friction` rows [`FRICTION_COLUMNS`],
    /// empty when the run had no friction), taken as [`Self::commit`] would have left
    /// it: λ_N, the foot point ξ̄_n (none off the patch) and t_{Tα,n} of the active
    /// nodes (eq. 4.7). The caller checked that the rows are this pair's slaves.
    ///
    /// [`CONTACT_STATE_COLUMNS`]: crate::format::scres::CONTACT_STATE_COLUMNS
    /// [`FRICTION_COLUMNS`]: crate::format::scres::FRICTION_COLUMNS
    pub fn restore_history(&mut self, state: &[[f64; 6]], friction: &[[f64; 9]], charts: &[u32]) {
        for (s, row) in state.iter().enumerate().take(self.slaves.len()) {
            let active = row[3] == SlaveStatus::Active.code();
            self.lambda_n[s] = row[2];
            self.xi_n[s] = if row[3] == SlaveStatus::Outside.code() { [f64::NAN; 2] } else { [row[4], row[5]] };
            self.t_t_n[s] = match friction.get(s) {
                Some(f) if active => [f[6], f[7]],
                _ => [0.0; 2],
            };
        }
        // atlas masters: the chart each ξ̄_n lies on, as stored (files without it:
        // the chart of the first search after the restart)
        for (s, c) in self.chart_n.iter_mut().enumerate() {
            *c = charts.get(s).filter(|&&c| (c as usize) < self.projector.n_charts()).map_or(usize::MAX, |&c| c as usize);
        }
        // and the chart the next search's hysteresis keeps, as the run left it: a
        // node on an edge between two charts stays on the one it was on
        if self.projector.is_atlas() {
            for (cell, &c) in self.cells.iter_mut().zip(&self.chart_n) {
                *cell = (c != usize::MAX).then_some([c, 0]);
            }
        }
        self.seams.commit(&self.projector, state.iter().zip(&self.chart_n).map(|(row, &c)| (row[3] == SlaveStatus::Active.code(), c, [row[4], row[5]])));
        self.lambda_committed.copy_from_slice(&self.lambda_n);
        self.xi_n_committed.copy_from_slice(&self.xi_n);
        self.t_t_n_committed.copy_from_slice(&self.t_t_n);
        self.chart_n_committed.copy_from_slice(&self.chart_n);
        self.augmentations = 0;
    }

    /// The increment failed: back to the last converged multipliers.
    pub fn restore(&mut self) {
        self.lambda_n.copy_from_slice(&self.lambda_committed);
        self.xi_n.copy_from_slice(&self.xi_n_committed);
        self.t_t_n.copy_from_slice(&self.t_t_n_committed);
        self.chart_n.copy_from_slice(&self.chart_n_committed);
        self.augmentations = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::net::ControlNet;
    use crate::format::sccontact::{ContactPair, SlaveKind};

    /// A wavy 6 × 5 master net (nodes 0..30) and 40 slave nodes over it and beyond
    /// its edges (nodes 30..70): positions and the pair.
    fn wavy_pair(kind: MasterKind) -> (Vec<Vec3>, PairSolver) {
        let (a, b) = (6, 5);
        let mut x: Vec<Vec3> = Vec::new();
        for j in 0..b {
            for i in 0..a {
                let (u, v) = (i as f64 / (a - 1) as f64, j as f64 / (b - 1) as f64);
                x.push(Vec3::new(u, v, 0.1 * (3.0 * u).sin() * (2.0 * v).cos()));
            }
        }
        let mut rng = crate::fem::fd::Lcg(11);
        for _ in 0..40 {
            // uniform() is in [−1, 1): x, y in [−0.1, 1.1), z in [−0.05, 0.15)
            x.push(Vec3::new(0.5 + 0.6 * rng.uniform(), 0.5 + 0.6 * rng.uniform(), 0.05 + 0.1 * rng.uniform()));
        }
        let pair = ContactPair {
            name: "c".into(),
            slave_kind: SlaveKind::NodeSet,
            slave: "s".into(),
            master: "m".into(),
            master_kind: kind,
            orders: if kind == MasterKind::Facet { [2, 2] } else { [3, 3] },
            slave_nodes: (30..70).collect(),
            net: ControlNet { a, b, nodes: (0..30).collect() }.into(),
        };
        let settings = PairSettings { eps_n: 1e3, enforcement: Enforcement::Penalty, penetration_tolerance: 1e-3, max_augmentations: 0, update_halvings: 0, mu: 0.0, eps_t: 0.0, stabilization: 0.0, integration: Integration::Node, multipliers: Default::default(), transfer: Default::default() };
        let def = ContactDefinition { pair, settings, areas: vec![0.01; 40], slave_faces: Vec::new(), h_master: 0.2, eps_n_default: false, adjust: None, allow_flipped_master: false };
        let solver = PairSolver::new(&def, &x).unwrap();
        (x, solver)
    }

    #[test]
    fn a_search_shared_by_two_ranks_gives_every_rank_the_single_search_bit_for_bit() {
        for kind in [MasterKind::Bspline, MasterKind::Facet] {
            let (x, mut whole) = wavy_pair(kind);
            let (_, mut rank_a) = wavy_pair(kind);
            let (_, mut rank_b) = wavy_pair(kind);
            let at = |n: u32| x[n as usize];
            whole.search(at).unwrap();
            // rank b searches the odd slave nodes and keeps what it would send
            let odd = |n: u32| n % 2 == 1;
            let even = |n: u32| n % 2 == 0;
            let mut sent = Vec::new();
            let mut keep = |buffer: &mut [f64]| {
                sent = buffer.to_vec();
                Ok(())
            };
            rank_b.search_shared(at, Some(SearchShare { mine: &odd, exchange: &mut keep })).unwrap();
            // rank a searches the even ones and receives the sum
            let mut add = |buffer: &mut [f64]| {
                buffer.iter_mut().zip(&sent).for_each(|(v, w)| *v += w);
                Ok(())
            };
            rank_a.search_shared(at, Some(SearchShare { mine: &even, exchange: &mut add })).unwrap();
            let inside = (0..40).filter(|&s| whole.usable(s)).count();
            assert!(inside > 10 && inside < 40, "{kind:?}: {inside} slaves on the patch: the test needs both kinds");
            for s in 0..40 {
                let (p, q) = (&whole.projections[s], &rank_a.projections[s]);
                assert_eq!((p.xi.map(f64::to_bits), p.g.to_bits(), p.inside, p.converged, p.clamped), (q.xi.map(f64::to_bits), q.g.to_bits(), q.inside, q.converged, q.clamped), "{kind:?} slave {s}");
                assert_eq!(whole.cells[s], rank_a.cells[s]);
                if whole.usable(s) {
                    assert_eq!(whole.points[s], rank_a.points[s], "{kind:?} slave {s}");
                }
            }
        }
    }

    #[test]
    fn an_exchange_failure_names_the_pair() {
        let (x, mut pair) = wavy_pair(MasterKind::Bspline);
        let mine = |n: u32| n < 50;
        let mut fail = |_: &mut [f64]| Err("MPI_Allreduce failed".to_string());
        let e = pair.search_shared(|n| x[n as usize], Some(SearchShare { mine: &mine, exchange: &mut fail })).unwrap_err().to_string();
        assert!(e.contains("'c'") && e.contains("MPI_Allreduce failed"), "{e}");
    }

    #[test]
    fn damped_update_lies_between_the_iterates() {
        let before = Multipliers { lambda_n: vec![0.0, -2.0], xi_n: vec![[0.1, 0.2], [f64::NAN; 2]], t_t_n: vec![[1.0, 0.0], [0.0, 0.0]] };
        let after = Multipliers { lambda_n: vec![-4.0, -1.0], xi_n: vec![[0.3, 0.2], [0.5, 0.6]], t_t_n: vec![[3.0, -2.0], [0.0, 1.0]] };
        assert_eq!(Multipliers::between(&before, &after, 1.0), after);
        let half = Multipliers::between(&before, &after, 0.5);
        assert_eq!(half.lambda_n, vec![-2.0, -1.5]);
        assert!((half.xi_n[0][0] - 0.2).abs() < 1e-15 && half.xi_n[0][1] == 0.2);
        // a node without a foot point before the update keeps the one it was given
        assert_eq!(half.xi_n[1], [0.5, 0.6]);
        assert_eq!(half.t_t_n, vec![[2.0, -1.0], [0.0, 0.5]]);
        let none = Multipliers::between(&before, &after, 0.0);
        assert_eq!((none.lambda_n, none.t_t_n), (before.lambda_n.clone(), before.t_t_n.clone()));
    }
}
