//! The contact law of one slave node, as data: the normal law t_N = min(0, λ_N +
//! ε_N g_N) with its multiplier, penalty and tributary area (eq. 4.2), Coulomb's
//! law with the node's history (eqs. 4.5–4.8), what an evaluation gives back, and
//! the one way it can fail. The elements ([`super::element`], [`super::friction`],
//! [`super::mortar`]) evaluate them.

use crate::spline::Vec3;

/// Outcome of one slave-node evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactState {
    /// Normal gap g_N = (x_s − x̄)·n̄ (negative = penetration).
    pub g_n: f64,
    /// Contact pressure t_N = min(0, λ_N + ε_N g_N) (≤ 0; compressive).
    pub t_n: f64,
    /// Whether λ_N + ε_N g_N < 0 (the node carries force).
    pub active: bool,
}

/// The local contact problem has no unique solution.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ContactElementError {
    /// ā_αβ − g_N b̄_αβ is singular: the slave node sits at a centre of curvature of
    /// the master (so deep inside it that the closest point is not unique).
    #[error("slave node at a centre of curvature of the master (g_N = {g_n:e}): the closest point is not unique")]
    FocalPoint { g_n: f64 },
}

/// The contact law of one slave node (eq. 4.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalLaw {
    /// Lagrange multiplier λ_N (≤ 0), fixed during a Newton solve.
    pub lambda_n: f64,
    /// Penalty ε_N.
    pub eps_n: f64,
    /// Tributary area A_s of the slave node (eq. 6.1).
    pub area: f64,
    /// A node that is not active but has λ_N + ε_N g_N ≤ ε_N·touch (touching within
    /// `touch`, a length) contributes the closed-branch stiffness ε_N A_s N Nᵀ with no
    /// force, so a body that starts touching is not free (see `docs/theory.md`).
    pub touch: f64,
}

/// Friction parameters and the history of one slave node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionLaw {
    /// Coulomb coefficient μ.
    pub mu: f64,
    /// Tangential penalty ε_T (traction per unit slip).
    pub eps_t: f64,
    /// Converged foot point ξ̄_n of the previous increment.
    pub xi_n: [f64; 2],
    /// Converged covariant tangential traction t_{Tα,n} (zero if the node was not in contact).
    pub t_t_n: [f64; 2],
    /// The return mapping's branch held by the solver (`Some(true)`: slip), or `None`:
    /// chosen by the slip criterion (eq. 4.8). See `PairSolver::freeze`.
    pub held_slip: Option<bool>,
}

impl FrictionLaw {
    /// No friction (μ = ε_T = 0, no history): the evaluation gives normal contact alone.
    pub const NONE: FrictionLaw = FrictionLaw { mu: 0.0, eps_t: 0.0, xi_n: [0.0; 2], t_t_n: [0.0; 2], held_slip: None };
}

/// Outcome of one frictional slave-node evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionState {
    pub g_n: f64,
    pub t_n: f64,
    pub active: bool,
    /// Covariant tangential traction t_Tα.
    pub t_t: [f64; 2],
    /// Tangential traction vector t_T = t_Tα ā^{αβ} ā_β (as a traction the slave exerts
    /// on the master; the master pushes the slave with −t_T).
    pub t_t_vector: Vec3,
    /// Whether the return mapping slipped (Φ > 0).
    pub slip: bool,
    /// Force the master exerts on the slave node, −r_s (normal and tangential).
    pub slave_force: Vec3,
}
