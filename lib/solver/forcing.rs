//! The forcing term of an inexact Newton method: how far each iterative linear
//! solve reduces its residual, ‖K Δu + R‖ ≤ η_k ‖R‖.
//!
//! Eisenstat & Walker (1996), choice 2, with their safeguard and Kelley's
//! safeguard against oversolving the last step:
//!
//! - η_0 = η_max;
//! - η_k = γ (r_k / r_{k−1})^α, γ = 0.9, α = 2 (how fast Newton is converging);
//! - η_k ← max(η_k, γ η_{k−1}^α) when γ η_{k−1}^α > 0.1 (no sudden drop);
//! - η_k ← min(η_k, η_max);
//! - η_k ← max(η_k, τ / (10 r_k)): a solve need not reach far below what the
//!   convergence test τ on the next residual asks (the last solve of an increment
//!   otherwise costs as much as a solve to round-off; the factor 10 leaves room
//!   for the nonlinear part of the next residual);
//!
//! r_k being Newton's relative residual. Near the solution η_k ~ r_k, and Newton
//! keeps its quadratic rate (Dembo, Eisenstat & Steihaug 1982).

/// γ of choice 2.
const GAMMA: f64 = 0.9;
/// α of choice 2.
const ALPHA: f64 = 2.0;

/// The forcing terms of one Newton solve.
#[derive(Debug, Clone, Copy)]
pub struct Forcing {
    /// The loosest a solve may stop at.
    eta_max: f64,
    /// Newton's convergence test on the relative residual.
    tolerance: f64,
    /// The last relative residual and forcing term.
    last: Option<(f64, f64)>,
}

impl Forcing {
    /// Forcing terms no larger than `eta_max`, for a Newton solve that stops at the
    /// relative residual `tolerance`.
    pub fn new(eta_max: f64, tolerance: f64) -> Self {
        Self { eta_max, tolerance, last: None }
    }

    /// Forget the history: the next term is the first of a new solve.
    pub fn restart(&mut self) {
        self.last = None;
    }

    /// The forcing term of the solve at relative residual `r` (and remember it).
    pub fn next(&mut self, r: f64) -> f64 {
        let eta = match self.last {
            None => self.eta_max,
            Some((r_prev, eta_prev)) => {
                let mut eta = if r_prev > 0.0 { GAMMA * (r / r_prev).powf(ALPHA) } else { self.eta_max };
                let floor = GAMMA * eta_prev.powf(ALPHA);
                if floor > 0.1 {
                    eta = eta.max(floor);
                }
                eta.min(self.eta_max)
            }
        };
        let eta = if r > 0.0 { eta.max((0.1 * self.tolerance / r).min(0.5)) } else { eta };
        let eta = if eta.is_finite() { eta } else { self.eta_max };
        self.last = Some((r, eta));
        eta
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_term_is_the_largest_and_a_quadratic_convergence_tightens_it_quadratically() {
        let mut f = Forcing::new(1e-3, 1e-12);
        assert_eq!(f.next(1.0), 1e-3);
        // r falls by 1e-2: η = 0.9 · 1e-4
        assert!((f.next(1e-2) - 0.9e-4).abs() < 1e-18);
        // r falls by 1e-3: η = 0.9 · 1e-6
        assert!((f.next(1e-5) - 0.9e-6).abs() < 1e-20);
    }

    #[test]
    fn a_stalling_newton_keeps_the_largest_term() {
        let mut f = Forcing::new(1e-2, 1e-10);
        f.next(1.0);
        assert_eq!(f.next(2.0), 1e-2);
        assert_eq!(f.next(1.9), 1e-2);
    }

    #[test]
    fn the_last_solve_is_not_oversolved() {
        let mut f = Forcing::new(1e-3, 1e-8);
        f.next(1e-1);
        // choice 2 alone would ask 0.9 · 1e-8; the next residual need only reach 1e-8
        let eta = f.next(1e-5);
        assert!((eta - 0.1 * 1e-8 / 1e-5).abs() < 1e-15, "{eta}");
    }

    #[test]
    fn a_restart_begins_a_new_sequence() {
        let mut f = Forcing::new(1e-3, 1e-12);
        f.next(1.0);
        f.next(1e-6);
        f.restart();
        assert_eq!(f.next(1e-6), 1e-3);
    }

    #[test]
    fn the_safeguard_holds_a_large_term_from_falling_at_once() {
        let mut f = Forcing::new(0.9, 1e-12);
        assert_eq!(f.next(1.0), 0.9);
        // choice 2: 0.9 · 1e-4; the safeguard keeps 0.9 · 0.9² = 0.729
        assert!((f.next(1e-2) - 0.729).abs() < 1e-12);
    }
}
