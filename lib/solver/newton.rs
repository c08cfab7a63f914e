//! Newton–Raphson for one load increment (style: deal.II step-44): assemble the
#![allow(non_snake_case)] // paper notation: X (reference coordinates)
//! residual R(u) = f_int(u) − f_ext(λ) and the tangent K_ff, solve K_ff Δu = −R_f,
//! update, until the residual (relative to the external or reaction force) and the
//! energy norm of the correction are both below tolerance.
//!
//! With contact the residual is only piecewise smooth, so three safeguards apply
//! (docs/theory.md, "Robustness"): a correction that inverts an element, or (from the
//! second on) raises ‖R_f‖, is halved; after `search_updates` iterations, or at a
//! 2-cycle of the contact configuration, the pairs hold their master facets and
//! stick/slip branches ([`PairSolver::freeze`]) until the solve converges; a 2-cycle
//! that persists fails the increment, naming the nodes.

use std::time::Instant;

use nalgebra::{DMatrix, DVector, Vector3};

use super::forcing::Forcing;
use super::free_bodies::{DampingReport, FreeBody, FreeBodyDamping};
use super::problem::Problem;
use super::ranks;
use super::stabilization::Stabilization;
use crate::assembly::{Assembly, AssemblyError, ElementFailure, NodeGroups, Pattern, PatternError, DOFS_PER_NODE};
use crate::contact::law::ContactElementError;
use crate::contact::pair::{PairError, PairSolver, SearchShare, SlaveConfiguration};
use crate::fem::element::{hex8_gauss_stresses, hex8_residual_tangent, ElementError};
use crate::fem::pressure::{follower_pressure_force_stiffness, FaceMatrix, FaceVector};
use crate::format::scres::{Increment, IterationLog};
use crate::format::setup::{LinearSolverChoice, LinearSolverSetup, NewtonSetup, OrderingChoice};
use crate::solver::gmres::GmresSettings;
use crate::solver::linear::{FaerDirect, FaerDirectOptions, LinearSolver, LinearSolverError, SolverTimings, SymmetricStrategy, Symmetry};
use crate::solver::ordering::FillOrdering;
use crate::solver::symmetric_part::SymmetricPartGmres;


/// Relative residual below which mortar pairs hold their segmentation for the rest
/// of the solve (`PairSolver::hold_segmentation`): the quadrature then no longer
/// moves, and what is left of the correction is far below the segments' size.
/// Measured on the shallow ironing (B-spline [2, 4], frictionless, to t = 1.1):
/// 1188 Newton corrections holding at 1e-5, 845 at 1e-3, 817 at 1e-2 (node-to-surface:
/// 724); but a segmentation held from 1e-2 on leaves the patch test's pressure off
/// by 5e-6 (the segments of a configuration that still moves), 1e-5 by ≤ 2.4e-9.
/// Re-segmenting a state that converged held, and going on when its residual is
/// above the tolerance, cycles at 3e-8–8e-8 on the ironing's first contact.
const MORTAR_HOLD_RESIDUAL: f64 = 1e-5;
/// The loosest an inexact Newton's linear solve stops at (the first of each solve;
/// [`Forcing`]). Looser first solves (1e-2) measured more Newton iterations on the
/// frictional crossed beams.
const FORCING_MAX: f64 = 1e-3;

/// Why an increment did not converge.
#[derive(Debug, Clone, thiserror::Error)]
pub enum IncrementFailure {
    #[error("iteration {iteration}: element {element} inverted or failed ({error})")]
    Element { iteration: u32, element: usize, error: ElementError },
    #[error("did not converge in {iteration} iterations: relative residual {residual:.3e}, energy {energy:.3e}")]
    NotConverged { iteration: u32, residual: f64, energy: f64 },
    #[error("iteration {iteration}: diverged (relative residual {residual:.3e})")]
    Diverged { iteration: u32, residual: f64 },
    #[error("iteration {iteration}: linear solver: {error}")]
    Linear { iteration: u32, error: LinearSolverError },
    #[error("iteration {iteration}: contact pair '{pair}', slave node {node_tag}: {error}")]
    Contact { iteration: u32, pair: String, node_tag: u64, error: ContactElementError },
    #[error("iteration {iteration}: {message}")]
    ContactSetup { iteration: u32, message: String },
    #[error("iteration {iteration}: the contact configuration cycles between {} states (relative residual {residual:.3e}): slave nodes {nodes} alternate between in and out of contact, between master elements or in and out of crease contact", period_name(*.period))]
    ContactCycling { iteration: u32, residual: f64, nodes: String, period: u32 },
}

/// "two", "three", "four" (the cycle lengths [`Newton`] detects).
fn period_name(p: u32) -> &'static str {
    match p {
        2 => "two",
        3 => "three",
        _ => "four",
    }
}

/// A local (element-level) failure during assembly.
#[derive(Debug, Clone)]
enum LocalFailure {
    Hex(ElementError),
    Contact(ContactElementError),
}

/// What a group of the sparsity pattern is.
#[derive(Debug, Clone, Copy)]
enum GroupOwner {
    /// A follower-pressure face (index into `problem.pressure_faces`).
    Pressure(usize),
    /// A contact element: (pair, slave index in the pair).
    Contact(usize, usize),
}

/// Setting the solver up failed (a mesh too large for the assembly's numbering, …).
#[derive(Debug, thiserror::Error)]
pub enum SetupFailure {
    #[error(transparent)]
    Pattern(#[from] PatternError),
    #[error(transparent)]
    Assembly(#[from] AssemblyError),
    #[error(transparent)]
    Linear(#[from] LinearSolverError),
    #[error(transparent)]
    Contact(#[from] PairError),
    #[error("linear_solver: {0} needs a symmetric tangent, and this problem's is not ({1}): use auto or lu")]
    NotSymmetric(&'static str, &'static str),
    #[error("linear_solver: petsc needs sc-solve built with the PETSc backend (cargo build --release --features petsc, with PETSc and MPI installed: docs/performance.md); this build has only faer's solvers: use auto or direct")]
    PetscNotBuilt,
    #[error("{0} MPI ranks need the PETSc backend (linear_solver: petsc or auto); linear_solver: {1} runs on one process: start it without mpirun")]
    DirectUnderMpi(usize, &'static str),
}

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
        let mut contact = Vec::with_capacity(problem.contact.len());
        for def in &problem.contact {
            contact.push(PairSolver::new(def, &problem.X)?);
        }
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
        contact_groups(problem, &mut contact, &vec![0.0; DOFS_PER_NODE * problem.n_nodes()], &mut groups, &mut owners, partition.as_ref())?;
        if let Some(part) = &partition {
            part.keep_local_groups(&mut groups, &mut owners);
        }
        for pair in &mut contact {
            pair.init_history();
        }
        let hexes = partition.as_ref().map_or(&problem.hexes[..], |part| &part.hexes[..]);
        let pattern = Pattern::build(problem.dofs.clone(), hexes, groups)?;
        let assembly = Assembly::new(&pattern)?;
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
            },
            ..Default::default()
        };
        let gmres = GmresSettings { tolerance: linear_setup.gmres_tolerance, max_iterations: linear_setup.gmres_max_iterations as usize, ..Default::default() };
        let mut linear: Box<dyn LinearSolver> = if petsc {
            petsc_backend(&linear_setup, problem)?
        } else {
            match (symmetry, choice) {
                (Symmetry::General, LinearSolverChoice::Auto | LinearSolverChoice::Direct | LinearSolverChoice::Gmres) => {
                    Box::new(SymmetricPartGmres::with_reuse(gmres, direct, linear_setup.preconditioner_reuse as usize))
                }
                _ => Box::new(FaerDirect::new(direct)),
            }
        };
        linear.analyse(pattern.symbolic(), symmetry)?;
        let n = DOFS_PER_NODE * problem.n_nodes();
        let n_free = pattern.n_free();
        let stabilization = Stabilization::new(problem, &contact);
        let forcing = linear_setup.inexact_newton.then(|| Forcing::new(FORCING_MAX, settings.residual_tolerance));
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
            symmetry,
            step_halvings: 0,
            line_search_steps: 0,
            stabilization,
            free_bodies: None,
            lambda_n: 0.0,
            frozen_at: None,
            notes: Vec::new(),
            planned_step: None,
            du_full: vec![0.0; n],
            forcing,
        })
    }

    /// Contact search at `u`; rebuilds the pattern (and the solver's symbolic
    /// analysis) if the contact groups changed.
    fn contact_search(&mut self, u: &[f64], iteration: u32) -> Result<(), IncrementFailure> {
        if self.contact.is_empty() {
            return Ok(());
        }
        let fail = |message: String| IncrementFailure::ContactSetup { iteration, message };
        let mut groups = std::mem::take(&mut self.group_scratch);
        contact_groups(self.problem, &mut self.contact, u, &mut groups, &mut self.owners, self.partition.as_ref()).map_err(|e| fail(e.to_string()))?;
        if let Some(part) = &self.partition {
            part.keep_local_groups(&mut groups, &mut self.owners);
        }
        let mut changed = [f64::from(u8::from(&groups != self.pattern.groups() || !self.assembly.fits(&self.pattern)))];
        if self.partition.is_some() {
            // the analysis of a new pattern is collective: every rank does it when
            // one rank's groups changed (its rows' entries did)
            ranks::reduce_over_ranks(&mut changed, ranks::Reduction::Max).map_err(|e| fail(format!("MPI: {e}")))?;
        }
        if changed[0] == 0.0 {
            self.group_scratch = groups;
        } else {
            self.pattern = self.pattern.with_groups(groups).map_err(|e| fail(e.to_string()))?;
            // the old workspace goes before the new one is built (peak memory); a
            // failure leaves the empty one, which `fits` no pattern: rebuilt next time
            self.assembly = Assembly::empty();
            self.assembly = Assembly::new(&self.pattern).map_err(|e| fail(e.to_string()))?;
            self.linear.analyse(self.pattern.symbolic(), self.symmetry).map_err(|error| IncrementFailure::Linear { iteration, error })?;
            self.pattern_rebuilds += 1;
        }
        Ok(())
    }

    /// The full residual R(u) and the free-dof tangent K_ff at `u` (external forces
    /// of the last increment solved, zero before any; contact search
    /// included), for checks against finite differences: `(residual, col_ptr,
    /// row_idx, values)`, K_ff in compressed sparse columns over the free dofs.
    pub fn residual_tangent_at(&mut self, u: &[f64], lambda: f64) -> Result<ResidualTangent, IncrementFailure> {
        self.contact_search(u, 0)?;
        let node_tags = &self.problem.node_tags;
        self.assemble(u, lambda).map_err(|f| f.into_increment_failure(0, &self.contact, node_tags))?;
        Ok((self.residual.clone(), self.pattern.col_ptr().to_vec(), self.pattern.row_idx().to_vec(), self.assembly.values().to_vec()))
    }

    /// Hold the master elements of every pair's search for the rest of this solve.
    /// Whether it did so now (not when already held or when no pair can hold anything).
    fn freeze_contact(&mut self, iteration: u32, why: &'static str) -> bool {
        if self.frozen_at.is_some() || !self.contact.iter().any(|c| c.can_freeze()) {
            return false;
        }
        self.contact.iter_mut().for_each(PairSolver::freeze);
        self.frozen_at = Some((iteration, why));
        true
    }

    /// Let the searches choose master elements again (at the start and end of a
    /// solve; `frozen_at` keeps saying what the last solve did).
    fn release_contact(&mut self) {
        self.contact.iter_mut().for_each(PairSolver::release);
    }

    /// Damp the bodies only contact holds (`bodies`, from the pre-solve check) with
    /// β = `beta` ([`FreeBodyDamping`]); nothing when there are none or β ≤ 0.
    pub fn damp_free_bodies(&mut self, bodies: Vec<FreeBody>, beta: f64) {
        if beta > 0.0 && bodies.iter().any(|b| !b.free.is_empty()) {
            self.free_bodies = Some(FreeBodyDamping::new(self.problem, bodies, beta));
        }
    }

    /// Accept the converged state `u` at `lambda` (the stabilisation's history; the
    /// free bodies' damping reports what it dissipated).
    pub fn commit_increment(&mut self, u: &[f64], lambda: f64) -> Option<DampingReport> {
        if let Some(s) = &mut self.stabilization {
            s.commit(u, lambda);
        }
        self.lambda_n = lambda;
        let (problem, contact) = (self.problem, &self.contact);
        self.free_bodies.as_mut().map(|f| f.commit(problem, u, contact))
    }

    /// Continue from the converged increments of a results file: the stabilisation
    /// takes the last two states (its extrapolation), the free bodies' damping the
    /// last one (its work counts from here: the read-back increments are not damped
    /// motion), every pair its multipliers and friction history, and the contact
    /// search runs at the last state, so the next increment starts where the
    /// interrupted run would have.
    /// `increments` are the converged ones read back (at least one).
    pub fn resume(&mut self, increments: &[Increment]) -> Result<(), IncrementFailure> {
        let tail = &increments[increments.len().saturating_sub(2)..];
        for inc in tail {
            if let Some(s) = &mut self.stabilization {
                s.commit(&inc.displacements(), inc.info.load_factor);
            }
            self.lambda_n = inc.info.load_factor;
        }
        if let (Some(f), Some(last)) = (&mut self.free_bodies, tail.last()) {
            f.restart_from(&last.displacements());
        }
        let Some(last) = tail.last() else { return Ok(()) };
        for (p, pair) in self.contact.iter_mut().enumerate() {
            let state = last.contact.get(p).map_or(&[][..], |s| &s[..]);
            let friction = last.friction.get(p).map_or(&[][..], |f| &f[..]);
            let charts = last.charts.get(p).map_or(&[][..], |c| &c[..]);
            pair.restore_history(state, friction, charts);
        }
        self.contact_search(&last.displacements(), 0)
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

    /// Assemble K_ff and the full residual R = f_int − f_ext(λ) at `u` (after
    /// [`Self::contact_search`] at the same `u`).
    fn assemble(&mut self, u: &[f64], lambda: f64) -> Result<(), AssemblyFailure> {
        let p = self.problem;
        let hex_ids = self.partition.as_ref().map(|part| &part.hex_ids[..]);
        let hex = |e: usize, r: &mut _, k: &mut _| {
            let e = hex_ids.map_or(e, |ids| ids[e] as usize);
            let (X, ue) = p.gather(e, u);
            hex8_residual_tangent(&X, &ue, &p.materials[p.hex_material[e] as usize], p.formulation, r, k).map_err(LocalFailure::Hex)
        };
        let (owners, contact) = (&self.owners, &self.contact);
        // Follower pressure: an external force, so the residual gets −f and the tangent −∂f/∂x.
        let group = |g: usize, r: &mut DVector<f64>, k: &mut DMatrix<f64>| {
            let f = match owners[g] {
                GroupOwner::Pressure(i) => &p.pressure_faces[i],
                GroupOwner::Contact(pair, s) => return contact[pair].element(s, r, k).map(|_| ()).map_err(LocalFailure::Contact),
            };
            let x: [Vector3<f64>; 4] = std::array::from_fn(|a| {
                let n = f.nodes[a] as usize;
                let d = DOFS_PER_NODE * n;
                p.X[n] + Vector3::new(u[d], u[d + 1], u[d + 2])
            });
            let (mut fv, mut km) = (FaceVector::zeros(), FaceMatrix::zeros());
            follower_pressure_force_stiffness(&x, p.amplitudes[f.amplitude as usize].at(lambda) * f.p, &mut fv, &mut km);
            for i in 0..12 {
                r[i] = -fv[i];
                for j in 0..12 {
                    k[(i, j)] = -km[(i, j)];
                }
            }
            Ok(())
        };
        let res = self.assembly.assemble_with_groups(&self.pattern, hex, group);
        let (full, failure) = match res {
            Ok((_, r)) => (Some(r), None),
            Err(ElementFailure::Hex { element, error }) | Err(ElementFailure::Group { group: element, error }) => {
                let f = match error {
                    LocalFailure::Hex(error) => AssemblyFailure::Hex(hex_ids.map_or(element, |ids| ids[element] as usize), error),
                    LocalFailure::Contact(error) => match owners[element] {
                        GroupOwner::Contact(pair, s) => AssemblyFailure::Contact(pair, s, error),
                        GroupOwner::Pressure(_) => unreachable!("pressure faces do not return contact errors"),
                    },
                };
                (None, Some(f))
            }
        };
        if self.partition.is_some() {
            // every rank takes the same branch: the worst failure of any rank decides
            let local = failure.as_ref().map_or(0.0, AssemblyFailure::severity);
            let mut worst = [local];
            ranks::reduce_over_ranks(&mut worst, ranks::Reduction::Max).map_err(AssemblyFailure::Mpi)?;
            if worst[0] > local {
                return Err(AssemblyFailure::OtherRank(worst[0] as u8));
            }
        }
        if let Some(f) = failure {
            return Err(f);
        }
        // the dofs whose residual this rank has whole: all, or those of its nodes
        let (a, b) = self.partition.as_ref().map_or((0, self.residual.len()), |part| (DOFS_PER_NODE * part.first, DOFS_PER_NODE * part.last));
        for (d, ((out, r), f)) in self.residual.iter_mut().zip(full.unwrap_or(&[])).zip(&self.f_ext).enumerate() {
            *out = if d >= a && d < b { r - f } else { 0.0 };
        }
        if self.partition.is_some() {
            // summed over the ranks, the complete parts give every rank the whole residual
            ranks::reduce_over_ranks(&mut self.residual, ranks::Reduction::Sum).map_err(AssemblyFailure::Mpi)?;
        }
        if let Some(s) = &self.stabilization {
            s.add_residual(u, &mut self.residual);
            s.add_tangent(&self.pattern, self.assembly.values_mut());
        }
        if let Some(f) = &self.free_bodies {
            f.add_residual(u, &mut self.residual);
            f.add_tangent(&self.pattern, self.assembly.values_mut());
        }
        Ok(())
    }

    /// Solve the increment at load factor `lambda`, starting from `u` (the previous
    /// converged state), which is updated in place. `on_iteration` sees each row.
    pub fn solve_increment(&mut self, lambda: f64, u: &mut [f64], on_iteration: &mut dyn FnMut(&IterationLog)) -> Result<Converged, IncrementFailure> {
        let p = self.problem;
        p.apply_prescribed(lambda, u);
        p.external_force(lambda, &mut self.f_ext);
        let ratio = cutback_ratio(self.planned_step, lambda - self.lambda_n);
        if let Some(s) = &mut self.stabilization {
            s.predict(lambda, ratio);
        }
        if let Some(f) = &mut self.free_bodies {
            f.set_cutback_ratio(ratio);
        }
        let ext_norm = self.f_ext.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut log = Vec::new();
        let mut energy0 = 0.0;
        let mut energy = f64::INFINITY;
        let mut first_residual = 0.0;
        let mut max_reaction: f64 = 0.0;
        // contact configurations of the last five iterates, to detect a cycle of
        // period 2, 3 or 4
        let mut configs: [Vec<SlaveConfiguration>; 5] = Default::default();
        let mut cycling = 0u32;
        self.release_contact();
        self.frozen_at = None;
        if let Some(forcing) = &mut self.forcing {
            forcing.restart();
        }
        let dofs = &p.dofs;
        let mut last_r_norm = f64::INFINITY;
        for iteration in 0..=self.settings.max_iterations {
            if self.settings.search_updates > 0 && iteration == self.settings.search_updates {
                self.freeze_contact(iteration, "search_updates reached");
            }
            // From the second correction on, a correction that raises ‖R_f‖ is
            // shortened (backtracking line search; the first follows the load step).
            // (Contact problems only: a smooth large-strain solve converges faster
            // with full steps, measured on the quadratic-rate test.)
            let line_search = self.settings.line_search && !self.contact.is_empty() && iteration >= 2;
            let (mut seconds_contact, mut seconds_assembly) = (0.0, 0.0);
            let mut halvings = 0;
            let r_norm = loop {
                let t = Instant::now();
                self.contact_search(u, iteration)?;
                seconds_contact += super::clock::seconds_since(t);
                let t = Instant::now();
                let assembled = self.assemble(u, lambda);
                seconds_assembly += super::clock::seconds_since(t);
                match assembled {
                    Ok(()) => {
                        dofs.gather_free(&self.residual, &mut self.rhs);
                        let r_norm = self.rhs.iter().map(|v| v * v).sum::<f64>().sqrt();
                        // Line search: the full correction raised the residual; take a
                        // shorter one (α = ½, ¼, …), or the last tried if none lowers it.
                        if !(line_search && r_norm > last_r_norm && halvings < self.settings.max_step_halvings) {
                            break r_norm;
                        }
                        self.line_search_steps += 1;
                    }
                    // Step control: the correction inverted an element; go back half of
                    // it and try again before giving the increment up.
                    Err(AssemblyFailure::Hex(..) | AssemblyFailure::OtherRank(1)) if iteration > 0 && halvings < self.settings.max_step_halvings => {
                        self.step_halvings += 1;
                    }
                    Err(f) => {
                        self.release_contact();
                        return Err(f.into_increment_failure(iteration, &self.contact, &p.node_tags));
                    }
                }
                // back half of the correction: u ← u − ½Δu (Δu, kept in r_free, halves)
                self.r_free.iter_mut().for_each(|d| *d *= -0.5);
                dofs.add_free(&self.r_free, u);
                self.r_free.iter_mut().for_each(|d| *d = -*d);
                halvings += 1;
            };
            last_r_norm = r_norm;
            let reaction_norm = (0..self.residual.len()).filter(|&d| dofs.is_constrained(d)).map(|d| self.residual[d].powi(2)).sum::<f64>().sqrt();
            // Reference force: the external load, or the largest reaction seen in this
            // increment (a stress-free state, e.g. a prescribed rigid rotation, drives
            // the current reaction itself to zero).
            max_reaction = max_reaction.max(reaction_norm);
            let reference = ext_norm.max(max_reaction);
            let residual = if reference > 0.0 { r_norm / reference } else if r_norm == 0.0 { 0.0 } else { f64::INFINITY };
            if !residual.is_finite() && r_norm != 0.0 && reference > 0.0 {
                return Err(IncrementFailure::Diverged { iteration, residual });
            }
            if iteration == 0 {
                first_residual = residual;
            } else {
                // Energy norm of the current state: the work of the residual R_i on the
                // last correction Δu_{i-1}, relative to the first |Δu_0 · R_0|. Near the
                // solution it falls like r_{i-1}·r_i, so it tracks the residual.
                let e = self.r_free.iter().zip(&self.rhs).map(|(du, r)| du * r).sum::<f64>().abs();
                energy = if energy0 > 0.0 { e / energy0 } else { 0.0 };
            }
            // Round-off floor: when the last correction Δu is at machine precision
            // relative to u and the energy criterion holds, Newton cannot improve the
            // state any further (the residual then measures the round-off of large,
            // nearly cancelling internal forces, e.g. a stiff body under a small load):
            // accepted as converged.
            let at_round_off = iteration > 0 && energy <= self.settings.energy_tolerance && {
                let du = self.r_free.iter().map(|v| v * v).sum::<f64>().sqrt();
                let un = u.iter().map(|v| v * v).sum::<f64>().sqrt();
                du <= 1e3 * f64::EPSILON * un
            };
            let converged = (residual <= self.settings.residual_tolerance || at_round_off) && (iteration == 0 || energy <= self.settings.energy_tolerance);
            // Mortar pairs: near the solution, hold the segmentation (PairSolver::hold_segmentation)
            if !converged && iteration > 0 && residual < MORTAR_HOLD_RESIDUAL {
                for pair in &mut self.contact {
                    pair.hold_segmentation();
                }
            }
            let mut row = IterationLog {
                iteration,
                residual,
                energy: if iteration == 0 { f64::NAN } else { energy },
                seconds_assembly,
                seconds_factor: 0.0,
                seconds_solve: 0.0,
                seconds_contact,
                contact_active: self.n_contact_pressed() as u32,
                augmentation: self.contact.iter().map(|c| c.augmentations).max().unwrap_or(0),
                krylov_iterations: 0,
            };
            if converged || r_norm == 0.0 {
                on_iteration(&row);
                log.push(row);
                self.release_contact();
                return Ok(Converged { iterations: log });
            }
            if iteration == self.settings.max_iterations {
                on_iteration(&row);
                log.push(row);
                return Err(IncrementFailure::NotConverged { iteration, residual, energy });
            }
            if iteration >= 4 && residual > 1e6 * first_residual.max(self.settings.residual_tolerance) {
                on_iteration(&row);
                return Err(IncrementFailure::Diverged { iteration, residual });
            }
            // A cycle of the contact configuration of period 2, 3 or 4 (C = A, B, A, B,
            // … or A, B, C, D, A, …) for three iterations in a row: Newton will not
            // settle; cut the increment back now.
            if !self.contact.is_empty() {
                configs.rotate_right(1);
                configs[0].clear();
                for pair in &self.contact {
                    pair.configuration(&mut configs[0]);
                }
                let period = (2..=4u32).find(|&k| iteration >= k && configs[0] == configs[k as usize] && configs[0] != configs[1]);
                cycling = if period.is_some() { cycling + 1 } else { 0 };
                // first remedy: hold the master elements and let Newton finish
                if cycling >= 3 && self.settings.search_updates > 0 && self.freeze_contact(iteration, "the contact configuration cycles") {
                    cycling = 0;
                } else if cycling >= 3 {
                    let tags = &p.node_tags;
                    let period = period.unwrap_or(2);
                    // the slaves whose state differs anywhere along the cycle
                    let flipping: Vec<String> = (0..configs[0].len())
                        .filter(|&i| (1..period as usize).any(|k| configs[k].get(i) != configs[0].get(i)))
                        .take(8)
                        .map(|i| {
                            let node = configs[0][i].0;
                            tags.get(node as usize).copied().unwrap_or(node as u64).to_string()
                        })
                        .collect();
                    on_iteration(&row);
                    return Err(IncrementFailure::ContactCycling { iteration, residual, nodes: flipping.join(", "), period });
                }
            }
            let t = Instant::now();
            self.linear.set_configuration(&self.problem.X, u);
            self.linear.factor(self.assembly.values()).map_err(|error| IncrementFailure::Linear { iteration, error })?;
            row.seconds_factor = super::clock::seconds_since(t);
            if let Some(forcing) = &mut self.forcing {
                self.linear.set_forcing(forcing.next(residual));
            }
            let t = Instant::now();
            // K_ff Δu_f = −R_f; Δu is kept in r_free for the next energy norm.
            self.r_free.iter_mut().zip(&self.rhs).for_each(|(du, r)| *du = -r);
            self.linear.solve_in_place(&mut self.r_free).map_err(|error| IncrementFailure::Linear { iteration, error })?;
            row.seconds_solve = super::clock::seconds_since(t);
            let report = self.linear.last_solve();
            row.krylov_iterations = report.krylov_iterations as u32;
            if let Some(why) = report.fallback {
                self.notes.push(format!("linear solver: iteration {iteration}: {why}"));
            }
            if iteration == 0 {
                energy0 = self.r_free.iter().zip(&self.rhs).map(|(du, r)| du * r).sum::<f64>().abs();
            }
            self.limit_penetration(iteration);
            dofs.add_free(&self.r_free, u);
            on_iteration(&row);
            log.push(row);
        }
        unreachable!("the loop returns at max_iterations")
    }

    /// Penetration step limit: shortens the correction Δu (in `r_free`) so that no
    /// slave node without contact stiffness goes deeper than
    /// `penetration_step_limit` master edge lengths past the master
    /// ([`PairSolver::step_limit`]). Every MPI rank has the whole Δu and the same
    /// search, so all take the same step.
    fn limit_penetration(&mut self, iteration: u32) {
        let depth = self.settings.penetration_step_limit;
        if depth.is_nan() || depth <= 0.0 || self.contact.is_empty() {
            return;
        }
        self.du_full.iter_mut().for_each(|d| *d = 0.0);
        self.problem.dofs.add_free(&self.r_free, &mut self.du_full);
        let du = &self.du_full;
        let at = |n: u32| {
            let d = DOFS_PER_NODE * n as usize;
            Vector3::new(du[d], du[d + 1], du[d + 2])
        };
        let mut limit: Option<(f64, u32, usize)> = None;
        for (k, pair) in self.contact.iter().enumerate() {
            if let Some((alpha, node)) = pair.step_limit(at, depth) {
                if limit.is_none_or(|(a, ..)| alpha < a) {
                    limit = Some((alpha, node, k));
                }
            }
        }
        let Some((alpha, node, k)) = limit else { return };
        self.r_free.iter_mut().for_each(|d| *d *= alpha);
        let tag = self.problem.node_tags.get(node as usize).copied().unwrap_or(node as u64);
        self.notes.push(format!(
            "iteration {iteration}: correction shortened to {alpha:.3} of its length: slave node {tag} of pair '{}' would have gone more than {depth} master edge lengths past the master",
            self.contact[k].name
        ));
    }

    /// Reaction force summed over each constrained node set at the last assembled state.
    pub fn reactions(&self) -> Vec<(String, [f64; 3])> {
        self.problem
            .reaction_sets
            .iter()
            .map(|(name, nodes)| {
                let mut f = [0.0; 3];
                for &n in nodes {
                    for (c, fc) in f.iter_mut().enumerate() {
                        *fc += self.residual[DOFS_PER_NODE * n as usize + c];
                    }
                }
                (name.clone(), f)
            })
            .collect()
    }
}

/// How many times shorter than planned the step from the converged λ_n is, Δλ̂/Δλ
/// (1 for a step as planned or longer, or without a plan): what a cutback does to
/// the step, by which the stabilisations stiffen.
fn cutback_ratio(planned: Option<f64>, step: f64) -> f64 {
    match planned {
        Some(p) if step > 0.0 && p > step => p / step,
        _ => 1.0,
    }
}

/// `(residual, col_ptr, row_idx, values)` of [`Newton::residual_tangent_at`].
pub type ResidualTangent = (Vec<f64>, Vec<usize>, Vec<usize>, Vec<f64>);

/// Which local evaluation failed during assembly.
enum AssemblyFailure {
    /// (hexahedron, error)
    Hex(usize, ElementError),
    /// (pair, slave index, error)
    Contact(usize, usize, ContactElementError),
    /// Another MPI rank's assembly failed ([`AssemblyFailure::severity`] of its failure).
    OtherRank(u8),
    /// An MPI reduction failed.
    Mpi(String),
}

impl AssemblyFailure {
    /// What every rank must do about a failure: 1 an inverted element (Newton halves
    /// the step), 2 anything else (the increment fails).
    fn severity(&self) -> f64 {
        match self {
            Self::Hex(..) | Self::OtherRank(1) => 1.0,
            _ => 2.0,
        }
    }

    /// The increment's failure, at `iteration` (`contact` names the pairs).
    fn into_increment_failure(self, iteration: u32, contact: &[PairSolver], node_tags: &[u64]) -> IncrementFailure {
        match self {
            Self::Hex(element, error) => IncrementFailure::Element { iteration, element, error },
            Self::Contact(pair, s, error) => {
                let c = &contact[pair];
                IncrementFailure::Contact { iteration, pair: c.name.clone(), node_tag: node_tags.get(c.slaves[s] as usize).copied().unwrap_or(c.slaves[s] as u64), error }
            }
            Self::OtherRank(1) => IncrementFailure::ContactSetup { iteration, message: "an element assembled by another MPI rank inverted or failed".into() },
            Self::OtherRank(_) => IncrementFailure::ContactSetup { iteration, message: "the assembly failed on another MPI rank (its log says why)".into() },
            Self::Mpi(message) => IncrementFailure::ContactSetup { iteration, message: format!("MPI: {message}") },
        }
    }
}

/// The share of the assembly one of several MPI ranks does: the hexahedra that touch
/// its nodes (`first..last`, the rows of the linear system it owns,
/// [`ranks::owned_nodes`]) and the node groups (contact elements, pressure faces)
/// that do. Every entry of its rows gets all its contributions there; the hexahedra
/// at a rank boundary are computed by both neighbours.
struct Partition {
    first: usize,
    last: usize,
    /// Global index of each local hexahedron.
    hex_ids: Vec<u32>,
    /// Their connectivity (the local pattern's elements).
    hexes: Vec<[u32; 8]>,
}

impl Partition {
    /// This rank's share of `problem`.
    fn new(problem: &Problem) -> Self {
        let (first, last) = ranks::owned_nodes(problem.n_nodes());
        let range = Self { first, last, hex_ids: Vec::new(), hexes: Vec::new() };
        let hex_ids: Vec<u32> = (0..problem.hexes.len() as u32).filter(|&e| problem.hexes[e as usize].iter().any(|&n| range.owns(n))).collect();
        let hexes = hex_ids.iter().map(|&e| problem.hexes[e as usize]).collect();
        Self { hex_ids, hexes, ..range }
    }

    /// Whether node `n` is this rank's.
    fn owns(&self, n: u32) -> bool {
        (n as usize) >= self.first && (n as usize) < self.last
    }

    /// Keeps the groups that touch this rank's nodes (and their owners).
    fn keep_local_groups(&self, groups: &mut NodeGroups, owners: &mut Vec<GroupOwner>) {
        let mut kept = NodeGroups::new();
        let mut kept_owners = Vec::with_capacity(owners.len());
        for (g, nodes) in groups.iter().enumerate() {
            if nodes.iter().any(|&n| self.owns(n)) {
                kept.push(nodes);
                kept_owners.push(owners[g]);
            }
        }
        *groups = kept;
        *owners = kept_owners;
    }
}

/// Contact search of every pair at `u` and the node groups of the pattern into
/// `groups`: the follower-pressure faces, then every contact element; `owners` says
/// which is which. (Both keep their storage between calls.)
/// With several MPI ranks (`partition`), each rank projects the slave nodes it owns
/// and the ranks exchange the results ([`PairSolver::search_shared`]).
fn contact_groups(p: &Problem, contact: &mut [PairSolver], u: &[f64], groups: &mut NodeGroups, owners: &mut Vec<GroupOwner>, partition: Option<&Partition>) -> Result<(), PairError> {
    groups.clear();
    for f in &p.pressure_faces {
        groups.push(&f.nodes);
    }
    owners.clear();
    owners.extend((0..p.pressure_faces.len()).map(GroupOwner::Pressure));
    for (k, pair) in contact.iter_mut().enumerate() {
        let x = |n: u32| {
            let d = DOFS_PER_NODE * n as usize;
            p.X[n as usize] + Vector3::new(u[d], u[d + 1], u[d + 2])
        };
        match partition {
            None => pair.search(x)?,
            Some(part) => {
                let mine = |n: u32| part.owns(n);
                let mut exchange = |buffer: &mut [f64]| ranks::reduce_over_ranks(buffer, ranks::Reduction::Sum);
                pair.search_shared(x, Some(SearchShare { mine: &mine, exchange: &mut exchange }))?;
            }
        }
        pair.push_groups(groups, |s| owners.push(GroupOwner::Contact(k, s)));
    }
    Ok(())
}

/// Cauchy stress at the Gauss points of every element (row-major 3×3), in parallel.
pub fn gauss_stresses(p: &Problem, u: &[f64]) -> Result<Vec<[[f64; 9]; 8]>, (usize, ElementError)> {
    use rayon::prelude::*;
    (0..p.hexes.len())
        .into_par_iter()
        .map(|e| {
            let (X, ue) = p.gather(e, u);
            let s = hex8_gauss_stresses(&X, &ue, &p.materials[p.hex_material[e] as usize]).map_err(|err| (e, err))?;
            Ok(std::array::from_fn(|q| std::array::from_fn(|i| s[q][(i / 3, i % 3)])))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::cutback_ratio;

    #[test]
    fn a_cut_back_step_is_shorter_than_planned_by_the_cutback_ratio() {
        assert_eq!(cutback_ratio(Some(1.0), 0.5), 2.0);
        assert_eq!(cutback_ratio(Some(0.01), 0.0025), 4.0);
        // as planned, longer, without a plan, or no step: unchanged
        assert_eq!(cutback_ratio(Some(1.0), 1.0), 1.0);
        assert_eq!(cutback_ratio(Some(1.0), 2.0), 1.0);
        assert_eq!(cutback_ratio(None, 0.5), 1.0);
        assert_eq!(cutback_ratio(Some(1.0), 0.0), 1.0);
    }
}
