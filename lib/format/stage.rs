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

use std::fs;
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

/// Element type of an array record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dtype {
    F64 = 1,
    U32 = 2,
    U64 = 3,
    I32 = 4,
    U8 = 5,
}

impl Dtype {
    fn from_u8(v: u8) -> Option<Self> {
        Some(match v {
            1 => Self::F64,
            2 => Self::U32,
            3 => Self::U64,
            4 => Self::I32,
            5 => Self::U8,
            _ => return None,
        })
    }
    pub fn size(self) -> usize {
        match self {
            Self::F64 | Self::U64 => 8,
            Self::U32 | Self::I32 => 4,
            Self::U8 => 1,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Self::F64 => "f64",
            Self::U32 => "u32",
            Self::U64 => "u64",
            Self::I32 => "i32",
            Self::U8 => "u8",
        }
    }
}

/// Typed payload of an array record.
#[derive(Debug, Clone, PartialEq)]
pub enum ArrayData {
    F64(Vec<f64>),
    U32(Vec<u32>),
    U64(Vec<u64>),
    I32(Vec<i32>),
    U8(Vec<u8>),
}

impl ArrayData {
    pub fn dtype(&self) -> Dtype {
        match self {
            Self::F64(_) => Dtype::F64,
            Self::U32(_) => Dtype::U32,
            Self::U64(_) => Dtype::U64,
            Self::I32(_) => Dtype::I32,
            Self::U8(_) => Dtype::U8,
        }
    }
    pub fn len(&self) -> usize {
        match self {
            Self::F64(v) => v.len(),
            Self::U32(v) => v.len(),
            Self::U64(v) => v.len(),
            Self::I32(v) => v.len(),
            Self::U8(v) => v.len(),
        }
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A named n-dimensional array (row-major).
#[derive(Debug, Clone, PartialEq)]
pub struct Array {
    pub name: String,
    pub dims: Vec<u64>,
    pub data: ArrayData,
}

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

const MAGIC: &str = "splinecontact";

/// 64-bit FNV-1a over 8-byte words (cheap enough for 100 MB files, catches
/// flipped or missing bytes that lengths alone would not).
#[derive(Clone, Copy)]
struct Checksum(u64);

impl Checksum {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    fn update(&mut self, bytes: &[u8]) {
        let mut h = self.0;
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let w = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
            h = (h ^ w).wrapping_mul(0x0000_0100_0000_01b3);
        }
        for &b in chunks.remainder() {
            h = (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
        self.0 = h;
    }
}

/// Where a file's last segment ended: the record count and checksum the next
/// segment continues from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SegmentEnd {
    records: u64,
    checksum: u64,
}

/// Builds a stage file (or segments to append to one) in memory;
/// [`StageWriter::finish`] returns its bytes.
pub struct StageWriter {
    buf: Vec<u8>,
    records: u64,
    /// The checksum the current segment continues (that of the last `END!`).
    chain: u64,
    /// Where the current segment starts in `buf`.
    segment_start: usize,
    /// Whether any segment was closed.
    closed: bool,
}

impl StageWriter {
    pub fn new(format: &str, major: u32, minor: u32) -> Self {
        let mut buf = Vec::with_capacity(1 << 16);
        buf.extend_from_slice(format!("{MAGIC} {format} {major}.{minor}\n").as_bytes());
        Self { buf, records: 0, chain: Checksum::new().0, segment_start: 0, closed: false }
    }

    /// Segments to append to a file whose last segment ended at `end` (no header).
    pub fn append_to(end: SegmentEnd) -> Self {
        Self { buf: Vec::with_capacity(1 << 16), records: end.records, chain: end.checksum, segment_start: 0, closed: true }
    }

    /// Close the current segment with its `END!`: the number of records in the file
    /// so far, and the checksum of the segment's bytes continuing the last `END!`'s.
    pub fn end_segment(&mut self) {
        let mut c = Checksum(self.chain);
        c.update(&self.buf[self.segment_start..]);
        self.buf.extend_from_slice(b"END!");
        self.buf.extend_from_slice(&self.records.to_le_bytes());
        self.buf.extend_from_slice(&c.0.to_le_bytes());
        self.chain = c.0;
        self.segment_start = self.buf.len();
        self.closed = true;
    }

    pub fn meta(&mut self, yaml: &str) {
        self.buf.extend_from_slice(b"META");
        self.buf.extend_from_slice(&(yaml.len() as u64).to_le_bytes());
        self.buf.extend_from_slice(yaml.as_bytes());
        self.records += 1;
    }

    fn array_header(&mut self, name: &str, dtype: Dtype, dims: &[u64]) {
        self.buf.extend_from_slice(b"ARRY");
        self.buf.extend_from_slice(&(name.len() as u32).to_le_bytes());
        self.buf.extend_from_slice(name.as_bytes());
        self.buf.push(dtype as u8);
        self.buf.push(dims.len() as u8);
        for d in dims {
            self.buf.extend_from_slice(&d.to_le_bytes());
        }
        let n: u64 = dims.iter().product();
        self.buf.reserve(n as usize * dtype.size());
        self.records += 1;
    }

    pub fn f64s(&mut self, name: &str, dims: &[u64], v: &[f64]) {
        debug_assert_eq!(dims.iter().product::<u64>() as usize, v.len());
        self.array_header(name, Dtype::F64, dims);
        v.iter().for_each(|x| self.buf.extend_from_slice(&x.to_le_bytes()));
    }
    pub fn u32s(&mut self, name: &str, dims: &[u64], v: &[u32]) {
        debug_assert_eq!(dims.iter().product::<u64>() as usize, v.len());
        self.array_header(name, Dtype::U32, dims);
        v.iter().for_each(|x| self.buf.extend_from_slice(&x.to_le_bytes()));
    }
    pub fn u64s(&mut self, name: &str, dims: &[u64], v: &[u64]) {
        debug_assert_eq!(dims.iter().product::<u64>() as usize, v.len());
        self.array_header(name, Dtype::U64, dims);
        v.iter().for_each(|x| self.buf.extend_from_slice(&x.to_le_bytes()));
    }
    pub fn i32s(&mut self, name: &str, dims: &[u64], v: &[i32]) {
        debug_assert_eq!(dims.iter().product::<u64>() as usize, v.len());
        self.array_header(name, Dtype::I32, dims);
        v.iter().for_each(|x| self.buf.extend_from_slice(&x.to_le_bytes()));
    }
    pub fn u8s(&mut self, name: &str, dims: &[u64], v: &[u8]) {
        debug_assert_eq!(dims.iter().product::<u64>() as usize, v.len());
        self.array_header(name, Dtype::U8, dims);
        self.buf.extend_from_slice(v);
    }

    /// Close the open segment (if it holds anything, or nothing was closed yet) and
    /// return the bytes: the complete file, or the segments to append.
    pub fn finish(self) -> Vec<u8> {
        self.finish_segments().0
    }

    /// As [`Self::finish`], with where the last segment ended (to append more later).
    pub fn finish_segments(mut self) -> (Vec<u8>, SegmentEnd) {
        if !self.closed || self.buf.len() > self.segment_start {
            self.end_segment();
        }
        (self.buf, SegmentEnd { records: self.records, checksum: self.chain })
    }
}

/// A stage file read into memory.
#[derive(Debug, Clone)]
pub struct StageFile {
    /// Where it was read from (for messages).
    pub path: String,
    pub format: String,
    pub major: u32,
    pub minor: u32,
    /// YAML metadata records, in file order (usually one).
    pub meta: Vec<String>,
    pub arrays: Vec<Array>,
    /// Why the bytes after the last complete segment were left out (an append
    /// interrupted by a crash leaves a partial segment); `None` when the file ends
    /// with a complete segment.
    pub tail: Option<String>,
}

struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    path: &'a str,
    /// The checksum the current segment continues (the last `END!`'s) and where the
    /// segment starts.
    chain: u64,
    segment_start: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], StageError> {
        if self.bytes.len() - self.pos < n {
            return Err(StageError::Truncated {
                path: self.path.to_string(),
                offset: self.bytes.len() as u64,
                what: format!("{what} needs {n} bytes at byte {}, only {} left", self.pos, self.bytes.len() - self.pos),
            });
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    fn u64(&mut self, what: &str) -> Result<u64, StageError> {
        let b = self.take(8, what)?;
        Ok(u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }
    fn u32(&mut self, what: &str) -> Result<u32, StageError> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }
    fn u8(&mut self, what: &str) -> Result<u8, StageError> {
        Ok(self.take(1, what)?[0])
    }
}

/// What [`StageFile::record`] read.
enum Record {
    Data,
    End,
}

fn decode<T, const N: usize>(b: &[u8], f: fn([u8; N]) -> T) -> Vec<T> {
    b.chunks_exact(N).map(|c| f(c.try_into().expect("chunk size"))).collect()
}

impl StageFile {
    /// Parse a stage file, checking the header against `expected_format` and
    /// `reads_major` (pass `None` to accept any format, e.g. for a dump).
    pub fn parse(path: &str, bytes: &[u8], expected: Option<(&str, u32)>) -> Result<Self, StageError> {
        let nl = bytes.iter().take(256).position(|&b| b == b'\n');
        let header = nl.map(|i| String::from_utf8_lossy(&bytes[..i]).into_owned());
        let exp_name = expected.map(|e| e.0).unwrap_or("<format>").to_string();
        let not_stage = |found: String| StageError::NotStageFile { path: path.to_string(), expected: exp_name.clone(), found };
        let header = match header {
            Some(h) => h,
            None => {
                let shown: String = String::from_utf8_lossy(&bytes[..bytes.len().min(40)]).into_owned();
                return Err(not_stage(shown));
            }
        };
        let parts: Vec<&str> = header.split(' ').collect();
        if parts.len() != 3 || parts[0] != MAGIC {
            return Err(not_stage(header));
        }
        let format = parts[1].to_string();
        let (major, minor) = parts[2]
            .split_once('.')
            .and_then(|(a, b)| Some((a.parse::<u32>().ok()?, b.parse::<u32>().ok()?)))
            .ok_or_else(|| not_stage(header.clone()))?;
        if let Some((name, reads_major)) = expected {
            if format != name {
                return Err(StageError::WrongFormat { path: path.to_string(), expected: name.to_string(), found: format });
            }
            if major != reads_major {
                return Err(StageError::UnsupportedVersion {
                    path: path.to_string(),
                    format,
                    found_major: major,
                    found_minor: minor,
                    reads_major,
                });
            }
        }
        let mut c = Cursor { bytes, pos: header.len() + 1, path, chain: Checksum::new().0, segment_start: 0 };
        let mut meta = Vec::new();
        let mut arrays = Vec::new();
        let mut records = 0u64;
        // what the complete segments so far hold (META and array counts)
        let mut complete: Option<(usize, usize)> = None;
        let result = loop {
            match Self::record(&mut c, &mut meta, &mut arrays, records) {
                Ok(Record::Data) => records += 1,
                Ok(Record::End) => {
                    complete = Some((meta.len(), arrays.len()));
                    if c.pos == bytes.len() {
                        break Ok(());
                    }
                }
                Err(e) => break Err(e),
            }
        };
        let tail = match (result, complete) {
            (Ok(()), _) => None,
            (Err(e), None) => return Err(e),
            // a complete segment was read: what follows is an interrupted append
            (Err(e), Some((n_meta, n_arrays))) => {
                meta.truncate(n_meta);
                arrays.truncate(n_arrays);
                let start = c.segment_start;
                Some(format!("the {} bytes after byte {start} are not a complete segment and were left out (an interrupted write?): {e}", bytes.len() - start))
            }
        };
        Ok(Self { path: path.to_string(), format, major, minor, meta, arrays, tail })
    }

    /// Reads one record at the cursor: a META or ARRY (pushed), or an END! (checked
    /// against the record count and the chained checksum of its segment).
    fn record(c: &mut Cursor, meta: &mut Vec<String>, arrays: &mut Vec<Array>, records: u64) -> Result<Record, StageError> {
        let (bytes, path, at) = (c.bytes, c.path, c.pos);
        let tag = c.take(4, "a record tag")?;
        match tag {
            b"META" => {
                let len = c.u64("META length")? as usize;
                let text = c.take(len, "META text")?;
                let text = std::str::from_utf8(text).map_err(|e| StageError::Corrupt {
                    path: path.to_string(),
                    offset: at as u64,
                    what: format!("META record is not UTF-8: {e}"),
                })?;
                meta.push(text.to_string());
            }
            b"ARRY" => {
                let name_len = c.u32("array name length")? as usize;
                if name_len > 4096 {
                    return Err(StageError::Corrupt { path: path.to_string(), offset: at as u64, what: format!("array name length {name_len} is implausible") });
                }
                let name = String::from_utf8_lossy(c.take(name_len, "array name")?).into_owned();
                let dt = c.u8("array dtype")?;
                let dtype = Dtype::from_u8(dt).ok_or_else(|| StageError::Corrupt {
                    path: path.to_string(),
                    offset: at as u64,
                    what: format!("array '{name}' has unknown dtype code {dt}"),
                })?;
                let ndim = c.u8("array rank")? as usize;
                let mut dims = Vec::with_capacity(ndim);
                for _ in 0..ndim {
                    dims.push(c.u64("array dimension")?);
                }
                let n = dims.iter().try_fold(1u64, |a, &d| a.checked_mul(d)).and_then(|n| n.checked_mul(dtype.size() as u64));
                let nbytes = match n {
                    Some(n) if n <= bytes.len() as u64 => n as usize,
                    _ => {
                        return Err(StageError::Truncated {
                            path: path.to_string(),
                            offset: bytes.len() as u64,
                            what: format!("array '{name}' of shape {dims:?} does not fit in the file"),
                        })
                    }
                };
                let b = c.take(nbytes, &format!("data of array '{name}'"))?;
                let data = match dtype {
                    Dtype::F64 => ArrayData::F64(decode(b, f64::from_le_bytes)),
                    Dtype::U32 => ArrayData::U32(decode(b, u32::from_le_bytes)),
                    Dtype::U64 => ArrayData::U64(decode(b, u64::from_le_bytes)),
                    Dtype::I32 => ArrayData::I32(decode(b, i32::from_le_bytes)),
                    Dtype::U8 => ArrayData::U8(b.to_vec()),
                };
                arrays.push(Array { name, dims, data });
            }
            b"END!" => {
                let count = c.u64("END record count")?;
                let sum = c.u64("END checksum")?;
                if count != records {
                    return Err(StageError::Corrupt { path: path.to_string(), offset: at as u64, what: format!("END says {count} records, found {records}") });
                }
                let mut ck = Checksum(c.chain);
                ck.update(&bytes[c.segment_start..at]);
                if ck.0 != sum {
                    return Err(StageError::Corrupt { path: path.to_string(), offset: at as u64, what: "checksum mismatch: the file was modified or damaged".into() });
                }
                c.chain = sum;
                c.segment_start = c.pos;
                return Ok(Record::End);
            }
            other => {
                return Err(StageError::Corrupt {
                    path: path.to_string(),
                    offset: at as u64,
                    what: format!("unknown record tag {:?} (expected META, ARRY or END!)", String::from_utf8_lossy(other)),
                })
            }
        }
        Ok(Record::Data)
    }

    /// Read a file (or standard input for `-`) and parse it.
    pub fn read(path: &Path, expected: Option<(&str, u32)>) -> Result<Self, StageError> {
        let shown = path.display().to_string();
        let bytes = read_input(path).map_err(|source| StageError::Io { path: shown.clone(), action: "read", source })?;
        Self::parse(&shown, &bytes, expected)
    }

    /// Read any stage file; when its format is one of `known` (name, major version
    /// read), the version is checked as [`StageFile::read`] would, before anything else.
    pub fn read_known(path: &Path, known: &[(&str, u32)]) -> Result<Self, StageError> {
        let shown = path.display().to_string();
        let bytes = read_input(path).map_err(|source| StageError::Io { path: shown.clone(), action: "read", source })?;
        let head = &bytes[..bytes.len().min(256)];
        let format = head.split(|&b| b == b'\n').next().and_then(|l| std::str::from_utf8(l).ok()).and_then(|l| l.split(' ').nth(1));
        let expected = format.and_then(|f| known.iter().find(|(k, _)| *k == f)).copied();
        Self::parse(&shown, &bytes, expected)
    }

    pub fn array(&self, name: &str) -> Option<&Array> {
        self.arrays.iter().find(|a| a.name == name)
    }

    fn missing(&self, name: &str, what: &str) -> StageError {
        StageError::Missing { path: self.path.clone(), name: name.to_string(), what: what.to_string() }
    }

    pub fn invalid(&self, name: &str, what: impl Into<String>) -> StageError {
        StageError::Invalid { path: self.path.clone(), name: name.to_string(), what: what.into() }
    }

    fn typed<'a, T>(&'a self, name: &str, cols: Option<u64>, pick: fn(&'a ArrayData) -> Option<&'a Vec<T>>, dtype: Dtype) -> Result<&'a [T], StageError> {
        let a = self.array(name).ok_or_else(|| self.missing(name, dtype.name()))?;
        let v = pick(&a.data).ok_or_else(|| self.invalid(name, format!("expected dtype {}, found {}", dtype.name(), a.data.dtype().name())))?;
        if let Some(c) = cols {
            if a.dims.len() != 2 || a.dims[1] != c {
                return Err(self.invalid(name, format!("expected shape [n, {c}], found {:?}", a.dims)));
            }
        }
        Ok(v)
    }

    /// The f64 array `name`; with `cols`, checks it has shape `[n, cols]`.
    pub fn f64s(&self, name: &str, cols: Option<u64>) -> Result<&[f64], StageError> {
        self.typed(name, cols, |d| if let ArrayData::F64(v) = d { Some(v) } else { None }, Dtype::F64)
    }
    pub fn u32s(&self, name: &str, cols: Option<u64>) -> Result<&[u32], StageError> {
        self.typed(name, cols, |d| if let ArrayData::U32(v) = d { Some(v) } else { None }, Dtype::U32)
    }
    pub fn u64s(&self, name: &str, cols: Option<u64>) -> Result<&[u64], StageError> {
        self.typed(name, cols, |d| if let ArrayData::U64(v) = d { Some(v) } else { None }, Dtype::U64)
    }
    pub fn i32s(&self, name: &str, cols: Option<u64>) -> Result<&[i32], StageError> {
        self.typed(name, cols, |d| if let ArrayData::I32(v) = d { Some(v) } else { None }, Dtype::I32)
    }
    pub fn u8s(&self, name: &str, cols: Option<u64>) -> Result<&[u8], StageError> {
        self.typed(name, cols, |d| if let ArrayData::U8(v) = d { Some(v) } else { None }, Dtype::U8)
    }

    /// The first META record, deserialised.
    pub fn meta_as<T: serde::de::DeserializeOwned>(&self) -> Result<T, StageError> {
        let text = self.meta.first().ok_or_else(|| self.missing("META", "metadata"))?;
        serde_yaml::from_str(text).map_err(|e| self.invalid("META", e.to_string()))
    }

    /// Human-readable dump: header, metadata, then each array as YAML rows.
    pub fn dump_yaml(&self, out: &mut dyn Write) -> io::Result<()> {
        writeln!(out, "format: {}", self.format)?;
        writeln!(out, "version: \"{}.{}\"", self.major, self.minor)?;
        if let Some(t) = &self.tail {
            writeln!(out, "tail: {t:?}")?;
        }
        for (i, m) in self.meta.iter().enumerate() {
            writeln!(out, "meta{}:", if i == 0 { String::new() } else { format!("_{i}") })?;
            for line in m.lines() {
                writeln!(out, "  {line}")?;
            }
        }
        writeln!(out, "arrays:")?;
        for a in &self.arrays {
            writeln!(out, "  {:?}:", a.name)?;
            writeln!(out, "    dtype: {}", a.data.dtype().name())?;
            writeln!(out, "    shape: {:?}", a.dims)?;
            writeln!(out, "    data:")?;
            let cols = if a.dims.len() >= 2 { a.dims[1..].iter().try_fold(1u64, |p, &d| p.checked_mul(d)).unwrap_or(0) as usize } else { 1 };
            let rows = a.data.len().checked_div(cols).unwrap_or(0);
            for r in 0..rows {
                let range = r * cols..(r + 1) * cols;
                let row: Vec<String> = match &a.data {
                    // `{:?}` prints the shortest string that round-trips the f64 exactly.
                    ArrayData::F64(v) => v[range].iter().map(|x| format!("{x:?}")).collect(),
                    ArrayData::U32(v) => v[range].iter().map(|x| x.to_string()).collect(),
                    ArrayData::U64(v) => v[range].iter().map(|x| x.to_string()).collect(),
                    ArrayData::I32(v) => v[range].iter().map(|x| x.to_string()).collect(),
                    ArrayData::U8(v) => v[range].iter().map(|x| x.to_string()).collect(),
                };
                if cols == 1 && a.dims.len() < 2 {
                    writeln!(out, "      - {}", row[0])?;
                } else {
                    writeln!(out, "      - [{}]", row.join(", "))?;
                }
            }
        }
        Ok(())
    }
}

/// Read a whole file, or standard input when the path is `-`.
pub fn read_input(path: &Path) -> io::Result<Vec<u8>> {
    if path.as_os_str() == "-" {
        let mut v = Vec::new();
        io::stdin().lock().read_to_end(&mut v)?;
        Ok(v)
    } else {
        fs::read(path)
    }
}

/// Write `bytes` to `path`: a regular file (or a new one) atomically, anything
/// else in place; see [`write_atomic_with`].
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), StageError> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Where [`write_atomic_with`] puts its bytes, decided by what `path` names now.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OutputKind {
    /// `-`: standard output.
    Stdout,
    /// A regular file, or nothing yet: a temporary file beside it, renamed onto
    /// it (`target` is the path itself, or the file a symbolic link points to, so
    /// that the link survives).
    Regular { target: PathBuf },
    /// A device, a FIFO or a socket: written in place. Renaming onto it would
    /// replace the device node with a regular file.
    Special,
}

/// What `path` names, or a clear error: a directory is no output, and a path that
/// cannot be inspected (a missing parent folder, no permission) is refused before
/// anything is produced.
pub fn output_kind(path: &Path) -> Result<OutputKind, StageError> {
    let shown = || path.display().to_string();
    if path.as_os_str() == "-" {
        return Ok(OutputKind::Stdout);
    }
    match fs::metadata(path) {
        Ok(m) if m.is_dir() => Err(StageError::Io {
            path: shown(),
            action: "write",
            source: io::Error::new(io::ErrorKind::IsADirectory, "it is a directory (give a file name inside it)"),
        }),
        Ok(m) if m.is_file() => {
            let target = if fs::symlink_metadata(path).is_ok_and(|l| l.file_type().is_symlink()) {
                fs::canonicalize(path).map_err(|source| StageError::Io { path: shown(), action: "follow the symbolic link", source })?
            } else {
                path.to_path_buf()
            };
            Ok(OutputKind::Regular { target })
        }
        Ok(_) => Ok(OutputKind::Special),
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(OutputKind::Regular { target: path.to_path_buf() }),
        Err(source) => Err(StageError::Io { path: shown(), action: "inspect the output path", source }),
    }
}

/// Write what `f` produces to `path`, so that a failure never leaves a half-written
/// regular file and never replaces what is not a regular file:
/// - a regular file, or a path that does not exist yet: into a temporary
///   `.<name>.<pid>.tmp` in the same folder, `fsync`ed, then renamed onto the
///   target (an existing file survives any failure; the temporary is removed);
/// - a device, a FIFO or a socket: opened and written in place (never created,
///   never renamed over); a write error (a full device: ENOSPC) is returned;
/// - `-`: standard output;
/// - a directory: an error, before `f` runs.
pub fn write_atomic_with(path: &Path, f: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> Result<(), StageError> {
    let shown = path.display().to_string();
    let io_err = |action: &'static str| {
        let shown = shown.clone();
        move |source| StageError::Io { path: shown, action, source }
    };
    let target = match output_kind(path)? {
        OutputKind::Stdout => {
            let mut buf = Vec::new();
            f(&mut buf).map_err(io_err("produce"))?;
            let mut out = io::stdout().lock();
            out.write_all(&buf).and_then(|_| out.flush()).map_err(io_err("write to standard output"))?;
            return Ok(());
        }
        OutputKind::Special => {
            let file = fs::OpenOptions::new().write(true).open(path).map_err(io_err("open for writing"))?;
            let mut w = io::BufWriter::with_capacity(1 << 20, file);
            return f(&mut w).and_then(|_| w.flush()).map_err(io_err("write"));
        }
        OutputKind::Regular { target } => target,
    };
    remove_stale_temporaries(&target);
    let tmp = temp_path(&target);
    let file = fs::File::create(&tmp).map_err(io_err("create its temporary file in the same folder"))?;
    let result = (|| -> io::Result<()> {
        let mut w = io::BufWriter::with_capacity(1 << 20, file);
        f(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_data()?;
        Ok(())
    })();
    if let Err(e) = result {
        let _ = fs::remove_file(&tmp);
        return Err(StageError::Io { path: shown, action: "write", source: e });
    }
    fs::rename(&tmp, &target).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        StageError::Io { path: shown, action: "rename the temporary file onto", source: e }
    })
}

/// Remove the temporaries of `target` (`.name.<pid>.tmp`) that a killed writer left:
/// those whose process no longer runs (Linux: no `/proc/<pid>`). A live writer's
/// temporary, another program's file, or anything elsewhere is never touched.
fn remove_stale_temporaries(target: &Path) {
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Some(name) = target.file_name().map(|n| n.to_string_lossy().into_owned()) else { return };
    let dir = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let prefix = format!(".{name}.");
    let Ok(entries) = fs::read_dir(&dir) else { return };
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().into_owned();
        let pid = file.strip_prefix(&prefix).and_then(|r| r.strip_suffix(".tmp")).and_then(|p| p.parse::<u32>().ok());
        if let Some(pid) = pid {
            if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
                let _ = fs::remove_file(e.path());
            }
        }
    }
}

/// `dir/.name.<pid>.tmp` beside the target (same file system, so rename is atomic).
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "out".into());
    let tmp = format!(".{name}.{}.tmp", std::process::id());
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.join(tmp),
        _ => PathBuf::from(tmp),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Vec<u8> {
        let mut w = StageWriter::new("demo", 1, 2);
        w.meta("name: test\n");
        w.f64s("x", &[2, 3], &[0.1, -2.5e300, f64::MIN_POSITIVE, 1.0 / 3.0, -0.0, 7.0]);
        w.u32s("ids", &[3], &[1, 2, 3]);
        w.finish()
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let f = StageFile::parse("t", &sample(), Some(("demo", 1))).unwrap();
        assert_eq!(f.minor, 2);
        let x = f.f64s("x", Some(3)).unwrap();
        assert_eq!(x[3].to_bits(), (1.0f64 / 3.0).to_bits());
        assert_eq!(x[4].to_bits(), (-0.0f64).to_bits());
        assert_eq!(f.u32s("ids", None).unwrap(), &[1, 2, 3]);
        assert_eq!(f.meta[0], "name: test\n");
    }

    #[test]
    fn every_truncation_is_detected() {
        let b = sample();
        for n in 0..b.len() {
            let e = StageFile::parse("t", &b[..n], Some(("demo", 1))).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains("truncated") || msg.contains("not a splinecontact"), "{n}: {msg}");
        }
    }

    #[test]
    fn flipped_byte_is_detected() {
        let mut b = sample();
        let i = b.len() / 2;
        b[i] ^= 0x10;
        assert!(StageFile::parse("t", &b, Some(("demo", 1))).is_err());
    }

    /// Two segments: the second appended later (from the first's end) gives the same
    /// bytes as both written at once, and reads back as one file.
    fn segmented() -> (Vec<u8>, usize) {
        let mut w = StageWriter::new("demo", 1, 0);
        w.meta("part: 0\n");
        w.f64s("a", &[2], &[1.0, 2.0]);
        let (mut bytes, end) = w.finish_segments();
        let first = bytes.len();
        let mut more = StageWriter::append_to(end);
        more.meta("part: 1\n");
        more.u32s("b", &[1], &[7]);
        bytes.extend(more.finish());
        (bytes, first)
    }

    #[test]
    fn appended_segments_read_as_one_file() {
        let (bytes, _) = segmented();
        let mut w = StageWriter::new("demo", 1, 0);
        w.meta("part: 0\n");
        w.f64s("a", &[2], &[1.0, 2.0]);
        w.end_segment();
        w.meta("part: 1\n");
        w.u32s("b", &[1], &[7]);
        assert_eq!(w.finish(), bytes);
        let f = StageFile::parse("t", &bytes, Some(("demo", 1))).unwrap();
        assert_eq!((f.meta.len(), f.arrays.len(), f.tail.clone()), (2, 2, None));
        assert_eq!(f.u32s("b", None).unwrap(), &[7]);
        // a single segment is the one-segment layout of before (checksum from the
        // FNV basis over every byte before END!)
        let one = sample();
        let mut c = Checksum::new();
        c.update(&one[..one.len() - 20]);
        assert_eq!(one[one.len() - 8..], c.0.to_le_bytes());
    }

    /// A file cut anywhere in its second segment reads as its first segment, and says
    /// that the rest was left out; cut in the first, it is refused.
    #[test]
    fn an_interrupted_append_leaves_the_complete_segments() {
        let (bytes, first) = segmented();
        for n in 0..bytes.len() {
            match StageFile::parse("t", &bytes[..n], Some(("demo", 1))) {
                Ok(f) => {
                    assert!(n >= first, "{n}: a cut first segment was accepted");
                    assert_eq!((f.meta.len(), f.arrays.len()), (1, 1), "{n}");
                    assert_eq!(f.tail.is_some(), n > first, "{n}: {:?}", f.tail);
                }
                Err(e) => assert!(n < first, "{n}: {e}"),
            }
        }
        // a damaged byte in the second segment: left out with the rest, and said
        let mut b = bytes.clone();
        b[first + 6] ^= 0x10;
        let f = StageFile::parse("t", &b, Some(("demo", 1))).unwrap();
        assert!(f.tail.as_deref().is_some_and(|t| t.contains(&format!("after byte {first}"))), "{:?}", f.tail);
        assert!(f.array("b").is_none());
    }

    #[test]
    fn newer_major_and_wrong_format_are_refused() {
        let b = StageWriter::new("demo", 2, 0).finish();
        let e = StageFile::parse("f.demo", &b, Some(("demo", 1))).unwrap_err().to_string();
        assert!(e.contains("version 2.0") && e.contains("reads demo 1.x"), "{e}");
        let e = StageFile::parse("f.demo", &b, Some(("scmesh", 1))).unwrap_err().to_string();
        assert!(e.contains("'demo' file") && e.contains("'scmesh' file is expected"), "{e}");
    }
}
