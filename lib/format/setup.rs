//! The solve setup (`sc-solve --setup solve.yaml`, or inline under a pipeline's
//! `solve` stage), documented key by key in `docs/pipelines.md`.
//!
//! ```yaml
//! formulation: updated_lagrangian
//! materials:
//!   - {body: lower, model: neo_hookean, E: 1.0e4, nu: 0.3}
//! constraints:
//!   - {set: lower_base, fix: [x, y, z]}
//!   - {set: top, displacement: {z: -1.0}}
//! loads:
//!   - {set: load_node, force: [0, 0, -100]}
//!   - {face_set: upper_top, pressure: 2.0}
//! increments: {count: 10}
//! newton: {max_iterations: 25, residual_tolerance: 1.0e-8}
//! ```

use serde::{Deserialize, Serialize};

// The contact settings are the contact layer's own plain data; this file reads
// and writes them (re-exported here, where the setup's readers look for them).
pub use crate::contact::settings::{Enforcement, Integration, MortarMultipliers, MortarQuadrature, MortarTransfer, UPDATE_HALVINGS};

/// Material models.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelName {
    /// Compressible neo-Hookean, Ciarlet–Simo form (paper eq. 3.3 / 8.1).
    NeoHookean,
    /// Deviatoric/volumetric neo-Hookean of ANSYS and CalculiX (paper eq. 8.2 / 8.3).
    NeoHookeanDevVol,
    /// Small-strain linear elasticity (geometrically linear), for checks.
    LinearElastic,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSetup {
    /// Body name (a gmsh physical volume).
    pub body: String,
    pub model: ModelName,
    /// Young's modulus (give `E` and `nu`, or `lambda` and `mu`).
    #[serde(rename = "E")]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub e: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nu: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lambda: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mu: Option<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    TotalLagrangian,
    UpdatedLagrangian,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Component {
    X,
    Y,
    Z,
}

impl Component {
    pub fn index(self) -> usize {
        match self {
            Self::X => 0,
            Self::Y => 1,
            Self::Z => 2,
        }
    }
}

/// Prescribed displacement components, ramped with the load factor.
#[derive(Debug, Clone, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Components {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub y: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z: Option<f64>,
}

impl Components {
    pub fn as_array(&self) -> [Option<f64>; 3] {
        [self.x, self.y, self.z]
    }
}

/// A Dirichlet condition on a node set: `fix` components to zero and/or prescribe
/// `displacement` components (scaled by the load factor), or move the set rigidly:
/// `rotation` (about a fixed axis, after the `displacement` translation).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ConstraintSetup {
    pub set: String,
    #[serde(default)]
    pub fix: Vec<Component>,
    #[serde(default)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub displacement: Option<Components>,
    /// Amplitude of `displacement` over the load factor ("time") t: a name from
    /// `curves`; default the ramp a(t) = t.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curve: Option<String>,
    #[serde(default)]
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotation: Option<RotationSetup>,
}

/// A prescribed finite rotation of a node set by `angle` (radians, at amplitude 1)
/// about the axis through `center` along `axis` (right-handed): every node goes to
/// x = c + R(θ a(t)) (X + d(t) − c), d the constraint's `displacement` (all three
/// components prescribed; missing ones are zero).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RotationSetup {
    pub axis: [f64; 3],
    #[serde(default)]
    pub center: [f64; 3],
    pub angle: f64,
    /// Amplitude of the angle: a name from `curves`; default the ramp a(t) = t.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curve: Option<String>,
}

/// A load: a force on a node set (total, spread evenly over its nodes, or
/// `per_node`), or a follower pressure on a face set. Scaled by the load factor.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSetup {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub set: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub force: Option<[f64; 3]>,
    #[serde(default)]
    pub per_node: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub face_set: Option<String>,
    /// Follower pressure (positive pushes against the face's outward normal).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pressure: Option<f64>,
    /// Amplitude over the load factor t (a name from `curves`; default a(t) = t).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub curve: Option<String>,
}

/// A piecewise-linear amplitude a(t) through `points` [[t, a], …] (t increasing),
/// constant beyond the ends — e.g. press then slide: a vertical displacement on
/// [[0, 0], [1, 1], [2, 1]] and a horizontal one on [[0, 0], [1, 0], [2, 1]].
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CurveSetup {
    pub name: String,
    pub points: Vec<[f64; 2]>,
}

/// Load factors ("time" t): `count` equal increments up to `end` (default 1), or an
/// explicit increasing list.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct IncrementSetup {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub count: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub factors: Option<Vec<f64>>,
    /// How many times an increment may be halved before the solve stops.
    #[serde(default = "default_cutbacks")]
    pub max_cutbacks: u32,
    /// Final load factor for `count` (default 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end: Option<f64>,
}

fn default_cutbacks() -> u32 {
    5
}

impl Default for IncrementSetup {
    fn default() -> Self {
        Self { count: Some(1), factors: None, max_cutbacks: default_cutbacks(), end: None }
    }
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct NewtonSetup {
    #[serde(default = "default_max_iterations")]
    pub max_iterations: u32,
    /// ‖R_free‖ ≤ tol · max(‖F_ext‖, ‖reactions‖, tiny).
    #[serde(default = "default_residual_tol")]
    pub residual_tolerance: f64,
    /// |Δu_{i−1} · R_i| ≤ tol · |Δu_0 · R_0|; falls like r_{i−1}·r_i near the solution,
    /// so 1e-12 matches a residual tolerance of 1e-8.
    #[serde(default = "default_energy_tol")]
    pub energy_tolerance: f64,
    /// Newton iterations in which the contact search may move a slave node to another
    /// master element (facet); after them — or as soon as the contact configuration
    /// cycles — the elements are held until the solve converges (0: never hold).
    #[serde(default = "default_search_updates")]
    pub search_updates: u32,
    /// Backtracking line search: from the second correction of a solve on, a
    /// correction that raises ‖R_f‖ is halved (up to `max_step_halvings` times; the
    /// last one is taken if none lowers it).
    #[serde(default = "default_true")]
    pub line_search: bool,
    /// A Newton correction that inverts an element (or, with `line_search`, raises
    /// the residual) is halved up to this many times; an inverted element then cuts
    /// the increment back.
    #[serde(default = "default_step_halvings")]
    pub max_step_halvings: u32,
    /// Penetration step limit: the deepest a slave node without contact stiffness
    /// may be carried past the master by one correction, in mean master edge
    /// lengths; a longer correction is shortened to it (0: no limit).
    #[serde(default = "default_penetration_step_limit")]
    pub penetration_step_limit: f64,
    /// Viscous damping β of the bodies whose rigid modes no constraint holds, as a
    /// share of an element's nodal stiffness G h̄ (`solver::free_bodies`; 0: off).
    #[serde(default)]
    pub free_body_damping: f64,
    /// Assemble an iterate's residual alone first when Newton's quadratic rate
    /// predicts that it has converged (the tangent follows only if it has not): the
    /// converged iterate of each solve then costs a quarter of an assembly. The
    /// iterates and results are the same bit for bit either way.
    #[serde(default = "default_true")]
    pub residual_first: bool,
}

fn default_max_iterations() -> u32 {
    25
}
fn default_residual_tol() -> f64 {
    1e-8
}
fn default_energy_tol() -> f64 {
    1e-12
}
fn default_search_updates() -> u32 {
    10
}
fn default_true() -> bool {
    true
}
fn default_step_halvings() -> u32 {
    6
}
fn default_penetration_step_limit() -> f64 {
    0.5
}

impl Default for NewtonSetup {
    fn default() -> Self {
        Self {
            max_iterations: default_max_iterations(),
            residual_tolerance: default_residual_tol(),
            energy_tolerance: default_energy_tol(),
            search_updates: default_search_updates(),
            line_search: true,
            max_step_halvings: default_step_halvings(),
            penetration_step_limit: default_penetration_step_limit(),
            free_body_damping: 0.0,
            residual_first: true,
        }
    }
}

/// Which linear solver a Newton iteration uses (`linear_solver:`, or its `method:`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum LinearSolverChoice {
    /// Cholesky while the tangent is symmetric (LDLᵀ if it is indefinite); GMRES
    /// preconditioned by the symmetric part's factorization when it is not.
    #[default]
    Auto,
    Cholesky,
    Ldlt,
    /// faer's sparse LU (COLAMD ordering, partial pivoting).
    Lu,
    /// GMRES preconditioned by the factorization of the symmetric part (LU fallback).
    Gmres,
    /// faer's direct solvers whatever the size: Cholesky for a symmetric tangent,
    /// GMRES on the symmetric part's factorization otherwise (what `auto` does
    /// below [`PetscSetup::auto_above_dofs`]).
    Direct,
    /// PETSc: CG or GMRES with algebraic multigrid (GAMG), under MPI when run by
    /// `mpirun` (needs a build with `--features petsc`).
    Petsc,
}

/// Dofs from which `auto` takes PETSc, in a build that has it: measured on the
/// frictional crossed beams (`docs/performance.md`, "PETSc and algebraic
/// multigrid").
pub const AUTO_PETSC_ABOVE_DOFS: u64 = 300_000;

/// The PETSc backend's settings (`linear_solver: {method: petsc, petsc: {...}}`).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct PetscSetup {
    /// PETSc options, after the defaults and before the command line's
    /// `--petsc-options`, e.g. `"-ksp_type bcgs -pc_gamg_threshold 0.02"`.
    pub options: String,
    /// Relative residual of the Krylov solve, unless the inexact Newton's forcing
    /// term is larger.
    pub tolerance: f64,
    /// Most Krylov iterations per solve before the MUMPS fallback.
    pub max_iterations: u32,
    /// Rebuild the multigrid hierarchy when a solve needs more than this factor (+5)
    /// of the iterations right after the last rebuild (0: every Newton iteration).
    pub reuse_growth: f64,
    /// `auto` takes PETSc from this many dofs (unknowns, free and held), when built in.
    pub auto_above_dofs: u64,
    /// Largest system (dofs) the MUMPS fallback factors; above it a solve that needs
    /// it fails and the load step is cut back.
    pub direct_fallback_max_dofs: u64,
}

impl Default for PetscSetup {
    fn default() -> Self {
        Self { options: String::new(), tolerance: 1e-10, max_iterations: 500, reuse_growth: 1.5, auto_above_dofs: AUTO_PETSC_ABOVE_DOFS, direct_fallback_max_dofs: 300_000 }
    }
}

/// Fill-reducing ordering of the Cholesky-type factorizations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum OrderingChoice {
    /// METIS nested dissection on the node graph.
    NestedDissection,
    /// faer's approximate minimum degree.
    Amd,
    /// Nested dissection by coordinate planes through the mesh
    /// (`solver::ordering::geometric`): the default.
    #[default]
    Geometric,
}

/// Precision of a symmetric tangent's Cholesky factor under `direct`, `gmres` and
/// `auto`, whose solves GMRES makes exact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum PrecisionChoice {
    /// `f32` values: half the factor's memory and traffic; every solve by GMRES (a
    /// fresh factor's to the round-off floor, a kept one's to `gmres_tolerance`),
    /// and a factor that `f32` cannot hold is made in `f64`.
    #[default]
    Single,
    /// `f64` values: a fresh factor of a symmetric tangent solves directly.
    Double,
}

/// The linear solver: `linear_solver: auto` (a method alone) or a map with these keys.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LinearSolverSetup {
    pub method: LinearSolverChoice,
    pub ordering: OrderingChoice,
    /// Precision of a symmetric tangent's Cholesky factor under `direct` / `gmres`
    /// (`cholesky`, `ldlt` and the symmetric part of a non-symmetric tangent always
    /// factor in double).
    pub factor_precision: PrecisionChoice,
    /// GMRES: relative residual ‖b − K x‖/‖b‖ to reach.
    pub gmres_tolerance: f64,
    /// GMRES: most iterations per solve before the LU fallback.
    pub gmres_max_iterations: u32,
    /// GMRES: keep the factorization of the symmetric part for the next Newton
    /// iteration while a solve needs at most this many iterations (0: factor every
    /// iteration).
    pub preconditioner_reuse: u32,
    /// Inexact Newton: each GMRES solve stops at η = min(1e-3, 1e-2 r) relative to
    /// its right-hand side, r being Newton's relative residual (never below
    /// `gmres_tolerance`); `false`: every solve to `gmres_tolerance`.
    pub inexact_newton: bool,
    /// The PETSc backend (`method: petsc`, or `auto` on a large model).
    pub petsc: PetscSetup,
}

impl Default for LinearSolverSetup {
    fn default() -> Self {
        Self {
            method: LinearSolverChoice::Auto,
            ordering: OrderingChoice::Geometric,
            factor_precision: PrecisionChoice::default(),
            gmres_tolerance: 1e-12,
            gmres_max_iterations: 100,
            preconditioner_reuse: 8,
            inexact_newton: true,
            petsc: PetscSetup::default(),
        }
    }
}

impl From<LinearSolverChoice> for LinearSolverSetup {
    fn from(method: LinearSolverChoice) -> Self {
        Self { method, ..Default::default() }
    }
}

/// The map form of [`LinearSolverSetup`], every key optional.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LinearSolverMap {
    #[serde(default)]
    method: LinearSolverChoice,
    #[serde(default)]
    ordering: OrderingChoice,
    #[serde(default)]
    factor_precision: PrecisionChoice,
    gmres_tolerance: Option<f64>,
    gmres_max_iterations: Option<u32>,
    preconditioner_reuse: Option<u32>,
    inexact_newton: Option<bool>,
    #[serde(default)]
    petsc: PetscSetup,
}

impl<'de> Deserialize<'de> for LinearSolverSetup {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = LinearSolverSetup;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a method (auto, direct, cholesky, ldlt, lu, gmres, petsc) or a map with keys method, ordering, factor_precision, gmres_tolerance, gmres_max_iterations, preconditioner_reuse, inexact_newton, petsc")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Self::Value, E> {
                let method = LinearSolverChoice::deserialize(serde::de::value::StrDeserializer::<E>::new(v))?;
                Ok(method.into())
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
                let m = LinearSolverMap::deserialize(serde::de::value::MapAccessDeserializer::new(map))?;
                let d = LinearSolverSetup::default();
                let tolerance = m.gmres_tolerance.unwrap_or(d.gmres_tolerance);
                if !(tolerance > 0.0 && tolerance < 1.0) {
                    return Err(serde::de::Error::custom(format!("gmres_tolerance must lie in (0, 1), got {tolerance}")));
                }
                let p = &m.petsc;
                if !(p.tolerance > 0.0 && p.tolerance < 1.0) {
                    return Err(serde::de::Error::custom(format!("petsc.tolerance must lie in (0, 1), got {}", p.tolerance)));
                }
                if !(p.reuse_growth >= 0.0 && p.reuse_growth.is_finite()) {
                    return Err(serde::de::Error::custom(format!("petsc.reuse_growth must be 0 or positive, got {}", p.reuse_growth)));
                }
                if p.options.contains('\0') {
                    return Err(serde::de::Error::custom("petsc.options contains a NUL character"));
                }
                Ok(LinearSolverSetup {
                    method: m.method,
                    ordering: m.ordering,
                    factor_precision: m.factor_precision,
                    gmres_tolerance: tolerance,
                    gmres_max_iterations: m.gmres_max_iterations.unwrap_or(d.gmres_max_iterations),
                    preconditioner_reuse: m.preconditioner_reuse.unwrap_or(d.preconditioner_reuse),
                    inexact_newton: m.inexact_newton.unwrap_or(d.inexact_newton),
                    petsc: m.petsc,
                })
            }
        }
        deserializer.deserialize_any(Visitor)
    }
}

/// Contact settings of one pair of the `.sccontact` model (by its name).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSetup {
    /// Pair name, as given to `sc-tag`.
    pub pair: String,
    /// Normal penalty ε_N: traction per unit penetration (force/length³); for a slave
    /// given as a node set (no tributary area) force per unit penetration. Default:
    /// 25 G/h (`solver::problem::default_penalty`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eps_n: Option<f64>,
    #[serde(default)]
    pub enforcement: Enforcement,
    /// Where the constraint is imposed: `node` (default) or `mortar`.
    #[serde(default, skip_serializing_if = "is_node")]
    pub integration: Integration,
    /// Mortar integration: the multiplier basis, `standard` (default) or `dual`.
    #[serde(default, skip_serializing_if = "is_standard")]
    pub multipliers: MortarMultipliers,
    /// Mortar integration: `trace` (default), `surface` or `balanced`.
    #[serde(default, skip_serializing_if = "is_trace")]
    pub transfer: MortarTransfer,
    /// Mortar integration: the segments cut by the master's `cells` (default) or
    /// further by its `knot_spans`, with a rule of higher degree.
    #[serde(default, skip_serializing_if = "is_cells")]
    pub quadrature: MortarQuadrature,
    /// Largest accepted penetration −g_N (a length), augmented Lagrangian only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub penetration_tolerance: Option<f64>,
    /// The same relative to the master's mean element edge length (default 1e-3 when
    /// neither is given).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub penetration_tolerance_relative: Option<f64>,
    /// Most Uzawa updates per increment.
    #[serde(default = "default_max_augmentations")]
    pub max_augmentations: u32,
    /// How often a Newton solve that fails after an Uzawa update is retried with half
    /// the update before the load step is cut back (`solver::uzawa`).
    #[serde(default = "default_update_halvings")]
    pub update_halvings: u32,
    /// Over-relaxation ω of the Uzawa update, λ_N ← min(0, λ_N + ω (t_N − λ_N)),
    /// 1 ≤ ω < 2 (default 1: λ_N ← t_N; `docs/theory/contact.md`).
    #[serde(default = "default_uzawa_relaxation", skip_serializing_if = "is_one")]
    pub uzawa_relaxation: f64,
    /// Coulomb friction coefficient μ (0: frictionless).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub mu: f64,
    /// Tangential penalty ε_T (traction per unit elastic slip); default ε_N.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub eps_t: Option<f64>,
    /// Master-surface stabilisation factor η (0, the default: off): the master net's
    /// nodes get an artificial inertia of stiffness η ε_N Ā_s against their motion
    /// extrapolated from the last two increments (`solver::stabilization`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub stabilization: f64,
    /// Adjust distance (Abaqus ADJUST, ANSYS ICONT): before the first increment,
    /// every slave node that projects onto the master with |g_N| ≤ this distance is
    /// moved onto the master, stress-free (its reference coordinates change;
    /// `contact::adjust`). Absent or 0: off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub adjust: Option<f64>,
    /// Solve even though the master normal n̄ points away from the slave body
    /// (`check::orientation`); without it such a pair is refused.
    #[serde(default, skip_serializing_if = "is_false")]
    pub allow_flipped_master: bool,
}

fn is_cells(v: &MortarQuadrature) -> bool {
    *v == MortarQuadrature::Cells
}

fn is_trace(v: &MortarTransfer) -> bool {
    *v == MortarTransfer::Trace
}

fn is_standard(v: &MortarMultipliers) -> bool {
    *v == MortarMultipliers::Standard
}

fn is_node(v: &Integration) -> bool {
    *v == Integration::Node
}

fn default_uzawa_relaxation() -> f64 {
    1.0
}

fn is_one(v: &f64) -> bool {
    *v == 1.0
}

fn is_false(v: &bool) -> bool {
    !*v
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn default_max_augmentations() -> u32 {
    20
}

fn default_update_halvings() -> u32 {
    UPDATE_HALVINGS
}

/// The whole setup.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SolveSetup {
    #[serde(default = "default_formulation")]
    pub formulation: Formulation,
    pub materials: Vec<MaterialSetup>,
    #[serde(default)]
    pub constraints: Vec<ConstraintSetup>,
    #[serde(default)]
    pub loads: Vec<LoadSetup>,
    #[serde(default)]
    pub increments: IncrementSetup,
    #[serde(default)]
    pub newton: NewtonSetup,
    #[serde(default)]
    pub linear_solver: LinearSolverSetup,
    /// Named amplitudes for constraints and loads.
    #[serde(default)]
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub curves: Vec<CurveSetup>,
    /// Settings per contact pair (input must then be a `.sccontact`).
    #[serde(default)]
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub contact: Vec<ContactSetup>,
}

/// The paper's (sec. 3: "written in the current configuration"), and the cheaper
/// tangent (docs/performance.md, "The hex8 element").
fn default_formulation() -> Formulation {
    Formulation::UpdatedLagrangian
}

/// A setup could not be read.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct SetupError {
    pub path: String,
    pub message: String,
}

/// The most equal load steps `increments.count` may ask for: the load factors are
/// built as a list, and a count no run could reach must be an error, not an
/// allocation (a setup of a few bytes asking for 10^12 increments).
pub const MAX_INCREMENTS: u32 = 1_000_000;

impl SolveSetup {
    pub fn parse(path: &str, text: &str) -> Result<Self, SetupError> {
        serde_yaml::from_str(text).map_err(|e| SetupError { path: path.into(), message: e.to_string() })
    }

    pub fn read(path: &std::path::Path) -> Result<Self, SetupError> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SetupError { path: shown.clone(), message: format!("cannot read: {e}") })?;
        Self::parse(&shown, &text)
    }

    /// The load factors of the converged increments to reach, increasing, ending at 1
    /// (or at the list's last entry).
    pub fn load_factors(&self, path: &str) -> Result<Vec<f64>, SetupError> {
        let err = |m: String| SetupError { path: path.into(), message: m };
        match (&self.increments.count, &self.increments.factors) {
            (Some(_), Some(_)) => Err(err("increments: give `count` or `factors`, not both".into())),
            (_, Some(_)) if self.increments.end.is_some() => Err(err("increments: `end` goes with `count`; `factors` already ends where it ends".into())),
            (_, Some(f)) => {
                if f.is_empty() || f.iter().any(|x| !x.is_finite() || *x <= 0.0) || f.windows(2).any(|w| w[1] <= w[0]) {
                    Err(err(format!("increments.factors must be positive and strictly increasing, found {f:?}")))
                } else {
                    Ok(f.clone())
                }
            }
            (Some(0), None) => Err(err("increments.count must be at least 1".into())),
            (Some(n), None) if *n > MAX_INCREMENTS => Err(err(format!("increments.count {n} is more than {MAX_INCREMENTS}, the most this build takes (each increment is a nonlinear solve and a segment of the results file)"))),
            (Some(n), None) => {
                let end = self.increments.end.unwrap_or(1.0);
                if !(end.is_finite() && end > 0.0) {
                    return Err(err(format!("increments.end must be a positive number, found {end}")));
                }
                Ok((1..=*n).map(|i| end * i as f64 / *n as f64).collect())
            }
            (None, None) => Ok(vec![1.0]),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_setup_parses() {
        let y = "materials:\n  - {body: b, model: neo_hookean, E: 1.0e4, nu: 0.3}\nconstraints:\n  - {set: base, fix: [x, y, z]}\n  - {set: top, displacement: {z: -1.0}}\nloads:\n  - {set: p, force: [0, 0, -1]}\n  - {face_set: f, pressure: 2}\nincrements: {factors: [0.5, 1.0]}\nnewton: {max_iterations: 10}\nlinear_solver: lu\n";
        let s = SolveSetup::parse("s.yaml", y).unwrap();
        assert_eq!(s.load_factors("s").unwrap(), vec![0.5, 1.0]);
        assert_eq!(s.linear_solver, LinearSolverChoice::Lu.into());
        assert_eq!(s.constraints[1].displacement.as_ref().unwrap().z, Some(-1.0));
    }

    /// A count no run reaches is an error, not a list of 4·10⁹ load factors (found by
    /// the fuzzer: `count: 4294967295` asked for 32 GiB).
    #[test]
    fn an_impossible_increment_count_is_refused() {
        let s = SolveSetup::parse("s", "materials: []\nincrements: {count: 4294967295}\n").unwrap();
        let e = s.load_factors("s").unwrap_err().to_string();
        assert!(e.contains("increments.count 4294967295 is more than 1000000"), "{e}");
        let s = SolveSetup::parse("s", "materials: []\nincrements: {count: 1000000}\n").unwrap();
        assert_eq!(s.load_factors("s").unwrap().len(), 1_000_000);
    }

    #[test]
    fn unknown_key_and_model_are_named_with_line() {
        let e = SolveSetup::parse("s.yaml", "materials:\n  - {body: b, model: neo_hookean, E: 1, nu: 0.3, rho: 2}\n").unwrap_err().to_string();
        assert!(e.contains("rho") && e.contains("line 2"), "{e}");
        let e = SolveSetup::parse("s.yaml", "materials:\n  - {body: b, model: mooney, E: 1, nu: 0.3}\n").unwrap_err().to_string();
        assert!(e.contains("mooney") && e.contains("neo_hookean"), "{e}");
    }

    #[test]
    fn linear_solver_as_a_word_or_a_map() {
        let s = SolveSetup::parse("s", "materials: []\nlinear_solver: gmres\n").unwrap();
        assert_eq!(s.linear_solver, LinearSolverChoice::Gmres.into());
        let s = SolveSetup::parse("s", "materials: []\nlinear_solver: {ordering: geometric}\n").unwrap();
        assert_eq!(s.linear_solver.ordering, OrderingChoice::Geometric);
        let s = SolveSetup::parse("s", "materials: []\nlinear_solver: {ordering: amd, gmres_tolerance: 1.0e-10}\n").unwrap();
        let d = LinearSolverSetup::default();
        assert_eq!(s.linear_solver, LinearSolverSetup { ordering: OrderingChoice::Amd, gmres_tolerance: 1e-10, ..d.clone() });
        // the default, and what a results file's setup echo reads back
        let s = SolveSetup::parse("s", "materials: []\n").unwrap();
        assert_eq!(s.linear_solver, d);
        let echo = serde_yaml::to_string(&s).unwrap();
        assert_eq!(SolveSetup::parse("echo", &echo).unwrap().linear_solver, d);
        let s = SolveSetup::parse("s", "materials: []\nlinear_solver: {method: petsc, petsc: {options: -ksp_type bcgs, max_iterations: 50}}\n").unwrap();
        assert_eq!(s.linear_solver.method, LinearSolverChoice::Petsc);
        assert_eq!((s.linear_solver.petsc.options.as_str(), s.linear_solver.petsc.max_iterations), ("-ksp_type bcgs", 50));
        assert_eq!(s.linear_solver.petsc.tolerance, PetscSetup::default().tolerance);
        for (text, expect) in [
            ("linear_solver: superlu\n", "unknown variant `superlu`"),
            ("linear_solver: {method: lu, orderng: amd}\n", "unknown field `orderng`"),
            ("linear_solver: {gmres_tolerance: 2}\n", "gmres_tolerance must lie in (0, 1)"),
            ("linear_solver: [lu]\n", "a method (auto, direct, cholesky, ldlt, lu, gmres, petsc) or a map"),
            ("linear_solver: {method: petsc, petsc: {tolerance: 0}}\n", "petsc.tolerance must lie in (0, 1)"),
            ("linear_solver: {method: petsc, petsc: {option: -ksp_monitor}}\n", "unknown field `option`"),
        ] {
            let e = SolveSetup::parse("s.yaml", &format!("materials: []\n{text}")).unwrap_err().to_string();
            assert!(e.contains(expect) && e.contains("line 2"), "{text}: {e}");
        }
    }

    #[test]
    fn count_gives_equal_steps() {
        let s = SolveSetup::parse("s", "materials: []\nincrements: {count: 4}\n").unwrap();
        assert_eq!(s.load_factors("s").unwrap(), vec![0.25, 0.5, 0.75, 1.0]);
    }
}
