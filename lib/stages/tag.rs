//! `sc-tag`: a mesh (`.scmesh`) and contact pair definitions → contact model
//! (`.sccontact`).
//!
//! For each pair the slave set (node set, or face set through its nodes) gives the
//! slave nodes, and the master face set is ordered into the a × b control net of
//! [`crate::contact::net`]; the orders are checked against the net with the spline
//! library (order k needs at least k control points per row) and the open uniform
//! knot vectors (eq. 5.1) are stored beside the net.

use std::path::Path;

use serde::Deserialize;

use super::StageRunError;
use crate::contact::{control_net, NetError};
use crate::format::scmesh;
use crate::format::sccontact::{ContactModel, ContactPair, MasterKind, SlaveKind};
use crate::mesh::Mesh;
use crate::spline::SplineError;

/// Default orders of a B-spline master when none are given: [3, 3], the
/// biquadratic patch (C¹ across knots) of the paper's examples.
pub const DEFAULT_ORDERS: [usize; 2] = [3, 3];

/// One pair as the user gives it (pipeline `tag.pairs` entry, `--pairs` file,
/// or `--pair NAME:SLAVE:MASTER[:bspline:KA:KB|:facet]`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairSpec {
    pub name: String,
    /// A node set or a face set (face set wins when both carry the name).
    pub slave: String,
    /// A face set: the master surface.
    pub master: String,
    #[serde(default)]
    pub master_kind: MasterKind,
    /// [ka, kb]; default [3, 3] for `bspline`; must be [2, 2] (or absent) for `facet`.
    #[serde(default)]
    pub orders: Option<[usize; 2]>,
}

/// A `--pairs` YAML file: `pairs: [{name, slave, master, master_kind, orders}, …]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairsFile {
    pub pairs: Vec<PairSpec>,
}

/// Why a pair could not be built.
#[derive(Debug, thiserror::Error)]
pub enum TagError {
    #[error("--pair {given:?}: {why} (expected NAME:SLAVE:MASTER, NAME:SLAVE:MASTER:bspline:KA:KB or NAME:SLAVE:MASTER:facet)")]
    PairSyntax { given: String, why: String },
    #[error("{path}: {message}")]
    PairsFile { path: String, message: String },
    #[error("no contact pairs given (use --pair or --pairs)")]
    NoPairs,
    #[error("pair '{0}' is defined twice")]
    Duplicate(String),
    #[error("pair '{pair}': slave '{slave}' is neither a node set nor a face set (node sets: {node_sets}; face sets: {face_sets})")]
    UnknownSlave { pair: String, slave: String, node_sets: String, face_sets: String },
    #[error("pair '{pair}': master {source}")]
    Master { pair: String, source: NetError },
    #[error("pair '{pair}': master '{master}' is a {a} × {b} node net, direction {direction}: {source}")]
    Orders { pair: String, master: String, a: usize, b: usize, direction: usize, source: SplineError },
    #[error("pair '{pair}': a facet master is bilinear (orders [2, 2]); orders {orders:?} were given")]
    FacetOrders { pair: String, orders: [usize; 2] },
}

impl PairSpec {
    /// Parse `NAME:SLAVE:MASTER[:bspline:KA:KB|:facet]`.
    pub fn parse(s: &str) -> Result<Self, TagError> {
        let err = |why: &str| TagError::PairSyntax { given: s.to_string(), why: why.to_string() };
        let parts: Vec<&str> = s.split(':').collect();
        if parts.len() < 3 || parts[..3].iter().any(|p| p.is_empty()) {
            return Err(err("a name, a slave set and a master face set are needed"));
        }
        let (master_kind, orders) = match &parts[3..] {
            [] => (MasterKind::Bspline, None),
            ["facet"] => (MasterKind::Facet, None),
            ["bspline", ka, kb] => {
                let k = |v: &str| v.parse::<usize>().map_err(|_| err(&format!("order {v:?} is not a whole number")));
                (MasterKind::Bspline, Some([k(ka)?, k(kb)?]))
            }
            ["bspline"] => (MasterKind::Bspline, None),
            [kind, ..] if *kind != "bspline" && *kind != "facet" => return Err(err(&format!("unknown master kind {kind:?}"))),
            _ => return Err(err("a bspline master takes two orders KA:KB, a facet master none")),
        };
        Ok(Self { name: parts[0].into(), slave: parts[1].into(), master: parts[2].into(), master_kind, orders })
    }
}

/// Read a `--pairs` YAML file.
pub fn read_pairs_file(path: &Path) -> Result<Vec<PairSpec>, TagError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| TagError::PairsFile { path: shown.clone(), message: format!("cannot read: {e}") })?;
    let f: PairsFile = serde_yaml::from_str(&text).map_err(|e| TagError::PairsFile { path: shown, message: e.to_string() })?;
    Ok(f.pairs)
}

/// Build one pair on `mesh`.
pub fn build_pair(mesh: &Mesh, spec: &PairSpec) -> Result<ContactPair, TagError> {
    let pair = spec.name.clone();
    let (slave_kind, slave_nodes) = if let Some(fs) = mesh.face_set(&spec.slave) {
        let mut n: Vec<u32> = fs.faces.iter().flat_map(|&f| mesh.face_nodes(f)).collect();
        n.sort_unstable();
        n.dedup();
        (SlaveKind::FaceSet, n)
    } else if let Some(ns) = mesh.node_set(&spec.slave) {
        (SlaveKind::NodeSet, ns.nodes.clone())
    } else {
        return Err(TagError::UnknownSlave {
            pair,
            slave: spec.slave.clone(),
            node_sets: mesh.node_set_names().join(", "),
            face_sets: mesh.face_set_names().join(", "),
        });
    };
    let net = control_net(mesh, &spec.master).map_err(|source| TagError::Master { pair: pair.clone(), source })?;
    let orders = match (spec.master_kind, spec.orders) {
        (MasterKind::Bspline, o) => o.unwrap_or(DEFAULT_ORDERS),
        (MasterKind::Facet, None | Some([2, 2])) => [2, 2],
        (MasterKind::Facet, Some(o)) => return Err(TagError::FacetOrders { pair, orders: o }),
    };
    let p = ContactPair { name: pair.clone(), slave_kind, slave: spec.slave.clone(), master: spec.master.clone(), master_kind: spec.master_kind, orders, slave_nodes, net };
    for (d, (n, k)) in [(p.net.a, orders[0]), (p.net.b, orders[1])].into_iter().enumerate() {
        crate::spline::KnotVector::open_uniform(n, k)
            .map_err(|source| TagError::Orders { pair: pair.clone(), master: spec.master.clone(), a: p.net.a, b: p.net.b, direction: d + 1, source })?;
    }
    Ok(p)
}

/// Build every pair (names unique, at least one pair).
pub fn build_model(mesh: Mesh, source: &str, specs: &[PairSpec]) -> Result<ContactModel, TagError> {
    if specs.is_empty() {
        return Err(TagError::NoPairs);
    }
    let mut pairs: Vec<ContactPair> = Vec::with_capacity(specs.len());
    for s in specs {
        if pairs.iter().any(|p| p.name == s.name) {
            return Err(TagError::Duplicate(s.name.clone()));
        }
        pairs.push(build_pair(&mesh, s)?);
    }
    Ok(ContactModel { mesh, source: source.to_string(), pairs })
}

/// Read `input` (`-` = stdin), build the pairs, write `output` atomically (nothing
/// is written on failure). Returns one summary line per pair.
pub fn tag(input: &Path, output: &Path, specs: &[PairSpec]) -> Result<Vec<String>, StageRunError> {
    let mesh = scmesh::read(input)?;
    let model = build_model(mesh, &input.display().to_string(), specs)?;
    model.write(output)?;
    Ok(summary(&model))
}

/// One line per pair: slave count, master net, kind and orders.
pub fn summary(model: &ContactModel) -> Vec<String> {
    model
        .pairs
        .iter()
        .map(|p| {
            format!(
                "pair {}: {} slave nodes ({} '{}') against master '{}', {} × {} control net, {} orders [{}, {}]",
                p.name,
                p.slave_nodes.len(),
                match p.slave_kind {
                    SlaveKind::NodeSet => "node set",
                    SlaveKind::FaceSet => "face set",
                },
                p.slave,
                p.master,
                p.net.a,
                p.net.b,
                p.master_kind.name(),
                p.orders[0],
                p.orders[1]
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pair_syntax() {
        let p = PairSpec::parse("c:up:low").unwrap();
        assert_eq!((p.master_kind, p.orders), (MasterKind::Bspline, None));
        let p = PairSpec::parse("c:up:low:bspline:4:2").unwrap();
        assert_eq!(p.orders, Some([4, 2]));
        assert_eq!(PairSpec::parse("c:up:low:facet").unwrap().master_kind, MasterKind::Facet);
        for bad in ["c:up", "c::low", "c:up:low:nurbs", "c:up:low:bspline:3", "c:up:low:bspline:x:3", "c:up:low:facet:2:2"] {
            assert!(matches!(PairSpec::parse(bad), Err(TagError::PairSyntax { .. })), "{bad}");
        }
    }
}
