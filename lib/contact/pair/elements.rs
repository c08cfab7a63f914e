//! The contact elements of a pair at the last search: which slaves get one (the node
//! groups `[slave, control points with nonzero basis at ξ̄]` of the sparsity
//! pattern), the residual and tangent of one (node-to-surface: eqs. 6.2–6.5,
//! frictionless or with Coulomb friction, eqs. 4.5–4.8; or the mortar element under
//! `integration: mortar`), and, after Newton converged, t_N = min(0, λ_N + ε_N g_N)
//! (eq. 4.2), the status and stick/slip of every slave and the force the master
//! exerts on the slave body (A_s t_N n̄ of eq. 6.1, plus the tangential part).

use nalgebra::{DMatrix, DVector};

use super::{PairSolver, SlaveConfiguration, SlaveStatus};
use crate::contact::element::{normal_contact, ContactElementError, NormalLaw};
use crate::contact::friction::{friction_state, frictional_contact, tangential_state, FrictionLaw};
use crate::contact::mortar::element::{mortar_contact, NodeFriction};
use crate::spline::Vec3;

impl PairSolver {
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

    /// λ_N + ε_N g_N of slave `s` at the last search (eq. 4.2): pressed when < 0.
    pub(super) fn trial(&self, s: usize) -> f64 {
        self.lambda_n[s] + self.settings.eps_n * self.gap(s)
    }

    /// Inside the patch and pressed into it at the last search.
    pub(super) fn pressed(&self, s: usize) -> bool {
        self.usable(s) && self.trial(s) < 0.0
    }

    pub(super) fn normal_law(&self, s: usize) -> NormalLaw {
        NormalLaw { lambda_n: self.lambda_n[s], eps_n: self.settings.eps_n, area: self.areas[s], touch: self.touch }
    }

    /// The friction law of slave `s`: its history ξ̄_n, t_{Tα,n} (ξ̄_n is set at the
    /// first search that finds the node on the patch, see `xi_n_committed`).
    pub(super) fn friction_law(&self, s: usize) -> FrictionLaw {
        FrictionLaw { mu: self.settings.mu, eps_t: self.settings.eps_t, xi_n: self.xi_n[s], t_t_n: self.t_t_n[s], held_slip: self.held_slip[s] }
    }

    /// Under mortar integration, whether slave `s` carries friction at its node: a
    /// frictional pair and the node's own foot point inside the master (where the
    /// closest-point conditions, and so the convective slip, hold).
    pub(super) fn mortar_friction(&self, s: usize) -> bool {
        self.mortar.is_some() && self.settings.frictional() && self.projections[s].inside && self.projections[s].converged
    }

    /// The friction state of slave `s` at the last search (the return mapping,
    /// without the tangent): node-to-surface, or at the node with the mortar pressure.
    pub(super) fn node_friction_state(&self, s: usize) -> Result<crate::contact::friction::FrictionState, ContactElementError> {
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

    /// The stiffness c = η ε_N Ā_s of the master-surface stabilisation, Ā_s the slave
    /// nodes' mean tributary area (0 when the pair has none).
    pub fn stabilization_stiffness(&self) -> f64 {
        if self.settings.stabilization <= 0.0 || self.areas.is_empty() {
            return 0.0;
        }
        let mean_area = self.areas.iter().sum::<f64>() / self.areas.len() as f64;
        self.settings.stabilization * self.settings.eps_n * mean_area
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

    /// Whether the pair integrates under `integration: mortar`.
    pub fn is_mortar(&self) -> bool {
        self.mortar.is_some()
    }

    /// Mortar pairs: the master cells left out of the last integration because their
    /// image over a slave face was not convex (`contact::mortar::segment`).
    pub fn mortar_skipped_cells(&self) -> Option<usize> {
        self.mortar.as_ref().map(|m| m.skipped_cells)
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
}
