//! Writing a stage file, or segments to append to one: [`StageWriter`].

use super::checksum::Checksum;
use super::record::{Dtype, MAGIC};

/// Where a file's last segment ended: the record count and checksum the next
/// segment continues from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SegmentEnd {
    pub(super) records: u64,
    pub(super) checksum: u64,
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
        self.put(v, |x| x.to_le_bytes());
    }
    pub fn u32s(&mut self, name: &str, dims: &[u64], v: &[u32]) {
        debug_assert_eq!(dims.iter().product::<u64>() as usize, v.len());
        self.array_header(name, Dtype::U32, dims);
        self.put(v, |x| x.to_le_bytes());
    }
    pub fn u64s(&mut self, name: &str, dims: &[u64], v: &[u64]) {
        debug_assert_eq!(dims.iter().product::<u64>() as usize, v.len());
        self.array_header(name, Dtype::U64, dims);
        self.put(v, |x| x.to_le_bytes());
    }
    pub fn i32s(&mut self, name: &str, dims: &[u64], v: &[i32]) {
        debug_assert_eq!(dims.iter().product::<u64>() as usize, v.len());
        self.array_header(name, Dtype::I32, dims);
        self.put(v, |x| x.to_le_bytes());
    }

    /// The little-endian bytes of `v`, appended in one resize and one pass of fixed
    /// width copies (a push per value checks the capacity each time and does not
    /// vectorise: 2 MB of Gauss stresses took about 1 ms that way).
    fn put<T: Copy, const B: usize>(&mut self, v: &[T], le: impl Fn(T) -> [u8; B]) {
        let start = self.buf.len();
        self.buf.resize(start + B * v.len(), 0);
        for (out, &x) in self.buf[start..].chunks_exact_mut(B).zip(v) {
            out.copy_from_slice(&le(x));
        }
    }

    /// Room for `bytes` more (a writer that knows the size of what follows allocates
    /// once instead of doubling its buffer).
    pub fn reserve(&mut self, bytes: usize) {
        self.buf.reserve(bytes);
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
