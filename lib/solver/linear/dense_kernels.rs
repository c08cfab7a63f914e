//! The dense kernels' first call, made early on a thread of its own.
//!
//! faer's matrix products go to `private-gemm-x86`, whose first call reads the
//! cache sizes from about a hundred sysfs files (`/sys/devices/system/cpu/*/cache`,
//! and `/proc/cpuinfo`): 1.3–1.5 ms on the reference machine, measured inside the
//! first factorization of the smallest Parisch level (97 unknowns; its second
//! factorization takes 12 µs). [`warm_in_background`] makes that call once per
//! process on a thread beside the reading of the model, on each worker of rayon's
//! pool, so the first factorization finds the sizes known and each worker's
//! packing buffers touched.

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

/// On every worker of rayon's pool (which this starts: its threads are up before
/// the first `rayon::join` needs them, about 1.4 ms at the Parisch r = 4), one
/// product in each precision the factorizations use, of the size of a supernode's
/// update: the first call reads the cache sizes, and each worker's first products
/// touch the pages of its own packing buffers, which the first factorization
/// otherwise pays for (13 % of its time at the Parisch r = 4, medians of 25 runs:
/// docs/performance.md).
fn warm() {
    rayon::broadcast(|_| {
        product::<f32>(WARM_N);
        product::<f64>(WARM_N);
    });
}

/// The warm-up products' order: above faer's own small kernels (16³), at the
/// width of a mid-sized supernode; 2 · 128³ multiply-adds take about 0.2 ms.
const WARM_N: usize = 128;

fn product<T: faer::traits::ComplexField + From<u8>>(n: usize) {
    let a = Mat::<T>::from_fn(n, n, |i, j| T::from(((i + j) % 7) as u8));
    let mut c = Mat::<T>::zeros(n, n);
    matmul(c.as_mut(), Accum::Replace, a.as_ref(), a.as_ref(), T::from(1u8), Par::Seq);
}
