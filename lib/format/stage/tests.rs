//! Stage files written and read back, appended to, cut short and corrupted.

use super::checksum::Checksum;
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
