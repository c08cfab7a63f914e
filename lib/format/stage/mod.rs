//! The versioned container every stage file uses (`.scmesh`, and later the contact
//! model and results files).
//!
//! Layout (all integers little-endian), specified in `docs/formats.md`:
//! ```text
//! "splinecontact <format> <major>.<minor>\n"      header line, ASCII
//! records, each starting with a 4-byte tag:
//!   "META" u64 len, UTF-8 YAML (small structured data: names, settings)
//!   "ARRY" u32 name_len, name, u8 dtype, u8 ndim, u64 dims[ndim], payload
//!   "END!" u64 number of records before it, u64 checksum (chained over segments)
//! ```
//! A file is one or more **segments**, each a run of records closed by an `END!`.
//! Files written at once have one; a results file grows by one segment per
//! converged increment, appended to the file, so a long run never rewrites what it
//! already wrote. A reader takes every complete segment; bytes after the last one
//! that do not form a complete segment (an append interrupted by a crash) are
//! left out and reported as [`StageFile::tail`].
//! Bulk data is raw little-endian binary (fast: a 1M-hex mesh is ~90 MB and
//! reads in a fraction of a second); everything small is YAML so `sc-export
//! --format yaml` can print any stage file.
//!
//! Readers accept the same major version with any minor version (new minor
//! versions only add records) and refuse anything else with a message that says
//! what was found and what is read.
//!
//! | file | concept |
//! |------|---------|
//! | [`record`] | the array records: element type, payload, name and shape |
//! | [`checksum`] | the checksum that closes a segment |
//! | [`writer`] | [`StageWriter`]: a file, or segments to append to one |
//! | [`reader`] | [`StageFile`]: every complete segment of a file |
//! | [`files`] | standard input and output, atomic writes, paths relative to a file |
//! | [`error`] | [`StageError`], naming the file |

mod checksum;
pub mod error;
pub mod files;
pub mod reader;
pub mod record;
pub mod writer;

pub use error::StageError;
pub use files::{output_kind, read_input, resolve, temp_path, write_atomic, write_atomic_unsynced, write_atomic_with, prepare_unsynced, OutputKind, Prepared};
pub use reader::StageFile;
pub use record::{Array, ArrayData, Dtype};
pub use writer::{SegmentEnd, StageWriter};

#[cfg(test)]
mod tests;
