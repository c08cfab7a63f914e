//! The Catmull–Clark limit surface of a quad control mesh: a smooth master surface for
//! any manifold quad mesh (extraordinary vertices, open boundaries), with the master
//! nodes as its control points. Theory and measured figures: `docs/theory/subdivision.md`.
//!
//! | file               | concept |
//! |--------------------|---------|
//! | `control_mesh.rs`   | the quad control mesh and what can be wrong with it |
//! | `topology.rs`       | edges → faces, node rings, manifold and orientation checks |
//! | `stencil.rs`        | a face's local mesh with boundary phantoms, stencil order |
//! | `bicubic.rs`        | the uniform bicubic B-spline patch of a regular face |
//! | `catmull_clark.rs`  | the rules (S1–S3), the subdivision matrix, exact evaluation (E1) |
//!
//! **Faces and parameters.** Face `f` is `mesh.faces[f] = [n_0, n_1, n_2, n_3]`, its
//! outward normal by the right-hand rule; `ξ = (u, v) ∈ [0,1]²` with `u` along
//! `n_0 → n_1` and `v` along `n_0 → n_3`, so `ā_1 × ā_2` points outward.
//!
//! **How a face is evaluated** (all set up in [`CatmullClark::new`]):
//! * all four corners of valence 4 (boundary nodes count as 4 with their phantoms):
//!   the uniform bicubic B-spline of its 16 stencil points;
//! * one extraordinary corner (valence N ≠ 4): exact evaluation over the `2N+8`
//!   stencil by repeated subdivision (eq. E1), the parameters rotated so that corner is
//!   the origin and the derivatives rotated back;
//! * two or more extraordinary corners: one subdivision step first; each quarter
//!   `[0,½]², [½,1]×[0,½], [½,1]², [0,½]×[½,1]` of the face then has at most one.
//!
//! Every stencil point is a fixed combination of real nodes (phantoms fold into the
//! nodes they are made of), so the basis `Q_a, Q_{a,α}, Q_{a,αβ}` lists each support
//! node of the face once and `x̄ = Σ_a Q_a x_a` exactly as for the B-spline patch
//! (eq. 6.2–6.3 carry over unchanged).
//!
//! **At an extraordinary vertex** (max(s, t) < 2^{−L(N)} in the rotated parameters,
//! `λ(N)^{L(N)} ≤ 1e-16`: L = 42 for N = 3, 62 for N = 5, 83 for N = 14) the point
//! moves out along the diagonal to max(s, t) = 2^{−L}: the position is then the limit
//! point to within `1e-16` of the stencil size and every derivative is finite, but the
//! metric degenerates as the theory says: first derivatives scale like `(2λ)^L`
//! (→ 0 for N = 3, large for N ≥ 5), second like `(4λ)^L`. The normal there is the
//! limit normal to `(μ/λ)^L` (μ the next eigenvalue): 1e-11 up to N = 6, 1e-3 at N = 14.
//!
//! **Cost.** Regular faces: one bicubic evaluation. Near a vertex, one `(2N+8)²`
//! vector–matrix product per level `k = ⌊−log2 max(s, t)⌋` (≈ 10 at 1e-3, `L(N)` at the
//! vertex). No allocation in [`CatmullClark::evaluate_into`] or [`CatmullClark::jet`].
//!
//! **For a search tree.** The basis is non-negative (tested on every mesh here, phantoms
//! folded in), so face `f` lies in the convex hull of [`CatmullClark::face_support`].
//! Parameters outside `[0,1]²` are clamped to the face.

mod bicubic;
mod boundary_vertex;
mod catmull_clark;
mod control_mesh;
mod stencil;
mod topology;

#[cfg(test)]
mod tests;

pub use catmull_clark::subdominant_eigenvalue;
pub use control_mesh::{QuadControlMesh, SubdivisionError};

use bicubic::{row_of, Rows, N_ROWS, N_ROWS_JET, ORDERS};
use catmull_clark::{subdivide, ValenceTables};
use stencil::{grid_index, local_mesh, GlobalNet, LocalMesh, OpenRing};
use topology::Topology;

use super::patch::Jet;
use super::{SurfacePoint, Vec3, MAX_NODES};

/// Highest supported valence: a `2N+8` stencil fits in [`MAX_NODES`] = 36.
pub const MAX_VALENCE: usize = (MAX_NODES - 8) / 2;

/// How a face is evaluated (cost grows down the list).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaceKind {
    /// Uniform bicubic B-spline (16 stencil points).
    Regular,
    /// One extraordinary corner of this valence: repeated subdivision near it.
    Extraordinary { valence: usize },
    /// Several extraordinary corners: split once into four quarters.
    Split,
    /// A corner is a boundary node in three or more faces: chain tables there, in one
    /// piece or (with more irregular corners) in four quarters.
    BoundaryCorner { pieces: usize },
}

/// One parameter region of a face with its own stencil.
#[derive(Debug, Clone, Copy)]
struct Piece {
    /// Face parameters of the local origin.
    origin: [f64; 2],
    /// `jac[a][α] = ∂s_a/∂u_α` (local `(s, t)` from face `(u, v)`).
    jac: [[f64; 2]; 2],
    /// The chain rule (s, t) → (u, v) of the derivative rows: row r of the face's
    /// derivatives is `Σ chain[r][r'] · row r'` over the rows r' of the same order.
    chain: [[f64; N_ROWS]; N_ROWS],
    /// `None`: regular bicubic piece (stencil rows in grid order); `Some(N)`: `2N+8` stencil.
    valence: Option<usize>,
    /// `Some(i)`: evaluated by [`CatmullClark::corner_tables`]`[i]` over the whole
    /// support (a boundary node in three or more faces at the origin).
    tables: Option<usize>,
    /// First stencil row in [`CatmullClark::row_ptr`].
    first_row: usize,
}

#[derive(Debug, Clone, Copy)]
struct FaceData {
    support: (usize, usize),
    pieces: (usize, usize),
    kind: FaceKind,
    /// Per edge `c` (corner c → c+1): the face across it and that face's edge index.
    across: [Option<(usize, usize)>; 4],
}

/// The Catmull–Clark limit surface of a [`QuadControlMesh`], ready to evaluate.
#[derive(Debug, Clone)]
pub struct CatmullClark {
    n_nodes: usize,
    faces: Vec<FaceData>,
    support: Vec<u32>,
    pieces: Vec<Piece>,
    /// Stencil rows: the entries of row `r` are `entries[row_ptr[r]..row_ptr[r+1]]`,
    /// each (column in the face's support, weight).
    row_ptr: Vec<u32>,
    entries: Vec<(u8, f64)>,
    /// Tables per valence (index N), built for the valences present.
    valences: Vec<Option<ValenceTables>>,
    /// Chain tables of the pieces at boundary nodes in three or more faces, one per piece.
    corner_tables: Vec<ValenceTables>,
}

/// Where a face's support nodes and pieces begin ([`CatmullClark::begin_face`]).
#[derive(Debug, Clone, Copy)]
struct FaceStart {
    support: usize,
    pieces: usize,
}

/// The error of face `face` whose neighbourhood does not form the stencils it needs.
fn incomplete(face: usize) -> impl Fn(OpenRing) -> SubdivisionError {
    move |_| SubdivisionError::StencilIncomplete { face }
}

/// Parameter positions of a face's corners.
const CORNERS: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];

impl CatmullClark {
    /// Checks the mesh and precomputes every face's stencil.
    pub fn new(mesh: &QuadControlMesh) -> Result<Self, SubdivisionError> {
        let topo = Topology::new(mesh)?;
        for (v, ring) in topo.rings.iter().enumerate() {
            let (node, n) = (v as u32, ring.faces.len());
            if n == 0 {
                continue;
            }
            if !ring.boundary && n < 3 {
                return Err(SubdivisionError::ValenceTooLow { node, valence: n });
            }
            if !ring.boundary && n > MAX_VALENCE {
                return Err(SubdivisionError::ValenceTooHigh { node, valence: n, max: MAX_VALENCE });
            }
        }
        let mut cc = Self {
            n_nodes: mesh.n_nodes,
            faces: Vec::with_capacity(mesh.faces.len()),
            support: Vec::new(),
            pieces: Vec::new(),
            row_ptr: vec![0],
            entries: Vec::new(),
            valences: vec![None; MAX_VALENCE + 1],
            corner_tables: Vec::new(),
        };
        for f in 0..mesh.faces.len() {
            if boundary_vertex::touches_irregular_boundary(mesh, &topo, f) {
                cc.push_boundary_corner_face(mesh, &topo, f)?;
                continue;
            }
            let (local, support) = local_mesh(&GlobalNet { mesh, topo: &topo }, f)?;
            let start = cc.begin_face(f, &support)?;
            let incomplete = incomplete(f);
            let mut valences = [0; 4];
            for (c, n) in valences.iter_mut().enumerate() {
                *n = local.valence(0, c).map_err(&incomplete)?;
            }
            let ev: Vec<usize> = (0..4).filter(|&c| valences[c] != 4).collect();
            let kind = match ev.as_slice() {
                [] => {
                    cc.push_piece(&local, 0, 0, CORNERS).map_err(&incomplete)?;
                    FaceKind::Regular
                }
                &[r] => {
                    cc.push_piece(&local, 0, r, CORNERS).map_err(&incomplete)?;
                    FaceKind::Extraordinary { valence: valences[r] }
                }
                _ => {
                    let (fine, children) = subdivide(&local);
                    for (c, child) in children[0].iter().enumerate() {
                        let child = child.ok_or(SubdivisionError::StencilIncomplete { face: f })?;
                        cc.push_piece(&fine, child, 0, quarter(c)).map_err(&incomplete)?;
                    }
                    FaceKind::Split
                }
            };
            cc.end_face(&topo, mesh.faces[f], start, kind);
        }
        Ok(cc)
    }

    /// Starts face `f` with its support: where its support and pieces begin.
    fn begin_face(&mut self, f: usize, support: &[u32]) -> Result<FaceStart, SubdivisionError> {
        if support.len() > MAX_NODES {
            return Err(SubdivisionError::SupportTooLarge { face: f, nodes: support.len(), max: MAX_NODES });
        }
        let start = FaceStart { support: self.support.len(), pieces: self.pieces.len() };
        self.support.extend(support);
        Ok(start)
    }

    /// Ends the face `q` begun at `start`: the valence tables its pieces need, its
    /// neighbours across its edges, its record.
    fn end_face(&mut self, topo: &Topology, q: [u32; 4], start: FaceStart, kind: FaceKind) {
        for p in &self.pieces[start.pieces..] {
            if let Some(n) = p.valence {
                if self.valences[n].is_none() {
                    self.valences[n] = Some(ValenceTables::new(n).expect("the canonical stencil mesh is complete"));
                }
            }
        }
        let across = [0, 1, 2, 3].map(|c| topo.half_edge(q[(c + 1) % 4], q[c]));
        let support = (start.support, self.support.len() - start.support);
        self.faces.push(FaceData { support, pieces: (start.pieces, self.pieces.len() - start.pieces), kind, across });
    }

    /// Adds face `f`, one of whose corners is a boundary node in three or more faces
    /// ([`boundary_vertex`]): with that one irregular corner, its tables; with more,
    /// one subdivision step (with the boundary rules) and a piece per quarter.
    fn push_boundary_corner_face(&mut self, mesh: &QuadControlMesh, topo: &Topology, f: usize) -> Result<(), SubdivisionError> {
        let incomplete = incomplete(f);
        let (real, bd, support) = boundary_vertex::real_local_mesh(mesh, topo, f);
        let start = self.begin_face(f, &support)?;
        let q = mesh.faces[f];
        let irregular = |v: u32| {
            let ring = &topo.rings[v as usize];
            if ring.boundary { ring.faces.len() > 2 } else { ring.faces.len() != 4 }
        };
        let ev: Vec<usize> = (0..4).filter(|&c| irregular(q[c])).collect();
        if let &[r] = ev.as_slice() {
            let tables = boundary_vertex::corner_tables(&real, &bd, 0, r).map_err(&incomplete)?;
            self.push_table_piece(tables, r, CORNERS);
        } else {
            let (fine, children, fine_bd) = catmull_clark::subdivide_with(&real, Some(&bd));
            for (c, child) in children[0].iter().enumerate() {
                let child = child.ok_or(SubdivisionError::StencilIncomplete { face: f })?;
                let pos = quarter(c);
                if boundary_vertex::is_irregular_boundary(topo, q[c]) {
                    let tables = boundary_vertex::corner_tables(&fine, &fine_bd, child, 0).map_err(&incomplete)?;
                    self.push_table_piece(tables, 0, pos);
                } else {
                    let lm = boundary_vertex::stencil_rows(&fine, child).map_err(&incomplete)?;
                    self.push_piece(&lm, 0, 0, pos).map_err(&incomplete)?;
                }
            }
        }
        let kind = FaceKind::BoundaryCorner { pieces: self.pieces.len() - start.pieces };
        self.end_face(topo, q, start, kind);
        Ok(())
    }

    /// Adds a piece evaluated by chain tables over the face's whole support (identity
    /// stencil rows), origin at corner `r` of the parameter square `pos`.
    fn push_table_piece(&mut self, tables: ValenceTables, r: usize, pos: [[f64; 2]; 4]) {
        let (origin, jac) = frame(pos, r);
        let first_row = self.row_ptr.len() - 1;
        for k in 0..tables.m {
            self.entries.push((k as u8, 1.0));
            self.row_ptr.push(self.entries.len() as u32);
        }
        self.corner_tables.push(tables);
        self.pieces.push(Piece {
            origin,
            jac,
            chain: chain_rule(&jac),
            valence: None,
            tables: Some(self.corner_tables.len() - 1),
            first_row,
        });
    }

    /// Adds the piece of local face `g` with its origin at corner `r` (the
    /// extraordinary corner, if any); `pos` are the face parameters of `g`'s corners.
    fn push_piece(&mut self, lm: &LocalMesh, g: usize, r: usize, pos: [[f64; 2]; 4]) -> Result<(), OpenRing> {
        let n = lm.valence(g, r)?;
        let st = lm.stencil(g, r)?;
        let (origin, jac) = frame(pos, r);
        let first_row = self.row_ptr.len() - 1;
        let mut rows: Vec<&[f64]> = vec![&[]; st.len()];
        for (k, &p) in st.iter().enumerate() {
            let slot = if n == 4 { grid_index(k) } else { k };
            rows[slot] = &lm.points[p];
        }
        for row in rows {
            for (col, &w) in row.iter().enumerate() {
                if w != 0.0 {
                    self.entries.push((col as u8, w));
                }
            }
            self.row_ptr.push(self.entries.len() as u32);
        }
        self.pieces.push(Piece { origin, jac, chain: chain_rule(&jac), valence: (n != 4).then_some(n), tables: None, first_row });
        Ok(())
    }

    /// Number of faces.
    pub fn n_faces(&self) -> usize {
        self.faces.len()
    }

    /// Number of control nodes the surface was built for (`x` must hold at least these).
    pub fn n_nodes(&self) -> usize {
        self.n_nodes
    }

    /// The control nodes that influence face `face` (for bounding boxes in a search
    /// tree); also the node order of its basis.
    pub fn face_support(&self, face: usize) -> &[u32] {
        let (s0, len) = self.faces[face].support;
        &self.support[s0..s0 + len]
    }

    /// The face across edge `edge` of `face` (edge c runs from corner c to c+1; corners
    /// at ξ = (0,0), (1,0), (1,1), (0,1)) and its own index for that edge, or `None` on
    /// an open boundary. The shared edge runs the other way there: the point at
    /// fraction `τ` along edge c of `face` is at `1 − τ` along the returned edge.
    pub fn neighbour_across(&self, face: usize, edge: usize) -> Option<(usize, usize)> {
        self.faces[face].across[edge]
    }

    /// How face `face` is evaluated.
    pub fn face_kind(&self, face: usize) -> FaceKind {
        self.faces[face].kind
    }

    /// Basis weights over the support of `face` at `xi` for derivative rows
    /// `0..n_rows`, derivatives with respect to the face's `(u, v)`. Returns the support.
    #[allow(clippy::needless_range_loop)] // k (stencil point), r (derivative row), col (node) are math indices
    fn weights_into(&self, face: usize, xi: [f64; 2], n_rows: usize, w: &mut Rows) -> &[u32] {
        let fd = &self.faces[face];
        let [u, v] = xi.map(|x| x.clamp(0.0, 1.0));
        let quarter = match (u >= 0.5, v >= 0.5) {
            (false, false) => 0,
            (true, false) => 1,
            (true, true) => 2,
            (false, true) => 3,
        };
        let p = &self.pieces[fd.pieces.0 + if fd.pieces.1 == 1 { 0 } else { quarter }];
        let d = [u - p.origin[0], v - p.origin[1]];
        let st = [0, 1].map(|a| (p.jac[a][0] * d[0] + p.jac[a][1] * d[1]).clamp(0.0, 1.0));
        let mut local: Rows = [[0.0; MAX_NODES]; N_ROWS];
        let m = match (p.tables, p.valence) {
            (Some(i), _) => {
                let tables = &self.corner_tables[i];
                tables.weights_into(st, n_rows, &mut local);
                tables.m
            }
            (None, None) => {
                bicubic::weights_into(st, n_rows, &mut local);
                16
            }
            (None, Some(n)) => {
                let tables = self.valences[n].as_ref().expect("tables built in new");
                tables.weights_into(st, n_rows, &mut local);
                tables.m
            }
        };
        // fold the stencil points into the support nodes
        let len = fd.support.1;
        let mut g: Rows = [[0.0; MAX_NODES]; N_ROWS];
        for k in 0..m {
            let row = p.first_row + k;
            for &(col, c) in &self.entries[self.row_ptr[row] as usize..self.row_ptr[row + 1] as usize] {
                for r in 0..n_rows {
                    g[r][col as usize] += local[r][k] * c;
                }
            }
        }
        // chain rule (s, t) → (u, v), per order (`Piece::chain`)
        w[0][..len].copy_from_slice(&g[0][..len]);
        for (r, &(i, j)) in ORDERS.iter().enumerate().take(n_rows).skip(1) {
            let first = row_of(i + j, 0);
            let row = &mut w[r][..len];
            row.fill(0.0);
            for r2 in first..=first + i + j {
                let c = p.chain[r][r2];
                if c != 0.0 {
                    for (o, &x) in row.iter_mut().zip(&g[r2][..len]) {
                        *o += c * x;
                    }
                }
            }
        }
        self.face_support(face)
    }

    /// Checks that `x` holds a finite position for every node.
    pub fn check_control_points(&self, x: &[Vec3]) -> Result<(), SubdivisionError> {
        if x.len() < self.n_nodes {
            return Err(SubdivisionError::ControlPointCount { got: x.len(), expected: self.n_nodes });
        }
        if let Some((index, p)) = x[..self.n_nodes].iter().enumerate().find(|(_, p)| !p.iter().all(|c| c.is_finite())) {
            return Err(SubdivisionError::NonFiniteControlPoint { index, point: [p.x, p.y, p.z] });
        }
        Ok(())
    }

    #[track_caller]
    fn assert_nodes(&self, x: &[Vec3]) {
        assert!(x.len() >= self.n_nodes, "{} control points for a mesh of {} nodes", x.len(), self.n_nodes);
    }

    /// Limit surface on `face` at `xi = (u, v)`: x̄, ā_α, ā_{α,β}, ā_{α,βγ}, n̄, ā_αβ,
    /// ā^{αβ}, b̄_αβ and the basis over [`Self::face_support`]. `x` holds the current
    /// node positions; panics if it has fewer than [`Self::n_nodes`].
    pub fn evaluate_into(&self, x: &[Vec3], face: usize, xi: [f64; 2], out: &mut SurfacePoint) {
        self.assert_nodes(x);
        let mut w: Rows = [[0.0; MAX_NODES]; N_ROWS];
        let support = self.weights_into(face, xi, N_ROWS, &mut w);
        let mut d = [Vec3::zeros(); N_ROWS];
        out.basis.clear();
        for (col, &node) in support.iter().enumerate() {
            let p = x[node as usize];
            for (dr, wr) in d.iter_mut().zip(&w) {
                *dr += p * wr[col];
            }
            out.basis.push(
                node as usize,
                w[0][col],
                [w[1][col], w[2][col]],
                [[w[3][col], w[4][col]], [w[4][col], w[5][col]]],
            );
        }
        out.xi = xi;
        out.x_bar = d[0];
        out.a_alpha = [d[1], d[2]];
        out.a_alpha_beta = [[d[3], d[4]], [d[4], d[5]]];
        for al in 0..2 {
            for be in 0..2 {
                for ga in 0..2 {
                    let n_v = al + be + ga;
                    out.a_alpha_beta_gamma[al][be][ga] = d[row_of(3 - n_v, n_v)];
                }
            }
        }
        out.complete_metric();
    }

    /// [`Self::evaluate_into`] into a new [`SurfacePoint`].
    pub fn evaluate(&self, x: &[Vec3], face: usize, xi: [f64; 2]) -> SurfacePoint {
        let mut out = SurfacePoint::default();
        self.evaluate_into(x, face, xi, &mut out);
        out
    }

    /// Position and first and second derivatives (for the closest-point Newton iteration).
    pub fn jet(&self, x: &[Vec3], face: usize, xi: [f64; 2]) -> Jet {
        self.assert_nodes(x);
        let mut w: Rows = [[0.0; MAX_NODES]; N_ROWS];
        let support = self.weights_into(face, xi, N_ROWS_JET, &mut w);
        let mut d = [Vec3::zeros(); N_ROWS_JET];
        for (col, &node) in support.iter().enumerate() {
            let p = x[node as usize];
            for (dr, wr) in d.iter_mut().zip(&w) {
                *dr += p * wr[col];
            }
        }
        Jet { x: d[0], a: [d[1], d[2]], aa: [[d[3], d[4]], [d[4], d[5]]] }
    }
}


/// The face parameters of the corners of the quarter at corner `c` of a face (its
/// corner 0 at the face's corner c, as [`subdivide`] orders a child).
fn quarter(c: usize) -> [[f64; 2]; 4] {
    let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
    [CORNERS[c], mid(CORNERS[c], CORNERS[(c + 1) % 4]), [0.5, 0.5], mid(CORNERS[(c + 3) % 4], CORNERS[c])]
}

/// The origin and `jac[a][α] = ∂s_a/∂u_α` of a piece whose corners sit at the face
/// parameters `pos`, its `s` along corner r → r+1 and `t` along r → r−1.
fn frame(pos: [[f64; 2]; 4], r: usize) -> ([f64; 2], [[f64; 2]; 2]) {
    let origin = pos[r];
    let axis = |k: usize| [pos[k][0] - origin[0], pos[k][1] - origin[1]];
    let (es, et) = (axis((r + 1) % 4), axis((r + 3) % 4));
    let h2 = es[0] * es[0] + es[1] * es[1];
    (origin, [[es[0] / h2, es[1] / h2], [et[0] / h2, et[1] / h2]])
}

/// The chain rule of the derivative rows for a piece whose local `(s, t)` follow
/// from the face's `(u, v)` by `jac[a][α] = ∂s_a/∂u_α`: `∂_α = Σ_a jac[a][α] ∂_a`,
/// applied i times along u and j times along v for row (i, j).
fn chain_rule(jac: &[[f64; 2]; 2]) -> [[f64; N_ROWS]; N_ROWS] {
    let mut t = [[0.0; N_ROWS]; N_ROWS];
    t[0][0] = 1.0;
    for (r, &(i, j)) in ORDERS.iter().enumerate().skip(1) {
        let order = i + j;
        let alpha = |q: usize| usize::from(q >= i); // i derivatives along u, then j along v
        for bits in 0..1usize << order {
            let mut prod = 1.0;
            let mut n_t = 0;
            for q in 0..order {
                let a = (bits >> q) & 1;
                prod *= jac[a][alpha(q)];
                n_t += a;
            }
            t[r][row_of(order - n_t, n_t)] += prod;
        }
    }
    t
}
