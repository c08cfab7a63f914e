//! A cursor over the bytes of an MSH file.
//!
//! MSH files mix two encodings: section headers (`$Nodes`), `$MeshFormat` and
//! `$PhysicalNames` are always ASCII lines, while the bulk data of a binary file
//! (`file-type` 1 in the header) is raw numbers in the writer's byte order. The
//! cursor reads both from one byte slice; the section parsers call the
//! mode-independent readers ([`Cursor::int`], [`Cursor::size_t`],
//! [`Cursor::double`]) so that one parser serves the ASCII and the binary form of
//! a section.
//!
//! Nothing is allocated per token. Positions are byte offsets; an error turns its
//! offset into `file:line` (ASCII files) or `file: byte N` (binary files) only
//! when the message is built.

use super::MshError;

pub(super) struct Cursor<'a> {
    pub file: &'a str,
    pub bytes: &'a [u8],
    pub pos: usize,
    /// Bulk data is binary (`file-type` 1).
    pub binary: bool,
    /// The binary data was written big-endian (the endianness check int read `0 0 0 1`).
    pub big_endian: bool,
    /// `sizeof(size_t)` of the writer (the header's `data-size` in MSH 4.1), 4 or 8.
    pub size_t: usize,
    /// The line closing the section being read, for "expected ... before end of file".
    pub section_end: &'static str,
}

/// A token shown in a message: lossy UTF-8, at most 40 characters.
pub(super) fn show(token: &[u8]) -> String {
    let s = String::from_utf8_lossy(token);
    if s.chars().count() > 40 {
        let mut t: String = s.chars().take(40).collect();
        t.push('…');
        t
    } else {
        s.into_owned()
    }
}

/// Decimal unsigned integer, optional leading `+`.
fn parse_u64(t: &[u8]) -> Option<u64> {
    let t = t.strip_prefix(b"+").unwrap_or(t);
    if t.is_empty() {
        return None;
    }
    let mut v: u64 = 0;
    for &b in t {
        let d = b.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        v = v.checked_mul(10)?.checked_add(u64::from(d))?;
    }
    Some(v)
}

/// Decimal signed integer.
fn parse_i64(t: &[u8]) -> Option<i64> {
    match t.strip_prefix(b"-") {
        Some(rest) => {
            let v = parse_u64(rest)?;
            if v <= i64::MAX as u64 + 1 {
                Some((v as i128).wrapping_neg() as i64)
            } else {
                None
            }
        }
        None => i64::try_from(parse_u64(t)?).ok(),
    }
}

/// Decimal floating-point number, correctly rounded (Rust's `str::parse::<f64>`).
fn parse_f64(t: &[u8]) -> Option<f64> {
    std::str::from_utf8(t).ok()?.parse::<f64>().ok()
}

impl<'a> Cursor<'a> {
    pub fn new(file: &'a str, bytes: &'a [u8]) -> Self {
        Self { file, bytes, pos: 0, binary: false, big_endian: false, size_t: 8, section_end: "$EndMeshFormat" }
    }

    /// `file:line` (ASCII) or `file: byte N` (binary) for a byte offset.
    pub fn at(&self, offset: usize) -> String {
        if self.binary {
            format!("{}: byte {}", self.file, offset)
        } else {
            let end = offset.min(self.bytes.len());
            let line = 1 + self.bytes[..end].iter().filter(|&&b| b == b'\n').count();
            format!("{}:{}", self.file, line)
        }
    }

    pub fn eof(&self) -> bool {
        self.pos >= self.bytes.len()
    }

    /// The error for running out of bytes inside the current section.
    pub fn truncated(&self) -> MshError {
        MshError::Truncated { at: self.at(self.bytes.len().saturating_sub(1)), expected: self.section_end.to_string() }
    }

    pub fn malformed(&self, offset: usize, what: impl Into<String>) -> MshError {
        MshError::Malformed { at: self.at(offset), what: what.into() }
    }

    pub fn skip_whitespace(&mut self) {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    /// Next whitespace-separated token and its offset.
    pub fn token(&mut self) -> Option<(usize, &'a [u8])> {
        self.skip_whitespace();
        if self.eof() {
            return None;
        }
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        Some((start, &self.bytes[start..self.pos]))
    }

    /// The rest of the current line without its `\n` (and a trailing `\r`),
    /// consuming exactly one `\n`: binary data may start right after it.
    pub fn rest_of_line(&mut self) -> &'a [u8] {
        let start = self.pos;
        let end = self.bytes[start..].iter().position(|&b| b == b'\n').map_or(self.bytes.len(), |i| start + i);
        self.pos = (end + 1).min(self.bytes.len());
        let line = &self.bytes[start..end];
        line.strip_suffix(b"\r").unwrap_or(line)
    }

    /// In a binary file, after an ASCII count: skip to just past the end of the line.
    pub fn finish_line(&mut self) -> Result<(), MshError> {
        let start = self.pos;
        let rest = self.rest_of_line();
        if rest.iter().all(|b| b.is_ascii_whitespace()) {
            Ok(())
        } else {
            Err(self.malformed(start, format!("expected the end of the line, found `{}`", show(rest))))
        }
    }

    /// A numeric token: end of file means the section is truncated, and a `$...`
    /// token means the section closed before its counts were satisfied.
    fn number_token(&mut self, what: &str) -> Result<(usize, &'a [u8]), MshError> {
        match self.token() {
            None => Err(self.truncated()),
            Some((start, t)) if t.first() == Some(&b'$') => Err(MshError::CountMismatch {
                at: self.at(start),
                what: format!(
                    "found `{}` where {what} was expected: the section holds fewer entries than its counts say",
                    show(t)
                ),
            }),
            Some(x) => Ok(x),
        }
    }

    fn bad_number(&self, start: usize, token: &[u8], what: &str) -> MshError {
        MshError::BadNumber { at: self.at(start), token: show(token), what: what.to_string() }
    }

    pub fn ascii_u64(&mut self, what: &str) -> Result<u64, MshError> {
        let (start, t) = self.number_token(what)?;
        parse_u64(t).ok_or_else(|| self.bad_number(start, t, what))
    }

    pub fn ascii_i32(&mut self, what: &str) -> Result<i32, MshError> {
        let (start, t) = self.number_token(what)?;
        parse_i64(t).and_then(|v| i32::try_from(v).ok()).ok_or_else(|| self.bad_number(start, t, what))
    }

    pub fn ascii_f64(&mut self, what: &str) -> Result<f64, MshError> {
        let (start, t) = self.number_token(what)?;
        parse_f64(t).ok_or_else(|| self.bad_number(start, t, what))
    }

    /// `n` raw bytes of binary data.
    pub fn take(&mut self, n: usize) -> Result<&'a [u8], MshError> {
        if self.bytes.len() - self.pos < n {
            return Err(self.truncated());
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn take4(&mut self) -> Result<[u8; 4], MshError> {
        let s = self.take(4)?;
        Ok([s[0], s[1], s[2], s[3]])
    }

    fn take8(&mut self) -> Result<[u8; 8], MshError> {
        let s = self.take(8)?;
        Ok([s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7]])
    }

    pub fn bin_i32(&mut self) -> Result<i32, MshError> {
        let b = self.take4()?;
        Ok(if self.big_endian { i32::from_be_bytes(b) } else { i32::from_le_bytes(b) })
    }

    pub fn bin_size_t(&mut self) -> Result<u64, MshError> {
        if self.size_t == 4 {
            let b = self.take4()?;
            Ok(u64::from(if self.big_endian { u32::from_be_bytes(b) } else { u32::from_le_bytes(b) }))
        } else {
            let b = self.take8()?;
            Ok(if self.big_endian { u64::from_be_bytes(b) } else { u64::from_le_bytes(b) })
        }
    }

    pub fn bin_f64(&mut self) -> Result<f64, MshError> {
        let b = self.take8()?;
        Ok(if self.big_endian { f64::from_be_bytes(b) } else { f64::from_le_bytes(b) })
    }

    /// Decode one binary `size_t` from the start of `b` (at least `self.size_t` bytes).
    #[inline]
    pub fn decode_size_t(&self, b: &[u8]) -> u64 {
        if self.size_t == 4 {
            let w = [b[0], b[1], b[2], b[3]];
            u64::from(if self.big_endian { u32::from_be_bytes(w) } else { u32::from_le_bytes(w) })
        } else {
            let w = [b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]];
            if self.big_endian {
                u64::from_be_bytes(w)
            } else {
                u64::from_le_bytes(w)
            }
        }
    }

    /// Decode one binary `double` from the start of `b` (at least 8 bytes).
    #[inline]
    pub fn decode_f64(&self, b: &[u8]) -> f64 {
        let w = [b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]];
        if self.big_endian {
            f64::from_be_bytes(w)
        } else {
            f64::from_le_bytes(w)
        }
    }

    /// An `int` of the spec: binary i32, or an ASCII integer in i32's range.
    pub fn int(&mut self, what: &str) -> Result<i32, MshError> {
        if self.binary {
            self.bin_i32()
        } else {
            self.ascii_i32(what)
        }
    }

    /// A `size_t` of the spec (MSH 4.1 counts and tags).
    pub fn size_t(&mut self, what: &str) -> Result<u64, MshError> {
        if self.binary {
            self.bin_size_t()
        } else {
            self.ascii_u64(what)
        }
    }

    /// A `double` of the spec.
    pub fn double(&mut self, what: &str) -> Result<f64, MshError> {
        if self.binary {
            self.bin_f64()
        } else {
            self.ascii_f64(what)
        }
    }

    /// A node coordinate: a `double` that must be finite (`nan`/`inf` parse in Rust).
    pub fn coordinate(&mut self) -> Result<f64, MshError> {
        let start = self.pos;
        let x = self.double("a node coordinate")?;
        if x.is_finite() {
            Ok(x)
        } else if self.binary {
            Err(self.malformed(start, format!("node coordinate {x} is not a finite number")))
        } else {
            let t = self.bytes[start..self.pos].trim_ascii();
            Err(self.bad_number(start + (self.pos - start - t.len()), t, "a finite node coordinate"))
        }
    }

    /// A count for a `Vec::with_capacity`, bounded by what the rest of the file can
    /// hold so that a corrupt count cannot exhaust memory.
    pub fn capacity(&self, count: u64, min_bytes_each: usize) -> usize {
        let fit = (self.bytes.len() - self.pos) / min_bytes_each.max(1);
        usize::try_from(count).unwrap_or(usize::MAX).min(fit)
    }

    /// The closing line of the current section (`$EndNodes`), after optional whitespace.
    pub fn expect_end(&mut self) -> Result<(), MshError> {
        match self.token() {
            None => Err(self.truncated()),
            Some((_, t)) if t == self.section_end.as_bytes() => Ok(()),
            Some((start, t)) => Err(MshError::CountMismatch {
                at: self.at(start),
                what: format!(
                    "expected `{}`, found `{}`: the section holds more data than its counts say",
                    self.section_end,
                    show(t)
                ),
            }),
        }
    }

    /// Skip a section we do not read, up to and including its `$End...` line.
    pub fn skip_section(&mut self, name: &str) -> Result<(), MshError> {
        let end = format!("$End{}", &name[1.min(name.len())..]);
        let needle = end.as_bytes();
        let mut i = self.pos;
        while let Some(k) = self.bytes[i..].windows(needle.len()).position(|w| w == needle) {
            let s = i + k;
            let after = s + needle.len();
            let line_start = s == 0 || self.bytes[s - 1] == b'\n';
            let line_end = after == self.bytes.len() || self.bytes[after].is_ascii_whitespace();
            if line_start && line_end {
                self.pos = after;
                return Ok(());
            }
            i = s + 1;
        }
        Err(MshError::Truncated { at: self.at(self.bytes.len().saturating_sub(1)), expected: end })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers() {
        assert_eq!(parse_u64(b"123"), Some(123));
        assert_eq!(parse_u64(b"+7"), Some(7));
        assert_eq!(parse_u64(b""), None);
        assert_eq!(parse_u64(b"1x"), None);
        assert_eq!(parse_u64(b"99999999999999999999999"), None);
        assert_eq!(parse_i64(b"-9223372036854775808"), Some(i64::MIN));
        assert_eq!(parse_i64(b"-5"), Some(-5));
    }

    #[test]
    fn lines_and_bytes() {
        let mut c = Cursor::new("f.msh", b"a\nb c\n");
        assert_eq!(c.at(3), "f.msh:2");
        c.binary = true;
        assert_eq!(c.at(3), "f.msh: byte 3");
        c.binary = false;
        assert_eq!(c.rest_of_line(), b"a");
        assert_eq!(c.token(), Some((2, &b"b"[..])));
    }

    #[test]
    fn skip_section_needs_a_whole_line() {
        let mut c = Cursor::new("f", b"$EndFooBar\n$EndFoo\nx");
        c.skip_section("$Foo").unwrap();
        assert_eq!(c.token(), Some((19, &b"x"[..])));
        let mut c = Cursor::new("f", b"1 2 3\n");
        let e = c.skip_section("$Foo").unwrap_err().to_string();
        assert!(e.contains("expected `$EndFoo` before end of file"), "{e}");
    }
}
