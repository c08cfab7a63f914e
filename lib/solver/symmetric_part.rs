//! The frictional tangent's solver: GMRES preconditioned by a Cholesky-type
//! factorization of the tangent's symmetric part.
//!
//! Friction makes the tangent `K` non-symmetric (the slip direction and the
//! normal–tangential coupling μ ε_N, paper eqs. 4.7–4.8, 6.x), but only mildly:
//! on the paper's beams `max|K − Kᵀ| / max|K|` is 0.02–0.2. A sparse LU pays for
//! the non-symmetry in full: faer orders it by COLAMD and pivots, and on 3D meshes
//! its fill explodes (24 s and 8.2 GB for one factorization at 110k dofs, where the
//! symmetric matrix factors by Cholesky in 2.3 s and 1.6 GB).
//!
//! Write `K = S + A` with `S = (K + Kᵀ)/2` and `A = (K − Kᵀ)/2`. Factor `S` once
//! per Newton iteration (`LLᵀ`, `LDLᵀ` if it is indefinite; nested-dissection
//! ordering, the symbolic analysis reused) and solve `K x = b` by GMRES with `S⁻¹`
//! as right preconditioner. When `S` is positive definite, `S⁻¹K = I + S⁻¹A` and
//! `S^{-1/2} A S^{-1/2}` is skew, so the preconditioned spectrum lies on the line
//! `1 + iσ`: GMRES converges in a few iterations when σ is moderate (Concus–Golub
//! and Widlund's observation for shifted skew systems). Each iteration costs one
//! triangular solve pair and one matrix–vector product.
//!
//! **Fallback.** When `S` cannot be factored, or GMRES misses its tolerance within
//! its budget, the iteration's system is solved by faer's LU instead, and
//! [`LinearSolver::last_solve`] says so; the next Newton iteration tries the
//! preconditioner again.
//!
//! The result is the solution of `K x = b` to the relative residual
//! [`GmresSettings::tolerance`] (1e-12 by default, far below Newton's 1e-8, or
//! the inexact Newton's forcing term, [`LinearSolver::set_forcing`]).
//!
//! **Keeping the factorization.** A factorization of `S` is kept for the next Newton
//! iteration while the last solve needed at most `reuse_below` GMRES iterations
//! (the tangent then changes little from one iteration to the next); a kept one
//! gets at most [`KEPT_BUDGET_FACTOR`] × `reuse_below` iterations, after which `S`
//! is factored anew and the solve repeated. Every increment starts with a fresh
//! factorization ([`LinearSolver::begin_increment`]).
//!
//! **A symmetric tangent** (frictionless, no follower pressure; `analyse` with
//! [`Symmetry::Symmetric`]): `S = K`, so a fresh factorization solves `K x = b`
//! directly (the direct solver's operations, bit for bit) and a kept one is a
//! preconditioner for the tangent it was not made of: a modified Newton method
//! whose steps GMRES makes exact. `K` is copied only for a kept factorization's
//! GMRES solve, and dropped after it (no transpose map, no separate `S`, and the
//! peak memory of a factorization is the direct solver's); a factorization that
//! fails is an error (a singular tangent is reported with its dof, as by
//! [`FaerDirect`]; no LU).
//!
//! **Single precision** ([`super::linear::FactorPrecision::Single`], the default
//! of `linear_solver: direct`). The factor of `S` (of `K` itself when it is
//! symmetric) is made in `f32`: half the bytes, so half the memory traffic of
//! the factorization and of every triangular solve, and twice the SIMD lanes.
//! Its solves are then accurate to about κ · 6e-8, so every solve, a fresh
//! factor's included, is a GMRES solve with it as preconditioner: a fresh
//! factor's of a symmetric tangent to the round-off floor a direct solve reaches
//! (within [`SINGLE_BUDGET`] iterations), a kept one's as with a double factor.
//! When GMRES does not converge with a fresh single-precision factor, the matrix
//! is factored in `f64` and the solve repeated (before the LU fallback of a
//! non-symmetric tangent); a factor that `f32` cannot hold (a non-positive or
//! tiny pivot) is made in `f64` at once ([`FaerDirect`]). Newton asks it for a
//! symmetric tangent only (`docs/theory/solver.md`).

use std::time::{Duration, Instant};

use faer::sparse::{SymbolicSparseColMat, SymbolicSparseColMatRef};
use rayon::prelude::*;

use super::gmres::{gmres, norm, GmresSettings};
use super::linear::{check_values, FactorInfo, FaerDirect, FaerDirectOptions, Factorization, LinearSolver, LinearSolverError, SharedPattern, SolveReport, SolverTimings, Symmetry};

/// A kept factorization gets at most this many times `reuse_below` GMRES
/// iterations before `S` is factored anew (a tangent that moved far from it).
pub const KEPT_BUDGET_FACTOR: usize = 4;

/// The loosest relative tolerance a kept factorization's solve of a symmetric
/// tangent is given (`SymmetricPartGmres::kept_symmetric_settings`): its GMRES stops at
/// `tolerance × ‖b₀‖`, `b₀` the largest right-hand side of the increment so far
/// (its first, usually), and never above this relative to its own `‖b‖`.
pub const KEPT_LOOSEST: f64 = 1e-8;

/// GMRES iterations a fresh single-precision factor gets before the tangent is
/// factored in double precision: a factor that needs more preconditions poorly
/// (κ ε₃₂ above ~0.15; the Parisch blocks need 3–4 to the round-off floor), and
/// the double factorization costs less than the iterations it saves.
pub const SINGLE_BUDGET: usize = 20;

/// GMRES on `K`, preconditioned by the factorization of `(K + Kᵀ)/2`.
pub struct SymmetricPartGmres {
    settings: GmresSettings,
    /// The tolerance of the settings, below which a forcing term never goes.
    base_tolerance: f64,
    /// Factors the symmetric part.
    symmetric: FaerDirect,
    /// The LU fallback, analysed on first use.
    lu: FaerDirect,
    lu_analysed: bool,
    /// `analyse` succeeded (the pattern is held by `symmetric`, or by `lu` when
    /// `transpose` is empty and the tangent is not symmetric).
    analysed: bool,
    /// `K` is symmetric (`analyse` with [`Symmetry::Symmetric`]): `S = K`.
    symmetric_tangent: bool,
    /// `transpose[p]`: position of entry `(j, i)` for the entry `(i, j)` at `p`;
    /// empty when the pattern is not structurally symmetric (then only LU is used).
    /// (The pattern itself is the inner factorizations'.)
    transpose: Vec<u32>,
    /// `Kᵀ` in the pattern's CSC order, that is `K` by rows (the only copy of `K`
    /// kept: `K[p] = values_t[transpose[p]]`); `K` itself when the pattern is not
    /// structurally symmetric. Empty for a symmetric `K`: its rows are its columns,
    /// and its solves read the caller's values (`solve_in_place`).
    values_t: Vec<f64>,
    /// Scratch: `S` for its factorization, or `K` for the LU fallback.
    s_values: Vec<f64>,
    rhs: Vec<f64>,
    /// Why this factor's systems go to LU (`None`: the preconditioner holds).
    lu_reason: Option<String>,
    /// Keep the held factorization of `S` while the last solve needed at most this
    /// many GMRES iterations (0: factor every time).
    reuse_below: usize,
    /// The factorization of `S` held, if any (for this pattern), and whether it is of
    /// the current values.
    held: Option<Factorization>,
    fresh: bool,
    /// GMRES iterations of the last solve that converged (`usize::MAX`: none yet).
    last_iterations: usize,
    /// The largest `‖b‖` solved for since the increment began (`begin_increment`).
    increment_rhs: f64,
    n_reused: usize,
    last: SolveReport,
    symbolic_time: Duration,
    numeric_time: Duration,
    solve_time: Duration,
    n_symbolic: usize,
    n_numeric: usize,
    n_solve: usize,
    n_krylov: usize,
    n_fallback: usize,
}

impl SymmetricPartGmres {
    /// `direct`: the options of both factorizations (its `symmetric` strategy is
    /// used for `S`); `reuse_below`: see [`Self::reuse_below`].
    pub fn new(settings: GmresSettings, direct: FaerDirectOptions) -> Self {
        Self::with_reuse(settings, direct, 0)
    }

    /// As [`Self::new`], keeping the factorization of `S` from one `factor` to the
    /// next while the last solve took at most `reuse_below` GMRES iterations.
    pub fn with_reuse(settings: GmresSettings, direct: FaerDirectOptions, reuse_below: usize) -> Self {
        Self {
            reuse_below,
            held: None,
            fresh: false,
            last_iterations: usize::MAX,
            increment_rhs: 0.0,
            n_reused: 0,
            base_tolerance: settings.tolerance,
            settings,
            symmetric: FaerDirect::new(direct),
            lu: FaerDirect::new(direct),
            lu_analysed: false,
            analysed: false,
            symmetric_tangent: false,
            transpose: Vec::new(),
            values_t: Vec::new(),
            s_values: Vec::new(),
            rhs: Vec::new(),
            lu_reason: None,
            last: SolveReport::default(),
            symbolic_time: Duration::ZERO,
            numeric_time: Duration::ZERO,
            solve_time: Duration::ZERO,
            n_symbolic: 0,
            n_numeric: 0,
            n_solve: 0,
            n_krylov: 0,
            n_fallback: 0,
        }
    }

    /// Whether a pattern of `nnz` entries goes to LU alone (not structurally
    /// symmetric: no transpose map).
    fn general_pattern(&self, nnz: usize) -> bool {
        !self.symmetric_tangent && self.transpose.is_empty() && nnz > 0
    }

    /// The analysed pattern (held by the inner factorization that uses it).
    fn pattern(&self) -> Option<&SymbolicSparseColMat<usize>> {
        if !self.analysed {
            None
        } else if self.transpose.is_empty() && !self.symmetric_tangent {
            self.lu.pattern().or(self.symmetric.pattern())
        } else {
            self.symmetric.pattern()
        }
    }

    /// GMRES on `K` (given by rows: `values_t`, or a symmetric `K`'s own values)
    /// with the held factorization of `S`, right-hand side `self.rhs`, solution
    /// into `x`.
    fn run_gmres(&self, values_t: &[f64], x: &mut [f64], settings: GmresSettings) -> Result<super::gmres::GmresOutcome, String> {
        let symmetric = &self.symmetric;
        let pattern = symmetric.pattern().ok_or("no pattern")?;
        let n = pattern.nrows();
        let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
        // (K x)_i = Σ_j K_ij x_j: row i of K is column i of Kᵀ (structural symmetry).
        let mut apply = |x: &[f64], out: &mut [f64]| {
            out.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, o)| {
                *o = (cp[i]..cp[i + 1]).map(|p| values_t[p] * x[ri[p]]).sum();
            });
        };
        let mut precondition = |v: &mut [f64]| symmetric.solve(v).map_err(|e| e.to_string());
        // round-off floor of the residual: 64 ε ‖|K| |x|‖ (partial sums over fixed
        // chunks, added in order: the same bits on any number of threads)
        let mut floor = |x: &[f64]| {
            const CHUNK: usize = 4096;
            let partial: Vec<f64> = (0..n.div_ceil(CHUNK))
                .into_par_iter()
                .map(|c| (c * CHUNK..n.min((c + 1) * CHUNK)).map(|i| (cp[i]..cp[i + 1]).map(|p| (values_t[p] * x[ri[p]]).abs()).sum::<f64>().powi(2)).sum())
                .collect();
            64.0 * f64::EPSILON * partial.iter().sum::<f64>().sqrt()
        };
        gmres(&self.rhs, x, settings, &mut apply, &mut precondition, &mut floor)
    }

    /// The GMRES settings of a solve with a kept factorization: a tangent far from it
    /// is factored anew after [`KEPT_BUDGET_FACTOR`] × `reuse_below` iterations.
    fn kept_settings(&self) -> GmresSettings {
        let budget = KEPT_BUDGET_FACTOR * self.reuse_below.max(1);
        GmresSettings { max_iterations: self.settings.max_iterations.min(budget), ..self.settings }
    }

    /// [`Self::kept_settings`] of a symmetric tangent's solve of `‖b‖ = b_norm`, to
    /// the tolerance of the increment's scale ([`KEPT_LOOSEST`]).
    fn kept_symmetric_settings(&self, b_norm: f64) -> GmresSettings {
        // the increment's scale: each of its solves to `tolerance` of its first
        // right-hand side, as accurate in u as the first (a direct solve's up to
        // round-off), not to `tolerance` of its own, which near convergence is
        // 1e-6 of the first and asks six more digits than u can hold
        let scaled = if b_norm > 0.0 { self.settings.tolerance * self.increment_rhs / b_norm } else { self.settings.tolerance };
        let tolerance = scaled.clamp(self.settings.tolerance, KEPT_LOOSEST.max(self.settings.tolerance));
        GmresSettings { tolerance, ..self.kept_settings() }
    }

    /// Factor `S` of the stored values: `S[p] = (K[p] + Kᵀ[p]) / 2` (in double
    /// precision when `double`, else in the options' precision).
    fn factor_symmetric(&mut self, double: bool) -> Result<Factorization, LinearSolverError> {
        let mut s = std::mem::take(&mut self.s_values);
        let vt = &self.values_t;
        s.clear();
        s.extend(self.transpose.iter().zip(vt).map(|(&q, at)| 0.5 * (vt[q as usize] + at)));
        let result = self.factor_and_hold(&s, double);
        self.s_values = s;
        result
    }

    /// Factor `K` (the stored values) by LU, for the reason given.
    fn factor_lu(&mut self, reason: String) -> Result<(), LinearSolverError> {
        if !self.lu_analysed {
            let pattern = self.symmetric.pattern().ok_or(LinearSolverError::Order("factor", "analyse"))?;
            // sized before it runs, from the symmetric part's Cholesky factor
            crate::solver::memory::check_lu(self.symmetric.factor_len(), pattern.nrows(), pattern.compute_nnz(), crate::solver::memory::available()).map_err(LinearSolverError::TooLarge)?;
            self.lu.analyse(pattern.as_ref(), Symmetry::General)?;
            self.lu_analysed = true;
        }
        if self.transpose.is_empty() {
            self.lu.factor(&self.values_t)?;
        } else {
            let vt = &self.values_t;
            self.s_values.clear();
            self.s_values.extend(self.transpose.iter().map(|&q| vt[q as usize]));
            self.lu.factor(&self.s_values)?;
        }
        self.n_numeric += 1;
        self.lu_reason = Some(reason);
        Ok(())
    }
}

impl SymmetricPartGmres {
    /// `factor` of a symmetric tangent: keep the held factorization while the last
    /// solve needed at most `reuse_below` iterations, else factor `K` itself. No
    /// copy of `K` either way: GMRES (with a kept or a single-precision factor)
    /// applies the values the solve is given. A tangent that cannot be factored
    /// is reported (a singular one with its dof), as the direct solver does.
    fn factor_symmetric_tangent(&mut self, values: &[f64]) -> Result<Factorization, LinearSolverError> {
        match self.held {
            Some(method) if self.last_iterations <= self.reuse_below => {
                self.fresh = false;
                self.n_reused += 1;
                Ok(method)
            }
            _ => self.factor_and_hold(values, false),
        }
    }

    /// Factor `values` (a symmetric tangent `K` itself, or the symmetric part `S`
    /// of a general one) and hold the factorization; in double precision when
    /// `double`, else in the options' precision.
    fn factor_and_hold(&mut self, values: &[f64], double: bool) -> Result<Factorization, LinearSolverError> {
        self.held = None;
        let info = if double { self.symmetric.factor_in_double(values)? } else { self.symmetric.factor(values)? };
        self.held = Some(info.method);
        self.fresh = true;
        self.n_numeric += 1;
        Ok(info.method)
    }

    /// `solve_in_place` of a symmetric tangent: directly with a fresh
    /// double-precision factorization (the direct solver's operations, bit for
    /// bit); by GMRES with a kept one or a single-precision one. A kept one that
    /// misses its budget is factored anew and the solve repeated; a
    /// single-precision one that misses, in double precision, which solves
    /// directly.
    fn solve_symmetric_tangent(&mut self, values: &[f64], rhs: &mut [f64]) -> Result<(), LinearSolverError> {
        if self.fresh && self.symmetric.solves_exactly() {
            self.last_iterations = 0;
            self.last = SolveReport::default();
            return self.symmetric.solve(rhs);
        }
        self.rhs.clear();
        self.rhs.extend_from_slice(rhs);
        let b_norm = norm(rhs);
        self.increment_rhs = self.increment_rhs.max(b_norm);
        // a fresh single-precision factor stands for a direct solve: GMRES to the
        // round-off floor a direct solve reaches (the floor stops it), not only to
        // the tolerance, which would leave a problem solved in one Newton
        // iteration accurate to κ times 1e-12 (the mortar patch tests, with S in
        // single in a trial: exact to 1.9e-8 instead of 1e-11)
        let settings = if self.fresh { self.fresh_single_settings() } else { self.kept_symmetric_settings(b_norm) };
        let mut iterations = 0;
        let mut converged = self.gmres_converged(values, rhs, settings, &mut iterations);
        let mut result = Ok(());
        if !converged && !self.fresh {
            // the tangent moved far from the kept factorization: factor it
            result = self.refactor_and_solve(values, rhs, false, &mut iterations).map(|done| converged = done);
        }
        if result.is_ok() && !converged {
            // a single-precision factor that does not make GMRES converge: double
            result = self.refactor_and_solve(values, rhs, true, &mut iterations).map(|_| ());
        }
        self.n_krylov += iterations;
        self.last = SolveReport { krylov_iterations: iterations, fallback: None };
        if self.fresh && self.symmetric.solves_exactly() {
            self.last_iterations = 0;
        }
        result
    }

    /// Factor `S` anew (in double precision when `double`) and run GMRES again on
    /// `self.rhs` into `x`; when the factorization fails, `outcome` stays the last
    /// one. Its iterations are added to `iterations`.
    fn refactor_symmetric_part_and_retry(&mut self, x: &mut [f64], double: bool, outcome: &mut Result<super::gmres::GmresOutcome, String>, iterations: &mut usize) {
        let t = Instant::now();
        let refactored = self.factor_symmetric(double);
        self.numeric_time += t.elapsed();
        if refactored.is_ok() {
            *outcome = self.run_gmres(&self.values_t, x, self.settings);
            *iterations += outcome.as_ref().map_or(0, |o| o.iterations);
        }
    }

    /// The GMRES settings of a symmetric tangent's solve with its fresh
    /// single-precision factor: to the round-off floor, within [`SINGLE_BUDGET`].
    fn fresh_single_settings(&self) -> GmresSettings {
        GmresSettings { tolerance: f64::EPSILON, max_iterations: self.settings.max_iterations.min(SINGLE_BUDGET), ..self.settings }
    }

    /// GMRES on the symmetric `K` of `values` and right-hand side `self.rhs` into
    /// `x`; whether it converged (its iterations added to `iterations`, and kept as
    /// the last solve's for the decision to keep the factorization).
    fn gmres_converged(&mut self, values: &[f64], x: &mut [f64], settings: GmresSettings, iterations: &mut usize) -> bool {
        let outcome = self.run_gmres(values, x, settings);
        let its = outcome.as_ref().map_or(0, |o| o.iterations);
        *iterations += its;
        self.last_iterations = its;
        matches!(outcome, Ok(o) if o.converged)
    }

    /// Factor the symmetric tangent `K` of `values` anew (in double precision when
    /// `double`) and solve `K x = self.rhs` into `x`: directly when the new factor
    /// is exact, by GMRES otherwise. Whether the solve converged.
    fn refactor_and_solve(&mut self, values: &[f64], x: &mut [f64], double: bool, iterations: &mut usize) -> Result<bool, LinearSolverError> {
        let t = Instant::now();
        let refactored = self.factor_and_hold(values, double);
        self.numeric_time += t.elapsed();
        refactored?;
        x.copy_from_slice(&self.rhs);
        if self.symmetric.solves_exactly() {
            self.symmetric.solve(x)?;
            return Ok(true);
        }
        Ok(self.gmres_converged(values, x, self.fresh_single_settings(), iterations))
    }
}

/// Positions of the transposed entries of a square CSC pattern with sorted rows, or
/// `None` when it is not structurally symmetric.
/// (Positions are `u32`: a pattern of more entries is treated as not symmetric.)
pub fn transpose_positions(pattern: SymbolicSparseColMatRef<'_, usize>) -> Option<Vec<u32>> {
    let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
    let n = pattern.ncols();
    if ri.len() > u32::MAX as usize {
        return None;
    }
    let mut next: Vec<usize> = cp[..n].to_vec();
    let mut transpose = vec![0; ri.len()];
    // Columns visited in increasing j reach the entries of row j of each column i
    // in increasing order, which is column i's sorted row order when (j, i) exists.
    for j in 0..n {
        for p in cp[j]..cp[j + 1] {
            let i = ri[p];
            let q = next[i];
            if q >= cp[i + 1] || ri[q] != j {
                return None;
            }
            transpose[p] = q as u32;
            next[i] += 1;
        }
    }
    Some(transpose)
}

impl SymmetricPartGmres {
    /// `analyse`, the symmetric part's analysis in the background when the pattern
    /// comes shared.
    fn analyse_with(&mut self, pattern: SymbolicSparseColMatRef<'_, usize>, symmetry: Symmetry, background: Option<&SharedPattern>) -> Result<(), LinearSolverError> {
        let start = Instant::now();
        self.analysed = false;
        self.held = None;
        self.last_iterations = usize::MAX;
        self.lu_analysed = false;
        self.lu_reason = None;
        self.symmetric_tangent = symmetry == Symmetry::Symmetric;
        // the old pattern's arrays and factors go first (peak memory)
        self.symmetric.release();
        self.lu.release();
        (self.transpose, self.values_t, self.s_values) = (Vec::new(), Vec::new(), Vec::new());
        if !self.symmetric_tangent {
            self.transpose = transpose_positions(pattern).unwrap_or_default();
        }
        // the inner factorizations own the pattern: S's, or LU's when the pattern is
        // not structurally symmetric
        if self.general_pattern(pattern.row_idx().len()) {
            self.lu.analyse(pattern, Symmetry::General)?;
            self.lu_analysed = true;
        } else if let Some(shared) = background {
            self.symmetric.analyse_in_background(shared, Symmetry::Symmetric)?;
        } else {
            self.symmetric.analyse(pattern, Symmetry::Symmetric)?;
        }
        self.analysed = true;
        self.symbolic_time += start.elapsed();
        self.n_symbolic += 1;
        Ok(())
    }
}

impl LinearSolver for SymmetricPartGmres {
    fn name(&self) -> &str {
        if self.symmetric_tangent {
            "faer-cholesky-kept"
        } else {
            "faer-symmetric-part-gmres"
        }
    }

    fn analyse(&mut self, pattern: SymbolicSparseColMatRef<'_, usize>, symmetry: Symmetry) -> Result<(), LinearSolverError> {
        self.analyse_with(pattern, symmetry, None)
    }

    /// The symmetric part's analysis (when the pattern is structurally symmetric)
    /// runs in the background as [`FaerDirect`]'s does; the LU's, when the pattern is
    /// not, here.
    fn analyse_in_background(&mut self, pattern: &SharedPattern, symmetry: Symmetry) -> Result<(), LinearSolverError> {
        self.analyse_with((**pattern).as_ref(), symmetry, Some(pattern))
    }

    /// For the symmetric part's ordering (the LU fallback orders by COLAMD).
    fn set_unknown_coordinates(&mut self, coordinates: std::sync::Arc<[[f64; 3]]>) {
        self.symmetric.set_unknown_coordinates(coordinates);
    }

    fn finish_analysis(&mut self) -> Result<(), LinearSolverError> {
        // the background thread's time joins this solver's analysis time
        let before = self.symmetric.timings().symbolic;
        self.symmetric.finish_analysis()?;
        self.symbolic_time += self.symmetric.timings().symbolic.saturating_sub(before);
        Ok(())
    }

    fn factor(&mut self, values: &[f64]) -> Result<FactorInfo, LinearSolverError> {
        self.finish_analysis()?;
        let nnz = check_values(self.pattern(), values)?.row_idx().len();
        let start = Instant::now();
        self.lu_reason = None;
        let method = if self.symmetric_tangent {
            self.factor_symmetric_tangent(values)?
        } else if self.general_pattern(nnz) {
            self.values_t.clear();
            self.values_t.extend_from_slice(values);
            self.factor_lu("the pattern is not structurally symmetric".into())?;
            Factorization::Lu
        } else {
            self.values_t.clear();
            let t = &self.transpose;
            self.values_t.extend(t.iter().map(|&q| values[q as usize]));
            match self.held {
                // the last solve converged quickly: the held S still preconditions well
                Some(method) if self.last_iterations <= self.reuse_below => {
                    self.fresh = false;
                    self.n_reused += 1;
                    method
                }
                _ => match self.factor_symmetric(false) {
                    Ok(method) => method,
                    Err(e) => {
                        self.factor_lu(format!("the symmetric part could not be factored ({e})"))?;
                        Factorization::Lu
                    }
                },
            }
        };
        let time = start.elapsed();
        self.numeric_time += time;
        Ok(FactorInfo { method, time })
    }

    fn begin_increment(&mut self) {
        // the held S is not used again: the increment's first `factor` factors anew
        self.held = None;
        self.increment_rhs = 0.0;
    }

    fn solve_in_place(&mut self, values: &[f64], rhs: &mut [f64]) -> Result<(), LinearSolverError> {
        self.finish_analysis()?;
        let Some(pattern) = self.pattern() else {
            return Err(LinearSolverError::Order("solve_in_place", "analyse"));
        };
        let (n, nnz) = (pattern.nrows(), pattern.row_idx().len());
        if rhs.len() != n {
            return Err(LinearSolverError::Dimension { what: "right-hand side entries", expected: n, got: rhs.len() });
        }
        let start = Instant::now();
        self.n_solve += 1;
        if self.symmetric_tangent {
            // GMRES applies the symmetric K of these values (its rows are its columns)
            if values.len() != nnz {
                return Err(LinearSolverError::Dimension { what: "values (pattern entries)", expected: nnz, got: values.len() });
            }
            let result = self.solve_symmetric_tangent(values, rhs);
            self.solve_time += start.elapsed();
            return result;
        }
        if let Some(reason) = &self.lu_reason {
            self.last = SolveReport { krylov_iterations: 0, fallback: Some(format!("{reason}: solved by LU instead")) };
            let r = self.lu.solve(rhs);
            self.solve_time += start.elapsed();
            return r;
        }
        self.rhs.clear();
        self.rhs.extend_from_slice(rhs);
        let settings = if self.fresh { self.settings } else { self.kept_settings() };
        let mut outcome = self.run_gmres(&self.values_t, rhs, settings);
        let mut iterations = outcome.as_ref().map_or(0, |o| o.iterations);
        if !matches!(outcome, Ok(o) if o.converged) && !self.fresh {
            // a held factorization of an earlier S: factor the current one and retry
            self.refactor_symmetric_part_and_retry(rhs, false, &mut outcome, &mut iterations);
        }
        if !matches!(outcome, Ok(o) if o.converged) && self.held.is_some() && !self.symmetric.solves_exactly() {
            // a single-precision factor of S that does not precondition K well
            // enough: S in double precision, and retry before LU
            self.refactor_symmetric_part_and_retry(rhs, true, &mut outcome, &mut iterations);
        }
        self.n_krylov += iterations;
        let result = match outcome {
            Ok(o) if o.converged => {
                self.last_iterations = iterations;
                self.last = SolveReport { krylov_iterations: iterations, fallback: None };
                Ok(())
            }
            other => {
                let why = match other {
                    Ok(o) => format!(
                        "GMRES preconditioned by the symmetric part reached a relative residual of {:.2e} in {} iterations (tolerance {:.0e})",
                        o.relative_residual, iterations, self.settings.tolerance
                    ),
                    Err(e) => format!("the symmetric part's solve failed ({e})"),
                };
                self.last_iterations = usize::MAX;
                self.n_fallback += 1;
                let t = Instant::now();
                let factored = self.factor_lu(why.clone());
                self.numeric_time += t.elapsed();
                factored?;
                rhs.copy_from_slice(&self.rhs);
                self.last = SolveReport { krylov_iterations: iterations, fallback: Some(format!("{why}: solved by LU instead")) };
                self.lu.solve(rhs)
            }
        };
        self.solve_time += start.elapsed();
        result
    }

    fn timings(&self) -> SolverTimings {
        SolverTimings {
            symbolic: self.symbolic_time,
            numeric: self.numeric_time,
            solve: self.solve_time,
            n_symbolic: self.n_symbolic,
            n_numeric: self.n_numeric,
            n_solve: self.n_solve,
            n_krylov: self.n_krylov,
            n_fallback: self.n_fallback,
            n_reused: self.n_reused,
            largest_factor: self.symmetric.timings().largest_factor.max(self.lu.timings().largest_factor),
        }
    }

    fn last_solve(&self) -> SolveReport {
        self.last.clone()
    }

    fn set_forcing(&mut self, eta: f64) {
        self.settings.tolerance = if eta.is_finite() { eta.clamp(self.base_tolerance, 0.5) } else { self.base_tolerance };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::bench::{elastic_cube_system, relative_residual};
    use crate::solver::linear::FactorPrecision;

    /// The elastic cube's stiffness plus a skew part of relative size `skew` on the
    /// couplings between the x and y dofs of neighbouring nodes (friction-like).
    fn skewed(skew: f64) -> (SymbolicSparseColMat<usize>, Vec<f64>, Vec<f64>) {
        let cube = elastic_cube_system(4).unwrap();
        let p = cube.pattern.symbolic_owned().clone();
        let mut v = cube.assembly.values().to_vec();
        let t = transpose_positions(p.as_ref()).unwrap();
        let scale = v.iter().map(|x| x.abs()).fold(0.0, f64::max);
        for j in 0..p.ncols() {
            for q in p.col_ptr()[j]..p.col_ptr()[j + 1] {
                let i = p.row_idx()[q];
                if i < j && i % 3 == 0 && j % 3 == 1 {
                    v[q] += skew * scale;
                    v[t[q] as usize] -= skew * scale;
                }
            }
        }
        (p, v, cube.rhs)
    }

    #[test]
    fn transposed_positions_pair_every_entry() {
        let (p, _, _) = skewed(0.0);
        let t = transpose_positions(p.as_ref()).unwrap();
        for j in 0..p.ncols() {
            for q in p.col_ptr()[j]..p.col_ptr()[j + 1] {
                let i = p.row_idx()[q];
                let back = t[q] as usize;
                assert_eq!(p.row_idx()[back], j);
                assert!(p.col_ptr()[i] <= back && back < p.col_ptr()[i + 1]);
                assert_eq!(t[back] as usize, q);
            }
        }
        // A pattern with (1, 0) but not (0, 1) is not structurally symmetric.
        let lower = SymbolicSparseColMat::new_checked(2, 2, vec![0, 2, 3], None, vec![0, 1, 1]);
        assert!(transpose_positions(lower.as_ref()).is_none());
    }

    #[test]
    fn solves_a_mildly_nonsymmetric_system_like_lu() {
        for skew in [0.01, 0.05] {
            let (p, v, b) = skewed(skew);
            let mut s = SymmetricPartGmres::new(GmresSettings::default(), FaerDirectOptions::default());
            s.analyse(p.as_ref(), Symmetry::General).unwrap();
            assert_eq!(s.factor(&v).unwrap().method, Factorization::Llt);
            let mut x = b.clone();
            s.solve_in_place(&v, &mut x).unwrap();
            let r = relative_residual(p.col_ptr(), p.row_idx(), &v, &x, &b);
            let report = s.last_solve();
            assert!(r <= 1e-12 && report.fallback.is_none(), "skew {skew}: residual {r:e}, {report:?}");
            assert!(report.krylov_iterations >= 2 && report.krylov_iterations < 60, "skew {skew}: {report:?}");
            let mut lu = FaerDirect::default();
            lu.analyse(p.as_ref(), Symmetry::General).unwrap();
            lu.factor(&v).unwrap();
            let mut y = b.clone();
            lu.solve_in_place(&v, &mut y).unwrap();
            let scale = y.iter().map(|v| v.abs()).fold(0.0, f64::max);
            let d = x.iter().zip(&y).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(d <= 1e-9 * scale, "skew {skew}: differs from LU by {:e}", d / scale);
        }
    }

    #[test]
    fn falls_back_to_lu_when_gmres_cannot_converge() {
        // A budget of one iteration cannot reach 1e-12 on a skewed system.
        let (p, v, b) = skewed(0.2);
        let settings = GmresSettings { max_iterations: 1, ..Default::default() };
        let mut s = SymmetricPartGmres::new(settings, FaerDirectOptions::default());
        s.analyse(p.as_ref(), Symmetry::General).unwrap();
        s.factor(&v).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&v, &mut x).unwrap();
        let report = s.last_solve();
        let why = report.fallback.expect("a fallback");
        assert!(why.contains("GMRES") && why.contains("1 iterations"), "{why}");
        assert!(relative_residual(p.col_ptr(), p.row_idx(), &v, &x, &b) < 1e-12);
        assert_eq!((s.timings().n_fallback, s.timings().n_solve), (1, 1));
        // The next factorization tries the preconditioner again.
        s.factor(&v).unwrap();
        assert!(s.lu_reason.is_none());
    }

    fn residual(p: &SymbolicSparseColMat<usize>, v: &[f64], x: &[f64], b: &[f64]) -> f64 {
        relative_residual(p.col_ptr(), p.row_idx(), v, x, b)
    }

    /// The values `v` with each diagonal entry `j` multiplied by `factor(j)`.
    fn scale_diagonal(p: &SymbolicSparseColMat<usize>, v: &[f64], factor: impl Fn(usize) -> f64) -> Vec<f64> {
        let mut out = v.to_vec();
        for j in 0..p.ncols() {
            let (lo, hi) = (p.col_ptr()[j], p.col_ptr()[j + 1]);
            let d = lo + p.row_idx()[lo..hi].binary_search(&j).unwrap();
            out[d] *= factor(j);
        }
        out
    }

    #[test]
    fn keeps_the_factorization_while_gmres_converges_quickly() {
        let (p, v, b) = skewed(0.002);
        let mut s = SymmetricPartGmres::with_reuse(GmresSettings { max_iterations: 15, ..Default::default() }, FaerDirectOptions::default(), 15);
        s.analyse(p.as_ref(), Symmetry::General).unwrap();
        s.factor(&v).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&v, &mut x).unwrap();
        assert!(s.fresh && s.last_solve().fallback.is_none() && s.last_solve().krylov_iterations <= 15, "{:?}", s.last_solve());
        // a nearby tangent: the held S preconditions it; the solution is K₂'s
        let v2: Vec<f64> = v.iter().map(|a| 1.02 * a).collect();
        s.factor(&v2).unwrap();
        assert!(!s.fresh);
        let mut x = b.clone();
        s.solve_in_place(&v2, &mut x).unwrap();
        assert!(residual(&p, &v2, &x, &b) <= 1e-12 && s.last_solve().fallback.is_none());
        let t = s.timings();
        assert_eq!((t.n_numeric, t.n_reused), (1, 1));
        // a far one: the stale S misses the budget, S is factored anew and GMRES
        // converges (no LU)
        let v3 = scale_diagonal(&p, &v, |j| if j % 2 == 0 { 50.0 } else { 0.6 });
        s.factor(&v3).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&v3, &mut x).unwrap();
        let t = s.timings();
        assert!(residual(&p, &v3, &x, &b) <= 1e-12, "{:?}", s.last_solve());
        assert_eq!((t.n_numeric, t.n_reused, t.n_fallback), (2, 2, 0), "{t:?}");
        assert!(s.fresh);
        // reuse 0: every factor() factors
        let mut every = SymmetricPartGmres::new(GmresSettings::default(), FaerDirectOptions::default());
        every.analyse(p.as_ref(), Symmetry::General).unwrap();
        for vals in [&v, &v2] {
            every.factor(vals).unwrap();
            let mut x = b.clone();
            every.solve_in_place(vals, &mut x).unwrap();
        }
        assert_eq!((every.timings().n_numeric, every.timings().n_reused), (2, 0));
    }

    #[test]
    fn a_symmetric_tangent_keeps_its_cholesky_factor_while_it_preconditions_well() {
        let (p, v, b) = skewed(0.0);
        let mut s = SymmetricPartGmres::with_reuse(GmresSettings::default(), FaerDirectOptions::default(), 8);
        s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        assert_eq!(s.name(), "faer-cholesky-kept");
        // no transpose map: K is stored once
        assert!(s.transpose.is_empty());
        // a fresh factor solves directly: the direct solver's answer, bit for bit,
        // and no copy of K held (nor ever: GMRES reads the values given to the solve)
        assert_eq!(s.factor(&v).unwrap().method, Factorization::Llt);
        assert!(s.values_t.is_empty());
        let mut x = b.clone();
        s.solve_in_place(&v, &mut x).unwrap();
        assert_eq!(s.last_solve().krylov_iterations, 0, "{:?}", s.last_solve());
        let mut direct = FaerDirect::default();
        direct.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        direct.factor(&v).unwrap();
        let mut y = b.clone();
        direct.solve_in_place(&v, &mut y).unwrap();
        assert_eq!(x, y);
        // a nearby tangent (a stiffer diagonal, as contact adds): the kept factor,
        // GMRES to the tolerance, no new factorization
        let v2 = scale_diagonal(&p, &v, |j| 1.0 + 0.005 * ((j % 7) as f64) / 7.0);
        s.factor(&v2).unwrap();
        assert!(!s.fresh);
        let mut x = b.clone();
        s.solve_in_place(&v2, &mut x).unwrap();
        let its = s.last_solve().krylov_iterations;
        assert!(residual(&p, &v2, &x, &b) <= 1e-12 && (2..=8).contains(&its), "{its} iterations");
        assert_eq!((s.timings().n_numeric, s.timings().n_reused), (1, 1));
        // the kept solve read v2 as given: no copy of K
        assert!(s.values_t.is_empty());
        // a far one: the kept factor misses its budget of 4 x 8 iterations and K is
        // factored anew (one more factorization, no LU)
        let v3 = scale_diagonal(&p, &v, |j| if j % 2 == 0 { 50.0 } else { 0.6 });
        s.factor(&v3).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&v3, &mut x).unwrap();
        let t = s.timings();
        assert!(residual(&p, &v3, &x, &b) <= 1e-12 && s.fresh, "{:?}", s.last_solve());
        assert_eq!((t.n_numeric, t.n_reused, t.n_fallback), (2, 2, 0), "{t:?}");
        assert_eq!(s.last_solve().krylov_iterations, KEPT_BUDGET_FACTOR * 8, "{:?}", s.last_solve());
        // a new increment starts from a fresh factorization
        s.begin_increment();
        s.factor(&v).unwrap();
        assert!(s.fresh);
    }

    /// A kept factor's solve of a symmetric tangent stops at the tolerance times the
    /// increment's first right-hand side: a right-hand side a hundredth of it to
    /// 1e-10 of its own, in fewer iterations than one of the first's size; a
    /// millionth never above [`KEPT_LOOSEST`] of its own; a new increment measures
    /// from its own first.
    #[test]
    fn a_kept_factor_solves_to_the_scale_of_the_increment() {
        let (p, v, b) = skewed(0.0);
        let mut s = SymmetricPartGmres::with_reuse(GmresSettings::default(), FaerDirectOptions::default(), 8);
        s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        s.begin_increment();
        s.factor(&v).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&v, &mut x).unwrap();
        let v2 = scale_diagonal(&p, &v, |j| 1.0 + 0.005 * ((j % 7) as f64) / 7.0);
        let kept_solve = |s: &mut SymmetricPartGmres, rhs: &[f64]| {
            s.factor(&v2).unwrap();
            assert!(!s.fresh, "the factor is kept");
            let mut x = rhs.to_vec();
            s.solve_in_place(&v2, &mut x).unwrap();
            (residual(&p, &v2, &x, rhs), s.last_solve().krylov_iterations)
        };
        let (r_full, its_full) = kept_solve(&mut s, &b);
        assert!(r_full <= 1e-12, "{r_full:e}");
        let hundredth: Vec<f64> = b.iter().map(|v| 1e-2 * v).collect();
        let (r, its) = kept_solve(&mut s, &hundredth);
        assert!(r <= 1e-10 && its < its_full, "relative residual {r:e} in {its} iterations, {its_full} for the first's size");
        let millionth: Vec<f64> = b.iter().map(|v| 1e-6 * v).collect();
        let (r, _) = kept_solve(&mut s, &millionth);
        assert!(r <= KEPT_LOOSEST, "{r:e}");
        s.begin_increment();
        assert_eq!(s.increment_rhs, 0.0);
    }

    #[test]
    fn a_single_precision_factor_solves_every_system_by_gmres_to_the_tolerance() {
        let single = FaerDirectOptions { precision: FactorPrecision::Single, ..Default::default() };
        // a symmetric tangent: the fresh factor preconditions, GMRES makes it exact,
        // reading K where the solve is given it (no copy)
        let (p, v, b) = skewed(0.0);
        let mut s = SymmetricPartGmres::with_reuse(GmresSettings::default(), single, 8);
        s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        assert_eq!(s.factor(&v).unwrap().method, Factorization::Llt);
        assert!(!s.symmetric.solves_exactly() && s.values_t.is_empty());
        let mut x = b.clone();
        s.solve_in_place(&v, &mut x).unwrap();
        let its = s.last_solve().krylov_iterations;
        assert!(residual(&p, &v, &x, &b) <= 1e-12 && (1..=8).contains(&its), "{its} iterations");
        // kept for a nearby tangent, as a double one is
        let v2 = scale_diagonal(&p, &v, |j| 1.0 + 0.005 * ((j % 7) as f64) / 7.0);
        s.factor(&v2).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&v2, &mut x).unwrap();
        assert!(residual(&p, &v2, &x, &b) <= 1e-12 && !s.fresh);
        assert_eq!((s.timings().n_numeric, s.timings().n_reused, s.timings().n_fallback), (1, 1, 0));
        // GMRES that cannot converge with the single factor (one iteration allowed):
        // K factored again in double, which solves directly
        let mut s = SymmetricPartGmres::with_reuse(GmresSettings { max_iterations: 1, ..Default::default() }, single, 8);
        s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        s.factor(&v).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&v, &mut x).unwrap();
        assert!(s.symmetric.solves_exactly() && residual(&p, &v, &x, &b) <= 1e-12);
        assert_eq!(s.timings().n_numeric, 2);
        // a free chain of unit springs, each node held by 1e-9 of one (κ ≈ 4e9):
        // singular in f32 (2 + 1e-9 rounds to 2), so the pivot check refuses the
        // single factor and the solve is the double factor's, bit for bit (with the
        // check off, GMRES with the single factor reaches the round-off floor in 20
        // iterations and the bits differ: this fails)
        let n: usize = 3000;
        let (mut col_ptr, mut row_idx, mut v) = (vec![0], vec![], vec![]);
        for j in 0..n {
            for i in j.saturating_sub(1)..(j + 2).min(n) {
                row_idx.push(i);
                v.push(if i != j { -1.0 } else if j == 0 || j == n - 1 { 1.0 + 1e-9 } else { 2.0 + 1e-9 });
            }
            col_ptr.push(row_idx.len());
        }
        let p = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let b: Vec<f64> = (0..n).map(|i| ((i % 11) as f64 - 5.0) / 5.0).collect();
        let mut s = SymmetricPartGmres::with_reuse(GmresSettings::default(), single, 8);
        s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        s.factor(&v).unwrap();
        let mut x = b.clone();
        s.solve_in_place(&v, &mut x).unwrap();
        let mut direct = FaerDirect::default();
        direct.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        direct.factor(&v).unwrap();
        let mut y = b.clone();
        direct.solve_in_place(&v, &mut y).unwrap();
        assert!(s.symmetric.solves_exactly() && x == y, "{:?}", s.last_solve());
        assert!(s.last_solve().krylov_iterations <= SINGLE_BUDGET);
        // a frictional tangent: S in single precision, GMRES, no LU
        let (p, v, b) = skewed(0.05);
        let mut s = SymmetricPartGmres::new(GmresSettings::default(), single);
        s.analyse(p.as_ref(), Symmetry::General).unwrap();
        s.factor(&v).unwrap();
        assert!(!s.symmetric.solves_exactly());
        let mut x = b.clone();
        s.solve_in_place(&v, &mut x).unwrap();
        assert!(residual(&p, &v, &x, &b) <= 1e-12, "{:?}", s.last_solve());
        assert_eq!((s.timings().n_fallback, s.last_solve().fallback), (0, None));
    }

    #[test]
    fn a_singular_symmetric_tangent_is_reported_with_its_dof() {
        // diag(1, 0): the second dof is not held; no LU fallback hides it
        let p = SymbolicSparseColMat::new_checked(2, 2, vec![0, 2, 4], None, vec![0, 1, 0, 1]);
        let v = vec![1.0, 0.0, 0.0, 0.0];
        let mut s = SymmetricPartGmres::with_reuse(GmresSettings::default(), FaerDirectOptions::default(), 8);
        s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        match s.factor(&v) {
            Err(LinearSolverError::Singular { dof: Some(1) }) => {}
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_forcing_term_loosens_the_solve_but_never_below_the_base_tolerance() {
        let (p, v, b) = skewed(0.01);
        let solve = |eta: Option<f64>| {
            let mut s = SymmetricPartGmres::new(GmresSettings::default(), FaerDirectOptions::default());
            s.analyse(p.as_ref(), Symmetry::General).unwrap();
            s.factor(&v).unwrap();
            if let Some(eta) = eta {
                s.set_forcing(eta);
            }
            let mut x = b.clone();
            s.solve_in_place(&v, &mut x).unwrap();
            (residual(&p, &v, &x, &b), s.last_solve().krylov_iterations)
        };
        let (r_tight, its_tight) = solve(None);
        let (r_loose, its_loose) = solve(Some(1e-3));
        assert!(r_tight <= 1e-12 && r_loose <= 1e-3 && its_loose < its_tight, "{r_tight:e} {its_tight}, {r_loose:e} {its_loose}");
        // a forcing term below the base tolerance, or not finite, gives the base one
        for eta in [1e-20, f64::NAN] {
            assert!(solve(Some(eta)).0 <= 1e-12);
        }
    }

    #[test]
    fn a_singular_symmetric_part_goes_to_lu() {
        // [[0, 1], [-1, 0]] + εI is regular, but its symmetric part εI with ε = 0 is
        // not: S = 0 cannot be factored, LU solves K.
        let p = SymbolicSparseColMat::new_checked(2, 2, vec![0, 2, 4], None, vec![0, 1, 0, 1]);
        let v = vec![0.0, -1.0, 1.0, 0.0];
        let mut s = SymmetricPartGmres::new(GmresSettings::default(), FaerDirectOptions::default());
        s.analyse(p.as_ref(), Symmetry::General).unwrap();
        assert_eq!(s.factor(&v).unwrap().method, Factorization::Lu);
        let mut x = vec![1.0, 2.0];
        s.solve_in_place(&v, &mut x).unwrap();
        // K x = b: x = (−2, 1)
        assert!((x[0] + 2.0).abs() < 1e-14 && (x[1] - 1.0).abs() < 1e-14, "{x:?}");
        assert!(s.last_solve().fallback.unwrap().contains("symmetric part could not be factored"));
    }
}
