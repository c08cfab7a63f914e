//! Integration tests: the built binaries driven in temporary folders, with
//! independent checks by Python's meshio and gmsh (see `test.sh`), and the
//! library's import structure (`structure`).

mod cli;
mod common;
mod fuzz;
mod structure;
mod verification;
