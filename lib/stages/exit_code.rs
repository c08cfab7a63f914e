//! Exit codes shared by every binary (ripgrep style): 0 success, 1 an I/O or
//! environment failure, 2 bad input (file, mesh, setup), 3 a solve that did not
//! converge (converged increments are kept on disk).

pub const IO: u8 = 1;
pub const BAD_INPUT: u8 = 2;
pub const DIVERGED: u8 = 3;
