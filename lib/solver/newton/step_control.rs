//! Step control: a Newton correction Δu is shortened rather than taken whole when
//! - the iterate it leads to inverts an element (J ≤ 0 at a Gauss point): go back
//!   half of it, u ← u − ½Δu, and assemble again, up to `max_step_halvings` times;
//! - (from the second correction on, contact problems only) it raises ‖R_f‖: the
//!   same halving, α = ½, ¼, … (backtracking line search), keeping the last tried
//!   when none lowers the residual;
//! - it would carry a slave node without contact stiffness deeper than
//!   `penetration_step_limit` master edge lengths past the master (the linearised
//!   gap Δg_N, eq. 4.16, [`PairSolver::step_limit`](crate::contact::pair::PairSolver::step_limit)).
//!
//! (docs/theory/robustness.md, "Line search and step control" and "Penetration step
//! limit".)

use crate::os::timeline;
use std::time::Instant;

use nalgebra::Vector3;

use super::assemble::AssemblyFailure;
use super::failure::IncrementFailure;
use super::Newton;
use crate::assembly::DOFS_PER_NODE;
use crate::solver::clock;

/// An iterate assembled: ‖R_f‖, and the seconds its contact searches and
/// assemblies took (halved steps included).
pub(super) struct Assembled {
    pub(super) r_norm: f64,
    pub(super) seconds_contact: f64,
    pub(super) seconds_assembly: f64,
}

impl Newton<'_> {
    /// Contact search and assembly at `u` for `iteration` of the solve at `lambda`,
    /// halving the last correction (kept in `r_free`, `u` moves back with it) while
    /// the iterate inverts an element or, under the line search, its ‖R_f‖ is above
    /// `last_r_norm`. Leaves R_f in `rhs`, and K_ff in the assembly when `tangent`.
    pub(super) fn assemble_iterate(&mut self, u: &mut [f64], lambda: f64, iteration: u32, last_r_norm: f64, tangent: bool) -> Result<Assembled, IncrementFailure> {
        let p = self.problem;
        let dofs = &p.dofs;
        // From the second correction on, a correction that raises ‖R_f‖ is
        // shortened (backtracking line search; the first follows the load step).
        // (Contact problems only: a smooth large-strain solve converges faster
        // with full steps, measured on the quadratic-rate test.)
        let line_search = self.settings.line_search && !self.contact.is_empty() && iteration >= 2;
        let (mut seconds_contact, mut seconds_assembly) = (0.0, 0.0);
        let mut halvings = 0;
        let r_norm = loop {
            let t = Instant::now();
            {
                let _span = timeline::span("contact search");
                self.contact_search(u, iteration)?;
            }
            seconds_contact += clock::seconds_since(t);
            let t = Instant::now();
            let assembly_span = timeline::span(if tangent { "assembly: residual and tangent" } else { "assembly: residual" });
            let assembled = self.assemble(u, lambda, tangent);
            drop(assembly_span);
            seconds_assembly += clock::seconds_since(t);
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
        Ok(Assembled { r_norm, seconds_contact, seconds_assembly })
    }

    /// Penetration step limit: shortens the correction Δu (in `r_free`) so that no
    /// slave node without contact stiffness goes deeper than
    /// `penetration_step_limit` master edge lengths past the master
    /// ([`PairSolver::step_limit`](crate::contact::pair::PairSolver::step_limit)).
    /// Every MPI rank has the whole Δu and the same search, so all take the same step.
    pub(super) fn limit_penetration(&mut self, iteration: u32) {
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
}
