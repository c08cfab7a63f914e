//! Newton–Raphson for one load increment (style: deal.II step-44): assemble the
//! residual R(u) = f_int(u) − f_ext(λ) and the tangent K_ff, solve K_ff Δu = −R_f,
//! update, until the residual (relative to the external or reaction force) and the
//! energy norm of the correction are both below tolerance.
//!
//! With contact the residual is only piecewise smooth, so three safeguards apply
//! (docs/theory/robustness.md): a correction that inverts an element, or (from the
//! second on) raises ‖R_f‖, is halved; after `search_updates` iterations, or at a
//! 2-cycle of the contact configuration, the pairs hold their master facets and
//! stick/slip branches ([`PairSolver::freeze`]) until the solve converges; a 2-cycle
//! that persists fails the increment, naming the nodes.
//!
//! This file holds the workspace, [`Newton`]: its construction (pattern, assembly
//! workspace, linear solver) and its public API. One concept per file:
//! - `iteration.rs`: the iteration of one increment and its convergence checks;
//! - `step_control.rs`: halving a correction, the line search, the penetration step limit;
//! - `cycles.rs`: cycling contact configurations, holding the search;
//! - `assemble.rs`: one iterate's contact search, pattern and K_ff, R;
//! - `groups.rs`: the pattern's node groups (pressure faces, contact elements);
//! - `partition.rs`: the share of the assembly of one of several MPI ranks;
//! - `reactions.rs`: the residual at the constrained dofs;
//! - `history.rs`: what a converged increment hands the next, restarts;
//! - `failure.rs`: why setting up or an increment fails;
//! - `stresses.rs`: Cauchy stress at the Gauss points.

#![allow(non_snake_case)] // paper notation: X (reference coordinates)

mod assemble;
mod cycles;
mod failure;
mod groups;
mod history;
mod iteration;
mod partition;
mod reactions;
mod step_control;
mod stresses;

pub use failure::{IncrementFailure, SetupFailure};
pub use stresses::gauss_stresses;

use crate::os::timeline;
use super::forcing::Forcing;
use super::free_bodies::{FreeBody, FreeBodyDamping};
use super::problem::Problem;
use super::ranks;
use super::stabilization::Stabilization;
use crate::assembly::{Assembly, NodeGroups, Pattern, DOFS_PER_NODE};
use crate::contact::pair::PairSolver;
use crate::format::scres::IterationLog;
use crate::format::setup::{LinearSolverChoice, LinearSolverSetup, NewtonSetup, OrderingChoice, PrecisionChoice};
use crate::solver::gmres::GmresSettings;
use crate::solver::linear::{FactorPrecision, FaerDirect, FaerDirectOptions, LinearSolver, SolverTimings, SymmetricStrategy, Symmetry};
use crate::solver::ordering::FillOrdering;
use crate::solver::symmetric_part::SymmetricPartGmres;
use groups::{contact_groups, GroupOwner};
use partition::Partition;

/// The loosest an inexact Newton's linear solve stops at (the first of each solve;
/// [`Forcing`]). Looser first solves (1e-2) measured more Newton iterations on the
/// frictional crossed beams.
const FORCING_MAX: f64 = 1e-3;

/// The PETSc backend for `problem`'s free dofs.
#[cfg(feature = "petsc")]
fn petsc_backend(setup: &LinearSolverSetup, problem: &Problem) -> Result<Box<dyn LinearSolver>, SetupFailure> {
    use super::petsc::{PetscKrylov, PetscSettings};
    let p = &setup.petsc;
    let settings = PetscSettings {
        options: p.options.clone(),
        tolerance: p.tolerance,
        max_iterations: p.max_iterations as usize,
        reuse_growth: p.reuse_growth,
        direct_fallback_max_dofs: p.direct_fallback_max_dofs as usize,
    };
    Ok(Box::new(PetscKrylov::new(settings, problem.dofs.global_of_free(), problem.n_nodes())?))
}

#[cfg(not(feature = "petsc"))]
fn petsc_backend(_setup: &LinearSolverSetup, _problem: &Problem) -> Result<Box<dyn LinearSolver>, SetupFailure> {
    Err(SetupFailure::PetscNotBuilt)
}

/// Newton workspace for one problem: the pattern, its symbolic factorization and the
/// buffers are built once and reused by every iteration of every increment.
pub struct Newton<'p> {
    pub problem: &'p Problem,
    settings: NewtonSetup,
    pattern: Pattern,
    assembly: Assembly,
    linear: Box<dyn LinearSolver>,
    residual: Vec<f64>,
    rhs: Vec<f64>,
    r_free: Vec<f64>,
    /// f_ext at the current load factor.
    f_ext: Vec<f64>,
    /// The contact pairs' state (search, multipliers, active sets).
    pub contact: Vec<PairSolver>,
    /// Owner of every group of `pattern`.
    owners: Vec<GroupOwner>,
    /// Under MPI with several ranks: the share of the assembly this rank does.
    partition: Option<Partition>,
    /// The contact search's groups, compared with the pattern's every iteration
    /// (storage reused).
    group_scratch: NodeGroups,
    /// Times the pattern was rebuilt because contact groups changed.
    pub pattern_rebuilds: u32,
    /// Iterates assembled residual first (`NewtonSetup::residual_first`), and how
    /// many of them had not converged and took the tangent after.
    pub residual_first: (usize, usize),
    /// The symmetry the linear solver was set up for.
    symmetry: Symmetry,
    /// Newton corrections halved because they inverted an element (all solves).
    pub step_halvings: u32,
    /// Corrections halved by the line search (all solves).
    pub line_search_steps: u32,
    /// The master-surface stabilisation of the pairs that ask for one.
    pub stabilization: Option<Stabilization>,
    /// The damping of the bodies only contact holds (`newton.free_body_damping`).
    pub free_bodies: Option<FreeBodyDamping>,
    /// λ of the last converged increment.
    lambda_n: f64,
    /// The iteration at which the current solve held the contact search's master
    /// elements, and why ([`PairSolver::freeze`]); `None` while they may change.
    pub frozen_at: Option<(u32, &'static str)>,
    /// What the solve had to say since the log last took these (an iterative
    /// solve handed to its direct fallback, a correction the penetration step
    /// limit shortened).
    pub notes: Vec<String>,
    /// The length the schedule planned for the increment being solved (the
    /// stabilisation stiffens when a cutback shortens it).
    pub planned_step: Option<f64>,
    /// Mortar pairs hold their segmentation from a relative residual of 1e-1
    /// instead of 1e-5 (`iteration::MORTAR_EARLY_HOLD_RESIDUAL`): set by the
    /// increment loop for an increment that failed without it, until it converges.
    pub early_segmentation_hold: bool,
    /// A full-length Newton correction (storage reused by the step limit).
    du_full: Vec<f64>,
    /// Inexact Newton: an iterative linear solver's tolerance follows the residual
    /// (`None`: every solve to the solver's own tolerance).
    forcing: Option<Forcing>,
}

/// A converged increment's iteration history.
pub struct Converged {
    pub iterations: Vec<IterationLog>,
}

impl<'p> Newton<'p> {
    pub fn new(problem: &'p Problem, settings: NewtonSetup, linear_setup: LinearSolverSetup) -> Result<Self, SetupFailure> {
        let choice = linear_setup.method;
        let pairs_span = timeline::span("set-up: contact pairs (masters, projectors)");
        let mut contact = Vec::with_capacity(problem.contact.len());
        for def in &problem.contact {
            contact.push(PairSolver::new(def, &problem.X)?);
        }
        drop(pairs_span);
        let (_, ranks) = ranks::rank_and_size();
        let n_dofs = (DOFS_PER_NODE * problem.n_nodes()) as u64;
        let petsc = match choice {
            LinearSolverChoice::Petsc => true,
            LinearSolverChoice::Auto => cfg!(feature = "petsc") && (ranks > 1 || n_dofs >= linear_setup.petsc.auto_above_dofs),
            _ => false,
        };
        if ranks > 1 && !petsc {
            let name = match choice {
                LinearSolverChoice::Cholesky => "cholesky",
                LinearSolverChoice::Ldlt => "ldlt",
                LinearSolverChoice::Lu => "lu",
                LinearSolverChoice::Gmres => "gmres",
                _ => "direct",
            };
            return Err(SetupFailure::DirectUnderMpi(ranks, name));
        }
        // several ranks share the work (only the PETSc backend can: checked above)
        let partition = (ranks > 1).then(|| Partition::new(problem));
        let (mut owners, mut groups) = (Vec::new(), NodeGroups::new());
        let groups_span = timeline::span("set-up: first contact search (groups)");
        contact_groups(problem, &mut contact, &vec![0.0; DOFS_PER_NODE * problem.n_nodes()], &mut groups, &mut owners, partition.as_ref())?;
        drop(groups_span);
        if let Some(part) = &partition {
            part.keep_local_groups(&mut groups, &mut owners);
        }
        for pair in &mut contact {
            pair.init_history();
        }
        let hexes = partition.as_ref().map_or(&problem.hexes[..], |part| &part.hexes[..]);
        if !problem.symmetric() && matches!(choice, LinearSolverChoice::Cholesky | LinearSolverChoice::Ldlt) {
            let why = if problem.pressure_faces.is_empty() { "friction" } else { "follower pressure" };
            return Err(SetupFailure::NotSymmetric(if choice == LinearSolverChoice::Cholesky { "cholesky" } else { "ldlt" }, why));
        }
        let (symmetry, strategy) = match choice {
            LinearSolverChoice::Auto | LinearSolverChoice::Direct | LinearSolverChoice::Petsc if problem.symmetric() => {
                (Symmetry::Symmetric, SymmetricStrategy::LltThenLdlt)
            }
            LinearSolverChoice::Auto
            | LinearSolverChoice::Direct
            | LinearSolverChoice::Petsc
            | LinearSolverChoice::Lu
            | LinearSolverChoice::Gmres => (Symmetry::General, SymmetricStrategy::LltThenLdlt),
            LinearSolverChoice::Cholesky => (Symmetry::Symmetric, SymmetricStrategy::Llt),
            LinearSolverChoice::Ldlt => (Symmetry::Symmetric, SymmetricStrategy::Ldlt),
        };
        let direct = FaerDirectOptions {
            symmetric: strategy,
            ordering: match linear_setup.ordering {
                OrderingChoice::NestedDissection => FillOrdering::NestedDissection,
                OrderingChoice::Amd => FillOrdering::Amd,
                OrderingChoice::Geometric => FillOrdering::Geometric,
            },
            // a symmetric tangent's factor under `direct` / `gmres`, which GMRES makes
            // exact; `cholesky` and `ldlt` solve directly, in double, and the
            // symmetric part of a non-symmetric tangent stays double (a mildly
            // non-symmetric system then converges in one GMRES iteration to
            // round-off, which the mortar patch tests need; the frictional crossed
            // beams gained nothing from single)
            precision: match (choice, symmetry, linear_setup.factor_precision) {
                (LinearSolverChoice::Auto | LinearSolverChoice::Direct | LinearSolverChoice::Gmres, Symmetry::Symmetric, PrecisionChoice::Single) => FactorPrecision::Single,
                _ => FactorPrecision::Double,
            },
            ..Default::default()
        };
        let gmres = GmresSettings { tolerance: linear_setup.gmres_tolerance, max_iterations: linear_setup.gmres_max_iterations as usize, ..Default::default() };
        let mut linear: Box<dyn LinearSolver> = if petsc {
            petsc_backend(&linear_setup, problem)?
        } else {
            match choice {
                // the symmetric tangent's Cholesky factorization kept across Newton
                // iterations while GMRES solves with it quickly; the non-symmetric
                // one's GMRES on the factorization of its symmetric part
                LinearSolverChoice::Auto | LinearSolverChoice::Direct | LinearSolverChoice::Gmres => {
                    Box::new(SymmetricPartGmres::with_reuse(gmres, direct, linear_setup.preconditioner_reuse as usize))
                }
                _ => Box::new(FaerDirect::new(direct)),
            }
        };
        // each unknown's node position, for the ordering by coordinate planes (the
        // only reader: not made for METIS, AMD or PETSc)
        if direct.ordering == FillOrdering::Geometric && !petsc {
            let unknowns: std::sync::Arc<[[f64; 3]]> = problem.dofs.global_of_free().iter().map(|&g| {
                let x = &problem.X[g as usize / DOFS_PER_NODE];
                [x[0], x[1], x[2]]
            }).collect();
            linear.set_unknown_coordinates(unknowns);
        }
        // the first analysis starts as soon as the pattern's structure is known and
        // runs beside the element slot maps, the assembly workspace and the first
        // tangent's assembly; the first factorization waits for it (`solve_increment`)
        let pattern_span = timeline::span("set-up: sparsity pattern");
        let mut analysis = Ok(());
        let pattern = Pattern::build_then(problem.dofs.clone(), hexes, groups, |structure| analysis = linear.analyse_in_background(structure, symmetry))?;
        drop(pattern_span);
        analysis?;
        let workspace_span = timeline::span("set-up: assembly workspace");
        let assembly = Assembly::new(&pattern)?;
        drop(workspace_span);
        let n = DOFS_PER_NODE * problem.n_nodes();
        let n_free = pattern.n_free();
        let stabilization = Stabilization::new(problem, &contact);
        // Inexact Newton for the iterative solves of a non-symmetric tangent and
        // PETSc's; a symmetric tangent's factorization (fresh or kept, single or
        // double precision) solves to the GMRES tolerance, so Newton's iterates are
        // the direct solve's up to round-off.
        let iterative = petsc || symmetry == Symmetry::General;
        let forcing = (linear_setup.inexact_newton && iterative).then(|| Forcing::new(FORCING_MAX, settings.residual_tolerance));
        Ok(Self {
            problem,
            settings,
            pattern,
            assembly,
            linear,
            residual: vec![0.0; n],
            rhs: vec![0.0; n_free],
            r_free: vec![0.0; n_free],
            f_ext: vec![0.0; n],
            contact,
            owners,
            partition,
            group_scratch: NodeGroups::new(),
            pattern_rebuilds: 0,
            residual_first: (0, 0),
            symmetry,
            step_halvings: 0,
            line_search_steps: 0,
            stabilization,
            free_bodies: None,
            lambda_n: 0.0,
            frozen_at: None,
            notes: Vec::new(),
            planned_step: None,
            early_segmentation_hold: false,
            du_full: vec![0.0; n],
            forcing,
        })
    }

    /// The full residual R(u) and the free-dof tangent K_ff at `u` (external forces
    /// of the last increment solved, zero before any; contact search
    /// included), for checks against finite differences: `(residual, col_ptr,
    /// row_idx, values)`, K_ff in compressed sparse columns over the free dofs.
    pub fn residual_tangent_at(&mut self, u: &[f64], lambda: f64) -> Result<ResidualTangent, IncrementFailure> {
        self.contact_search(u, 0)?;
        let node_tags = &self.problem.node_tags;
        self.assemble(u, lambda, true).map_err(|f| f.into_increment_failure(0, &self.contact, node_tags))?;
        Ok((self.residual.clone(), self.pattern.col_ptr().to_vec(), self.pattern.row_idx().to_vec(), self.assembly.values().to_vec()))
    }

    /// Damp the bodies only contact holds (`bodies`, from the pre-solve check) with
    /// β = `beta` ([`FreeBodyDamping`]); nothing when there are none or β ≤ 0.
    pub fn damp_free_bodies(&mut self, bodies: Vec<FreeBody>, beta: f64) {
        if beta > 0.0 && bodies.iter().any(|b| !b.free.is_empty()) {
            self.free_bodies = Some(FreeBodyDamping::new(self.problem, bodies, beta));
        }
    }

    /// The stabilisation force ‖f‖ on each pair's master net at `u` (0 for a pair
    /// without one), in the order of `contact`.
    pub fn stabilization_forces(&self, u: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.contact.len()];
        if let Some(s) = &self.stabilization {
            for (k, f) in s.forces(u) {
                out[k] = f;
            }
        }
        out
    }

    /// Slave nodes pressed into the master at the last search, over all pairs.
    pub fn n_contact_pressed(&self) -> usize {
        self.contact.iter().map(|c| c.n_pressed()).sum()
    }

    pub fn n_free(&self) -> usize {
        self.pattern.n_free()
    }

    pub fn nnz(&self) -> usize {
        self.pattern.nnz()
    }

    /// A load increment's first attempt, or a cutback's next one, starts: the linear
    /// solver keeps no preconditioner from before (restarts continue bit for bit).
    pub fn begin_increment(&mut self) {
        self.linear.begin_increment();
    }

    pub fn linear_solver_name(&self) -> &str {
        self.linear.name()
    }

    /// The linear solver's accumulated timings and counts.
    pub fn linear_timings(&self) -> SolverTimings {
        self.linear.timings()
    }
}

/// `(residual, col_ptr, row_idx, values)` of [`Newton::residual_tangent_at`].
pub type ResidualTangent = (Vec<f64>, Vec<usize>, Vec<usize>, Vec<f64>);
