//! The linear-solver interface and the faer direct backend.
//!
//! **One small interface.** Every backend (this sparse direct one; a PETSc/AMG
//! Krylov one under MPI later) implements [`LinearSolver`]:
//! `analyse(pattern, symmetry)` once per sparsity pattern, `factor(values)` once
//! per Newton iteration (for an iterative backend: build the preconditioner),
//! `solve_in_place(rhs)` per right-hand side. The values are always in the CSC
//! order of the pattern given to `analyse` (the order of
//! [`crate::assembly::Pattern`] and [`crate::assembly::Assembly::values`]); a
//! distributed backend would receive the locally owned columns in the same form.
//!
//! **Symbolic once, numeric many.** [`FaerDirect`] computes the fill-reducing
//! ordering and the symbolic factorization in `analyse` and reuses them for every
//! numeric refactorization; only a new pattern (contact groups changed) or a change
//! of [`Symmetry`] needs a new `analyse`.
//!
//! **Which factorization.** [`Symmetry::Symmetric`]: `LLᵀ` (Cholesky, nested
//! dissection or AMD ordering ([`super::ordering`]), supernodal) for the symmetric positive definite tangent; when it
//! meets a non-positive pivot, `LDLᵀ` on the same symbolic factorization
//! (symmetric indefinite, no pivoting: fails only on a zero pivot).
//! [`Symmetry::General`]: `LU` with partial pivoting (COLAMD ordering). On 3D
//! meshes its fill explodes (the frictional crossed beams at 109k dofs: 24 s and
//! 8.2 GB for one LU), so the frictional tangent goes by default to
//! [`super::symmetric_part::SymmetricPartGmres`], which factors only the symmetric
//! part and keeps this LU as its fallback (`docs/performance.md`).
//!
//! **Singularity.** faer reports exact zero / non-positive pivots; a body that is
//! not held (rigid modes) usually produces a pivot that is only round-off small
//! instead, so after a Cholesky-type factorization every pivot `d_j` is compared
//! with its diagonal entry `a_jj` and `|d_j| ≤ tol·|a_jj|` is reported as
//! [`LinearSolverError::Singular`] with the dof
//! ([`FaerDirectOptions::singular_pivot_tolerance`]). LU pivots are not checked; a
//! non-finite solution is reported as singular.
//!
//! **Threads and determinism.** The library never calls
//! `faer::set_global_parallelism`. Parallelism is
//! [`FaerDirectOptions::par`]: `None` runs faer sequentially on factors whose widest
//! supernode is narrower than [`PARALLEL_SUPERNODE`] and with faer's global setting
//! (default: all rayon threads) above, `Some(par)` passes `par` explicitly to every
//! faer call. For
//! bit-identical reruns fix it (`Par::Seq`, or `Par::rayon(n)` with a fixed `n`):
//! faer's blocked kernels may split work differently for different thread counts.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, simplicial::SimplicialLltRef, supernodal::SupernodalLltRef, LdltRef, LltRef,
    SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuRef, NumericLu, SymbolicLu};
use faer::linalg::cholesky::llt::factor::LltError;
use faer::sparse::linalg::LuError;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::perm::PermRef;
use faer::{Conj, MatMut, Par, Side};

use super::ordering::{nested_dissection, FillOrdering};

/// Structure of the matrix, chosen by the caller (the tangent is symmetric
/// without friction, non-symmetric with it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Symmetry {
    /// Symmetric; both triangles are stored, the lower one is read.
    Symmetric,
    /// Non-symmetric.
    General,
}

/// The factorization actually computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Factorization {
    Llt,
    Ldlt,
    Lu,
    /// No factorization: an algebraic-multigrid preconditioner (built or kept).
    Multigrid,
}

/// What one `factor` call did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FactorInfo {
    pub method: Factorization,
    /// Wall time of this numeric factorization (including a failed `LLᵀ` before
    /// the `LDLᵀ` fallback).
    pub time: Duration,
}

/// Accumulated wall times, split by phase, and call counts.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SolverTimings {
    /// Ordering + symbolic factorization (`analyse`).
    pub symbolic: Duration,
    /// Numeric factorizations (`factor`).
    pub numeric: Duration,
    /// Triangular solves (`solve_in_place`).
    pub solve: Duration,
    pub n_symbolic: usize,
    pub n_numeric: usize,
    pub n_solve: usize,
    /// Krylov iterations over all solves (iterative backends).
    pub n_krylov: usize,
    /// Solves an iterative backend handed to its direct fallback.
    pub n_fallback: usize,
    /// `factor` calls that kept an earlier preconditioner instead of factoring.
    pub n_reused: usize,
}

/// What the last `solve_in_place` did, for the log.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SolveReport {
    /// Krylov iterations (0 for a direct solve).
    pub krylov_iterations: usize,
    /// Why an iterative backend solved this system by its direct fallback.
    pub fallback: Option<String>,
}

/// Linear-solver failures.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinearSolverError {
    #[error(
        "the system is singular{}: is a body unconstrained? a body held only by contact needs contact or springs before first load",
        dof_text(*.dof)
    )]
    Singular {
        /// Free-dof index of the offending pivot, when known.
        dof: Option<usize>,
    },
    #[error("the matrix is not positive definite (non-positive pivot at free dof {dof}) and only LLT was allowed")]
    NotPositiveDefinite { dof: usize },
    #[error("the matrix has a non-finite value at position {index} of the values array")]
    NonFinite { index: usize },
    #[error("expected {expected} {what}, got {got}")]
    Dimension { what: &'static str, expected: usize, got: usize },
    #[error("{0} called before {1}")]
    Order(&'static str, &'static str),
    #[error("iterative solver did not converge: {iterations} iterations, relative residual {relative_residual:e}")]
    DidNotConverge { iterations: usize, relative_residual: f64 },
    #[error("faer: {0}")]
    Faer(String),
    /// An external backend's failure, with its own words (PETSc names the function).
    #[error("{0}")]
    Backend(String),
    /// The factorization would not fit in memory (checked after the symbolic analysis).
    #[error("{0}")]
    TooLarge(super::memory::TooLarge),
}

fn dof_text(dof: Option<usize>) -> String {
    match dof {
        Some(d) => format!(" (zero pivot at free dof {d})"),
        None => String::new(),
    }
}

/// The interface every linear-solver backend implements.
pub trait LinearSolver: Send {
    /// Short name for logs, e.g. `"faer-direct"`.
    fn name(&self) -> &str;
    /// Analyses a sparsity pattern (square, CSC, both triangles, sorted rows):
    /// ordering and symbolic factorization. Call again when the pattern or the
    /// symmetry changes; invalidates the previous factorization.
    fn analyse(&mut self, pattern: SymbolicSparseColMatRef<'_, usize>, symmetry: Symmetry) -> Result<(), LinearSolverError>;
    /// Numeric factorization of the matrix with these values (pattern order).
    fn factor(&mut self, values: &[f64]) -> Result<FactorInfo, LinearSolverError>;
    /// Overwrites `rhs` with the solution of `A x = rhs`.
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolverError>;
    /// Accumulated timings since construction.
    fn timings(&self) -> SolverTimings;
    /// What the last `solve_in_place` did (a direct backend: nothing to say).
    fn last_solve(&self) -> SolveReport {
        SolveReport::default()
    }
    /// The relative residual the next solves may stop at, for an iterative
    /// backend (an inexact Newton's forcing term); a direct backend ignores it.
    fn set_forcing(&mut self, _eta: f64) {}
    /// The current configuration: nodal reference coordinates and the full
    /// displacement vector, before `factor` (a multigrid backend builds its
    /// rigid-body near-null space from them); others ignore it.
    fn set_configuration(&mut self, _reference: &[nalgebra::Vector3<f64>], _u: &[f64]) {}
}

/// Widest supernode (columns) from which [`FaerDirect`] runs faer in parallel when
/// its parallelism is left to it.
pub const PARALLEL_SUPERNODE: usize = 2048;

/// Options of [`FaerDirect`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaerDirectOptions {
    /// Parallelism passed to faer; `None`: faer's global setting for a factor with a
    /// supernode of at least [`PARALLEL_SUPERNODE`] columns, sequential below.
    pub par: Option<Par>,
    /// Which factorization a [`Symmetry::Symmetric`] matrix gets.
    pub symmetric: SymmetricStrategy,
    /// Relative pivot size below which a Cholesky-type factorization is reported
    /// singular (default `1e-13`; `0` disables the check).
    pub singular_pivot_tolerance: f64,
    /// Fill-reducing ordering of the Cholesky-type factorizations (LU always uses
    /// faer's COLAMD).
    pub ordering: FillOrdering,
}

impl Default for FaerDirectOptions {
    fn default() -> Self {
        Self { par: None, symmetric: SymmetricStrategy::LltThenLdlt, singular_pivot_tolerance: 1e-13, ordering: FillOrdering::default() }
    }
}

/// Factorization of symmetric matrices.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SymmetricStrategy {
    /// `LLᵀ`; on a non-positive pivot, `LDLᵀ` on the same symbolic factorization.
    #[default]
    LltThenLdlt,
    /// `LLᵀ` only: a non-positive pivot is [`LinearSolverError::NotPositiveDefinite`].
    Llt,
    /// `LDLᵀ` directly (known indefinite systems, e.g. contact saddle points).
    Ldlt,
}

enum Symbolic {
    Cholesky(SymbolicCholesky<usize>),
    Lu(SymbolicLu<usize>),
}

enum Numeric {
    None,
    Llt,
    Ldlt,
    Lu(Box<NumericLu<usize, f64>>),
}

/// Sparse direct solver on faer: `LLᵀ` → `LDLᵀ` fallback for symmetric matrices,
/// `LU` for general ones; symbolic factorization reused across `factor` calls.
pub struct FaerDirect {
    options: FaerDirectOptions,
    pattern: Option<SymbolicSparseColMat<usize>>,
    /// Position of each diagonal entry in the values array (`usize::MAX` if absent).
    diag_pos: Vec<usize>,
    symbolic: Option<Symbolic>,
    numeric: Numeric,
    /// Values of the Cholesky-type factor.
    l_values: Vec<f64>,
    /// Columns of the widest supernode of the Cholesky-type symbolic factor (0 for
    /// none or LU): decides the automatic parallelism ([`PARALLEL_SUPERNODE`]).
    widest_supernode: usize,
    symbolic_time: Duration,
    numeric_time: Duration,
    n_symbolic: usize,
    n_numeric: usize,
    solve_nanos: AtomicU64,
    n_solve: AtomicU64,
}

impl Default for FaerDirect {
    fn default() -> Self {
        Self::new(FaerDirectOptions::default())
    }
}

impl FaerDirect {
    pub fn new(options: FaerDirectOptions) -> Self {
        Self {
            options,
            pattern: None,
            diag_pos: Vec::new(),
            symbolic: None,
            numeric: Numeric::None,
            l_values: Vec::new(),
            widest_supernode: 0,
            symbolic_time: Duration::ZERO,
            numeric_time: Duration::ZERO,
            n_symbolic: 0,
            n_numeric: 0,
            solve_nanos: AtomicU64::new(0),
            n_solve: AtomicU64::new(0),
        }
    }

    pub fn options(&self) -> &FaerDirectOptions {
        &self.options
    }

    /// The factorization held now, if any.
    pub fn factorization(&self) -> Option<Factorization> {
        match self.numeric {
            Numeric::None => None,
            Numeric::Llt => Some(Factorization::Llt),
            Numeric::Ldlt => Some(Factorization::Ldlt),
            Numeric::Lu(_) => Some(Factorization::Lu),
        }
    }

    /// Number of stored values of the factor(s), a proxy for its memory.
    pub fn factor_len(&self) -> usize {
        match (&self.symbolic, &self.numeric) {
            (Some(Symbolic::Cholesky(s)), _) => s.len_val(),
            _ => 0,
        }
    }

    /// Columns of the widest supernode of the Cholesky-type factor (0 if none; set
    /// by `analyse`).
    pub fn largest_supernode(&self) -> usize {
        self.widest_supernode
    }

    /// The parallelism of every faer call: the option's, else (auto) faer's global
    /// setting for a factor whose widest supernode has at least
    /// [`PARALLEL_SUPERNODE`] columns and `Par::Seq` below (on 2 cores the parallel
    /// supernodal kernels lose to the sequential ones on narrower factors: the
    /// crossed beams' 108k-dof factor, 14.5 s sequential against 19.5 s on 2
    /// threads; the 30³ cube's, widest supernode 4,320, 2.9 s against 1.7 s;
    /// `docs/performance.md`).
    fn par(&self) -> Par {
        self.options.par.unwrap_or_else(|| if self.widest_supernode >= PARALLEL_SUPERNODE { faer::get_global_parallelism() } else { Par::Seq })
    }

    fn factor_cholesky(&mut self, values: &[f64]) -> Result<Factorization, LinearSolverError> {
        let par = self.par();
        let (Some(pattern), Some(Symbolic::Cholesky(sym))) = (&self.pattern, &self.symbolic) else {
            return Err(LinearSolverError::Order("factor", "analyse"));
        };
        let a = SparseColMatRef::new(pattern.as_ref(), values);
        self.l_values.resize(sym.len_val(), 0.0);
        let orig = |j: usize| sym.perm().map_or(j, |p| p.arrays().0[j]);
        // faer 0.24 reports failed pivots 1-based in the simplicial path
        // (`index: k + 1`) and 0-based in the supernodal one.
        let simplicial = matches!(sym.raw(), SymbolicCholeskyRaw::Simplicial(_));
        let failed = |index: usize| orig(if simplicial { index.saturating_sub(1) } else { index });

        let strategy = self.options.symmetric;
        let mut method = Factorization::Ldlt;
        if strategy != SymmetricStrategy::Ldlt {
            let mut buf = MemBuffer::try_new(sym.factorize_numeric_llt_scratch::<f64>(par, Default::default()))
                .map_err(|e| LinearSolverError::Faer(format!("{e:?}")))?;
            let llt = sym.factorize_numeric_llt(
                &mut self.l_values,
                a,
                Side::Lower,
                LltRegularization { dynamic_regularization_delta: 0.0, dynamic_regularization_epsilon: 0.0 },
                par,
                MemStack::new(&mut buf),
                Default::default(),
            );
            match llt {
                Ok(_) => method = Factorization::Llt,
                Err(LltError::NonPositivePivot { index }) => {
                    if strategy == SymmetricStrategy::Llt {
                        return Err(LinearSolverError::NotPositiveDefinite { dof: failed(index) });
                    }
                }
            }
        }
        if method == Factorization::Ldlt {
            let mut buf = MemBuffer::try_new(sym.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()))
                .map_err(|e| LinearSolverError::Faer(format!("{e:?}")))?;
            let ldlt = sym.factorize_numeric_ldlt(
                &mut self.l_values,
                a,
                Side::Lower,
                LdltRegularization::default(),
                par,
                MemStack::new(&mut buf),
                Default::default(),
            );
            if let Err(faer::linalg::cholesky::ldlt::factor::LdltError::ZeroPivot { index }) = ldlt {
                return Err(LinearSolverError::Singular { dof: Some(failed(index)) });
            }
        }

        // Round-off-small pivots: compare each pivot with its diagonal entry.
        let tol = self.options.singular_pivot_tolerance;
        if tol > 0.0 {
            let pivots = factor_diagonal(sym, &self.l_values);
            let scale = self
                .diag_pos
                .iter()
                .map(|&p| if p == usize::MAX { 0.0 } else { values[p].abs() })
                .fold(0.0, f64::max);
            for (j, &l) in pivots.iter().enumerate() {
                let d = if method == Factorization::Llt { l * l } else { l.abs() };
                let p = self.diag_pos[orig(j)];
                let a_jj = if p == usize::MAX { 0.0 } else { values[p].abs() };
                let reference = if a_jj > 0.0 { a_jj } else { scale };
                if d.is_nan() || d <= tol * reference {
                    return Err(LinearSolverError::Singular { dof: Some(orig(j)) });
                }
            }
        }
        Ok(method)
    }
}

/// The checks every `factor(values)` makes: a pattern was analysed, `values` has one
/// finite entry per pattern entry. Returns the pattern.
pub fn check_values<'a>(pattern: Option<&'a SymbolicSparseColMat<usize>>, values: &[f64]) -> Result<&'a SymbolicSparseColMat<usize>, LinearSolverError> {
    let pattern = pattern.ok_or(LinearSolverError::Order("factor", "analyse"))?;
    let nnz = pattern.row_idx().len();
    if values.len() != nnz {
        return Err(LinearSolverError::Dimension { what: "values (pattern entries)", expected: nnz, got: values.len() });
    }
    if let Some(index) = values.iter().position(|v| !v.is_finite()) {
        return Err(LinearSolverError::NonFinite { index });
    }
    Ok(pattern)
}

/// Diagonal of a Cholesky-type factor in the permuted order: `L_jj` for `LLᵀ`,
/// `D_jj` for `LDLᵀ` (both are stored on the factor's diagonal).
fn factor_diagonal(sym: &SymbolicCholesky<usize>, values: &[f64]) -> Vec<f64> {
    let n = sym.nrows();
    let mut diag = vec![0.0; n];
    match sym.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            let l = SimplicialLltRef::new(s, values);
            let f = s.factor();
            for (j, d) in diag.iter_mut().enumerate() {
                let (lo, hi) = (f.col_ptr()[j], f.col_ptr()[j + 1]);
                if let Some(k) = f.row_idx()[lo..hi].iter().position(|&r| r == j) {
                    *d = l.values()[lo + k];
                }
            }
        }
        SymbolicCholeskyRaw::Supernodal(s) => {
            let l = SupernodalLltRef::new(s, values);
            for sn in 0..s.n_supernodes() {
                let node = l.supernode(sn);
                let (start, m) = (node.start(), node.val());
                for k in 0..m.ncols() {
                    diag[start + k] = m[(k, k)];
                }
            }
        }
    }
    diag
}

impl LinearSolver for FaerDirect {
    fn name(&self) -> &str {
        "faer-direct"
    }

    fn analyse(&mut self, pattern: SymbolicSparseColMatRef<'_, usize>, symmetry: Symmetry) -> Result<(), LinearSolverError> {
        let n = pattern.nrows();
        if pattern.ncols() != n {
            return Err(LinearSolverError::Dimension { what: "columns (square matrix)", expected: n, got: pattern.ncols() });
        }
        let start = Instant::now();
        self.release();
        let owned = pattern.to_owned().map_err(|e| LinearSolverError::Faer(format!("{e:?}")))?;
        self.diag_pos = (0..n)
            .map(|j| {
                let (lo, hi) = (owned.col_ptr()[j], owned.col_ptr()[j + 1]);
                owned.row_idx()[lo..hi].binary_search(&j).map_or(usize::MAX, |k| lo + k)
            })
            .collect();
        let symbolic = match symmetry {
            Symmetry::Symmetric => {
                let perm = match self.options.ordering {
                    FillOrdering::Amd => None,
                    FillOrdering::NestedDissection => Some(nested_dissection(owned.as_ref())?),
                };
                let ordering = match &perm {
                    None => SymmetricOrdering::Amd,
                    Some(p) => SymmetricOrdering::Custom(PermRef::new_checked(&p.forward, &p.inverse, n)),
                };
                let c = factorize_symbolic_cholesky(owned.as_ref(), Side::Lower, ordering, Default::default())
                    .map_err(|e| LinearSolverError::Faer(format!("{e:?}")))?;
                super::memory::check_cholesky(c.len_val(), n, owned.compute_nnz()).map_err(LinearSolverError::TooLarge)?;
                Symbolic::Cholesky(c)
            }
            Symmetry::General => Symbolic::Lu(
                factorize_symbolic_lu(owned.as_ref(), Default::default())
                    .map_err(|e| LinearSolverError::Faer(format!("{e:?}")))?,
            ),
        };
        self.pattern = Some(owned);
        self.widest_supernode = match &symbolic {
            Symbolic::Cholesky(c) => match c.raw() {
                SymbolicCholeskyRaw::Supernodal(s) => s.supernode_begin().iter().zip(s.supernode_end()).map(|(b, e)| e - b).max().unwrap_or(0),
                SymbolicCholeskyRaw::Simplicial(_) => 1,
            },
            Symbolic::Lu(_) => 0,
        };
        self.symbolic = Some(symbolic);
        self.symbolic_time += start.elapsed();
        self.n_symbolic += 1;
        Ok(())
    }

    fn factor(&mut self, values: &[f64]) -> Result<FactorInfo, LinearSolverError> {
        let pattern = check_values(self.pattern.as_ref(), values)?;
        let start = Instant::now();
        self.numeric = Numeric::None;
        let result = match &self.symbolic {
            Some(Symbolic::Cholesky(_)) => self.factor_cholesky(values).inspect(|&m| {
                self.numeric = if m == Factorization::Llt { Numeric::Llt } else { Numeric::Ldlt };
            }),
            Some(Symbolic::Lu(sym)) => {
                let par = self.par();
                let a = SparseColMatRef::new(pattern.as_ref(), values);
                let mut numeric = NumericLu::new();
                let mut buf = MemBuffer::try_new(sym.factorize_numeric_lu_scratch::<f64>(par, Default::default()))
                    .map_err(|e| LinearSolverError::Faer(format!("{e:?}")))?;
                match sym.factorize_numeric_lu(&mut numeric, a, par, MemStack::new(&mut buf), Default::default()) {
                    Ok(_) => {
                        self.numeric = Numeric::Lu(Box::new(numeric));
                        Ok(Factorization::Lu)
                    }
                    Err(LuError::SymbolicSingular { index }) => {
                        let dof = sym.col_perm().arrays().0.get(index).copied();
                        Err(LinearSolverError::Singular { dof })
                    }
                    Err(e) => Err(LinearSolverError::Faer(format!("{e:?}"))),
                }
            }
            None => Err(LinearSolverError::Order("factor", "analyse")),
        };
        let time = start.elapsed();
        self.numeric_time += time;
        self.n_numeric += 1;
        result.map(|method| FactorInfo { method, time })
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolverError> {
        self.solve(rhs)
    }

    fn timings(&self) -> SolverTimings {
        SolverTimings {
            symbolic: self.symbolic_time,
            numeric: self.numeric_time,
            solve: Duration::from_nanos(self.solve_nanos.load(Ordering::Relaxed)),
            n_symbolic: self.n_symbolic,
            n_numeric: self.n_numeric,
            n_solve: self.n_solve.load(Ordering::Relaxed) as usize,
            n_krylov: 0,
            n_fallback: 0,
            n_reused: 0,
        }
    }
}

impl FaerDirect {
    /// Drops the pattern, the analysis and the factor (their memory), as a new
    /// `analyse` would before building its own.
    pub fn release(&mut self) {
        self.numeric = Numeric::None;
        self.symbolic = None;
        self.pattern = None;
        self.diag_pos = Vec::new();
        self.l_values = Vec::new();
        self.widest_supernode = 0;
    }

    /// The analysed pattern, if any.
    pub fn pattern(&self) -> Option<&SymbolicSparseColMat<usize>> {
        self.pattern.as_ref()
    }

    /// [`LinearSolver::solve_in_place`] without exclusive access (the factor is only
    /// read), so that a preconditioner can solve while its owner is borrowed.
    pub fn solve(&self, rhs: &mut [f64]) -> Result<(), LinearSolverError> {
        let start = Instant::now();
        let par = self.par();
        let n = match &self.pattern {
            Some(p) => p.nrows(),
            None => return Err(LinearSolverError::Order("solve_in_place", "analyse")),
        };
        if rhs.len() != n {
            return Err(LinearSolverError::Dimension { what: "right-hand side entries", expected: n, got: rhs.len() });
        }
        let faer_err = |e: faer::dyn_stack::mem::AllocError| LinearSolverError::Faer(format!("{e:?}"));
        let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
        match (&self.symbolic, &self.numeric) {
            (Some(Symbolic::Cholesky(sym)), Numeric::Llt) => {
                let mut buf = MemBuffer::try_new(sym.solve_in_place_scratch::<f64>(1, par)).map_err(faer_err)?;
                LltRef::new(sym, &self.l_values).solve_in_place_with_conj(Conj::No, x, par, MemStack::new(&mut buf));
            }
            (Some(Symbolic::Cholesky(sym)), Numeric::Ldlt) => {
                let mut buf = MemBuffer::try_new(sym.solve_in_place_scratch::<f64>(1, par)).map_err(faer_err)?;
                LdltRef::new(sym, &self.l_values).solve_in_place_with_conj(Conj::No, x, par, MemStack::new(&mut buf));
            }
            (Some(Symbolic::Lu(sym)), Numeric::Lu(num)) => {
                let mut buf = MemBuffer::try_new(sym.solve_in_place_scratch::<f64>(1, par)).map_err(faer_err)?;
                LuRef::new_unchecked(sym, num).solve_in_place_with_conj(Conj::No, x, par, MemStack::new(&mut buf));
            }
            _ => return Err(LinearSolverError::Order("solve_in_place", "a successful factor")),
        }
        self.solve_nanos.fetch_add(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
        self.n_solve.fetch_add(1, Ordering::Relaxed);
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolverError::Singular { dof: None });
        }
        Ok(())
    }

}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::solver::bench::{elastic_cube_system, relative_residual};

    use crate::fem::fd::Lcg;

    /// CSC (entries where `keep(i, j)`, rows sorted) of a dense matrix.
    fn dense_to_csc(a: &[Vec<f64>], keep: impl Fn(usize, usize) -> bool) -> (SymbolicSparseColMat<usize>, Vec<f64>) {
        let n = a.len();
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], vec![], vec![]);
        for j in 0..n {
            for (i, row) in a.iter().enumerate() {
                if keep(i, j) {
                    row_idx.push(i);
                    values.push(row[j]);
                }
            }
            col_ptr.push(row_idx.len());
        }
        (SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx), values)
    }

    fn residual_of(p: &SymbolicSparseColMat<usize>, v: &[f64], x: &[f64], b: &[f64]) -> f64 {
        relative_residual(p.col_ptr(), p.row_idx(), v, x, b)
    }

    fn solve(solver: &mut FaerDirect, p: &SymbolicSparseColMat<usize>, v: &[f64], b: &[f64], sym: Symmetry) -> (Vec<f64>, Factorization) {
        solver.analyse(p.as_ref(), sym).unwrap();
        let info = solver.factor(v).unwrap();
        let mut x = b.to_vec();
        solver.solve_in_place(&mut x).unwrap();
        (x, info.method)
    }

    fn with(symmetric: SymmetricStrategy) -> FaerDirect {
        FaerDirect::new(FaerDirectOptions { symmetric, ..Default::default() })
    }

    #[test]
    fn llt_ldlt_lu_agree_on_elastic_cube() {
        let cube = elastic_cube_system(4).unwrap();
        let p = cube.pattern.symbolic_owned();
        let v = cube.assembly.values();
        let b = &cube.rhs;
        let (x_llt, m1) = solve(&mut with(SymmetricStrategy::LltThenLdlt), p, v, b, Symmetry::Symmetric);
        let (x_ldlt, m2) = solve(&mut with(SymmetricStrategy::Ldlt), p, v, b, Symmetry::Symmetric);
        let (x_lu, m3) = solve(&mut FaerDirect::default(), p, v, b, Symmetry::General);
        assert_eq!((m1, m2, m3), (Factorization::Llt, Factorization::Ldlt, Factorization::Lu));
        for x in [&x_llt, &x_ldlt, &x_lu] {
            let r = residual_of(p, v, x, b);
            assert!(r < 1e-12, "residual {r:e}");
        }
        let norm = x_llt.iter().map(|v| v * v).sum::<f64>().sqrt();
        for x in [&x_ldlt, &x_lu] {
            let d = x.iter().zip(&x_llt).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
            assert!(d / norm < 1e-10, "solutions differ by {:e}", d / norm);
        }
        // The load pushes the top face down.
        assert!(x_llt.iter().cloned().fold(0.0, f64::min) < -1.0);
    }

    /// Quasi-definite `[[K, Bᵀ], [B, −C]]`: symmetric indefinite.
    fn saddle_point(nk: usize, nb: usize) -> Vec<Vec<f64>> {
        let n = nk + nb;
        let mut rng = Lcg(3);
        let mut a = vec![vec![0.0; n]; n];
        for i in 0..n {
            for j in 0..i {
                let coupled = j < nk && ((i < nk && (i - j) <= 3) || (i >= nk && (i * 7 + j) % 5 == 0));
                if coupled {
                    let v = rng.uniform();
                    a[i][j] = v;
                    a[j][i] = v;
                }
            }
        }
        for i in 0..nk {
            a[i][i] = 8.0 + rng.uniform();
        }
        for i in nk..n {
            a[i][i] = -1e-3 * (1.5 + rng.uniform());
        }
        a
    }

    #[test]
    fn symmetric_indefinite_goes_to_ldlt() {
        let a = saddle_point(24, 8);
        let (p, v) = dense_to_csc(&a, |i, j| i == j || a[i][j] != 0.0);
        let b: Vec<f64> = (0..a.len()).map(|i| 1.0 + i as f64 * 0.1).collect();
        let mut s = FaerDirect::default();
        let (x, m) = solve(&mut s, &p, &v, &b, Symmetry::Symmetric);
        assert_eq!(m, Factorization::Ldlt);
        let r = residual_of(&p, &v, &x, &b);
        assert!(r < 1e-12, "residual {r:e}");
        // LLT alone refuses it, with the typed error.
        let mut llt = with(SymmetricStrategy::Llt);
        llt.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        assert!(matches!(llt.factor(&v), Err(LinearSolverError::NotPositiveDefinite { .. })));
        // LU agrees.
        let (x_lu, _) = solve(&mut FaerDirect::default(), &p, &v, &b, Symmetry::General);
        let d = x.iter().zip(&x_lu).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(d < 1e-10 * x.iter().map(|v| v.abs()).fold(0.0, f64::max));
    }

    #[test]
    fn nonsymmetric_with_lu() {
        let n = 40;
        let mut rng = Lcg(11);
        let mut a = vec![vec![0.0; n]; n];
        for (i, row) in a.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                if i == j {
                    *v = 0.5 * rng.uniform(); // not diagonally dominant: pivoting needed
                } else if (i + 2 * j) % 7 == 0 || i.abs_diff(j) == 1 {
                    *v = rng.uniform();
                }
            }
        }
        let (p, v) = dense_to_csc(&a, |i, j| i == j || a[i][j] != 0.0);
        let b: Vec<f64> = (0..n).map(|i| (i as f64).sin() + 2.0).collect();
        let mut s = FaerDirect::default();
        let (x, m) = solve(&mut s, &p, &v, &b, Symmetry::General);
        assert_eq!(m, Factorization::Lu);
        let r = residual_of(&p, &v, &x, &b);
        assert!(r < 1e-12, "residual {r:e}");
    }

    #[test]
    fn symbolic_factorization_is_reused() {
        let cube = elastic_cube_system(3).unwrap();
        let p = cube.pattern.symbolic_owned();
        let v1 = cube.assembly.values().to_vec();
        // Same pattern, other values: 2 K + 0.5 I-like diagonal shift.
        let mut v2: Vec<f64> = v1.iter().map(|v| 2.0 * v).collect();
        for j in 0..p.nrows() {
            let s = p.col_ptr()[j] + p.row_idx()[p.col_ptr()[j]..p.col_ptr()[j + 1]].binary_search(&j).unwrap();
            v2[s] += 0.5;
        }
        for sym in [Symmetry::Symmetric, Symmetry::General] {
            let mut s = FaerDirect::default();
            s.analyse(p.as_ref(), sym).unwrap();
            let mut xs = vec![];
            for v in [&v1, &v2] {
                s.factor(v).unwrap();
                let mut x = cube.rhs.clone();
                s.solve_in_place(&mut x).unwrap();
                let r = residual_of(p, v, &x, &cube.rhs);
                assert!(r < 1e-12, "{sym:?}: residual {r:e}");
                xs.push(x);
            }
            let t = s.timings();
            assert_eq!((t.n_symbolic, t.n_numeric, t.n_solve), (1, 2, 2));
            assert!(t.symbolic > Duration::ZERO && t.numeric > Duration::ZERO && t.solve > Duration::ZERO);
            // The second system is stiffer: smaller displacements.
            let max = |x: &Vec<f64>| x.iter().map(|v| v.abs()).fold(0.0, f64::max);
            assert!(max(&xs[1]) < 0.51 * max(&xs[0]));
        }
    }

    #[test]
    fn singular_matrices_give_typed_errors() {
        // A decoupled dof with a zero diagonal: an exact zero pivot.
        let n = 12;
        let mut a = vec![vec![0.0; n]; n];
        for i in 0..n {
            a[i][i] = 4.0;
            if i + 1 < n {
                a[i][i + 1] = -1.0;
                a[i + 1][i] = -1.0;
            }
        }
        let dead = 7;
        for i in 0..n {
            a[dead][i] = 0.0;
            a[i][dead] = 0.0;
        }
        let (p, v) = dense_to_csc(&a, |i, j| i == j || a[i][j] != 0.0);
        for strategy in [SymmetricStrategy::LltThenLdlt, SymmetricStrategy::Ldlt] {
            let mut s = with(strategy);
            s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
            let err = s.factor(&v).unwrap_err();
            assert_eq!(err, LinearSolverError::Singular { dof: Some(dead) }, "{strategy:?}");
            assert!(err.to_string().contains("is a body unconstrained?"));
            let mut x = vec![1.0; n];
            assert_eq!(s.solve_in_place(&mut x), Err(LinearSolverError::Order("solve_in_place", "a successful factor")));
        }
        // The same on an elastic cube large enough for the supernodal path.
        let cube = elastic_cube_system(6).unwrap();
        let p6 = cube.pattern.symbolic_owned();
        let mut v6 = cube.assembly.values().to_vec();
        let dead = 100;
        for j in 0..p6.nrows() {
            for s in p6.col_ptr()[j]..p6.col_ptr()[j + 1] {
                if j == dead || p6.row_idx()[s] == dead {
                    v6[s] = 0.0;
                }
            }
        }
        for strategy in [SymmetricStrategy::LltThenLdlt, SymmetricStrategy::Ldlt] {
            let mut s = with(strategy);
            s.analyse(p6.as_ref(), Symmetry::Symmetric).unwrap();
            assert!(matches!(s.symbolic, Some(Symbolic::Cholesky(ref c)) if matches!(c.raw(), SymbolicCholeskyRaw::Supernodal(_))));
            assert_eq!(s.factor(&v6), Err(LinearSolverError::Singular { dof: Some(dead) }), "{strategy:?}");
        }

        // LU: a structurally empty column.
        let (p, v) = dense_to_csc(&a, |i, j| a[i][j] != 0.0);
        let mut s = FaerDirect::default();
        s.analyse(p.as_ref(), Symmetry::General).unwrap();
        match s.factor(&v) {
            Err(LinearSolverError::Singular { .. }) => {}
            other => panic!("expected Singular, got {other:?}"),
        }

        // An unconstrained elastic cube: six rigid modes, round-off pivots.
        let (nodes, hexes) = crate::assembly::pattern::structured_hex_grid(2, 2, 2);
        let pat = crate::assembly::Pattern::build(
            crate::assembly::DofMap::all_free(nodes.len()).unwrap(),
            &hexes,
            crate::assembly::NodeGroups::new(),
        )
        .unwrap();
        let mut asm = crate::assembly::Assembly::new(&pat).unwrap();
        let (values, _) = asm
            .assemble(&pat, |e, _r, k| {
                let x = std::array::from_fn(|a| nodes[hexes[e][a] as usize]);
                *k = crate::solver::bench::hex8_elastic_stiffness(&x, 1.0, 0.3).ok_or(())?;
                Ok::<(), ()>(())
            })
            .unwrap();
        let mut s = FaerDirect::default();
        s.analyse(pat.symbolic(), Symmetry::Symmetric).unwrap();
        match s.factor(values) {
            Err(LinearSolverError::Singular { dof: Some(_) }) => {}
            other => panic!("expected Singular with a dof, got {other:?}"),
        }
    }

    #[test]
    fn misuse_gives_errors_not_panics() {
        let mut s = FaerDirect::default();
        assert!(matches!(s.factor(&[1.0]), Err(LinearSolverError::Order(..))));
        let a = vec![vec![2.0, 0.0], vec![0.0, 3.0]];
        let (p, v) = dense_to_csc(&a, |i, j| i == j);
        s.analyse(p.as_ref(), Symmetry::Symmetric).unwrap();
        assert!(matches!(s.factor(&[1.0]), Err(LinearSolverError::Dimension { .. })));
        assert_eq!(s.factor(&[1.0, f64::NAN]), Err(LinearSolverError::NonFinite { index: 1 }));
        s.factor(&v).unwrap();
        assert!(matches!(s.solve_in_place(&mut [1.0]), Err(LinearSolverError::Dimension { .. })));
        let mut x = [2.0, 3.0];
        s.solve_in_place(&mut x).unwrap();
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15, "{x:?}");
    }

    #[test]
    fn fixed_parallelism_is_reproducible() {
        let cube = elastic_cube_system(6).unwrap();
        let p = cube.pattern.symbolic_owned();
        let run = |par: Par| {
            let mut s = FaerDirect::new(FaerDirectOptions { par: Some(par), ..Default::default() });
            solve(&mut s, p, cube.assembly.values(), &cube.rhs, Symmetry::Symmetric).0
        };
        let bits = |x: Vec<f64>| x.into_iter().map(f64::to_bits).collect::<Vec<_>>();
        assert_eq!(bits(run(Par::Seq)), bits(run(Par::Seq)));
        assert_eq!(bits(run(Par::rayon(2))), bits(run(Par::rayon(2))));
    }
}
