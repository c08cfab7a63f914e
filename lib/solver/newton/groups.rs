//! The node groups of the sparsity pattern besides the hexahedra: the
//! follower-pressure faces (their load depends on u, so each couples its four
//! nodes), then every contact element the search found (a slave node and the master
//! nodes its foot point depends on). [`GroupOwner`] says which group is which. The
//! groups come from the contact search of every pair at the current iterate; with
//! several MPI ranks each rank projects the slave nodes it owns and the ranks
//! exchange the results (`partition.rs`).

use nalgebra::Vector3;

use super::partition::Partition;
use crate::assembly::{NodeGroups, DOFS_PER_NODE};
use crate::contact::pair::{PairError, PairSolver, SearchShare};
use crate::solver::problem::Problem;
use crate::solver::ranks;

/// What a group of the sparsity pattern is.
#[derive(Debug, Clone, Copy)]
pub(super) enum GroupOwner {
    /// A follower-pressure face (index into `problem.pressure_faces`).
    Pressure(usize),
    /// A contact element: (pair, slave index in the pair).
    Contact(usize, usize),
}

/// Contact search of every pair at `u` and the node groups of the pattern into
/// `groups`: the follower-pressure faces, then every contact element; `owners` says
/// which is which. (Both keep their storage between calls.)
/// With several MPI ranks (`partition`), each rank projects the slave nodes it owns
/// and the ranks exchange the results ([`PairSolver::search_shared`]).
pub(super) fn contact_groups(p: &Problem, contact: &mut [PairSolver], u: &[f64], groups: &mut NodeGroups, owners: &mut Vec<GroupOwner>, partition: Option<&Partition>) -> Result<(), PairError> {
    groups.clear();
    for f in &p.pressure_faces {
        groups.push(&f.nodes);
    }
    owners.clear();
    owners.extend((0..p.pressure_faces.len()).map(GroupOwner::Pressure));
    for (k, pair) in contact.iter_mut().enumerate() {
        let x = |n: u32| {
            let d = DOFS_PER_NODE * n as usize;
            p.X[n as usize] + Vector3::new(u[d], u[d + 1], u[d + 2])
        };
        match partition {
            None => pair.search(x)?,
            Some(part) => {
                let mine = |n: u32| part.owns(n);
                let mut exchange = |buffer: &mut [f64]| ranks::reduce_over_ranks(buffer, ranks::Reduction::Sum);
                pair.search_shared(x, Some(SearchShare { mine: &mine, exchange: &mut exchange }))?;
            }
        }
        pair.push_groups(groups, |s| owners.push(GroupOwner::Contact(k, s)));
    }
    Ok(())
}
