//! `sc-tag`: a mesh (`.scmesh`) and contact pair definitions → contact model
//! (`.sccontact`).
//!
//! For each pair the slave set (node set, or face set through its nodes) gives the
//! slave nodes, and the master face set is ordered into a control net
//! ([`crate::contact::net`]). A `bspline` master takes the first that fits of
//! ([`smooth_net`]): one grid (the paper's patch, open knots), a grid closed on
//! itself (periodic knots along ξ¹), several grids (one patch each), and — for any
//! other manifold quad surface — the Catmull–Clark limit surface (`subdivision`). `patch`,
//! `periodic`, `multipatch` and `subdivision` force one of them; `facet` takes one
//! grid when the set is one, any quad surface otherwise. The orders are checked
//! against every grid (order k needs at least k control points per row) and the knot
//! vectors (eq. 5.1) are stored beside the net.

use std::path::Path;

use serde::Deserialize;

use super::StageRunError;
pub use super::tag_error::TagError;
use crate::contact::{check_subdivision, master_net, smooth_net, MasterNet, NetChoice, NetShape, SmoothNet, SmoothNetError};
use crate::format::scmesh;
use crate::format::sccontact::{ContactModel, ContactPair, MasterKind, SlaveKind};
use crate::mesh::Mesh;

/// Default orders of a B-spline master when none are given: [3, 3], the
/// biquadratic patch (C¹ across knots) of the paper's examples.
pub const DEFAULT_ORDERS: [usize; 2] = [3, 3];

/// One pair as the user gives it (pipeline `tag.pairs` entry, `--pairs` file,
/// or `--pair NAME:SLAVE:MASTER[:KIND[:KA:KB]]`, KIND one of bspline, patch,
/// periodic, multipatch, subdivision, facet).
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
    /// [ka, kb]; default [3, 3] for the B-spline kinds; must be [2, 2] (or absent)
    /// for `facet` and [4, 4] (or absent) for `subdivision`.
    #[serde(default)]
    pub orders: Option<[usize; 2]>,
}

/// A `--pairs` YAML file: `pairs: [{name, slave, master, master_kind, orders}, …]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairsFile {
    pub pairs: Vec<PairSpec>,
}

impl PairSpec {
    /// Parse `NAME:SLAVE:MASTER[:bspline:KA:KB|:facet]`.
    pub fn parse(s: &str) -> Result<Self, TagError> {
        let err = |why: &str| TagError::PairSyntax { given: s.to_string(), why: why.to_string() };
        let parts: Vec<&str> = s.split(':').collect();
        if parts.len() < 3 || parts[..3].iter().any(|p| p.is_empty()) {
            return Err(err("a name, a slave set and a master face set are needed"));
        }
        let kind_of = |k: &str| -> Option<MasterKind> {
            [MasterKind::Bspline, MasterKind::Patch, MasterKind::Periodic, MasterKind::Multipatch, MasterKind::Subdivision, MasterKind::Facet].into_iter().find(|m| m.name() == k)
        };
        let (master_kind, orders) = match &parts[3..] {
            [] => (MasterKind::Bspline, None),
            [kind] => (kind_of(kind).ok_or_else(|| err(&format!("unknown master kind {kind:?}")))?, None),
            [kind, ka, kb] => {
                let m = kind_of(kind).ok_or_else(|| err(&format!("unknown master kind {kind:?}")))?;
                if matches!(m, MasterKind::Facet | MasterKind::Subdivision) {
                    return Err(err(&format!("a {} master has fixed orders; give none", m.name())));
                }
                let k = |v: &str| v.parse::<usize>().map_err(|_| err(&format!("order {v:?} is not a whole number")));
                (m, Some([k(ka)?, k(kb)?]))
            }
            [kind, ..] if kind_of(kind).is_none() => return Err(err(&format!("unknown master kind {kind:?}"))),
            _ => return Err(err("a B-spline master takes two orders KA:KB, a facet or subdivision master none")),
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
    let master_err = |source| TagError::Master { pair: pair.clone(), source };
    let net_of = |choice| master_net(mesh, &spec.master, choice).map_err(master_err);
    let bspline_orders = spec.orders.unwrap_or(DEFAULT_ORDERS);
    let make = |master_kind: MasterKind, orders: [usize; 2], net: MasterNet| ContactPair {
        name: pair.clone(),
        slave_kind,
        slave: spec.slave.clone(),
        master: spec.master.clone(),
        master_kind,
        orders,
        slave_nodes: slave_nodes.clone(),
        net,
    };
    let orders_err = |net: &MasterNet, source| TagError::Orders { pair: pair.clone(), master: spec.master.clone(), net: net.describe(), source };
    let check = |p: ContactPair| -> Result<ContactPair, TagError> {
        p.check_orders().map_err(|source| orders_err(&p.net, source))?;
        Ok(p)
    };
    match spec.master_kind {
        MasterKind::Facet => {
            if let Some(o) = spec.orders.filter(|&o| o != [2, 2]) {
                return Err(TagError::FacetOrders { pair, orders: o });
            }
            check(make(MasterKind::Facet, [2, 2], net_of(NetChoice::GridOrQuads)?))
        }
        MasterKind::Subdivision => {
            if let Some(o) = spec.orders.filter(|&o| o != [4, 4]) {
                return Err(TagError::SubdivisionOrders { pair, orders: o });
            }
            let net = net_of(NetChoice::Quads)?;
            check_subdivision(mesh, &spec.master, &net).map_err(|why| TagError::Subdivision { pair: pair.clone(), master: spec.master.clone(), why })?;
            check(make(MasterKind::Subdivision, [4, 4], net))
        }
        MasterKind::Patch => check(make(MasterKind::Bspline, bspline_orders, net_of(NetChoice::Grid)?)),
        MasterKind::Periodic => check(make(MasterKind::Bspline, bspline_orders, net_of(NetChoice::Periodic)?)),
        MasterKind::Multipatch => check(make(MasterKind::Bspline, bspline_orders, net_of(NetChoice::Patches)?)),
        MasterKind::Bspline => match smooth_net(mesh, &spec.master, bspline_orders) {
            Ok(SmoothNet::Bspline(net)) => Ok(make(MasterKind::Bspline, bspline_orders, net)),
            Ok(SmoothNet::Subdivision(net)) => Ok(make(MasterKind::Subdivision, [4, 4], net)),
            Err(SmoothNetError::Net(e)) => Err(master_err(e)),
            Err(SmoothNetError::Orders { net, source }) => Err(orders_err(&net, source)),
            Err(SmoothNetError::NoShape { grid, patches, subdivision }) => Err(TagError::NoSmoothMaster { pair, master: spec.master.clone(), grid, patches, subdivision }),
        },
    }
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
                "pair {}: {} slave nodes ({} '{}') against master '{}', {}, {} orders [{}, {}]",
                p.name,
                p.slave_nodes.len(),
                match p.slave_kind {
                    SlaveKind::NodeSet => "node set",
                    SlaveKind::FaceSet => "face set",
                },
                p.slave,
                p.master,
                p.net.describe(),
                match (&p.net.shape, p.master_kind) {
                    (NetShape::Periodic { .. }, MasterKind::Bspline) => "periodic bspline",
                    (NetShape::Patches(_), MasterKind::Bspline) => "multipatch bspline",
                    (_, k) => k.name(),
                },
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
        assert_eq!(PairSpec::parse("c:up:low:periodic:4:3").unwrap().master_kind, MasterKind::Periodic);
        assert_eq!(PairSpec::parse("c:up:low:subdivision").unwrap().master_kind, MasterKind::Subdivision);
        for bad in ["c:up", "c::low", "c:up:low:nurbs", "c:up:low:bspline:3", "c:up:low:bspline:x:3", "c:up:low:facet:2:2", "c:up:low:subdivision:4:4"] {
            assert!(matches!(PairSpec::parse(bad), Err(TagError::PairSyntax { .. })), "{bad}");
        }
    }
}
