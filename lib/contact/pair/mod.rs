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
//!
//! | file | concept |
//! |------|---------|
//! | `mod.rs` | the pair's state [`PairSolver`] and its set-up (the mortar integration included), [`SlaveStatus`], [`PairError`] |
//! | `search.rs` | the closest-point search of every slave (eq. 2.2): projection, the edge tolerance, held master elements (facet cells, atlas charts) and slip branches, the friction history moved between atlas charts, the search shared by MPI ranks |
//! | `multipliers.rs` | the multipliers and the history: the Uzawa update λ_N ← t_N (sec. 4) with the tangential Δλ_T (eq. 4.7), the damped update, commit and restore of λ_N, ξ̄_n, t_{Tα,n} and their charts |
//! | `elements.rs` | the contact elements: node groups of the sparsity pattern, residual and tangent of one slave (eqs. 6.2–6.5, or mortar), t_N and stick/slip (eqs. 4.2, 4.5–4.8), the force on the slave body |

mod elements;
mod multipliers;
mod search;

pub use multipliers::Multipliers;
pub use search::SearchShare;

use super::definition::ContactDefinition;
use super::master::Projector;
use super::mortar::{Mortar, MortarError};
use super::seam::SeamWatch;
pub use super::settings::PairSettings;
use super::settings::Integration;
use crate::format::sccontact::MasterKind;
use crate::spline::{Projection, SplineError, SurfacePoint, Vec3};

/// One slave's contact configuration ([`PairSolver::configuration`]): its mesh node,
/// whether it is pressed, the first control point carrying it (its master element)
/// and whether it is in crease contact, per direction.
pub type SlaveConfiguration = (u32, bool, u32, [bool; 2]);

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

/// A pair that cannot be set up.
#[derive(Debug, thiserror::Error)]
pub enum PairError {
    #[error("contact pair '{pair}': master surface: {source}")]
    Master { pair: String, source: SplineError },
    #[error("contact pair '{pair}': {source}")]
    Mortar { pair: String, source: MortarError },
    #[error("contact pair '{pair}': exchanging the search results between MPI ranks: {message}")]
    Exchange { pair: String, message: String },
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

impl PairSolver {
    /// The mortar integration of an `integration: mortar` pair.
    pub fn mortar(&self) -> Option<&Mortar> {
        self.mortar.as_ref()
    }

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
                    &pair.net,
                    &projector,
                    settings.multipliers,
                    settings.transfer,
                    // faces farther than twice the capture distance are not integrated (`Mortar::far`)
                    h_master,
                )
                    .map_err(err)?
                    .map_err(|source| PairError::Mortar { pair: pair.name.clone(), source })?
                    .with_quadrature(settings.quadrature),
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

    /// The master net's mesh nodes (control points of a B-spline master, facet corners).
    pub fn net_nodes(&self) -> &[u32] {
        &self.net
    }
}
