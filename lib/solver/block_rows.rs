//! The tangent as node-block rows of the full system, for a backend that wants
//! 3×3 blocks (PETSc's AIJ with block size 3, whose algebraic multigrid aggregates
//! nodes, not dofs).
//!
//! Newton's tangent is `K_ff` over the free dofs only (Dirichlet by elimination,
//! [`crate::assembly::DofMap`]). A node with one component held would break the
//! 3×3 blocks, so the backend sees the full `3n × 3n` system instead:
//!
//! ```text
//!     [ K_ff  0 ] [Δu_f]   [−R_f]
//!     [  0   dI ] [Δu_c] = [  0 ]        d = mean |diag K_ff|
//! ```
//!
//! which has the same solution `Δu_f` and `Δu_c = 0`, keeps symmetry, and gives the
//! constrained rows a diagonal of the matrix's own scale (a row of 1s in a matrix of
//! 1e9s would spoil the multigrid's smoother and coarse spaces).
//!
//! Layout: block row `I` (node `I`) holds block columns `cols[ptr[I]..ptr[I+1]]`
//! (sorted, the diagonal always present); its values are one row-major
//! `3 × 3·ncols` array at `9·ptr[I]`, the layout `MatSetValuesBlocked` reads for
//! one block row. [`BlockRows::scatter`] moves the CSC values into it through a
//! position map computed once per pattern.

use faer::sparse::SymbolicSparseColMatRef;

/// Node-block row structure of the full system and the map from the free-dof CSC.
#[derive(Debug, Clone)]
pub struct BlockRows {
    /// Block-row pointers, one row per node (`n_nodes + 1`).
    pub ptr: Vec<usize>,
    /// Block columns (node numbers) of each row, sorted.
    pub cols: Vec<i32>,
    /// Destination in the block values of each CSC entry of `K_ff`.
    dest: Vec<u32>,
    /// Destination of each constrained dof's diagonal.
    constrained_diag: Vec<u32>,
    /// Destination of each free dof's diagonal (the scale of the constrained rows).
    free_diag: Vec<u32>,
    /// Global dof of each free dof.
    global_of_free: Vec<u32>,
}

/// A pattern this layout cannot address.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BlockRowsError {
    #[error("{what} ({got}) does not fit the 32-bit indices of the block layout")]
    TooLarge { what: &'static str, got: usize },
    #[error("the pattern has {got} columns, the dof map {expected} free dofs")]
    Dimension { expected: usize, got: usize },
}

impl BlockRows {
    /// The block structure of the full system of `n_nodes` nodes whose free dofs are
    /// `global_of_free` (increasing, `3·node + component`), from the free-dof CSC
    /// pattern.
    pub fn new(pattern: SymbolicSparseColMatRef<'_, usize>, global_of_free: &[u32], n_nodes: usize) -> Result<Self, BlockRowsError> {
        let n_free = pattern.ncols();
        if n_free != global_of_free.len() {
            return Err(BlockRowsError::Dimension { expected: global_of_free.len(), got: n_free });
        }
        if n_nodes > i32::MAX as usize {
            return Err(BlockRowsError::TooLarge { what: "nodes", got: n_nodes });
        }
        let node = |f: usize| global_of_free[f] as usize / 3;
        // block columns of each block row: the diagonal, and every node pair of K_ff
        // (structurally symmetric: both triangles are stored)
        let mut rows: Vec<Vec<i32>> = (0..n_nodes).map(|i| vec![i as i32]).collect();
        for j in 0..n_free {
            let nj = node(j);
            for i in pattern.row_idx_of_col(j) {
                rows[node(i)].push(nj as i32);
            }
        }
        let mut ptr = Vec::with_capacity(n_nodes + 1);
        ptr.push(0usize);
        let mut cols = Vec::new();
        for r in &mut rows {
            r.sort_unstable();
            r.dedup();
            cols.extend_from_slice(r);
            ptr.push(cols.len());
            *r = Vec::new();
        }
        drop(rows);
        let n_values = 9 * cols.len();
        if n_values > u32::MAX as usize {
            return Err(BlockRowsError::TooLarge { what: "block values", got: n_values });
        }
        let at = |gi: usize, gj: usize| -> u32 {
            let (ni, ri) = (gi / 3, gi % 3);
            let (nj, cj) = (gj / 3, gj % 3);
            let row = &cols[ptr[ni]..ptr[ni + 1]];
            let k = row.binary_search(&(nj as i32)).expect("block column present by construction");
            (9 * ptr[ni] + ri * 3 * row.len() + 3 * k + cj) as u32
        };
        let mut dest = Vec::with_capacity(pattern.compute_nnz());
        let mut free_diag = vec![0u32; n_free];
        for j in 0..n_free {
            let gj = global_of_free[j] as usize;
            for i in pattern.row_idx_of_col(j) {
                let d = at(global_of_free[i] as usize, gj);
                if i == j {
                    free_diag[j] = d;
                }
                dest.push(d);
            }
        }
        let mut is_free = vec![false; 3 * n_nodes];
        for &g in global_of_free {
            is_free[g as usize] = true;
        }
        let constrained_diag = (0..3 * n_nodes).filter(|&g| !is_free[g]).map(|g| at(g, g)).collect();
        Ok(Self { ptr, cols, dest, constrained_diag, free_diag, global_of_free: global_of_free.to_vec() })
    }

    /// Number of node blocks stored.
    pub fn n_blocks(&self) -> usize {
        self.cols.len()
    }

    /// Number of nodes (block rows).
    pub fn n_nodes(&self) -> usize {
        self.ptr.len() - 1
    }

    /// Fills `block_values` (length `9·n_blocks`) with the full system: `K_ff`'s
    /// values (CSC order), zeros where only a constrained dof meets, and
    /// `d = mean |diag K_ff|` on the constrained diagonal. Collects into
    /// `non_positive` the global dofs whose free diagonal entry is not positive: an
    /// indefinite tangent, from which a multigrid preconditioner cannot be built.
    pub fn scatter(&self, values: &[f64], block_values: &mut [f64], non_positive: &mut Vec<usize>) {
        block_values.iter_mut().for_each(|v| *v = 0.0);
        for (&d, &v) in self.dest.iter().zip(values) {
            block_values[d as usize] = v;
        }
        non_positive.clear();
        let mut sum = 0.0;
        for (&d, &g) in self.free_diag.iter().zip(&self.global_of_free) {
            let v = block_values[d as usize];
            sum += v.abs();
            if !(v > 0.0) {
                non_positive.push(g as usize);
            }
        }
        let scale = if self.free_diag.is_empty() || sum == 0.0 { 1.0 } else { sum / self.free_diag.len() as f64 };
        for &d in &self.constrained_diag {
            block_values[d as usize] = scale;
        }
    }

    /// Block columns of block row `i`, and the offset of its values.
    pub fn row(&self, i: usize) -> (&[i32], usize) {
        (&self.cols[self.ptr[i]..self.ptr[i + 1]], 9 * self.ptr[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::SymbolicSparseColMat;

    /// Two nodes; node 0's z and node 1's x held: free dofs 0,1,4,5 (global).
    #[test]
    fn full_system_reproduces_k_ff_and_scales_the_constrained_diagonal() {
        let global_of_free = [0u32, 1, 4, 5];
        // dense 4×4 K_ff with K[i][j] = 10(i+1) + j + 1, diagonal 11, 22, 33, 44
        let n = 4;
        let col_ptr: Vec<usize> = (0..=n).map(|j| j * n).collect();
        let row_idx: Vec<usize> = (0..n).flat_map(|_| 0..n).collect();
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let values: Vec<f64> = (0..n).flat_map(|j| (0..n).map(move |i| (10 * (i + 1) + j + 1) as f64)).collect();
        let b = BlockRows::new(pattern.as_ref(), &global_of_free, 2).unwrap();
        assert_eq!(b.ptr, vec![0, 2, 4]);
        assert_eq!(b.cols, vec![0, 1, 0, 1]);
        let mut bv = vec![f64::NAN; 9 * b.n_blocks()];
        let mut bad = Vec::new();
        b.scatter(&values, &mut bv, &mut bad);
        assert!(bad.is_empty());
        // dense 6×6 from the block rows
        let mut full = [[0.0; 6]; 6];
        for i in 0..2 {
            let (cols, off) = b.row(i);
            for r in 0..3 {
                for (k, &c) in cols.iter().enumerate() {
                    for cc in 0..3 {
                        full[3 * i + r][3 * c as usize + cc] = bv[off + r * 3 * cols.len() + 3 * k + cc];
                    }
                }
            }
        }
        let scale = (11.0 + 22.0 + 33.0 + 44.0) / 4.0;
        for (fi, &gi) in global_of_free.iter().enumerate() {
            for (fj, &gj) in global_of_free.iter().enumerate() {
                assert_eq!(full[gi as usize][gj as usize], (10 * (fi + 1) + fj + 1) as f64);
            }
        }
        for g in [2usize, 3] {
            for k in 0..6 {
                let expected = if k == g { scale } else { 0.0 };
                assert_eq!(full[g][k], expected, "row {g}");
                assert_eq!(full[k][g], expected, "column {g}");
            }
        }
    }

    #[test]
    fn a_non_positive_free_diagonal_is_counted() {
        let pattern = SymbolicSparseColMat::new_checked(3, 3, vec![0, 1, 2, 3], None, vec![0, 1, 2]);
        let b = BlockRows::new(pattern.as_ref(), &[0, 1, 2], 1).unwrap();
        let mut bv = vec![0.0; 9];
        let mut bad = Vec::new();
        b.scatter(&[1.0, -2.0, 0.0], &mut bv, &mut bad);
        assert_eq!(bad, vec![1, 2]);
    }
}
