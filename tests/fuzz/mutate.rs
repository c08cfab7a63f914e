//! The mutations: what a hand edit, a bad copy or a half-finished write does to a
//! file. Each takes the input and returns a changed copy; [`mutate`] stacks one to
//! four of them, picked at random.
//!
//! - bytes: flip a bit, set a byte, cut a range, duplicate a range, swap two
//!   ranges, truncate, insert bytes that mean something to a reader (`\n`, `\0`,
//!   `$EndNodes`), overwrite a 4- or 8-byte word with a binary count or value that
//!   breaks assumptions (0, 2³¹ − 1, 2³², 10¹², u64::MAX, NaN);
//! - lines: drop, duplicate or swap whole lines (sections, YAML keys, CSV rows);
//! - tokens (runs of letters, digits, `.+-_`): replace a token by a number that
//!   breaks assumptions (`-1`, `4294967296`, `1000000000000`, `1e308`, `nan`, a
//!   20-digit string, …) or by another token of the file, nudge a number
//!   (±1, ×10, negated), drop or duplicate a token;
//! - crossover: the start of this input with the end of another seed.

use super::rng::Rng;

/// Text that breaks a parser's assumptions about a number or a YAML scalar.
pub const INTERESTING_TOKENS: &[&str] = &[
    "0", "-1", "1", "2", "3", "4", "7", "8", "27", "255", "256", "65535", "65536", "2147483647", "2147483648",
    "-2147483648", "4294967295", "4294967296", "9223372036854775807", "9223372036854775808", "18446744073709551615",
    "18446744073709551616", "1000000000000", "1e12", "1e308", "-1e308", "1e-320", "1e999", "nan", "NaN", ".nan", "inf",
    "-inf", ".inf", "-0", "0.0", "-0.0", "0.5", "99999999999999999999999999", "+1", "0x10", "1_000", "~", "null",
    "[]", "{}", "''", "true", "*a", "&a x", "!!binary", "$Nodes", "$EndNodes", "$Elements", "$EndElements",
    "$Entities", "$PhysicalNames",
];

/// Binary words (little-endian) that break a parser's assumptions about a count.
const INTERESTING_U64: &[u64] = &[
    0,
    1,
    2,
    7,
    8,
    255,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
    0x1_0000_0000,
    1_000_000_000_000,
    1 << 40,
    0x7fff_ffff_ffff_ffff,
    u64::MAX,
];

fn interesting_word(rng: &mut Rng) -> u64 {
    match rng.below(4) {
        0 => f64::NAN.to_bits(),
        1 => [f64::INFINITY, -0.0, 1e308, f64::MIN_POSITIVE][rng.below(4)].to_bits(),
        _ => *rng.pick(INTERESTING_U64),
    }
}

fn range(rng: &mut Rng, len: usize) -> (usize, usize) {
    if len == 0 {
        return (0, 0);
    }
    let a = rng.below(len);
    // mostly short ranges, sometimes long ones
    let max = if rng.one_in(4) { len - a } else { (len - a).min(64) };
    (a, a + 1 + rng.below(max.max(1)).min(len - a - 1))
}

/// Spans of "token" bytes: letters, digits and `.+-_$`.
fn tokens(b: &[u8]) -> Vec<(usize, usize)> {
    let is_tok = |c: u8| c.is_ascii_alphanumeric() || matches!(c, b'.' | b'+' | b'-' | b'_' | b'$');
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if is_tok(b[i]) {
            let s = i;
            while i < b.len() && is_tok(b[i]) {
                i += 1;
            }
            out.push((s, i));
        } else {
            i += 1;
        }
    }
    out
}

fn lines(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut s = 0;
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' {
            out.push((s, i + 1));
            s = i + 1;
        }
    }
    if s < b.len() {
        out.push((s, b.len()));
    }
    out
}

fn splice(b: &[u8], (s, e): (usize, usize), with: &[u8]) -> Vec<u8> {
    let mut v = Vec::with_capacity(b.len() - (e - s) + with.len());
    v.extend_from_slice(&b[..s]);
    v.extend_from_slice(with);
    v.extend_from_slice(&b[e..]);
    v
}

/// A number nudged: ±1, ×10, negated, or digits appended.
fn nudge(t: &[u8], rng: &mut Rng) -> Option<Vec<u8>> {
    let s = std::str::from_utf8(t).ok()?;
    if let Ok(v) = s.parse::<i128>() {
        let n = match rng.below(5) {
            0 => v.wrapping_add(1),
            1 => v.wrapping_sub(1),
            2 => v.wrapping_mul(10),
            3 => v.wrapping_neg(),
            _ => return Some(format!("{s}000000").into_bytes()),
        };
        return Some(n.to_string().into_bytes());
    }
    let v = s.parse::<f64>().ok()?;
    let n = match rng.below(4) {
        0 => v * 1e10,
        1 => -v,
        2 => v + 1.0,
        _ => v / 3.0,
    };
    Some(format!("{n:e}").into_bytes())
}

/// One mutation of `b`; `others` are the other seeds of the target (for crossover
/// and borrowed tokens).
pub fn mutate_once(b: &[u8], others: &[Vec<u8>], rng: &mut Rng) -> Vec<u8> {
    let len = b.len();
    match rng.below(16) {
        0 if len > 0 => {
            let mut v = b.to_vec();
            let i = rng.below(len);
            v[i] ^= 1 << rng.below(8);
            v
        }
        1 if len > 0 => {
            let mut v = b.to_vec();
            let i = rng.below(len);
            v[i] = rng.next_u64() as u8;
            v
        }
        2 => splice(b, range(rng, len), b""),
        3 => {
            let (s, e) = range(rng, len);
            let at = rng.below(len + 1);
            splice(b, (at, at), &b[s..e])
        }
        4 if len > 2 => {
            let (s1, e1) = range(rng, len);
            let (s2, e2) = range(rng, len);
            let ((s1, e1), (s2, e2)) = if s1 <= s2 { ((s1, e1), (s2, e2)) } else { ((s2, e2), (s1, e1)) };
            if e1 > s2 {
                return b.to_vec();
            }
            let mut v = Vec::with_capacity(len);
            v.extend_from_slice(&b[..s1]);
            v.extend_from_slice(&b[s2..e2]);
            v.extend_from_slice(&b[e1..s2]);
            v.extend_from_slice(&b[s1..e1]);
            v.extend_from_slice(&b[e2..]);
            v
        }
        5 => b[..rng.below(len + 1)].to_vec(),
        6 => {
            let at = rng.below(len + 1);
            let ins: &[u8] = match rng.below(6) {
                0 => b"\n",
                1 => b"\0",
                2 => b"\xff\xfe",
                3 => b"\r\n",
                4 => b" ",
                _ => rng.pick(INTERESTING_TOKENS).as_bytes(),
            };
            splice(b, (at, at), ins)
        }
        7 if len >= 8 => {
            let w = interesting_word(rng);
            let n = if rng.one_in(2) { 4 } else { 8 };
            let at = rng.below(len - n + 1);
            let mut v = b.to_vec();
            v[at..at + n].copy_from_slice(&w.to_le_bytes()[..n]);
            v
        }
        8 | 9 => {
            let ls = lines(b);
            if ls.is_empty() {
                return b.to_vec();
            }
            let l = *rng.pick(&ls);
            match rng.below(3) {
                0 => splice(b, l, b""),
                1 => splice(b, (l.1, l.1), &b[l.0..l.1]),
                _ => {
                    let m = *rng.pick(&ls);
                    let (a, c) = if l.0 <= m.0 { (l, m) } else { (m, l) };
                    if a.1 > c.0 {
                        return b.to_vec();
                    }
                    let mut v = Vec::with_capacity(len);
                    v.extend_from_slice(&b[..a.0]);
                    v.extend_from_slice(&b[c.0..c.1]);
                    v.extend_from_slice(&b[a.1..c.0]);
                    v.extend_from_slice(&b[a.0..a.1]);
                    v.extend_from_slice(&b[c.1..]);
                    v
                }
            }
        }
        10..=13 => {
            let ts = tokens(b);
            if ts.is_empty() {
                return mutate_once(b, others, rng);
            }
            let t = *rng.pick(&ts);
            let tok = &b[t.0..t.1];
            match rng.below(6) {
                0 | 1 => splice(b, t, rng.pick(INTERESTING_TOKENS).as_bytes()),
                2 => match nudge(tok, rng) {
                    Some(n) => splice(b, t, &n),
                    None => splice(b, t, rng.pick(INTERESTING_TOKENS).as_bytes()),
                },
                3 => {
                    let o = *rng.pick(&ts);
                    splice(b, t, &b[o.0..o.1])
                }
                4 => splice(b, t, b""),
                _ => splice(b, (t.1, t.1), &[b" ", tok].concat()),
            }
        }
        14 if !others.is_empty() => {
            let o = rng.pick(others);
            let (i, j) = (rng.below(len + 1), rng.below(o.len() + 1));
            [&b[..i], &o[j..]].concat()
        }
        _ => {
            let mut v = b.to_vec();
            if len > 0 {
                let i = rng.below(len);
                v[i] = *rng.pick(b"0123456789-.e \n$");
            }
            v
        }
    }
}

/// One to four mutations stacked.
pub fn mutate(b: &[u8], others: &[Vec<u8>], rng: &mut Rng) -> Vec<u8> {
    let n = 1 + rng.below(4);
    let mut v = mutate_once(b, others, rng);
    for _ in 1..n {
        v = mutate_once(&v, others, rng);
    }
    v
}
