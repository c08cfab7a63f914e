//! `$PhysicalNames`: names of physical groups. ASCII in every file, binary ones too.
//!
//! ```text
//! $PhysicalNames
//! numPhysicalNames
//! dimension physicalTag "name"
//! ...
//! $EndPhysicalNames
//! ```
//! A group is identified by `(dimension, physicalTag)`: the same tag may name a
//! volume and a surface. Names are quoted and may contain spaces.

use super::cursor::{show, Cursor};
use super::MshError;

/// One `dimension physicalTag "name"` line.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct PhysicalName {
    pub dim: u8,
    pub tag: i32,
    pub name: String,
    /// Byte offset of the line, for messages.
    pub offset: usize,
}

pub(super) fn parse(cur: &mut Cursor, out: &mut Vec<PhysicalName>) -> Result<(), MshError> {
    cur.section_end = "$EndPhysicalNames";
    let count = cur.ascii_u64("the number of physical names")?;
    for _ in 0..count {
        cur.skip_whitespace();
        let offset = cur.pos;
        let dim = cur.ascii_i32("a physical group dimension")?;
        let dim = match u8::try_from(dim) {
            Ok(d) if d <= 3 => d,
            _ => return Err(cur.malformed(offset, format!("physical group dimension {dim} is not 0, 1, 2 or 3"))),
        };
        let tag = cur.ascii_i32("a physical tag")?;
        let name = quoted(cur)?;
        if let Some(previous) = out.iter().find(|p| p.dim == dim && p.tag == tag) {
            return Err(cur.malformed(
                offset,
                format!(
                    "physical group (dimension {dim}, tag {tag}) is named twice: `{}` ({}) and `{name}`",
                    previous.name,
                    cur.at(previous.offset)
                ),
            ));
        }
        out.push(PhysicalName { dim, tag, name, offset });
    }
    cur.expect_end()
}

/// A `"..."` string on the current line.
fn quoted(cur: &mut Cursor) -> Result<String, MshError> {
    while cur.pos < cur.bytes.len() && matches!(cur.bytes[cur.pos], b' ' | b'\t') {
        cur.pos += 1;
    }
    let start = cur.pos;
    if cur.eof() {
        return Err(cur.truncated());
    }
    if cur.bytes[start] != b'"' {
        let line = cur.rest_of_line();
        return Err(cur.malformed(start, format!("expected a quoted physical name, found `{}`", show(line))));
    }
    let rest = &cur.bytes[start + 1..];
    let len = rest.iter().position(|&b| b == b'"' || b == b'\n');
    match len {
        Some(n) if rest[n] == b'"' => {
            cur.pos = start + 1 + n + 1;
            Ok(String::from_utf8_lossy(&rest[..n]).into_owned())
        }
        _ => Err(cur.malformed(start, "unterminated physical name (no closing `\"` on the line)")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(text: &[u8]) -> Result<Vec<PhysicalName>, MshError> {
        let mut c = Cursor::new("t.msh", text);
        let mut out = Vec::new();
        parse(&mut c, &mut out).map(|_| out)
    }

    #[test]
    fn names_with_spaces() {
        let n = names(b"2\n3 1 \"solid body\"\n2 1 \"top\"\n$EndPhysicalNames\n").unwrap();
        assert_eq!(n.len(), 2);
        assert_eq!((n[0].dim, n[0].tag, n[0].name.as_str()), (3, 1, "solid body"));
        assert_eq!((n[1].dim, n[1].tag, n[1].name.as_str()), (2, 1, "top"));
    }

    #[test]
    fn unterminated_name() {
        let e = names(b"1\n3 1 \"solid\n$EndPhysicalNames\n").unwrap_err().to_string();
        assert_eq!(e, "t.msh:2: unterminated physical name (no closing `\"` on the line)");
    }

    #[test]
    fn fewer_names_than_counted() {
        let e = names(b"2\n3 1 \"a\"\n$EndPhysicalNames\n").unwrap_err().to_string();
        assert!(e.starts_with("t.msh:3: found `$EndPhysicalNames` where a physical group dimension was expected"), "{e}");
    }
}
