//! `$MeshFormat`: the header every MSH file starts with.
//!
//! ```text
//! $MeshFormat
//! version file-type data-size      e.g. "4.1 0 8" (ASCII) or "2.2 1 8" (binary)
//! [int 1, binary files only]       4 raw bytes: tells the reader the byte order
//! $EndMeshFormat
//! ```
//! `file-type` is 0 for ASCII, 1 for binary. `data-size` is `sizeof(double)` in
//! MSH 2.2 (always 8) and `sizeof(size_t)` in MSH 4.1 (the width of every
//! count and tag in binary 4.1 files; 8 on 64-bit writers, 4 on 32-bit ones).

use super::cursor::{show, Cursor};
use super::MshError;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Version {
    V2_2,
    V4_1,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Header {
    pub version: Version,
    pub binary: bool,
}

impl Header {
    /// `"2.2 ASCII"`, `"4.1 binary"`.
    pub fn describe(&self) -> String {
        let v = match self.version {
            Version::V2_2 => "2.2",
            Version::V4_1 => "4.1",
        };
        format!("{v} {}", if self.binary { "binary" } else { "ASCII" })
    }
}

/// Read the header and configure the cursor (binary mode, byte order, size_t width).
pub(super) fn parse(cur: &mut Cursor) -> Result<Header, MshError> {
    cur.skip_whitespace();
    let first = cur.rest_of_line();
    if first.trim_ascii() != b"$MeshFormat" {
        let found = if first.is_empty() {
            " (the file is empty)".to_string()
        } else {
            format!(" (the first line is `{}`)", show(first.trim_ascii()))
        };
        return Err(MshError::NotMsh { file: cur.file.to_string(), found });
    }
    cur.section_end = "$EndMeshFormat";
    let line_start = cur.pos;
    let line = cur.rest_of_line();
    let mut fields = line.split(|b| b.is_ascii_whitespace()).filter(|t| !t.is_empty());
    let version_token = fields.next().ok_or_else(|| {
        if cur.eof() {
            cur.truncated()
        } else {
            cur.malformed(line_start, "expected `version file-type data-size` after $MeshFormat, found an empty line")
        }
    })?;
    let version = match version_token {
        b"2.2" => Version::V2_2,
        b"4.1" => Version::V4_1,
        other => {
            return Err(MshError::UnsupportedVersion { at: cur.at(line_start), found: show(other) });
        }
    };
    let file_type = fields.next();
    let binary = match file_type {
        Some(b"0") => false,
        Some(b"1") => true,
        other => {
            return Err(cur.malformed(
                line_start,
                format!(
                    "expected file-type 0 (ASCII) or 1 (binary) after the version, found `{}`",
                    show(other.unwrap_or(b""))
                ),
            ))
        }
    };
    let data_size = fields.next().unwrap_or(b"");
    let size = match data_size {
        b"8" => 8,
        b"4" if version == Version::V4_1 => 4,
        _ if !binary => 8,
        other => {
            let need = if version == Version::V4_1 { "4 or 8 (sizeof(size_t))" } else { "8 (sizeof(double))" };
            return Err(cur.malformed(line_start, format!("data-size `{}` is not supported: expected {need}", show(other))));
        }
    };
    if binary {
        let at = cur.pos;
        let one = cur.take(4)?;
        cur.big_endian = match one {
            [1, 0, 0, 0] => false,
            [0, 0, 0, 1] => true,
            other => {
                return Err(cur.malformed(
                    at,
                    format!("binary endianness check failed: expected the int 1 after the header line, found bytes {other:?}"),
                ))
            }
        };
        cur.size_t = size;
    }
    cur.expect_end()?;
    // From here on locations are byte offsets in binary files.
    cur.binary = binary;
    Ok(Header { version, binary })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(text: &[u8]) -> Result<Header, MshError> {
        let mut c = Cursor::new("t.msh", text);
        parse(&mut c)
    }

    #[test]
    fn ascii_versions() {
        assert_eq!(header(b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n").unwrap().describe(), "2.2 ASCII");
        assert_eq!(header(b"$MeshFormat\r\n4.1 0 8\r\n$EndMeshFormat\r\n").unwrap().describe(), "4.1 ASCII");
    }

    #[test]
    fn binary_needs_the_endianness_int() {
        let mut b = b"$MeshFormat\n4.1 1 8\n".to_vec();
        b.extend_from_slice(&1i32.to_le_bytes());
        b.extend_from_slice(b"\n$EndMeshFormat\n");
        assert_eq!(header(&b).unwrap().describe(), "4.1 binary");
        let mut b = b"$MeshFormat\n4.1 1 8\n".to_vec();
        b.extend_from_slice(&7i32.to_le_bytes());
        b.extend_from_slice(b"\n$EndMeshFormat\n");
        let e = header(&b).unwrap_err().to_string();
        assert!(e.starts_with("t.msh:3:") && e.contains("endianness"), "{e}");
    }

    #[test]
    fn unknown_version_lists_the_supported_ones() {
        let e = header(b"$MeshFormat\n3.0 0 8\n$EndMeshFormat\n").unwrap_err().to_string();
        assert_eq!(e, "t.msh:2: MSH version `3.0` is not supported (supported: 2.2, 4.1); re-export it from gmsh with `-format msh41` or `-format msh22`");
    }

    #[test]
    fn random_bytes_are_not_msh() {
        let e = header(b"\x7fELF\x02\x01\x01garbage").unwrap_err().to_string();
        assert!(e.starts_with("t.msh: not a gmsh MSH file: no $MeshFormat header"), "{e}");
        let e = header(b"").unwrap_err().to_string();
        assert!(e.contains("no $MeshFormat header"), "{e}");
    }
}
