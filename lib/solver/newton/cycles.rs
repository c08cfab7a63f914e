//! Contact configurations that cycle, and holding the search. With contact the
//! residual is only piecewise smooth: slave nodes that flip between in and out of
//! contact, between master elements or in and out of crease contact can make Newton
//! cycle between configurations. After `search_updates` iterations, or when the
//! configuration cycles with period 2, 3 or 4 for three iterations in a row, the
//! pairs hold their master elements and stick/slip branches
//! ([`PairSolver::freeze`], eq. 4.8) until the solve converges; a cycle that persists
//! fails the increment, naming the nodes (docs/theory/robustness.md, "Held facets"
//! and "Cycling contact configuration").

use super::failure::IncrementFailure;
use super::Newton;
use crate::contact::pair::{PairSolver, SlaveConfiguration};

/// The contact configurations of the last five iterates, to detect a cycle of
/// period 2, 3 or 4, and for how many iterations in a row one was seen.
#[derive(Default)]
pub(super) struct ContactCycles {
    configs: [Vec<SlaveConfiguration>; 5],
    cycling: u32,
}

impl Newton<'_> {
    /// Hold the master elements of every pair's search for the rest of this solve.
    /// Whether it did so now (not when already held or when no pair can hold anything).
    pub(super) fn freeze_contact(&mut self, iteration: u32, why: &'static str) -> bool {
        if self.frozen_at.is_some() || !self.contact.iter().any(|c| c.can_freeze()) {
            return false;
        }
        self.contact.iter_mut().for_each(PairSolver::freeze);
        self.frozen_at = Some((iteration, why));
        true
    }

    /// Let the searches choose master elements again (at the start and end of a
    /// solve; `frozen_at` keeps saying what the last solve did).
    pub(super) fn release_contact(&mut self) {
        self.contact.iter_mut().for_each(PairSolver::release);
    }

    /// A cycle of the contact configuration of period 2, 3 or 4 (C = A, B, A, B,
    /// … or A, B, C, D, A, …) for three iterations in a row: Newton will not
    /// settle. The first remedy holds the master elements and lets Newton finish;
    /// when they are held already (or cannot be), the increment fails
    /// ([`IncrementFailure::ContactCycling`]) to be cut back now. `cycles` carries
    /// the configurations from iteration to iteration of one solve.
    pub(super) fn check_cycles(&mut self, cycles: &mut ContactCycles, iteration: u32, residual: f64) -> Result<(), IncrementFailure> {
        if self.contact.is_empty() {
            return Ok(());
        }
        let ContactCycles { configs, cycling } = cycles;
        configs.rotate_right(1);
        configs[0].clear();
        for pair in &self.contact {
            pair.configuration(&mut configs[0]);
        }
        let period = (2..=4u32).find(|&k| iteration >= k && configs[0] == configs[k as usize] && configs[0] != configs[1]);
        *cycling = if period.is_some() { *cycling + 1 } else { 0 };
        // first remedy: hold the master elements and let Newton finish
        if *cycling >= 3 && self.settings.search_updates > 0 && self.freeze_contact(iteration, "the contact configuration cycles") {
            *cycling = 0;
        } else if *cycling >= 3 {
            let tags = &self.problem.node_tags;
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
            return Err(IncrementFailure::ContactCycling { iteration, residual, nodes: flipping.join(", "), period });
        }
        Ok(())
    }
}
