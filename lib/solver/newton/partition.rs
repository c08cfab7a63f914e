//! The share of the assembly one of several MPI ranks does. Each rank owns a
//! contiguous range of nodes, and so the rows of the linear system of their dofs
//! ([`ranks::owned_nodes`]); it assembles the hexahedra and the node groups (contact
//! elements, pressure faces) that touch one of its nodes, so every entry of its rows
//! gets all its contributions there. The hexahedra at a rank boundary are computed by
//! both neighbours; summed over the ranks, the complete parts of the residual give
//! every rank the whole of R (`assemble.rs`).

use crate::assembly::NodeGroups;
use crate::solver::problem::Problem;
use crate::solver::ranks;

/// The share of the assembly one of several MPI ranks does: the hexahedra that touch
/// its nodes (`first..last`, the rows of the linear system it owns,
/// [`ranks::owned_nodes`]) and the node groups (contact elements, pressure faces)
/// that do. Every entry of its rows gets all its contributions there; the hexahedra
/// at a rank boundary are computed by both neighbours.
pub(super) struct Partition {
    pub(super) first: usize,
    pub(super) last: usize,
    /// Global index of each local hexahedron.
    pub(super) hex_ids: Vec<u32>,
    /// Their connectivity (the local pattern's elements).
    pub(super) hexes: Vec<[u32; 8]>,
}

impl Partition {
    /// This rank's share of `problem`.
    pub(super) fn new(problem: &Problem) -> Self {
        let (first, last) = ranks::owned_nodes(problem.n_nodes());
        let range = Self { first, last, hex_ids: Vec::new(), hexes: Vec::new() };
        let hex_ids: Vec<u32> = (0..problem.hexes.len() as u32).filter(|&e| problem.hexes[e as usize].iter().any(|&n| range.owns(n))).collect();
        let hexes = hex_ids.iter().map(|&e| problem.hexes[e as usize]).collect();
        Self { hex_ids, hexes, ..range }
    }

    /// Whether node `n` is this rank's.
    pub(super) fn owns(&self, n: u32) -> bool {
        (n as usize) >= self.first && (n as usize) < self.last
    }

    /// Keeps the groups that touch this rank's nodes (and their owners: what each
    /// group is, `groups.rs`).
    pub(super) fn keep_local_groups<O: Copy>(&self, groups: &mut NodeGroups, owners: &mut Vec<O>) {
        let mut kept = NodeGroups::new();
        let mut kept_owners = Vec::with_capacity(owners.len());
        for (g, nodes) in groups.iter().enumerate() {
            if nodes.iter().any(|&n| self.owns(n)) {
                kept.push(nodes);
                kept_owners.push(owners[g]);
            }
        }
        *groups = kept;
        *owners = kept_owners;
    }
}
