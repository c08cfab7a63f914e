//! A contact pair's settings, as plain data: how the normal constraint is enforced
//! ([`Enforcement`], paper sec. 4), where it is imposed ([`Integration`]: at the
//! slave nodes or mortar-integrated over the slave faces), the mortar pair's bases
//! ([`MortarMultipliers`], [`MortarTransfer`], [`MortarQuadrature`]) and all of them resolved for one pair
//! ([`PairSettings`]). The solve setup (`format::setup`) reads and writes them.

use serde::{Deserialize, Serialize};

/// How often a Newton solve that fails after an Uzawa update is retried with half
/// the update (`solver::uzawa`), by default.
pub const UPDATE_HALVINGS: u32 = 3;

/// How a pair's normal constraint is enforced (paper sec. 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Enforcement {
    /// t_N = min(0, ε_N g_N): λ_N stays 0, the penetration is ε_N-dependent.
    Penalty,
    /// t_N = min(0, λ_N + ε_N g_N) with Uzawa updates λ_N ← t_N after each converged
    /// Newton solve until the penetration is below the tolerance.
    #[default]
    AugmentedLagrangian,
}

/// Where a pair's normal constraint is imposed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Integration {
    /// At the slave nodes, one closest-point projection each (the paper's
    /// node-to-surface method, eqs. 2.2, 6.2).
    #[default]
    Node,
    /// Integrated over the slave faces, segment by segment against the master cells,
    /// with multipliers at the slave nodes (`contact::mortar`): passes the contact
    /// patch test. Needs a face-set slave; friction acts at the slave nodes, bounded
    /// by the mortar pressure.
    Mortar,
}

/// The multiplier basis of a mortar pair (`contact::mortar`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum MortarMultipliers {
    /// Φ_s = N_s, the slave faces' bilinear functions.
    #[default]
    Standard,
    /// Biorthogonal to N_s per face (Wohlmuth 2000): each slave node couples only to
    /// its own multiplier.
    Dual,
}

/// Through which basis a mortar pair's master receives the contact forces
/// (`contact::mortar`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum MortarTransfer {
    /// The master body's facets (its own hex8 faces): the consistent nodal forces of
    /// a uniform pressure, the contact patch test exact with every master.
    #[default]
    Trace,
    /// The master surface's basis (the B-spline's Q_A, eq. 6.2): the variation of the
    /// gap, a symmetric tangent and smoother force histories in sliding; the patch
    /// test is exact only with facets.
    Surface,
    /// The master surface's basis recombined near its edges so that a uniform
    /// pressure gives the faces' consistent nodal forces (`contact::mortar::balance`):
    /// as smooth in sliding as `surface`, the patch test to the quadrature of the
    /// smooth basis.
    Balanced,
}

/// How a mortar pair's segments are cut and integrated (`contact::mortar::segment`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum MortarQuadrature {
    /// Each slave face cut by the master's cells (its facets), 7 points of degree 5
    /// per triangle: exact where the integrand is a polynomial per cell (the trace
    /// transfer, facet masters).
    #[default]
    Cells,
    /// Cut further by the smooth master's knot lines (chart edges on an atlas), 64
    /// points of degree 14 per triangle: the smooth basis integrated to round-off on
    /// a flat master (`transfer: balanced`: the patch test to 1e-8); many times the
    /// points.
    KnotSpans,
}

/// Settings of a pair, resolved (absolute lengths).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairSettings {
    pub eps_n: f64,
    pub enforcement: Enforcement,
    /// Largest accepted penetration (length), augmented Lagrangian.
    pub penetration_tolerance: f64,
    pub max_augmentations: u32,
    /// Retries of a failed solve with half the last Uzawa update (`solver::uzawa`).
    pub update_halvings: u32,
    /// Over-relaxation ω of the Uzawa update, λ_N ← min(0, λ_N + ω (t_N − λ_N)),
    /// 1 ≤ ω < 2 (1: the plain update λ_N ← t_N).
    pub uzawa_relaxation: f64,
    /// Coulomb coefficient μ and tangential penalty ε_T (μ = 0: frictionless).
    pub mu: f64,
    pub eps_t: f64,
    /// Master-surface stabilisation factor η (0: off): an artificial inertia of
    /// stiffness η ε_N Ā_s on the master net's nodes (`solver::stabilization`).
    pub stabilization: f64,
    /// Node-to-surface or mortar (`contact::mortar`).
    pub integration: Integration,
    /// Mortar: the multiplier basis.
    pub multipliers: MortarMultipliers,
    /// Mortar: the basis the master receives the forces through.
    pub transfer: MortarTransfer,
    /// Mortar: how the segments are cut and integrated.
    pub quadrature: MortarQuadrature,
}

impl PairSettings {
    pub fn frictional(&self) -> bool {
        self.mu > 0.0
    }
}
