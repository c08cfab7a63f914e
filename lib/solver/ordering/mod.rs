//! Fill-reducing orderings for the sparse direct factorizations.
//!
//! A Cholesky factor `L` of `P A Pᵀ` holds the entries of `A` plus the *fill* the
//! elimination creates; the permutation `P` decides how much. Two orderings:
//!
//! - **AMD** (approximate minimum degree, faer's own): greedy, local; excellent on
//!   2D and thin meshes, but on 3D meshes its fill grows much faster than
//!   nested dissection's.
//! - **Nested dissection** (METIS `METIS_NodeND`): find a small vertex separator
//!   that splits the graph in two, number the separator last, recurse into the
//!   halves. On an `n × n × n` hex mesh the top separator has `O(n²)` nodes, so the
//!   factor holds `O(N^{4/3})` entries and costs `O(N²)` flops (George 1973; AMD
//!   has no such bound). It is the ordering of MUMPS, PARDISO and SPOOLES (CalculiX).
//!
//! **The node graph, not the dof graph.** The three dofs of a mesh node have
//! identical columns (the pattern is built from node couplings). Consecutive
//! columns with identical row lists are merged into one *supervariable*; METIS
//! orders the supervariable graph (a third of the vertices, a ninth of the
//! edges), weighted by supervariable size, and the dofs of a supervariable stay
//! together in the result, which keeps faer's supernodes dense.
//!
//! METIS is deterministic for a given graph (it reseeds its generator with a fixed
//! seed at every call), so the ordering, and the factorization, repeat bit for bit
//! — provided no two calls run at once: the generator's state is a global of
//! GKlib's, so calls are serialised by [`METIS_LOCK`].

use super::linear::error::LinearSolverError;
use faer::sparse::SymbolicSparseColMatRef;

pub mod geometric;
pub mod vertex_cover;
pub use geometric::{geometric_dissection, geometric_order_of};

/// Serialises the calls into METIS (its random generator is a process global).
static METIS_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Which fill-reducing ordering a symmetric factorization uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FillOrdering {
    /// faer's approximate minimum degree.
    Amd,
    /// METIS nested dissection on the supervariable (node) graph.
    #[default]
    NestedDissection,
    /// Nested dissection by coordinate planes ([`geometric`]); METIS's when the
    /// solver was given no coordinates.
    Geometric,
}

/// A permutation as faer reads it: `forward[k]` is the original index of the
/// `k`-th pivot, `inverse[forward[k]] = k`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Permutation {
    pub forward: Vec<usize>,
    pub inverse: Vec<usize>,
}

/// Supervariables of a pattern: runs of consecutive columns with identical row
/// lists. `start[s]..start[s + 1]` are the columns of supervariable `s`.
pub fn supervariables(pattern: SymbolicSparseColMatRef<'_, usize>) -> Vec<usize> {
    let n = pattern.ncols();
    let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
    let mut start = Vec::with_capacity(n / 3 + 2);
    for j in 0..n {
        let same = j > 0 && ri[cp[j - 1]..cp[j]] == ri[cp[j]..cp[j + 1]];
        if !same {
            start.push(j);
        }
    }
    start.push(n);
    start
}

/// The supervariable graph of a pattern: a vertex per supervariable, `s` and `t`
/// adjacent when a column of `s` has a row in `t` (no self loops). The neighbours
/// of `s` are `adjncy[xadj[s]..xadj[s + 1]]`, sorted.
pub struct SupervariableGraph {
    /// `start[s]..start[s + 1]`: the columns of supervariable `s` ([`supervariables`]).
    pub start: Vec<usize>,
    pub xadj: Vec<usize>,
    pub adjncy: Vec<u32>,
}

impl SupervariableGraph {
    /// The graph of a structurally symmetric pattern (square CSC, both triangles).
    pub fn of(pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<Self, LinearSolverError> {
        let n = pattern.ncols();
        let (cp, ri) = (pattern.col_ptr(), pattern.row_idx());
        let start = supervariables(pattern);
        let n_super = start.len() - 1;
        if u32::try_from(n_super).is_err() {
            return Err(LinearSolverError::Faer(format!("ordering: {n_super} supervariables exceed a 32-bit index")));
        }
        let mut owner = vec![0u32; n];
        for s in 0..n_super {
            owner[start[s]..start[s + 1]].fill(s as u32);
        }
        // neighbours of s: the supervariables of the rows of its first column, without
        // s itself; rows are sorted and a supervariable's columns consecutive, so
        // duplicates are adjacent
        let mut xadj = Vec::with_capacity(n_super + 1);
        let mut adjncy = Vec::with_capacity(ri.len() / 9 + n_super);
        xadj.push(0);
        for s in 0..n_super {
            let j = start[s];
            let mut last = u32::MAX;
            for &i in &ri[cp[j]..cp[j + 1]] {
                let t = owner[i];
                if t as usize != s && t != last {
                    adjncy.push(t);
                    last = t;
                }
            }
            xadj.push(adjncy.len());
        }
        Ok(Self { start, xadj, adjncy })
    }

    pub fn n_vertices(&self) -> usize {
        self.start.len() - 1
    }

    pub fn neighbours(&self, s: usize) -> &[u32] {
        &self.adjncy[self.xadj[s]..self.xadj[s + 1]]
    }

    /// The column permutation of a supervariable order (`order[k]` the `k`-th
    /// supervariable to eliminate): each supervariable's columns in turn.
    pub fn expand(&self, order: impl IntoIterator<Item = usize>, what: &str) -> Result<Permutation, LinearSolverError> {
        let n = *self.start.last().unwrap_or(&0);
        let n_super = self.n_vertices();
        let mut forward = Vec::with_capacity(n);
        for s in order {
            if s >= n_super {
                return Err(LinearSolverError::Faer(format!("{what} returned an index out of range")));
            }
            forward.extend(self.start[s]..self.start[s + 1]);
        }
        let mut inverse = vec![usize::MAX; n];
        for (k, &j) in forward.iter().enumerate() {
            if j < n {
                inverse[j] = k;
            }
        }
        if forward.len() != n || inverse.contains(&usize::MAX) {
            return Err(LinearSolverError::Faer(format!("{what} returned no permutation")));
        }
        Ok(Permutation { forward, inverse })
    }
}

/// Nested-dissection ordering (METIS) of a structurally symmetric pattern
/// (square CSC, both triangles stored).
pub fn nested_dissection(pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<Permutation, LinearSolverError> {
    let graph = SupervariableGraph::of(pattern)?;
    let order = nested_dissection_of(&graph)?;
    graph.expand(order, "METIS_NodeND")
}

/// [`nested_dissection`]'s order of the supervariables of `pattern`.
pub fn nested_dissection_order(pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<Vec<usize>, LinearSolverError> {
    nested_dissection_of(&SupervariableGraph::of(pattern)?)
}

/// METIS's nested-dissection order of the vertices of a supervariable graph
/// (each weighted by its columns): `order[k]` the `k`-th to eliminate.
pub fn nested_dissection_of(graph: &SupervariableGraph) -> Result<Vec<usize>, LinearSolverError> {
    if graph.n_vertices() == 0 {
        return Ok(Vec::new());
    }
    let start = &graph.start;
    let n_super = graph.n_vertices();
    let too_big = |what: &'static str| LinearSolverError::Faer(format!("METIS ordering: the {what} exceeds METIS's 32-bit index"));
    let mut xadj: Vec<metis_sys::idx_t> = graph.xadj.iter().map(|&k| metis_sys::idx_t::try_from(k)).collect::<Result<_, _>>().map_err(|_| too_big("graph's edge count"))?;
    let mut adjncy: Vec<metis_sys::idx_t> = graph.adjncy.iter().map(|&t| metis_sys::idx_t::try_from(t)).collect::<Result<_, _>>().map_err(|_| too_big("node count"))?;
    let mut vwgt: Vec<metis_sys::idx_t> =
        (0..n_super).map(|s| metis_sys::idx_t::try_from(start[s + 1] - start[s]).unwrap_or(metis_sys::idx_t::MAX)).collect();
    let mut nvtxs = metis_sys::idx_t::try_from(n_super).map_err(|_| too_big("node count"))?;
    let mut perm = vec![0 as metis_sys::idx_t; n_super];
    let mut iperm = vec![0 as metis_sys::idx_t; n_super];
    // SAFETY: every array has the length METIS_NodeND reads or writes (xadj n+1,
    // adjncy xadj[n], vwgt n, perm and iperm n); a null options pointer selects
    // METIS's defaults.
    let guard = METIS_LOCK.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let status = unsafe {
        metis_sys::METIS_NodeND(
            &mut nvtxs,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            vwgt.as_mut_ptr(),
            std::ptr::null_mut(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    drop(guard);
    if status != metis_sys::rstatus_et_METIS_OK {
        return Err(LinearSolverError::Faer(format!("METIS_NodeND failed with status {status}")));
    }
    // the supervariables in METIS's order (each with its columns in order, `expand`)
    Ok(perm.iter().map(|&s| usize::try_from(s).unwrap_or(usize::MAX)).collect())
}

/// `perm` is a permutation of `0..n` (with its inverse), and the 3 dofs of each
/// node are consecutive pivots (every node of the test meshes has 3 free dofs).
#[cfg(test)]
pub(super) fn assert_keeps_nodes_together(perm: &Permutation, n: usize) {
    let mut seen = vec![false; n];
    for &j in &perm.forward {
        assert!(!seen[j]);
        seen[j] = true;
    }
    assert_eq!(perm.forward.len(), n);
    for (k, &j) in perm.forward.iter().enumerate() {
        assert_eq!(perm.inverse[j], k);
    }
    for c in perm.forward.chunks(3) {
        assert_eq!((c[1], c[2]), (c[0] + 1, c[0] + 2));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::bench::elastic_cube_system;

    #[test]
    fn supervariables_are_the_nodes_of_a_hex_mesh() {
        let cube = elastic_cube_system(3).unwrap();
        let p = cube.pattern.symbolic();
        let start = supervariables(p);
        // every free node has its 3 dofs (the clamped face has none)
        assert_eq!(start.len() - 1, p.ncols() / 3);
        assert!(start.windows(2).all(|w| w[1] - w[0] == 3));
    }

    #[test]
    fn nested_dissection_is_a_permutation_that_keeps_nodes_together() {
        let cube = elastic_cube_system(5).unwrap();
        let p = cube.pattern.symbolic();
        let perm = nested_dissection(p).unwrap();
        assert_keeps_nodes_together(&perm, p.ncols());
        // deterministic, also when called from several threads at once
        assert_eq!(nested_dissection(p).unwrap(), perm);
        std::thread::scope(|scope| {
            let runs: Vec<_> = (0..4).map(|_| scope.spawn(|| nested_dissection(p).unwrap())).collect();
            for r in runs {
                assert_eq!(r.join().unwrap(), perm);
            }
        });
    }
}
