//! The master body's trace: the bilinear facets of the master's control net, the
//! master nodes being the corners of the master body's own faces. The mortar
//! integration cuts the slave faces by these cells ([`super::segment`]) and, with
//! `transfer: trace`, gives the master body its share of the traction through them
//! (module docs of [`super`]).
//!
//! One grid (the paper's patch) keeps the facet net of the grid, cell `[i, j]` with
//! index `i + (a − 1)·j`; every other net (closed, several grids, free quads) is read
//! as a facet atlas over [`MasterNet::cells`], cell = chart. Both give the same cells
//! in the same order, and the same corner cycle `[x_00, x_10, x_11, x_01]`.

use crate::contact::{MasterNet, NetShape};
use crate::spline::{Atlas, AtlasProjector, FacetProjector, FacetSurface, Projection, SplineError, SurfacePoint, Vec3};

/// The facet projector behind the trace.
#[derive(Clone)]
enum Facets {
    Grid { projector: FacetProjector, cells_a: usize },
    Quads(AtlasProjector),
}

/// The trace cells of a master net at the current configuration.
#[derive(Clone)]
pub struct Trace {
    facets: Facets,
    /// Every cell's corners (positions in the net's node list), in cycle order.
    cells: Vec<[u32; 4]>,
    /// The cells around every net node (`around[offsets[k]..offsets[k + 1]]`).
    offsets: Vec<u32>,
    around: Vec<u32>,
    /// Per net node, the mean of the unit normals of its cells' facets at it: the
    /// direction along which every cell around the node carries it onto a slave
    /// face's plane ([`Self::node_normal`]).
    normals: Vec<Vec3>,
}

impl Trace {
    /// The trace of `net` with control points at `x_net` (the net's node order).
    pub fn new(net: &MasterNet, x_net: &[Vec3]) -> Result<Self, SplineError> {
        let cells = net.cells();
        let facets = match net.shape {
            NetShape::Grid { a, b } => Facets::Grid { projector: FacetProjector::new(FacetSurface::new(a, b)?, x_net)?, cells_a: a - 1 },
            _ => Facets::Quads(AtlasProjector::new(Atlas::facets(net.nodes.len(), cells.clone()), x_net)?),
        };
        let mut count = vec![0u32; net.nodes.len() + 1];
        for q in &cells {
            for &k in q {
                count[k as usize + 1] += 1;
            }
        }
        for k in 1..count.len() {
            count[k] += count[k - 1];
        }
        let offsets = count.clone();
        let mut around = vec![0u32; *offsets.last().unwrap_or(&0) as usize];
        for (c, q) in cells.iter().enumerate() {
            for &k in q {
                around[count[k as usize] as usize] = c as u32;
                count[k as usize] += 1;
            }
        }
        let mut trace = Self { facets, cells, offsets, around, normals: vec![Vec3::zeros(); net.nodes.len()] };
        trace.node_normals(x_net);
        Ok(trace)
    }

    /// New control point positions.
    pub fn update(&mut self, x_net: &[Vec3]) -> Result<(), SplineError> {
        match &mut self.facets {
            Facets::Grid { projector, .. } => projector.update(x_net)?,
            Facets::Quads(projector) => projector.update(x_net)?,
        }
        self.node_normals(x_net);
        Ok(())
    }

    /// The nodes' normals at `x_net`: the facet of cell `[x_0, x_1, x_2, x_3]` has at
    /// its corner l the normal (x_{l+1} − x_l) × (x_{l−1} − x_l) (= ā_1 × ā_2 there).
    fn node_normals(&mut self, x_net: &[Vec3]) {
        self.normals.iter_mut().for_each(|n| *n = Vec3::zeros());
        for q in &self.cells {
            for l in 0..4 {
                let x = |i: usize| x_net[q[i % 4] as usize];
                if let Some(n) = (x(l + 1) - x(l)).cross(&(x(l + 3) - x(l))).try_normalize(0.0) {
                    self.normals[q[l] as usize] += n;
                }
            }
        }
        self.normals.iter_mut().for_each(|n| *n = n.try_normalize(0.0).unwrap_or_else(Vec3::zeros));
    }

    /// The normal of net node `k` ([`Self::node_normals`]): shared by every cell
    /// around the node, so the cells' images in a plane tile it without gaps or
    /// overlaps.
    pub fn node_normal(&self, k: u32) -> Vec3 {
        self.normals[k as usize]
    }

    pub fn n_cells(&self) -> usize {
        self.cells.len()
    }

    /// The corners of cell `c` (positions in the net's node list), in cycle order.
    pub fn corners(&self, c: usize) -> [u32; 4] {
        self.cells[c]
    }

    /// The cells that share a node with cell `c` (`c` itself included).
    pub fn neighbours(&self, c: usize) -> impl Iterator<Item = usize> + '_ {
        self.cells[c].into_iter().flat_map(move |k| self.around[self.offsets[k as usize] as usize..self.offsets[k as usize + 1] as usize].iter().map(|&d| d as usize))
    }

    /// The master element of cell `c` as [`crate::contact::master::Projector`] names
    /// it on a master of facets: `[i, j]` on a grid, `[chart, 0]` on an atlas.
    pub fn element(&self, c: usize) -> [usize; 2] {
        match &self.facets {
            Facets::Grid { cells_a, .. } => [c % cells_a, c / cells_a],
            Facets::Quads(_) => [c, 0],
        }
    }

    /// The facet of cell `c` at its parameter `zeta`.
    pub fn evaluate(&self, zeta: [f64; 2], c: usize) -> SurfacePoint {
        match &self.facets {
            Facets::Grid { projector, .. } => projector.evaluate_in_cell(zeta, self.element(c)),
            Facets::Quads(projector) => projector.evaluate(c, zeta),
        }
    }

    /// The cell under `x` (closest point, kept on `prev` at ties); `None` when the
    /// projection fails.
    pub fn locate(&self, x: &Vec3, prev: Option<usize>) -> Option<usize> {
        match &self.facets {
            Facets::Grid { projector, cells_a } => {
                let (p, cell) = projector.project_keeping(x, prev.map(|c| self.element(c)));
                p.converged.then_some(cell[0] + cells_a * cell[1])
            }
            Facets::Quads(projector) => {
                let (p, chart) = projector.project_keeping(x, prev);
                p.converged.then_some(chart)
            }
        }
    }

    /// The closest point of `x` on cell `c`'s bilinear map (continued over the
    /// cell's edges shared with other cells); `None` when it is not found there.
    pub fn project_on_cell(&self, x: &Vec3, c: usize) -> Option<Projection> {
        match &self.facets {
            Facets::Grid { projector, .. } => {
                let cell = self.element(c);
                let (p, found) = projector.project_on_cell(x, cell, [None, None]);
                (p.converged && found == cell).then_some(p)
            }
            Facets::Quads(projector) => {
                let (p, found) = projector.project_on_chart(x, c, [None, None]);
                (p.converged && found == c).then_some(p)
            }
        }
    }
}
