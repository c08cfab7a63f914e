//! Degree-of-freedom numbering: 3 displacement components per node, each either
//! *free* (an unknown of the reduced system `K_ff Δu_f = −r_f`) or *constrained*
//! (Dirichlet, eliminated).
//!
//! Global dof of node `a`, component `i` is `3a + i`. Free dofs are numbered
//! `0..n_free` in increasing global order (node-major). Any numbering keeps the
//! reduced matrix SPD for elasticity — `K_ff = Pᵀ K P` is a principal submatrix of
//! the (positive semidefinite) stiffness, positive definite once the rigid modes
//! are removed by the constraints — and the fill-reducing ordering is chosen later
//! by the factorization (AMD/COLAMD), so the simplest, monotone numbering is used:
//! it makes the rows of each column of the pattern come out sorted for free.
//!
//! Dirichlet by elimination: constrained dofs never enter `K_ff`; their prescribed
//! values are written into the displacement vector before the residual is
//! evaluated, so their effect on the free equations is carried by the residual.

/// Number of dofs per node (3D displacement).
pub const DOFS_PER_NODE: usize = 3;

/// Marker in [`DofMap`] for a constrained dof.
const CONSTRAINED: u32 = u32::MAX;

/// Errors building a [`DofMap`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DofError {
    #[error("the constrained-dof mask has length {len}, not a multiple of {DOFS_PER_NODE}")]
    MaskLength { len: usize },
    #[error("{n_dofs} dofs do not fit the 32-bit dof numbering")]
    TooMany { n_dofs: usize },
}

/// Map between global dofs (`3·node + component`) and free-dof numbers.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DofMap {
    /// Free number of each global dof, or `CONSTRAINED`.
    free_of_global: Vec<u32>,
    /// Global dof of each free dof (increasing).
    global_of_free: Vec<u32>,
}

impl DofMap {
    /// Builds the map from a per-dof mask (`true` = constrained), of length
    /// `3·n_nodes`.
    pub fn from_constrained_mask(constrained: &[bool]) -> Result<Self, DofError> {
        if constrained.len() % DOFS_PER_NODE != 0 {
            return Err(DofError::MaskLength { len: constrained.len() });
        }
        if constrained.len() >= CONSTRAINED as usize {
            return Err(DofError::TooMany { n_dofs: constrained.len() });
        }
        let mut free_of_global = Vec::with_capacity(constrained.len());
        let mut global_of_free = Vec::with_capacity(constrained.len());
        for (g, &c) in constrained.iter().enumerate() {
            if c {
                free_of_global.push(CONSTRAINED);
            } else {
                free_of_global.push(global_of_free.len() as u32);
                global_of_free.push(g as u32);
            }
        }
        Ok(Self { free_of_global, global_of_free })
    }

    /// All `3·n_nodes` dofs free.
    pub fn all_free(n_nodes: usize) -> Result<Self, DofError> {
        Self::from_constrained_mask(&vec![false; DOFS_PER_NODE * n_nodes])
    }

    pub fn n_nodes(&self) -> usize {
        self.free_of_global.len() / DOFS_PER_NODE
    }

    /// Number of global dofs, `3·n_nodes`.
    pub fn n_dofs(&self) -> usize {
        self.free_of_global.len()
    }

    /// Number of free dofs (size of `K_ff`).
    pub fn n_free(&self) -> usize {
        self.global_of_free.len()
    }

    pub fn n_constrained(&self) -> usize {
        self.n_dofs() - self.n_free()
    }

    /// Free number of global dof `dof`, `None` if it is constrained.
    #[inline]
    pub fn free(&self, dof: usize) -> Option<usize> {
        match self.free_of_global[dof] {
            CONSTRAINED => None,
            f => Some(f as usize),
        }
    }

    #[inline]
    pub fn is_constrained(&self, dof: usize) -> bool {
        self.free_of_global[dof] == CONSTRAINED
    }

    /// Global dof of each free dof, increasing.
    pub fn global_of_free(&self) -> &[u32] {
        &self.global_of_free
    }

    /// `out[f] = full[global(f)]`: restriction of a full vector (e.g. the
    /// residual) to the free dofs.
    pub fn gather_free(&self, full: &[f64], out: &mut [f64]) {
        assert_eq!(full.len(), self.n_dofs());
        assert_eq!(out.len(), self.n_free());
        for (o, &g) in out.iter_mut().zip(&self.global_of_free) {
            *o = full[g as usize];
        }
    }

    /// `full[global(f)] += reduced[f]`: adds a free-dof increment (e.g. the
    /// Newton correction) to a full vector; constrained entries are untouched.
    pub fn add_free(&self, reduced: &[f64], full: &mut [f64]) {
        assert_eq!(full.len(), self.n_dofs());
        assert_eq!(reduced.len(), self.n_free());
        for (r, &g) in reduced.iter().zip(&self.global_of_free) {
            full[g as usize] += r;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbering_skips_constrained_dofs() {
        let mask = [true, false, false, false, true, false];
        let m = DofMap::from_constrained_mask(&mask).unwrap();
        assert_eq!(m.n_nodes(), 2);
        assert_eq!(m.n_free(), 4);
        assert_eq!(m.n_constrained(), 2);
        assert_eq!(m.global_of_free(), &[1, 2, 3, 5]);
        assert_eq!(m.free(0), None);
        assert_eq!(m.free(3), Some(2));
        assert_eq!(m.free(5), Some(3));
        let full = [10.0, 11.0, 12.0, 13.0, 14.0, 15.0];
        let mut red = [0.0; 4];
        m.gather_free(&full, &mut red);
        assert_eq!(red, [11.0, 12.0, 13.0, 15.0]);
        let mut full2 = full;
        m.add_free(&[1.0; 4], &mut full2);
        assert_eq!(full2, [10.0, 12.0, 13.0, 14.0, 14.0, 16.0]);
        assert_eq!(
            DofMap::from_constrained_mask(&[false; 4]),
            Err(DofError::MaskLength { len: 4 })
        );
    }
}
