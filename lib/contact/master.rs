//! The master surface as the closest-point search sees it: the B-spline patch of
//! sec. 5 or the bilinear facets over the same control net, each with its projector
//! (eq. 2.2), or — for closed, multi-patch and free quad masters — an atlas of
//! charts ([`crate::spline::atlas`]), behind one interface for the contact pair and
//! the mortar integration.
//!
//! The master element of a foot point (`cell`) is the facet cell `[i, j]` on a
//! facet net and `[chart, 0]` on an atlas; a single B-spline patch has none, except
//! while a frozen search holds the knot span `[s, t]` a foot point lies in.

use crate::contact::{MasterNet, NetShape};
use crate::format::sccontact::MasterKind;
use crate::spline::atlas::SheetNet;
use crate::spline::{Atlas, AtlasProjector, BSplinePatch, BSplineProjector, FacetProjector, FacetSurface, Projection, SplineError, SurfacePoint, Vec3};

/// The master as the projection sees it.
pub enum Projector {
    BSpline(BSplineProjector),
    Facet(FacetProjector),
    Atlas(AtlasProjector),
}

impl Projector {
    /// The projector of a master of `kind` and `orders` on `net`, at the control
    /// point positions `x_net` (the net's node order). One grid keeps the paper's
    /// patch (or the facet net); every other shape is an atlas.
    pub fn for_net(kind: MasterKind, orders: [usize; 2], net: &MasterNet, x_net: &[Vec3]) -> Result<Self, SplineError> {
        let n = net.nodes.len();
        Ok(match (kind, &net.shape) {
            (MasterKind::Facet, NetShape::Grid { a, b }) => Self::Facet(FacetProjector::new(FacetSurface::new(*a, *b)?, x_net)?),
            (MasterKind::Facet, _) => Self::Atlas(AtlasProjector::new(Atlas::facets(n, net.cells()), x_net)?),
            (MasterKind::Subdivision, _) => Self::Atlas(AtlasProjector::new(Atlas::subdivision(n, net.cells()).map_err(|e| SplineError::Subdivision { message: e.to_string() })?, x_net)?),
            (_, NetShape::Grid { a, b }) => Self::BSpline(BSplineProjector::new(BSplinePatch::new(*a, *b, orders[0], orders[1])?, x_net)?),
            (_, NetShape::Periodic { a, b }) => {
                let nodes: Vec<u32> = (0..n as u32).collect();
                Self::Atlas(AtlasProjector::new(Atlas::splines(n, &[SheetNet { a: *a, b: *b, nodes: &nodes }], orders, true)?, x_net)?)
            }
            (_, NetShape::Patches(ps)) => {
                let sheets: Vec<SheetNet> = ps.iter().map(|p| SheetNet { a: p.a, b: p.b, nodes: &p.nodes }).collect();
                Self::Atlas(AtlasProjector::new(Atlas::splines(n, &sheets, orders, false)?, x_net)?)
            }
            (_, NetShape::Quads(_)) => return Err(SplineError::Unsupported { what: "a B-spline master on a free quad net (use subdivision)".into() }),
        })
    }

    pub fn update(&mut self, x: &[Vec3]) -> Result<(), SplineError> {
        match self {
            Self::BSpline(p) => p.update(x),
            Self::Facet(p) => p.update(x),
            Self::Atlas(p) => p.update(x),
        }
    }
    /// The projection and, for facets, the cell it lies on (kept from `prev` at ties).
    pub fn project(&self, p: &Vec3, prev: Option<[usize; 2]>) -> (Projection, Option<[usize; 2]>) {
        match self {
            Self::BSpline(pr) => (pr.project(p), None),
            Self::Atlas(pr) => {
                let (proj, chart) = pr.project_keeping(p, prev.map(|c| c[0]));
                (proj, Some([chart, 0]))
            }
            Self::Facet(pr) => {
                let (proj, cell) = pr.project_keeping(p, prev);
                (proj, Some(cell))
            }
        }
    }
    /// The closest point near a known one: on an atlas, first on the chart of
    /// `near` (its element and parameter) alone, accepted when strictly inside it;
    /// otherwise, and on other masters, [`Self::project`] kept on `near`'s element.
    pub fn project_near(&self, p: &Vec3, near: Option<([usize; 2], [f64; 2])>) -> (Projection, Option<[usize; 2]>) {
        if let (Self::Atlas(pr), Some((element, uv))) = (self, near) {
            if let Some(proj) = pr.project_on_chart_interior(p, element[0], uv) {
                return (proj, Some(element));
            }
        }
        self.project(p, near.map(|n| n.0))
    }

    /// With the master element held (a frozen search): a facet slave projects onto
    /// its last cell's continued bilinear map, a slave in crease contact onto the same
    /// crease (`last`: its previous projection); a B-spline slave onto the knot span
    /// it was held in (its polynomial continued), or as usual when none is held.
    pub fn project_frozen(&self, p: &Vec3, prev: Option<[usize; 2]>, last: &Projection) -> (Projection, Option<[usize; 2]>) {
        match (self, prev) {
            (Self::BSpline(pr), Some(span)) => (pr.project_in_span(p, last.xi, span), Some(span)),
            (Self::Facet(pr), Some(c)) => {
                let crease = [0, 1].map(|al| last.clamped[al].then_some(last.xi[al]));
                let (proj, cell) = pr.project_on_cell(p, c, crease);
                (proj, Some(cell))
            }
            (Self::Atlas(pr), Some(c)) => {
                let crease = [0, 1].map(|al| last.clamped[al].then_some(last.xi[al]));
                let (proj, chart) = pr.project_on_chart(p, c[0], crease);
                (proj, Some([chart, 0]))
            }
            _ => self.project(p, prev),
        }
    }
    /// The closest point on the surface's extension beyond its edge (see
    /// [`BSplineProjector::project_extended`]).
    pub fn project_extended(&self, p: &Vec3, xi0: [f64; 2], cell: Option<[usize; 2]>, margin: [f64; 2]) -> Projection {
        match (self, cell) {
            (Self::BSpline(pr), _) => pr.project_extended(p, xi0, margin),
            (Self::Facet(pr), Some(c)) => pr.project_extended(p, c, margin),
            (Self::Facet(pr), None) => pr.project(p),
            (Self::Atlas(pr), Some(c)) => pr.project_extended(p, c[0], margin),
            (Self::Atlas(pr), None) => pr.project(p).0,
        }
    }
    pub fn evaluate(&self, xi: [f64; 2], cell: Option<[usize; 2]>) -> SurfacePoint {
        match (self, cell) {
            (Self::BSpline(p), None) => p.evaluate(xi),
            (Self::BSpline(p), Some(span)) => p.evaluate_in_span(xi, span),
            (Self::Facet(p), Some(c)) => p.evaluate_in_cell(xi, c),
            (Self::Facet(p), None) => p.evaluate(xi),
            (Self::Atlas(p), c) => p.evaluate(c.map_or(0, |c| c[0]), xi),
        }
    }

    /// The friction history (ξ̄_n on chart `from`, covariant t_{Tα,n}) re-expressed on
    /// chart `to` of an atlas: ξ̄_n by [`AtlasProjector::transfer`], the traction
    /// vector t = t_α ā^α kept, t'_β = t·ā'_β. Other masters have one chart: unchanged.
    pub fn transfer_history(&self, from: usize, xi_n: [f64; 2], t_t_n: [f64; 2], to: usize) -> ([f64; 2], [f64; 2]) {
        let Self::Atlas(pr) = self else { return (xi_n, t_t_n) };
        if from == to {
            return (xi_n, t_t_n);
        }
        let old = pr.evaluate(from, xi_n);
        let xi = pr.transfer(from, xi_n, to);
        let new = pr.evaluate(to, xi);
        let up = old.a_inv * nalgebra::Vector2::new(t_t_n[0], t_t_n[1]);
        let t = old.a_alpha[0] * up[0] + old.a_alpha[1] * up[1];
        (xi, [t.dot(&new.a_alpha[0]), t.dot(&new.a_alpha[1])])
    }

    /// `fraction` of a span (of a chart, on an atlas) in the parameter units of
    /// [`Self::project_extended`]'s margin (smooth masters; a facet net: none).
    pub fn span_margin(&self, fraction: f64) -> [f64; 2] {
        match self {
            Self::BSpline(pr) => pr.patch().n_spans().map(|n| fraction / n as f64),
            Self::Facet(_) => [0.0; 2],
            Self::Atlas(_) => [fraction; 2],
        }
    }

    /// The knot span of a single patch's foot point at `xi`, the element a frozen
    /// search holds; `None` on other masters (their cells come from the search).
    pub fn span_of(&self, xi: [f64; 2]) -> Option<[usize; 2]> {
        match self {
            Self::BSpline(pr) if xi.iter().all(|x| x.is_finite()) => Some(pr.patch().span_of(xi)),
            _ => None,
        }
    }

    /// Whether the single patch is C⁰ somewhere (order 2 with an interior knot):
    /// there the spans meet at kinks that a frozen search holds the slaves on.
    pub fn has_kinks(&self) -> bool {
        match self {
            Self::BSpline(pr) => (0..2).any(|al| pr.patch().orders()[al] == 2 && pr.patch().n_spans()[al] > 1),
            _ => false,
        }
    }

    /// Charts of an atlas (1 for other masters).
    pub fn n_charts(&self) -> usize {
        match self {
            Self::Atlas(p) => p.atlas().n_charts(),
            _ => 1,
        }
    }

    /// Whether the master is made of bilinear facets (a facet grid or a facet atlas).
    pub fn is_facets(&self) -> bool {
        match self {
            Self::Facet(_) => true,
            Self::Atlas(p) => p.atlas().is_facets(),
            Self::BSpline(_) => false,
        }
    }

    /// Whether the master is an atlas (its `cell` is `[chart, 0]`).
    pub fn is_atlas(&self) -> bool {
        matches!(self, Self::Atlas(_))
    }
}

