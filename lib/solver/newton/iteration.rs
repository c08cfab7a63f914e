//! The Newton iteration of one increment and its convergence checks
//! (docs/theory/solver.md, "Newton–Raphson"). Per iteration i: assemble K_ff and
//! R(u_i) (`step_control.rs` shortens the last correction first if needed); stop
//! when both
//! - ‖R_f‖ ≤ tol_r · F_ref, F_ref = max(‖λ f̂‖, max_{j ≤ i} ‖R_c,j‖) (the external
//!   load or the largest reaction seen in the increment, `reactions.rs`), or the
//!   state is at round-off (‖Δu_{i−1}‖ ≤ 10³ ε ‖u‖), and
//! - |Δu_{i−1}·R_i| ≤ tol_e · |Δu_0·R_0| (energy norm);
//!
//! else fail on divergence (a residual 10⁶ times the first after 4 iterations) or a
//! cycling contact configuration (`cycles.rs`), solve K_ff Δu = −R_f (an inexact
//! Newton's forcing term sets an iterative solve's tolerance), limit the step and
//! update u.

use crate::os::timeline;
use std::time::Instant;

use super::cycles::ContactCycles;
use super::failure::IncrementFailure;
use super::history::cutback_ratio;
use super::step_control::Assembled;
use super::{Converged, Newton};
use crate::format::scres::IterationLog;
use crate::solver::clock;

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

/// The same threshold for an increment solved again after it failed with
/// [`MORTAR_HOLD_RESIDUAL`] ([`Newton::early_segmentation_hold`]): far from the
/// solution the segments move with every correction and the tangent, which takes
/// them as fixed, misses the term of the master's moving edge (docs/theory/mortar.md),
/// so Newton can cycle there. Measured on the frictional parallel beams under
/// mortar, the paper's 30 increments: with 1e-5 only, increment 14 cycles with period
/// 5 at a relative residual of 4e-3–1e-2 and the solve stops after 5 cutbacks; held
/// from 1e-1 in every increment it completes (121 corrections, 1 cutback), and from
/// 1e-2 (110 corrections, 2 cutbacks); from 1e-3 it stops as with 1e-5. The price is
/// the quadrature of a segmentation taken while the bodies still move (the patch
/// test's pressure 5e-6 off when held from 1e-2), in that increment only.
pub(super) const MORTAR_EARLY_HOLD_RESIDUAL: f64 = 1e-1;

/// An iterate is assembled residual first (no tangent; the tangent follows only if
/// it has not converged) when Newton's quadratic rate predicts convergence,
/// r_{i-1}² / r_{i-2} ≤ this × the residual tolerance. The converged iterate of an
/// increment needs no tangent; the residual alone costs about a quarter of the
/// residual and tangent (hex8: 1.2 µs against 4.7 µs, and no scatter into K_ff),
/// so a wrong guess costs a quarter of an assembly and a right one saves three
/// quarters. The margin takes the rates before the asymptotic regime, often faster
/// than quadratic from a large first residual (Parisch r = 6: r_0 = 1,
/// r_1 = 1.6e-4, predicted 2.5e-8, converged at 2.4e-10).
pub(super) const RESIDUAL_FIRST_MARGIN: f64 = 100.0;

impl Newton<'_> {
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
        let mut cycles = ContactCycles::default();
        self.release_contact();
        self.frozen_at = None;
        if let Some(forcing) = &mut self.forcing {
            forcing.restart();
        }
        let dofs = &p.dofs;
        let mut last_r_norm = f64::INFINITY;
        // relative residuals of the last two iterates: r_{i-2}, r_{i-1}
        let mut last_residuals = [f64::INFINITY; 2];
        for iteration in 0..=self.settings.max_iterations {
            if self.settings.search_updates > 0 && iteration == self.settings.search_updates {
                self.freeze_contact(iteration, "search_updates reached");
            }
            let [r_2, r_1] = last_residuals;
            let residual_first = self.settings.residual_first && iteration >= 2 && r_1 * r_1 <= RESIDUAL_FIRST_MARGIN * self.settings.residual_tolerance * r_2;
            self.residual_first.0 += usize::from(residual_first);
            let Assembled { r_norm, seconds_contact, seconds_assembly } = self.assemble_iterate(u, lambda, iteration, last_r_norm, !residual_first)?;
            last_r_norm = r_norm;
            let reaction_norm = self.reaction_norm();
            // Reference force: the external load, or the largest reaction seen in this
            // increment (a stress-free state, e.g. a prescribed rigid rotation, drives
            // the current reaction itself to zero).
            max_reaction = max_reaction.max(reaction_norm);
            let reference = ext_norm.max(max_reaction);
            let residual = if reference > 0.0 { r_norm / reference } else if r_norm == 0.0 { 0.0 } else { f64::INFINITY };
            if !residual.is_finite() && r_norm != 0.0 && reference > 0.0 {
                return Err(IncrementFailure::Diverged { iteration, residual });
            }
            last_residuals = [r_1, residual];
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
            let hold_below = if self.early_segmentation_hold { MORTAR_EARLY_HOLD_RESIDUAL } else { MORTAR_HOLD_RESIDUAL };
            if !converged && iteration > 0 && residual < hold_below {
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
            // A contact configuration that cycles: hold the master elements, or cut
            // the increment back now.
            if let Err(failure) = self.check_cycles(&mut cycles, iteration, residual) {
                on_iteration(&row);
                return Err(failure);
            }
            if residual_first {
                // not converged after all: the tangent at the same state (no new
                // search; the residual is the same, bit for bit)
                self.residual_first.1 += 1;
                let t = Instant::now();
                if let Err(f) = self.assemble(u, lambda, true) {
                    self.release_contact();
                    return Err(f.into_increment_failure(iteration, &self.contact, &p.node_tags));
                }
                dofs.gather_free(&self.residual, &mut self.rhs);
                row.seconds_assembly += clock::seconds_since(t);
            }
            // the first analysis, if it still runs (`Newton::new` started it in the
            // background; nothing to wait for after it): its failure (a factor too
            // large for the memory) is the setup's
            {
                let _wait = timeline::span("waiting for the first analysis");
                self.linear.finish_analysis().map_err(|error| IncrementFailure::Setup { error })?;
            }
            let t = Instant::now();
            let factor_span = timeline::span("linear solver: factor");
            self.linear.set_configuration(&self.problem.X, u);
            self.linear.factor(self.assembly.values()).map_err(|error| IncrementFailure::Linear { iteration, error })?;
            drop(factor_span);
            row.seconds_factor = clock::seconds_since(t);
            if let Some(forcing) = &mut self.forcing {
                self.linear.set_forcing(forcing.next(residual));
            }
            let t = Instant::now();
            // K_ff Δu_f = −R_f; Δu is kept in r_free for the next energy norm.
            self.r_free.iter_mut().zip(&self.rhs).for_each(|(du, r)| *du = -r);
            let solve_span = timeline::span("linear solver: solve");
            self.linear.solve_in_place(self.assembly.values(), &mut self.r_free).map_err(|error| IncrementFailure::Linear { iteration, error })?;
            drop(solve_span);
            row.seconds_solve = clock::seconds_since(t);
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
}
