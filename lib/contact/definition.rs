//! One contact pair as the problem defines it: the tagged pair of the contact model
//! with its settings from the setup resolved, the slave nodes' tributary areas
//! (eq. 6.1) and the master's mean edge length.

use super::settings::{Integration, MortarTransfer, PairSettings};
use crate::format::sccontact::{ContactPair, MasterKind};

/// A contact pair of the model with its settings from the setup.
#[derive(Debug, Clone)]
pub struct ContactDefinition {
    pub pair: ContactPair,
    pub settings: PairSettings,
    /// Tributary area of each slave node (eq. 6.1), order of `pair.slave_nodes`.
    pub areas: Vec<f64>,
    /// The slave faces (mesh node ids, cycle order; empty for a node-set slave).
    pub slave_faces: Vec<[u32; 4]>,
    /// Mean edge length of the master net (reference configuration).
    pub h_master: f64,
    /// ε_N was not given: [`default_penalty`](crate::solver::problem::default_penalty).
    pub eps_n_default: bool,
    /// `adjust` distance of the setup (None: off).
    pub adjust: Option<f64>,
    /// The setup accepts a master whose normal points away from the slave body.
    pub allow_flipped_master: bool,
}

impl ContactDefinition {
    /// Whether the pair's contact tangent is symmetric: frictionless, and the master
    /// virtual displacement the variation of its geometry (node-to-surface; mortar
    /// with facets, whose trace is the surface itself). Slip, and a mortar pair's
    /// B-spline master (geometry from the patch, forces through the facet trace of
    /// the segment's cell, `contact::mortar`) make it non-symmetric.
    pub fn symmetric_tangent(&self) -> bool {
        let trace_is_geometry = self.pair.master_kind == MasterKind::Facet || self.settings.transfer == MortarTransfer::Surface;
        !self.settings.frictional() && (self.settings.integration == Integration::Node || trace_is_geometry)
    }
}
