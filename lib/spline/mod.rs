//! The B-spline master surface (paper sec. 5) and its bilinear-facet counterpart.
//!
//! One tensor-product B-spline patch smooths the whole master contact surface; its
//! control points are the master surface nodes, so the patch moves with the body
//! (every evaluation takes the *current* control point coordinates).
//!
//! | file            | concept |
//! |-----------------|---------|
//! | [`knots`]       | open (clamped) uniform knot vectors, eq. 5.1 |
//! | [`basis`]       | Cox–de Boor basis functions and their derivatives, eq. 5.3 |
//! | [`patch`]       | tensor-product patch: x̄, ā_α, ā_{α,β}, ā_{α,βγ}, n̄, ā_αβ, b̄_αβ, Q_{a/b} (eqs. 4.11–4.13, 5.2, 6.3) |
//! | [`facet`]       | the same control net read as bilinear 4-node facets (for comparison) |
//! | [`box_tree`]    | a refittable hierarchy of boxes and its branch-and-bound walk (the global search of eq. 2.2) |
//! | [`span_tree`]   | AABB hierarchy over knot spans / facet cells, refittable |
//! | [`closest_point`] | the box-constrained Newton iteration of eq. 2.2 on one smooth map, the outside test |
//! | [`projection`]  | closest-point projection, eq. 2.2 (global search + box-constrained Newton) |
//! | [`subdivision`] | Catmull–Clark limit surface of any manifold quad control mesh (exact evaluation, basis) |
//! | [`atlas`]       | a master of many charts: periodic and multi-patch B-splines, subdivision faces, facets on any quad surface |
//!
//! ## Notation (paper symbol ↔ Rust name ↔ equation)
//! | paper | Rust | eq. |
//! |-------|------|-----|
//! | Ξ = [ξ_1 … ξ_{n+k}] | [`KnotVector`] | 5.1 |
//! | N_{i,k}(ξ), M_{j,l}(η) | [`basis::ders_basis_funs_into`] | 5.3 |
//! | ξ̄ = (ξ¹, ξ²) | `xi: [f64; 2]` | 4.10 |
//! | x̄ | `x_bar` | 2.2, 5.2 |
//! | ā_α = x̄_{,α} | `a_alpha[α]` | 4.13 |
//! | ā_{α,β} | `a_alpha_beta[α][β]` | 4.17, 4.24 |
//! | ā_{α,βγ} | `a_alpha_beta_gamma[α][β][γ]` | 4.24 |
//! | ā_αβ = ā_α·ā_β, ā^{αβ} | `a_ab`, `a_inv` | 4.11 |
//! | b̄_αβ = ā_{α,β}·n̄ | `b_ab` | 4.12 |
//! | n̄ = ā_1×ā_2/‖ā_1×ā_2‖ | `n_bar` | 4.3 |
//! | Q_{a/b} = N_a M_b, Q_{a/b,α}, Q_{a/b,αβ} | `SurfaceBasis::{q, q_alpha, q_alpha_beta}` | 6.2–6.3 |
//! | g (signed, along n̄) | `Projection::g` | 2.2, 4.3 |
//!
//! Control points are stored `i + na * j` with `i` along direction 1 (ξ¹) and `j`
//! along direction 2 (ξ²). The parameter domain is `[0, 1]²`.

pub mod atlas;
pub mod basis;
pub mod box_tree;
pub mod closest_point;
pub mod facet;
pub mod knots;
pub mod patch;
pub mod projection;
pub mod span_tree;
pub mod subdivision;

#[cfg(test)]
mod fd;

pub use atlas::{Atlas, AtlasProjector, EdgeKind};
pub use facet::{FacetProjector, FacetSurface};
pub use knots::KnotVector;
pub use patch::{BSplinePatch, SurfaceBasis, SurfacePoint};
pub use projection::{BSplineProjector, Projection, ProjectionOptions};
pub use span_tree::SpanTree;

/// Highest supported order per direction (order = degree + 1; 6 = quintic).
pub const MAX_ORDER: usize = 6;
/// Most nonzero tensor-product basis functions at one parameter (`MAX_ORDER²`).
pub const MAX_NODES: usize = MAX_ORDER * MAX_ORDER;

/// `f((i, chunk))` for every `chunk`-sized piece of `samples` (a projector's
/// surface samples refitted to new control points): through rayon's pool from
/// `parallel_from` samples on, on the calling thread below. A small refit takes
/// tens of microseconds; handed to the pool while its workers are busy (their
/// start-up and warm-up at the beginning of a solve, the first analysis beside the
/// set-up) the caller waited 1–4 ms for them (Parisch r = 4: 1,296 B-spline
/// samples, the first refit 1.1–2.1 ms through the pool, 0.02–0.07 ms once it is
/// idle).
pub(crate) fn refit_samples_in_chunks<F>(samples: &mut [Vec3], chunk: usize, parallel_from: usize, f: F)
where
    F: Fn((usize, &mut [Vec3])) + Sync + Send,
{
    use rayon::prelude::*;
    if samples.len() < parallel_from {
        samples.chunks_mut(chunk).enumerate().for_each(f);
    } else {
        samples.par_chunks_mut(chunk).enumerate().for_each(f);
    }
}

/// Point or vector in 3D.
pub type Vec3 = nalgebra::Vector3<f64>;
/// 2×2 surface tensor (metric, curvature).
pub type Mat2 = nalgebra::Matrix2<f64>;

/// Everything that can be wrong with a patch definition or its control net.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SplineError {
    #[error("B-spline order {order} is below 2 (order = degree + 1; order 2 is bilinear)")]
    OrderTooLow { order: usize },
    #[error("B-spline order {order} exceeds the supported maximum {max}")]
    OrderTooHigh { order: usize, max: usize },
    #[error("a {n}-node row cannot carry order {order} (order k needs at least k control points)")]
    TooFewControlPoints { n: usize, order: usize },
    #[error("control net has {got} points, the patch expects {na} × {nb} = {expected}")]
    ControlNetSize { got: usize, na: usize, nb: usize, expected: usize },
    #[error("control point {index} is not finite: {point:?}")]
    NonFiniteControlPoint { index: usize, point: [f64; 3] },
    #[error("{what} is not available in this build")]
    Unsupported { what: String },
    #[error("Catmull–Clark master: {message}")]
    Subdivision { message: String },
}
