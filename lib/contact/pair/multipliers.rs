//! The multipliers of a pair and its friction history, from one Newton solve to the
//! next: the Uzawa update of the augmented Lagrangian, λ_N ← t_N = min(0, λ_N + ε_N g_N)
//! (eq. 4.2, sec. 4), with friction also the tangential Δλ_T of eq. 4.7 (a sticking
//! node keeps its anchor ξ̄_n and takes t_{Tα,n} ← t_Tα, a sliding one is re-anchored);
//! whether another update is due (penetration, elastic slip of a sticking node); the
//! damped update [`Multipliers::between`]; and the history an increment commits, a
//! failed increment restores and a restart reads back: λ_N, the foot point ξ̄_n, the
//! traction t_{Tα,n} and the atlas chart these are expressed on.

use super::{PairSolver, SlaveStatus};
use crate::contact::seam::SeamLoss;
use crate::contact::settings::Enforcement;
use crate::spline::Vec3;

/// A snapshot of the multipliers an Uzawa update sets ([`PairSolver::multipliers`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Multipliers {
    pub lambda_n: Vec<f64>,
    pub xi_n: Vec<[f64; 2]>,
    pub t_t_n: Vec<[f64; 2]>,
}

impl Multipliers {
    /// A damped Uzawa update: `before + θ (after − before)`, between the iterate an
    /// update started from and the one it set (θ = 1: the full update). A foot point
    /// ξ̄_n without a `before` (NaN: the node first touched in this update) is taken as
    /// `after` set it.
    pub fn between(before: &Self, after: &Self, theta: f64) -> Self {
        let mix = |b: f64, a: f64| if b.is_finite() { b + theta * (a - b) } else { a };
        let mix2 = |b: &[f64; 2], a: &[f64; 2]| [mix(b[0], a[0]), mix(b[1], a[1])];
        Self {
            lambda_n: before.lambda_n.iter().zip(&after.lambda_n).map(|(b, a)| mix(*b, *a)).collect(),
            xi_n: before.xi_n.iter().zip(&after.xi_n).map(|(b, a)| mix2(b, a)).collect(),
            t_t_n: before.t_t_n.iter().zip(&after.t_t_n).map(|(b, a)| mix2(b, a)).collect(),
        }
    }
}

impl PairSolver {
    /// Largest penetration −g_N over the active slaves (0 if none).
    pub fn max_penetration(&self) -> f64 {
        (0..self.slaves.len()).filter(|&s| self.status[s] == SlaveStatus::Active).map(|s| -self.gap(s)).fold(0.0, f64::max)
    }

    /// Largest elastic slip ‖t_T − t_{T,n}‖ / ε_T of a sticking node (0 without
    /// friction): the tangential constraint violation the augmentation removes.
    pub fn max_elastic_slip(&self) -> f64 {
        if !self.settings.frictional() {
            return 0.0;
        }
        (0..self.slaves.len())
            .filter(|&s| self.status[s] == SlaveStatus::Active && !self.slipping[s])
            .map(|s| {
                let d = [self.t_t[s][0] - self.t_t_n[s][0], self.t_t[s][1] - self.t_t_n[s][1]];
                let ai = self.points[s].a_inv;
                (d[0] * ai[(0, 0)] * d[0] + 2.0 * d[0] * ai[(0, 1)] * d[1] + d[1] * ai[(1, 1)] * d[1]).max(0.0).sqrt() / self.settings.eps_t
            })
            .fold(0.0, f64::max)
    }

    /// Whether another Uzawa update is due (augmented Lagrangian, penetration or
    /// elastic slip of a sticking node above the tolerance, updates left).
    pub fn needs_augmentation(&self) -> bool {
        let tol = self.settings.penetration_tolerance;
        self.settings.enforcement == Enforcement::AugmentedLagrangian
            && (self.max_penetration() > tol || self.max_elastic_slip() > tol)
            && self.augmentations < self.settings.max_augmentations
    }

    /// Uzawa update (sec. 4): λ_N ← t_N = min(0, λ_N + ε_N g_N), or over-relaxed,
    /// λ_N ← min(0, λ_N + ω (t_N − λ_N)) with the pair's `uzawa_relaxation` ω
    /// (docs/theory/contact.md); with friction the tangential multiplier too (eq.
    /// 4.7's Δλ_T): a sticking node keeps its anchor ξ̄_n and takes t_{T,n} ← t_T, so
    /// the next solve drives its elastic slip to zero; a sliding node's slip is
    /// plastic: it is re-anchored, ξ̄_n ← ξ̄, t_{T,n} ← t_T.
    pub fn augment(&mut self) {
        let omega = self.settings.uzawa_relaxation;
        // ω = 1 copies t_N: λ + (t − λ) need not round to t, and the plain update
        // keeps its results bit for bit
        if omega == 1.0 {
            self.lambda_n.copy_from_slice(&self.t_n);
        } else {
            for (l, t) in self.lambda_n.iter_mut().zip(&self.t_n) {
                *l = (*l + omega * (t - *l)).min(0.0);
            }
        }
        if self.settings.frictional() {
            for s in 0..self.slaves.len() {
                if self.status[s] != SlaveStatus::Active {
                    continue;
                }
                self.t_t_n[s] = self.t_t[s];
                if self.slipping[s] {
                    self.xi_n[s] = self.projections[s].xi;
                    self.chart_n[s] = self.chart(s);
                }
            }
        }
        self.augmentations += 1;
    }

    /// The multipliers an Uzawa update sets: λ_N and, with friction, ξ̄_n and t_{Tα,n}.
    pub fn multipliers(&self) -> Multipliers {
        Multipliers { lambda_n: self.lambda_n.clone(), xi_n: self.xi_n.clone(), t_t_n: self.t_t_n.clone() }
    }

    /// Set the multipliers (a damped update: [`Multipliers::between`]).
    pub fn set_multipliers(&mut self, m: &Multipliers) {
        self.lambda_n.copy_from_slice(&m.lambda_n);
        self.xi_n.copy_from_slice(&m.xi_n);
        self.t_t_n.copy_from_slice(&m.t_t_n);
    }

    /// Start the friction history from the current search (the reference
    /// configuration, before the first increment).
    pub fn init_history(&mut self) {
        for s in 0..self.slaves.len() {
            if self.usable(s) {
                self.xi_n[s] = self.projections[s].xi;
                self.chart_n[s] = self.chart(s);
            }
        }
        self.xi_n_committed.copy_from_slice(&self.xi_n);
        self.chart_n_committed.copy_from_slice(&self.chart_n);
    }

    /// Slip increment of slave `s` in this increment, (ξ̄ − ξ̄_n)^α ā_α.
    pub fn slip_increment(&self, s: usize) -> Vec3 {
        if self.status[s] == SlaveStatus::Outside || self.xi_n[s][0].is_nan() {
            return Vec3::zeros();
        }
        let law = self.friction_law(s);
        let xi = self.projections[s].xi;
        let a = &self.points[s].a_alpha;
        a[0] * (xi[0] - law.xi_n[0]) + a[1] * (xi[1] - law.xi_n[1])
    }

    /// The increment converged: keep its multipliers and, with friction, the history
    /// (ξ̄_n ← ξ̄; t_{Tα,n} ← t_Tα for active nodes, 0 for the others: a node that
    /// leaves contact forgets its traction).
    pub fn commit(&mut self) {
        self.lambda_committed.copy_from_slice(&self.lambda_n);
        self.augmentations = 0;
        for s in 0..self.slaves.len() {
            // off the patch: forget the foot point, the next one found starts afresh
            self.xi_n[s] = if self.status[s] == SlaveStatus::Outside { [f64::NAN; 2] } else { self.projections[s].xi };
            self.t_t_n[s] = if self.status[s] == SlaveStatus::Active { self.t_t[s] } else { [0.0; 2] };
            self.chart_n[s] = self.chart(s);
        }
        self.xi_n_committed.copy_from_slice(&self.xi_n);
        self.t_t_n_committed.copy_from_slice(&self.t_t_n);
        self.chart_n_committed.copy_from_slice(&self.chart_n);
        self.seams.commit(&self.projector, (0..self.slaves.len()).map(|s| (self.status[s] == SlaveStatus::Active, self.chart_n[s], self.xi_n[s])));
    }

    /// Slave nodes the last search lost at a seam between charts (atlas masters:
    /// active at the last commit on an edge between charts, off the master now).
    pub fn seam_losses(&self) -> &[SeamLoss] {
        self.seams.lost()
    }

    /// A restart: the converged history of an increment as a results file stores it
    /// (`state` rows [`CONTACT_STATE_COLUMNS`], `friction` rows [`FRICTION_COLUMNS`],
    /// empty when the run had no friction), taken as [`Self::commit`] would have left
    /// it: λ_N, the foot point ξ̄_n (none off the patch) and t_{Tα,n} of the active
    /// nodes (eq. 4.7). The caller checked that the rows are this pair's slaves.
    ///
    /// [`CONTACT_STATE_COLUMNS`]: crate::format::scres::CONTACT_STATE_COLUMNS
    /// [`FRICTION_COLUMNS`]: crate::format::scres::FRICTION_COLUMNS
    pub fn restore_history(&mut self, state: &[[f64; 6]], friction: &[[f64; 9]], charts: &[u32]) {
        for (s, row) in state.iter().enumerate().take(self.slaves.len()) {
            let active = row[3] == SlaveStatus::Active.code();
            self.lambda_n[s] = row[2];
            self.xi_n[s] = if row[3] == SlaveStatus::Outside.code() { [f64::NAN; 2] } else { [row[4], row[5]] };
            self.t_t_n[s] = match friction.get(s) {
                Some(f) if active => [f[6], f[7]],
                _ => [0.0; 2],
            };
        }
        // atlas masters: the chart each ξ̄_n lies on, as stored (files without it:
        // the chart of the first search after the restart)
        for (s, c) in self.chart_n.iter_mut().enumerate() {
            *c = charts.get(s).filter(|&&c| (c as usize) < self.projector.n_charts()).map_or(usize::MAX, |&c| c as usize);
        }
        // and the chart the next search's hysteresis keeps, as the run left it: a
        // node on an edge between two charts stays on the one it was on
        if self.projector.is_atlas() {
            for (cell, &c) in self.cells.iter_mut().zip(&self.chart_n) {
                *cell = (c != usize::MAX).then_some([c, 0]);
            }
        }
        self.seams.commit(&self.projector, state.iter().zip(&self.chart_n).map(|(row, &c)| (row[3] == SlaveStatus::Active.code(), c, [row[4], row[5]])));
        self.lambda_committed.copy_from_slice(&self.lambda_n);
        self.xi_n_committed.copy_from_slice(&self.xi_n);
        self.t_t_n_committed.copy_from_slice(&self.t_t_n);
        self.chart_n_committed.copy_from_slice(&self.chart_n);
        self.augmentations = 0;
    }

    /// The increment failed: back to the last converged multipliers.
    pub fn restore(&mut self) {
        self.lambda_n.copy_from_slice(&self.lambda_committed);
        self.xi_n.copy_from_slice(&self.xi_n_committed);
        self.t_t_n.copy_from_slice(&self.t_t_n_committed);
        self.chart_n.copy_from_slice(&self.chart_n_committed);
        self.augmentations = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damped_update_lies_between_the_iterates() {
        let before = Multipliers { lambda_n: vec![0.0, -2.0], xi_n: vec![[0.1, 0.2], [f64::NAN; 2]], t_t_n: vec![[1.0, 0.0], [0.0, 0.0]] };
        let after = Multipliers { lambda_n: vec![-4.0, -1.0], xi_n: vec![[0.3, 0.2], [0.5, 0.6]], t_t_n: vec![[3.0, -2.0], [0.0, 1.0]] };
        assert_eq!(Multipliers::between(&before, &after, 1.0), after);
        let half = Multipliers::between(&before, &after, 0.5);
        assert_eq!(half.lambda_n, vec![-2.0, -1.5]);
        assert!((half.xi_n[0][0] - 0.2).abs() < 1e-15 && half.xi_n[0][1] == 0.2);
        // a node without a foot point before the update keeps the one it was given
        assert_eq!(half.xi_n[1], [0.5, 0.6]);
        assert_eq!(half.t_t_n, vec![[2.0, -1.0], [0.0, 0.5]]);
        let none = Multipliers::between(&before, &after, 0.0);
        assert_eq!((none.lambda_n, none.t_t_n), (before.lambda_n.clone(), before.t_t_n.clone()));
    }
}
