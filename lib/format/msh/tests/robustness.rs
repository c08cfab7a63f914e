//! Malformed input never panics.

use super::*;

/// Every strict prefix of a valid file is an error, never a panic; so is every
/// single-byte corruption of a binary file (an error or, rarely, a valid mesh).
#[test]
fn prefixes_and_corruptions_never_panic() {
    for (version, bytes) in two_hexes().all() {
        let end = bytes.len() - 1; // the file minus its final newline is still valid
        for n in 0..end {
            if parse_msh("t.msh", &bytes[..n]).is_ok() {
                panic!("{version}: prefix of {n} bytes parsed");
            }
        }
        if version.ends_with("binary") {
            for i in 0..bytes.len() {
                for flip in [0xffu8, 0x80, 0x01] {
                    let mut b = bytes.clone();
                    b[i] ^= flip;
                    let _ = parse_msh("t.msh", &b);
                }
            }
        }
    }
}
