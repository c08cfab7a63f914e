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
//! [`GmresSettings::tolerance`] (1e-12 by default, far below Newton's 1e-8), so
//! Newton's iterates, and its iteration counts, are those of the direct solve up
//! to round-off.

use std::time::{Duration, Instant};

use faer::sparse::{SymbolicSparseColMat, SymbolicSparseColMatRef};
use rayon::prelude::*;

use super::gmres::{gmres, GmresSettings};
use super::linear::{FactorInfo, FaerDirect, FaerDirectOptions, Factorization, LinearSolver, LinearSolverError, SolveReport, SolverTimings, Symmetry};

/// GMRES on `K`, preconditioned by the factorization of `(K + Kᵀ)/2`.
pub struct SymmetricPartGmres {
    settings: GmresSettings,
    /// Factors the symmetric part.
    symmetric: FaerDirect,
    /// The LU fallback, analysed on first use.
    lu: FaerDirect,
    lu_analysed: bool,
    pattern: Option<SymbolicSparseColMat<usize>>,
    /// `transpose[p]`: position of entry `(j, i)` for the entry `(i, j)` at `p`;
    /// empty when the pattern is not structurally symmetric (then only LU is used).
    transpose: Vec<usize>,
    /// `K` in the pattern's CSC order, and `Kᵀ` in it (that is, `K` by rows).
    values: Vec<f64>,
    values_t: Vec<f64>,
    s_values: Vec<f64>,
    rhs: Vec<f64>,
    /// Why this factor's systems go to LU (`None`: the preconditioner holds).
    lu_reason: Option<String>,
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
    /// used for `S`).
    pub fn new(settings: GmresSettings, direct: FaerDirectOptions) -> Self {
        Self {
            settings,
            symmetric: FaerDirect::new(direct),
            lu: FaerDirect::new(direct),
            lu_analysed: false,
            pattern: None,
            transpose: Vec::new(),
            values: Vec::new(),
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

    /// Factor `K` (the stored values) by LU, for the reason given.
    fn factor_lu(&mut self, reason: String) -> Result<(), LinearSolverError> {
        if !self.lu_analysed {
            let pattern = self.pattern.as_ref().ok_or(LinearSolverError::Order("factor", "analyse"))?;
            self.lu.analyse(pattern.as_ref(), Symmetry::General)?;
            self.lu_analysed = true;
        }
        self.lu.factor(&self.values)?;
        self.lu_reason = Some(reason);
        Ok(())
    }
}

/// Positions of the transposed entries of a square CSC pattern with sorted rows, or
/// `None` when it is not structurally symmetric.
pub fn transpose_positions(pattern: SymbolicSparseColMatRef<'_, usize>) -> Option<Vec<usize>> {
    let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
    let n = pattern.ncols();
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
            transpose[p] = q;
            next[i] += 1;
        }
    }
    Some(transpose)
}

impl LinearSolver for SymmetricPartGmres {
    fn name(&self) -> &str {
        "faer-symmetric-part-gmres"
    }

    fn analyse(&mut self, pattern: SymbolicSparseColMatRef<'_, usize>, symmetry: Symmetry) -> Result<(), LinearSolverError> {
        let start = Instant::now();
        self.lu_analysed = false;
        self.lu_reason = None;
        let owned = pattern.to_owned().map_err(|e| LinearSolverError::Faer(format!("{e:?}")))?;
        self.transpose = transpose_positions(owned.as_ref()).unwrap_or_default();
        if !self.transpose.is_empty() || owned.row_idx().is_empty() {
            self.symmetric.analyse(owned.as_ref(), Symmetry::Symmetric)?;
        }
        if symmetry == Symmetry::General && self.transpose.is_empty() && !owned.row_idx().is_empty() {
            self.lu.analyse(owned.as_ref(), Symmetry::General)?;
            self.lu_analysed = true;
        }
        self.pattern = Some(owned);
        self.symbolic_time += start.elapsed();
        self.n_symbolic += 1;
        Ok(())
    }

    fn factor(&mut self, values: &[f64]) -> Result<FactorInfo, LinearSolverError> {
        let Some(pattern) = &self.pattern else {
            return Err(LinearSolverError::Order("factor", "analyse"));
        };
        let nnz = pattern.row_idx().len();
        if values.len() != nnz {
            return Err(LinearSolverError::Dimension { what: "values (pattern entries)", expected: nnz, got: values.len() });
        }
        if let Some(index) = values.iter().position(|v| !v.is_finite()) {
            return Err(LinearSolverError::NonFinite { index });
        }
        let start = Instant::now();
        self.values.clear();
        self.values.extend_from_slice(values);
        self.lu_reason = None;
        let method = if self.transpose.is_empty() && nnz > 0 {
            self.factor_lu("the pattern is not structurally symmetric".into())?;
            Factorization::Lu
        } else {
            let t = &self.transpose;
            self.values_t.clear();
            self.values_t.extend(t.iter().map(|&q| values[q]));
            self.s_values.clear();
            self.s_values.extend(values.iter().zip(&self.values_t).map(|(a, at)| 0.5 * (a + at)));
            match self.symmetric.factor(&self.s_values) {
                Ok(info) => info.method,
                Err(e) => {
                    self.factor_lu(format!("the symmetric part could not be factored ({e})"))?;
                    Factorization::Lu
                }
            }
        };
        let time = start.elapsed();
        self.numeric_time += time;
        self.n_numeric += 1;
        Ok(FactorInfo { method, time })
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolverError> {
        let Some(pattern) = &self.pattern else {
            return Err(LinearSolverError::Order("solve_in_place", "analyse"));
        };
        let n = pattern.nrows();
        if rhs.len() != n {
            return Err(LinearSolverError::Dimension { what: "right-hand side entries", expected: n, got: rhs.len() });
        }
        let start = Instant::now();
        self.n_solve += 1;
        if let Some(reason) = &self.lu_reason {
            self.last = SolveReport { krylov_iterations: 0, fallback: Some(reason.clone()) };
            let r = self.lu.solve_in_place(rhs);
            self.solve_time += start.elapsed();
            return r;
        }
        self.rhs.clear();
        self.rhs.extend_from_slice(rhs);
        let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
        let values_t = &self.values_t;
        // (K x)_i = Σ_j K_ij x_j: row i of K is column i of Kᵀ (structural symmetry).
        let mut apply = |x: &[f64], out: &mut [f64]| {
            out.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, o)| {
                *o = (cp[i]..cp[i + 1]).map(|p| values_t[p] * x[ri[p]]).sum();
            });
        };
        let symmetric = &mut self.symmetric;
        let mut precondition = |v: &mut [f64]| symmetric.solve_in_place(v).map_err(|e| e.to_string());
        // round-off floor of the residual: 64 ε ‖|K| |x|‖
        // (partial sums over fixed chunks, added in order: the same bits on any
        // number of threads)
        let mut floor = |x: &[f64]| {
            const CHUNK: usize = 4096;
            let partial: Vec<f64> = (0..n.div_ceil(CHUNK))
                .into_par_iter()
                .map(|c| (c * CHUNK..n.min((c + 1) * CHUNK)).map(|i| (cp[i]..cp[i + 1]).map(|p| (values_t[p] * x[ri[p]]).abs()).sum::<f64>().powi(2)).sum())
                .collect();
            64.0 * f64::EPSILON * partial.iter().sum::<f64>().sqrt()
        };
        let outcome = gmres(&self.rhs, rhs, self.settings, &mut apply, &mut precondition, &mut floor);
        let result = match outcome {
            Ok(o) if o.converged => {
                self.n_krylov += o.iterations;
                self.last = SolveReport { krylov_iterations: o.iterations, fallback: None };
                Ok(())
            }
            other => {
                let why = match other {
                    Ok(o) => {
                        self.n_krylov += o.iterations;
                        format!("GMRES preconditioned by the symmetric part reached a relative residual of {:.2e} in {} iterations (tolerance {:.0e})", o.relative_residual, o.iterations, self.settings.tolerance)
                    }
                    Err(e) => format!("the symmetric part's solve failed ({e})"),
                };
                self.n_fallback += 1;
                self.factor_lu(why.clone())?;
                rhs.copy_from_slice(&self.rhs);
                self.last = SolveReport { krylov_iterations: 0, fallback: Some(why) };
                self.lu.solve_in_place(rhs)
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
        }
    }

    fn last_solve(&self) -> SolveReport {
        self.last.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::bench::{elastic_cube_system, relative_residual};

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
                    v[t[q]] -= skew * scale;
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
                let back = t[q];
                assert_eq!(p.row_idx()[back], j);
                assert!(p.col_ptr()[i] <= back && back < p.col_ptr()[i + 1]);
                assert_eq!(t[back], q);
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
            s.solve_in_place(&mut x).unwrap();
            let r = relative_residual(p.col_ptr(), p.row_idx(), &v, &x, &b);
            let report = s.last_solve();
            assert!(r <= 1e-12 && report.fallback.is_none(), "skew {skew}: residual {r:e}, {report:?}");
            assert!(report.krylov_iterations >= 2 && report.krylov_iterations < 60, "skew {skew}: {report:?}");
            let mut lu = FaerDirect::default();
            lu.analyse(p.as_ref(), Symmetry::General).unwrap();
            lu.factor(&v).unwrap();
            let mut y = b.clone();
            lu.solve_in_place(&mut y).unwrap();
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
        s.solve_in_place(&mut x).unwrap();
        let report = s.last_solve();
        let why = report.fallback.expect("a fallback");
        assert!(why.contains("GMRES") && why.contains("1 iterations"), "{why}");
        assert!(relative_residual(p.col_ptr(), p.row_idx(), &v, &x, &b) < 1e-12);
        assert_eq!((s.timings().n_fallback, s.timings().n_solve), (1, 1));
        // The next factorization tries the preconditioner again.
        s.factor(&v).unwrap();
        assert!(s.lu_reason.is_none());
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
        s.solve_in_place(&mut x).unwrap();
        // K x = b: x = (−2, 1)
        assert!((x[0] + 2.0).abs() < 1e-14 && (x[1] - 1.0).abs() < 1e-14, "{x:?}");
        assert!(s.last_solve().fallback.unwrap().contains("symmetric part could not be factored"));
    }
}
