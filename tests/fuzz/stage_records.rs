//! Structure-aware mutation of stage files (`.scmesh`, `.sccontact`, `.scres`).
//!
//! A byte flip in a stage file is caught by the segment checksum, so a byte-level
//! mutator only ever tests the container. Here the file is split into its header
//! line and segments of records (`docs/formats.md`, "The container"), one record
//! or segment is changed — a META's YAML edited as text, an array's dimensions,
//! dtype, name or values, records dropped, duplicated or swapped, segments merged,
//! dropped or duplicated — and the file is sealed again: every `END!` gets the
//! record count and the chained FNV-1a checksum the format asks for (computed here
//! from the specification, independently of the writer). So the readers behind
//! the container — the mesh, the pairs, the increments, the restart — see
//! well-formed files that lie. One file in eight keeps one stale checksum.

use super::mutate::{mutate, INTERESTING_TOKENS};
use super::rng::Rng;

#[derive(Clone)]
enum Record {
    Meta(Vec<u8>),
    Array { name: Vec<u8>, dtype: u8, dims: Vec<u64>, payload: Vec<u8> },
}

#[derive(Clone)]
pub struct Stage {
    header: Vec<u8>,
    segments: Vec<Vec<Record>>,
    /// Bytes after the last record that could be split (kept as they are).
    rest: Vec<u8>,
}

fn dtype_size(d: u8) -> Option<usize> {
    match d {
        1 | 3 => Some(8),
        2 | 4 => Some(4),
        5 => Some(1),
        _ => None,
    }
}

fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

/// Split a stage file; `None` when it has no header line.
pub fn split(b: &[u8]) -> Option<Stage> {
    let nl = b.iter().take(256).position(|&c| c == b'\n')?;
    let header = b[..=nl].to_vec();
    let (mut segments, mut current) = (Vec::new(), Vec::new());
    let mut at = nl + 1;
    let rest = loop {
        let Some(tag) = b.get(at..at + 4) else { break b[at.min(b.len())..].to_vec() };
        match tag {
            b"META" => {
                let Some(n) = u64_at(b, at + 4).and_then(|n| usize::try_from(n).ok()) else { break b[at..].to_vec() };
                let Some(text) = b.get(at + 12..(at + 12).saturating_add(n)) else { break b[at..].to_vec() };
                current.push(Record::Meta(text.to_vec()));
                at += 12 + n;
            }
            b"ARRY" => {
                let parsed = (|| {
                    let nl = u32::from_le_bytes(b.get(at + 4..at + 8)?.try_into().ok()?) as usize;
                    let name = b.get(at + 8..at + 8 + nl)?.to_vec();
                    let mut p = at + 8 + nl;
                    let dtype = *b.get(p)?;
                    let ndim = *b.get(p + 1)? as usize;
                    p += 2;
                    let mut dims = Vec::new();
                    for _ in 0..ndim {
                        dims.push(u64_at(b, p)?);
                        p += 8;
                    }
                    let n = dims.iter().try_fold(1u64, |a, &d| a.checked_mul(d))?.checked_mul(dtype_size(dtype)? as u64)?;
                    let payload = b.get(p..p.checked_add(usize::try_from(n).ok()?)?)?.to_vec();
                    Some((Record::Array { name, dtype, dims, payload: payload.clone() }, p + payload.len()))
                })();
                let Some((r, next)) = parsed else { break b[at..].to_vec() };
                current.push(r);
                at = next;
            }
            b"END!" if b.len() >= at + 20 => {
                segments.push(std::mem::take(&mut current));
                at += 20;
            }
            _ => break b[at..].to_vec(),
        }
    };
    if !current.is_empty() {
        segments.push(current);
    }
    Some(Stage { header, segments, rest })
}

/// The checksum of `docs/formats.md`: FNV-1a over 8-byte little-endian words, then
/// the remaining bytes one by one, continuing from `h`.
fn fnv(mut h: u64, bytes: &[u8]) -> u64 {
    let mut words = bytes.chunks_exact(8);
    for w in &mut words {
        h = (h ^ u64::from_le_bytes(w.try_into().unwrap())).wrapping_mul(0x100_0000_01b3);
    }
    for &c in words.remainder() {
        h = (h ^ c as u64).wrapping_mul(0x100_0000_01b3);
    }
    h
}

/// Write the file back, every segment sealed (except `stale`, whose checksum is off).
pub fn seal(s: &Stage, stale: Option<usize>) -> Vec<u8> {
    let mut out = s.header.clone();
    let (mut chain, mut records, mut seg_start) = (0xcbf2_9ce4_8422_2325u64, 0u64, 0usize);
    for (k, seg) in s.segments.iter().enumerate() {
        for r in seg {
            match r {
                Record::Meta(t) => {
                    out.extend_from_slice(b"META");
                    out.extend_from_slice(&(t.len() as u64).to_le_bytes());
                    out.extend_from_slice(t);
                }
                Record::Array { name, dtype, dims, payload } => {
                    out.extend_from_slice(b"ARRY");
                    out.extend_from_slice(&(name.len() as u32).to_le_bytes());
                    out.extend_from_slice(name);
                    out.push(*dtype);
                    out.push(dims.len() as u8);
                    dims.iter().for_each(|d| out.extend_from_slice(&d.to_le_bytes()));
                    out.extend_from_slice(payload);
                }
            }
            records += 1;
        }
        chain = fnv(chain, &out[seg_start..]);
        out.extend_from_slice(b"END!");
        out.extend_from_slice(&records.to_le_bytes());
        out.extend_from_slice(&(if stale == Some(k) { chain ^ 1 } else { chain }).to_le_bytes());
        seg_start = out.len();
    }
    out.extend_from_slice(&s.rest);
    out
}

fn interesting_dim(rng: &mut Rng, d: u64) -> u64 {
    *rng.pick(&[0, 1, 2, 3, 6, 8, 9, d.wrapping_add(1), d.wrapping_sub(1), d.wrapping_mul(2), 1 << 32, 1_000_000_000_000, u64::MAX, u64::MAX / 8 + 1])
}

/// Change one array: its dimensions (payload resized to match, when small), dtype,
/// name, or one of its values.
fn mutate_array(r: &mut Record, names: &[Vec<u8>], rng: &mut Rng) {
    let Record::Array { name, dtype, dims, payload } = r else { return };
    match rng.below(6) {
        0 | 1 if !dims.is_empty() => {
            let i = rng.below(dims.len());
            dims[i] = interesting_dim(rng, dims[i]);
            // mostly keep the file consistent, so the reader behind the container runs
            if !rng.one_in(4) {
                let n = dims.iter().try_fold(1u64, |a, &d| a.checked_mul(d)).and_then(|n| n.checked_mul(dtype_size(*dtype).unwrap_or(1) as u64));
                match n {
                    Some(n) if n <= 1 << 20 => payload.resize(n as usize, 0),
                    _ => {}
                }
            }
        }
        0 | 1 => dims.push(interesting_dim(rng, 1)),
        2 => *dtype = if rng.one_in(4) { rng.next_u64() as u8 } else { 1 + rng.below(5) as u8 },
        3 => {
            *name = if rng.one_in(2) && !names.is_empty() {
                rng.pick(names).clone()
            } else {
                mutate(name, &[], rng)
            }
        }
        _ if !payload.is_empty() => {
            let size = dtype_size(*dtype).unwrap_or(1);
            let n = payload.len() / size;
            if n == 0 {
                return;
            }
            let at = rng.below(n) * size;
            let v: u64 = match (*dtype, rng.below(3)) {
                (1, 0) => f64::NAN.to_bits(),
                (1, 1) => [f64::INFINITY, -1e308, 1e300, -0.0, 5e-324][rng.below(5)].to_bits(),
                (2 | 4, 0) => u32::MAX as u64,
                (2 | 4, 1) => [1u64, 7, 8, 9, 1 << 20, 0x7fff_ffff][rng.below(6)],
                (3, 0) => u64::MAX,
                _ => rng.next_u64() >> rng.below(64),
            };
            payload[at..at + size].copy_from_slice(&v.to_le_bytes()[..size]);
        }
        _ => {}
    }
}

/// The same count in a META number and an array dimension (payload resized when
/// small): the lie a reader's cross-checks between metadata and arrays let through
/// (a net of 10^12 x 0 points against an empty array).
fn lie_consistently(s: &mut Stage, rng: &mut Rng) {
    let v: u64 = *rng.pick(&[0, 1, 2, 3, 4, 9, 1 << 20, 1 << 32, 1_000_000_000_000, u64::MAX]);
    let metas: Vec<(usize, usize)> = s.segments.iter().enumerate().flat_map(|(k, sg)| sg.iter().enumerate().filter(|(_, r)| matches!(r, Record::Meta(_))).map(move |(i, _)| (k, i))).collect();
    let arrays: Vec<(usize, usize)> = s.segments.iter().enumerate().flat_map(|(k, sg)| sg.iter().enumerate().filter(|(_, r)| matches!(r, Record::Array { .. })).map(move |(i, _)| (k, i))).collect();
    if metas.is_empty() || arrays.is_empty() {
        return;
    }
    let &(mk, mi) = rng.pick(&metas);
    if let Record::Meta(t) = &mut s.segments[mk][mi] {
        let nums: Vec<(usize, usize)> = {
            let mut out = Vec::new();
            let mut i = 0;
            while i < t.len() {
                if t[i].is_ascii_digit() && (i == 0 || !t[i - 1].is_ascii_alphanumeric()) {
                    let st = i;
                    while i < t.len() && t[i].is_ascii_digit() {
                        i += 1;
                    }
                    out.push((st, i));
                } else {
                    i += 1;
                }
            }
            out
        };
        if nums.is_empty() {
            return;
        }
        let (a, b) = *rng.pick(&nums);
        *t = [&t[..a], v.to_string().as_bytes(), &t[b..]].concat();
    }
    let &(ak, ai) = rng.pick(&arrays);
    if let Record::Array { dtype, dims, payload, .. } = &mut s.segments[ak][ai] {
        if dims.is_empty() {
            dims.push(v);
        } else {
            let i = rng.below(dims.len());
            dims[i] = v;
        }
        let n = dims.iter().try_fold(1u64, |a, &d| a.checked_mul(d)).and_then(|n| n.checked_mul(dtype_size(*dtype).unwrap_or(1) as u64));
        if let Some(n) = n.filter(|&n| n <= 1 << 20) {
            payload.resize(n as usize, 0);
        }
    }
}

/// One structural mutation of a stage file, sealed again; `None` when the input
/// has no header line (the caller mutates its bytes instead).
pub fn mutate_stage(b: &[u8], rng: &mut Rng) -> Option<Vec<u8>> {
    let mut s = split(b)?;
    let n_ops = 1 + rng.below(3);
    for _ in 0..n_ops {
        let names: Vec<Vec<u8>> = s.segments.iter().flatten().filter_map(|r| if let Record::Array { name, .. } = r { Some(name.clone()) } else { None }).collect();
        if s.segments.is_empty() {
            s.segments.push(Vec::new());
        }
        let k = rng.below(s.segments.len());
        let seg_len = s.segments[k].len();
        match rng.below(10) {
            0..=2 => {
                // a META's YAML, edited as text
                let metas: Vec<(usize, usize)> = s.segments.iter().enumerate().flat_map(|(k, sg)| sg.iter().enumerate().filter(|(_, r)| matches!(r, Record::Meta(_))).map(move |(i, _)| (k, i))).collect();
                if let Some(&(k, i)) = (!metas.is_empty()).then(|| rng.pick(&metas)) {
                    if let Record::Meta(t) = &mut s.segments[k][i] {
                        *t = mutate(t, &[], rng);
                    }
                }
            }
            3..=5 if seg_len > 0 => {
                let i = rng.below(seg_len);
                mutate_array(&mut s.segments[k][i], &names, rng);
            }
            6 if rng.one_in(2) => lie_consistently(&mut s, rng),
            6 if seg_len > 0 => {
                s.segments[k].remove(rng.below(seg_len));
            }
            7 if seg_len > 0 => {
                let r = s.segments[k][rng.below(seg_len)].clone();
                let k2 = rng.below(s.segments.len());
                let at = rng.below(s.segments[k2].len() + 1);
                s.segments[k2].insert(at, r);
            }
            8 if seg_len > 1 => {
                let (i, j) = (rng.below(seg_len), rng.below(seg_len));
                s.segments[k].swap(i, j);
            }
            _ => match rng.below(4) {
                0 if s.segments.len() > 1 => {
                    s.segments.remove(k);
                }
                1 => {
                    let seg = s.segments[k].clone();
                    s.segments.insert(rng.below(s.segments.len() + 1), seg);
                }
                2 if k + 1 < s.segments.len() => {
                    let next = s.segments.remove(k + 1);
                    s.segments[k].extend(next);
                }
                _ => {
                    let h = String::from_utf8_lossy(&s.header).into_owned();
                    let tok = rng.pick(INTERESTING_TOKENS);
                    let parts: Vec<&str> = h.trim_end().split(' ').collect();
                    let i = rng.below(parts.len().max(1));
                    let mut parts: Vec<String> = parts.iter().map(|p| p.to_string()).collect();
                    if i < parts.len() {
                        parts[i] = if i == 2 { format!("{}.{tok}", parts[i].split('.').next().unwrap_or("1")) } else { tok.to_string() };
                    }
                    s.header = format!("{}\n", parts.join(" ")).into_bytes();
                }
            },
        }
    }
    let stale = rng.one_in(8).then(|| rng.below(s.segments.len().max(1)));
    Some(seal(&s, stale))
}

