//! The augmented Lagrangian's outer loop (paper sec. 4; Simo & Laursen 1992): Newton
//! converges with the multipliers λ_N fixed, then every augmented-Lagrangian pair
//! whose largest penetration is above its tolerance updates
//! ```text
//! λ_N ← t_N = min(0, λ_N + ε_N g_N)                                (Uzawa, eq. 4.2)
//! ```
//! and Newton solves again from the converged state, until no pair needs an update
//! or a pair has used its `max_augmentations` (then the increment is accepted and
//! its summary says the penetration did not converge). Penalty pairs keep λ_N = 0.
//!
//! When Newton fails after an update, the update was too large a step for it (an
//! update moves every pressed node's force at once): the solve is retried from the
//! state the update started from with half the update, λ_N = λ_N,old + ½ Δλ_N, then a
//! quarter, an eighth (the pairs' `update_halvings`, default
//! [`UPDATE_HALVINGS`](crate::contact::settings::UPDATE_HALVINGS)),
//! before the failure goes to the load stepping as a cutback.

use super::newton::{Converged, IncrementFailure, Newton};
use crate::contact::pair::Multipliers;
use crate::format::scres::IterationLog;

/// Newton plus Uzawa updates at load factor `lambda`; `u` is updated in place.
/// `note` receives one line per update.
pub fn solve_augmented(newton: &mut Newton, lambda: f64, u: &mut [f64], on_iteration: &mut dyn FnMut(&IterationLog), note: &mut dyn FnMut(&str)) -> Result<Converged, IncrementFailure> {
    let mut iterations = Vec::new();
    // the converged state the last update started from, and per updated pair its
    // multipliers before and after the update
    let mut u_start = Vec::new();
    let mut update: Vec<(usize, Multipliers, Multipliers)> = Vec::new();
    let mut theta = 1.0;
    newton.begin_increment();
    loop {
        let (halvings, searched) = (newton.step_halvings, newton.line_search_steps);
        let solved = newton.solve_increment(lambda, u, on_iteration);
        for text in std::mem::take(&mut newton.notes) {
            note(&text);
        }
        let conv = match solved {
            Ok(conv) => conv,
            // the setup's failure: no update mends it
            Err(failure @ IncrementFailure::Setup { .. }) => return Err(failure),
            Err(failure) if theta > 0.5f64.powi(halvings_allowed(newton, &update)) => {
                theta *= 0.5;
                note(&format!("Newton failed after the Uzawa update ({failure}): solving again with {theta} of the update"));
                u.copy_from_slice(&u_start);
                for (k, before, after) in &update {
                    newton.contact[*k].set_multipliers(&Multipliers::between(before, after, theta));
                }
                continue;
            }
            Err(failure) => return Err(failure),
        };
        iterations.extend(conv.iterations);
        if let Some((iteration, why)) = newton.frozen_at {
            note(&format!("master elements held from iteration {iteration} ({why})"));
        }
        if newton.step_halvings > halvings {
            note(&format!("{} Newton corrections halved (an element inverted)", newton.step_halvings - halvings));
        }
        if newton.line_search_steps > searched {
            note(&format!("line search: {} corrections halved", newton.line_search_steps - searched));
        }
        let mut due = false;
        update.clear();
        theta = 1.0;
        let node_tags = &newton.problem.node_tags;
        for (k, pair) in newton.contact.iter_mut().enumerate() {
            pair.update_states().map_err(|(node, error)| IncrementFailure::Contact {
                iteration: 0,
                pair: pair.name.clone(),
                node_tag: node_tags.get(node as usize).copied().unwrap_or(node as u64),
                error,
            })?;
            if let Some(n) = pair.mortar_skipped_cells().filter(|&n| n > 0) {
                note(&format!("pair '{}': the mortar integration left out {n} master cells whose image over a slave face is not convex (their share of the weighted gaps is missing; a finer or less distorted master, or integration: node, avoids it)", pair.name));
            }
            if pair.needs_augmentation() {
                note(&format!(
                    "pair '{}': largest penetration {:.3e}{} (tolerance {:.3e}), {} active nodes: augmentation {} (λ_N ← t_N{})",
                    pair.name,
                    pair.max_penetration(),
                    if pair.settings.frictional() { format!(", elastic slip {:.3e}", pair.max_elastic_slip()) } else { String::new() },
                    pair.settings.penetration_tolerance,
                    pair.n_active(),
                    pair.augmentations + 1,
                    if pair.settings.frictional() { ", t_T,n ← t_T" } else { "" }
                ));
                let before = pair.multipliers();
                pair.augment();
                update.push((k, before, pair.multipliers()));
                due = true;
            }
        }
        if !due {
            return Ok(Converged { iterations });
        }
        u_start.clear();
        u_start.extend_from_slice(u);
    }
}

/// How often the last update may be halved: the fewest retries any updated pair
/// allows (none when no pair was updated).
fn halvings_allowed(newton: &Newton, update: &[(usize, Multipliers, Multipliers)]) -> i32 {
    update.iter().map(|(k, _, _)| newton.contact[*k].settings.update_halvings as i32).min().unwrap_or(0)
}
