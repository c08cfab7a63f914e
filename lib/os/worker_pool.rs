//! The process's main thread as one of rayon's workers.
//!
//! By default rayon's global pool has as many threads of its own as there are
//! cores, and a thread outside it that starts parallel work (the solver's main
//! thread) hands the work over and sleeps until the workers are done: on two cores
//! three threads, of which the main one is woken and put to sleep again at every
//! parallel phase, and two workers that spin and sleep between the main thread's
//! serial phases. [`join_as_worker`] makes the calling thread worker 0 of the
//! global pool instead (`ThreadPoolBuilder::use_current_thread`): on two cores one
//! thread is started, the main thread works on its own parallel phases at once and
//! runs no sleep/wake cycle of its own. Measured on the Parisch blocks r = 4 (3,238
//! unknowns, whole process, paired medians against the pool of two workers): A/B
//! wall 0.84 and 0.87 over 51 pairs, r = 1 0.84, the frictional crossed beams n = 4
//! 0.94; r = 8 1.00 (docs/performance.md).
//!
//! A worker 0 of this kind runs pool jobs only while it waits inside rayon (a
//! `join`, a parallel iterator, a scope) or when it yields to the pool: code that
//! blocks outside rayon on a task it gave the pool must yield first (the background
//! analysis' wait, `solver::linear::faer_direct`). Only a thread that lives as long
//! as the process may join: the binaries' `main`, never a library caller's thread
//! (a test harness' thread that ended would leave the pool's broadcasts waiting).

/// Make the calling thread worker 0 of rayon's global pool, with as many workers in
/// all as rayon would start (`RAYON_NUM_THREADS`, else the cores), when that is two
/// or more. False when it is one (the pool's one worker of its own then runs what
/// other threads give it, the pre-solve check's projections among them, while the
/// main thread blocks outside rayon waiting for their result: as worker 0 of a pool
/// of one it would wait for itself), when the global pool exists already, or when
/// it cannot be built: rayon then runs as before, with workers of its own.
pub fn join_as_worker() -> bool {
    let threads = std::env::var("RAYON_NUM_THREADS")
        .ok()
        .and_then(|v| v.trim().parse::<usize>().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    threads >= 2 && rayon::ThreadPoolBuilder::new().num_threads(threads).use_current_thread().build_global().is_ok()
}
