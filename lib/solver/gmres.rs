//! Restarted GMRES with right preconditioning (Saad & Schultz 1986; Saad,
//! *Iterative Methods for Sparse Linear Systems*, 2nd ed., alg. 9.5).
//!
//! Solves `A x = b` by minimising `‖b − A M⁻¹ y‖` over the Krylov space of
//! `A M⁻¹`, then `x = M⁻¹ y`. Right preconditioning makes the minimised norm the
//! true residual's, so the stopping test `‖b − A x‖ ≤ tol ‖b‖` means what it says;
//! at each restart, and before reporting convergence, the residual is recomputed
//! from `x` (the recurrence drifts from it in floating point). A solve to the
//! round-off floor (a tolerance at or below [`FLOOR_TOLERANCE`]) estimates the
//! floor at its first iterate, so that its first cycle stops there; the
//! convergence test uses the floor at the final `x`.
//!
//! Arnoldi by modified Gram–Schmidt, the Hessenberg least-squares problem by Givens
//! rotations. The preconditioner is applied once per iteration: the preconditioned
//! vectors `z_k = M⁻¹ v_k` are kept, so the update is `x += Z y` (a preconditioner
//! application costs a pair of triangular solves, the vectors only memory). The
//! vectors are allocated as the iterations first need them, once per call.

/// Settings of [`gmres`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GmresSettings {
    /// Relative residual `‖b − A x‖ / ‖b‖` to reach.
    pub tolerance: f64,
    /// Most Krylov iterations in all (over every restart cycle).
    pub max_iterations: usize,
    /// Krylov vectors per cycle.
    pub restart: usize,
}

impl Default for GmresSettings {
    fn default() -> Self {
        Self { tolerance: 1e-12, max_iterations: 200, restart: 60 }
    }
}

/// How a [`gmres`] call ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GmresOutcome {
    pub converged: bool,
    pub iterations: usize,
    /// `‖b − A x‖ / ‖b‖` of the returned `x`.
    pub relative_residual: f64,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The Euclidean norm (the same sum, in the same order, as every GMRES norm here).
pub(crate) fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// A tolerance at or below which a solve is one to the round-off floor: its
/// first cycle stops at the floor estimated at its first iterate.
pub const FLOOR_TOLERANCE: f64 = 1e-14;

/// Solves `A x = b`, starting from `x = 0`. `apply(v, out)`: `out = A v`;
/// `precondition(v)`: `v ← M⁻¹ v` in place; `floor(x)`: the residual norm that
/// round-off alone leaves at `x` (e.g. `c ε ‖|A| |x|‖`, what a backward-stable
/// direct solve attains), below which no iteration can go: the solve stops at
/// `max(tolerance ‖b‖, floor(x))`. A well-conditioned system never meets the
/// floor; one with large cancellation (a stiff penalty spring between bodies
/// that move together) would otherwise iterate on round-off noise.
pub fn gmres(
    b: &[f64],
    x: &mut [f64],
    settings: GmresSettings,
    apply: &mut dyn FnMut(&[f64], &mut [f64]),
    precondition: &mut dyn FnMut(&mut [f64]) -> Result<(), String>,
    floor: &mut dyn FnMut(&[f64]) -> f64,
) -> Result<GmresOutcome, String> {
    let n = b.len();
    x.fill(0.0);
    let b_norm = norm(b);
    if b_norm == 0.0 {
        return Ok(GmresOutcome { converged: true, iterations: 0, relative_residual: 0.0 });
    }
    let m = settings.restart.max(1);
    let tolerance = settings.tolerance * b_norm;
    let mut target = tolerance;
    let mut v: Vec<Vec<f64>> = vec![vec![0.0; n]];
    let mut zs: Vec<Vec<f64>> = Vec::new();
    let mut h = vec![vec![0.0; m]; m + 1]; // h[i][k]
    let (mut cs, mut sn, mut g) = (vec![0.0; m], vec![0.0; m], vec![0.0; m + 1]);
    let mut w = vec![0.0; n];
    let mut iterations = 0;
    // A solve to the round-off floor: the floor, known only at an iterate, is
    // estimated at the first one (the preconditioned residual, β M⁻¹ v₀, the iterate
    // of a near-exact preconditioner), so that the first cycle stops there instead
    // of iterating on to the tolerance's ε ‖b‖; the true residual decides after
    // it, against the floor at the final x.
    let to_floor = settings.tolerance <= FLOOR_TOLERANCE;
    loop {
        // r = b − A x (x = 0 at the start: r = b, no product)
        if iterations == 0 {
            w.copy_from_slice(b);
        } else {
            apply(x, &mut w);
            for (wi, bi) in w.iter_mut().zip(b) {
                *wi = bi - *wi;
            }
        }
        let beta = norm(&w);
        if iterations > 0 {
            // the floor at this x, not the first iterate's estimate; not needed
            // (a pass over A) when the tolerance is met
            target = if beta <= tolerance { tolerance } else { tolerance.max(floor(x)) };
        }
        if beta <= target || iterations >= settings.max_iterations || !beta.is_finite() {
            return Ok(GmresOutcome { converged: beta <= target, iterations, relative_residual: beta / b_norm });
        }
        for (vi, wi) in v[0].iter_mut().zip(&w) {
            *vi = wi / beta;
        }
        g.fill(0.0);
        g[0] = beta;
        let mut k_done = 0;
        for k in 0..m {
            // z_k = M⁻¹ v_k, w = A z_k
            if zs.len() <= k {
                zs.push(vec![0.0; n]);
            }
            if v.len() <= k + 1 {
                v.push(vec![0.0; n]);
            }
            let (head, _) = v.split_at_mut(k + 1);
            zs[k].copy_from_slice(&head[k]);
            precondition(&mut zs[k])?;
            if to_floor && iterations == 0 {
                // the first iterate in w, which the product below overwrites
                for (wj, zj) in w.iter_mut().zip(&zs[0]) {
                    *wj = g[0] * zj;
                }
                target = target.max(floor(&w));
            }
            apply(&zs[k], &mut w);
            // modified Gram–Schmidt against v_0 … v_k
            for (i, vi) in head.iter().enumerate() {
                let hik = dot(&w, vi);
                h[i][k] = hik;
                for (wj, vj) in w.iter_mut().zip(vi) {
                    *wj -= hik * vj;
                }
            }
            let h_next = norm(&w);
            h[k + 1][k] = h_next;
            if h_next > 0.0 {
                for (vj, wj) in v[k + 1].iter_mut().zip(&w) {
                    *vj = wj / h_next;
                }
            }
            // the earlier rotations on column k, then a new one against h[k+1][k]
            for i in 0..k {
                let (a, c) = (h[i][k], h[i + 1][k]);
                h[i][k] = cs[i] * a + sn[i] * c;
                h[i + 1][k] = -sn[i] * a + cs[i] * c;
            }
            let (a, c) = (h[k][k], h[k + 1][k]);
            let r = a.hypot(c);
            (cs[k], sn[k]) = if r == 0.0 { (1.0, 0.0) } else { (a / r, c / r) };
            h[k][k] = r;
            h[k + 1][k] = 0.0;
            g[k + 1] = -sn[k] * g[k];
            g[k] *= cs[k];
            iterations += 1;
            k_done = k + 1;
            if g[k + 1].abs() <= target || h_next == 0.0 || iterations >= settings.max_iterations {
                break;
            }
        }
        // y = H⁻¹ g (upper triangular), x += Z y
        let mut y = vec![0.0; k_done];
        for i in (0..k_done).rev() {
            let s: f64 = ((i + 1)..k_done).map(|j| h[i][j] * y[j]).sum();
            y[i] = if h[i][i] != 0.0 { (g[i] - s) / h[i][i] } else { 0.0 };
        }
        for (yi, zi) in y.iter().zip(&zs) {
            for (xj, zj) in x.iter_mut().zip(zi) {
                *xj += yi * zj;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::fd::Lcg;

    /// A dense non-symmetric, non-normal matrix: tridiagonal plus a skew part.
    fn matrix(n: usize, skew: f64) -> Vec<Vec<f64>> {
        let mut rng = Lcg(5);
        let mut a = vec![vec![0.0; n]; n];
        for i in 0..n {
            a[i][i] = 4.0 + rng.uniform();
            if i + 1 < n {
                let s = skew * rng.uniform();
                a[i][i + 1] = -1.0 + s;
                a[i + 1][i] = -1.0 - s;
            }
            if i + 5 < n {
                a[i][i + 5] = 0.3 * skew;
            }
        }
        a
    }

    fn mul(a: &[Vec<f64>], x: &[f64], out: &mut [f64]) {
        for (o, row) in out.iter_mut().zip(a) {
            *o = dot(row, x);
        }
    }

    #[test]
    fn converges_to_the_true_residual_with_and_without_restarts() {
        let n = 120;
        let a = matrix(n, 2.0);
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 0.5).collect();
        for restart in [5, 200] {
            let mut x = vec![0.0; n];
            let settings = GmresSettings { tolerance: 1e-12, max_iterations: 2000, restart };
            let out = gmres(&b, &mut x, settings, &mut |v, o| mul(&a, v, o), &mut |_| Ok(()), &mut |_| 0.0).unwrap();
            let mut r = vec![0.0; n];
            mul(&a, &x, &mut r);
            let res = r.iter().zip(&b).map(|(ri, bi)| (bi - ri).powi(2)).sum::<f64>().sqrt() / norm(&b);
            assert!(out.converged && res <= 1e-12, "restart {restart}: {out:?}, true residual {res:e}");
            assert!((out.relative_residual - res).abs() < 1e-14);
        }
    }

    #[test]
    fn an_exact_preconditioner_converges_in_one_iteration() {
        // M = A (diagonal): one Krylov vector spans the solution.
        let n = 30;
        let d: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        let b = vec![1.0; n];
        let mut x = vec![0.0; n];
        let out = gmres(
            &b,
            &mut x,
            GmresSettings::default(),
            &mut |v, o| o.iter_mut().zip(v).zip(&d).for_each(|((o, v), d)| *o = d * v),
            &mut |v| {
                v.iter_mut().zip(&d).for_each(|(v, d)| *v /= d);
                Ok(())
            },
            &mut |_| 0.0,
        )
        .unwrap();
        assert!(out.converged && out.iterations == 1, "{out:?}");
        assert!(x.iter().zip(&d).all(|(x, d)| (x * d - 1.0).abs() < 1e-14));
    }

    /// A solve to the round-off floor stops where the floor is, in its first cycle:
    /// as many iterations as a solve to a tolerance equal to the floor (without
    /// the early estimate it iterates on toward ε ‖b‖). An estimate at the first
    /// iterate that is too high stops the first cycle early, but the answer is
    /// checked against the floor at the final x and iterated on to it.
    #[test]
    fn a_solve_to_the_floor_stops_at_the_floor_and_only_there() {
        let n = 120;
        let a = matrix(n, 2.0);
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 0.5).collect();
        let b_norm = norm(&b);
        let run = |tolerance: f64, floor: &mut dyn FnMut(&[f64]) -> f64| {
            let mut x = vec![0.0; n];
            let settings = GmresSettings { tolerance, max_iterations: 500, restart: 200 };
            gmres(&b, &mut x, settings, &mut |v, o| mul(&a, v, o), &mut |_| Ok(()), floor).unwrap()
        };
        let mut floors = 0;
        let to_tolerance = run(1e-9, &mut |_| {
            floors += 1;
            0.0
        });
        assert_eq!(floors, 0, "a solve that meets its tolerance never needs the floor");
        let to_floor = run(f64::EPSILON, &mut |_| 1e-9 * b_norm);
        assert!(to_floor.converged && to_floor.relative_residual <= 1e-9, "{to_floor:?}");
        assert_eq!(to_floor.iterations, to_tolerance.iterations, "{to_floor:?} against {to_tolerance:?}");
        let to_epsilon = run(1.1 * FLOOR_TOLERANCE, &mut |_| 1e-9 * b_norm);
        assert!(to_epsilon.iterations > to_floor.iterations, "above FLOOR_TOLERANCE the first cycle runs on: {to_epsilon:?}");
        // the first estimate a thousand times too high: still solved to the floor
        let mut calls = 0;
        let misled = run(f64::EPSILON, &mut |_| {
            calls += 1;
            if calls == 1 { 1e-6 * b_norm } else { 1e-9 * b_norm }
        });
        assert!(misled.converged && misled.relative_residual <= 1e-9, "{misled:?}");
    }

    #[test]
    fn reports_failure_within_the_iteration_budget() {
        let n = 200;
        let a = matrix(n, 40.0);
        let b = vec![1.0; n];
        let mut x = vec![0.0; n];
        let settings = GmresSettings { tolerance: 1e-14, max_iterations: 7, restart: 3 };
        let out = gmres(&b, &mut x, settings, &mut |v, o| mul(&a, v, o), &mut |_| Ok(()), &mut |_| 0.0).unwrap();
        assert!(!out.converged && out.iterations == 7 && out.relative_residual > 1e-14, "{out:?}");
    }
}
