//! Why sc-tag could not build a contact pair (its own file: the stage error wraps it,
//! and the tag stage returns the stage error).

use crate::contact::NetError;
use crate::spline::SplineError;

/// Why a pair could not be built.
#[derive(Debug, thiserror::Error)]
pub enum TagError {
    #[error("--pair {given:?}: {why} (expected NAME:SLAVE:MASTER, NAME:SLAVE:MASTER:KIND or NAME:SLAVE:MASTER:KIND:KA:KB with KIND bspline, patch, periodic, multipatch, subdivision or facet)")]
    PairSyntax { given: String, why: String },
    #[error("{path}: {message}")]
    PairsFile { path: String, message: String },
    #[error("no contact pairs given (use --pair or --pairs)")]
    NoPairs,
    #[error("pair '{0}' is defined twice")]
    Duplicate(String),
    #[error("pair '{pair}': slave '{slave}' is neither a node set nor a face set (node sets: {node_sets}; face sets: {face_sets})")]
    UnknownSlave { pair: String, slave: String, node_sets: String, face_sets: String },
    #[error("pair '{pair}': master {source}")]
    Master { pair: String, source: NetError },
    #[error("pair '{pair}': master '{master}' is a {net}: {source}")]
    Orders { pair: String, master: String, net: String, source: SplineError },
    #[error("pair '{pair}': a facet master is bilinear (orders [2, 2]); orders {orders:?} were given")]
    FacetOrders { pair: String, orders: [usize; 2] },
    #[error("pair '{pair}': a subdivision master is bicubic where regular (orders [4, 4]); orders {orders:?} were given")]
    SubdivisionOrders { pair: String, orders: [usize; 2] },
    #[error("pair '{pair}': master face set '{master}' cannot carry a Catmull–Clark surface: {why}")]
    Subdivision { pair: String, master: String, why: String },
    #[error("pair '{pair}': master face set '{master}' has no smooth master (a `facet` master takes any quad set):\n  one grid: {grid}\n  several grids: {patches}\n  subdivision: {subdivision}")]
    NoSmoothMaster { pair: String, master: String, grid: String, patches: String, subdivision: String },
}
