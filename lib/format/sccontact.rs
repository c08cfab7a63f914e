//! The contact-model stage file, `.sccontact` (format `sccontact`, version 1.1),
//! written by `sc-tag`: the mesh and, per contact pair, the slave nodes and the
//! master surface as an ordered control net with its knot vectors (paper sec. 5).
//!
//! Records (container: [`super::stage`]):
//! ```text
//! META  pairs (YAML): per pair name, slave kind + set, master set, master kind,
//!       orders [ka, kb], net [a, b]; since 1.1 `layout` (grid when absent) and, for
//!       several patches, `patches: [[a, b], …]`
//! META  mesh metadata (as in .scmesh)
//! mesh/…                 the mesh records (as in .scmesh, prefixed)
//! pair/<p>/slave_nodes   u32 [n]      slave node indices, sorted
//! layout grid / periodic (net = [a, b]):
//! pair/<p>/net           u32 [b, a]   control net node indices, row j holds i = 0..a
//! pair/<p>/knots_1       f64          knot vector along ξ¹: open uniform (eq. 5.1),
//!                                     periodic uniform for `periodic`
//! pair/<p>/knots_2       f64 [b + kb] open uniform, along ξ²
//! layout patches (net = [patches, nodes]):
//! pair/<p>/nodes         u32 [n]      master node indices
//! pair/<p>/patch/<q>/net u32 [b, a]   positions in `nodes`
//! layout quads (net = [faces, nodes]):
//! pair/<p>/nodes         u32 [n]      master node indices
//! pair/<p>/faces         u32 [f, 4]   positions in `nodes`, outward node cycles
//! ```
//! `<p>` is the pair's position in the META list (0, 1, …), so pair names need no
//! escaping.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::scmesh;
use super::stage::{write_atomic, StageError, StageFile, StageWriter};
use crate::contact::{MasterNet, NetShape, PatchNet};
use crate::mesh::Mesh;
use crate::spline::{KnotVector, SplineError};

pub const FORMAT: &str = "sccontact";
pub const MAJOR: u32 = 1;
pub const MINOR: u32 = 1;

/// How the master surface is represented.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum MasterKind {
    /// One B-spline patch whose control points are the master nodes (the paper's method).
    #[default]
    Bspline,
    /// Bilinear 4-node facets on the master's quads (the classic baseline; orders [2, 2]).
    Facet,
    /// The Catmull–Clark limit surface of the master's quads (orders [4, 4]: bicubic
    /// on regular regions).
    Subdivision,
    /// sc-tag choices: a B-spline master forced to one grid (`patch`), a grid closed
    /// along ξ¹ (`periodic`) or several grids (`multipatch`). A built pair carries
    /// `bspline` and its net's shape.
    Patch,
    Periodic,
    Multipatch,
}

impl MasterKind {
    pub fn name(self) -> &'static str {
        match self {
            Self::Bspline => "bspline",
            Self::Facet => "facet",
            Self::Subdivision => "subdivision",
            Self::Patch => "patch",
            Self::Periodic => "periodic",
            Self::Multipatch => "multipatch",
        }
    }
}

/// What kind of set the slave was given as.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SlaveKind {
    NodeSet,
    /// A face set, used through its nodes.
    FaceSet,
}

/// One contact pair: slave nodes against a master control net.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactPair {
    pub name: String,
    pub slave_kind: SlaveKind,
    /// Name of the slave set.
    pub slave: String,
    /// Name of the master face set.
    pub master: String,
    pub master_kind: MasterKind,
    /// B-spline orders [ka, kb] (order = degree + 1; [2, 2] for facets).
    pub orders: [usize; 2],
    /// Slave node indices, sorted and unique.
    pub slave_nodes: Vec<u32>,
    pub net: MasterNet,
}

impl ContactPair {
    /// The faces of the slave face set (mesh node ids, cycle order), `None` for a
    /// node-set slave.
    pub fn slave_faces(&self, mesh: &crate::mesh::Mesh) -> Option<Vec<[u32; 4]>> {
        if self.slave_kind != SlaveKind::FaceSet {
            return None;
        }
        mesh.face_set(&self.slave).map(|fs| fs.faces.iter().map(|&f| mesh.face_nodes(f)).collect())
    }

    /// The knot vectors along ξ¹ and ξ² of a one-grid net ([`MasterNet::knot_vectors`]
    /// at the pair's orders); `None` for other shapes.
    pub fn knot_vectors(&self) -> Result<Option<[KnotVector; 2]>, SplineError> {
        self.net.knot_vectors(self.orders)
    }

    /// Checks that the orders fit every grid of the net (each patch of a multi-patch net).
    pub fn check_orders(&self) -> Result<(), SplineError> {
        self.net.check_orders(self.orders)
    }
}

/// A pair's metadata as stored in META (also in `.scres`, which carries the pairs).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PairMeta {
    name: String,
    slave_kind: SlaveKind,
    slave: String,
    master: String,
    master_kind: MasterKind,
    orders: [usize; 2],
    net: [usize; 2],
    #[serde(default, skip_serializing_if = "Layout::is_grid")]
    layout: Layout,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    patches: Vec<[usize; 2]>,
}

/// The net's shape in META.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub(crate) enum Layout {
    #[default]
    Grid,
    Periodic,
    Patches,
    Quads,
}

impl Layout {
    fn is_grid(&self) -> bool {
        *self == Layout::Grid
    }
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PairsMeta {
    source: String,
    pairs: Vec<PairMeta>,
}

pub(crate) fn pair_meta(p: &ContactPair) -> PairMeta {
    PairMeta {
        name: p.name.clone(),
        slave_kind: p.slave_kind,
        slave: p.slave.clone(),
        master: p.master.clone(),
        master_kind: p.master_kind,
        orders: p.orders,
        net: match &p.net.shape {
            NetShape::Grid { a, b } | NetShape::Periodic { a, b } => [*a, *b],
            NetShape::Patches(ps) => [ps.len(), p.net.nodes.len()],
            NetShape::Quads(f) => [f.len(), p.net.nodes.len()],
        },
        layout: match p.net.shape {
            NetShape::Grid { .. } => Layout::Grid,
            NetShape::Periodic { .. } => Layout::Periodic,
            NetShape::Patches(_) => Layout::Patches,
            NetShape::Quads(_) => Layout::Quads,
        },
        patches: match &p.net.shape {
            NetShape::Patches(ps) => ps.iter().map(|q| [q.a, q.b]).collect(),
            _ => Vec::new(),
        },
    }
}

/// The arrays of pair `k`: `pair/<k>/slave_nodes|net|knots_1|knots_2`.
pub(crate) fn write_pair_records(w: &mut StageWriter, k: usize, p: &ContactPair) -> Result<(), SplineError> {
    p.check_orders()?;
    w.u32s(&format!("pair/{k}/slave_nodes"), &[p.slave_nodes.len() as u64], &p.slave_nodes);
    match &p.net.shape {
        NetShape::Grid { a, b } | NetShape::Periodic { a, b } => {
            let Some([k1, k2]) = p.knot_vectors()? else { unreachable!("one-grid nets have knot vectors") };
            w.u32s(&format!("pair/{k}/net"), &[*b as u64, *a as u64], &p.net.nodes);
            w.f64s(&format!("pair/{k}/knots_1"), &[k1.knots().len() as u64], k1.knots());
            w.f64s(&format!("pair/{k}/knots_2"), &[k2.knots().len() as u64], k2.knots());
        }
        NetShape::Patches(ps) => {
            w.u32s(&format!("pair/{k}/nodes"), &[p.net.nodes.len() as u64], &p.net.nodes);
            for (q, pn) in ps.iter().enumerate() {
                w.u32s(&format!("pair/{k}/patch/{q}/net"), &[pn.b as u64, pn.a as u64], &pn.nodes);
            }
        }
        NetShape::Quads(f) => {
            w.u32s(&format!("pair/{k}/nodes"), &[p.net.nodes.len() as u64], &p.net.nodes);
            let flat: Vec<u32> = f.iter().flatten().copied().collect();
            w.u32s(&format!("pair/{k}/faces"), &[f.len() as u64, 4], &flat);
        }
    }
    Ok(())
}

/// Pair `k` from its META entry and arrays, checked against a mesh of `n` nodes:
/// node indices in range, net size = a·b, orders fit the net, knot vectors are the
/// open uniform ones.
pub(crate) fn read_pair(f: &StageFile, k: usize, pm: PairMeta, n: usize) -> Result<ContactPair, StageError> {
    let rec = |s: &str| format!("pair/{k}/{s}");
    let slave_nodes = f.u32s(&rec("slave_nodes"), None)?.to_vec();
    if slave_nodes.iter().any(|&v| v as usize >= n) {
        return Err(f.invalid(&rec("slave_nodes"), format!("pair '{}' refers to a node beyond {n}", pm.name)));
    }
    let [a, b] = pm.net;
    let beyond = |name: &str, v: &[u32], limit: usize| -> Result<(), StageError> {
        if v.iter().any(|&x| x as usize >= limit) {
            return Err(f.invalid(&rec(name), format!("pair '{}' refers to a node beyond {limit}", pm.name)));
        }
        Ok(())
    };
    let net = match pm.layout {
        Layout::Grid | Layout::Periodic => {
            let nodes = f.u32s(&rec("net"), Some(a as u64))?.to_vec();
            // an empty net with a huge side would pass `a · b = 0` and then size the knot
            // vectors by the metadata alone
            if a == 0 || b == 0 || a.checked_mul(b) != Some(nodes.len()) {
                return Err(f.invalid(&rec("net"), format!("pair '{}': metadata says a {a} × {b} net, the array holds {} ids", pm.name, nodes.len())));
            }
            beyond("net", &nodes, n)?;
            let shape = if pm.layout == Layout::Grid { NetShape::Grid { a, b } } else { NetShape::Periodic { a, b } };
            MasterNet { nodes, shape }
        }
        Layout::Patches | Layout::Quads => {
            let nodes = f.u32s(&rec("nodes"), None)?.to_vec();
            if nodes.len() != b {
                return Err(f.invalid(&rec("nodes"), format!("pair '{}': metadata says {b} master nodes, the array holds {}", pm.name, nodes.len())));
            }
            beyond("nodes", &nodes, n)?;
            if pm.layout == Layout::Quads {
                let flat = f.u32s(&rec("faces"), Some(4))?;
                if a == 0 || flat.len() != 4 * a {
                    return Err(f.invalid(&rec("faces"), format!("pair '{}': metadata says {a} faces, the array holds {} ids", pm.name, flat.len())));
                }
                beyond("faces", flat, b)?;
                MasterNet { nodes, shape: NetShape::Quads(flat.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()) }
            } else {
                if a == 0 || pm.patches.len() != a {
                    return Err(f.invalid("META", format!("pair '{}': metadata says {a} patches and lists {}", pm.name, pm.patches.len())));
                }
                let mut ps = Vec::with_capacity(a);
                for (q, &[pa, pb]) in pm.patches.iter().enumerate() {
                    let name = format!("patch/{q}/net");
                    let v = f.u32s(&rec(&name), Some(pa as u64))?.to_vec();
                    if pa == 0 || pb == 0 || pa.checked_mul(pb) != Some(v.len()) {
                        return Err(f.invalid(&rec(&name), format!("pair '{}': metadata says a {pa} × {pb} patch, the array holds {} ids", pm.name, v.len())));
                    }
                    beyond(&name, &v, b)?;
                    ps.push(PatchNet { a: pa, b: pb, nodes: v });
                }
                MasterNet { nodes, shape: NetShape::Patches(ps) }
            }
        }
    };
    let pair = ContactPair {
        name: pm.name,
        slave_kind: pm.slave_kind,
        slave: pm.slave,
        master: pm.master,
        master_kind: pm.master_kind,
        orders: pm.orders,
        slave_nodes,
        net,
    };
    pair.check_orders().map_err(|e| f.invalid(&rec("net"), format!("pair '{}': {e}", pair.name)))?;
    if let Some(kv) = pair.knot_vectors().map_err(|e| f.invalid(&rec("net"), format!("pair '{}': {e}", pair.name)))? {
        for (d, kv) in kv.iter().enumerate() {
            let name = rec(&format!("knots_{}", d + 1));
            if f.f64s(&name, None)? != kv.knots() {
                return Err(f.invalid(&name, format!("pair '{}': not the {} uniform knot vector for {} points of order {}", pair.name, if d == 0 && pm.layout == Layout::Periodic { "periodic" } else { "open" }, kv.n(), kv.order())));
            }
        }
    }
    Ok(pair)
}

/// A contact model in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactModel {
    pub mesh: Mesh,
    /// Where the mesh came from (the .scmesh path given to sc-tag).
    pub source: String,
    pub pairs: Vec<ContactPair>,
}

impl ContactModel {
    /// Encode; fails only if a pair's orders do not fit its net (build pairs through
    /// `stages::tag`, which checks that first).
    pub fn encode(&self) -> Result<Vec<u8>, SplineError> {
        let mut w = StageWriter::new(FORMAT, MAJOR, MINOR);
        let meta = PairsMeta {
            source: self.source.clone(),
            pairs: self.pairs.iter().map(pair_meta).collect(),
        };
        w.meta(&serde_yaml::to_string(&meta).expect("pairs metadata serialises"));
        w.meta(&scmesh::mesh_meta_yaml(&self.mesh, &self.source));
        scmesh::write_mesh_records(&mut w, &self.mesh, "mesh/");
        for (k, p) in self.pairs.iter().enumerate() {
            write_pair_records(&mut w, k, p)?;
        }
        Ok(w.finish())
    }

    /// Write atomically (`-` for standard output).
    pub fn write(&self, path: &Path) -> Result<(), StageError> {
        let bytes = self.encode().map_err(|e| StageError::Invalid { path: path.display().to_string(), name: "pair".into(), what: e.to_string() })?;
        write_atomic(path, &bytes)
    }

    /// Decode and check each pair (see `read_pair`).
    pub fn from_stage(f: &StageFile) -> Result<Self, StageError> {
        let meta: PairsMeta = f.meta_as()?;
        let mesh_meta = f.meta.get(1).ok_or_else(|| f.invalid("META", "the mesh metadata record is missing"))?;
        let mesh = scmesh::read_mesh_records(f, "mesh/", mesh_meta)?;
        let pairs = meta.pairs.into_iter().enumerate().map(|(k, pm)| read_pair(f, k, pm, mesh.nodes.len())).collect::<Result<_, _>>()?;
        Ok(Self { mesh, source: meta.source, pairs })
    }

    pub fn read(path: &Path) -> Result<Self, StageError> {
        Self::from_stage(&StageFile::read(path, Some((FORMAT, MAJOR)))?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Body, FaceSet, HexFace};

    fn model() -> ContactModel {
        let nodes: Vec<[f64; 3]> = (0..12).map(|k| [(k % 3) as f64, ((k / 3) % 2) as f64, (k / 6) as f64]).collect();
        let id = |i: u32, j: u32, k: u32| i + 3 * j + 6 * k;
        let hex = |i: u32| [id(i, 0, 0), id(i + 1, 0, 0), id(i + 1, 1, 0), id(i, 1, 0), id(i, 0, 1), id(i + 1, 0, 1), id(i + 1, 1, 1), id(i, 1, 1)];
        let mesh = Mesh {
            nodes,
            hexes: vec![hex(0), hex(1)],
            hex_body: vec![0, 0],
            bodies: vec![Body { name: "b".into(), physical_tag: 1 }],
            node_sets: vec![],
            face_sets: vec![FaceSet { name: "top".into(), physical_tag: 2, faces: vec![HexFace { element: 0, local: 1 }, HexFace { element: 1, local: 1 }], quad_tags: vec![5, 6] }],
            node_tags: (1..=12).collect(),
            element_tags: vec![1, 2],
        };
        let net = crate::contact::control_net(&mesh, "top").unwrap().into();
        let pair = ContactPair {
            name: "p".into(),
            slave_kind: SlaveKind::NodeSet,
            slave: "s".into(),
            master: "top".into(),
            master_kind: MasterKind::Bspline,
            orders: [3, 2],
            slave_nodes: vec![0, 1],
            net,
        };
        ContactModel { mesh, source: "m.scmesh".into(), pairs: vec![pair] }
    }

    #[test]
    fn round_trip() {
        let m = model();
        let bytes = m.encode().unwrap();
        let f = StageFile::parse("c.sccontact", &bytes, Some((FORMAT, MAJOR))).unwrap();
        assert_eq!(ContactModel::from_stage(&f).unwrap(), m);
    }

    /// Found by reading the code for the fuzzing (every count a reader trusts is
    /// bounded by the file): a net of 10¹² × 0 points matched its empty array, and the
    /// knot vectors were then sized by the 10¹² of the metadata.
    #[test]
    fn an_empty_net_with_a_huge_side_is_refused() {
        let m = model();
        let mut pm = pair_meta(&m.pairs[0]);
        pm.net = [1_000_000_000_000, 0];
        let mut w = StageWriter::new(FORMAT, MAJOR, MINOR);
        w.meta(&serde_yaml::to_string(&PairsMeta { source: "m".into(), pairs: vec![pm] }).unwrap());
        w.meta(&scmesh::mesh_meta_yaml(&m.mesh, "m"));
        scmesh::write_mesh_records(&mut w, &m.mesh, "mesh/");
        w.u32s("pair/0/slave_nodes", &[2], &[0, 1]);
        w.u32s("pair/0/net", &[0, 1_000_000_000_000], &[]);
        let f = StageFile::parse("c.sccontact", &w.finish(), Some((FORMAT, MAJOR))).unwrap();
        let e = ContactModel::from_stage(&f).unwrap_err().to_string();
        assert!(e.contains("pair/0/net") && e.contains("1000000000000 × 0 net"), "{e}");
    }

    #[test]
    fn every_net_shape_round_trips() {
        let mut m = model();
        let nodes: Vec<u32> = (0..6).collect();
        for (shape, kind) in [
            (NetShape::Periodic { a: 3, b: 2 }, MasterKind::Bspline),
            (NetShape::Patches(vec![PatchNet { a: 2, b: 2, nodes: vec![0, 1, 3, 4] }, PatchNet { a: 2, b: 2, nodes: vec![1, 2, 4, 5] }]), MasterKind::Bspline),
            (NetShape::Quads(vec![[0, 1, 4, 3], [1, 2, 5, 4]]), MasterKind::Subdivision),
        ] {
            m.pairs[0].net = MasterNet { nodes: nodes.clone(), shape };
            m.pairs[0].master_kind = kind;
            m.pairs[0].orders = if kind == MasterKind::Subdivision { [4, 4] } else { [2, 2] };
            let bytes = m.encode().unwrap();
            let f = StageFile::parse("c.sccontact", &bytes, Some((FORMAT, MAJOR))).unwrap();
            assert_eq!(ContactModel::from_stage(&f).unwrap(), m);
        }
    }

    #[test]
    fn order_too_high_is_refused_on_encode() {
        let mut m = model();
        m.pairs[0].orders = [4, 2];
        let e = m.encode().unwrap_err().to_string();
        assert!(e.contains("a 3-node row cannot carry order 4"), "{e}");
    }
}
