//! The augmented Lagrangian's outer loop (paper sec. 4; Simo & Laursen 1992): Newton
//! converges with the multipliers λ_N fixed, then every augmented-Lagrangian pair
//! whose largest penetration is above its tolerance updates
//! ```text
//! λ_N ← t_N = min(0, λ_N + ε_N g_N)                                (Uzawa, eq. 4.2)
//! ```
//! and Newton solves again from the converged state, until no pair needs an update
//! or a pair has used its `max_augmentations` (then the increment is accepted and
//! its summary says the penetration did not converge). Penalty pairs keep λ_N = 0.

use super::newton::{Converged, IncrementFailure, Newton};
use crate::format::scres::IterationLog;

/// Newton plus Uzawa updates at load factor `lambda`; `u` is updated in place.
/// `note` receives one line per update.
pub fn solve_augmented(newton: &mut Newton, lambda: f64, u: &mut [f64], on_iteration: &mut dyn FnMut(&IterationLog), note: &mut dyn FnMut(&str)) -> Result<Converged, IncrementFailure> {
    let mut iterations = Vec::new();
    loop {
        let (halvings, searched) = (newton.step_halvings, newton.line_search_steps);
        let conv = newton.solve_increment(lambda, u, on_iteration)?;
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
        let node_tags = &newton.problem.node_tags;
        for pair in &mut newton.contact {
            pair.update_states().map_err(|(node, error)| IncrementFailure::Contact {
                iteration: 0,
                pair: pair.name.clone(),
                node_tag: node_tags.get(node as usize).copied().unwrap_or(node as u64),
                error,
            })?;
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
                pair.augment();
                due = true;
            }
        }
        if !due {
            return Ok(Converged { iterations });
        }
    }
}
