//! Reactions: the residual R = f_int − f_ext at the constrained dofs. Dirichlet dofs
//! are eliminated from K_ff, so R there is the force the supports take; summed over
//! each constrained node set it is the reaction the results report. Its norm ‖R_c‖
//! is also the reference force of the convergence check when it exceeds the external
//! load, F_ref = max(‖λ f̂‖, max_{j ≤ i} ‖R_c,j‖) (`iteration.rs`,
//! docs/theory/solver.md, "Newton–Raphson").

use super::Newton;
use crate::assembly::DOFS_PER_NODE;

impl Newton<'_> {
    /// ‖R_c‖: the norm of the residual over the constrained dofs at the last
    /// assembled state.
    pub(super) fn reaction_norm(&self) -> f64 {
        let dofs = &self.problem.dofs;
        (0..self.residual.len()).filter(|&d| dofs.is_constrained(d)).map(|d| self.residual[d].powi(2)).sum::<f64>().sqrt()
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
