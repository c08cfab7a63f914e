//! Segment-to-segment (mortar) integration of the normal contact constraint over the
//! slave surface: `integration: mortar` of a pair. The one-pass node-to-surface
//! method of the paper (`integration: node`) puts the whole constraint at the slave
//! nodes; here it is integrated over the slave faces, with slave-side multipliers at
//! the slave nodes (Puso & Laursen 2004; for smooth masters De Lorenzis, Wriggers &
//! Zavarise 2011): standard, Φ_s = N_s, or dual (biorthogonal, Wohlmuth 2000),
//! Φ_s per face from [`dual_basis`] ([`Multipliers`]). Per slave node s:
//! ```text
//! ĝ_s  = (1/A_s) ∫_Γs Φ_s g dA₀            weighted gap, g = (x − x̄(ξ̄(x)))·n̄ at every
//!                                          point x of the slave surface, projected
//!                                          onto the master (eq. 2.2)
//! t_s  = min(0, λ_s + ε_N ĝ_s)             the law of eq. 4.2 on the weighted gap
//! δΠ_c = Σ_s t_s A_s δ̃ĝ_s                  (A_s = ∫ N_s dA₀, the tributary area, eq. 6.1)
//! ```
//! The master stays the pair's master (the B-spline patch or the facets): it gives
//! the foot point x̄, the normal n̄ and the gap. The virtual displacement of the
//! master side, δ̃ĝ, is taken in the master body's own trace, the bilinear facets of
//! the same net, at the point of the segment's cell under x:
//! ```text
//! δ̃g = n̄·(Σ_l N_l(η) δx_l − Σ_k N^F_k(ζ̄) δx_k)     (facets: ζ̄ = ξ̄, N^F = Q)
//! ```
//! So a uniform traction gives the master body the consistent nodal forces of a
//! uniform pressure, ∫ N^F_k t dA, whatever the master kind: the contact patch test
//! is passed on matching and non-matching meshes with every master (a B-spline
//! basis Q_A spreads the same traction over control points off the surface, with
//! weights that are not those of the body's faces near its edges, and fails it).
//! With facets, δ̃g = δg and the tangent is the symmetric Hessian; with a B-spline
//! master it is not symmetric. The integrals run over the segments of
//! [`segment`]; the tangent takes the segmentation as fixed (a quadrature choice).
//!
//! `transfer: surface` takes δ̃g through the surface's own basis Q_A instead (δ̃g = δg),
//! and `transfer: balanced` through T_k = Σ_A M_kA Q_A, the basis recombined so that
//! a uniform pressure gives the faces' consistent forces ([`balance`]).
//!
//! | file        | concept |
//! |-------------|---------|
//! | [`trace`]   | the master body's facets: the cells that cut the slave faces |
//! | [`balance`] | the smooth basis recombined to the faces' forces (`transfer: balanced`) |
//! | [`segment`] | slave face ∩ master cells, triangle quadrature |
//! | [`element`] | the weighted gap of one slave node: residual and tangent |

pub mod balance;
pub mod element;
pub mod segment;
pub mod trace;

use rayon::prelude::*;

use self::balance::Balance;
use self::segment::{clip_convex, collapsed_triangle_rule, face_jacobian, face_point, is_convex_ccw, polygon_quadrature, quad4, signed_area2, FacePlane, Pieces, P2, TRIANGLE_7};
use self::trace::Trace;
use super::master::Projector;
use crate::contact::MasterNet;
use crate::spline::{Projection, SplineError, SurfacePoint, Vec3};

pub use crate::contact::settings::MortarMultipliers as Multipliers;
pub use crate::contact::settings::MortarTransfer as Transfer;
pub use crate::contact::settings::MortarQuadrature as Quadrature;

/// `quadrature: knot_spans`: Gauss points per direction of the collapsed triangle
/// rule (64 points, total degree 14). Near an open patch's edges the pieces'
/// integrands are smooth, not polynomial (x(ξ) is not affine there), and the rule
/// converges exponentially: the balanced basis's forces of a uniform traction on a
/// flat net (`span_tests`) are off by up to 2.3e-6 with 4 points, 2.4e-9 with 6,
/// 3.2e-12 with 8 and 7.1e-13 with 12; in the contact patch test that is 7.4e-9
/// with 6 points and 1.6e-9 with 8 (`docs/validation/contact.md`).
const SPAN_RULE_POINTS: usize = 8;

const IDENTITY: [[f64; 4]; 4] = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];

/// One quadrature point of the slave surface, with its foot points on the master.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MortarPoint {
    /// The slave face (index into the pair's faces).
    pub face: u32,
    /// Slave shape functions N_l(η) of the face's corners.
    pub n: [f64; 4],
    /// Quadrature weight in the reference configuration (area).
    pub w: f64,
    /// The master net cell of the segment (a [`Trace`] cell).
    pub cell: usize,
    /// The master element of the foot point, as [`Projector::evaluate`] takes it:
    /// the facet cell, the atlas chart `[chart, 0]`, or none on a single patch.
    pub element: Option<[usize; 2]>,
    /// Foot point on the master (its parameter ξ̄).
    pub xi: [f64; 2],
    /// Foot point on the trace facet `cell` (ζ̄; = ξ̄ for a facet master).
    pub zeta: [f64; 2],
    /// Gap g = (x − x̄)·n̄ at the last integration.
    pub g: f64,
}

/// The slaves' own closest-point projections (eq. 2.2), which the integration
/// starts from: per slave, its projection, master element (as
/// [`Projector::project`] returns it) and surface point.
#[derive(Clone, Copy)]
pub struct Feet<'a> {
    pub projections: &'a [Projection],
    pub elements: &'a [Option<[usize; 2]>],
    pub points: &'a [SurfacePoint],
}

/// The mortar integration of one pair.
#[derive(Clone)]
pub struct Mortar {
    /// Slave faces as indices into the pair's slave list, corners in cycle order.
    faces: Vec<[u32; 4]>,
    /// Their reference corner coordinates (dA₀).
    faces_ref: Vec<[Vec3; 4]>,
    /// Per face, the multiplier basis Φ_i = Σ_j a_ij N_j (identity: standard;
    /// [`dual_basis`]: dual).
    duals: Vec<[[f64; 4]; 4]>,
    /// The faces around each slave.
    faces_of: Vec<Vec<u32>>,
    /// The trace: the master net read as facets (segmentation and δ̃g).
    trace: Trace,
    /// Quadrature points per face (storage reused between searches).
    points: Vec<Vec<MortarPoint>>,
    /// Trace cell of each slave node (search start of its faces).
    node_cell: Vec<Option<usize>>,
    /// ĝ_s at the last integration.
    pub gap: Vec<f64>,
    /// ∫ N_s dA₀ over the part of the node's faces that faces the master.
    pub covered: Vec<f64>,
    /// The element's mesh nodes of each slave (sorted): its faces' corners and the
    /// master nodes under them.
    nodes: Vec<Vec<u32>>,
    /// Per face, the master nodes its quadrature points reach (sorted, mesh ids):
    /// each point's master basis, and under the trace transfer its trace cell's
    /// corners. Found once per point; the four slaves around a face share them.
    face_nodes: Vec<Vec<u32>>,
    /// Cells skipped because their image in a slave face was not convex.
    pub skipped_cells: usize,
    /// Through which basis the master receives the forces.
    pub transfer: Transfer,
    /// `transfer: balanced`: the recombination of the master's basis.
    balance: Option<Balance>,
    /// How the segments are cut and integrated.
    pub quadrature: Quadrature,
    /// The triangle rule of the segments' fans (barycentric points, weights).
    rule: Vec<([f64; 3], f64)>,
    /// A face whose corners' own foot points all lie farther than this in front of
    /// the master is not integrated (no slave node near it can be pressed; the
    /// pair passes twice its capture distance, infinity integrates every face).
    far: f64,
    /// Mesh node of every control point, and of every slave.
    net: Vec<u32>,
    slaves: Vec<u32>,
}

/// Slave faces that cannot be integrated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MortarError {
    #[error("mortar integration needs the slave as a face set; slave node {node} is on no slave face")]
    NodeWithoutFace { node: u32 },
    #[error("slave face with nodes {nodes:?}: node {node} is not a slave node")]
    ForeignNode { nodes: [u32; 4], node: u32 },
}

impl Mortar {
    /// `faces`: the slave faces as mesh node ids (cycle order); `slaves`: the pair's
    /// slave nodes (sorted); `x_ref`: reference coordinates of all mesh nodes;
    /// `net`: the master control net (any shape); `geometry`: the master in the
    /// reference configuration (`transfer: balanced` integrates its basis); `far`:
    /// faces whose corners all lie farther than this in front of the master are not
    /// integrated (the field `far`, `f64::INFINITY`: every face is).
    #[allow(clippy::too_many_arguments)]
    pub fn new(faces: &[[u32; 4]], slaves: &[u32], x_ref: &[Vec3], net: &MasterNet, geometry: &Projector, multipliers: Multipliers, transfer: Transfer, far: f64) -> Result<Result<Self, MortarError>, SplineError> {
        let x_net: Vec<Vec3> = net.nodes.iter().map(|&n| x_ref[n as usize]).collect();
        let trace = Trace::new(net, &x_net)?;
        let balance = (transfer == Transfer::Balanced).then(|| Balance::new(geometry, &trace, &x_net));
        let mut local = Vec::with_capacity(faces.len());
        let mut faces_of = vec![Vec::new(); slaves.len()];
        for (f, nodes) in faces.iter().enumerate() {
            let mut idx = [0u32; 4];
            for a in 0..4 {
                match slaves.binary_search(&nodes[a]) {
                    Ok(s) => idx[a] = s as u32,
                    Err(_) => return Ok(Err(MortarError::ForeignNode { nodes: *nodes, node: nodes[a] })),
                }
                faces_of[idx[a] as usize].push(f as u32);
            }
            local.push(idx);
        }
        if let Some(s) = faces_of.iter().position(|f| f.is_empty()) {
            return Ok(Err(MortarError::NodeWithoutFace { node: slaves[s] }));
        }
        let faces_ref: Vec<[Vec3; 4]> = faces.iter().map(|f| f.map(|n| x_ref[n as usize])).collect();
        let duals = match multipliers {
            Multipliers::Standard => vec![IDENTITY; faces_ref.len()],
            Multipliers::Dual => faces_ref.iter().map(dual_basis).collect(),
        };
        let n = slaves.len();
        Ok(Ok(Self {
            faces: local,
            faces_ref,
            duals,
            faces_of,
            trace,
            points: vec![Vec::new(); faces.len()],
            node_cell: vec![None; n],
            gap: vec![f64::INFINITY; n],
            covered: vec![0.0; n],
            nodes: vec![Vec::new(); n],
            face_nodes: vec![Vec::new(); faces.len()],
            skipped_cells: 0,
            transfer,
            balance,
            quadrature: Quadrature::Cells,
            rule: TRIANGLE_7.to_vec(),
            far,
            net: net.nodes.clone(),
            slaves: slaves.to_vec(),
        }))
    }

    /// The pair's quadrature (`cells`, the default of [`Self::new`], or
    /// `knot_spans`: the segments cut further by the master's knot lines, and a rule
    /// of higher degree; module [`segment`]).
    pub fn with_quadrature(mut self, quadrature: Quadrature) -> Self {
        self.quadrature = quadrature;
        self.rule = match quadrature {
            Quadrature::Cells => TRIANGLE_7.to_vec(),
            Quadrature::KnotSpans => collapsed_triangle_rule(SPAN_RULE_POINTS),
        };
        self
    }

    /// Φ_l at a point of face `f` with slave shape functions `n` (the dual basis
    /// function of the face's corner `l`).
    pub fn dual_shape(&self, f: u32, l: usize, n: &[f64; 4]) -> f64 {
        dual_shape(&self.duals[f as usize], l, n)
    }

    /// The faces around slave `s`.
    pub fn faces_of(&self, s: usize) -> &[u32] {
        &self.faces_of[s]
    }

    /// The slave indices of face `f`'s corners.
    pub fn face(&self, f: u32) -> [u32; 4] {
        self.faces[f as usize]
    }

    /// Number of slave faces.
    pub fn n_faces(&self) -> usize {
        self.faces.len()
    }

    /// The quadrature points of face `f` at the last integration.
    pub fn points(&self, f: u32) -> &[MortarPoint] {
        &self.points[f as usize]
    }

    /// Mesh node of every control point.
    pub fn net_nodes(&self) -> &[u32] {
        &self.net
    }

    /// Mesh node of every slave.
    pub fn slave_nodes(&self) -> &[u32] {
        &self.slaves
    }

    /// The trace facets at the current configuration.
    pub fn trace(&self) -> &Trace {
        &self.trace
    }

    /// `transfer: balanced`: the recombination of the master's basis (`None` under
    /// the other transfers).
    pub fn balance(&self) -> Option<&Balance> {
        self.balance.as_ref()
    }

    /// The mesh nodes of slave `s`'s element (sorted; empty when no point of its
    /// faces lies over the master).
    pub fn element_nodes(&self, s: usize) -> &[u32] {
        &self.nodes[s]
    }

    /// ∫ N_s n̄ dA₀ over slave `s`'s faces at the last integration: times −t_s, the
    /// force the master exerts on the slave body through node s's multiplier.
    pub fn slave_force(&self, s: usize, geometry: &Projector) -> Vec3 {
        let mut f = Vec3::zeros();
        for &fc in &self.faces_of[s] {
            let Some(l) = self.faces[fc as usize].iter().position(|&c| c as usize == s) else { continue };
            for p in &self.points[fc as usize] {
                f += geometry.evaluate(p.xi, p.element).n_bar * (p.w * self.dual_shape(fc, l, &p.n));
            }
        }
        f
    }

    /// Segments every slave face by the master cells over it, projects its
    /// quadrature points onto the master, and sums the weighted gaps ĝ_s. `x_net`:
    /// the current net (already in `geometry`); `x_slave`: the slaves' current
    /// positions; `feet`: their own projections (warm starts; their surface points'
    /// basis nodes join the element, friction acting at the slave node,
    /// `element::NodeFriction`); `areas`: A_s.
    ///
    /// The cells of a face are found by a walk over the trace from the cells under
    /// its corners: a cell whose image cuts the face passes the walk on to the cells
    /// that share a node with it (the cells under the corners always do, as a corner
    /// on a cell edge may face the neighbouring cell). The cells that cut a convex
    /// face are connected, so none is missed, on any quad net. A face's points are
    /// kept in cell order, not in the walk's, so the sums over them do not depend
    /// on the cells the last search left the corners in (a restart has none).
    pub fn integrate(&mut self, geometry: &Projector, x_net: &[Vec3], x_slave: &[Vec3], feet: Feet<'_>, areas: &[f64]) -> Result<(), SplineError> {
        self.trace.update(x_net)?;
        let trace = &self.trace;
        self.node_cell.par_iter_mut().zip(x_slave.par_iter()).with_min_len(64).for_each(|(c, x)| {
            *c = trace.locate(x, *c);
        });
        let (node_cell, far, quadrature, rule) = (&self.node_cell, self.far, self.quadrature, &self.rule[..]);
        let skipped: usize = self
            .points
            .par_iter_mut()
            .zip(self.faces.par_iter())
            .zip(self.faces_ref.par_iter())
            .enumerate()
            .with_min_len(16)
            // per thread: the walk's queue and the clipping's polygons
            .map_init(
                || (Vec::<(usize, bool)>::with_capacity(16), Vec::with_capacity(8), Vec::with_capacity(8), Pieces::default()),
                |(queue, seg, scratch, pieces), (f, ((pts, face), x0))| {
                    pts.clear();
                    if face.iter().all(|&s| feet.projections[s as usize].converged && feet.projections[s as usize].g > far) {
                        return 0;
                    }
                    let xf = face.map(|s| x_slave[s as usize]);
                    // its projected corners run counter-clockwise (the frame's e₂ = n × e₁)
                    let Some(plane) = FacePlane::new(&xf) else { return 0 };
                    queue.clear();
                    for &s in face {
                        if let Some(c) = node_cell[s as usize] {
                            if !queue.iter().any(|q| q.0 == c) {
                                queue.push((c, true));
                            }
                        }
                    }
                    if queue.is_empty() {
                        return 0;
                    }
                    let corner = face.iter().map(|&s| s as usize).find(|&s| feet.projections[s].converged);
                    let start = Start { xi: corner.map(|s| feet.projections[s].xi), element: corner.and_then(|s| feet.elements[s]) };
                    let mut skipped = 0;
                    let mut next = 0;
                    while next < queue.len() {
                        let (cell, seed) = queue[next];
                        next += 1;
                        let cuts = match segment(trace, x_net, &plane, cell, seg, scratch) {
                            Segment::Cut => {
                                // back to the face: the segment's vertices to η (module `segment`, step 4)
                                pieces.reset(seg);
                                let mut back = true;
                                for v in pieces.piece_mut(0).iter_mut() {
                                    match plane.eta(v) {
                                        Some(eta) => *v = P2::new(eta[0], eta[1]),
                                        None => back = false,
                                    }
                                }
                                if back {
                                    if quadrature == Quadrature::KnotSpans {
                                        cut_by_spans(geometry, &plane, &xf, start, seg, pieces);
                                    }
                                    for i in 0..pieces.len() {
                                        polygon_quadrature(pieces.piece_mut(i), rule, |eta, w| {
                                            let (xq, _) = face_point(&xf, eta);
                                            let Some(Foot { xi, element, zeta, g }) = project_point(geometry, trace, &xq, cell, start) else {
                                                return;
                                            };
                                            let (n, _) = quad4(eta);
                                            pts.push(MortarPoint { face: f as u32, n, w: w * face_jacobian(x0, eta), cell, element, xi, zeta, g });
                                        });
                                    }
                                } else {
                                    skipped += 1;
                                }
                                true
                            }
                            Segment::NotConvex => {
                                skipped += 1;
                                false
                            }
                            Segment::Empty => false,
                        };
                        if cuts || seed {
                            for d in trace.neighbours(cell) {
                                if !queue.iter().any(|q| q.0 == d) {
                                    queue.push((d, false));
                                }
                            }
                        }
                    }
                    // The walk starts from the cells under the corners, which a corner
                    // on a cell edge keeps from the last search (`Trace::locate`), so
                    // it meets the cells in an order the search's history sets. In
                    // cell order (each cell's points in its quadrature's order) the
                    // sums over the points (ĝ_s, the residual, the tangent) are the
                    // same function of the configuration whatever that history: a run
                    // restarted from its results file, whose first search starts
                    // afresh, repeats the uninterrupted run bit for bit.
                    pts.sort_by_key(|p| p.cell);
                    skipped
                },
            )
            .sum();
        self.skipped_cells = skipped;
        self.gather(geometry, feet, areas);
        Ok(())
    }

    /// The foot points and gaps of the current quadrature points at a new
    /// configuration, the segmentation held (what the tangent differentiates, see
    /// `PairSolver::hold_segmentation`; the finite-difference checks use it too).
    /// `x_net` must already be in `geometry`. A point whose projection now fails is
    /// dropped.
    pub fn refresh(&mut self, geometry: &Projector, x_net: &[Vec3], x_slave: &[Vec3], feet: Feet<'_>, areas: &[f64]) -> Result<(), SplineError> {
        self.trace.update(x_net)?;
        let trace = &self.trace;
        self.points.par_iter_mut().zip(self.faces.par_iter()).with_min_len(16).for_each(|(pts, face)| {
            let xf = face.map(|s| x_slave[s as usize]);
            pts.retain_mut(|p| {
                let x: Vec3 = (0..4).map(|l| xf[l] * p.n[l]).sum();
                match project_point(geometry, trace, &x, p.cell, Start { xi: Some(p.xi), element: p.element }) {
                    Some(Foot { xi, element, zeta, g }) => {
                        (p.xi, p.element, p.zeta, p.g) = (xi, element, zeta, g);
                        true
                    }
                    None => false,
                }
            });
        });
        self.gather(geometry, feet, areas);
        Ok(())
    }

    /// ĝ_s, the covered area and the element's nodes of every slave from the
    /// quadrature points.
    fn gather(&mut self, geometry: &Projector, feet: Feet<'_>, areas: &[f64]) {
        let (faces, faces_of, points, net, slaves, duals, transfer, trace, balance) = (&self.faces, &self.faces_of, &self.points, &self.net, &self.slaves, &self.duals, self.transfer, &self.trace, self.balance.as_ref());
        self.face_nodes.par_iter_mut().zip(points.par_iter()).with_min_len(16).for_each(|(nodes, pts)| {
            nodes.clear();
            for p in pts {
                let basis = geometry.evaluate(p.xi, p.element).basis;
                nodes.extend(basis.nodes().iter().map(|&k| net[k]));
                if transfer == Transfer::Trace {
                    nodes.extend(trace.corners(p.cell).iter().map(|&k| net[k as usize]));
                }
                if let Some(b) = balance {
                    // the nodes that take a share of each basis function (M's columns)
                    nodes.extend(basis.nodes().iter().flat_map(|&a| b.column(a).iter().map(|&(k, _)| net[k as usize])));
                }
            }
            nodes.sort_unstable();
            nodes.dedup();
        });
        let face_nodes = &self.face_nodes;
        self.gap
            .par_iter_mut()
            .zip(self.covered.par_iter_mut())
            .zip(self.nodes.par_iter_mut())
            .enumerate()
            .with_min_len(64)
            .for_each(|(s, ((gap, covered), nodes))| {
                let (mut gw, mut cw) = (0.0, 0.0);
                nodes.clear();
                for &f in &faces_of[s] {
                    let face = faces[f as usize];
                    let Some(l) = face.iter().position(|&c| c as usize == s) else { continue };
                    for p in &points[f as usize] {
                        let c = p.w * dual_shape(&duals[f as usize], l, &p.n);
                        gw += c * p.g;
                        cw += c;
                    }
                    if !points[f as usize].is_empty() {
                        nodes.extend_from_slice(&face_nodes[f as usize]);
                        nodes.extend(face.iter().map(|&c| slaves[c as usize]));
                    }
                }
                if cw > 0.0 {
                    nodes.push(slaves[s]);
                    if feet.projections[s].converged {
                        nodes.extend(feet.points[s].basis.nodes().iter().map(|&k| net[k]));
                    }
                }
                nodes.sort_unstable();
                nodes.dedup();
                *covered = cw;
                *gap = if cw > 0.0 { gw / areas[s] } else { f64::INFINITY };
            });
    }
}

/// The dual (biorthogonal) basis of a bilinear face (Wohlmuth 2000; Popp et al.
/// 2010): Φ_i = Σ_j a_ij N_j with ∫_f Φ_i N_j dA₀ = δ_ij ∫_f N_j dA₀, so
/// `a = D M⁻¹`, M_ij = ∫ N_i N_j dA₀, D = diag(∫ N_i dA₀) (3 × 3 Gauss: exact for
/// the degree ≤ 3 integrands of a bilinear face). Σ_i Φ_i = 1, so a uniform traction
/// stays uniform (the patch test), and the slave node s feels only its own
/// multiplier: ∫ Φ_s N_j = δ_sj A_j, the coupling of node-to-surface, which keeps the
/// Uzawa updates as fast as there (standard multipliers couple neighbours through
/// M, and the mesh-scale oscillating modes of λ converge slowly).
pub fn dual_basis(x: &[Vec3; 4]) -> [[f64; 4]; 4] {
    const G3: [(f64, f64); 3] = [(-0.774_596_669_241_483_4, 5.0 / 9.0), (0.0, 8.0 / 9.0), (0.774_596_669_241_483_4, 5.0 / 9.0)];
    let mut m = nalgebra::Matrix4::<f64>::zeros();
    for (s, ws) in G3 {
        for (t, wt) in G3 {
            let (n, _) = quad4([s, t]);
            let w = ws * wt * face_jacobian(x, [s, t]);
            for i in 0..4 {
                for j in 0..4 {
                    m[(i, j)] += w * n[i] * n[j];
                }
            }
        }
    }
    let d = nalgebra::Matrix4::from_diagonal(&nalgebra::Vector4::from_fn(|i, _| m.row(i).sum()));
    let a = d * m.try_inverse().unwrap_or_else(nalgebra::Matrix4::identity);
    std::array::from_fn(|i| std::array::from_fn(|j| a[(i, j)]))
}

/// Φ_l = Σ_j a_lj N_j.
fn dual_shape(a: &[[f64; 4]; 4], l: usize, n: &[f64; 4]) -> f64 {
    (0..4).map(|j| a[l][j] * n[j]).sum()
}

/// A quadrature point's foot points: on the master (ξ̄ and its element) and on the
/// trace facet (ζ̄), and the gap.
struct Foot {
    xi: [f64; 2],
    element: Option<[usize; 2]>,
    zeta: [f64; 2],
    g: f64,
}

/// Where the search for a quadrature point's foot starts: a foot point of the
/// face's corners (its parameter and master element).
#[derive(Debug, Clone, Copy)]
struct Start {
    xi: Option<[f64; 2]>,
    element: Option<[usize; 2]>,
}

/// What a master cell makes of a slave face.
enum Segment {
    /// The segment, a convex polygon of the face's parameter square.
    Cut,
    /// No area in common.
    Empty,
    /// The cell's image in the face is not convex (not integrated, counted).
    NotConvex,
}

/// The segment of the slave face in `plane` under trace cell `cell`, written into
/// `seg` in the plane's coordinates ([`segment`] module docs, steps 1–3).
fn segment(trace: &Trace, x_net: &[Vec3], plane: &FacePlane, cell: usize, seg: &mut Vec<P2>, scratch: &mut Vec<P2>) -> Segment {
    let corners = trace.corners(cell);
    let mut quad = [P2::zeros(); 4];
    for (l, q) in quad.iter_mut().enumerate() {
        // along the node's normal, which every cell around it uses: the images tile
        let n = trace.node_normal(corners[l]);
        let Some(e) = plane.meet(&x_net[corners[l] as usize], &n) else { return Segment::Empty };
        *q = e;
    }
    let a2 = signed_area2(&quad);
    if a2 < 0.0 {
        quad.reverse();
    }
    // areas relative to the face's (twice its area: 8 in η, where these were set)
    let face_a2 = signed_area2(&plane.corners);
    if a2.abs() < 1e-12 / 8.0 * face_a2 {
        return Segment::Empty;
    }
    if !is_convex_ccw(&quad) {
        // only an image over the face matters (a cell far round a curved master
        // maps, through its tilted normals, to a twisted quad far from the square)
        let face = &plane.corners;
        let over = (0..2).all(|al| quad.iter().any(|q| face.iter().any(|f| q[al] > f[al])) && quad.iter().any(|q| face.iter().any(|f| q[al] < f[al])));
        return if over { Segment::NotConvex } else { Segment::Empty };
    }
    clip_convex(&plane.corners, &quad, seg, scratch);
    if seg.len() < 3 || signed_area2(seg) < 1e-13 / 8.0 * face_a2 {
        return Segment::Empty;
    }
    Segment::Cut
}

/// `quadrature: knot_spans`: the segment (`seg` in the face's plane; the one piece
/// of `pieces`, in η) cut further by the knot lines of the B-spline patch that cross
/// its parameter range. Each line is the image of two points of the knot line,
/// carried onto the plane along the surface's normal there, as the cells' corners are
/// along their nodes' normals: the points whose foot lies on the line, exactly so on a
/// flat master. Inside each piece the integrand is then smooth (module [`segment`]).
/// Facet masters are not cut (their pieces are the cells), and neither are atlases
/// (periodic, several patches, Catmull–Clark): cut by the lines through their chart
/// edges' corners, the held residual's finite-difference check on the periodic
/// cylinder missed 5e-4 of K, so their segments keep the cells and only the rule of
/// higher degree.
fn cut_by_spans(geometry: &Projector, plane: &FacePlane, xf: &[Vec3; 4], start: Start, seg: &[P2], pieces: &mut Pieces) {
    let Projector::BSpline(pr) = geometry else { return };
    // in η, where the pieces are integrated, a face square of doubled area 8
    let min_a2 = 1e-13;
    let line = |a: &SurfacePoint, b: &SurfacePoint, pieces: &mut Pieces| {
        let (Some(p), Some(q)) = (plane.meet(&a.x_bar, &a.n_bar), plane.meet(&b.x_bar, &b.n_bar)) else { return };
        // where the line crosses the segment (in the plane), taken to η: the pieces
        // are split there along a straight line in η, so that they tile the
        // segment's η-polygon exactly (split in the plane, a new vertex on the
        // segment's edge would bend that edge in η on a face that is not a
        // parallelogram, and the pieces would leave gaps against the next segment)
        let d = q - p;
        let side = |v: &P2| d.x * (v.y - p.y) - d.y * (v.x - p.x);
        let (mut ends, mut n) = ([P2::zeros(); 2], 0);
        let m = seg.len();
        for i in 0..m {
            let (u, v) = (seg[i], seg[(i + 1) % m]);
            let (su, sv) = (side(&u), side(&v));
            if (su >= 0.0) != (sv >= 0.0) && n < 2 {
                ends[n] = u + (v - u) * (su / (su - sv));
                n += 1;
            }
        }
        if n < 2 {
            return;
        }
        if let (Some(e0), Some(e1)) = (plane.eta(&ends[0]), plane.eta(&ends[1])) {
            let (e0, e1) = (P2::new(e0[0], e0[1]), P2::new(e1[0], e1[1]));
            if (e1 - e0).norm() > 0.0 {
                pieces.split(e0, e1, min_a2);
            }
        }
    };
    // the parameter range of the segment's vertices (and centre) on the patch: a
    // knot line that crosses the segment has its value inside it wherever ξ̄ varies
    // monotonically over the segment (a flat net; on a curved one a line missed is
    // a quadrature choice, not an error)
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let centre = seg.iter().sum::<P2>() / seg.len() as f64;
    for v in seg.iter().chain(std::iter::once(&centre)) {
        let Some(eta) = plane.eta(v) else { continue };
        let (x, _) = face_point(xf, eta);
        let p = start.xi.map_or_else(|| pr.project(&x), |xi0| pr.project_warm(&x, xi0));
        if p.converged {
            for al in 0..2 {
                lo[al] = lo[al].min(p.xi[al]);
                hi[al] = hi[al].max(p.xi[al]);
            }
        }
    }
    let patch = pr.patch();
    let n_spans = patch.n_spans();
    for al in 0..2 {
        let be = 1 - al;
        // the line's two points half a span beyond the segment's range across
        let pad = 0.5 / n_spans[be] as f64;
        let (blo, bhi) = ((lo[be] - pad).max(0.0), (hi[be] + pad).min(1.0));
        for s in 1..n_spans[al] {
            let t = patch.knots(al).span_bounds(s).0;
            if t > lo[al] && t < hi[al] {
                let at = |b: f64| {
                    let mut xi = [0.0; 2];
                    xi[al] = t;
                    xi[be] = b;
                    pr.evaluate(xi)
                };
                line(&at(blo), &at(bhi), pieces);
            }
        }
    }
}

/// The foot points of a slave quadrature point `x` of the segment over trace cell
/// `cell`: on the master (ξ̄ and its element; within `cell` for facets) and on the
/// trace facet (ζ̄), and the gap. `None` when a projection fails or the foot point
/// lies off the master.
fn project_point(geometry: &Projector, trace: &Trace, x: &Vec3, cell: usize, start: Start) -> Option<Foot> {
    if geometry.is_facets() {
        // the master is the trace itself: the point's foot on the segment's cell
        let p = trace.project_on_cell(x, cell)?;
        return Some(Foot { xi: p.xi, element: Some(trace.element(cell)), zeta: p.xi, g: p.g });
    }
    let (p, element) = match geometry {
        Projector::BSpline(pr) => (start.xi.map_or_else(|| pr.project(x), |xi0| pr.project_warm(x, xi0)), None),
        _ => geometry.project_near(x, start.element.zip(start.xi)),
    };
    if !p.converged {
        return None;
    }
    let p = if p.inside {
        p
    } else {
        // The point lies on a segment, so over a trace cell; at the master's edge the
        // smooth surface's own edge curve may pass inside the facet's edge. Its foot
        // on the surface's extension (half a span at most) keeps the integrand
        // continuous as quadrature points cross that curve: cut off there, each
        // crossing drops ε_N w g from the residual, and Newton chatters (the
        // parallel beams under mortar stalled so).
        let ext = geometry.project_extended(x, p.xi, element, geometry.span_margin(0.5));
        if !ext.converged || !ext.inside {
            return None;
        }
        ext
    };
    let t = trace.project_on_cell(x, cell)?;
    Some(Foot { xi: p.xi, element, zeta: t.xi, g: p.g })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::NetShape;
    use crate::format::sccontact::MasterKind;

    /// Slave corners on the master's cell edges are located in either cell, the one
    /// the last search left (`Trace::locate` keeps it at ties), so the walk over the
    /// cells starts elsewhere after a restart than in the uninterrupted run. The
    /// quadrature points, and the weighted gaps summed over them, come out the same
    /// bit for bit whichever cells the corners start from.
    #[test]
    fn the_integration_does_not_depend_on_the_cells_the_last_search_left() {
        // a 5 × 5 facet net, z = 0, unit cells; a 3 × 3 slave patch whose rows lie
        // on the net's lines y = 1, 2, 3, pressed in by different depths
        let (a, b) = (5, 5);
        let x_net: Vec<Vec3> = (0..a * b).map(|k| Vec3::new((k % a) as f64, (k / a) as f64, 0.0)).collect();
        let net = MasterNet { nodes: (0..(a * b) as u32).collect(), shape: NetShape::Grid { a, b } };
        let x_slave: Vec<Vec3> = (0..9).map(|k| Vec3::new(1.5 + (k % 3) as f64, 1.0 + (k / 3) as f64, -0.01 - 0.003 * k as f64)).collect();
        let mut x_all = x_net.clone();
        x_all.extend(&x_slave);
        let slaves: Vec<u32> = (0..9).map(|s| (a * b) as u32 + s).collect();
        let faces: Vec<[u32; 4]> = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]].iter().map(|f: &[u32; 4]| f.map(|s| slaves[s as usize])).collect();
        let geometry = Projector::for_net(MasterKind::Facet, [2, 2], &net, &x_net).unwrap();
        let feet: Vec<_> = x_slave.iter().map(|x| geometry.project(x, None)).collect();
        let points: Vec<_> = feet.iter().map(|(p, c)| geometry.evaluate(p.xi, *c)).collect();
        let (projections, elements): (Vec<_>, Vec<_>) = feet.into_iter().unzip();
        let feet = Feet { projections: &projections, elements: &elements, points: &points };
        let areas = vec![1.0; 9];
        let mut fresh = Mortar::new(&faces, &slaves, &x_all, &net, &geometry, Multipliers::Standard, Transfer::Trace, f64::INFINITY).unwrap().unwrap();
        let mut kept = fresh.clone();
        fresh.integrate(&geometry, &x_net, &x_slave, feet, &areas).unwrap();
        // every corner starts from the other cell of its edge (cells a − 1 wide)
        let cells_a = a - 1;
        kept.node_cell = fresh.node_cell.iter().zip(&x_slave).map(|(c, x)| c.map(|c| if c / cells_a == x.y as usize { c - cells_a } else { c + cells_a })).collect();
        let seeds = kept.node_cell.clone();
        kept.integrate(&geometry, &x_net, &x_slave, feet, &areas).unwrap();
        assert_eq!(kept.node_cell, seeds, "the ties keep the cells given");
        assert_ne!(kept.node_cell, fresh.node_cell);
        for f in 0..faces.len() as u32 {
            assert!(fresh.points(f).len() >= 2 * 14, "face {f}: {} points", fresh.points(f).len());
            assert_eq!(fresh.points(f), kept.points(f), "face {f}");
        }
        assert_eq!(fresh.gap.iter().map(|g| g.to_bits()).collect::<Vec<_>>(), kept.gap.iter().map(|g| g.to_bits()).collect::<Vec<_>>());
    }
}

#[cfg(test)]
mod span_tests {
    use super::*;
    use crate::contact::NetShape;
    use crate::format::sccontact::MasterKind;

    /// The master forces of a uniform traction under `transfer: balanced`,
    /// Σ_q w_q T_k(ξ̄_q), against the faces' consistent forces f_k = ∫ N^F_k dA, on a
    /// flat uniform net covered exactly by a slave grid of `ns × ns` faces: the worst
    /// |F_k − f_k| / max f.
    fn force_defect(order: usize, nm: usize, ns: usize, quadrature: Quadrature) -> f64 {
        let h = 1.0 / (nm - 1) as f64;
        let x_net: Vec<Vec3> = (0..nm * nm).map(|k| Vec3::new((k % nm) as f64 * h, (k / nm) as f64 * h, 0.0)).collect();
        let net = MasterNet { nodes: (0..(nm * nm) as u32).collect(), shape: NetShape::Grid { a: nm, b: nm } };
        let geometry = Projector::for_net(MasterKind::Bspline, [order, order], &net, &x_net).unwrap();
        let m = ns + 1;
        let x_slave: Vec<Vec3> = (0..m * m).map(|k| Vec3::new((k % m) as f64 / ns as f64, (k / m) as f64 / ns as f64, -1e-3)).collect();
        let mut x_all = x_net.clone();
        x_all.extend(&x_slave);
        let slaves: Vec<u32> = (0..(m * m) as u32).map(|s| (nm * nm) as u32 + s).collect();
        let faces: Vec<[u32; 4]> = (0..ns * ns).map(|f| {
            let (i, j) = (f % ns, f / ns);
            [j * m + i, j * m + i + 1, (j + 1) * m + i + 1, (j + 1) * m + i].map(|s| slaves[s])
        }).collect();
        let feet: Vec<_> = x_slave.iter().map(|x| geometry.project(x, None)).collect();
        let points: Vec<_> = feet.iter().map(|(p, c)| geometry.evaluate(p.xi, *c)).collect();
        let (projections, elements): (Vec<_>, Vec<_>) = feet.into_iter().unzip();
        let feet = Feet { projections: &projections, elements: &elements, points: &points };
        let areas = vec![1.0; m * m];
        let mut mortar = Mortar::new(&faces, &slaves, &x_all, &net, &geometry, Multipliers::Standard, Transfer::Balanced, f64::INFINITY).unwrap().unwrap().with_quadrature(quadrature);
        mortar.integrate(&geometry, &x_net, &x_slave, feet, &areas).unwrap();
        let balance = mortar.balance().unwrap();
        let mut force = vec![0.0; nm * nm];
        for f in 0..faces.len() as u32 {
            for p in mortar.points(f) {
                let basis = geometry.evaluate(p.xi, p.element).basis;
                for (&a, &q) in basis.nodes().iter().zip(basis.q()) {
                    for &(k, m_ka) in balance.column(a) {
                        force[k as usize] += p.w * q * m_ka;
                    }
                }
            }
        }
        let f_max = h * h;
        (0..nm * nm).map(|k| {
            let edges = [k % nm, k / nm].iter().filter(|&&i| i == 0 || i == nm - 1).count();
            let f = h * h / f64::from(1 << edges);
            (force[k] - f).abs() / f_max
        }).fold(0.0, f64::max)
    }

    /// `quadrature: knot_spans` integrates the balanced basis to round-off on a flat
    /// net (orders 3 and 4, the net finer and coarser than the slave): measured
    /// ≤ 3.2e-12 of the largest force, where the cells' quadrature is off by 2e-7 –
    /// 1.3e-3 (the bound on the cells' fails if the two quadratures become one).
    #[test]
    fn knot_span_quadrature_integrates_the_balanced_basis_to_round_off() {
        for order in [3, 4] {
            for (nm, ns) in [(4, 5), (5, 4), (6, 3), (7, 5)] {
                let (cells, spans) = (force_defect(order, nm, ns, Quadrature::Cells), force_defect(order, nm, ns, Quadrature::KnotSpans));
                assert!(spans < 1e-11, "order {order}, net {nm}, slave {ns}: knot spans {spans:e}");
                assert!(cells > 1e-7, "order {order}, net {nm}, slave {ns}: cells {cells:e}");
            }
        }
    }
}
