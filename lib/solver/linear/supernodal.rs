//! The supernodal structure of a Cholesky factor, computed on the supervariable
//! (node) graph.
//!
//! The numeric factorization ([`super::tree_cholesky`]) and its solves
//! ([`super::tree_solve`]) read a supernodal structure: the supernodes (runs of
//! consecutive columns of `L` that share their rows below), each one's row pattern
//! below its own columns, and the offsets of its dense block in the value array.
//! faer computes it on the unknowns' pattern (`factorize_symbolic_cholesky`:
//! elimination tree, column counts, fundamental supernodes, their relaxation, the
//! row patterns). A mesh's unknowns come in supervariables, the free dofs of a node,
//! whose columns have identical rows: every step of that computation is the same
//! for the dofs of one supervariable, so [`Supernodal::of_supervariables`] does it
//! once per supervariable, on a graph a ninth of the size, each supervariable
//! weighted by its dofs, and expands the result. It follows faer's rules step by
//! step (the same fundamental supernodes, the same relaxation, [`RELAX`]): the
//! structure is faer's, entry for entry (tested below), so the factors and every
//! result are the same, bit for bit, as with faer's analysis. Parisch r = 4
//! (3,238 unknowns): 0.3 ms against faer's 3.3 ms (docs/performance.md).
//!
//! The algorithm, on the supervariables in elimination order `k = 0..m` (weights
//! `w_k`, the neighbours of `k` in the graph `adj(k)`):
//! 1. the elimination tree (Liu's algorithm with path compression): `parent(i)`;
//! 2. `deg(j)`, the dofs of `L`'s column `j` below the supervariable itself: for
//!    every `k` and every `i ∈ adj(k)` with `i < k`, the path from `i` up the tree to
//!    `k` (the row subtree of row `k`) gets `w_k` once per column on it;
//! 3. fundamental supernodes: `k − 1` and `k` in one when `k` is the parent of
//!    `k − 1` and of no other, and `deg(k − 1) = w_k + deg(k)` (faer's rule on the
//!    dofs, `count(j − 1) = count(j) + 1`, across the two supervariables; within a
//!    supervariable it always holds);
//! 4. faer's relaxation: a supernode absorbs the child just before it while the
//!    explicit zeros that adds stay under [`RELAX`]'s share of its entries;
//! 5. each supernode's rows: row `k` belongs to the supernodes on the paths up the
//!    supernodal tree from the supernodes of `adj(k) ∩ [0, k)` to that of `k`
//!    (faer's `ereach_super`), in increasing `k`: sorted.

use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;

use crate::solver::ordering::SupervariableGraph;

/// faer 0.24's supernode relaxation (its `DEFAULT_RELAX`): a merged supernode of
/// at most `.0` columns may hold up to the share `.1` of explicit zeros.
pub const RELAX: &[(usize, f64)] = &[(4, 1.0), (16, 0.8), (48, 0.1), (usize::MAX, 0.05)];

const NONE: usize = usize::MAX;

/// The supernodal structure of a Cholesky factor in faer's layout: supernode `s`
/// has the columns `begin[s]..begin[s + 1]`, the rows below them
/// `rows[row_ptr[s]..row_ptr[s + 1]]` (sorted), and its dense column-major block of
/// (columns + rows below) × columns at `val_ptr[s]` in the value array.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Supernodal {
    n: usize,
    begin: Vec<usize>,
    row_ptr: Vec<usize>,
    val_ptr: Vec<usize>,
    rows: Vec<usize>,
}

impl Supernodal {
    pub fn n_supernodes(&self) -> usize {
        self.begin.len() - 1
    }

    /// The order of the factor.
    pub fn nrows(&self) -> usize {
        self.n
    }

    /// The first column of each supernode.
    pub fn supernode_begin(&self) -> &[usize] {
        &self.begin[..self.n_supernodes()]
    }

    /// One past the last column of each supernode.
    pub fn supernode_end(&self) -> &[usize] {
        &self.begin[1..]
    }

    /// `row_idx()[p[s]..p[s + 1]]`: the rows of supernode `s` below its columns.
    pub fn col_ptr_for_row_idx(&self) -> &[usize] {
        &self.row_ptr
    }

    /// Offsets of the supernodes' blocks in the value array.
    pub fn col_ptr_for_val(&self) -> &[usize] {
        &self.val_ptr
    }

    pub fn row_idx(&self) -> &[usize] {
        &self.rows
    }

    /// The columns of supernode `s`.
    pub fn columns(&self, s: usize) -> std::ops::Range<usize> {
        self.begin[s]..self.begin[s + 1]
    }

    /// The rows of supernode `s` below its columns, sorted.
    pub fn rows_below(&self, s: usize) -> &[usize] {
        &self.rows[self.row_ptr[s]..self.row_ptr[s + 1]]
    }

    /// Where supernode `s`'s block lies in the value array.
    pub fn block(&self, s: usize) -> std::ops::Range<usize> {
        self.val_ptr[s]..self.val_ptr[s + 1]
    }

    /// Entries of the value array.
    pub fn len_val(&self) -> usize {
        self.val_ptr.last().copied().unwrap_or(0)
    }

    /// Columns of the widest supernode.
    pub fn widest(&self) -> usize {
        self.begin.windows(2).map(|b| b[1] - b[0]).max().unwrap_or(0)
    }

    /// faer's supernodal structure, copied.
    pub fn of_faer(s: &SymbolicSupernodalCholesky<usize>) -> Self {
        let mut begin = s.supernode_begin().to_vec();
        begin.push(s.supernode_end().last().copied().unwrap_or(0));
        Self { n: s.nrows(), begin, row_ptr: s.col_ptr_for_row_idx().to_vec(), val_ptr: s.col_ptr_for_val().to_vec(), rows: s.row_idx().to_vec() }
    }

    /// The structure of the factor of `P A Pᵀ`, `A` the pattern of `graph` and `P`
    /// the expansion of the supervariable order `order` (`order[k]` the `k`-th
    /// supervariable eliminated; [`SupervariableGraph::expand`]): faer's, computed
    /// on the supervariables (module documentation).
    pub fn of_supervariables(graph: &SupervariableGraph, order: &[usize]) -> Self {
        let m = graph.n_vertices();
        assert_eq!(order.len(), m, "one position per supervariable");
        let w: Vec<usize> = order.iter().map(|&v| graph.start[v + 1] - graph.start[v]).collect();
        let mut inv = vec![NONE; m];
        for (k, &v) in order.iter().enumerate() {
            inv[v] = k;
        }
        // the neighbours of k eliminated before it, in the elimination order
        let earlier = |k: usize| graph.neighbours(order[k]).iter().map(|&t| inv[t as usize]).filter(move |&i| i < k);

        // 1. elimination tree
        let mut parent = vec![NONE; m];
        let mut ancestor = vec![NONE; m];
        for k in 0..m {
            for mut i in earlier(k) {
                while i != NONE && i < k {
                    let next = ancestor[i];
                    ancestor[i] = k;
                    if next == NONE {
                        parent[i] = k;
                    }
                    i = next;
                }
            }
        }
        // 2. dofs below each column, by the row subtrees
        let mut deg = vec![0usize; m];
        let mut mark = vec![NONE; m];
        for k in 0..m {
            mark[k] = k;
            for mut j in earlier(k) {
                while mark[j] != k {
                    deg[j] += w[k];
                    mark[j] = k;
                    j = parent[j];
                }
            }
        }
        let mut n_children = vec![0usize; m];
        for &p in &parent {
            if p != NONE {
                n_children[p] += 1;
            }
        }
        // 3. fundamental supernodes: first[f]..first[f + 1] of the supervariables
        let mut first = Vec::with_capacity(m / 2 + 1);
        for k in 0..m {
            let joins = k > 0 && parent[k - 1] == k && n_children[k] == 1 && deg[k - 1] == w[k] + deg[k];
            if !joins {
                first.push(k);
            }
        }
        first.push(m);
        let nf = first.len() - 1;
        let mut fund_of = vec![0usize; m];
        for f in 0..nf {
            fund_of[first[f]..first[f + 1]].fill(f);
        }
        let mut size: Vec<usize> = (0..nf).map(|f| w[first[f]..first[f + 1]].iter().sum()).collect();
        let degree: Vec<usize> = (0..nf).map(|f| deg[first[f + 1] - 1]).collect();
        let fund_parent: Vec<usize> = (0..nf).map(|f| parent[first[f + 1] - 1]).map(|p| if p == NONE { NONE } else { fund_of[p] }).collect();

        // 4. relaxation, as faer's (`ghost_factorize_supernodal_symbolic`)
        relax(&mut size, &degree, &fund_parent);

        // the relaxed supernodes: the fundamental ones left with columns, each with
        // the merged ones before it
        let mut pos = vec![0usize; m + 1];
        for k in 0..m {
            pos[k + 1] = pos[k] + w[k];
        }
        let mut begin = vec![0usize];
        let mut super_degree = Vec::new();
        let mut super_of = vec![0usize; m];
        let mut next_sv = 0;
        for f in 0..nf {
            if size[f] == 0 {
                continue;
            }
            let s = begin.len() - 1;
            let end = begin[s] + size[f];
            while next_sv < m && pos[next_sv] < end {
                super_of[next_sv] = s;
                next_sv += 1;
            }
            begin.push(end);
            super_degree.push(degree[f]);
        }
        let n_super = begin.len() - 1;
        let super_parent: Vec<usize> = (0..n_super)
            .map(|s| {
                let last = super_of.partition_point(|&t| t <= s) - 1;
                let p = parent[last];
                if p == NONE {
                    NONE
                } else {
                    super_of[p]
                }
            })
            .collect();

        // 5. the rows of each supernode
        let mut row_ptr = vec![0usize; n_super + 1];
        let mut val_ptr = vec![0usize; n_super + 1];
        for s in 0..n_super {
            let ncols = begin[s + 1] - begin[s];
            row_ptr[s + 1] = row_ptr[s] + super_degree[s];
            val_ptr[s + 1] = val_ptr[s] + (ncols + super_degree[s]) * ncols;
        }
        let mut rows = vec![0usize; row_ptr[n_super]];
        let mut cursor = row_ptr[..n_super].to_vec();
        let mut visited = vec![NONE; n_super];
        for k in 0..m {
            visited[super_of[k]] = k;
            for i in earlier(k) {
                let mut s = super_of[i];
                while visited[s] != k {
                    for d in pos[k]..pos[k + 1] {
                        rows[cursor[s]] = d;
                        cursor[s] += 1;
                    }
                    visited[s] = k;
                    s = super_parent[s];
                }
            }
        }
        debug_assert!(cursor == row_ptr[1..], "each supernode's rows fill its degree");
        Self { n: pos[m], begin, row_ptr, val_ptr, rows }
    }
}

/// faer's relaxation of the fundamental supernodes (sizes in columns, `degree`:
/// rows below the last column, `parent` in the supernodal tree): each supernode,
/// in increasing order, absorbs the child just before it when the explicit zeros
/// of the merged block stay within [`RELAX`]; an absorbed supernode's size moves
/// to the one that absorbed it and becomes 0.
fn relax(size: &mut [usize], degree: &[usize], parent: &[usize]) {
    let nf = size.len();
    // children lists, as faer links them (the latest child first)
    let mut head = vec![NONE; nf];
    let mut next = vec![NONE; nf];
    for s in 0..nf {
        if parent[s] != NONE {
            next[s] = head[parent[s]];
            head[parent[s]] = s;
        }
    }
    let mut zeros = vec![0usize; nf];
    let mut merged_into = vec![NONE; nf];
    let mut last_merged = vec![NONE; nf];
    for p in 0..nf {
        loop {
            let (mut merging, mut new_zeros, mut merged_zeros, mut largest) = (NONE, 0usize, 0usize, 0usize);
            let mut c = head[p];
            while c != NONE {
                let candidate = c;
                c = next[c];
                if candidate + 1 != p || merged_into[candidate] != NONE || size[candidate] < largest {
                    continue;
                }
                let (p_size, c_size) = (size[p], size[candidate]);
                let (p_zeros, c_zeros) = (zeros[p], zeros[candidate]);
                let added = (p_size + degree[p] - degree[candidate]) * c_size;
                let status = if added == 0 {
                    p_zeros + c_zeros
                } else {
                    let total = added + c_zeros + p_zeros;
                    let combined = c_size + p_size;
                    let entries = combined * (combined + 1) / 2 + degree[p] * combined;
                    RELAX.iter().find(|(cols, share)| *cols >= combined && entries as f64 * share >= total as f64).map_or(NONE, |_| total)
                };
                if status == NONE {
                    continue;
                }
                let proposed = status - (c_zeros + p_zeros);
                if c_size > largest || proposed < new_zeros {
                    merging = candidate;
                    new_zeros = proposed;
                    merged_zeros = status;
                    largest = c_size;
                }
            }
            if merging == NONE {
                break;
            }
            size[p] += size[merging];
            size[merging] = 0;
            zeros[p] = merged_zeros;
            merged_into[merging] = if last_merged[p] != NONE { last_merged[p] } else { p };
            last_merged[p] = if last_merged[merging] != NONE { last_merged[merging] } else { merging };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::bench::elastic_cube_system;
    use faer::perm::PermRef;
    use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholeskyRaw, SymmetricOrdering};
    use faer::sparse::linalg::SupernodalThreshold;
    use faer::sparse::{SymbolicSparseColMat, SymbolicSparseColMatRef};
    use faer::Side;

    /// faer's structure of `P A Pᵀ` and ours, for the supervariable order `order`.
    fn both(p: SymbolicSparseColMatRef<'_, usize>, order: &[usize]) -> (Supernodal, Supernodal) {
        let graph = SupervariableGraph::of(p).unwrap();
        let perm = graph.expand(order.iter().copied(), "test").unwrap();
        let params = CholeskySymbolicParams { supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL, ..Default::default() };
        let ordering = SymmetricOrdering::Custom(PermRef::new_checked(&perm.forward, &perm.inverse, p.nrows()));
        let c = factorize_symbolic_cholesky(p, Side::Lower, ordering, params).unwrap();
        let SymbolicCholeskyRaw::Supernodal(s) = c.raw() else { panic!("a supernodal factor") };
        (Supernodal::of_faer(s), Supernodal::of_supervariables(&graph, order))
    }

    /// The submatrix pattern of the columns (and rows) `keep`.
    fn sub(p: SymbolicSparseColMatRef<'_, usize>, keep: impl Fn(usize) -> bool) -> SymbolicSparseColMat<usize> {
        let n = p.nrows();
        let mut new = vec![NONE; n];
        let mut m = 0;
        for j in 0..n {
            if keep(j) {
                new[j] = m;
                m += 1;
            }
        }
        let (mut cp, mut ri) = (vec![0usize], Vec::new());
        for j in (0..n).filter(|&j| new[j] != NONE) {
            ri.extend(p.row_idx_of_col(j).filter(|&i| new[i] != NONE).map(|i| new[i]));
            cp.push(ri.len());
        }
        SymbolicSparseColMat::new_checked(m, m, cp, None, ri)
    }

    /// A deterministic shuffle of `0..m` (a linear congruential generator).
    fn shuffled(m: usize, seed: u64) -> Vec<usize> {
        let mut order: Vec<usize> = (0..m).collect();
        let mut x = seed;
        for i in (1..m).rev() {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            order.swap(i, (x >> 33) as usize % (i + 1));
        }
        order
    }

    /// On the clamped cube, with nodes of 3 free dofs and, with every seventh dof
    /// removed, of 1, 2 and 3, in the natural order, METIS's nested dissection, the
    /// geometric one and shuffled ones: our structure is faer's, entry for entry
    /// (the supernodes, their rows, their value offsets). The orders give hundreds
    /// of supernodes, relaxed ones among them (checked: fewer than the fundamental
    /// ones), so every rule of faer's is met.
    #[test]
    fn the_structure_is_faers_entry_for_entry() {
        let cube = elastic_cube_system(7).unwrap();
        let full = cube.pattern.symbolic_owned().clone();
        let holed = sub(full.as_ref(), |j| j % 7 != 3);
        for (name, p) in [("cube", &full), ("cube with holes", &holed)] {
            let graph = SupervariableGraph::of(p.as_ref()).unwrap();
            let m = graph.n_vertices();
            let sizes: std::collections::BTreeSet<usize> = (0..m).map(|v| graph.start[v + 1] - graph.start[v]).collect();
            if name == "cube with holes" {
                assert!(sizes.len() >= 2, "supervariables of several sizes: {sizes:?}");
            }
            let metis = crate::solver::ordering::nested_dissection_order(p.as_ref()).unwrap();
            let mut orders = vec![("natural", (0..m).collect::<Vec<_>>()), ("METIS", metis)];
            for seed in [1, 2, 3] {
                orders.push(("shuffled", shuffled(m, seed)));
            }
            for (what, order) in orders {
                let (faer, ours) = both(p.as_ref(), &order);
                assert!(faer.n_supernodes() > 10, "{name}, {what}: {} supernodes", faer.n_supernodes());
                assert_eq!(ours, faer, "{name}, {what} order");
            }
        }
    }

    /// Relaxation merges supernodes: on the cube in METIS's order the structure has
    /// fewer supernodes than without it (faer's `relax: None`), and still equals
    /// faer's with it (the test above).
    #[test]
    fn relaxation_merges_supernodes() {
        let cube = elastic_cube_system(7).unwrap();
        let p = cube.pattern.symbolic_owned();
        let graph = SupervariableGraph::of(p.as_ref()).unwrap();
        let order = crate::solver::ordering::nested_dissection_order(p.as_ref()).unwrap();
        let perm = graph.expand(order.iter().copied(), "test").unwrap();
        let mut params = CholeskySymbolicParams { supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL, ..Default::default() };
        params.supernodal_params.relax = None;
        let ordering = SymmetricOrdering::Custom(PermRef::new_checked(&perm.forward, &perm.inverse, p.nrows()));
        let c = factorize_symbolic_cholesky(p.as_ref(), Side::Lower, ordering, params).unwrap();
        let SymbolicCholeskyRaw::Supernodal(fundamental) = c.raw() else { panic!("a supernodal factor") };
        let ours = Supernodal::of_supervariables(&graph, &order);
        assert!(ours.n_supernodes() < fundamental.n_supernodes(), "{} relaxed, {} fundamental", ours.n_supernodes(), fundamental.n_supernodes());
    }
}
