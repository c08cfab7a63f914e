//! Between increments: what a converged increment hands the next. Accepting it
//! (`commit_increment`) moves λ_n to its load factor, gives its state to the
//! master-surface stabilisation's history (the extrapolation of the next
//! prediction) and to the free bodies' damping (which reports the work it
//! dissipated). Restarting from a results file (`resume`) hands over the same from
//! the increments read back, and each pair's multipliers and friction history, so
//! the next increment starts where the interrupted run would have. When a cutback
//! makes the step from λ_n shorter than planned, the stabilisation and the damping
//! scale with the ratio Δλ̂/Δλ ([`cutback_ratio`]).

use super::failure::IncrementFailure;
use super::Newton;
use crate::format::scres::Increment;
use crate::solver::free_bodies::DampingReport;

impl Newton<'_> {
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
}

/// How many times shorter than planned the step from the converged λ_n is, Δλ̂/Δλ
/// (1 for a step as planned or longer, or without a plan): what a cutback does to
/// the step, by which the stabilisations stiffen.
pub(super) fn cutback_ratio(planned: Option<f64>, step: f64) -> f64 {
    match planned {
        Some(p) if step > 0.0 && p > step => p / step,
        _ => 1.0,
    }
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
