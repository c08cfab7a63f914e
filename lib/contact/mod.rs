//! Contact definitions: which surfaces meet, and the master surface as the
//! B-spline control net of paper sec. 5.
//!
//! | file    | concept |
//! |---------|---------|
//! | [`net`] | a master face set ordered into the a × b control net P_{i,j} (eq. 5.2), outward n̄ |

pub mod element;
pub mod net;

pub use net::{control_net, ControlNet, NetError};
