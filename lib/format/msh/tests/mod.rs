//! Tests of the whole reader on tiny meshes written in all four encodings
//! (2.2/4.1 × ASCII/binary) by a small writer ([`writer`]), and on gmsh's own
//! output in `tests/data/msh/`.

use super::*;
use crate::mesh::{HexFace, Mesh};
use writer::*;

mod conversion;
mod encodings;
mod errors;
mod gmsh_files;
mod robustness;
mod writer;

fn parse_ok(bytes: &[u8]) -> (Mesh, ImportReport) {
    match parse_msh("t.msh", bytes) {
        Ok(x) => x,
        Err(e) => panic!("{e}\n{}", String::from_utf8_lossy(bytes)),
    }
}

fn parse_err(bytes: &[u8]) -> String {
    match parse_msh("t.msh", bytes) {
        Ok(_) => panic!("expected an error for\n{}", String::from_utf8_lossy(bytes)),
        Err(e) => e.to_string(),
    }
}
