//! The master surface as the closest-point search sees it: the B-spline patch of
//! sec. 5 or the bilinear facets over the same control net, each with its projector
//! (eq. 2.2), behind one interface for the contact pair and the mortar integration.

use crate::spline::{BSplineProjector, FacetProjector, Projection, SplineError, SurfacePoint, Vec3};

/// The master as the projection sees it.
pub enum Projector {
    BSpline(BSplineProjector),
    Facet(FacetProjector),
}

impl Projector {
    pub fn update(&mut self, x: &[Vec3]) -> Result<(), SplineError> {
        match self {
            Self::BSpline(p) => p.update(x),
            Self::Facet(p) => p.update(x),
        }
    }
    /// The projection and, for facets, the cell it lies on (kept from `prev` at ties).
    pub fn project(&self, p: &Vec3, prev: Option<[usize; 2]>) -> (Projection, Option<[usize; 2]>) {
        match self {
            Self::BSpline(pr) => (pr.project(p), None),
            Self::Facet(pr) => {
                let (proj, cell) = pr.project_keeping(p, prev);
                (proj, Some(cell))
            }
        }
    }
    /// With the master element held (a frozen search): a facet slave projects onto
    /// its last cell's continued bilinear map, a slave in crease contact onto the same
    /// crease (`last`: its previous projection); a B-spline slave as usual (the patch
    /// is one smooth map, there is no element to hold).
    pub fn project_frozen(&self, p: &Vec3, prev: Option<[usize; 2]>, last: &Projection) -> (Projection, Option<[usize; 2]>) {
        match (self, prev) {
            (Self::Facet(pr), Some(c)) => {
                let crease = [0, 1].map(|al| last.clamped[al].then_some(last.xi[al]));
                let (proj, cell) = pr.project_on_cell(p, c, crease);
                (proj, Some(cell))
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
        }
    }
    pub fn evaluate(&self, xi: [f64; 2], cell: Option<[usize; 2]>) -> SurfacePoint {
        match (self, cell) {
            (Self::BSpline(p), _) => p.evaluate(xi),
            (Self::Facet(p), Some(c)) => p.evaluate_in_cell(xi, c),
            (Self::Facet(p), None) => p.evaluate(xi),
        }
    }
}

