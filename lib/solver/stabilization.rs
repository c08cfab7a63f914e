//! Master-surface stabilisation: an artificial inertia of the master net's nodes.
//!
//! A faceted master made of a soft body can leave the quasi-static path without a
//! stable continuation: under a stiff sliding slave the tangent turns indefinite at
//! the rim of the crater (the pressed facets' rotation term t_N ∂n̄/∂x outweighs the
//! soft body there), the discrete model must snap, and no Newton variant follows it
//! (docs/validation.md, "Shallow ironing"). A stabilisation that resists *sudden*
//! motion carries the solve across such a snap. It acts on the master net's nodes
//! only, so the slave body's reactions are its contact forces, and on the deviation
//! from the motion extrapolated from the last two converged increments, so a steady
//! motion is not resisted (a viscous force c (u − u_n) would drag every translating
//! node):
//! ```text
//! u_pred = u_n + (λ − λ_n) / (λ_n − λ_{n−1}) · (u_n − u_{n−1})
//! f_a    = c (u_a − u_pred,a)            every free dof a of a master net node
//! K_aa  += c
//! c      = η ε_N Ā_s                     η the pair's `stabilization`, Ā_s the mean
//!                                         slave tributary area: η times a mean
//!                                         contact spring
//! ```
//! Before the second increment there is one state to extrapolate from, and u_pred = u_n
//! (a viscous force for that increment). The force is a second difference of the
//! motion in load steps, like an inertia force: it shrinks with the increment size
//! and vanishes for motion linear in λ. Every converged increment reports its size
//! (`stabilization_force` in the `.scres` pair summary and the forces CSV), to be
//! compared with the contact force.
//!
//! **It follows the step.** An inertia force is M ü ≈ M (u − u_pred) / Δt²: with the
//! load factor as pseudo-time and the mass fixed at c Δλ̂² for the planned step Δλ̂
//! of the increment, a step cut back to Δλ gets
//! ```text
//! c(Δλ) = c (Δλ̂ / Δλ)²                  (never less than c)
//! ```
//! so each halving makes it four times stiffer, where a constant c would give the
//! smaller step nothing more to work with: the deviation u − u_pred shrinks like
//! Δλ², and the force M ü stays what the snap needs. An increment that is not cut
//! back sees c itself.

use super::problem::Problem;
use crate::assembly::Pattern;
use crate::contact::pair::PairSolver;

/// The stabilisation of a problem's master nets.
pub struct Stabilization {
    /// c of every dof (global numbering); 0 where not stabilised and on constrained dofs.
    c: Vec<f64>,
    /// The dofs of each pair's master net (`(pair, dofs)` for the pairs with c > 0).
    pairs: Vec<(usize, Vec<u32>)>,
    /// (u_n, λ_n): the last converged increment (the initial state before any).
    last: (Vec<f64>, f64),
    /// (u_{n−1}, λ_{n−1}), once two states are known.
    before: Option<(Vec<f64>, f64)>,
    /// u_pred at the load factor of the current solve.
    u_pred: Vec<f64>,
    /// (Δλ̂ / Δλ)² of the current solve: how much stiffer a cut-back step makes it.
    scale: f64,
}

impl Stabilization {
    /// The stabilisation of `contact`'s pairs with η > 0; `None` when no pair has one.
    pub fn new(problem: &Problem, contact: &[PairSolver]) -> Option<Self> {
        let n = problem.dofs.n_dofs();
        let mut c = vec![0.0; n];
        let mut pairs = Vec::new();
        for (k, pair) in contact.iter().enumerate() {
            let c_pair = pair.stabilization_stiffness();
            if c_pair <= 0.0 {
                continue;
            }
            let mut dofs = Vec::new();
            for &node in pair.net_nodes() {
                let first = 3 * node as usize;
                for (d, c_d) in c.iter_mut().enumerate().skip(first).take(3) {
                    if !problem.dofs.is_constrained(d) {
                        *c_d = f64::max(*c_d, c_pair);
                        dofs.push(d as u32);
                    }
                }
            }
            pairs.push((k, dofs));
        }
        if pairs.is_empty() {
            return None;
        }
        Some(Self { c, pairs, last: (vec![0.0; n], 0.0), before: None, u_pred: vec![0.0; n], scale: 1.0 })
    }

    /// Extrapolate the converged history to the load factor `lambda` of the next solve,
    /// whose step is `cutback_ratio` (Δλ̂/Δλ ≥ 1) times shorter than planned.
    pub fn predict(&mut self, lambda: f64, cutback_ratio: f64) {
        let (u_n, lambda_n) = (&self.last.0, self.last.1);
        self.scale = cutback_ratio.powi(2);
        match &self.before {
            Some((u_b, lambda_b)) if lambda_n > *lambda_b => {
                let f = (lambda - lambda_n) / (lambda_n - lambda_b);
                for ((p, &a), &b) in self.u_pred.iter_mut().zip(u_n).zip(u_b) {
                    *p = a + f * (a - b);
                }
            }
            _ => self.u_pred.copy_from_slice(u_n),
        }
    }

    /// Accept the converged state `u` at `lambda` into the history.
    pub fn commit(&mut self, u: &[f64], lambda: f64) {
        let last = std::mem::replace(&mut self.last, (u.to_vec(), lambda));
        self.before = Some(last);
    }

    /// The stiffness factor of the current solve, (Δλ̂ / Δλ)² (1 unless cut back).
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// residual += f = c(Δλ) (u − u_pred).
    pub fn add_residual(&self, u: &[f64], residual: &mut [f64]) {
        for ((r, &c), (&x, &p)) in residual.iter_mut().zip(&self.c).zip(u.iter().zip(&self.u_pred)) {
            if c > 0.0 {
                *r += self.scale * c * (x - p);
            }
        }
    }

    /// K_ff += c(Δλ) on the diagonal (`values` in the layout of `pattern`).
    pub fn add_tangent(&self, pattern: &Pattern, values: &mut [f64]) {
        for (j, &global) in pattern.dofs().global_of_free().iter().enumerate() {
            let c = self.c[global as usize];
            if c > 0.0 {
                if let Some(slot) = pattern.diagonal_slot(j) {
                    values[slot] += self.scale * c;
                }
            }
        }
    }

    /// ‖f‖ over each stabilised pair's master net at `u`: `(pair index, norm)`.
    pub fn forces(&self, u: &[f64]) -> Vec<(usize, f64)> {
        self.pairs
            .iter()
            .map(|(k, dofs)| {
                let sum: f64 = dofs.iter().map(|&d| (self.scale * self.c[d as usize] * (u[d as usize] - self.u_pred[d as usize])).powi(2)).sum();
                (*k, sum.sqrt())
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A bare stabilisation over `n` dofs with c on the given ones.
    fn bare(n: usize, c_of: &[(usize, f64)]) -> Stabilization {
        let mut c = vec![0.0; n];
        for &(d, v) in c_of {
            c[d] = v;
        }
        let dofs = c_of.iter().map(|&(d, _)| d as u32).collect();
        Stabilization { c, pairs: vec![(0, dofs)], last: (vec![0.0; n], 0.0), before: None, u_pred: vec![0.0; n], scale: 1.0 }
    }

    #[test]
    fn motion_linear_in_the_load_factor_is_not_resisted() {
        // u(λ) = a + b λ on every dof, increments of unequal size (a cutback)
        let (a, b) = ([0.3, -1.0, 2.0], [1.5, 0.25, -4.0]);
        let u = |l: f64| -> Vec<f64> { (0..3).map(|i| a[i] + b[i] * l).collect() };
        let mut s = bare(3, &[(0, 10.0), (1, 10.0), (2, 10.0)]);
        s.last = (u(0.0), 0.0);
        s.commit(&u(0.1), 0.1);
        s.commit(&u(0.15), 0.15);
        s.predict(0.4, 1.0);
        let mut r = vec![0.0; 3];
        s.add_residual(&u(0.4), &mut r);
        assert!(r.iter().all(|v| v.abs() < 1e-12), "{r:?}");
        assert!(s.forces(&u(0.4))[0].1 < 1e-12);
    }

    #[test]
    fn force_is_c_times_the_deviation_from_the_extrapolation() {
        let mut s = bare(2, &[(1, 4.0)]);
        s.commit(&[0.0, 1.0], 1.0);
        s.commit(&[0.0, 3.0], 2.0);
        s.predict(2.5, 1.0); // u_pred = 3 + 0.5 · 2 = 4
        let mut r = vec![0.5, 0.5];
        s.add_residual(&[7.0, 4.5], &mut r);
        // the unstabilised dof keeps its residual; the other gets 4 · (4.5 − 4)
        assert_eq!(r, vec![0.5, 2.5]);
        assert!((s.forces(&[7.0, 4.5])[0].1 - 2.0).abs() < 1e-12);
        // before the second converged increment: no extrapolation (u_pred = u_n)
        let mut first = bare(2, &[(1, 4.0)]);
        first.predict(0.3, 1.0);
        let mut r = vec![0.0; 2];
        first.add_residual(&[0.0, 0.25], &mut r);
        assert_eq!(r, vec![0.0, 1.0]);
    }

    #[test]
    fn a_cut_back_step_makes_it_stiffer_by_the_square_of_the_cut() {
        let mut s = bare(2, &[(1, 4.0)]);
        s.commit(&[0.0, 1.0], 1.0);
        s.commit(&[0.0, 3.0], 2.0);
        // planned 2 → 3, cut back to 2 → 2.5 (ratio 2): c × 2² = 16; u_pred = 4
        s.predict(2.5, 2.0);
        assert_eq!(s.scale(), 4.0);
        let mut r = vec![0.0; 2];
        s.add_residual(&[0.0, 4.5], &mut r);
        assert_eq!(r, vec![0.0, 8.0]);
        assert!((s.forces(&[0.0, 4.5])[0].1 - 8.0).abs() < 1e-12);
        // the tangent takes the same factor
        let (nodes, hexes) = crate::assembly::pattern::structured_hex_grid(1, 1, 1);
        let dofs = crate::assembly::DofMap::from_constrained_mask(&vec![false; 3 * nodes.len()]).unwrap();
        let pattern = crate::assembly::Pattern::build(dofs, &hexes, crate::assembly::NodeGroups::new()).unwrap();
        let mut big = bare(3 * nodes.len(), &[(1, 4.0)]);
        big.commit(&vec![0.0; 3 * nodes.len()], 1.0);
        big.predict(1.25, 4.0);
        let mut values = vec![0.0; pattern.nnz()];
        big.add_tangent(&pattern, &mut values);
        assert_eq!(values.iter().sum::<f64>(), 16.0 * 4.0);
        // a step as planned keeps c
        s.predict(3.0, 1.0);
        assert_eq!(s.scale(), 1.0);
    }
}
