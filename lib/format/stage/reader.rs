//! Reading a stage file: [`StageFile`], every complete segment of it.

use std::io::{self, Write};
use std::path::Path;

use super::checksum::Checksum;
use super::error::StageError;
use super::files::read_input;
use super::record::{Array, ArrayData, Dtype, MAGIC};

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
