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
//! 1. scatter the lower triangle of `P A Pᵀ`'s columns `[s₀, s₁)` into `L_s`, read
//!    from `A` itself (column `p(j)` of `A`, its rows renumbered by `p⁻¹`; no permuted
//!    copy is made);
//! 2. for every descendant `d` whose row pattern meets `[s₀, s₁)` (in increasing
//!    order of `d`), with `L_d,mid` its rows in `[s₀, s₁)` and `L_d,low` its rows
//!    from `s₀` on: `W = L_d,low L_d,midᵀ` (dense, into a buffer, by panels of
//!    columns that keep it under 1/64 of the factor's size, at least
//!    [`W_ENTRIES`]), then `L_s[rows, cols] -= W`
//!    through the row map of `s`. Where these updates are heavy (the top of the
//!    tree, which waits for everything below it), they run as parallel tasks, each
//!    for its own chunk of the columns of `L_s` and every descendant in turn
//!    ([`CHUNK_FLOPS`]);
//! 3. `L_s,top = chol(L_s,top)`, `L_s,bot ← L_s,bot L_s,top⁻ᵀ`.
//!
//! **Determinism.** Each supernode's operations and their order are fixed by the
//! symbolic factorization alone; which thread runs them does not change a bit.
//! The column chunks of step 2 are fixed by the symbolic factorization too, and a
//! chunk applies the descendants in the same order as the unchunked loop, and the
//! dense products give each entry of `W` the same sum whatever panel it is
//! computed in: the factor is the same bit for bit with chunks or without
//! (`faer_direct::tests`, against faer's own factorization).
//! The factor is therefore the same for any number of threads, except where the
//! dense kernels of one supernode are themselves given several threads
//! ([`TreeCholesky::factor`]'s `par`, used only for the supernodes above the last
//! parallel split, from [`DENSE_PARALLEL_COLUMNS`] columns on).
//!
//! **Precision.** The factor is of any [`FactorReal`] (`f64`, or `f32` for a
//! preconditioner: half the memory and bandwidth, twice the SIMD lanes); the
//! matrix is read in `f64` and each entry rounded once, times a scale the caller
//! chooses (a power of two keeps it exact).
//!
//! **Safety.** All supernodes write into one value array. A task writes only the
//! block of the supernode it factors and reads only the blocks of that
//! supernode's descendants, which were finished before it started (the same task
//! factored them before it, children before parents, or a child task that was
//! joined before): the blocks a thread writes are never read or written by
//! another thread at the same time. A large update's scatter splits the columns
//! of `L_s` among threads, and so do the chunk tasks of step 2; distinct columns
//! of `L_d,mid` land in distinct columns of `L_s`.

use std::cell::Cell;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch, LltError, LltRegularization};
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use super::supernodal::Supernodal;
use faer::sparse::SparseColMatRef;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::traits::RealField;
use faer::{Accum, MatMut, MatRef, Par};
use rayon::prelude::*;

/// The scalars a [`TreeCholesky`] factor is made of: `f64`, and `f32` for a
/// single-precision preconditioner.
pub trait FactorReal: RealField + Copy + Send + Sync + 'static {
    /// `x` rounded to this type.
    fn of_f64(x: f64) -> Self;
    /// `self` as an `f64` (exact).
    fn to_f64(self) -> f64;
    /// The update buffer `W` of this type, of a thread's two.
    fn buffer<'a>(w: &'a mut Vec<f64>, w32: &'a mut Vec<f32>) -> &'a mut Vec<Self>;
}

impl FactorReal for f64 {
    fn of_f64(x: f64) -> Self {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn buffer<'a>(w: &'a mut Vec<f64>, _: &'a mut Vec<f32>) -> &'a mut Vec<Self> {
        w
    }
}

impl FactorReal for f32 {
    fn of_f64(x: f64) -> Self {
        x as f32
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    fn buffer<'a>(_: &'a mut Vec<f64>, w32: &'a mut Vec<f32>) -> &'a mut Vec<Self> {
        w32
    }
}

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

/// The descendants' updates of a supernode that cost this many flops (~0.1 ms)
/// or more are split by columns of `L_s` into chunks of at least this much work
/// (at most [`MAX_CHUNKS`], at least [`CHUNK_MIN_COLUMNS`] columns each), run as
/// parallel tasks: the supernodes at the top of the tree wait for all others
/// and have the most updates (Parisch r = 4: the root, 486 columns, 129 updates,
/// 1.5 ms of a 7.5 ms factorization on one core while the other idled). A chunk
/// applies each descendant's update to its own columns, in the same order of the
/// descendants: the chunks, fixed by the symbolic factor alone, are the same for
/// any number of threads.
const CHUNK_FLOPS: f64 = 4.0e6;
/// See [`CHUNK_FLOPS`].
const MAX_CHUNKS: usize = 8;
/// See [`CHUNK_FLOPS`].
const CHUNK_MIN_COLUMNS: usize = 16;

/// A subtree whose factorization costs less than this many flops runs as one
/// sequential task (spawning costs microseconds; this is ~0.1 ms of work).
const TASK_FLOPS: f64 = 2.0e6;

/// The schedule of the parallel factorization of one symbolic factor: the
/// supernodal elimination tree and, per supernode, the descendants that update it.
#[derive(Debug, Clone)]
pub struct TreeCholesky {
    /// `children[s]`: the supernodes whose parent is `s`, increasing.
    pub(super) children: Vec<Vec<usize>>,
    /// Roots of the forest, increasing.
    pub(super) roots: Vec<usize>,
    /// Flops of the factorization of the subtree of `s` (its own and its
    /// descendants').
    subtree_flops: Vec<f64>,
    /// `updaters[s]`: the descendants `d` whose row pattern meets the columns of
    /// `s`, increasing.
    pub(super) updaters: Vec<Vec<usize>>,
    /// Entries of the factor in the subtree of `s` (the work of its triangular
    /// solves, [`super::tree_solve`]).
    pub(super) subtree_entries: Vec<usize>,
    /// `chunks[s]`: the column bounds (local, from 0 to the width of `s`) of the
    /// chunks of `L_s` whose descendants' updates run as parallel tasks, or empty
    /// (they run in the task of `s`): [`CHUNK_FLOPS`].
    pub(super) chunks: Vec<Vec<usize>>,
}

/// The raw value array shared by the tasks (see the module's **Safety**).
pub(super) struct SharedValues<T> {
    pub(super) ptr: *mut T,
    pub(super) len: usize,
}
impl<T> Clone for SharedValues<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for SharedValues<T> {}
// SAFETY: the tasks write disjoint supernode blocks and read only finished ones
// (module documentation).
unsafe impl<T: Send> Send for SharedValues<T> {}
unsafe impl<T: Sync> Sync for SharedValues<T> {}

impl<T> SharedValues<T> {
    /// `len` values from `offset` on, for reading.
    ///
    /// # Safety
    /// `offset + len` within the array, and no one writes them while the slice
    /// lives.
    pub(super) unsafe fn slice(&self, offset: usize, len: usize) -> &[T] {
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
    pub(super) unsafe fn slice_mut(&self, offset: usize, len: usize) -> &mut [T] {
        assert!(offset + len <= self.len, "a block inside the value array");
        // SAFETY: in bounds (checked); exclusive by the caller's contract
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(offset), len) }
    }
}

/// Per-thread scratch of [`Context::supernode`]: the global-to-local row map
/// (`NONE` outside the supernode being factored), the update buffer `W` (of each
/// precision), and the dense Cholesky's workspace.
#[derive(Default)]
struct Scratch {
    local: Vec<usize>,
    w: Vec<f64>,
    w32: Vec<f32>,
    map: Vec<usize>,
    dense: Option<MemBuffer>,
}

thread_local! {
    /// Taken out while a supernode is factored and put back after: a thread
    /// waiting in a parallel dense kernel may run another task's supernode,
    /// which then finds none and makes its own.
    static SCRATCH: Cell<Option<Box<Scratch>>> = const { Cell::new(None) };
}

thread_local! {
    /// The update buffers of a chunk task ([`CHUNK_FLOPS`]), apart from
    /// [`SCRATCH`], which the task of the supernode holds while its chunks run.
    static CHUNK_SCRATCH: Cell<Option<Box<Scratch>>> = const { Cell::new(None) };
}

const NONE: usize = usize::MAX;

impl TreeCholesky {
    /// The schedule of `symbolic`'s numeric factorization.
    pub fn new(symbolic: &Supernodal) -> Self {
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
        let mut subtree_entries = vec![0usize; n_super];
        let mut update_flops = vec![0.0; n_super];
        for d in 0..n_super {
            let pattern = &rows[row_ptr[d]..row_ptr[d + 1]];
            let c = (end[d] - begin[d]) as f64;
            let m = pattern.len() as f64;
            // chol of the c × c block, the m × c triangular solve, the updates it sends
            own_flops[d] = c * c * c / 3.0 + m * c * c + m * m * c;
            subtree_entries[d] = (end[d] - begin[d]) * (end[d] - begin[d] + pattern.len());
            match pattern.first() {
                Some(&r) => children[super_of[r]].push(d),
                None => roots.push(d),
            }
            let mut last = NONE;
            for (i, &r) in pattern.iter().enumerate() {
                let s = super_of[r];
                if s != last {
                    updaters[s].push(d);
                    last = s;
                }
                // row r of L_d,mid: a column of W with the rows of L_d,low from it on
                update_flops[s] += 2.0 * c * (pattern.len() - i) as f64;
            }
        }
        let chunks = (0..n_super)
            .map(|s| {
                let n_chunks = (update_flops[s] / CHUNK_FLOPS) as usize;
                let ncols = end[s] - begin[s];
                if n_chunks < 2 || ncols < 2 * CHUNK_MIN_COLUMNS {
                    return Vec::new();
                }
                let n_chunks = n_chunks.min(MAX_CHUNKS).min(ncols / CHUNK_MIN_COLUMNS);
                // column j of L_s takes updates on its rows from j down: weight nrows − j
                let nrows = ncols + (row_ptr[s + 1] - row_ptr[s]);
                let total: usize = (0..ncols).map(|j| nrows - j).sum();
                let mut bounds = vec![0];
                let mut acc = 0;
                for j in 0..ncols {
                    acc += nrows - j;
                    if acc * n_chunks >= total * bounds.len() && bounds.len() < n_chunks {
                        bounds.push(j + 1);
                    }
                }
                bounds.push(ncols);
                bounds.dedup();
                bounds
            })
            .collect();
        let mut subtree_flops = own_flops;
        for s in 0..n_super {
            // children have smaller numbers than their parent
            for &c in &children[s] {
                let f = subtree_flops[c];
                subtree_flops[s] += f;
                let e = subtree_entries[c];
                subtree_entries[s] += e;
            }
        }
        Self { children, roots, subtree_flops, updaters, subtree_entries, chunks }
    }

    /// `visit` every supernode of the subtree of `root`, children before parents
    /// (without recursion: chains can be long).
    pub(super) fn each_in_postorder(&self, root: usize, mut visit: impl FnMut(usize)) {
        let mut stack = vec![(root, false)];
        while let Some((t, expanded)) = stack.pop() {
            if expanded {
                visit(t);
            } else {
                stack.push((t, true));
                stack.extend(self.children[t].iter().rev().map(|&c| (c, false)));
            }
        }
    }

    /// Whether the subtree of `s` runs as one sequential task: it is light, or a
    /// leaf.
    fn light(&self, s: usize) -> bool {
        self.subtree_flops[s] < TASK_FLOPS || self.children[s].is_empty()
    }

    /// How many subtrees the schedule hands to separate tasks (the children of
    /// every supernode that is split; 0: the factorization runs as one task).
    pub fn parallel_subtrees(&self) -> usize {
        let split = |s: usize| !self.light(s) && self.children[s].len() > 1;
        let tops = if self.roots.len() > 1 { self.roots.len() } else { 0 };
        tops + (0..self.children.len()).filter(|&s| split(s)).map(|s| self.children[s].len()).sum::<usize>()
    }

    /// Numeric `LLᵀ` of `P A Pᵀ` (`P` the symbolic factor's permutation `perm`,
    /// `None` for the identity) into `l_values`: `a` is read through `perm`, and its
    /// entries that land on or below the diagonal of `P A Pᵀ` are taken (both
    /// triangles of `A` may be stored, or only those entries; row indices within a
    /// column in any order). The values go to
    /// `l_values` (faer's supernodal layout, `symbolic.len_val()` values). `par`
    /// is given to the dense kernels of the wide supernodes at the top of the tree
    /// (see [`DENSE_PARALLEL_COLUMNS`]); the subtrees run on rayon's pool.
    ///
    /// Returns the first column (in the permuted order, smallest over the
    /// supernodes that met one) where a pivot is not positive.
    pub fn factor(
        &self,
        symbolic: &Supernodal,
        a: SparseColMatRef<'_, usize, f64>,
        perm: Option<FillPermutation<'_>>,
        l_values: &mut [f64],
        par: Par,
    ) -> Result<(), LltError> {
        self.factor_scaled(symbolic, a, perm, 1.0, l_values, par)
    }

    /// [`Self::factor`] of `scale · A` into a factor of any [`FactorReal`]
    /// (each entry `scale · a_ij` rounded once).
    pub fn factor_scaled<T: FactorReal>(
        &self,
        symbolic: &Supernodal,
        a: SparseColMatRef<'_, usize, f64>,
        perm: Option<FillPermutation<'_>>,
        scale: f64,
        l_values: &mut [T],
        par: Par,
    ) -> Result<(), LltError> {
        assert_eq!(l_values.len(), symbolic.len_val(), "the value array must match the symbolic factor");
        assert_eq!(a.nrows(), symbolic.nrows(), "the matrix must match the symbolic factor");
        if let Some(p) = &perm {
            assert!(p.forward.len() == a.nrows() && p.inverse.len() == a.nrows(), "the permutation must match the matrix");
        }
        let values = SharedValues { ptr: l_values.as_mut_ptr(), len: l_values.len() };
        let failed = std::sync::Mutex::new(None::<usize>);
        let ctx = Context { tree: self, symbolic, a, perm, scale, values, failed: &failed, par, w_entries: W_ENTRIES.max(l_values.len() / 64) };
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

/// The fill-reducing permutation `P` of a factorization: `forward[j]` the column of
/// `A` that is column `j` of `P A Pᵀ`, `inverse` its inverse.
#[derive(Clone, Copy, Debug)]
pub struct FillPermutation<'a> {
    pub forward: &'a [usize],
    pub inverse: &'a [usize],
}

/// What every task of one factorization shares.
struct Context<'a, T> {
    tree: &'a TreeCholesky,
    symbolic: &'a Supernodal,
    /// `A` (its entries on or below the diagonal of `P A Pᵀ` are read).
    a: SparseColMatRef<'a, usize, f64>,
    perm: Option<FillPermutation<'a>>,
    /// Factor of the matrix's entries (see [`TreeCholesky::factor_scaled`]).
    scale: f64,
    values: SharedValues<T>,
    failed: &'a std::sync::Mutex<Option<usize>>,
    par: Par,
    /// Entries of a thread's update buffer (see [`W_ENTRIES`]).
    w_entries: usize,
}

impl<T: FactorReal> Context<'_, T> {
    /// Factors the subtree of `s`: sequentially if it is light; otherwise down its
    /// chain of only children (a loop, not a recursion: chains can be long) to the
    /// first supernode that is light or has several children, whose children's
    /// subtrees run in parallel; then the chain back up.
    fn subtree(&self, s: usize) {
        let tree = self.tree;
        let mut chain = vec![s];
        let mut bottom = s;
        while !tree.light(bottom) && tree.children[bottom].len() == 1 {
            bottom = tree.children[bottom][0];
            chain.push(bottom);
        }
        if tree.light(bottom) {
            chain.pop();
            tree.each_in_postorder(bottom, |t| self.supernode(t, Par::Seq));
        } else {
            let kids = &tree.children[bottom];
            rayon::scope(|scope| {
                for &c in &kids[1..] {
                    scope.spawn(move |_| self.subtree(c));
                }
                self.subtree(kids[0]);
            });
        }
        let (begin, end) = (self.symbolic.supernode_begin(), self.symbolic.supernode_end());
        for &t in chain.iter().rev() {
            self.supernode(t, if end[t] - begin[t] >= DENSE_PARALLEL_COLUMNS { self.par } else { Par::Seq });
        }
    }

    /// `L_s[rows, cols] -= W` of descendant `d` (step 2 of the module's algorithm)
    /// for the columns `cols` of `L_s` (local, `0..s_ncols` for all): `W = L_d,low
    /// L_d,midᵀ` over the rows of `L_d,mid` that fall in `cols`, by panels. `local`
    /// maps the rows of `s` to its block's rows; `ls_cols` is `L_s` (column-major);
    /// the caller owns its columns `cols`.
    #[allow(clippy::too_many_arguments)]
    fn update(&self, s: usize, d: usize, cols: std::ops::Range<usize>, ls_cols: SharedValues<T>, local: &[usize], buffer: &mut Vec<T>, map: &mut Vec<usize>, par: Par) {
        let sym = self.symbolic;
        let std::ops::Range { start: s0, end: s1 } = sym.columns(s);
        let s_nrows = ls_cols.len / (s1 - s0);
        let d_ncols = sym.columns(d).len();
        let d_pattern = sym.rows_below(d);
        let d_nrows = d_ncols + d_pattern.len();
        let d_block = sym.block(d);
        // SAFETY: `d` is a finished descendant of `s`: read only.
        let ld = unsafe { self.values.slice(d_block.start, d_block.len()) };
        let ld = MatRef::from_column_major_slice(ld, d_nrows, d_ncols);
        let p0 = d_pattern.partition_point(|&r| r < s0);
        let mid = d_pattern[p0..].partition_point(|&r| r < s1);
        // the rows of L_d,mid in the columns `cols` of L_s: [a, b) of mid
        let a = d_pattern[p0..p0 + mid].partition_point(|&r| r < s0 + cols.start);
        let b = d_pattern[p0..p0 + mid].partition_point(|&r| r < s0 + cols.end);
        if a == b {
            return;
        }
        let low = d_pattern.len() - p0;
        let ld_low = ld.subrows(d_ncols + p0, low);
        let ld_mid = ld_low.subrows(0, mid);
        // the rows of W in L_s
        map.clear();
        map.extend(d_pattern[p0..].iter().map(|&r| if r < s1 { r - s0 } else { local[r] }));
        // W = L_low L_midᵀ by panels of the mid columns [j0, j1), each the lower
        // triangle of its top block and the rectangle below (the buffer stays
        // under w_entries however large the update)
        let width = (self.w_entries / low.max(1)).max(32).min(mid.max(1));
        for j0 in (a..b).step_by(width) {
            let j1 = (j0 + width).min(b);
            let (w_cols, w_rows) = (j1 - j0, low - j0);
            if buffer.len() < w_rows * w_cols {
                buffer.resize(w_rows * w_cols, T::of_f64(0.0));
            }
            let mut w = MatMut::from_column_major_slice_mut(&mut buffer[..w_rows * w_cols], w_rows, w_cols);
            let panel = ld_mid.subrows(j0, w_cols);
            let (w_top, w_bot) = w.rb_mut().split_at_row_mut(w_cols);
            triangular::matmul(
                w_top,
                BlockStructure::TriangularLower,
                Accum::Replace,
                panel,
                BlockStructure::Rectangular,
                panel.transpose(),
                BlockStructure::Rectangular,
                T::of_f64(1.0),
                par,
            );
            matmul(w_bot, Accum::Replace, ld_low.subrows(j1, low - j1), panel.transpose(), T::of_f64(1.0), par);
            let w = w.rb();
            let map = &map[j0..];
            let scatter = |jj: usize, dst: &mut [T]| {
                let w_col = w.col(jj).try_as_col_major().expect("W is column-major").as_slice();
                for ii in jj..w_rows {
                    dst[map[ii]] -= w_col[ii];
                }
            };
            // SAFETY: L_s is column-major with s_nrows rows, and the columns
            // d_pattern[p0 + j] − s₀ are distinct for distinct j, all in `cols`,
            // which the caller owns: each call writes its own column
            let column = |jj: usize| unsafe { ls_cols.slice_mut((d_pattern[p0 + j0 + jj] - s0) * s_nrows, s_nrows) };
            if matches!(par, Par::Rayon(_)) && w_rows * w_cols >= PARALLEL_SCATTER {
                (0..w_cols).into_par_iter().for_each(|jj| scatter(jj, column(jj)));
            } else {
                for jj in 0..w_cols {
                    scatter(jj, column(jj));
                }
            }
        }
    }

    /// Steps 1–3 of the module's algorithm for supernode `s`.
    fn supernode(&self, s: usize, par: Par) {
        let sym = self.symbolic;
        let std::ops::Range { start: s0, end: s1 } = sym.columns(s);
        let s_pattern = sym.rows_below(s);
        let s_ncols = s1 - s0;
        let s_nrows = s_ncols + s_pattern.len();
        let s_block = sym.block(s);
        // SAFETY: block `s` is written by this task only; see the module's Safety.
        let ls_slice = unsafe { self.values.slice_mut(s_block.start, s_block.len()) };
        ls_slice.fill(T::of_f64(0.0));
        let mut ls = MatMut::from_column_major_slice_mut(ls_slice, s_nrows, s_ncols);
        let mut scratch = SCRATCH.with(Cell::take).unwrap_or_default();
        {
            let Scratch { local, w, w32, map, .. } = &mut *scratch;
            let buffer = T::buffer(w, w32);
            if local.len() < sym.nrows() {
                local.resize(sym.nrows(), NONE);
            }
            for (i, &r) in s_pattern.iter().enumerate() {
                local[r] = s_ncols + i;
            }
            // 1. the matrix's own entries: column j of P A Pᵀ is column p(j) of A,
            // its row i' at p⁻¹(i')
            for j in s0..s1 {
                let col = j - s0;
                let c = self.perm.as_ref().map_or(j, |p| p.forward[j]);
                for (i, &v) in self.a.row_idx_of_col(c).zip(self.a.val_of_col(c)) {
                    let i = self.perm.as_ref().map_or(i, |p| p.inverse[i]);
                    if i < j {
                        continue;
                    }
                    let row = if i < s1 { i - s0 } else { local[i] };
                    ls[(row, col)] += T::of_f64(self.scale * v);
                }
            }
            // 2. the updates of the descendants: by column chunks of L_s in parallel
            // where they are heavy (`TreeCholesky::chunks`), else here
            let ls_cols = SharedValues { ptr: ls.rb_mut().as_ptr_mut(), len: s_nrows * s_ncols };
            let chunks = &self.tree.chunks[s];
            if chunks.len() > 2 {
                let local: &[usize] = local;
                let run = |k: usize| {
                    let mut mine = CHUNK_SCRATCH.with(Cell::take).unwrap_or_default();
                    let Scratch { w, w32, map, .. } = &mut *mine;
                    let buffer = T::buffer(w, w32);
                    for &d in &self.tree.updaters[s] {
                        self.update(s, d, chunks[k]..chunks[k + 1], ls_cols, local, buffer, map, Par::Seq);
                    }
                    CHUNK_SCRATCH.with(|c| c.set(Some(mine)));
                };
                if rayon::current_num_threads() > 1 {
                    (0..chunks.len() - 1).into_par_iter().for_each(run);
                } else {
                    (0..chunks.len() - 1).for_each(run);
                }
            } else {
                for &d in &self.tree.updaters[s] {
                    self.update(s, d, 0..s_ncols, ls_cols, local, buffer, map, par);
                }
            }
            for &r in s_pattern {
                local[r] = NONE;
            }
        }
        // 3. the dense factorization of the supernode
        let (mut ls_top, ls_bot) = ls.split_at_row_mut(s_ncols);
        let req = cholesky_in_place_scratch::<T>(s_ncols, par, Default::default());
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
        let regularization = LltRegularization::<T>::default();
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
pub(super) mod tests {
    use super::*;
    use crate::solver::bench::{elastic_cube_system, relative_residual};
    use crate::solver::linear::{FaerDirect, FaerDirectOptions, LinearSolver, LinearSolverError, SymmetricStrategy, Symmetry};
    use crate::solver::ordering::nested_dissection;
    use faer::perm::PermRef;
    use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering};
    use faer::sparse::linalg::SupernodalThreshold;
    use faer::sparse::{SymbolicSparseColMat, SymbolicSparseColMatRef};
    use faer::Side;

    /// A symmetric matrix (both triangles stored), its supernodal symbolic factor
    /// (METIS ordering, as `FaerDirect` makes it) and the lower triangle of `P A Pᵀ`.
    pub(in crate::solver::linear) struct Problem {
        pub(in crate::solver::linear) p: SymbolicSparseColMat<usize>,
        pub(in crate::solver::linear) v: Vec<f64>,
        pub(in crate::solver::linear) sym: SymbolicCholesky<usize>,
        /// `sym`'s supernodal structure, copied.
        structure: Supernodal,
        lower: (Vec<usize>, Vec<usize>, Vec<f64>),
        /// Factor faer's permuted lower triangle instead of `A` through `P`.
        from_permuted_copy: bool,
    }

    impl Problem {
        fn new(p: SymbolicSparseColMat<usize>, v: Vec<f64>) -> Self {
            let order = nested_dissection(p.as_ref()).unwrap();
            let n = p.nrows();
            let params = CholeskySymbolicParams { supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL, ..Default::default() };
            let ordering = SymmetricOrdering::Custom(PermRef::new_checked(&order.forward, &order.inverse, n));
            let sym = factorize_symbolic_cholesky(p.as_ref(), Side::Lower, ordering, params).unwrap();
            let nnz = p.row_idx().len();
            let (mut cp, mut ri, mut val) = (vec![0usize; n + 1], vec![0usize; nnz], vec![0.0; nnz]);
            let mut buf = MemBuffer::new(faer::sparse::utils::permute_self_adjoint_scratch::<usize>(n));
            let a = SparseColMatRef::new(p.as_ref(), &v);
            let perm = sym.perm().expect("a fill-reducing permutation");
            faer::sparse::utils::permute_self_adjoint_to_unsorted(&mut val, &mut cp, &mut ri, a, perm, Side::Lower, Side::Lower, MemStack::new(&mut buf));
            let used = cp[n];
            ri.truncate(used);
            val.truncate(used);
            let structure = match sym.raw() {
                SymbolicCholeskyRaw::Supernodal(s) => Supernodal::of_faer(s),
                SymbolicCholeskyRaw::Simplicial(_) => panic!("a supernodal factor"),
            };
            Self { p, v, sym, structure, lower: (cp, ri, val), from_permuted_copy: false }
        }

        pub(in crate::solver::linear) fn supernodal(&self) -> &Supernodal {
            &self.structure
        }

        /// The tree factorization's values, on `threads` rayon threads.
        fn tree_factor(&self, threads: usize, par: Par) -> Result<Vec<f64>, LltError> {
            self.tree_factor_scaled(threads, par, 1.0)
        }

        /// The tree factorization of `scale · A` in any precision, on `threads`
        /// rayon threads.
        pub(in crate::solver::linear) fn tree_factor_scaled<T: FactorReal>(&self, threads: usize, par: Par, scale: f64) -> Result<Vec<T>, LltError> {
            let s = self.supernodal();
            let mut l = vec![T::of_f64(0.0); s.len_val()];
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool");
            let tree = TreeCholesky::new(s);
            if self.from_permuted_copy {
                // the lower triangle of P A Pᵀ made by faer, identity permutation
                let (cp, ri, val) = &self.lower;
                let n = self.p.nrows();
                let a_lower = SparseColMatRef::new(SymbolicSparseColMatRef::new_unsorted_checked(n, n, cp, None, ri), val);
                pool.install(|| tree.factor_scaled(s, a_lower, None, scale, &mut l, par))?;
            } else {
                let a = SparseColMatRef::new(self.p.as_ref(), &self.v);
                let (forward, inverse) = self.sym.perm().expect("a fill-reducing permutation").arrays();
                pool.install(|| tree.factor_scaled(s, a, Some(FillPermutation { forward, inverse }), scale, &mut l, par))?;
            }
            Ok(l)
        }

        /// faer's own numeric factorization's values.
        fn faer_factor(&self) -> Result<Vec<f64>, LltError> {
            let mut l = vec![0.0; self.sym.len_val()];
            let mut buf = MemBuffer::new(self.sym.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()));
            let regularization = LltRegularization { dynamic_regularization_delta: 0.0, dynamic_regularization_epsilon: 0.0 };
            let a = SparseColMatRef::new(self.p.as_ref(), &self.v);
            self.sym.factorize_numeric_llt(&mut l, a, Side::Lower, regularization, Par::Seq, MemStack::new(&mut buf), Default::default())?;
            Ok(l)
        }
    }

    pub(in crate::solver::linear) fn cube(n: usize) -> Problem {
        let cube = elastic_cube_system(n).unwrap();
        Problem::new(cube.pattern.symbolic_owned().clone(), cube.assembly.values().to_vec())
    }

    fn solve(options: FaerDirectOptions, p: &SymbolicSparseColMat<usize>, v: &[f64], b: &[f64]) -> Result<Vec<f64>, LinearSolverError> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("a thread pool");
        pool.install(|| {
            let mut s = FaerDirect::new(options);
            s.analyse(p.as_ref(), Symmetry::Symmetric)?;
            s.factor(v)?;
            let mut x = b.to_vec();
            s.solve_in_place(&v, &mut x)?;
            Ok(x)
        })
    }

    #[test]
    fn the_tree_factor_is_faers_own_to_round_off() {
        let pb = cube(10);
        // the schedule really splits this factor into parallel subtrees
        let schedule = TreeCholesky::new(pb.supernodal());
        assert!(schedule.parallel_subtrees() >= 4, "{} parallel subtrees", schedule.parallel_subtrees());
        // the same factor entry by entry (bit for bit with sequential dense kernels,
        // `faer_direct::tests`); two threads in the wide supernodes' kernels may
        // split their sums differently: round-off, and the cube's condition number
        // is ~1e4, so 1e-16 · 1e4 with room
        let faer_l = pb.faer_factor().unwrap();
        let tree_l = pb.tree_factor(2, Par::rayon(2)).unwrap();
        let scale = faer_l.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let d = tree_l.iter().zip(&faer_l).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(d <= 1e-11 * scale, "factors differ by {:e} of the largest entry", d / scale);
        // and FaerDirect, which uses it by default, solves with it
        let b: Vec<f64> = (0..pb.p.nrows()).map(|i| ((i % 13) as f64 - 6.0) / 6.0).collect();
        let x = solve(FaerDirectOptions::default(), &pb.p, &pb.v, &b).unwrap();
        let r = relative_residual(pb.p.col_ptr(), pb.p.row_idx(), &pb.v, &x, &b);
        assert!(r < 1e-12, "residual {r:e}");
    }

    /// Read from `A` through `P` (both triangles stored, the entries on or below
    /// the diagonal of `P A Pᵀ` taken), the factor is the one of faer's permuted
    /// lower triangle bit for bit: the elastic cube's matrix is symmetric bit for
    /// bit, so the entries taken from A's upper triangle equal the lower ones.
    #[test]
    fn the_factor_read_through_the_permutation_is_that_of_the_permuted_copy() {
        let mut pb = cube(8);
        let through = pb.tree_factor(2, Par::Seq).unwrap();
        pb.from_permuted_copy = true;
        let copy = pb.tree_factor(2, Par::Seq).unwrap();
        assert!(through == copy, "the two factors differ");
    }

    #[test]
    fn the_tree_factor_is_the_same_for_any_number_of_threads() {
        let pb = cube(10);
        // the top supernodes' updates split into column chunks run in parallel too
        let schedule = TreeCholesky::new(pb.supernodal());
        let chunked: Vec<_> = schedule.chunks.iter().filter(|c| c.len() > 2).collect();
        assert!(!chunked.is_empty(), "no supernode's updates are chunked");
        // the dense kernels sequential: only the tree runs in parallel
        let bits = |l: Vec<f64>| l.into_iter().map(f64::to_bits).collect::<Vec<_>>();
        let one = bits(pb.tree_factor(1, Par::Seq).unwrap());
        for threads in [2, 3] {
            assert_eq!(one, bits(pb.tree_factor(threads, Par::Seq).unwrap()), "{threads} threads");
        }
        // and in single precision, of the matrix scaled by a power of two
        let single = |threads: usize| -> Vec<u32> {
            let l: Vec<f32> = pb.tree_factor_scaled(threads, Par::Seq, 0.25).unwrap();
            l.into_iter().map(f32::to_bits).collect()
        };
        let one = single(1);
        for threads in [2, 3] {
            assert_eq!(one, single(threads), "{threads} threads, single precision");
        }
    }

    #[test]
    fn a_non_positive_pivot_is_reported_where_faer_reports_it() {
        let mut pb = cube(8);
        // an indefinite matrix: one diagonal entry in the middle of the cube negated
        let j = pb.p.ncols() / 2;
        let k = (pb.p.col_ptr()[j]..pb.p.col_ptr()[j + 1]).find(|&k| pb.p.row_idx()[k] == j).unwrap();
        pb.v[k] = -pb.v[k];
        let pb = Problem::new(pb.p, pb.v);
        let index = |r: Result<Vec<f64>, LltError>| match r {
            Err(LltError::NonPositivePivot { index }) => index,
            Ok(_) => panic!("expected a non-positive pivot"),
        };
        let faer_index = index(pb.faer_factor());
        assert_eq!(index(pb.tree_factor(2, Par::rayon(2))), faer_index);
        assert_eq!(index(pb.tree_factor(1, Par::Seq)), faer_index);
        // FaerDirect reports it with its dof under `Llt`, and its default strategy
        // goes on to LDLᵀ, which solves it
        let b: Vec<f64> = (0..pb.p.nrows()).map(|i| ((i % 13) as f64 - 6.0) / 6.0).collect();
        let llt_only = FaerDirectOptions { symmetric: SymmetricStrategy::Llt, ..Default::default() };
        let dof = pb.sym.perm().unwrap().arrays().0[faer_index];
        assert!(matches!(solve(llt_only, &pb.p, &pb.v, &b), Err(LinearSolverError::NotPositiveDefinite { dof: d }) if d == dof));
        let x = solve(FaerDirectOptions::default(), &pb.p, &pb.v, &b).unwrap();
        let r = relative_residual(pb.p.col_ptr(), pb.p.row_idx(), &pb.v, &x, &b);
        assert!(r < 1e-10, "residual {r:e}");
    }
}
