//! The faer sparse direct backend, [`FaerDirect`].
//!
//! **Symbolic once, numeric many.** [`FaerDirect`] computes the fill-reducing
//! ordering and the symbolic factorization in `analyse` and reuses them for every
//! numeric refactorization; only a new pattern (contact groups changed) or a change
//! of [`Symmetry`] needs a new `analyse`.
//!
//! **Which factorization.** [`Symmetry::Symmetric`]: `LLᵀ` (Cholesky, nested
//! dissection or AMD ordering ([`crate::solver::ordering`]), supernodal, its numeric
//! part by [`super::tree_cholesky`], parallel over the elimination tree) for the symmetric positive definite tangent; when it
//! meets a non-positive pivot, `LDLᵀ` on the same symbolic factorization
//! (symmetric indefinite, no pivoting: fails only on a zero pivot). The `LLᵀ`
//! factor is in `f64`, or in `f32` with [`FactorPrecision::Single`] (a
//! preconditioner whose solves a Krylov method makes exact; double whenever `f32`
//! cannot hold it).
//! [`Symmetry::General`]: `LU` with partial pivoting (COLAMD ordering). On 3D
//! meshes its fill explodes (the frictional crossed beams at 109k dofs: 24 s and
//! 8.2 GB for one LU), so the frictional tangent goes by default to
//! [`crate::solver::symmetric_part::SymmetricPartGmres`], which factors only the symmetric
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
//! `faer::set_global_parallelism`. The `LLᵀ` factors independent subtrees of the
//! elimination tree on rayon's threads, and gives the dense kernels of its wide top
//! supernodes [`FaerDirectOptions::par`] (`None`: faer's global setting, default
//! all rayon threads). For every other faer call (`LDLᵀ`, `LU`, the solves),
//! `None` runs faer sequentially on factors whose widest supernode is narrower than
//! [`PARALLEL_SUPERNODE`] and with faer's global setting above; `Some(par)` passes
//! `par` explicitly. For bit-identical reruns fix it (`Par::Seq`, or
//! `Par::rayon(n)` with a fixed `n`): faer's blocked kernels may split work
//! differently for different thread counts. With `Par::Seq` the `LLᵀ` factor is
//! the same, bit for bit, for any number of rayon threads.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, simplicial::SimplicialLltRef, LdltRef, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuRef, NumericLu, SymbolicLu};
use faer::sparse::linalg::cholesky::CholeskySymbolicParams;
use faer::sparse::linalg::SupernodalThreshold;
use faer::linalg::cholesky::llt::factor::LltError;
use faer::sparse::linalg::LuError;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::perm::PermRef;
use faer::{Conj, MatMut, Par, Side};

use super::error::LinearSolverError;
use crate::os::timeline;
use super::supernodal::Supernodal;
use super::tree_cholesky::{FactorReal, FillPermutation, TreeCholesky};
use crate::solver::ordering::{geometric_order_of, nested_dissection_of, FillOrdering, Permutation, SupervariableGraph};
use super::interface::{check_values, FactorInfo, Factorization, LinearSolver, SharedPattern, SolverTimings, Symmetry};

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
    /// `LLᵀ` by [`TreeCholesky`] (parallel over the elimination tree; default)
    /// instead of faer's numeric supernodal factorization (sequential over the
    /// supernodes). Both fill the same factor layout; `LDLᵀ` is always faer's.
    pub elimination_tree: bool,
    /// Precision of the `LLᵀ` factor's values ([`FactorPrecision`]).
    pub precision: FactorPrecision,
}

/// Precision of the values of the `LLᵀ` factor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FactorPrecision {
    /// `f64`: the solves are exact to round-off.
    #[default]
    Double,
    /// `f32` for the tree factorization's `LLᵀ` (of the matrix scaled by a power of
    /// two near its largest diagonal entry's inverse, so that any unit system
    /// stays inside `f32`'s range): half the memory and memory traffic of the
    /// factor and its solves, twice the SIMD lanes. The solves are then accurate
    /// only to about κ · 6e-8: a preconditioner, for a Krylov method that makes
    /// them exact ([`FaerDirect::solves_exactly`]). A factorization that meets a
    /// non-positive or a small pivot in `f32` (below [`SINGLE_PIVOT_FLOOR`] of its
    /// diagonal entry: κ too large for `f32`) is made in `f64` instead, as is
    /// every `LDLᵀ`.
    Single,
}

/// A single-precision `LLᵀ` pivot `L_jj²` below this fraction of its (scaled)
/// diagonal entry sends the factorization to double precision: the matrix is too
/// ill-conditioned, or too close to singular, for an `f32` factor to precondition
/// it (and the singularity check, [`FaerDirectOptions::singular_pivot_tolerance`],
/// is made on the double one).
pub const SINGLE_PIVOT_FLOOR: f64 = 1e-5;

impl Default for FaerDirectOptions {
    fn default() -> Self {
        Self {
            par: None,
            symmetric: SymmetricStrategy::LltThenLdlt,
            singular_pivot_tolerance: 1e-13,
            ordering: FillOrdering::default(),
            elimination_tree: true,
            precision: FactorPrecision::Double,
        }
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
    Cholesky(CholeskySymbolic),
    Lu(SymbolicLu<usize>),
}

/// The analysis of a symmetric pattern: the fill-reducing permutation, the
/// supernodal structure the tree factorization and its solves read, and faer's
/// symbolic factorization for faer's own numeric ones (`LDLᵀ`; `LLᵀ` without the
/// tree). Under nested dissection (METIS or geometric) with the tree the structure
/// is computed on the supervariables ([`Supernodal::of_supervariables`], faer's
/// own, a tenth of its time) and faer's symbolic factorization only when an
/// `LDLᵀ` needs it ([`FaerDirect::ensure_faer_symbolic`]); otherwise faer's is
/// made at once and the structure copied from it.
struct CholeskySymbolic {
    /// `P`: column `j` of `P A Pᵀ` is column `perm.forward[j]` of `A`.
    perm: Permutation,
    /// `None` only for a simplicial faer factor.
    structure: Option<Supernodal>,
    faer: Option<SymbolicCholesky<usize>>,
}

impl CholeskySymbolic {
    fn of_faer(c: SymbolicCholesky<usize>) -> Self {
        let n = c.nrows();
        let perm = match c.perm() {
            Some(p) => {
                let (forward, inverse) = p.arrays();
                Permutation { forward: forward.to_vec(), inverse: inverse.to_vec() }
            }
            None => Permutation { forward: (0..n).collect(), inverse: (0..n).collect() },
        };
        let structure = match c.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => Some(Supernodal::of_faer(s)),
            SymbolicCholeskyRaw::Simplicial(_) => None,
        };
        Self { perm, structure, faer: Some(c) }
    }

    fn len_val(&self) -> usize {
        match (&self.structure, &self.faer) {
            (Some(s), _) => s.len_val(),
            (None, Some(c)) => c.len_val(),
            (None, None) => 0,
        }
    }

    /// The dof of `A` whose pivot faer reports failed at `index`: faer 0.24 counts
    /// from 1 in the simplicial path (`index: k + 1`) and from 0 in the supernodal one.
    fn dof_of_failed_pivot(&self, index: usize) -> usize {
        let k = if self.structure.is_none() { index.saturating_sub(1) } else { index };
        self.perm.forward[k]
    }

    /// faer's symbolic factorization, if made.
    fn faer(&self) -> Result<&SymbolicCholesky<usize>, LinearSolverError> {
        self.faer.as_ref().ok_or(LinearSolverError::Order("a faer factorization", "its symbolic analysis"))
    }
}

/// faer's symbolic factorization of `pattern` (both triangles, its lower one read)
/// in the order `ordering`, supernodal always: faer's automatic choice takes the
/// simplicial factorization when flops / nnz(L) < 40, as on the shallow ironing's
/// one-element-thick slab (4.5k unknowns), where the supernodal one (each node's 3
/// dofs a dense block at least) factors in half the time (docs/performance.md).
fn faer_symbolic(pattern: SymbolicSparseColMatRef<'_, usize>, ordering: SymmetricOrdering<'_, usize>) -> Result<SymbolicCholesky<usize>, LinearSolverError> {
    let params = CholeskySymbolicParams { supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL, ..Default::default() };
    factorize_symbolic_cholesky(pattern, Side::Lower, ordering, params).map_err(|e| LinearSolverError::Faer(format!("{e:?}")))
}

enum Numeric {
    None,
    Llt,
    /// `LLᵀ` of `scale · A` in `f32` ([`FactorPrecision::Single`]).
    LltSingle { scale: f64 },
    Ldlt,
    Lu(Box<NumericLu<usize, f64>>),
}

/// Sparse direct solver on faer: `LLᵀ` → `LDLᵀ` fallback for symmetric matrices,
/// `LU` for general ones; symbolic factorization reused across `factor` calls.
pub struct FaerDirect {
    options: FaerDirectOptions,
    pattern: Option<SharedPattern>,
    /// Position of each diagonal entry in the values array (`usize::MAX` if absent).
    diag_pos: Vec<usize>,
    symbolic: Option<Symbolic>,
    numeric: Numeric,
    /// Values of the Cholesky-type factor.
    l_values: Vec<f64>,
    /// Values of a single-precision `LLᵀ` factor (only one of the two is held).
    l_values32: Vec<f32>,
    /// Columns of the widest supernode of the Cholesky-type symbolic factor (0 for
    /// none or LU): decides the automatic parallelism ([`PARALLEL_SUPERNODE`]).
    widest_supernode: usize,
    /// The elimination-tree schedule of the supernodal `LLᵀ` (set by `analyse`
    /// when [`FaerDirectOptions::elimination_tree`]).
    tree: Option<TreeCholesky>,
    /// An analysis still running beside the caller
    /// ([`LinearSolver::analyse_in_background`]); waited for by `finish_analysis`
    /// or the next `factor`.
    pending: Option<PendingAnalysis>,
    /// Each unknown's node position, for [`FillOrdering::Geometric`].
    coordinates: Option<Arc<[[f64; 3]]>>,
    /// Entries of the largest Cholesky-type factor analysed so far.
    largest_factor: usize,
    symbolic_time: Duration,
    numeric_time: Duration,
    n_symbolic: usize,
    n_numeric: usize,
    solve_nanos: AtomicU64,
    n_solve: AtomicU64,
    /// The work arrays of a tree solve (kept from one solve to the next: a Krylov
    /// solve applies the factor every iteration).
    solve_scratch: Mutex<SolveScratch>,
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
            l_values32: Vec::new(),
            widest_supernode: 0,
            tree: None,
            pending: None,
            coordinates: None,
            largest_factor: 0,
            symbolic_time: Duration::ZERO,
            numeric_time: Duration::ZERO,
            n_symbolic: 0,
            n_numeric: 0,
            solve_nanos: AtomicU64::new(0),
            n_solve: AtomicU64::new(0),
            solve_scratch: Mutex::new(SolveScratch::default()),
        }
    }

    pub fn options(&self) -> &FaerDirectOptions {
        &self.options
    }

    /// The factorization held now, if any.
    pub fn factorization(&self) -> Option<Factorization> {
        match self.numeric {
            Numeric::None => None,
            Numeric::Llt | Numeric::LltSingle { .. } => Some(Factorization::Llt),
            Numeric::Ldlt => Some(Factorization::Ldlt),
            Numeric::Lu(_) => Some(Factorization::Lu),
        }
    }

    /// Number of stored values of the factor(s), a proxy for its memory.
    pub fn factor_len(&self) -> usize {
        match (&self.symbolic, &self.numeric) {
            (Some(Symbolic::Cholesky(c)), _) => c.len_val(),
            _ => 0,
        }
    }

    /// Whether a solve with the factor held is exact to round-off (`false` for a
    /// single-precision `LLᵀ`: a preconditioner).
    pub fn solves_exactly(&self) -> bool {
        !matches!(self.numeric, Numeric::LltSingle { .. })
    }

    /// `factor` in double precision whatever [`FaerDirectOptions::precision`] says
    /// (a single-precision factor that did not precondition well enough).
    pub fn factor_in_double(&mut self, values: &[f64]) -> Result<FactorInfo, LinearSolverError> {
        let precision = std::mem::replace(&mut self.options.precision, FactorPrecision::Double);
        let result = self.factor(values);
        self.options.precision = precision;
        result
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

    /// faer's symbolic factorization of the analysed pattern in the analysis'
    /// order, made now if the analysis did without it (its time counted with the
    /// analyses').
    fn ensure_faer_symbolic(&mut self) -> Result<(), LinearSolverError> {
        let (Some(pattern), Some(Symbolic::Cholesky(c))) = (&self.pattern, &mut self.symbolic) else {
            return Err(LinearSolverError::Order("factor", "analyse"));
        };
        if c.faer.is_none() {
            let start = Instant::now();
            let n = c.perm.forward.len();
            let ordering = SymmetricOrdering::Custom(PermRef::new_checked(&c.perm.forward, &c.perm.inverse, n));
            c.faer = Some(faer_symbolic((**pattern).as_ref(), ordering)?);
            self.symbolic_time += start.elapsed();
        }
        Ok(())
    }

    fn factor_cholesky(&mut self, values: &[f64]) -> Result<Numeric, LinearSolverError> {
        let par = self.par();
        let strategy = self.options.symmetric;
        // faer's numeric factorizations need its symbolic one: LDLᵀ, and LLᵀ
        // without the tree
        if strategy == SymmetricStrategy::Ldlt || self.tree.is_none() {
            self.ensure_faer_symbolic()?;
        }
        let (Some(pattern), Some(Symbolic::Cholesky(sym))) = (&self.pattern, &self.symbolic) else {
            return Err(LinearSolverError::Order("factor", "analyse"));
        };
        let a = SparseColMatRef::new((**pattern).as_ref(), values);

        let mut method = Factorization::Ldlt;
        let tree = match (&self.tree, &sym.structure) {
            (Some(tree), Some(s)) => Some((tree, s)),
            _ => None,
        };
        if strategy != SymmetricStrategy::Ldlt {
            let llt = match tree {
                Some((tree, s)) => {
                    // A itself, read through P: the tree factorization takes the
                    // entries on or below the diagonal of P A Pᵀ (no permuted copy)
                    let perm = Some(FillPermutation { forward: &sym.perm.forward, inverse: &sym.perm.inverse });
                    let dense_par = self.options.par.unwrap_or_else(faer::get_global_parallelism);
                    // the tasks write every block: no zeroing pass here, and the pages of a
                    // new factor are first touched in parallel (calloc'd, not written)
                    if let (FactorPrecision::Single, Some(scale)) = (self.options.precision, single_scale(values, &self.diag_pos)) {
                        // the double factor goes first (peak memory)
                        self.l_values = Vec::new();
                        if self.l_values32.len() != s.len_val() {
                            self.l_values32 = vec![0.0; s.len_val()];
                        }
                        let factored = tree.factor_scaled(s, a, perm, scale, &mut self.l_values32, dense_par).is_ok();
                        if factored && single_pivots_hold(s, &self.l_values32, values, &self.diag_pos, scale, |j| sym.perm.forward[j]) {
                            return Ok(Numeric::LltSingle { scale });
                        }
                    }
                    self.l_values32 = Vec::new();
                    if self.l_values.len() != s.len_val() {
                        self.l_values = vec![0.0; s.len_val()];
                    }
                    tree.factor(s, a, perm, &mut self.l_values, dense_par)
                }
                None => {
                    let faer = sym.faer()?;
                    self.l_values32 = Vec::new();
                    self.l_values.resize(faer.len_val(), 0.0);
                    let mut buf = MemBuffer::try_new(faer.factorize_numeric_llt_scratch::<f64>(par, Default::default()))
                        .map_err(|e| LinearSolverError::Faer(format!("{e:?}")))?;
                    faer.factorize_numeric_llt(
                        &mut self.l_values,
                        a,
                        Side::Lower,
                        LltRegularization { dynamic_regularization_delta: 0.0, dynamic_regularization_epsilon: 0.0 },
                        par,
                        MemStack::new(&mut buf),
                        Default::default(),
                    )
                    .map(|_| ())
                }
            };
            match llt {
                Ok(()) => method = Factorization::Llt,
                Err(LltError::NonPositivePivot { index }) => {
                    if strategy == SymmetricStrategy::Llt {
                        return Err(LinearSolverError::NotPositiveDefinite { dof: sym.dof_of_failed_pivot(index) });
                    }
                }
            }
        }
        if method == Factorization::Ldlt {
            self.l_values32 = Vec::new();
            self.ensure_faer_symbolic()?;
            let (Some(pattern), Some(Symbolic::Cholesky(sym))) = (&self.pattern, &self.symbolic) else {
                return Err(LinearSolverError::Order("factor", "analyse"));
            };
            let a = SparseColMatRef::new((**pattern).as_ref(), values);
            let faer = sym.faer()?;
            self.l_values.resize(faer.len_val(), 0.0);
            let mut buf = MemBuffer::try_new(faer.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()))
                .map_err(|e| LinearSolverError::Faer(format!("{e:?}")))?;
            let ldlt = faer.factorize_numeric_ldlt(
                &mut self.l_values,
                a,
                Side::Lower,
                LdltRegularization::default(),
                par,
                MemStack::new(&mut buf),
                Default::default(),
            );
            if let Err(faer::linalg::cholesky::ldlt::factor::LdltError::ZeroPivot { index }) = ldlt {
                return Err(LinearSolverError::Singular { dof: Some(sym.dof_of_failed_pivot(index)) });
            }
        }
        let Some(Symbolic::Cholesky(sym)) = &self.symbolic else {
            return Err(LinearSolverError::Order("factor", "analyse"));
        };
        let orig = |j: usize| sym.perm.forward[j];

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
        Ok(if method == Factorization::Llt { Numeric::Llt } else { Numeric::Ldlt })
    }
}

/// The scale of a single-precision factorization: the power of two nearest the
/// inverse of the largest diagonal entry (`None` when there is none, or it is
/// not a positive finite number).
fn single_scale(values: &[f64], diag_pos: &[usize]) -> Option<f64> {
    inverse_power_of_two(diag_pos.iter().filter(|&&p| p != usize::MAX).map(|&p| values[p]).fold(0.0, f64::max))
}

/// The power of two nearest `1 / largest` (`None` unless `largest` is a positive
/// finite number): a scale that moves values of that size near 1 exactly.
fn inverse_power_of_two(largest: f64) -> Option<f64> {
    (largest.is_finite() && largest > 0.0).then(|| 2f64.powi(-(largest.log2().round() as i32)))
}

/// Whether every pivot `L_jj²` of a single-precision factor of `scale · A` is
/// finite and at least [`SINGLE_PIVOT_FLOOR`] of its diagonal entry `scale · a_jj`.
fn single_pivots_hold(structure: &Supernodal, l_values: &[f32], values: &[f64], diag_pos: &[usize], scale: f64, orig: impl Fn(usize) -> usize) -> bool {
    supernodal_diagonal(structure, l_values).iter().enumerate().all(|(j, &l)| {
        let p = diag_pos[orig(j)];
        let a_jj = if p == usize::MAX { 0.0 } else { scale * values[p] };
        let d = l * l;
        d.is_finite() && d > 0.0 && d >= SINGLE_PIVOT_FLOOR * a_jj
    })
}

/// Diagonal of a Cholesky-type factor in the permuted order: `L_jj` for `LLᵀ`,
/// `D_jj` for `LDLᵀ` (both are stored on the factor's diagonal).
fn factor_diagonal<T: super::tree_cholesky::FactorReal>(sym: &CholeskySymbolic, values: &[T]) -> Vec<f64> {
    match (&sym.structure, &sym.faer) {
        (Some(s), _) => supernodal_diagonal(s, values),
        (None, Some(c)) => match c.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let l = SimplicialLltRef::new(s, values);
                let f = s.factor();
                (0..c.nrows())
                    .map(|j| {
                        let (lo, hi) = (f.col_ptr()[j], f.col_ptr()[j + 1]);
                        f.row_idx()[lo..hi].iter().position(|&r| r == j).map_or(0.0, |k| l.values()[lo + k].to_f64())
                    })
                    .collect()
            }
            SymbolicCholeskyRaw::Supernodal(s) => supernodal_diagonal(&Supernodal::of_faer(s), values),
        },
        (None, None) => Vec::new(),
    }
}

/// The diagonal of a supernodal factor: entry `(k, k)` of each supernode's block.
fn supernodal_diagonal<T: super::tree_cholesky::FactorReal>(s: &Supernodal, values: &[T]) -> Vec<f64> {
    let mut diag = vec![0.0; s.nrows()];
    let (begin, end, val_ptr) = (s.supernode_begin(), s.supernode_end(), s.col_ptr_for_val());
    for sn in 0..s.n_supernodes() {
        let ncols = end[sn] - begin[sn];
        let nrows = (val_ptr[sn + 1] - val_ptr[sn]) / ncols.max(1);
        for k in 0..ncols {
            diag[begin[sn] + k] = values[val_ptr[sn] + k * nrows + k].to_f64();
        }
    }
    diag
}

impl LinearSolver for FaerDirect {
    fn name(&self) -> &str {
        "faer-direct"
    }

    fn analyse(&mut self, pattern: SymbolicSparseColMatRef<'_, usize>, symmetry: Symmetry) -> Result<(), LinearSolverError> {
        let owned = self.take_pattern(pattern)?;
        self.analyse_here(owned, symmetry)
    }

    /// The analysis beside the caller while it goes on (the first tangent's
    /// assembly), when rayon has more than one thread (with one, the caller asked
    /// for one core: here). The pattern is shared, not copied.
    fn analyse_in_background(&mut self, pattern: &SharedPattern, symmetry: Symmetry) -> Result<(), LinearSolverError> {
        let owned = self.share_pattern(pattern)?;
        // known at once (an `Arc`), before the analysis that installs it again
        self.pattern = Some(Arc::clone(&owned));
        if rayon::current_num_threads() < 2 {
            return self.analyse_here(owned, symmetry);
        }
        let options = self.options;
        let coordinates = self.coordinates.clone();
        // a task of rayon's pool: while it runs, the caller's parallel work (the
        // first assembly) goes to the other workers, and the cores hold as many
        // threads as they have (a thread of its own made three on two). A caller
        // that is a worker itself (the main thread: lib/os/worker_pool.rs) waits for
        // it by yielding to the pool first (`PendingAnalysis::wait`), so that the
        // task runs even when no other worker is free to take it.
        let (tx, rx) = std::sync::mpsc::sync_channel(1);
        rayon::spawn(move || {
            let done = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| analysis(owned, symmetry, options, coordinates.as_deref())))
                .unwrap_or_else(|_| Err(LinearSolverError::Faer("the analysis panicked".into())));
            let _ = tx.send(done);
        });
        self.pending = Some(PendingAnalysis(rx));
        Ok(())
    }

    fn set_unknown_coordinates(&mut self, coordinates: Arc<[[f64; 3]]>) {
        self.coordinates = Some(coordinates);
    }

    fn finish_analysis(&mut self) -> Result<(), LinearSolverError> {
        if let Some(pending) = self.pending.take() {
            let done = pending.wait()?;
            self.install(done);
        }
        Ok(())
    }

    fn factor(&mut self, values: &[f64]) -> Result<FactorInfo, LinearSolverError> {
        self.finish_analysis()?;
        let _span = timeline::span("factor (faer_direct)");
        let pattern = check_values(self.pattern.as_deref(), values)?;
        let start = Instant::now();
        self.numeric = Numeric::None;
        let result = match &self.symbolic {
            Some(Symbolic::Cholesky(_)) => self.factor_cholesky(values).map(|numeric| {
                self.numeric = numeric;
                if matches!(self.numeric, Numeric::Ldlt) { Factorization::Ldlt } else { Factorization::Llt }
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

    fn solve_in_place(&mut self, _values: &[f64], rhs: &mut [f64]) -> Result<(), LinearSolverError> {
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
            largest_factor: self.largest_factor,
        }
    }
}

/// The background analysis' result, to come from its task in rayon's pool.
struct PendingAnalysis(std::sync::mpsc::Receiver<Result<Analysis, LinearSolverError>>);

impl PendingAnalysis {
    /// The analysis' result. A worker of the pool runs what the pool has queued
    /// while the result is not there (the analysis itself, if no other worker took
    /// it), and blocks only once the pool has nothing left to run: the task is then
    /// running elsewhere, or done.
    fn wait(self) -> Result<Analysis, LinearSolverError> {
        use std::sync::mpsc::TryRecvError;
        let ended = || LinearSolverError::Faer("the analysis task ended without a result".into());
        loop {
            match self.0.try_recv() {
                Ok(done) => return done,
                Err(TryRecvError::Disconnected) => return Err(ended()),
                Err(TryRecvError::Empty) => {
                    if rayon::yield_now() != Some(rayon::Yield::Executed) {
                        return self.0.recv().map_err(|_| ended())?;
                    }
                }
            }
        }
    }
}

impl FaerDirect {
    /// Drops the pattern, the analysis and the factor (their memory), as a new
    /// `analyse` would before building its own.
    pub fn release(&mut self) {
        if let Some(pending) = self.pending.take() {
            // its result is of the pattern being replaced: dropped, its time counted
            if let Ok(a) = pending.wait() {
                self.symbolic_time += a.time;
                self.n_symbolic += 1;
            }
        }
        self.numeric = Numeric::None;
        self.symbolic = None;
        self.pattern = None;
        self.diag_pos = Vec::new();
        self.l_values = Vec::new();
        self.l_values32 = Vec::new();
        self.widest_supernode = 0;
        self.tree = None;
    }

    /// The analysed pattern, if any.
    pub fn pattern(&self) -> Option<&SymbolicSparseColMat<usize>> {
        self.pattern.as_deref()
    }

    /// Solve in place by the elimination tree ([`TreeCholesky::solve_in_place`])
    /// when the factor held is an `LLᵀ` that the tree made (double, or single of
    /// `scale · A`); `false`, untouched, otherwise (faer's solve).
    fn solve_by_tree(&self, rhs: &mut [f64]) -> bool {
        let (Some(tree), Some(Symbolic::Cholesky(sym))) = (&self.tree, &self.symbolic) else {
            return false;
        };
        let Some(s) = &sym.structure else {
            return false;
        };
        let fwd = &sym.perm.forward[..];
        // a solve already under way on this solver (another thread's, or one a
        // waiting rayon worker took up) keeps the kept arrays: this one makes its own
        let (mut held, mut own) = (self.solve_scratch.try_lock().ok(), SolveScratch::default());
        let scratch = held.as_deref_mut().unwrap_or(&mut own);
        match self.numeric {
            Numeric::Llt => permuted_tree_solve(tree, s, fwd, &self.l_values, rhs, |v| v, |v| v, &mut scratch.z, &mut scratch.w),
            Numeric::LltSingle { scale } => {
                // A⁻¹ b = scale (scale A)⁻¹ b
                let b_scale = single_rhs_scale(rhs);
                let back = scale / b_scale;
                permuted_tree_solve(tree, s, fwd, &self.l_values32, rhs, |v| (v * b_scale) as f32, |v| back * f64::from(v), &mut scratch.z32, &mut scratch.w32);
            }
            _ => return false,
        }
        true
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
        // the tree's own solve for the factors it made, faer's for the others
        if !self.solve_by_tree(rhs) {
            match (&self.symbolic, &self.numeric) {
                (Some(Symbolic::Cholesky(c)), Numeric::Llt) => {
                    let sym = c.faer()?;
                    let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
                    let mut buf = MemBuffer::try_new(sym.solve_in_place_scratch::<f64>(1, par)).map_err(faer_err)?;
                    LltRef::new(sym, &self.l_values).solve_in_place_with_conj(Conj::No, x, par, MemStack::new(&mut buf));
                }
                (Some(Symbolic::Cholesky(c)), &Numeric::LltSingle { scale }) => {
                    let sym = c.faer()?;
                    // A⁻¹ b = scale (scale A)⁻¹ b
                    let b_scale = single_rhs_scale(rhs);
                    let mut x32: Vec<f32> = rhs.iter().map(|&v| (v * b_scale) as f32).collect();
                    let mut buf = MemBuffer::try_new(sym.solve_in_place_scratch::<f32>(1, par)).map_err(faer_err)?;
                    let x = MatMut::from_column_major_slice_mut(&mut x32, n, 1);
                    LltRef::new(sym, &self.l_values32).solve_in_place_with_conj(Conj::No, x, par, MemStack::new(&mut buf));
                    let back = scale / b_scale;
                    rhs.iter_mut().zip(&x32).for_each(|(r, &v)| *r = back * f64::from(v));
                }
                (Some(Symbolic::Cholesky(c)), Numeric::Ldlt) => {
                    let sym = c.faer()?;
                    let mut buf = MemBuffer::try_new(sym.solve_in_place_scratch::<f64>(1, par)).map_err(faer_err)?;
                    let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
                    LdltRef::new(sym, &self.l_values).solve_in_place_with_conj(Conj::No, x, par, MemStack::new(&mut buf));
                }
                (Some(Symbolic::Lu(sym)), Numeric::Lu(num)) => {
                    let mut buf = MemBuffer::try_new(sym.solve_in_place_scratch::<f64>(1, par)).map_err(faer_err)?;
                    let x = MatMut::from_column_major_slice_mut(rhs, n, 1);
                    LuRef::new_unchecked(sym, num).solve_in_place_with_conj(Conj::No, x, par, MemStack::new(&mut buf));
                }
                _ => return Err(LinearSolverError::Order("solve_in_place", "a successful factor")),
            }
        }
        self.solve_nanos.fetch_add(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
        self.n_solve.fetch_add(1, Ordering::Relaxed);
        if rhs.iter().any(|v| !v.is_finite()) {
            return Err(LinearSolverError::Singular { dof: None });
        }
        Ok(())
    }

}

/// The power of two that brings a right-hand side into `f32`'s range for a
/// single-precision solve (1 for a zero one).
fn single_rhs_scale(rhs: &[f64]) -> f64 {
    let largest = rhs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    inverse_power_of_two(largest).unwrap_or(1.0)
}

/// `rhs ← (L Lᵀ)⁻¹ rhs` through the tree's solve of `P rhs` (`fwd`: the forward
/// permutation), each entry converted `into` the factor's precision and `back`.
#[allow(clippy::too_many_arguments)]
fn permuted_tree_solve<T: FactorReal>(
    tree: &TreeCholesky,
    symbolic: &Supernodal,
    fwd: &[usize],
    l_values: &[T],
    rhs: &mut [f64],
    into: impl Fn(f64) -> T,
    back: impl Fn(T) -> f64,
    z: &mut Vec<T>,
    w: &mut Vec<T>,
) {
    z.clear();
    z.extend(fwd.iter().map(|&i| into(rhs[i])));
    tree.solve_in_place(symbolic, l_values, z, w);
    fwd.iter().zip(z.iter()).for_each(|(&i, &v)| rhs[i] = back(v));
}

/// The work arrays of a tree solve ([`TreeCholesky::solve_in_place`]) in each
/// precision: the permuted right-hand side and the supernodes' updates.
#[derive(Default)]
struct SolveScratch {
    z: Vec<f64>,
    w: Vec<f64>,
    z32: Vec<f32>,
    w32: Vec<f32>,
}

/// What `analyse` makes of a pattern: everything a numeric factorization reads.
struct Analysis {
    pattern: SharedPattern,
    diag_pos: Vec<usize>,
    symbolic: Symbolic,
    tree: Option<TreeCholesky>,
    widest_supernode: usize,
    time: Duration,
}

impl FaerDirect {
    /// The checked, owned copy of a pattern to analyse; the old pattern, analysis
    /// and factor are dropped first (peak memory).
    fn take_pattern(&mut self, pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<SharedPattern, LinearSolverError> {
        square(pattern.nrows(), pattern.ncols())?;
        self.release();
        pattern.to_owned().map(Arc::new).map_err(|e| LinearSolverError::Faer(format!("{e:?}")))
    }

    /// [`Self::take_pattern`] of a shared pattern: the same checks, no copy.
    fn share_pattern(&mut self, pattern: &SharedPattern) -> Result<SharedPattern, LinearSolverError> {
        square(pattern.nrows(), pattern.ncols())?;
        self.release();
        Ok(Arc::clone(pattern))
    }

    /// The analysis of `owned` on the caller's thread, installed.
    fn analyse_here(&mut self, owned: SharedPattern, symmetry: Symmetry) -> Result<(), LinearSolverError> {
        let done = analysis(owned, symmetry, self.options, self.coordinates.as_deref())?;
        self.install(done);
        Ok(())
    }

    fn install(&mut self, a: Analysis) {
        self.pattern = Some(a.pattern);
        self.diag_pos = a.diag_pos;
        self.symbolic = Some(a.symbolic);
        self.largest_factor = self.largest_factor.max(self.factor_len());
        self.tree = a.tree;
        self.widest_supernode = a.widest_supernode;
        self.symbolic_time += a.time;
        self.n_symbolic += 1;
    }
}

/// A pattern to factor is square.
fn square(n_rows: usize, n_cols: usize) -> Result<(), LinearSolverError> {
    if n_cols != n_rows {
        return Err(LinearSolverError::Dimension { what: "columns (square matrix)", expected: n_rows, got: n_cols });
    }
    Ok(())
}

/// Ordering and symbolic factorization of `owned` (on any thread: it reads nothing
/// but its arguments).
fn analysis(owned: SharedPattern, symmetry: Symmetry, options: FaerDirectOptions, coordinates: Option<&[[f64; 3]]>) -> Result<Analysis, LinearSolverError> {
    let start = Instant::now();
    let a = (*owned).as_ref();
    let n = a.nrows();
    let diag_pos = (0..n)
        .map(|j| {
            let (lo, hi) = (owned.col_ptr()[j], owned.col_ptr()[j + 1]);
            owned.row_idx()[lo..hi].binary_search(&j).map_or(usize::MAX, |k| lo + k)
        })
        .collect();
    let symbolic = match symmetry {
        Symmetry::Symmetric => {
            let c = match options.ordering {
                FillOrdering::Amd => {
                    let _symbolic_span = timeline::span("analysis: symbolic factorization (faer)");
                    CholeskySymbolic::of_faer(faer_symbolic(a, SymmetricOrdering::Amd)?)
                }
                FillOrdering::NestedDissection | FillOrdering::Geometric => {
                    let ordering_span = timeline::span("analysis: fill-reducing ordering");
                    let graph = SupervariableGraph::of(a)?;
                    // without the unknowns' positions (a caller that gave none) the
                    // graph's own nested dissection
                    let (order, what) = match (options.ordering, coordinates) {
                        (FillOrdering::Geometric, Some(x)) => (geometric_order_of(&graph, x)?, "the geometric ordering"),
                        _ => (nested_dissection_of(&graph)?, "METIS_NodeND"),
                    };
                    let perm = graph.expand(order.iter().copied(), what)?;
                    drop(ordering_span);
                    if options.elimination_tree {
                        // faer's structure on the supervariables; faer's own analysis
                        // only if an LDLᵀ needs it
                        let _symbolic_span = timeline::span("analysis: supernodal structure");
                        let structure = Supernodal::of_supervariables(&graph, &order);
                        CholeskySymbolic { perm, structure: Some(structure), faer: None }
                    } else {
                        let _symbolic_span = timeline::span("analysis: symbolic factorization (faer)");
                        let ordering = SymmetricOrdering::Custom(PermRef::new_checked(&perm.forward, &perm.inverse, n));
                        CholeskySymbolic::of_faer(faer_symbolic(a, ordering)?)
                    }
                }
            };
            // sized in double even for a single-precision factor: one that f32 cannot
            // hold is made in double
            crate::solver::memory::check_cholesky(c.len_val(), n, owned.compute_nnz()).map_err(LinearSolverError::TooLarge)?;
            Symbolic::Cholesky(c)
        }
        Symmetry::General => Symbolic::Lu(factorize_symbolic_lu(a, Default::default()).map_err(|e| LinearSolverError::Faer(format!("{e:?}")))?),
    };
    let _tree_span = timeline::span("analysis: elimination-tree tasks");
    let tree = match &symbolic {
        Symbolic::Cholesky(CholeskySymbolic { structure: Some(s), .. }) if options.elimination_tree => Some(TreeCholesky::new(s)),
        _ => None,
    };
    let widest_supernode = match &symbolic {
        Symbolic::Cholesky(CholeskySymbolic { structure: Some(s), .. }) => s.widest(),
        Symbolic::Cholesky(_) => 1,
        Symbolic::Lu(_) => 0,
    };
    Ok(Analysis { pattern: owned, diag_pos, symbolic, tree, widest_supernode, time: start.elapsed() })
}

#[cfg(test)]
mod tests;
