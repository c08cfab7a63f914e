//! Contact: which surfaces meet, the master surface as the B-spline control net of
//! paper sec. 5, and the node-to-surface contact element of secs. 4 and 6.
//!
//! | file          | concept |
//! |---------------|---------|
//! | [`settings`]  | a pair's settings as plain data: enforcement, integration, mortar bases |
//! | [`definition`] | one pair as the problem defines it: the tagged pair, its settings, areas |
//! | [`net`]       | a master face set ordered into the a × b control net P_{i,j} (eq. 5.2), outward n̄ |
//! | [`tributary`] | slave tributary areas A_s (eq. 6.1) |
//! | [`law`]       | the contact law of one slave node as data: normal (eq. 4.2), Coulomb with its history (eqs. 4.5–4.8), the outcome |
//! | [`element`]   | one slave node against the master: g_N, t_N, residual and tangent (eqs. 4.2–4.3, 6.2–6.5) |
//! | [`friction`]  | Coulomb friction of one slave node: trial traction, return mapping (eqs. 4.5–4.9) |
//! | [`dual_element`] | the frictional element (and crease contact) on dual numbers, for its exact tangent |
//! | [`dual`]      | forward-mode dual numbers, for the exact frictional tangent |
//! | [`master`]    | the master surface behind one projection interface (B-spline or facets) |
//! | [`mortar`]    | segment-to-segment integration of the constraint over the slave faces (`integration: mortar`) |
//! | [`pair`]      | one pair during the solve: closest-point search (eq. 2.2), contact elements and active set, Uzawa updates and friction history |
//! | [`seam`]      | atlas masters: active nodes that a search loses at an edge between charts, for the log |
//! | [`adjust`]    | slave nodes moved onto the master before the first increment (stress-free) |

pub mod adjust;
#[cfg(test)]
mod atlas_fd;
pub mod definition;
pub mod dual;
pub mod dual_element;
pub mod element;
pub mod friction;
pub mod law;
pub mod master;
pub mod mortar;
pub mod net;
pub mod pair;
pub mod seam;
#[cfg(test)]
mod seam_tests;
pub mod settings;
pub mod tributary;

pub use net::{check_subdivision, control_net, master_net, smooth_net, ControlNet, MasterNet, NetChoice, NetError, NetShape, PatchNet, SmoothNet, SmoothNetError};
