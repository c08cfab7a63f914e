//! What the operating system is asked for directly.
#[cfg(target_os = "linux")]
pub mod large_pages;
