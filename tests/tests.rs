//! Integration tests: the built binaries driven in temporary folders, with
//! independent checks by Python's meshio and gmsh (see `test.sh`).

mod cli;
mod common;
mod fuzz;
mod verification;
