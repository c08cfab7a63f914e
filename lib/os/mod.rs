//! What the operating system is asked for directly, and what a process keeps of
//! its own run: the binaries' allocator ([`large_pages`]), the timeline of a
//! run's phases ([`timeline`]) and the main thread's place among rayon's workers
//! ([`worker_pool`]).
#[cfg(target_os = "linux")]
pub mod large_pages;
pub mod timeline;
pub mod worker_pool;
