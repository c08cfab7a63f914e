//! What can go wrong reading or writing a stage file.

use std::io;

/// What went wrong reading or writing a stage file. Every variant names the file.
#[derive(Debug, thiserror::Error)]
pub enum StageError {
    #[error("{path}: cannot {action}: {source}")]
    Io { path: String, action: &'static str, source: io::Error },
    #[error("{path}: not a splinecontact stage file (expected a header line \"splinecontact {expected} <major>.<minor>\", found {found:?})")]
    NotStageFile { path: String, expected: String, found: String },
    #[error("{path}: is a splinecontact '{found}' file, but a '{expected}' file is expected here")]
    WrongFormat { path: String, expected: String, found: String },
    #[error("{path}: is {format} version {found_major}.{found_minor}; this build reads {format} {reads_major}.x (newer major versions are not understood, upgrade splinecontact)")]
    UnsupportedVersion {
        path: String,
        format: String,
        found_major: u32,
        found_minor: u32,
        reads_major: u32,
    },
    #[error("{path}: truncated at byte {offset}: {what} (the file ends early: was it written completely?)")]
    Truncated { path: String, offset: u64, what: String },
    #[error("{path}: corrupt at byte {offset}: {what}")]
    Corrupt { path: String, offset: u64, what: String },
    #[error("{path}: missing record '{name}' ({what})")]
    Missing { path: String, name: String, what: String },
    #[error("{path}: record '{name}': {what}")]
    Invalid { path: String, name: String, what: String },
}
