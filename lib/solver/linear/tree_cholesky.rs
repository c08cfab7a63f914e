//! Supernodal `LLᵀ`, parallel over the elimination tree.
//!
//! faer's numeric supernodal Cholesky walks the supernodes one after another and
//! parallelises only inside the dense kernels of a supernode, which pays on two
//! cores only when the widest supernode has thousands of columns
//! ([`super::faer_direct::PARALLEL_SUPERNODE`]). Below that the factorization ran on
//! one core while the other idled. But two supernodes of which neither is an
//! ancestor of the other never touch each other's columns: the subtrees of the
//! (supernodal) elimination tree are independent, and a nested-dissection ordering
//! makes the tree bushy (the two halves under each separator; the two bodies of a
//! contact model under their interface). This module factors the subtrees in
//! parallel and the supernodes above them once their children are done.
//!
//! **The algorithm** is the left-looking supernodal one, on faer's symbolic
//! factorization and into faer's value layout (each supernode `s` a dense
//! column-major block of its rows × its columns), so faer's triangular solves use
//! the factor unchanged. For supernode `s` with columns `[s₀, s₁)`:
//! 1. scatter the lower triangle of `P A Pᵀ`'s columns `[s₀, s₁)` into `L_s`;
//! 2. for every descendant `d` whose row pattern meets `[s₀, s₁)` (in increasing
//!    order of `d`), with `L_d,mid` its rows in `[s₀, s₁)` and `L_d,low` its rows
//!    from `s₀` on: `W = L_d,low L_d,midᵀ` (dense, into a buffer, by panels of
//!    columns that keep it under 1/64 of the factor's size, at least
//!    [`W_ENTRIES`]), then `L_s[rows, cols] -= W`
//!    through the row map of `s`;
//! 3. `L_s,top = chol(L_s,top)`, `L_s,bot ← L_s,bot L_s,top⁻ᵀ`.
//!
//! **Determinism.** Each supernode's operations and their order are fixed by the
//! symbolic factorization alone; which thread runs them does not change a bit.
//! The factor is therefore the same for any number of threads, except where the
//! dense kernels of one supernode are themselves given several threads
//! ([`TreeCholesky::factor`]'s `par`, used only for the supernodes above the last
//! parallel split, from [`DENSE_PARALLEL_COLUMNS`] columns on).
//!
//! **Safety.** All supernodes write into one value array. A task writes only the
//! block of the supernode it factors and reads only the blocks of that
//! supernode's descendants, which were finished before it started (the same task
//! factored them before it, children before parents, or a child task that was
//! joined before): the blocks a thread writes are never read or written by
//! another thread at the same time. A large update's scatter splits the columns
//! of `L_s` among threads; distinct columns of `L_d,mid` land in distinct columns
//! of `L_s`.

use std::cell::Cell;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch, LltError, LltRegularization};
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::SparseColMatRef;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, MatMut, MatRef, Par};
use rayon::prelude::*;

/// Supernodes from this width on get the factorization's `par` for their dense
/// kernels when no other task can run beside them.
pub const DENSE_PARALLEL_COLUMNS: usize = 256;

/// Entries of the update buffer `W` of one thread: 1/64 of the factor's entries
/// and at least this (1 MB); a larger update goes by panels of columns. Narrow
/// panels re-read `L_d,low` once per panel: the 30³ cube's factor (2 threads)
/// takes 2.1 s with a 11 MB buffer and 2.45 s with 1 MB.
const W_ENTRIES: usize = 1 << 17;

/// An update `W` of at least this many entries is scattered into `L_s` by
/// several threads (when the supernode's `par` has them).
const PARALLEL_SCATTER: usize = 1 << 16;

/// A subtree whose factorization costs less than this many flops runs as one
/// sequential task (spawning costs microseconds; this is ~0.1 ms of work).
const TASK_FLOPS: f64 = 2.0e6;

/// The schedule of the parallel factorization of one symbolic factor: the
/// supernodal elimination tree and, per supernode, the descendants that update it.
#[derive(Debug, Clone)]
pub struct TreeCholesky {
    /// `children[s]`: the supernodes whose parent is `s`, increasing.
    children: Vec<Vec<usize>>,
    /// Roots of the forest, increasing.
    roots: Vec<usize>,
    /// Flops of the factorization of the subtree of `s` (its own and its
    /// descendants').
    subtree_flops: Vec<f64>,
    /// `updaters[s]`: the descendants `d` whose row pattern meets the columns of
    /// `s`, increasing.
    updaters: Vec<Vec<usize>>,
    /// Total flops.
    flops: f64,
}

/// The raw value array shared by the tasks (see the module's **Safety**).
#[derive(Clone, Copy)]
struct SharedValues {
    ptr: *mut f64,
    len: usize,
}
// SAFETY: the tasks write disjoint supernode blocks and read only finished ones
// (module documentation).
unsafe impl Send for SharedValues {}
unsafe impl Sync for SharedValues {}

impl SharedValues {
    /// `len` values from `offset` on, for reading.
    ///
    /// # Safety
    /// `offset + len` within the array, and no one writes them while the slice
    /// lives.
    unsafe fn slice(&self, offset: usize, len: usize) -> &[f64] {
        assert!(offset + len <= self.len, "a block inside the value array");
        // SAFETY: in bounds (checked); not written by the caller's contract
        unsafe { std::slice::from_raw_parts(self.ptr.add(offset), len) }
    }

    /// `len` values from `offset` on, for writing.
    ///
    /// # Safety
    /// `offset + len` within the array, and no one else reads or writes them
    /// while the slice lives.
    #[allow(clippy::mut_from_ref)]
    unsafe fn slice_mut(&self, offset: usize, len: usize) -> &mut [f64] {
        assert!(offset + len <= self.len, "a block inside the value array");
        // SAFETY: in bounds (checked); exclusive by the caller's contract
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(offset), len) }
    }
}

/// Per-thread scratch of [`Context::supernode`]: the global-to-local row map
/// (`NONE` outside the supernode being factored), the update buffer `W`, and the
/// dense Cholesky's workspace.
#[derive(Default)]
struct Scratch {
    local: Vec<usize>,
    w: Vec<f64>,
    map: Vec<usize>,
    dense: Option<MemBuffer>,
}

thread_local! {
    /// Taken out while a supernode is factored and put back after: a thread
    /// waiting in a parallel dense kernel may run another task's supernode,
    /// which then finds none and makes its own.
    static SCRATCH: Cell<Option<Box<Scratch>>> = const { Cell::new(None) };
}

const NONE: usize = usize::MAX;

impl TreeCholesky {
    /// The schedule of `symbolic`'s numeric factorization.
    pub fn new(symbolic: &SymbolicSupernodalCholesky<usize>) -> Self {
        let n_super = symbolic.n_supernodes();
        let n = symbolic.nrows();
        let (begin, end) = (symbolic.supernode_begin(), symbolic.supernode_end());
        let row_ptr = symbolic.col_ptr_for_row_idx();
        let rows = symbolic.row_idx();
        let mut super_of = vec![0usize; n];
        for s in 0..n_super {
            super_of[begin[s]..end[s]].fill(s);
        }
        let mut children = vec![Vec::new(); n_super];
        let mut roots = Vec::new();
        let mut updaters = vec![Vec::new(); n_super];
        let mut own_flops = vec![0.0; n_super];
        for d in 0..n_super {
            let pattern = &rows[row_ptr[d]..row_ptr[d + 1]];
            let c = (end[d] - begin[d]) as f64;
            let m = pattern.len() as f64;
            // chol of the c × c block, the m × c triangular solve, the updates it sends
            own_flops[d] = c * c * c / 3.0 + m * c * c + m * m * c;
            match pattern.first() {
                Some(&r) => children[super_of[r]].push(d),
                None => roots.push(d),
            }
            let mut last = NONE;
            for &r in pattern {
                let s = super_of[r];
                if s != last {
                    updaters[s].push(d);
                    last = s;
                }
            }
        }
        let mut subtree_flops = own_flops;
        for s in 0..n_super {
            // children have smaller numbers than their parent
            for &c in &children[s] {
                let f = subtree_flops[c];
                subtree_flops[s] += f;
            }
        }
        let flops = roots.iter().map(|&r| subtree_flops[r]).sum();
        Self { children, roots, subtree_flops, updaters, flops }
    }

    /// Flops of one numeric factorization (multiply and add counted apart).
    pub fn flops(&self) -> f64 {
        self.flops
    }

    /// How many subtrees the schedule hands to separate tasks (the children of
    /// every supernode that is split; 0: the factorization runs as one task).
    pub fn parallel_subtrees(&self) -> usize {
        let split = |s: usize| self.subtree_flops[s] >= TASK_FLOPS && self.children[s].len() > 1;
        let tops = if self.roots.len() > 1 { self.roots.len() } else { 0 };
        tops + (0..self.children.len()).filter(|&s| split(s)).map(|s| self.children[s].len()).sum::<usize>()
    }

    /// Numeric `LLᵀ` of `a_lower` (the lower triangle of `P A Pᵀ`, in the
    /// symbolic factor's order; row indices within a column in any order) into
    /// `l_values` (faer's supernodal layout, `symbolic.len_val()` values). `par`
    /// is given to the dense kernels of the wide supernodes at the top of the tree
    /// (see [`DENSE_PARALLEL_COLUMNS`]); the subtrees run on rayon's pool.
    ///
    /// Returns the first column (in the permuted order, smallest over the
    /// supernodes that met one) where a pivot is not positive.
    pub fn factor(
        &self,
        symbolic: &SymbolicSupernodalCholesky<usize>,
        a_lower: SparseColMatRef<'_, usize, f64>,
        l_values: &mut [f64],
        par: Par,
    ) -> Result<(), LltError> {
        assert_eq!(l_values.len(), symbolic.len_val(), "the value array must match the symbolic factor");
        assert_eq!(a_lower.nrows(), symbolic.nrows(), "the matrix must match the symbolic factor");
        let values = SharedValues { ptr: l_values.as_mut_ptr(), len: l_values.len() };
        let failed = std::sync::Mutex::new(None::<usize>);
        let ctx = Context { tree: self, symbolic, a_lower, values, failed: &failed, par, w_entries: W_ENTRIES.max(l_values.len() / 64) };
        let threads = rayon::current_num_threads();
        if threads <= 1 {
            for s in 0..symbolic.n_supernodes() {
                ctx.supernode(s, Par::Seq);
            }
        } else {
            rayon::scope(|scope| {
                for &r in &self.roots {
                    let ctx = &ctx;
                    scope.spawn(move |_| ctx.subtree(r));
                }
            });
        }
        match failed.into_inner().unwrap_or_else(|e| e.into_inner()) {
            Some(index) => Err(LltError::NonPositivePivot { index }),
            None => Ok(()),
        }
    }
}

/// What every task of one factorization shares.
struct Context<'a> {
    tree: &'a TreeCholesky,
    symbolic: &'a SymbolicSupernodalCholesky<usize>,
    a_lower: SparseColMatRef<'a, usize, f64>,
    values: SharedValues,
    failed: &'a std::sync::Mutex<Option<usize>>,
    par: Par,
    /// Entries of a thread's update buffer (see [`W_ENTRIES`]).
    w_entries: usize,
}

impl Context<'_> {
    /// Factors the subtree of `s`: sequentially if it is small or a chain,
    /// otherwise its children's subtrees in parallel, then `s`.
    fn subtree(&self, s: usize) {
        let tree = self.tree;
        let kids = &tree.children[s];
        if tree.subtree_flops[s] < TASK_FLOPS || kids.is_empty() {
            // children before parents, without recursion (chains can be long)
            let mut stack = vec![(s, false)];
            while let Some((t, expanded)) = stack.pop() {
                if expanded {
                    self.supernode(t, Par::Seq);
                } else {
                    stack.push((t, true));
                    stack.extend(tree.children[t].iter().rev().map(|&c| (c, false)));
                }
            }
            return;
        }
        if kids.len() == 1 {
            self.subtree(kids[0]);
        } else {
            rayon::scope(|scope| {
                for &c in &kids[1..] {
                    scope.spawn(move |_| self.subtree(c));
                }
                self.subtree(kids[0]);
            });
        }
        let ncols = self.symbolic.supernode_end()[s] - self.symbolic.supernode_begin()[s];
        self.supernode(s, if ncols >= DENSE_PARALLEL_COLUMNS { self.par } else { Par::Seq });
    }

    /// Steps 1–3 of the module's algorithm for supernode `s`.
    fn supernode(&self, s: usize, par: Par) {
        let sym = self.symbolic;
        let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
        let row_ptr = sym.col_ptr_for_row_idx();
        let val_ptr = sym.col_ptr_for_val();
        let rows = sym.row_idx();
        let (s0, s1) = (begin[s], end[s]);
        let s_pattern = &rows[row_ptr[s]..row_ptr[s + 1]];
        let s_ncols = s1 - s0;
        let s_nrows = s_ncols + s_pattern.len();
        // SAFETY: block `s` is written by this task only; see the module's Safety.
        let ls_slice = unsafe { self.values.slice_mut(val_ptr[s], val_ptr[s + 1] - val_ptr[s]) };
        ls_slice.fill(0.0);
        let mut ls = MatMut::from_column_major_slice_mut(ls_slice, s_nrows, s_ncols);
        let mut scratch = SCRATCH.with(Cell::take).unwrap_or_default();
        {
            let Scratch { local, w: buffer, map, .. } = &mut *scratch;
            if local.len() < sym.nrows() {
                local.resize(sym.nrows(), NONE);
            }
            for (i, &r) in s_pattern.iter().enumerate() {
                local[r] = s_ncols + i;
            }
            // 1. the matrix's own entries
            for j in s0..s1 {
                let col = j - s0;
                for (i, &v) in self.a_lower.row_idx_of_col(j).zip(self.a_lower.val_of_col(j)) {
                    if i < j {
                        continue;
                    }
                    let row = if i < s1 { i - s0 } else { local[i] };
                    ls[(row, col)] += v;
                }
            }
            // 2. the updates of the descendants
            for &d in &self.tree.updaters[s] {
                let (d0, d1) = (begin[d], end[d]);
                let d_ncols = d1 - d0;
                let d_pattern = &rows[row_ptr[d]..row_ptr[d + 1]];
                let d_nrows = d_ncols + d_pattern.len();
                // SAFETY: `d` is a finished descendant of `s`: read only.
                let ld = unsafe { self.values.slice(val_ptr[d], val_ptr[d + 1] - val_ptr[d]) };
                let ld = MatRef::from_column_major_slice(ld, d_nrows, d_ncols);
                let p0 = d_pattern.partition_point(|&r| r < s0);
                let mid = d_pattern[p0..].partition_point(|&r| r < s1);
                let low = d_pattern.len() - p0;
                let ld_low = ld.subrows(d_ncols + p0, low);
                let ld_mid = ld_low.subrows(0, mid);
                // the rows of W in L_s
                map.clear();
                map.extend(d_pattern[p0..].iter().map(|&r| if r < s1 { r - s0 } else { local[r] }));
                let ls_cols = SharedValues { ptr: ls.rb_mut().as_ptr_mut(), len: s_nrows * s_ncols };
                // W = L_low L_midᵀ by panels of the mid columns [j0, j1), each the lower
                // triangle of its top block and the rectangle below (the buffer stays
                // under w_entries however large the update)
                let width = (self.w_entries / low.max(1)).max(32).min(mid.max(1));
                for j0 in (0..mid).step_by(width) {
                    let j1 = (j0 + width).min(mid);
                    let (cols, rows) = (j1 - j0, low - j0);
                    if buffer.len() < rows * cols {
                        buffer.resize(rows * cols, 0.0);
                    }
                    let mut w = MatMut::from_column_major_slice_mut(&mut buffer[..rows * cols], rows, cols);
                    let panel = ld_mid.subrows(j0, cols);
                    let (w_top, w_bot) = w.rb_mut().split_at_row_mut(cols);
                    triangular::matmul(
                        w_top,
                        BlockStructure::TriangularLower,
                        Accum::Replace,
                        panel,
                        BlockStructure::Rectangular,
                        panel.transpose(),
                        BlockStructure::Rectangular,
                        1.0,
                        par,
                    );
                    matmul(w_bot, Accum::Replace, ld_low.subrows(j1, low - j1), panel.transpose(), 1.0, par);
                    let w = w.rb();
                    let map = &map[j0..];
                    let scatter = |jj: usize, dst: &mut [f64]| {
                        let w_col = w.col(jj).try_as_col_major().expect("W is column-major").as_slice();
                        for ii in jj..rows {
                            dst[map[ii]] -= w_col[ii];
                        }
                    };
                    // SAFETY: L_s is column-major with s_nrows rows, and the columns
                    // d_pattern[p0 + j] − s₀ are distinct for distinct j: each call
                    // writes its own column
                    let column = |jj: usize| unsafe { ls_cols.slice_mut((d_pattern[p0 + j0 + jj] - s0) * s_nrows, s_nrows) };
                    if matches!(par, Par::Rayon(_)) && rows * cols >= PARALLEL_SCATTER {
                        (0..cols).into_par_iter().for_each(|jj| scatter(jj, column(jj)));
                    } else {
                        for jj in 0..cols {
                            scatter(jj, column(jj));
                        }
                    }
                }
            }
            for &r in s_pattern {
                local[r] = NONE;
            }
        }
        // 3. the dense factorization of the supernode
        let (mut ls_top, ls_bot) = ls.split_at_row_mut(s_ncols);
        let req = cholesky_in_place_scratch::<f64>(s_ncols, par, Default::default());
        let mem = match scratch.dense.take() {
            Some(mut m) => {
                if MemStack::new(&mut m).can_hold(req) {
                    m
                } else {
                    MemBuffer::new(req)
                }
            }
            None => MemBuffer::new(req),
        };
        let mem = scratch.dense.insert(mem);
        let regularization = LltRegularization { dynamic_regularization_delta: 0.0, dynamic_regularization_epsilon: 0.0 };
        let result = cholesky_in_place(ls_top.rb_mut(), regularization, par, MemStack::new(mem), Default::default());
        SCRATCH.with(|c| c.set(Some(scratch)));
        if let Err(LltError::NonPositivePivot { index }) = result {
            let mut failed = self.failed.lock().unwrap_or_else(|e| e.into_inner());
            let index = index + s0;
            *failed = Some(failed.map_or(index, |f| f.min(index)));
            return;
        }
        solve_lower_triangular_in_place(ls_top.rb(), ls_bot.transpose_mut(), par);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::bench::{elastic_cube_system, relative_residual};
    use crate::solver::linear::{FaerDirect, FaerDirectOptions, LinearSolver, LinearSolverError, SymmetricStrategy, Symmetry};
    use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
    use faer::sparse::SymbolicSparseColMat;

    fn solve(options: FaerDirectOptions, p: &SymbolicSparseColMat<usize>, v: &[f64], b: &[f64], threads: usize) -> Result<Vec<f64>, LinearSolverError> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool");
        pool.install(|| {
            let mut s = FaerDirect::new(options);
            s.analyse(p.as_ref(), Symmetry::Symmetric)?;
            s.factor(v)?;
            let mut x = b.to_vec();
            s.solve_in_place(&mut x)?;
            Ok(x)
        })
    }

    fn tree(on: bool) -> FaerDirectOptions {
        FaerDirectOptions { elimination_tree: on, ..Default::default() }
    }

    #[test]
    fn the_tree_factor_solves_as_faers_own_does() {
        let cube = elastic_cube_system(10).unwrap();
        let (p, v, b) = (cube.pattern.symbolic_owned(), cube.assembly.values(), &cube.rhs);
        // the schedule really splits this factor into parallel subtrees
        let sym = faer::sparse::linalg::cholesky::factorize_symbolic_cholesky(
            p.as_ref(),
            faer::Side::Lower,
            faer::sparse::linalg::cholesky::SymmetricOrdering::Custom(faer::perm::PermRef::new_checked(
                &crate::solver::ordering::nested_dissection(p.as_ref()).unwrap().forward,
                &crate::solver::ordering::nested_dissection(p.as_ref()).unwrap().inverse,
                p.nrows(),
            )),
            faer::sparse::linalg::cholesky::CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: faer::sparse::linalg::SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .unwrap();
        let SymbolicCholeskyRaw::Supernodal(s) = sym.raw() else { panic!("a supernodal factor") };
        let schedule = TreeCholesky::new(s);
        assert!(schedule.parallel_subtrees() >= 4, "{} parallel subtrees", schedule.parallel_subtrees());
        let x_faer = solve(tree(false), p, v, b, 2).unwrap();
        let x_tree = solve(tree(true), p, v, b, 2).unwrap();
        let r = relative_residual(p.col_ptr(), p.row_idx(), v, &x_tree, b);
        assert!(r < 1e-12, "residual {r:e}");
        // the same operations in another order: the two differ by round-off only
        // (the cube's condition number is ~1e4: 1e-16 · 1e4 with room)
        let norm = x_faer.iter().map(|v| v * v).sum::<f64>().sqrt();
        let d = x_tree.iter().zip(&x_faer).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
        assert!(d / norm < 1e-11, "solutions differ by {:e}", d / norm);
    }

    #[test]
    fn the_tree_factor_is_the_same_for_any_number_of_threads() {
        let cube = elastic_cube_system(10).unwrap();
        let (p, v, b) = (cube.pattern.symbolic_owned(), cube.assembly.values(), &cube.rhs);
        // the dense kernels sequential: only the tree runs in parallel
        let options = FaerDirectOptions { par: Some(Par::Seq), ..tree(true) };
        let bits = |x: Vec<f64>| x.into_iter().map(f64::to_bits).collect::<Vec<_>>();
        let one = bits(solve(options, p, v, b, 1).unwrap());
        for threads in [2, 3] {
            assert_eq!(one, bits(solve(options, p, v, b, threads).unwrap()), "{threads} threads");
        }
    }

    #[test]
    fn a_non_positive_pivot_is_reported_where_faer_reports_it() {
        let cube = elastic_cube_system(8).unwrap();
        let (p, b) = (cube.pattern.symbolic_owned(), &cube.rhs);
        let mut v = cube.assembly.values().to_vec();
        // an indefinite matrix: one diagonal entry in the middle of the cube negated
        let j = p.ncols() / 2;
        let k = (p.col_ptr()[j]..p.col_ptr()[j + 1]).find(|&k| p.row_idx()[k] == j).unwrap();
        v[k] = -v[k];
        let llt_only = |on: bool| FaerDirectOptions { symmetric: SymmetricStrategy::Llt, ..tree(on) };
        let dof = |r: Result<Vec<f64>, LinearSolverError>| match r {
            Err(LinearSolverError::NotPositiveDefinite { dof }) => dof,
            other => panic!("expected a non-positive pivot, got {:?}", other.map(|x| x.len())),
        };
        let faer_dof = dof(solve(llt_only(false), p, &v, b, 2));
        assert_eq!(dof(solve(llt_only(true), p, &v, b, 2)), faer_dof);
        assert_eq!(dof(solve(llt_only(true), p, &v, b, 1)), faer_dof);
        // and the default strategy goes on to LDLᵀ, which solves it
        let x = solve(tree(true), p, &v, b, 2).unwrap();
        let r = relative_residual(p.col_ptr(), p.row_idx(), &v, &x, b);
        assert!(r < 1e-10, "residual {r:e}");
    }
}
