//! A master surface made of many charts: the generalisation of the paper's single
//! patch to closed, multi-patch and free quad masters (the nets of
//! [`crate::contact::net`]).
//!
//! Every chart maps the unit square `(u, v) ∈ [0, 1]²` to a piece of the surface,
//! and its control points are master nodes (positions in the master node list):
//!
//! | charts | one chart is | across chart edges |
//! |--------|--------------|--------------------|
//! | [`Atlas::facets`] | one quad, bilinear | C⁰ (a crease) |
//! | [`Atlas::splines`] | one knot span of a B-spline patch (open or periodic knots) | C^{k−2} inside a patch, C⁰ at a seam between patches |
//! | [`Atlas::subdivision`] | one quad of the Catmull–Clark limit surface ([`crate::spline::subdivision`]) | C² where regular, C¹ at extraordinary nodes |
//!
//! On a B-spline chart the patch parameter is `ξ = lo + h ⊙ (u, v)` over the span
//! `[lo, lo + h]`, so `ā_α = h_α x̄_{,ξ^α}`, `ā_{α,β} = h_α h_β x̄_{,ξ^α ξ^β}` and the
//! basis derivatives scale alike: the contact element (eqs. 6.2–6.5) sees the same
//! kind of [`SurfacePoint`] as on the single patch, with its control points renumbered
//! into the master node list. Each chart edge is a [`EdgeKind`]: the surface's
//! boundary, a smooth join, or a crease. The projection ([`projector`]) uses it to
//! decide whether a foot point held on the edge is outside, fine, or in crease contact.

pub mod projector;
pub mod tree;

pub use projector::AtlasProjector;

use super::patch::Jet;
use super::subdivision::{CatmullClark, QuadControlMesh, SubdivisionError};
use super::{BSplinePatch, KnotVector, SplineError, SurfacePoint, Vec3};

/// What lies across one edge of a chart.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeKind {
    /// The edge of the whole master surface.
    Boundary,
    /// Another chart, joined with a continuous tangent plane.
    Smooth,
    /// Another chart, joined only C⁰ (facet edges, seams between patches).
    Crease,
}

/// Edge sides of a chart, in this order: u = 0, u = 1, v = 0, v = 1.
pub const SIDES: usize = 4;

/// One B-spline patch of a spline atlas.
#[derive(Debug, Clone)]
struct Sheet {
    patch: BSplinePatch,
    /// Patch control point (`i + na·j`) → master node position.
    map: Vec<u32>,
    /// First chart of this patch; its charts are the spans `s + ns_a·t`.
    first_chart: usize,
    /// Current control points in patch order.
    x: Vec<Vec3>,
    /// Closed along ξ¹ (period 1 in ξ¹).
    periodic: bool,
}

#[derive(Debug, Clone)]
enum Charts {
    Facets(Vec<[u32; 4]>),
    Splines(Vec<Sheet>),
    Subdivision(CatmullClark),
}

/// The charts of a master surface and the current master node positions.
#[derive(Debug, Clone)]
pub struct Atlas {
    n_nodes: usize,
    charts: Charts,
    n_charts: usize,
    edges: Vec<[EdgeKind; SIDES]>,
    /// Chart c's control points: `support[offsets[c]..offsets[c + 1]]`.
    offsets: Vec<usize>,
    support: Vec<u32>,
    x: Vec<Vec3>,
}

/// One grid of master node positions for [`Atlas::splines`].
pub struct SheetNet<'a> {
    pub a: usize,
    pub b: usize,
    /// `nodes[i + a·j]`, positions in the master node list.
    pub nodes: &'a [u32],
}

impl Atlas {
    /// Bilinear facets on `faces` (master node positions, outward cycles); an edge
    /// shared by two faces is a crease.
    pub fn facets(n_nodes: usize, faces: Vec<[u32; 4]>) -> Self {
        let mut by_edge: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
        for q in &faces {
            for c in 0..4 {
                *by_edge.entry((q[c].min(q[(c + 1) % 4]), q[c].max(q[(c + 1) % 4]))).or_default() += 1;
            }
        }
        let kind = |u: u32, v: u32| if by_edge[&(u.min(v), u.max(v))] > 1 { EdgeKind::Crease } else { EdgeKind::Boundary };
        // corners (0,0) (1,0) (1,1) (0,1) = q[0..4]: u = 0 is q3–q0, u = 1 is q1–q2,
        // v = 0 is q0–q1, v = 1 is q2–q3
        let edges = faces.iter().map(|q| [kind(q[3], q[0]), kind(q[1], q[2]), kind(q[0], q[1]), kind(q[2], q[3])]).collect();
        let mut offsets = vec![0];
        let mut support = Vec::with_capacity(4 * faces.len());
        for q in &faces {
            support.extend_from_slice(q);
            offsets.push(support.len());
        }
        Self { n_nodes, n_charts: faces.len(), charts: Charts::Facets(faces), edges, offsets, support, x: vec![Vec3::zeros(); n_nodes] }
    }

    /// B-spline patches of `orders` on `nets`; `periodic` closes the single net along
    /// ξ¹ (periodic knots, [`KnotVector::periodic_uniform`]). Patch sides whose nodes
    /// all belong to another patch too are seams (creases); spans of order 2 meet in
    /// creases, higher orders smoothly.
    pub fn splines(n_nodes: usize, nets: &[SheetNet], orders: [usize; 2], periodic: bool) -> Result<Self, SplineError> {
        let mut sheets = Vec::with_capacity(nets.len());
        let mut n_charts = 0;
        for net in nets {
            let (kv_a, map): (KnotVector, Vec<u32>) = if periodic {
                let kv = KnotVector::periodic_uniform(net.a, orders[0])?;
                let na = kv.n();
                (kv, (0..na * net.b).map(|p| net.nodes[(p % na) % net.a + net.a * (p / na)]).collect())
            } else {
                (KnotVector::open_uniform(net.a, orders[0])?, net.nodes.to_vec())
            };
            let patch = BSplinePatch::with_knots(kv_a, KnotVector::open_uniform(net.b, orders[1])?);
            let ns = patch.n_spans();
            sheets.push(Sheet { patch, map, first_chart: n_charts, x: Vec::new(), periodic });
            n_charts += ns[0] * ns[1];
        }
        // Which patch sides are seams: every node of the side is in another patch.
        let mut owners: std::collections::HashMap<u32, Vec<usize>> = std::collections::HashMap::new();
        for (p, net) in nets.iter().enumerate() {
            for &n in net.nodes {
                let o = owners.entry(n).or_default();
                if !o.contains(&p) {
                    o.push(p);
                }
            }
        }
        let smooth = |k: usize| if k >= 3 { EdgeKind::Smooth } else { EdgeKind::Crease };
        let mut edges = Vec::with_capacity(n_charts);
        let mut offsets = vec![0];
        let mut support = Vec::new();
        for (p, (sheet, net)) in sheets.iter().zip(nets).enumerate() {
            let side_is_seam = |nodes: &mut dyn Iterator<Item = u32>| -> bool {
                let mut any = false;
                for n in nodes {
                    any = true;
                    if !owners[&n].iter().any(|&q| q != p) {
                        return false;
                    }
                }
                any
            };
            let (a, b) = (net.a, net.b);
            let seam = [
                !periodic && side_is_seam(&mut (0..b).map(|j| net.nodes[a * j])),
                !periodic && side_is_seam(&mut (0..b).map(|j| net.nodes[a - 1 + a * j])),
                side_is_seam(&mut (0..a).map(|i| net.nodes[i])),
                side_is_seam(&mut (0..a).map(|i| net.nodes[i + a * (b - 1)])),
            ];
            let [ns_a, ns_b] = sheet.patch.n_spans();
            let [ka, kb] = sheet.patch.orders();
            let na = sheet.patch.n_ctrl()[0];
            for t in 0..ns_b {
                for s in 0..ns_a {
                    let outer = |first: bool, inner_kind: EdgeKind, wraps: bool, side: usize| {
                        if !first || wraps {
                            inner_kind
                        } else if seam[side] {
                            EdgeKind::Crease
                        } else {
                            EdgeKind::Boundary
                        }
                    };
                    edges.push([
                        outer(s == 0, smooth(ka), periodic, 0),
                        outer(s + 1 == ns_a, smooth(ka), periodic, 1),
                        outer(t == 0, smooth(kb), false, 2),
                        outer(t + 1 == ns_b, smooth(kb), false, 3),
                    ]);
                    for c in 0..kb {
                        for r in 0..ka {
                            support.push(sheet.map[(s + r) + na * (t + c)]);
                        }
                    }
                    offsets.push(support.len());
                }
            }
        }
        Ok(Self { n_nodes, charts: Charts::Splines(sheets), n_charts, edges, offsets, support, x: vec![Vec3::zeros(); n_nodes] })
    }

    /// The Catmull–Clark limit surface of `faces` (master node positions, outward
    /// cycles): one chart per face; interior edges are smooth.
    pub fn subdivision(n_nodes: usize, faces: Vec<[u32; 4]>) -> Result<Self, SubdivisionError> {
        let cc = CatmullClark::new(&QuadControlMesh { n_nodes, faces })?;
        let nf = cc.n_faces();
        let edges = (0..nf)
            .map(|f| {
                // helper edges c run corner c → c+1 with corners (0,0) (1,0) (1,1) (0,1):
                // edge 3 is u = 0, edge 1 is u = 1, edge 0 is v = 0, edge 2 is v = 1
                let k = |c: usize| if cc.neighbour_across(f, c).is_some() { EdgeKind::Smooth } else { EdgeKind::Boundary };
                [k(3), k(1), k(0), k(2)]
            })
            .collect();
        let mut offsets = vec![0];
        let mut support = Vec::new();
        for f in 0..nf {
            support.extend_from_slice(cc.face_support(f));
            offsets.push(support.len());
        }
        Ok(Self { n_nodes, n_charts: nf, charts: Charts::Subdivision(cc), edges, offsets, support, x: vec![Vec3::zeros(); n_nodes] })
    }

    /// On a subdivision atlas, (u, v) of chart `from` (within one chart width beyond
    /// one of its edges) on the chart `to` across that edge: the two faces' parameters
    /// join along the shared edge, which runs the other way on `to`.
    pub fn adjacent_parameter(&self, from: usize, uv: [f64; 2], to: usize) -> Option<[f64; 2]> {
        let Charts::Subdivision(cc) = &self.charts else { return None };
        // (fraction τ along edge c, depth inward) → (u, v), and back
        let at = |c: usize, tau: f64, depth: f64| match c {
            0 => [tau, depth],
            1 => [1.0 - depth, tau],
            2 => [1.0 - tau, 1.0 - depth],
            _ => [depth, 1.0 - tau],
        };
        let [u, v] = uv;
        let (c, tau, depth) = if v < 0.0 && (0.0..=1.0).contains(&u) {
            (0, u, v)
        } else if u > 1.0 && (0.0..=1.0).contains(&v) {
            (1, v, 1.0 - u)
        } else if v > 1.0 && (0.0..=1.0).contains(&u) {
            (2, 1.0 - u, 1.0 - v)
        } else if u < 0.0 && (0.0..=1.0).contains(&v) {
            (3, 1.0 - v, u)
        } else {
            // inside `from` (or beyond a corner): the nearest edge shared with `to`
            let cands = [(0, u, v), (1, v, 1.0 - u), (2, 1.0 - u, 1.0 - v), (3, 1.0 - v, u)];
            let (c, tau, depth) = cands.into_iter().filter(|&(c, _, _)| cc.neighbour_across(from, c).is_some_and(|(f, _)| f == to)).min_by(|a, b| a.2.total_cmp(&b.2))?;
            let (f2, c2) = cc.neighbour_across(from, c)?;
            return (f2 == to).then(|| at(c2, 1.0 - tau.clamp(0.0, 1.0), -depth));
        };
        let (f2, c2) = cc.neighbour_across(from, c)?;
        (f2 == to).then(|| at(c2, 1.0 - tau, -depth))
    }

    /// Whether the charts are Catmull–Clark faces (their polynomials do not continue
    /// beyond the face: parameters are clamped to it).
    pub fn is_subdivision(&self) -> bool {
        matches!(self.charts, Charts::Subdivision(_))
    }

    pub fn n_nodes(&self) -> usize {
        self.n_nodes
    }

    pub fn n_charts(&self) -> usize {
        self.n_charts
    }

    /// What lies across side `side` (u = 0, u = 1, v = 0, v = 1) of `chart`.
    pub fn edge(&self, chart: usize, side: usize) -> EdgeKind {
        self.edges[chart][side]
    }

    /// Chart `c`'s control points (master node positions).
    pub fn support(&self, c: usize) -> &[u32] {
        &self.support[self.offsets[c]..self.offsets[c + 1]]
    }

    /// The current master node positions.
    pub fn control_points(&self) -> &[Vec3] {
        &self.x
    }

    /// New master node positions (checked finite, right count).
    pub fn update(&mut self, x: &[Vec3]) -> Result<(), SplineError> {
        if x.len() != self.n_nodes {
            return Err(SplineError::ControlNetSize { got: x.len(), na: self.n_nodes, nb: 1, expected: self.n_nodes });
        }
        if let Some((index, p)) = x.iter().enumerate().find(|(_, p)| !p.iter().all(|c| c.is_finite())) {
            return Err(SplineError::NonFiniteControlPoint { index, point: [p.x, p.y, p.z] });
        }
        self.x.clear();
        self.x.extend_from_slice(x);
        if let Charts::Splines(sheets) = &mut self.charts {
            for sh in sheets {
                sh.x.clear();
                sh.x.extend(sh.map.iter().map(|&k| x[k as usize]));
            }
        }
        Ok(())
    }

    /// The sheet, span and span box `(lo, h)` of a spline chart.
    fn span_of(sheets: &[Sheet], chart: usize) -> (&Sheet, [usize; 2], [f64; 2], [f64; 2]) {
        let p = sheets.partition_point(|s| s.first_chart <= chart) - 1;
        let sh = &sheets[p];
        let ns_a = sh.patch.n_spans()[0];
        let local = chart - sh.first_chart;
        let span = [local % ns_a, local / ns_a];
        let (a0, a1) = sh.patch.knots(0).span_bounds(span[0]);
        let (b0, b1) = sh.patch.knots(1).span_bounds(span[1]);
        (sh, span, [a0, b0], [a1 - a0, b1 - b0])
    }

    /// Position and first and second derivatives of `chart` at (u, v) (the chart's
    /// own polynomial, continued when (u, v) lies outside the unit square).
    pub fn jet(&self, chart: usize, uv: [f64; 2]) -> Jet {
        match &self.charts {
            Charts::Facets(f) => {
                let [x0, x1, x2, x3] = f[chart].map(|k| self.x[k as usize]);
                let [s, t] = uv;
                let p = x0 * ((1.0 - s) * (1.0 - t)) + x1 * (s * (1.0 - t)) + x2 * (s * t) + x3 * ((1.0 - s) * t);
                let a1 = (x1 - x0) * (1.0 - t) + (x2 - x3) * t;
                let a2 = (x3 - x0) * (1.0 - s) + (x2 - x1) * s;
                let twist = x0 - x1 + x2 - x3;
                Jet { x: p, a: [a1, a2], aa: [[Vec3::zeros(), twist], [twist, Vec3::zeros()]] }
            }
            Charts::Subdivision(cc) => cc.jet(&self.x, chart, uv),
            Charts::Splines(sheets) => {
                let (sh, span, lo, h) = Self::span_of(sheets, chart);
                let j = sh.patch.jet_in_span(&sh.x, [lo[0] + h[0] * uv[0], lo[1] + h[1] * uv[1]], span);
                Jet { x: j.x, a: [j.a[0] * h[0], j.a[1] * h[1]], aa: [[j.aa[0][0] * (h[0] * h[0]), j.aa[0][1] * (h[0] * h[1])], [j.aa[1][0] * (h[0] * h[1]), j.aa[1][1] * (h[1] * h[1])]] }
            }
        }
    }

    /// Everything the contact element needs at (u, v) of `chart` (eqs. 4.11–4.13,
    /// 6.2–6.3), the basis numbered by master node position.
    pub fn evaluate_into(&self, chart: usize, uv: [f64; 2], out: &mut SurfacePoint) {
        match &self.charts {
            Charts::Facets(f) => {
                let q4 = f[chart];
                let j = self.jet(chart, uv);
                let [s, t] = uv;
                out.xi = uv;
                out.x_bar = j.x;
                out.a_alpha = j.a;
                out.a_alpha_beta = j.aa;
                out.a_alpha_beta_gamma = [[[Vec3::zeros(); 2]; 2]; 2];
                out.basis.clear();
                let q = [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t];
                let q1 = [-(1.0 - t), 1.0 - t, t, -t];
                let q2 = [-(1.0 - s), -s, s, 1.0 - s];
                let q12 = [1.0, -1.0, 1.0, -1.0];
                for k in 0..4 {
                    out.basis.push(q4[k] as usize, q[k], [q1[k], q2[k]], [[0.0, q12[k]], [q12[k], 0.0]]);
                }
            }
            Charts::Splines(sheets) => {
                let (sh, span, lo, h) = Self::span_of(sheets, chart);
                sh.patch.evaluate_in_span_into(&sh.x, [lo[0] + h[0] * uv[0], lo[1] + h[1] * uv[1]], span, out);
                out.xi = uv;
                for al in 0..2 {
                    out.a_alpha[al] *= h[al];
                    for be in 0..2 {
                        out.a_alpha_beta[al][be] *= h[al] * h[be];
                        for ga in 0..2 {
                            out.a_alpha_beta_gamma[al][be][ga] *= h[al] * h[be] * h[ga];
                        }
                    }
                }
                out.basis.remap_scale(|k| sh.map[k] as usize, h);
            }
            Charts::Subdivision(cc) => cc.evaluate_into(&self.x, chart, uv, out),
        }
        out.clamped = [false; 2];
        out.complete_metric();
    }

    pub fn evaluate(&self, chart: usize, uv: [f64; 2]) -> SurfacePoint {
        let mut out = SurfacePoint::default();
        self.evaluate_into(chart, uv, &mut out);
        out
    }

    /// A patch-wide parameter for charts of the same spline patch: `(patch, ξ)`; none
    /// for facets. Lets the friction history move between spans exactly.
    pub fn patch_parameter(&self, chart: usize, uv: [f64; 2]) -> Option<(usize, [f64; 2])> {
        match &self.charts {
            Charts::Facets(_) | Charts::Subdivision(_) => None,
            Charts::Splines(sheets) => {
                let p = sheets.partition_point(|s| s.first_chart <= chart) - 1;
                let (_, _, lo, h) = Self::span_of(sheets, chart);
                Some((p, [lo[0] + h[0] * uv[0], lo[1] + h[1] * uv[1]]))
            }
        }
    }

    /// (u, v) on `chart` of the patch parameter ξ of the same patch, with a
    /// periodic direction wrapped to the image nearest the chart.
    pub fn chart_parameter(&self, chart: usize, xi: [f64; 2]) -> [f64; 2] {
        match &self.charts {
            Charts::Facets(_) | Charts::Subdivision(_) => xi,
            Charts::Splines(sheets) => {
                let (sh, _, lo, h) = Self::span_of(sheets, chart);
                let mut u = [(xi[0] - lo[0]) / h[0], (xi[1] - lo[1]) / h[1]];
                if sh.periodic {
                    // period 1 in ξ¹: the image nearest the chart
                    let period = 1.0 / h[0];
                    u[0] -= period * ((u[0] - 0.5) / period).round();
                }
                u
            }
        }
    }

    /// Whether this atlas is made of bilinear facets.
    pub fn is_facets(&self) -> bool {
        matches!(self.charts, Charts::Facets(_))
    }
}

#[cfg(test)]
mod tests;
