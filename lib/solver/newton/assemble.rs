//! One iterate's linear system. The contact search at u gives the pattern's node
//! groups (`groups.rs`); when they change, the pattern, the assembly workspace and
//! the linear solver's symbolic analysis are rebuilt. Then the full residual
//! R = f_int(u) − f_ext(λ) and the free-dof tangent K_ff are assembled: the
//! hexahedra, the follower-pressure faces (an external force: −f and −∂f/∂x), the
//! contact elements, and the terms of the master-surface stabilisation and of the
//! free bodies' damping. Under MPI each rank assembles its share (`partition.rs`),
//! the ranks agree on the worst local failure, and summing the complete parts gives
//! every rank the whole residual.

use nalgebra::{DMatrix, DVector, Vector3};

use super::failure::IncrementFailure;
use super::groups::{contact_groups, GroupOwner};
use super::Newton;
use crate::assembly::{Assembly, ElementFailure, DOFS_PER_NODE};
use crate::contact::law::ContactElementError;
use crate::contact::pair::PairSolver;
use crate::fem::element::{hex8_residual, hex8_residual_tangent, ElementError};
use crate::fem::pressure::{follower_pressure_force_stiffness, FaceMatrix, FaceVector};
use crate::solver::ranks;

/// A local (element-level) failure during assembly.
#[derive(Debug, Clone)]
enum LocalFailure {
    Hex(ElementError),
    Contact(ContactElementError),
}

/// Which local evaluation failed during assembly.
pub(super) enum AssemblyFailure {
    /// (hexahedron, error)
    Hex(usize, ElementError),
    /// (pair, slave index, error)
    Contact(usize, usize, ContactElementError),
    /// Another MPI rank's assembly failed ([`AssemblyFailure::severity`] of its failure).
    OtherRank(u8),
    /// An MPI reduction failed.
    Mpi(String),
}

impl AssemblyFailure {
    /// What every rank must do about a failure: 1 an inverted element (Newton halves
    /// the step), 2 anything else (the increment fails).
    fn severity(&self) -> f64 {
        match self {
            Self::Hex(..) | Self::OtherRank(1) => 1.0,
            _ => 2.0,
        }
    }

    /// The increment's failure, at `iteration` (`contact` names the pairs).
    pub(super) fn into_increment_failure(self, iteration: u32, contact: &[PairSolver], node_tags: &[u64]) -> IncrementFailure {
        match self {
            Self::Hex(element, error) => IncrementFailure::Element { iteration, element, error },
            Self::Contact(pair, s, error) => {
                let c = &contact[pair];
                IncrementFailure::Contact { iteration, pair: c.name.clone(), node_tag: node_tags.get(c.slaves[s] as usize).copied().unwrap_or(c.slaves[s] as u64), error }
            }
            Self::OtherRank(1) => IncrementFailure::ContactSetup { iteration, message: "an element assembled by another MPI rank inverted or failed".into() },
            Self::OtherRank(_) => IncrementFailure::ContactSetup { iteration, message: "the assembly failed on another MPI rank (its log says why)".into() },
            Self::Mpi(message) => IncrementFailure::ContactSetup { iteration, message: format!("MPI: {message}") },
        }
    }
}

impl Newton<'_> {
    /// Contact search at `u`; rebuilds the pattern (and the solver's symbolic
    /// analysis) if the contact groups changed.
    pub(super) fn contact_search(&mut self, u: &[f64], iteration: u32) -> Result<(), IncrementFailure> {
        if self.contact.is_empty() {
            return Ok(());
        }
        let fail = |message: String| IncrementFailure::ContactSetup { iteration, message };
        let mut groups = std::mem::take(&mut self.group_scratch);
        contact_groups(self.problem, &mut self.contact, u, &mut groups, &mut self.owners, self.partition.as_ref()).map_err(|e| fail(e.to_string()))?;
        if let Some(part) = &self.partition {
            part.keep_local_groups(&mut groups, &mut self.owners);
        }
        let mut changed = [f64::from(u8::from(&groups != self.pattern.groups() || !self.assembly.fits(&self.pattern)))];
        if self.partition.is_some() {
            // the analysis of a new pattern is collective: every rank does it when
            // one rank's groups changed (its rows' entries did)
            ranks::reduce_over_ranks(&mut changed, ranks::Reduction::Max).map_err(|e| fail(format!("MPI: {e}")))?;
        }
        if changed[0] == 0.0 {
            self.group_scratch = groups;
        } else {
            self.pattern = self.pattern.with_groups(groups).map_err(|e| fail(e.to_string()))?;
            // the old workspace goes before the new one is built (peak memory); a
            // failure leaves the empty one, which `fits` no pattern: rebuilt next time
            self.assembly = Assembly::empty();
            self.assembly = Assembly::new(&self.pattern).map_err(|e| fail(e.to_string()))?;
            // analysed here: beside the elements' assembly it saved no time on the
            // punch's 79 rebuilds and cost 8 % more peak memory (docs/performance.md)
            self.linear.analyse(self.pattern.symbolic(), self.symmetry).map_err(|error| IncrementFailure::Linear { iteration, error })?;
            self.pattern_rebuilds += 1;
        }
        Ok(())
    }

    /// Assemble K_ff and the full residual R = f_int − f_ext(λ) at `u` (after
    /// [`Self::contact_search`] at the same `u`); with `tangent` false, R alone (the
    /// same bits; K_ff is then not that of `u`).
    pub(super) fn assemble(&mut self, u: &[f64], lambda: f64, tangent: bool) -> Result<(), AssemblyFailure> {
        let p = self.problem;
        let hex_ids = self.partition.as_ref().map(|part| &part.hex_ids[..]);
        // hexahedron e of this rank's share: its reference nodes, displacements and material
        let local = |e: usize| {
            let e = hex_ids.map_or(e, |ids| ids[e] as usize);
            let (X, ue) = p.gather(e, u);
            (X, ue, &p.materials[p.hex_material[e] as usize])
        };
        let hex = |e: usize, r: &mut _, k: &mut _| {
            let (X, ue, mat) = local(e);
            hex8_residual_tangent(&X, &ue, mat, p.formulation, r, k).map_err(LocalFailure::Hex)
        };
        let (owners, contact) = (&self.owners, &self.contact);
        // Follower pressure: an external force, so the residual gets −f and the tangent −∂f/∂x.
        let group = |g: usize, r: &mut DVector<f64>, k: &mut DMatrix<f64>| {
            let f = match owners[g] {
                GroupOwner::Pressure(i) => &p.pressure_faces[i],
                GroupOwner::Contact(pair, s) => return contact[pair].element(s, r, k).map(|_| ()).map_err(LocalFailure::Contact),
            };
            let x: [Vector3<f64>; 4] = std::array::from_fn(|a| {
                let n = f.nodes[a] as usize;
                let d = DOFS_PER_NODE * n;
                p.X[n] + Vector3::new(u[d], u[d + 1], u[d + 2])
            });
            let (mut fv, mut km) = (FaceVector::zeros(), FaceMatrix::zeros());
            follower_pressure_force_stiffness(&x, p.amplitudes[f.amplitude as usize].at(lambda) * f.p, &mut fv, &mut km);
            for i in 0..12 {
                r[i] = -fv[i];
                for j in 0..12 {
                    k[(i, j)] = -km[(i, j)];
                }
            }
            Ok(())
        };
        let res = if tangent {
            self.assembly.assemble_with_groups(&self.pattern, hex, group).map(|(_, r)| r)
        } else {
            let hex_residual = |e: usize, r: &mut _| {
                let (X, ue, mat) = local(e);
                hex8_residual(&X, &ue, mat, p.formulation, r).map_err(LocalFailure::Hex)
            };
            self.assembly.assemble_residual_with_groups(&self.pattern, hex_residual, group)
        };
        let (full, failure) = match res {
            Ok(r) => (Some(r), None),
            Err(ElementFailure::Hex { element, error }) | Err(ElementFailure::Group { group: element, error }) => {
                let f = match error {
                    LocalFailure::Hex(error) => AssemblyFailure::Hex(hex_ids.map_or(element, |ids| ids[element] as usize), error),
                    LocalFailure::Contact(error) => match owners[element] {
                        GroupOwner::Contact(pair, s) => AssemblyFailure::Contact(pair, s, error),
                        GroupOwner::Pressure(_) => unreachable!("pressure faces do not return contact errors"),
                    },
                };
                (None, Some(f))
            }
        };
        if self.partition.is_some() {
            // every rank takes the same branch: the worst failure of any rank decides
            let local = failure.as_ref().map_or(0.0, AssemblyFailure::severity);
            let mut worst = [local];
            ranks::reduce_over_ranks(&mut worst, ranks::Reduction::Max).map_err(AssemblyFailure::Mpi)?;
            if worst[0] > local {
                return Err(AssemblyFailure::OtherRank(worst[0] as u8));
            }
        }
        if let Some(f) = failure {
            return Err(f);
        }
        // the dofs whose residual this rank has whole: all, or those of its nodes
        let (a, b) = self.partition.as_ref().map_or((0, self.residual.len()), |part| (DOFS_PER_NODE * part.first, DOFS_PER_NODE * part.last));
        for (d, ((out, r), f)) in self.residual.iter_mut().zip(full.unwrap_or(&[])).zip(&self.f_ext).enumerate() {
            *out = if d >= a && d < b { r - f } else { 0.0 };
        }
        if self.partition.is_some() {
            // summed over the ranks, the complete parts give every rank the whole residual
            ranks::reduce_over_ranks(&mut self.residual, ranks::Reduction::Sum).map_err(AssemblyFailure::Mpi)?;
        }
        if let Some(s) = &self.stabilization {
            s.add_residual(u, &mut self.residual);
            if tangent {
                s.add_tangent(&self.pattern, self.assembly.values_mut());
            }
        }
        if let Some(f) = &self.free_bodies {
            f.add_residual(u, &mut self.residual);
            if tangent {
                f.add_tangent(&self.pattern, self.assembly.values_mut());
            }
        }
        Ok(())
    }
}
