//! The closest-point search of a pair's slave nodes (eq. 2.2): the control net
//! follows the master body, every slave node is projected onto the master (span
//! tree and Newton, near-linear in the number of slaves), and the master is evaluated
//! at each foot point ξ̄ (x̄, ā_α, n̄, ā_αβ, b̄_αβ: eqs. 4.11–4.13).
//!
//! - A foot point beyond the patch edge by less than the edge tolerance is moved onto
//!   the surface's extension: a slave edge flush with the master's stays in contact.
//! - Freezing holds every slave's master element (facet cell, atlas chart) and, with
//!   friction, its return-mapping branch (eq. 4.8), so Newton sees one smooth residual
//!   near a crease; mortar integration holds its segmentation.
//! - On atlas masters the friction history ξ̄_n, t_{Tα,n} (eq. 4.7) is moved to the
//!   chart the node's foot point lies on now.
//! - Several MPI ranks may share a search, each projecting its own slaves and
//!   exchanging the results.
//!
//! And what a search tells: which slaves have a foot point, their gap g_N (eq. 4.3) or
//! mortar's weighted gap, failed projections, and how far a Newton correction may go
//! before it carries an unpressed slave through the master (the linearised gap
//! Δg_N, eq. 4.16).

use rayon::prelude::*;

use super::{PairError, PairSolver};
use crate::contact::master::Projector;
use crate::contact::mortar::Feet;
use crate::spline::{Projection, SurfacePoint, Vec3};

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

/// `f(s, projection, surface point, cell, x, node)` for every slave `s` of a pair, in
/// parallel (chunks of at least 64 slaves): the search's per-slave arrays walked
/// together, in place.
#[inline]
fn for_each_slave<F>(projections: &mut [Projection], points: &mut [SurfacePoint], cells: &mut [Option<[usize; 2]>], x_slave: &[Vec3], slaves: &[u32], f: F)
where
    F: Fn(usize, &mut Projection, &mut SurfacePoint, &mut Option<[usize; 2]>, &Vec3, u32) + Sync + Send,
{
    projections
        .par_iter_mut()
        .zip(points.par_iter_mut())
        .zip(cells.par_iter_mut())
        .zip(x_slave.par_iter())
        .zip(slaves.par_iter())
        .enumerate()
        .with_min_len(64)
        .for_each(|(s, ((((proj, sp), cell), xs), &node))| f(s, proj, sp, cell, xs, node));
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

impl PairSolver {
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
        for_each_slave(&mut self.projections, &mut self.points, &mut self.cells, &self.x_slave, &self.slaves, |_, proj, sp, cell, xs, node| {
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
            for_each_slave(&mut self.projections, &mut self.points, &mut self.cells, &self.x_slave, &self.slaves, |s, proj, sp, cell, xs, node| {
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
            mortar.refresh(&self.projector, &self.x_net, &self.x_slave, Feet { projections: &self.projections, elements: &self.cells, points: &self.points }, &self.areas).map_err(|source| PairError::Master { pair: self.name.clone(), source })?;
        } else if let Some(mortar) = &mut self.mortar {
            mortar.integrate(&self.projector, &self.x_net, &self.x_slave, Feet { projections: &self.projections, elements: &self.cells, points: &self.points }, &self.areas).map_err(|source| PairError::Master { pair: self.name.clone(), source })?;
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
    /// update" limit of FEBio and others). A single B-spline patch holds each
    /// slave's knot span where the patch is C⁰ (order 2): on a knot line the
    /// one-sided derivatives of the basis differ, and a slave on it flips between
    /// the spans by round-off (docs/validation/masters.md, the knot-line row). A
    /// patch that is C¹ everywhere has no element to hold.
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
        if self.mortar.is_none() && self.projector.has_kinks() {
            for (cell, p) in self.cells.iter_mut().zip(&self.projections) {
                *cell = if p.converged { self.projector.span_of(p.xi) } else { None };
            }
        }
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
        if self.projector.has_kinks() {
            // a single patch's spans were held only while frozen
            self.cells.iter_mut().for_each(|c| *c = None);
        }
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

    /// Whether freezing holds anything (facet and atlas masters: their elements and
    /// crease contact; a single patch's spans where it is C⁰; frictional pairs).
    pub fn can_freeze(&self) -> bool {
        matches!(self.projector, Projector::Facet(_) | Projector::Atlas(_)) || self.projector.has_kinks() || self.settings.frictional() || self.mortar.is_some()
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

    /// Atlas masters: the chart of every slave's foot point (`u32::MAX`: none), as the
    /// results file stores it for a restart; `None` on other masters.
    pub fn charts(&self) -> Option<Vec<u32>> {
        self.projector.is_atlas().then(|| (0..self.slaves.len()).map(|s| if self.usable(s) { self.chart(s) as u32 } else { u32::MAX }).collect())
    }

    /// The atlas chart of slave `s`'s foot point (`usize::MAX` on other masters).
    pub(super) fn chart(&self, s: usize) -> usize {
        if self.projector.is_atlas() {
            self.cells[s].map_or(usize::MAX, |c| c[0])
        } else {
            usize::MAX
        }
    }

    /// Slaves whose closest-point projection failed at the last search (treated as
    /// out of contact), and the first of them.
    pub fn failed_projections(&self) -> (usize, Option<u32>) {
        let failed: Vec<u32> = (0..self.slaves.len()).filter(|&s| !self.projections[s].converged).map(|s| self.slaves[s]).collect();
        (failed.len(), failed.first().copied())
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::definition::ContactDefinition;
    use crate::contact::net::ControlNet;
    use crate::contact::settings::{Enforcement, Integration, PairSettings};
    use crate::format::sccontact::{ContactPair, MasterKind, SlaveKind};

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
        let settings = PairSettings { eps_n: 1e3, enforcement: Enforcement::Penalty, penetration_tolerance: 1e-3, max_augmentations: 0, update_halvings: 0, uzawa_relaxation: 1.0, mu: 0.0, eps_t: 0.0, stabilization: 0.0, integration: Integration::Node, multipliers: Default::default(), transfer: Default::default(), quadrature: Default::default() };
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
}
