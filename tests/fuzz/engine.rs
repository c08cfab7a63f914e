//! The fuzz loop: mutate a seed (or an input the reader accepted earlier, to get
//! past its first checks), run the target under the guards, keep what crashed.
//!
//! Depth comes from structure and from feedback. The stage mutator keeps files
//! well-sealed; inputs that a reader *accepted* after a mutation join the pool (up
//! to 256) so that later mutations stack on them; and so does an input refused
//! with a reason no earlier input got (the message with its numbers and quoted
//! names blanked): it reached a check no input had reached, the closest thing to
//! new coverage that a stable toolchain shows without instrumenting the build.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use super::guard::{last_peak, run_guarded, Outcome};
use super::mutate::mutate;
use super::rng::Rng;
use super::stage_records::mutate_stage;
use super::targets::{Kind, Target};
use crate::common::repo;

/// 64-bit FNV-1a of the bytes (names the saved inputs).
pub fn fnv(b: &[u8]) -> u64 {
    b.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &c| (h ^ c as u64).wrapping_mul(0x100_0000_01b3))
}

/// The regression corpus of a target: `tests/data/fuzz/<target>/`.
pub fn corpus_dir(target: &str) -> PathBuf {
    repo().join("tests/data/fuzz").join(target)
}

#[derive(Default, Debug)]
pub struct Stats {
    pub inputs: u64,
    pub accepted: u64,
    pub refused: u64,
    pub seconds: f64,
    /// (saved file, panic message) of each input that crashed.
    pub crashes: Vec<(PathBuf, String)>,
    /// Distinct refusal reasons met (the feedback).
    pub reasons: usize,
    /// The most bytes one input held live, and the most per byte of input among
    /// inputs of at least 1 kB.
    pub peak: usize,
    pub peak_per_byte: f64,
}

/// A refusal reason with what varies between inputs of one check blanked: numbers
/// (a run of digits with its sign, point and exponent), and quoted or bracketed
/// text (the offending token, a list of values) — from an opening quote to the
/// last such quote of the message, since a fuzzed token may hold quotes itself.
pub fn reason(message: &str) -> String {
    let chars: Vec<char> = message.chars().collect();
    let mut out = String::with_capacity(message.len());
    let mut in_number = false;
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let close = match c {
            '\'' | '"' | '`' => Some(c),
            '[' => Some(']'),
            _ => None,
        };
        if let Some(close) = close {
            if let Some(last) = chars.iter().rposition(|&d| d == close).filter(|&l| l > i) {
                out.push('~');
                in_number = false;
                i = last + 1;
                continue;
            }
        }
        let next_digit = chars.get(i + 1).is_some_and(|n| n.is_ascii_digit());
        let number = c.is_ascii_digit() || ((c == '-' || c == '+' || c == '.') && next_digit) || (in_number && (c == '.' || c == 'e' || c == 'E'));
        if number && !in_number {
            out.push('#');
        }
        if !number && c.is_ascii() {
            out.push(c);
        }
        in_number = number;
        i += 1;
    }
    out
}

/// Shrink a crashing input by cutting ranges while it still panics (at most
/// `tries` runs), so the corpus keeps small files.
fn shrink(t: &Target, mut b: Vec<u8>, tries: usize) -> Vec<u8> {
    let mut chunk = b.len() / 2;
    let mut left = tries;
    while chunk > 0 && left > 0 {
        let mut i = 0;
        while i + chunk <= b.len() && left > 0 {
            let cand = [&b[..i], &b[i + chunk..]].concat();
            left -= 1;
            if matches!(run_guarded(&cand, corpus_dir(t.name), t.run), Outcome::Panicked(_)) {
                b = cand;
            } else {
                i += chunk;
            }
        }
        chunk /= 2;
    }
    b
}

/// Fuzz `t` for `budget`, starting the generator from `seed`.
pub fn fuzz(t: &Target, budget: Duration, seed: u64) -> Stats {
    let seeds: Vec<Vec<u8>> = (t.seeds)().into_iter().map(|(_, b)| b).collect();
    assert!(!seeds.is_empty(), "target {} has no seeds", t.name);
    let mut pool: Vec<Vec<u8>> = Vec::new();
    let mut rng = Rng::new(seed ^ fnv(t.name.as_bytes()));
    let mut stats = Stats::default();
    let mut seen_panics = std::collections::HashSet::new();
    let mut reasons = std::collections::HashSet::new();
    let start = Instant::now();
    while start.elapsed() < budget {
        let base = if !pool.is_empty() && rng.one_in(3) { rng.pick(&pool) } else { rng.pick(&seeds) };
        let mut input = match t.kind {
            Kind::Stage if rng.one_in(2) => mutate_stage(base, &mut rng).unwrap_or_else(|| mutate(base, &seeds, &mut rng)),
            _ => mutate(base, &seeds, &mut rng),
        };
        stats.inputs += 1;
        let outcome = run_guarded(&input, corpus_dir(t.name), t.run);
        let peak = last_peak();
        stats.peak = stats.peak.max(peak);
        if input.len() >= 1000 {
            stats.peak_per_byte = stats.peak_per_byte.max(peak as f64 / input.len() as f64);
        }
        let keep = match outcome {
            Outcome::Accepted => {
                stats.accepted += 1;
                true
            }
            Outcome::Refused(why) => {
                stats.refused += 1;
                let r = reason(&why);
                reasons.insert(r)
            }
            Outcome::Panicked(msg) => {
                // one saved input per panic site
                let site = msg.rsplit(" at ").next().unwrap_or(&msg).to_string();
                if seen_panics.insert(site) {
                    let small = shrink(t, std::mem::take(&mut input), 2000);
                    let path = corpus_dir(t.name).join(format!("crash-{:016x}", fnv(&small)));
                    std::fs::create_dir_all(corpus_dir(t.name)).unwrap();
                    std::fs::write(&path, &small).unwrap();
                    eprintln!("fuzz {}: PANIC {msg}; saved {} ({} bytes)", t.name, path.display(), small.len());
                    stats.crashes.push((path, msg));
                }
                false
            }
        };
        if keep {
            if pool.len() < 256 {
                pool.push(input);
            } else {
                let i = rng.below(pool.len());
                pool[i] = input;
            }
        }
    }
    stats.reasons = reasons.len();
    stats.seconds = start.elapsed().as_secs_f64();
    stats
}
