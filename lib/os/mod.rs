//! What the operating system is asked for directly, and what a process keeps of
//! its own run: the binaries' allocator ([`large_pages`]) and the timeline of a
//! run's phases ([`timeline`]).
#[cfg(target_os = "linux")]
pub mod large_pages;
pub mod timeline;
