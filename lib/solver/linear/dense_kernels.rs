//! The dense kernels' first call, made early on a thread of its own.
//!
//! faer's matrix products go to `private-gemm-x86`, whose first call reads the
//! cache sizes from about a hundred sysfs files (`/sys/devices/system/cpu/*/cache`,
//! and `/proc/cpuinfo`): 1.3–1.5 ms on the reference machine, measured inside the
//! first factorization of the smallest Parisch level (97 unknowns; its second
//! factorization takes 12 µs). [`warm_in_background`] makes that call once per
//! process on a thread beside the reading of the model, so the first
//! factorization finds the sizes known.

use std::sync::Once;

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};

/// Start the products' first call on a thread of its own (once per process; the
/// later calls return at once). A thread that cannot be had leaves the first call
/// to the first factorization, as without this.
pub fn warm_in_background() {
    static STARTED: Once = Once::new();
    STARTED.call_once(|| {
        let _ = std::thread::Builder::new().name("sc-kernels".into()).spawn(warm);
    });
}

/// One product in each precision the factorizations use, above the size that
/// faer computes by its own small kernels (16³ multiply-adds).
fn warm() {
    const N: usize = 17;
    let a = Mat::<f32>::from_fn(N, N, |i, j| (i + j) as f32);
    let mut c = Mat::<f32>::zeros(N, N);
    matmul(c.as_mut(), Accum::Replace, a.as_ref(), a.as_ref(), 1.0, Par::Seq);
    let a = Mat::<f64>::from_fn(N, N, |i, j| (i + j) as f64);
    let mut c = Mat::<f64>::zeros(N, N);
    matmul(c.as_mut(), Accum::Replace, a.as_ref(), a.as_ref(), 1.0, Par::Seq);
}
