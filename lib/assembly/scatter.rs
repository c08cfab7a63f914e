//! Parallel, deterministic assembly of the reduced stiffness values and the full
//! residual from per-element contributions.
//!
//! **Stiffness: colour by colour.** The hexahedra are split into colours that share
//! no node ([`Colouring`], built with the pattern). The elements of one colour are
//! computed in parallel (rayon), and each adds its 24 × 24 matrix straight into the
//! values array through its slot map: two elements of one colour have no common
//! row, so no entry is written by two threads. The colours follow one another in
//! a fixed order, so every entry receives its contributions in the same sequence
//! at any thread count: `values` is **bit-identical at any thread count**. No
//! element matrix is kept: at 1M dofs that saves the 1.5 GB of buffers (8 bytes
//! per element-matrix entry) and the 1.4 GB of "entry → contributions" lists that
//! a buffer-and-gather scheme needs.
//!
//! **Contact groups** (a few thousand, each 3k × 3k) are computed in parallel into
//! their own buffers and then added in group order, one after another.
//!
//! **Residual: buffer and gather.** Each element writes its residual into its own
//! 24-vector; every dof then sums its contributions from a precomputed
//! "dof → contributions" list in a fixed order (hexahedra by increasing index,
//! then groups), in parallel over dofs: the residual is bit-identical at any
//! thread count too, and costs 8 + 4 bytes per element dof.
//!
//! **No allocation per iteration.** [`Assembly`] owns the buffers, the
//! contribution lists and the output arrays; it is built once per [`Pattern`]
//! (rebuilt with it when the contact groups change) and reused by every Newton
//! iteration.
//!
//! **Dirichlet by elimination.** Entries of `k_e` that touch a constrained dof are
//! dropped (`K_ff` only); the residual is assembled for *all* dofs, so the
//! reactions can be read at the constrained ones. Prescribed displacements must
//! already be in the displacement vector the element routine reads.

use nalgebra::{DMatrix, DVector, SMatrix, SVector};
use rayon::prelude::*;

use super::colouring::Colouring;
use super::dofs::DOFS_PER_NODE;
use super::pattern::{Pattern, HEX_DOFS, HEX_ENTRIES, NO_SLOT};

/// Residual vector of a hex8 element.
pub type HexVector = SVector<f64, HEX_DOFS>;
/// Tangent matrix of a hex8 element.
pub type HexMatrix = SMatrix<f64, HEX_DOFS, HEX_DOFS>;

/// Borrowed result of an assembly: (`K_ff` values in pattern order, full residual).
pub type Assembled<'a> = (&'a [f64], &'a [f64]);

/// Slots summed per parallel task in the gather phase.
const GATHER_CHUNK: usize = 4096;

/// Errors building an [`Assembly`] workspace.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum AssemblyError {
    #[error("{n_hex} hexahedra exceed the 32-bit contribution numbering")]
    TooManyElements { n_hex: usize },
    #[error("contact group {group} has {n_nodes} nodes, more than the 32-bit contribution numbering allows")]
    GroupTooLarge { group: usize, n_nodes: usize },
}

/// Which element failed, with its error.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ElementFailure<E> {
    #[error("hexahedron {element}: {error}")]
    Hex { element: usize, error: E },
    #[error("contact group {group}: {error}")]
    Group { group: usize, error: E },
}

/// Contributions to each output entry, CSR: `src[ptr[s]..ptr[s + 1]]`.
#[derive(Debug, Clone, Default)]
struct Contributions<T> {
    ptr: Vec<usize>,
    src: Vec<T>,
}

impl<T: Copy + Default> Contributions<T> {
    /// `targets` yields (target, source) in the required summation order.
    fn build(n_targets: usize, targets: impl Iterator<Item = (usize, T)> + Clone) -> Self {
        let mut ptr = vec![0usize; n_targets + 1];
        for (t, _) in targets.clone() {
            ptr[t + 1] += 1;
        }
        for t in 0..n_targets {
            ptr[t + 1] += ptr[t];
        }
        let mut fill = ptr.clone();
        let mut src = vec![T::default(); ptr[n_targets]];
        for (t, s) in targets {
            src[fill[t]] = s;
            fill[t] += 1;
        }
        Self { ptr, src }
    }

    #[inline]
    fn of(&self, t: usize) -> &[T] {
        &self.src[self.ptr[t]..self.ptr[t + 1]]
    }
}

/// Wall times of the last assembly, by phase.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct AssemblyTimings {
    /// Element routines and the hexahedra's additions into the values (parallel
    /// over the elements of each colour), contact group routines.
    pub compute: std::time::Duration,
    /// The groups' additions into the values and the residual's fixed-order sums.
    pub sum: std::time::Duration,
}

/// A slice shared by the elements of one colour, each of which touches only
/// entries no other element of the colour touches (see the module docs): the
/// stiffness values of its rows, its own residual buffer.
struct ColourWrites<T> {
    ptr: *mut T,
    len: usize,
}

// SAFETY: entries are only reached through `get`, whose callers (the elements of
// one colour) touch disjoint entries; the slice outlives the colour's pass.
unsafe impl<T: Send> Send for ColourWrites<T> {}
unsafe impl<T: Send> Sync for ColourWrites<T> {}

impl<T> ColourWrites<T> {
    fn new(slice: &mut [T]) -> Self {
        Self { ptr: slice.as_mut_ptr(), len: slice.len() }
    }

    /// Entry `i`.
    ///
    /// # Safety
    /// No other thread reads or writes entry `i` while the reference lives.
    #[inline]
    #[allow(clippy::mut_from_ref)]
    unsafe fn get(&self, i: usize) -> &mut T {
        assert!(i < self.len);
        // SAFETY: in bounds (checked); exclusive by the caller's contract
        unsafe { &mut *self.ptr.add(i) }
    }
}

/// Assembly workspace for one [`Pattern`]: element buffers, contribution lists
/// and the assembled `values` (of `K_ff`, in the pattern's CSC order) and
/// `residual` (all `3·n_nodes` dofs).
#[derive(Debug, Clone)]
pub struct Assembly {
    n_hex: usize,
    n_groups: usize,
    nnz: usize,
    r_hex: Vec<HexVector>,
    k_grp: Vec<DMatrix<f64>>,
    r_grp: Vec<DVector<f64>>,
    /// dof -> `e·24 + local dof`.
    hex_to_dof: Contributions<u32>,
    /// dof -> (group, local dof).
    grp_to_dof: Contributions<(u32, u32)>,
    values: Vec<f64>,
    residual: Vec<f64>,
    timings: AssemblyTimings,
}

impl Assembly {
    /// Builds the workspace (buffers and contribution lists) for `pattern`.
    pub fn new(pattern: &Pattern) -> Result<Self, AssemblyError> {
        let n_hex = pattern.hexes().len();
        if n_hex.checked_mul(HEX_ENTRIES).is_none_or(|n| n >= u32::MAX as usize) {
            return Err(AssemblyError::TooManyElements { n_hex });
        }
        let groups = pattern.groups();
        for (g, nodes) in groups.iter().enumerate() {
            let nd = DOFS_PER_NODE * nodes.len();
            if nd * nd >= u32::MAX as usize {
                return Err(AssemblyError::GroupTooLarge { group: g, n_nodes: nodes.len() });
            }
        }
        let nnz = pattern.nnz();
        let n_dofs = pattern.dofs().n_dofs();

        let hexes = pattern.hexes();
        let hex_to_dof = Contributions::build(
            n_dofs,
            (0..n_hex).flat_map(|e| {
                (0..HEX_DOFS).map(move |i| {
                    (DOFS_PER_NODE * hexes[e][i / DOFS_PER_NODE] as usize + i % DOFS_PER_NODE, (e * HEX_DOFS + i) as u32)
                })
            }),
        );
        let grp_to_dof = Contributions::build(
            n_dofs,
            (0..groups.len()).flat_map(|g| {
                let nodes = groups.group(g);
                (0..DOFS_PER_NODE * nodes.len()).map(move |i| {
                    (DOFS_PER_NODE * nodes[i / DOFS_PER_NODE] as usize + i % DOFS_PER_NODE, (g as u32, i as u32))
                })
            }),
        );
        let nd = |g: usize| DOFS_PER_NODE * groups.group(g).len();
        Ok(Self {
            n_hex,
            n_groups: groups.len(),
            nnz,
            r_hex: vec![HexVector::zeros(); n_hex],
            k_grp: (0..groups.len()).map(|g| DMatrix::zeros(nd(g), nd(g))).collect(),
            r_grp: (0..groups.len()).map(|g| DVector::zeros(nd(g))).collect(),
            hex_to_dof,
            grp_to_dof,
            values: vec![0.0; nnz],
            residual: vec![0.0; n_dofs],
            timings: AssemblyTimings::default(),
        })
    }

    /// A workspace for no pattern (holds nothing): what an owner keeps while it
    /// drops the old workspace before building the next, so that the two never
    /// live at once.
    pub fn empty() -> Self {
        Self {
            n_hex: 0,
            n_groups: 0,
            nnz: 0,
            r_hex: Vec::new(),
            k_grp: Vec::new(),
            r_grp: Vec::new(),
            hex_to_dof: Contributions::default(),
            grp_to_dof: Contributions::default(),
            values: Vec::new(),
            residual: Vec::new(),
            timings: AssemblyTimings::default(),
        }
    }

    /// Whether this workspace was built for `pattern` (its element, group and entry
    /// counts).
    pub fn fits(&self, pattern: &Pattern) -> bool {
        pattern.hexes().len() == self.n_hex && pattern.groups().len() == self.n_groups && pattern.nnz() == self.nnz && self.values.len() == self.nnz
    }

    /// Assembles hexahedra only (contact groups, if any, contribute zero).
    ///
    /// `element(e, r_e, k_e)` fills the (zeroed) residual and tangent of hexahedron
    /// `e`; it runs in parallel. On failure the error of the failing element with
    /// the lowest index is returned (deterministic), with that index.
    pub fn assemble<E, F>(&mut self, pattern: &Pattern, element: F) -> Result<Assembled<'_>, (usize, E)>
    where
        E: Send,
        F: Fn(usize, &mut HexVector, &mut HexMatrix) -> Result<(), E> + Sync,
    {
        let no_groups = |_: usize, _: &mut DVector<f64>, _: &mut DMatrix<f64>| Ok(());
        match self.assemble_with_groups(pattern, element, no_groups) {
            Ok(out) => Ok(out),
            Err(ElementFailure::Hex { element, error }) => Err((element, error)),
            Err(ElementFailure::Group { .. }) => unreachable!("group routine never fails"),
        }
    }

    /// Assembles hexahedra and contact groups. `group(g, r_g, k_g)` fills the
    /// zeroed `3k` residual and `3k × 3k` tangent of group `g` (node order of
    /// [`NodeGroups::group`](super::pattern::NodeGroups::group)). Hexahedron
    /// failures are reported before group failures.
    pub fn assemble_with_groups<E, F, G>(
        &mut self,
        pattern: &Pattern,
        element: F,
        group: G,
    ) -> Result<Assembled<'_>, ElementFailure<E>>
    where
        E: Send,
        F: Fn(usize, &mut HexVector, &mut HexMatrix) -> Result<(), E> + Sync,
        G: Fn(usize, &mut DVector<f64>, &mut DMatrix<f64>) -> Result<(), E> + Sync,
    {
        assert!(self.fits(pattern), "Assembly workspace used with a different pattern than it was built for");
        // Phase 1: the hexahedra, colour by colour, add into the values; their
        // residuals and the groups go to private buffers.
        let start = std::time::Instant::now();
        self.values.par_iter_mut().for_each(|v| *v = 0.0);
        let values = ColourWrites::new(&mut self.values);
        let residuals = ColourWrites::new(&mut self.r_hex);
        let colouring: &Colouring = pattern.colouring();
        let mut hex_failure: Option<(usize, E)> = None;
        for c in 0..colouring.n_colours() {
            let failure = colouring
                .colour(c)
                .par_iter()
                .filter_map(|&e| {
                    let e = e as usize;
                    // SAFETY: every element of the colour has its own residual buffer
                    let r = unsafe { residuals.get(e) };
                    r.fill(0.0);
                    let mut k = HexMatrix::zeros();
                    if let Err(error) = element(e, r, &mut k) {
                        return Some((e, error));
                    }
                    let k = k.as_slice();
                    pattern.scatter_hex(e, |i, slot| {
                        // SAFETY: the elements of one colour share no node, hence
                        // no row: no other thread touches this entry
                        unsafe { *values.get(slot) += k[i] };
                    });
                    None
                })
                .min_by_key(|(e, _)| *e);
            if let Some((e, error)) = failure {
                if hex_failure.as_ref().is_none_or(|(w, _)| e < *w) {
                    hex_failure = Some((e, error));
                }
            }
        }
        if let Some((element, error)) = hex_failure {
            return Err(ElementFailure::Hex { element, error });
        }
        self.compute_groups(group)?;
        self.timings.compute = start.elapsed();

        // Phase 2: the groups' matrices in group order, and the residual's
        // fixed-order sums, parallel over dofs.
        let start = std::time::Instant::now();
        for (g, k) in self.k_grp.iter().enumerate() {
            for (&slot, &v) in pattern.group_slots(g).iter().zip(k.as_slice()) {
                if slot != NO_SLOT {
                    self.values[slot as usize] += v;
                }
            }
        }
        self.gather_residual();
        self.timings.sum = start.elapsed();
        Ok((&self.values, &self.residual))
    }

    /// The residual alone, as [`Self::assemble_with_groups`] makes it (the same
    /// sums in the same order: the same bits), at a fraction of the cost:
    /// `element(e, r_e)` fills the zeroed residual of hexahedron `e` (no tangent,
    /// no colours: each element writes only its own buffer), `group` as there (its
    /// tangent is dropped). The values are left as they were: not those of this
    /// state. Newton checks convergence with it where it expects to have converged.
    pub fn assemble_residual_with_groups<E, F, G>(&mut self, pattern: &Pattern, element: F, group: G) -> Result<&[f64], ElementFailure<E>>
    where
        E: Send,
        F: Fn(usize, &mut HexVector) -> Result<(), E> + Sync,
        G: Fn(usize, &mut DVector<f64>, &mut DMatrix<f64>) -> Result<(), E> + Sync,
    {
        assert!(self.fits(pattern), "Assembly workspace used with a different pattern than it was built for");
        let start = std::time::Instant::now();
        let hex_failure = self
            .r_hex
            .par_iter_mut()
            .enumerate()
            .filter_map(|(e, r)| {
                r.fill(0.0);
                element(e, r).err().map(|error| (e, error))
            })
            .min_by_key(|(e, _)| *e);
        if let Some((element, error)) = hex_failure {
            return Err(ElementFailure::Hex { element, error });
        }
        self.compute_groups(group)?;
        self.timings.compute = start.elapsed();
        let start = std::time::Instant::now();
        self.gather_residual();
        self.timings.sum = start.elapsed();
        Ok(&self.residual)
    }

    /// Every contact group's residual and tangent into its own buffers, in parallel;
    /// the failure of the lowest group index, if any.
    fn compute_groups<E, G>(&mut self, group: G) -> Result<(), ElementFailure<E>>
    where
        E: Send,
        G: Fn(usize, &mut DVector<f64>, &mut DMatrix<f64>) -> Result<(), E> + Sync,
    {
        let group_failure = self
            .k_grp
            .par_iter_mut()
            .zip(self.r_grp.par_iter_mut())
            .enumerate()
            .filter_map(|(g, (k, r))| {
                k.fill(0.0);
                r.fill(0.0);
                group(g, r, k).err().map(|error| (g, error))
            })
            .min_by_key(|(g, _)| *g);
        match group_failure {
            Some((group, error)) => Err(ElementFailure::Group { group, error }),
            None => Ok(()),
        }
    }

    /// Every dof's residual: its contributions from the hexahedra's and the groups'
    /// buffers, summed in a fixed order (hexahedra by index, then groups), in
    /// parallel over dofs.
    fn gather_residual(&mut self) {
        let (r_hex, r_grp) = (&self.r_hex, &self.r_grp);
        let (hex_to_dof, grp_to_dof) = (&self.hex_to_dof, &self.grp_to_dof);
        self.residual.par_chunks_mut(GATHER_CHUNK).enumerate().for_each(|(c, chunk)| {
            for (k, v) in chunk.iter_mut().enumerate() {
                let d = c * GATHER_CHUNK + k;
                let mut sum = 0.0;
                for &src in hex_to_dof.of(d) {
                    let src = src as usize;
                    sum += r_hex[src / HEX_DOFS][src % HEX_DOFS];
                }
                for &(g, l) in grp_to_dof.of(d) {
                    sum += r_grp[g as usize][l as usize];
                }
                *v = sum;
            }
        });
    }

    /// Phase times of the last successful assembly.
    pub fn timings(&self) -> AssemblyTimings {
        self.timings
    }

    /// Values of `K_ff` from the last assembly, in the pattern's CSC order.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The same, to add terms assembled elsewhere (the stabilisation's diagonal).
    pub fn values_mut(&mut self) -> &mut [f64] {
        &mut self.values
    }

    /// Full residual (all `3·n_nodes` dofs) from the last assembly.
    pub fn residual(&self) -> &[f64] {
        &self.residual
    }

    /// Bytes held by the workspace (element buffers and contribution lists).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        self.r_hex.len() * size_of::<HexVector>()
            + self.k_grp.iter().map(|k| k.len() * 8).sum::<usize>()
            + self.r_grp.iter().map(|r| r.len() * 8).sum::<usize>()
            + self.hex_to_dof.src.len() * 4
            + self.grp_to_dof.src.len() * 8
            + (self.hex_to_dof.ptr.len() + self.grp_to_dof.ptr.len()) * 8
            + (self.values.len() + self.residual.len()) * 8
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::assembly::dofs::DofMap;
    use crate::assembly::pattern::{structured_hex_grid, NodeGroups};

    use crate::fem::fd::Lcg;

    fn hex_contribution(e: usize, r: &mut HexVector, k: &mut HexMatrix) -> Result<(), String> {
        let mut rng = Lcg(0x9E37_79B9 ^ (e as u64).wrapping_mul(0x1234_5678_9ABC));
        for v in r.iter_mut() {
            *v = rng.uniform();
        }
        for v in k.iter_mut() {
            *v = rng.uniform() * 1e3;
        }
        Ok(())
    }

    fn group_contribution(g: usize, r: &mut DVector<f64>, k: &mut DMatrix<f64>) -> Result<(), String> {
        let mut rng = Lcg(77 + g as u64);
        for v in r.iter_mut() {
            *v = rng.uniform();
        }
        for v in k.iter_mut() {
            *v = rng.uniform();
        }
        Ok(())
    }

    fn setup() -> Pattern {
        let (nodes, hexes) = structured_hex_grid(3, 2, 2);
        let mut mask = vec![false; 3 * nodes.len()];
        for (a, x) in nodes.iter().enumerate() {
            if x[2] == 0.0 {
                mask[3 * a..3 * a + 3].fill(true);
            }
        }
        mask[3 * 35 + 1] = true;
        let groups: NodeGroups = [&[35u32, 3, 17][..], &[30, 5][..], &[35, 30, 0][..]].into_iter().collect();
        Pattern::build(DofMap::from_constrained_mask(&mask).unwrap(), &hexes, groups).unwrap()
    }

    #[test]
    fn assembled_values_equal_dense_reference_exactly() {
        let p = setup();
        let dofs = p.dofs();
        let mut asm = Assembly::new(&p).unwrap();
        let (values, residual) = asm.assemble_with_groups(&p, hex_contribution, group_contribution).unwrap();

        // Dense reference in the documented orders: the stiffness colour by colour
        // (any order within a colour: no entry gets two terms from one), then the
        // groups; the residual by element index, then the groups.
        let (n, nd) = (dofs.n_free(), dofs.n_dofs());
        let mut dense = vec![vec![0.0f64; n]; n];
        let mut r_ref = vec![0.0f64; nd];
        let mut add_k = |nodes: &[u32], k: &dyn Fn(usize, usize) -> f64| {
            let m = 3 * nodes.len();
            for j in 0..m {
                let gj = 3 * nodes[j / 3] as usize + j % 3;
                for i in 0..m {
                    let gi = 3 * nodes[i / 3] as usize + i % 3;
                    if let (Some(a), Some(b)) = (dofs.free(gi), dofs.free(gj)) {
                        dense[a][b] += k(i, j);
                    }
                }
            }
        };
        assert!(p.colouring().n_colours() > 1);
        for c in 0..p.colouring().n_colours() {
            for &e in p.colouring().colour(c).iter().rev() {
                let (mut r, mut k) = (HexVector::zeros(), HexMatrix::zeros());
                hex_contribution(e as usize, &mut r, &mut k).unwrap();
                add_k(&p.hexes()[e as usize], &|i, j| k[(i, j)]);
            }
        }
        for (g, nodes) in p.groups().iter().enumerate() {
            let m = 3 * nodes.len();
            let (mut r, mut k) = (DVector::zeros(m), DMatrix::zeros(m, m));
            group_contribution(g, &mut r, &mut k).unwrap();
            add_k(nodes, &|i, j| k[(i, j)]);
        }
        let mut add_r = |nodes: &[u32], r: &[f64]| {
            for (j, v) in r.iter().enumerate() {
                r_ref[3 * nodes[j / 3] as usize + j % 3] += v;
            }
        };
        for (e, hex) in p.hexes().iter().enumerate() {
            let (mut r, mut k) = (HexVector::zeros(), HexMatrix::zeros());
            hex_contribution(e, &mut r, &mut k).unwrap();
            add_r(hex, r.as_slice());
        }
        for (g, nodes) in p.groups().iter().enumerate() {
            let m = 3 * nodes.len();
            let (mut r, mut k) = (DVector::zeros(m), DMatrix::zeros(m, m));
            group_contribution(g, &mut r, &mut k).unwrap();
            add_r(nodes, r.as_slice());
        }
        // Every stored entry matches bit for bit, and nothing outside the pattern.
        let mut stored = 0;
        for c in 0..n {
            for s in p.col_ptr()[c]..p.col_ptr()[c + 1] {
                let r = p.row_idx()[s];
                assert_eq!(values[s].to_bits(), dense[r][c].to_bits(), "entry ({r}, {c})");
                stored += 1;
            }
        }
        let nonzero = dense.iter().flatten().filter(|&&v| v != 0.0).count();
        assert_eq!(stored, nonzero);
        for (a, b) in residual.iter().zip(&r_ref) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
        // Reactions at constrained dofs are there.
        assert!(residual.iter().enumerate().any(|(d, &v)| dofs.is_constrained(d) && v != 0.0));
    }

    #[test]
    fn one_and_two_threads_give_bit_identical_values() {
        let p = setup();
        let run = |threads: usize| -> (Vec<f64>, Vec<f64>) {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut asm = Assembly::new(&p).unwrap();
                // Twice: the second run reuses the buffers.
                asm.assemble_with_groups(&p, hex_contribution, group_contribution).unwrap();
                let (v, r) = asm.assemble_with_groups(&p, hex_contribution, group_contribution).unwrap();
                (v.to_vec(), r.to_vec())
            })
        };
        let (v1, r1) = run(1);
        let (v2, r2) = run(2);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&v1), bits(&v2));
        assert_eq!(bits(&r1), bits(&r2));
    }

    /// The residual alone is the residual of the full assembly, bit for bit, on 1
    /// and 2 threads, and leaves the values as they were; its failures are the
    /// lowest-index ones, as there.
    #[test]
    fn the_residual_alone_is_the_full_assemblys_residual() {
        let p = setup();
        let residual_only = |e: usize, r: &mut HexVector| hex_contribution(e, r, &mut HexMatrix::zeros());
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut asm = Assembly::new(&p).unwrap();
                let (v, r) = asm.assemble_with_groups(&p, hex_contribution, group_contribution).unwrap();
                let (v, r) = (v.to_vec(), r.to_vec());
                // another state's residual in the buffers first: every entry is rewritten
                asm.assemble_residual_with_groups(&p, |_, r: &mut HexVector| Ok::<_, String>(r.fill(7.0)), |_, r: &mut DVector<f64>, _: &mut DMatrix<f64>| Ok(r.fill(-3.0)))
                    .unwrap();
                let alone = asm.assemble_residual_with_groups(&p, residual_only, group_contribution).unwrap().to_vec();
                assert!(alone.iter().zip(&r).all(|(a, b)| a.to_bits() == b.to_bits()), "{threads} threads");
                assert!(asm.values().iter().zip(&v).all(|(a, b)| a.to_bits() == b.to_bits()), "the values changed");
                let err = asm.assemble_residual_with_groups(&p, |e, _: &mut HexVector| if e == 4 || e == 9 { Err(e) } else { Ok(()) }, |_, _, _| Ok(())).unwrap_err();
                assert_eq!(err, ElementFailure::Hex { element: 4, error: 4 });
                let err = asm.assemble_residual_with_groups(&p, |_, _: &mut HexVector| Ok(()), |g, _, _| if g >= 1 { Err(g) } else { Ok(()) }).unwrap_err();
                assert_eq!(err, ElementFailure::Group { group: 1, error: 1 });
            });
        }
    }

    #[test]
    fn failing_element_index_is_returned() {
        let p = setup();
        let mut asm = Assembly::new(&p).unwrap();
        let err = asm
            .assemble(&p, |e, _r, _k| if e == 5 || e == 9 { Err(format!("J < 0 in {e}")) } else { Ok(()) })
            .unwrap_err();
        assert_eq!(err, (5, "J < 0 in 5".to_string()));
        let err = asm
            .assemble_with_groups(&p, |_, _, _| Ok(()), |g, _, _| if g == 1 { Err("bad") } else { Ok(()) })
            .unwrap_err();
        assert_eq!(err, ElementFailure::Group { group: 1, error: "bad" });
    }
}
