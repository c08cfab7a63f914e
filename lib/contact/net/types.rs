//! The master nets (one grid, a closed grid, several grids, free quads) and why a
//! face set cannot be one.

use crate::spline::{KnotVector, SplineError};

/// One structured a × b grid of mesh nodes, `nodes[i + a·j]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ControlNet {
    /// Control points along ξ¹ (a) and ξ² (b).
    pub a: usize,
    pub b: usize,
    /// Node indices, `nodes[i + a*j]`.
    pub nodes: Vec<u32>,
}

impl ControlNet {
    /// The node at grid position (i, j).
    pub fn at(&self, i: usize, j: usize) -> u32 {
        self.nodes[i + self.a * j]
    }
}

/// One grid of a multi-patch master: `nodes[i + a·j]` are positions in
/// [`MasterNet::nodes`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PatchNet {
    pub a: usize,
    pub b: usize,
    pub nodes: Vec<u32>,
}

/// How the master nodes are arranged.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum NetShape {
    /// One a × b grid, `nodes[i + a·j]` (the paper's patch).
    Grid { a: usize, b: usize },
    /// One a × b grid closed along ξ¹: column a is column 0.
    Periodic { a: usize, b: usize },
    /// Several grids sharing the nodes on their seams.
    Patches(Vec<PatchNet>),
    /// Any manifold quad surface: faces as positions in [`MasterNet::nodes`].
    Quads(Vec<[u32; 4]>),
}

/// The master nodes (mesh node indices, the control points) and their arrangement.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MasterNet {
    pub nodes: Vec<u32>,
    pub shape: NetShape,
}

impl From<ControlNet> for MasterNet {
    fn from(net: ControlNet) -> Self {
        Self { shape: NetShape::Grid { a: net.a, b: net.b }, nodes: net.nodes }
    }
}

impl MasterNet {
    /// The single grid of a [`NetShape::Grid`] net.
    pub fn grid(&self) -> Option<ControlNet> {
        match self.shape {
            NetShape::Grid { a, b } => Some(ControlNet { a, b, nodes: self.nodes.clone() }),
            _ => None,
        }
    }

    /// Grid dimensions [a, b] of a one-grid net (open or periodic).
    pub fn dims(&self) -> Option<[usize; 2]> {
        match self.shape {
            NetShape::Grid { a, b } | NetShape::Periodic { a, b } => Some([a, b]),
            _ => None,
        }
    }

    /// Every cell of the net as positions in [`Self::nodes`], each cycle outward.
    pub fn cells(&self) -> Vec<[u32; 4]> {
        let grid_cells = |a: usize, b: usize, wrap: bool, map: &dyn Fn(usize) -> u32| -> Vec<[u32; 4]> {
            let ni = if wrap { a } else { a - 1 };
            let mut out = Vec::with_capacity(ni * (b - 1));
            for j in 0..b - 1 {
                for i in 0..ni {
                    let i1 = (i + 1) % a;
                    out.push([map(i + a * j), map(i1 + a * j), map(i1 + a * (j + 1)), map(i + a * (j + 1))]);
                }
            }
            out
        };
        match &self.shape {
            NetShape::Grid { a, b } => grid_cells(*a, *b, false, &|p| p as u32),
            NetShape::Periodic { a, b } => grid_cells(*a, *b, true, &|p| p as u32),
            NetShape::Patches(ps) => ps.iter().flat_map(|p| grid_cells(p.a, p.b, false, &|k| p.nodes[k])).collect(),
            NetShape::Quads(f) => f.clone(),
        }
    }

    /// Every edge of the net's cells once, as (smaller, larger) positions in
    /// [`Self::nodes`], sorted.
    pub fn edges(&self) -> Vec<(u32, u32)> {
        let mut edges: Vec<(u32, u32)> = self.cells().iter().flat_map(|q| (0..4).map(move |c| (q[c].min(q[(c + 1) % 4]), q[c].max(q[(c + 1) % 4])))).collect();
        edges.sort_unstable();
        edges.dedup();
        edges
    }

    /// The knot vectors along ξ¹ and ξ² of a one-grid net for B-spline orders
    /// `orders`: open uniform (eq. 5.1), or periodic along ξ¹ for a closed grid; fails
    /// when an order does not fit the net ("a 3-node row cannot carry order 4").
    /// `None` for other shapes.
    pub fn knot_vectors(&self, orders: [usize; 2]) -> Result<Option<[KnotVector; 2]>, SplineError> {
        Ok(match self.shape {
            NetShape::Grid { a, b } => Some([KnotVector::open_uniform(a, orders[0])?, KnotVector::open_uniform(b, orders[1])?]),
            NetShape::Periodic { a, b } => Some([KnotVector::periodic_uniform(a, orders[0])?, KnotVector::open_uniform(b, orders[1])?]),
            NetShape::Patches(_) | NetShape::Quads(_) => None,
        })
    }

    /// Checks that B-spline orders `orders` fit every grid of the net (each patch of
    /// a multi-patch net).
    pub fn check_orders(&self, orders: [usize; 2]) -> Result<(), SplineError> {
        self.knot_vectors(orders)?;
        if let NetShape::Patches(ps) = &self.shape {
            for p in ps {
                KnotVector::open_uniform(p.a, orders[0])?;
                KnotVector::open_uniform(p.b, orders[1])?;
            }
        }
        Ok(())
    }

    /// "6 × 4 grid", "32 × 5 closed grid", "3 grids (4 × 4, 4 × 4, 4 × 4)", "118 quads".
    pub fn describe(&self) -> String {
        match &self.shape {
            NetShape::Grid { a, b } => format!("{a} × {b} grid"),
            NetShape::Periodic { a, b } => format!("{a} × {b} grid closed along ξ¹"),
            NetShape::Patches(ps) => format!("{} grids ({})", ps.len(), ps.iter().map(|p| format!("{} × {}", p.a, p.b)).collect::<Vec<_>>().join(", ")),
            NetShape::Quads(f) => format!("{} quads on {} nodes", f.len(), self.nodes.len()),
        }
    }
}

/// Which arrangement to build, when the master kind asks for one (the smooth master
/// that fits best: [`super::smooth_net`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NetChoice {
    Grid,
    Periodic,
    Patches,
    Quads,
    /// One grid when the face set is one, else any quad surface (a facet master).
    GridOrQuads,
}

/// The smooth master a face set carries ([`super::smooth_net`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SmoothNet {
    /// One grid, a closed grid or several grids: B-spline patches of the orders asked for.
    Bspline(MasterNet),
    /// Any other manifold quad surface: the Catmull–Clark limit surface (orders [4, 4]).
    Subdivision(MasterNet),
}

/// Why a face set has no smooth master of the orders asked for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SmoothNetError {
    /// Not a manifold, consistently oriented quad surface of one body.
    #[error(transparent)]
    Net(#[from] NetError),
    /// The first shape that fits, one grid or a closed grid, is too small for the orders.
    #[error("the master is a {}: {source}", net.describe())]
    Orders { net: MasterNet, source: SplineError },
    /// No shape fits: why not one grid, why not several grids (or too small for the
    /// orders), why no Catmull–Clark surface.
    #[error("no smooth master:\n  one grid: {grid}\n  several grids: {patches}\n  subdivision: {subdivision}")]
    NoShape { grid: String, patches: String, subdivision: String },
}

/// Why a face set cannot be a master control net. Faces are named by their gmsh
/// quad tag and the hexahedron (gmsh element tag) they bound, nodes by gmsh tag.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NetError {
    #[error("face set '{set}' does not exist (face sets: {known})")]
    UnknownFaceSet { set: String, known: String },
    #[error("face set '{set}' is empty")]
    Empty { set: String },
    #[error("face set '{set}' spans two bodies: {face_a} is in body '{body_a}', {face_b} in body '{body_b}' (one master surface follows one body)")]
    SpansTwoBodies { set: String, body_a: String, face_a: String, body_b: String, face_b: String },
    #[error("face set '{set}' has a collapsed face: {face} repeats a node (a master face is a quad with 4 distinct nodes)")]
    Degenerate { set: String, face: String },
    #[error("face set '{set}' branches: the edge between nodes {n0} and {n1} (gmsh tags) is shared by {count} faces: {faces} (a surface edge bounds at most 2 faces)")]
    Branch { set: String, n0: u64, n1: u64, count: usize, faces: String },
    #[error("face set '{set}' is not a manifold surface at node {node} (gmsh tag): its faces {faces} touch only at that node")]
    NonManifoldVertex { set: String, node: u64, faces: String },
    #[error("face set '{set}' has a hole: its boundary is {loops} closed loops, not one (a rectangular patch has a single outline)")]
    Hole { set: String, loops: usize },
    #[error("face set '{set}' has a non-rectangular outline: {what}")]
    NonRectangular { set: String, what: String },
    #[error("face set '{set}' is not a regular grid: interior node {node} (gmsh tag) is in {count} faces, a structured grid has 4 ({faces})")]
    IrregularInterior { set: String, node: u64, count: usize, faces: String },
    #[error("face set '{set}' is not a structured grid: {what}")]
    NotAGrid { set: String, what: String },
    #[error("face set '{set}' is inconsistently oriented: {face} faces the other way from {other}")]
    Orientation { set: String, face: String, other: String },
    #[error("face set '{set}' is not a closed grid: {what}")]
    NotPeriodic { set: String, what: String },
    #[error("face set '{set}' does not split into rectangular grids: {what}")]
    NotPatches { set: String, what: String },
}
