//! The wall-clock times a run records in its results (`seconds_contact`,
//! `seconds_assembly`, `seconds_factor`, `seconds_solve` per Newton iteration,
//! `seconds_output` per increment) and its convergence CSV.
//!
//! They are the only part of a `.scres` that differs between two runs of the same
//! input (every number the solve computes is the same bit for bit, with 1 or 2
//! threads: `tests/verification/determinism.rs`). With the environment variable
//! `SC_REPRODUCIBLE=1` they are recorded as 0, and two runs give byte-identical
//! files — what a reproducible-build check or a results archive compares.

use std::sync::OnceLock;
use std::time::Instant;

/// Whether `SC_REPRODUCIBLE` is set (to anything but empty or `0`).
pub fn reproducible() -> bool {
    static R: OnceLock<bool> = OnceLock::new();
    *R.get_or_init(|| std::env::var_os("SC_REPRODUCIBLE").is_some_and(|v| !v.is_empty() && v != "0"))
}

/// Seconds since `start`, or 0 when the run is to be reproducible.
pub fn seconds_since(start: Instant) -> f64 {
    if reproducible() {
        0.0
    } else {
        start.elapsed().as_secs_f64()
    }
}
