//! Sparsity pattern of the reduced stiffness `K_ff`, built once, and the map from
//! every element-matrix entry to its position in the values array.
//!
//! **Symbolic once, numeric many.** The pattern depends only on the connectivity
//! (hexahedra plus contact node groups) and on which dofs are constrained. It is
//! built once; every Newton iteration then refills the values by an index scatter
//! (`values[slot[e][i + 24 j]] += k_e[(i, j)]`) with no search and no allocation, and
//! the solver reuses its symbolic factorization. The pattern is rebuilt only when
//! the contact groups change (a slave node finds new master control points), by
//! calling [`Pattern::build`] again (or [`Pattern::with_groups`]).
//!
//! **Layout.** Compressed sparse columns over the free dofs, both triangles stored
//! (LU needs the whole matrix; Cholesky reads the lower one), rows sorted in each
//! column, as faer's [`SymbolicSparseColMat<usize>`]. Two free dofs are coupled
//! when their nodes share a hexahedron or a contact group; all three components of
//! coupled nodes are coupled (the 3×3 node blocks are stored whole).
//!
//! **Element slots.** For hexahedron `e`, `hex_slots(e)[i + 24 j]` (column-major,
//! like nalgebra's `SMatrix<f64, 24, 24>`) is the index in the values array of the
//! entry (row = local dof `i`, column = local dof `j`), local dof `3a + c` being
//! component `c` of local node `a`; it is [`NO_SLOT`] when either dof is
//! constrained. A hexahedron stores only its 64 node blocks' offsets
//! ([`Pattern::hex_blocks`]: where row node `b`'s first free dof sits among the
//! rows of column node `a`'s columns), a ninth of the 576 slots, from which
//! [`Pattern::scatter_hex`] finds every slot as it adds (the assembly reads 256
//! bytes of map per element instead of 2.3 kB). Contact groups ("elements with k
//! nodes") keep the whole map of size `(3k)²`, [`Pattern::group_slots`].

use std::sync::Arc;

use faer::sparse::{SymbolicSparseColMat, SymbolicSparseColMatRef};
use rayon::prelude::*;

use super::colouring::Colouring;
use super::dofs::{DofMap, DOFS_PER_NODE};

/// Slot of an element-matrix entry that touches a constrained dof (dropped).
pub const NO_SLOT: u32 = u32::MAX;
/// Dofs of a hex8 element.
pub const HEX_DOFS: usize = 8 * DOFS_PER_NODE;
/// Entries of a hex8 element matrix.
pub const HEX_ENTRIES: usize = HEX_DOFS * HEX_DOFS;
/// Node blocks of a hex8 element matrix (8 × 8).
pub const HEX_BLOCKS: usize = 64;

/// Errors building a [`Pattern`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PatternError {
    #[error("hexahedron {element} refers to node {node}, but the dof map has {n_nodes} nodes")]
    HexNodeOutOfRange { element: usize, node: u32, n_nodes: usize },
    #[error("contact group {group} refers to node {node}, but the dof map has {n_nodes} nodes")]
    GroupNodeOutOfRange { group: usize, node: u32, n_nodes: usize },
    #[error("the pattern has {nnz} entries, more than the 32-bit slot numbering allows")]
    TooManyEntries { nnz: usize },
}

/// A list of node groups, each coupled all-to-all (a contact element: one slave
/// node and the master control points it sees), stored flat.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct NodeGroups {
    offsets: Vec<usize>,
    nodes: Vec<u32>,
}

impl NodeGroups {
    pub fn new() -> Self {
        Self { offsets: vec![0], nodes: Vec::new() }
    }

    /// Appends one group.
    pub fn push(&mut self, nodes: &[u32]) {
        self.push_iter(nodes.iter().copied());
    }

    /// Appends one group from an iterator (no intermediate list).
    pub fn push_iter(&mut self, nodes: impl IntoIterator<Item = u32>) {
        if self.offsets.is_empty() {
            self.offsets.push(0);
        }
        self.nodes.extend(nodes);
        self.offsets.push(self.nodes.len());
    }

    /// Removes every group, keeping the storage (rebuilt every Newton iteration).
    pub fn clear(&mut self) {
        self.offsets.clear();
        self.offsets.push(0);
        self.nodes.clear();
    }

    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Nodes of group `g`.
    pub fn group(&self, g: usize) -> &[u32] {
        &self.nodes[self.offsets[g]..self.offsets[g + 1]]
    }

    pub fn iter(&self) -> impl Iterator<Item = &[u32]> + Clone + '_ {
        (0..self.len()).map(move |g| self.group(g))
    }
}

impl<'a> FromIterator<&'a [u32]> for NodeGroups {
    fn from_iter<T: IntoIterator<Item = &'a [u32]>>(iter: T) -> Self {
        let mut g = NodeGroups::new();
        for nodes in iter {
            g.push(nodes);
        }
        g
    }
}

/// Sparsity pattern of `K_ff` plus the element → value-slot maps.
#[derive(Debug, Clone)]
pub struct Pattern {
    dofs: DofMap,
    hexes: Vec<[u32; 8]>,
    /// The hexahedra in colours that share no node (the assembly's parallel order).
    colouring: Colouring,
    groups: NodeGroups,
    symbolic: Arc<SymbolicSparseColMat<usize>>,
    /// `n_hex · 64`: `hex_blocks[64 e + 8 a + b]` is the offset of local node `b`'s
    /// first free dof among the rows of local node `a`'s columns (`NO_SLOT` when
    /// either node has no free dof).
    hex_blocks: Vec<u32>,
    /// `group_slots[group_slot_offsets[g]..group_slot_offsets[g + 1]]`, `(3k)²` each.
    group_slot_offsets: Vec<usize>,
    group_slots: Vec<u32>,
}

impl Pattern {
    /// Builds the pattern from hexahedra and contact node groups.
    pub fn build(dofs: DofMap, hexes: &[[u32; 8]], groups: NodeGroups) -> Result<Self, PatternError> {
        Self::build_coloured(dofs, hexes, None, groups, |_| {})
    }

    /// [`Self::build`], handing the sparsity structure (rows of every column) to
    /// `on_structure` as soon as it is complete, before the element slot maps are
    /// made: the solver's symbolic analysis needs nothing more, and started there it
    /// runs beside the rest of the set-up instead of beside the first assembly.
    pub fn build_then(dofs: DofMap, hexes: &[[u32; 8]], groups: NodeGroups, on_structure: impl FnOnce(&Arc<SymbolicSparseColMat<usize>>)) -> Result<Self, PatternError> {
        Self::build_coloured(dofs, hexes, None, groups, on_structure)
    }

    /// [`Self::build_then`], with the hexahedra's colouring when it is known already.
    fn build_coloured(
        dofs: DofMap,
        hexes: &[[u32; 8]],
        colouring: Option<Colouring>,
        groups: NodeGroups,
        on_structure: impl FnOnce(&Arc<SymbolicSparseColMat<usize>>),
    ) -> Result<Self, PatternError> {
        let n_nodes = dofs.n_nodes();
        for (e, hex) in hexes.iter().enumerate() {
            if let Some(&node) = hex.iter().find(|&&a| a as usize >= n_nodes) {
                return Err(PatternError::HexNodeOutOfRange { element: e, node, n_nodes });
            }
        }
        for (g, nodes) in groups.iter().enumerate() {
            if let Some(&node) = nodes.iter().find(|&&a| a as usize >= n_nodes) {
                return Err(PatternError::GroupNodeOutOfRange { group: g, node, n_nodes });
            }
        }

        let structure_span = crate::os::timeline::span("set-up: pattern structure");
        // node -> hexes and node -> groups (CSR, by counting).
        let node_hexes = invert(n_nodes, hexes.iter().map(|h| &h[..]));
        let node_groups = invert(n_nodes, groups.iter());

        // Sorted, unique neighbour nodes of every node (itself included if it is
        // in any element).
        let neighbours: Vec<Vec<u32>> = (0..n_nodes)
            .into_par_iter()
            .map(|a| {
                let mut nb: Vec<u32> = Vec::new();
                for &e in node_hexes.of(a) {
                    nb.extend_from_slice(&hexes[e as usize]);
                }
                for &g in node_groups.of(a) {
                    nb.extend_from_slice(groups.group(g as usize));
                }
                nb.sort_unstable();
                nb.dedup();
                nb
            })
            .collect();

        // The columns of node a's free dofs all hold the same rows: the free dofs of
        // its neighbours, in increasing order (the free numbering is monotone in the
        // global dof). Counted per node first, so that the columns are filled in
        // parallel into arrays of their final size.
        let n_free_of: Vec<u8> = (0..n_nodes).map(|a| (0..DOFS_PER_NODE).filter(|&c| !dofs.is_constrained(DOFS_PER_NODE * a + c)).count() as u8).collect();
        let rows_of_node: Vec<usize> = neighbours.par_iter().map(|nb| nb.iter().map(|&b| usize::from(n_free_of[b as usize])).sum()).collect();
        let n_free = dofs.n_free();
        let mut col_ptr = Vec::with_capacity(n_free + 1);
        col_ptr.push(0usize);
        // where the first column of each node starts in row_idx
        let mut node_start = Vec::with_capacity(n_nodes + 1);
        let mut nnz = 0usize;
        for (a, &rows) in rows_of_node.iter().enumerate() {
            node_start.push(nnz);
            for _ in 0..n_free_of[a] {
                nnz += rows;
                col_ptr.push(nnz);
            }
        }
        node_start.push(nnz);
        debug_assert_eq!(col_ptr.len(), n_free + 1);
        if nnz >= NO_SLOT as usize {
            return Err(PatternError::TooManyEntries { nnz });
        }
        let mut row_idx = vec![0usize; nnz];
        let mut node_rows: Vec<&mut [usize]> = Vec::with_capacity(n_nodes);
        let mut rest = &mut row_idx[..];
        for a in 0..n_nodes {
            let (this, tail) = rest.split_at_mut(node_start[a + 1] - node_start[a]);
            node_rows.push(this);
            rest = tail;
        }
        node_rows.into_par_iter().enumerate().for_each(|(a, out)| {
            if out.is_empty() {
                return; // no free dof: no column
            }
            // out holds the node's free columns of n_rows each: non-empty, n_rows ≥ 1
            let n_rows = rows_of_node[a];
            let mut k = 0;
            for &b in &neighbours[a] {
                for c in 0..DOFS_PER_NODE {
                    if let Some(f) = dofs.free(DOFS_PER_NODE * b as usize + c) {
                        out[k] = f;
                        k += 1;
                    }
                }
            }
            // the node's other free columns repeat its first
            let (first, others) = out.split_at_mut(n_rows);
            for column in others.chunks_exact_mut(n_rows) {
                column.copy_from_slice(first);
            }
        });

        let symbolic = Arc::new(SymbolicSparseColMat::new_checked(n_free, n_free, col_ptr, None, row_idx));
        drop(structure_span);
        on_structure(&symbolic);
        let _slots_span = crate::os::timeline::span("set-up: element slot maps and colouring");
        let col_ptr = symbolic.col_ptr();

        // Slots of an element's entries. Node blocks are stored whole, the free
        // components of one row node sit in consecutive positions of every column
        // that couples it, and the free columns of one node hold the same rows.
        // `offset[k]`: position of the element's k-th node's first free dof within
        // the rows of the column node a, or `NO_SLOT` for a node without free dofs;
        // found by one merge of the element's sorted nodes with a's sorted
        // neighbours, whose free dofs are counted on the way (a binary search of the
        // rows per node pair took a third of the pattern's time).
        let offsets_in = |a: u32, sorted: &[(u32, u32)], offset: &mut [u32]| {
            let (mut at, mut s) = (0u32, 0usize);
            for &b in &neighbours[a as usize] {
                while s < sorted.len() && sorted[s].0 == b {
                    offset[sorted[s].1 as usize] = if n_free_of[b as usize] == 0 { NO_SLOT } else { at };
                    s += 1;
                }
                if s == sorted.len() {
                    break;
                }
                at += u32::from(n_free_of[b as usize]);
            }
            debug_assert_eq!(s, sorted.len(), "coupled nodes are neighbours by construction");
        };
        let sort_nodes = |nodes: &[u32], sorted: &mut Vec<(u32, u32)>| {
            sorted.clear();
            sorted.extend(nodes.iter().enumerate().map(|(k, &b)| (b, k as u32)));
            sorted.sort_unstable();
        };
        // A hexahedron's node blocks: for each column node, its row nodes' offsets.
        let hex_blocks_of = |nodes: &[u32], out: &mut [u32], sorted: &mut Vec<(u32, u32)>| {
            sort_nodes(nodes, sorted);
            for (block, &a) in out.chunks_exact_mut(nodes.len()).zip(nodes) {
                if n_free_of[a as usize] == 0 {
                    block.fill(NO_SLOT);
                } else {
                    offsets_in(a, sorted, block);
                }
            }
        };
        // A contact group's whole slot map (its node count varies).
        let element_slots = |nodes: &[u32], out: &mut [u32], (sorted, offset): &mut (Vec<(u32, u32)>, Vec<u32>)| {
            let nd = DOFS_PER_NODE * nodes.len();
            sort_nodes(nodes, sorted);
            offset.clear();
            offset.resize(nodes.len(), NO_SLOT);
            for (block, &a) in out.chunks_exact_mut(DOFS_PER_NODE * nd).zip(nodes) {
                let base = DOFS_PER_NODE * a as usize;
                if n_free_of[a as usize] == 0 {
                    block.fill(NO_SLOT);
                    continue;
                }
                offsets_in(a, sorted, offset);
                for (c, col) in block.chunks_exact_mut(nd).enumerate() {
                    let Some(fj) = dofs.free(base + c) else {
                        col.fill(NO_SLOT);
                        continue;
                    };
                    let start = col_ptr[fj];
                    for ((&b, &k), rows) in nodes.iter().zip(offset.iter()).zip(col.chunks_exact_mut(DOFS_PER_NODE)) {
                        if k == NO_SLOT {
                            rows.fill(NO_SLOT);
                            continue;
                        }
                        let base_b = DOFS_PER_NODE * b as usize;
                        let mut at = start + k as usize;
                        for (cb, slot) in rows.iter_mut().enumerate() {
                            *slot = if dofs.is_constrained(base_b + cb) {
                                NO_SLOT
                            } else {
                                at += 1;
                                (at - 1) as u32
                            };
                        }
                    }
                }
            }
        };

        // zeroed (calloc'd pages, first touched by the tasks that write them): every
        // entry is written below
        let mut hex_blocks = vec![0u32; hexes.len() * HEX_BLOCKS];
        hex_blocks
            .par_chunks_mut(HEX_BLOCKS)
            .zip(hexes.par_iter())
            .for_each_init(Vec::new, |sorted, (out, hex)| hex_blocks_of(hex, out, sorted));

        let mut group_slot_offsets = Vec::with_capacity(groups.len() + 1);
        group_slot_offsets.push(0usize);
        for nodes in groups.iter() {
            let nd = DOFS_PER_NODE * nodes.len();
            group_slot_offsets.push(group_slot_offsets[group_slot_offsets.len() - 1] + nd * nd);
        }
        let mut group_slots = vec![0u32; group_slot_offsets[groups.len()]];
        let mut outs = Vec::with_capacity(groups.len());
        let mut rest = &mut group_slots[..];
        for g in 0..groups.len() {
            let (out, tail) = rest.split_at_mut(group_slot_offsets[g + 1] - group_slot_offsets[g]);
            outs.push(out);
            rest = tail;
        }
        outs.into_par_iter().enumerate().for_each_init(Default::default, |scratch, (g, out)| element_slots(groups.group(g), out, scratch));

        let colouring = colouring.unwrap_or_else(|| Colouring::greedy(n_nodes, hexes.iter().map(|h| &h[..])));
        Ok(Self {
            dofs,
            hexes: hexes.to_vec(),
            colouring,
            groups,
            symbolic,
            hex_blocks,
            group_slot_offsets,
            group_slots,
        })
    }

    /// The same dofs and hexahedra with new contact groups (the pattern and every
    /// slot map are rebuilt; the solver must then `analyse` again).
    pub fn with_groups(&self, groups: NodeGroups) -> Result<Self, PatternError> {
        Self::build_coloured(self.dofs.clone(), &self.hexes, Some(self.colouring.clone()), groups, |_| {})
    }

    /// The hexahedra in colours that share no node.
    pub fn colouring(&self) -> &Colouring {
        &self.colouring
    }

    pub fn dofs(&self) -> &DofMap {
        &self.dofs
    }

    pub fn hexes(&self) -> &[[u32; 8]] {
        &self.hexes
    }

    pub fn groups(&self) -> &NodeGroups {
        &self.groups
    }

    /// The CSC pattern of `K_ff` (both triangles, sorted rows).
    pub fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        (*self.symbolic).as_ref()
    }

    /// The CSC pattern itself (a copy is one `clone` away; a solver that keeps it
    /// shares it instead: [`Self::shared`]).
    pub fn symbolic_owned(&self) -> &SymbolicSparseColMat<usize> {
        &self.symbolic
    }

    /// The pattern, shared with a linear solver that keeps it
    /// ([`crate::solver::linear::LinearSolver::analyse_in_background`]).
    pub fn shared(&self) -> &Arc<SymbolicSparseColMat<usize>> {
        &self.symbolic
    }

    /// Order of `K_ff`.
    pub fn n_free(&self) -> usize {
        self.dofs.n_free()
    }

    /// Stored entries (length of the values array).
    pub fn nnz(&self) -> usize {
        self.symbolic.row_idx().len()
    }

    /// Column pointers (length `n_free + 1`).
    pub fn col_ptr(&self) -> &[usize] {
        self.symbolic.col_ptr()
    }

    /// Row indices (length `nnz`).
    pub fn row_idx(&self) -> &[usize] {
        self.symbolic.row_idx()
    }

    /// The value slot of the diagonal entry of free dof (column) `j` (rows are sorted
    /// within a column; every free dof couples with itself, so it is stored).
    pub fn diagonal_slot(&self, j: usize) -> Option<usize> {
        let (col_ptr, row_idx) = (self.col_ptr(), self.row_idx());
        row_idx[col_ptr[j]..col_ptr[j + 1]].binary_search(&j).ok().map(|k| col_ptr[j] + k)
    }

    /// The 64 node-block offsets of hexahedron `e` (see the module's Element slots).
    pub fn hex_blocks(&self, e: usize) -> &[u32] {
        &self.hex_blocks[e * HEX_BLOCKS..(e + 1) * HEX_BLOCKS]
    }

    /// Value slots of hexahedron `e`: 576 entries, column-major, [`NO_SLOT`] for
    /// entries touching a constrained dof (made from its node blocks: the slots
    /// [`Self::scatter_hex`] adds to).
    pub fn hex_slots(&self, e: usize) -> [u32; HEX_ENTRIES] {
        let mut slots = [NO_SLOT; HEX_ENTRIES];
        self.scatter_hex(e, |i, slot| slots[i] = slot as u32);
        slots
    }

    /// Every free entry of hexahedron `e`'s matrix, in column-major order: `add(i,
    /// slot)` for the entry `i + 24 j` (row `i`, column `j`) and its index in the
    /// values array; entries touching a constrained dof are skipped. From the node
    /// blocks: a free column's first entry (`col_ptr`), the row node's offset among
    /// the column node's rows, then its free components one after another.
    #[inline]
    pub fn scatter_hex(&self, e: usize, mut add: impl FnMut(usize, usize)) {
        let nodes = &self.hexes[e];
        let blocks = self.hex_blocks(e);
        let col_ptr = self.symbolic.col_ptr();
        // which of the 24 local dofs are free (the rows), and their columns' starts
        let mut free = [false; HEX_DOFS];
        let mut start = [usize::MAX; HEX_DOFS];
        for (k, &a) in nodes.iter().enumerate() {
            for c in 0..DOFS_PER_NODE {
                if let Some(f) = self.dofs.free(DOFS_PER_NODE * a as usize + c) {
                    free[DOFS_PER_NODE * k + c] = true;
                    start[DOFS_PER_NODE * k + c] = col_ptr[f];
                }
            }
        }
        if free.iter().all(|&f| f) {
            // every dof free (most hexahedra): each block column is 3 consecutive
            // slots, with no test per entry
            for j in 0..HEX_DOFS {
                let column_blocks = &blocks[8 * (j / DOFS_PER_NODE)..8 * (j / DOFS_PER_NODE) + 8];
                for (kb, &offset) in column_blocks.iter().enumerate() {
                    debug_assert_ne!(offset, NO_SLOT, "a free node pair of hexahedron {e} without its block");
                    let (at, i) = (start[j] + offset as usize, DOFS_PER_NODE * kb + HEX_DOFS * j);
                    add(i, at);
                    add(i + 1, at + 1);
                    add(i + 2, at + 2);
                }
            }
            return;
        }
        for j in 0..HEX_DOFS {
            if !free[j] {
                continue;
            }
            let column_blocks = &blocks[8 * (j / DOFS_PER_NODE)..8 * (j / DOFS_PER_NODE) + 8];
            for (kb, &offset) in column_blocks.iter().enumerate() {
                if offset == NO_SLOT {
                    continue;
                }
                let mut at = start[j] + offset as usize;
                for i in DOFS_PER_NODE * kb..DOFS_PER_NODE * kb + DOFS_PER_NODE {
                    if free[i] {
                        add(i + HEX_DOFS * j, at);
                        at += 1;
                    }
                }
            }
        }
    }

    /// Value slots of contact group `g`: `(3k)²` entries, column-major.
    pub fn group_slots(&self, g: usize) -> &[u32] {
        &self.group_slots[self.group_slot_offsets[g]..self.group_slot_offsets[g + 1]]
    }
}

/// Node → items incidence in CSR form.
struct Incidence {
    ptr: Vec<usize>,
    items: Vec<u32>,
}

impl Incidence {
    fn of(&self, a: usize) -> &[u32] {
        &self.items[self.ptr[a]..self.ptr[a + 1]]
    }
}

/// Inverts item → nodes into node → items (items in increasing order).
fn invert<'a>(n_nodes: usize, items: impl Iterator<Item = &'a [u32]> + Clone) -> Incidence {
    let mut ptr = vec![0usize; n_nodes + 1];
    for nodes in items.clone() {
        for &a in nodes {
            ptr[a as usize + 1] += 1;
        }
    }
    for a in 0..n_nodes {
        ptr[a + 1] += ptr[a];
    }
    let mut fill = ptr.clone();
    let mut out = vec![0u32; ptr[n_nodes]];
    for (e, nodes) in items.enumerate() {
        for &a in nodes {
            out[fill[a as usize]] = e as u32;
            fill[a as usize] += 1;
        }
    }
    Incidence { ptr, items: out }
}

/// Structured `nx × ny × nz` hex grid on the unit-spaced lattice, for tests and
/// benchmarks: nodes `(i, j, k)` numbered `i + (nx+1)(j + (ny+1) k)`, hexes in
/// VTK order.
pub fn structured_hex_grid(nx: usize, ny: usize, nz: usize) -> (Vec<[f64; 3]>, Vec<[u32; 8]>) {
    let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                nodes.push([i as f64, j as f64, k as f64]);
            }
        }
    }
    let mut hexes = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                hexes.push([
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ]);
            }
        }
    }
    (nodes, hexes)
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;

    /// Dense brute force: coupled[r][c] for free dofs.
    fn dense_pattern(dofs: &DofMap, elements: &[Vec<u32>]) -> Vec<Vec<bool>> {
        let n = dofs.n_free();
        let mut m = vec![vec![false; n]; n];
        for nodes in elements {
            for &a in nodes {
                for &b in nodes {
                    for i in 0..3 {
                        for j in 0..3 {
                            if let (Some(r), Some(c)) =
                                (dofs.free(3 * a as usize + i), dofs.free(3 * b as usize + j))
                            {
                                m[r][c] = true;
                            }
                        }
                    }
                }
            }
        }
        m
    }

    fn to_dense(p: &Pattern) -> Vec<Vec<bool>> {
        let n = p.n_free();
        let mut m = vec![vec![false; n]; n];
        for c in 0..n {
            let rows = &p.row_idx()[p.col_ptr()[c]..p.col_ptr()[c + 1]];
            assert!(rows.windows(2).all(|w| w[0] < w[1]), "rows sorted and unique");
            for &r in rows {
                m[r][c] = true;
            }
        }
        m
    }

    fn grid_with_constraints() -> (Vec<[u32; 8]>, DofMap) {
        let (nodes, hexes) = structured_hex_grid(3, 2, 2);
        // Clamp x = 0 fully, and u_z on the node at (3, 2, 2).
        let mut mask = vec![false; 3 * nodes.len()];
        for (a, x) in nodes.iter().enumerate() {
            if x[0] == 0.0 {
                mask[3 * a..3 * a + 3].fill(true);
            }
            if *x == [3.0, 2.0, 2.0] {
                mask[3 * a + 2] = true;
            }
        }
        (hexes, DofMap::from_constrained_mask(&mask).unwrap())
    }

    #[test]
    fn pattern_matches_dense_brute_force_on_3x2x2_grid() {
        let (hexes, dofs) = grid_with_constraints();
        assert_eq!(dofs.n_nodes(), 4 * 3 * 3);
        assert_eq!(dofs.n_free(), 3 * 36 - 3 * 9 - 1);
        let p = Pattern::build(dofs.clone(), &hexes, NodeGroups::new()).unwrap();
        let elements: Vec<Vec<u32>> = hexes.iter().map(|h| h.to_vec()).collect();
        let dense = dense_pattern(&dofs, &elements);
        assert_eq!(to_dense(&p), dense);
        let nnz_dense = dense.iter().flatten().filter(|&&b| b).count();
        assert_eq!(p.nnz(), nnz_dense);

        // Every slot points at the entry it claims to, on both of scatter_hex's
        // paths: hexahedra with every dof free, and with some constrained.
        let all_free = |hex: &[u32; 8]| (0..24).all(|i| dofs.free(3 * hex[i / 3] as usize + i % 3).is_some());
        let n_all_free = hexes.iter().filter(|h| all_free(h)).count();
        assert!(n_all_free > 0 && n_all_free < hexes.len(), "{n_all_free} of {} hexahedra with every dof free", hexes.len());
        for (e, hex) in hexes.iter().enumerate() {
            let slots = p.hex_slots(e);
            for j in 0..24 {
                for i in 0..24 {
                    let gi = 3 * hex[i / 3] as usize + i % 3;
                    let gj = 3 * hex[j / 3] as usize + j % 3;
                    let s = slots[i + 24 * j];
                    match (dofs.free(gi), dofs.free(gj)) {
                        (Some(r), Some(c)) => {
                            let s = s as usize;
                            assert!(p.col_ptr()[c] <= s && s < p.col_ptr()[c + 1]);
                            assert_eq!(p.row_idx()[s], r);
                        }
                        _ => assert_eq!(s, NO_SLOT),
                    }
                }
            }
        }
    }

    /// A cleared list refilled (as the contact search does every iteration) equals
    /// one built afresh, whether groups come as slices or iterators, and a taken
    /// (empty, default) list can be refilled too.
    #[test]
    fn node_groups_refill_equals_a_fresh_list() {
        let fresh: NodeGroups = [&[3u32, 35, 28][..], &[5, 30][..]].into_iter().collect();
        let mut g: NodeGroups = [&[1u32, 2, 3, 4][..]].into_iter().collect();
        g.clear();
        g.push_iter(std::iter::once(3).chain([35, 28]));
        g.push(&[5, 30]);
        assert_eq!(g, fresh);
        let mut taken = std::mem::take(&mut g);
        assert!(g.is_empty());
        g.push_iter([3, 35, 28]);
        g.push_iter([5, 30]);
        assert_eq!(g, fresh);
        taken.clear();
        assert_eq!((taken.len(), taken, g.group(1)), (0, NodeGroups::new(), &[5u32, 30][..]));
    }

    #[test]
    fn contact_groups_add_their_couplings() {
        let (hexes, dofs) = grid_with_constraints();
        let without = Pattern::build(dofs.clone(), &hexes, NodeGroups::new()).unwrap();
        // Node 3 (x=3,y=0,z=0) with far nodes 35 (3,2,2) and 28 (0,1,2: clamped) and 17.
        let groups: NodeGroups = [&[3u32, 35, 28, 17][..], &[5, 30][..]].into_iter().collect();
        let p = without.with_groups(groups.clone()).unwrap();
        let mut elements: Vec<Vec<u32>> = hexes.iter().map(|h| h.to_vec()).collect();
        elements.extend(groups.iter().map(|g| g.to_vec()));
        let dense = dense_pattern(&dofs, &elements);
        assert_eq!(to_dense(&p), dense);

        // New couplings: u_x(3) with u_y(35) (new), u_x(3) with u_z(35) constrained.
        let f = |a: usize, c: usize| dofs.free(3 * a + c);
        let d = to_dense(&without);
        let (r, c) = (f(35, 1).unwrap(), f(3, 0).unwrap());
        assert!(!d[r][c] && dense[r][c]);
        assert!(f(35, 2).is_none() && f(28, 0).is_none());
        // 2 new node pairs (3,35), (3,17), (35,17) are new; (17, 35) far apart too.
        assert_eq!(p.nnz() - without.nnz(), dense.iter().flatten().filter(|&&b| b).count() - d.iter().flatten().filter(|&&b| b).count());
        assert!(p.nnz() > without.nnz());

        // Group slots point at the right entries.
        for (g, nodes) in groups.iter().enumerate() {
            let nd = 3 * nodes.len();
            let slots = p.group_slots(g);
            assert_eq!(slots.len(), nd * nd);
            for j in 0..nd {
                for i in 0..nd {
                    let s = slots[i + nd * j];
                    match (f(nodes[i / 3] as usize, i % 3), f(nodes[j / 3] as usize, j % 3)) {
                        (Some(r), Some(c)) => {
                            let s = s as usize;
                            assert!(p.col_ptr()[c] <= s && s < p.col_ptr()[c + 1]);
                            assert_eq!(p.row_idx()[s], r);
                        }
                        _ => assert_eq!(s, NO_SLOT),
                    }
                }
            }
        }
    }

    #[test]
    fn bad_node_index_is_an_error() {
        let dofs = DofMap::all_free(8).unwrap();
        let err = Pattern::build(dofs, &[[0, 1, 2, 3, 4, 5, 6, 8]], NodeGroups::new()).unwrap_err();
        assert_eq!(err, PatternError::HexNodeOutOfRange { element: 0, node: 8, n_nodes: 8 });
    }
}
