//! The triangular solves of a supernodal `LLᵀ` factor, parallel over the
//! elimination tree.
//!
//! A Krylov solve preconditioned by a factor applies it once per iteration, and at
//! ten thousand unknowns and more those applications are a large part of a Newton
//! iteration (the frictional crossed beams at 26k dofs: 44 % of the run). faer's
//! supernodal solve walks the supernodes one after another; on two cores the other
//! one idled. As in the factorization ([`super::tree_cholesky`]), two supernodes of
//! which neither is an ancestor of the other never touch each other's entries of
//! the solution, so the subtrees are solved in parallel.
//!
//! With `P A Pᵀ = L Lᵀ` and `x` already permuted, for supernode `s` with columns
//! `[s₀, s₁)`, `L_s = [L_s,top; L_s,bot]`, row pattern `R_s` of `L_s,bot`:
//! - **forward**, `L y = b`, children before parents: `y_s ← y_s − Σ_d w_d[rows
//!   in [s₀, s₁)]` over the descendants `d` whose pattern meets `s` (increasing),
//!   `y_s ← L_s,top⁻¹ y_s`, and `w_s = L_s,bot y_s` kept for the ancestors. Each
//!   supernode's block is read once, whole, by its own task (faer's right-looking
//!   solve reads it so too, but scatters `w_s` into the ancestors' rows at once,
//!   which parallel tasks would share; gathering `L_d`'s rows piece by piece in
//!   each ancestor instead measured 2.3 times slower than the backward solve); every
//!   task writes only its own rows of `x` and its own `w_s`;
//! - **backward**, `Lᵀ x = y`, parents before children: `x_s ← L_s,top⁻ᵀ (y_s −
//!   L_s,botᵀ x[R_s])`, where `x[R_s]` belongs to ancestors, finished before.
//!
//! **Determinism.** Each supernode's operations and their order are fixed by the
//! symbolic factor alone (the dense kernels run sequentially): the solution is the
//! same bit for bit at any number of threads.

use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::{solve_lower_triangular_in_place, solve_upper_triangular_in_place};
use super::supernodal::Supernodal;
use faer::{Accum, ColMut, ColRef, MatRef, Par};

use super::tree_cholesky::{FactorReal, SharedValues, TreeCholesky};

/// A subtree whose factor holds fewer entries than this is solved as one
/// sequential task (about 10 µs of work; spawning costs microseconds).
const TASK_ENTRIES: usize = 1 << 15;

impl TreeCholesky {
    /// Solve `L Lᵀ x = b` in place (`x = b` on entry), in the symbolic factor's
    /// permuted order; `l_values` is the factor of [`TreeCholesky::factor`] (or
    /// any factor in faer's supernodal layout of `symbolic`); `work` holds the
    /// supernodes' updates `w_s` (resized here; keep it between solves). The
    /// subtrees run on rayon's pool.
    pub fn solve_in_place<T: FactorReal>(&self, symbolic: &Supernodal, l_values: &[T], x: &mut [T], work: &mut Vec<T>) {
        assert_eq!(l_values.len(), symbolic.len_val(), "the value array must match the symbolic factor");
        assert_eq!(x.len(), symbolic.nrows(), "the right-hand side must match the symbolic factor");
        // every entry is written (by its supernode's forward step) before it is read
        work.resize(symbolic.row_idx().len(), T::of_f64(0.0));
        let ctx = Solve {
            tree: self,
            symbolic,
            l: l_values,
            x: SharedValues { ptr: x.as_mut_ptr(), len: x.len() },
            w: SharedValues { ptr: work.as_mut_ptr(), len: work.len() },
        };
        if rayon::current_num_threads() <= 1 {
            let mut buffer = Vec::new();
            // children have smaller numbers than their parents
            for s in 0..symbolic.n_supernodes() {
                ctx.forward(s);
            }
            for s in (0..symbolic.n_supernodes()).rev() {
                ctx.backward(s, &mut buffer);
            }
            return;
        }
        let ctx = &ctx;
        rayon::scope(|scope| {
            for &r in &self.roots {
                scope.spawn(move |_| ctx.forward_subtree(r));
            }
        });
        rayon::scope(|scope| {
            for &r in &self.roots {
                scope.spawn(move |_| ctx.backward_subtree(r));
            }
        });
    }

    /// Whether the subtree of `s` is solved as one sequential task.
    fn light_solve(&self, s: usize) -> bool {
        self.subtree_entries[s] < TASK_ENTRIES || self.children[s].is_empty()
    }
}

/// What the tasks of one solve share.
struct Solve<'a, T> {
    tree: &'a TreeCholesky,
    symbolic: &'a Supernodal,
    l: &'a [T],
    /// The solution, written supernode by supernode (see the module's
    /// Determinism; a task writes only the rows of the supernode it solves).
    x: SharedValues<T>,
    /// `w_s = L_s,bot y_s` of every supernode, at the offsets of its row pattern
    /// (written by the forward step of `s`, read by its ancestors').
    w: SharedValues<T>,
}

impl<T: FactorReal> Solve<'_, T> {
    /// Supernode `s`'s block of the factor: `(L_s, columns, row pattern of L_s,bot)`.
    fn block(&self, s: usize) -> (MatRef<'_, T>, usize, &[usize]) {
        let sym = self.symbolic;
        let (begin, end) = (sym.supernode_begin(), sym.supernode_end());
        let (row_ptr, val_ptr) = (sym.col_ptr_for_row_idx(), sym.col_ptr_for_val());
        let pattern = &sym.row_idx()[row_ptr[s]..row_ptr[s + 1]];
        let ncols = end[s] - begin[s];
        let l = MatRef::from_column_major_slice(&self.l[val_ptr[s]..val_ptr[s + 1]], ncols + pattern.len(), ncols);
        (l, ncols, pattern)
    }

    /// The forward step of supernode `s` (module documentation).
    fn forward(&self, s: usize) {
        let sym = self.symbolic;
        let (begin, row_ptr) = (sym.supernode_begin(), sym.col_ptr_for_row_idx());
        let s0 = begin[s];
        let (ls, ncols, pattern) = self.block(s);
        let s1 = s0 + ncols;
        // SAFETY: the rows of `s` are written by this task only
        let ys = unsafe { self.x.slice_mut(s0, ncols) };
        for &d in &self.tree.updaters[s] {
            let d_pattern = &sym.row_idx()[row_ptr[d]..row_ptr[d + 1]];
            let p0 = d_pattern.partition_point(|&r| r < s0);
            let mid = d_pattern[p0..].partition_point(|&r| r < s1);
            // SAFETY: `w_d` of a descendant, finished before this task started: read only
            let wd = unsafe { self.w.slice(row_ptr[d] + p0, mid) };
            for (&r, &v) in d_pattern[p0..p0 + mid].iter().zip(wd) {
                ys[r - s0] -= v;
            }
        }
        solve_lower_triangular_in_place(ls.subrows(0, ncols), ColMut::from_slice_mut(&mut *ys).as_mat_mut(), Par::Seq);
        if !pattern.is_empty() {
            // SAFETY: `w_s` is written by this task only, before any ancestor reads it
            let ws = unsafe { self.w.slice_mut(row_ptr[s], pattern.len()) };
            matmul(ColMut::from_slice_mut(ws).as_mat_mut(), Accum::Replace, ls.subrows(ncols, pattern.len()), ColRef::from_slice(ys).as_mat(), T::of_f64(1.0), Par::Seq);
        }
    }

    /// The backward step of supernode `s` (module documentation).
    fn backward(&self, s: usize, buffer: &mut Vec<T>) {
        let s0 = self.symbolic.supernode_begin()[s];
        let (ls, ncols, pattern) = self.block(s);
        // SAFETY: the rows of `s` are written by this task only
        let xs = unsafe { self.x.slice_mut(s0, ncols) };
        if !pattern.is_empty() {
            buffer.clear();
            // SAFETY: the rows of R_s belong to ancestors, finished and read only
            buffer.extend(pattern.iter().map(|&r| unsafe { self.x.slice(r, 1)[0] }));
            let g = ColRef::from_slice(&buffer[..]);
            matmul(ColMut::from_slice_mut(&mut *xs).as_mat_mut(), Accum::Add, ls.subrows(ncols, pattern.len()).transpose(), g.as_mat(), T::of_f64(-1.0), Par::Seq);
        }
        solve_upper_triangular_in_place(ls.subrows(0, ncols).transpose(), ColMut::from_slice_mut(xs).as_mat_mut(), Par::Seq);
    }

    /// The forward steps of the subtree of `s`: sequentially if it is light;
    /// otherwise down its chain of only children to the first supernode that is
    /// light or has several, whose children's subtrees run in parallel, then the
    /// chain back up.
    fn forward_subtree(&self, s: usize) {
        let tree = self.tree;
        let mut chain = Vec::new();
        let mut t = s;
        while !tree.light_solve(t) && tree.children[t].len() == 1 {
            chain.push(t);
            t = tree.children[t][0];
        }
        if tree.light_solve(t) {
            tree.each_in_postorder(t, |u| self.forward(u));
        } else {
            let kids = &tree.children[t];
            rayon::scope(|scope| {
                for &c in &kids[1..] {
                    scope.spawn(move |_| self.forward_subtree(c));
                }
                self.forward_subtree(kids[0]);
            });
            self.forward(t);
        }
        for &u in chain.iter().rev() {
            self.forward(u);
        }
    }

    /// The backward steps of the subtree of `s`: down its chain of only children,
    /// then the children's subtrees in parallel (a light subtree sequentially,
    /// parents before children).
    fn backward_subtree(&self, s: usize) {
        let tree = self.tree;
        let mut buffer = Vec::new();
        let mut t = s;
        loop {
            if tree.light_solve(t) {
                let mut stack = vec![t];
                while let Some(u) = stack.pop() {
                    self.backward(u, &mut buffer);
                    stack.extend(tree.children[u].iter().copied());
                }
                return;
            }
            self.backward(t, &mut buffer);
            let kids = &tree.children[t];
            if kids.len() == 1 {
                t = kids[0];
                continue;
            }
            rayon::scope(|scope| {
                for &c in &kids[1..] {
                    scope.spawn(move |_| self.backward_subtree(c));
                }
                self.backward_subtree(kids[0]);
            });
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::bench::relative_residual;
    use crate::solver::linear::tree_cholesky::tests::{cube, Problem};
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::cholesky::LltRef;
    use faer::{Conj, MatMut};

    /// `b` permuted into the factor's order, solved by the tree on `threads`
    /// threads with the tree factor of `scale · A` in `T`, and permuted back
    /// (`(scale A)⁻¹ b`).
    fn tree_solve<T: FactorReal>(pb: &Problem, threads: usize, scale: f64, b: &[f64]) -> Vec<T> {
        let l: Vec<T> = pb.tree_factor_scaled(1, Par::Seq, scale).unwrap();
        let fwd = pb.sym.perm().unwrap().arrays().0;
        let mut z: Vec<T> = fwd.iter().map(|&i| T::of_f64(b[i])).collect();
        let s = pb.supernodal();
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool");
        pool.install(|| TreeCholesky::new(s).solve_in_place(s, &l, &mut z, &mut Vec::new()));
        let mut x = vec![T::of_f64(0.0); b.len()];
        fwd.iter().zip(&z).for_each(|(&i, &v)| x[i] = v);
        x
    }

    /// faer's own solve with the same factor.
    fn faer_solve<T: FactorReal>(pb: &Problem, scale: f64, b: &[f64]) -> Vec<T> {
        let l: Vec<T> = pb.tree_factor_scaled(1, Par::Seq, scale).unwrap();
        let mut x: Vec<T> = b.iter().map(|&v| T::of_f64(v)).collect();
        let n = x.len();
        let mut buf = MemBuffer::new(pb.sym.solve_in_place_scratch::<T>(1, Par::Seq));
        LltRef::new(&pb.sym, &l).solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(&mut x, n, 1), Par::Seq, MemStack::new(&mut buf));
        x
    }

    fn rhs(n: usize) -> Vec<f64> {
        (0..n).map(|i| ((i % 13) as f64 - 6.0) / 6.0).collect()
    }

    #[test]
    fn the_tree_solve_is_faers_own_to_round_off() {
        let pb = cube(10);
        let b = rhs(pb.p.nrows());
        let x: Vec<f64> = tree_solve(&pb, 2, 1.0, &b);
        // the same solution as faer's solve with the same factor, to the round-off
        // of two summation orders (the cube's condition number is ~1e4: 1e-16 · 1e4
        // with room); a missed or doubled update is an error of order one
        let y: Vec<f64> = faer_solve(&pb, 1.0, &b);
        let size = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let d = x.iter().zip(&y).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(d <= 1e-11 * size, "solutions differ by {:e} of the largest entry", d / size);
        let r = relative_residual(pb.p.col_ptr(), pb.p.row_idx(), &pb.v, &x, &b);
        assert!(r < 1e-12, "residual {r:e}");
        // single precision, of A scaled by a power of two: faer's f32 solve with the
        // same factor to f32's round-off times the condition number (6e-8 · 1e4)
        let x: Vec<f32> = tree_solve(&pb, 2, 0.25, &b);
        let y: Vec<f32> = faer_solve(&pb, 0.25, &b);
        let size = y.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        let d = x.iter().zip(&y).fold(0.0f32, |m, (a, b)| m.max((a - b).abs()));
        assert!(d <= 1e-3 * size, "single-precision solutions differ by {:e} of the largest entry", d / size);
    }

    #[test]
    fn the_tree_solve_is_the_same_for_any_number_of_threads() {
        let pb = cube(10);
        // the schedule really splits this factor's solve into parallel subtrees
        let tree = TreeCholesky::new(pb.supernodal());
        let split = (0..tree.children.len()).filter(|&s| !tree.light_solve(s) && tree.children[s].len() > 1).count();
        assert!(split >= 3, "{split} supernodes split");
        let b = rhs(pb.p.nrows());
        let bits = |x: Vec<f64>| x.into_iter().map(f64::to_bits).collect::<Vec<_>>();
        let one = bits(tree_solve(&pb, 1, 1.0, &b));
        for threads in [2, 3] {
            assert_eq!(one, bits(tree_solve(&pb, threads, 1.0, &b)), "{threads} threads");
        }
        let single = |threads: usize| -> Vec<u32> { tree_solve::<f32>(&pb, threads, 0.25, &b).into_iter().map(f32::to_bits).collect() };
        let one = single(1);
        for threads in [2, 3] {
            assert_eq!(one, single(threads), "{threads} threads, single precision");
        }
    }

    /// One solve through the 18³ elastic cube's single-precision factor, by the
    /// tree on 1 and 2 threads and by faer's sequential solve (means of 20; docs/performance.md):
    /// `cargo test --release --lib bench_tree_solve -- --ignored --nocapture`.
    #[test]
    #[ignore = "a benchmark: prints times"]
    fn bench_tree_solve() {
        let pb = cube(18);
        let l: Vec<f32> = pb.tree_factor_scaled(2, Par::Seq, 0.25).unwrap();
        let s = pb.supernodal();
        let tree = TreeCholesky::new(s);
        let n = pb.p.nrows();
        eprintln!("{n} unknowns, {} factor entries", l.len());
        let mean_ms = |f: &mut dyn FnMut()| {
            f();
            let t = std::time::Instant::now();
            for _ in 0..20 {
                f();
            }
            t.elapsed().as_secs_f64() * 1e3 / 20.0
        };
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool");
            let (mut z, mut w) = (vec![1.0f32; n], Vec::new());
            let ms = pool.install(|| mean_ms(&mut || tree.solve_in_place(s, &l, &mut z, &mut w)));
            eprintln!("tree solve, {threads} threads: {ms:.3} ms");
        }
        let mut x = vec![1.0f32; n];
        let mut buf = MemBuffer::new(pb.sym.solve_in_place_scratch::<f32>(1, Par::Seq));
        let ms = mean_ms(&mut || {
            LltRef::new(&pb.sym, &l).solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(&mut x, n, 1), Par::Seq, MemStack::new(&mut buf));
        });
        eprintln!("faer's solve: {ms:.3} ms");
    }
}
