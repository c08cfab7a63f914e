//! The fuzz loop: mutate a seed (or an input the reader accepted earlier, to get
//! past its first checks), run the target under the guards, keep what crashed.
//!
//! Without coverage feedback, depth comes from structure: the stage mutator keeps
//! files well-sealed, and inputs that a reader *accepted* after a mutation join the
//! pool (up to 256) so that later mutations stack on them.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use super::guard::{run_guarded, Outcome};
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
    let start = Instant::now();
    while start.elapsed() < budget {
        let base = if !pool.is_empty() && rng.one_in(3) { rng.pick(&pool) } else { rng.pick(&seeds) };
        let input = match t.kind {
            Kind::Stage if rng.one_in(2) => mutate_stage(base, &mut rng).unwrap_or_else(|| mutate(base, &seeds, &mut rng)),
            _ => mutate(base, &seeds, &mut rng),
        };
        stats.inputs += 1;
        match run_guarded(&input, corpus_dir(t.name), t.run) {
            Outcome::Accepted => {
                stats.accepted += 1;
                if pool.len() < 256 {
                    pool.push(input);
                } else {
                    let i = rng.below(pool.len());
                    pool[i] = input;
                }
            }
            Outcome::Refused => stats.refused += 1,
            Outcome::Panicked(msg) => {
                // one saved input per panic site
                let site = msg.rsplit(" at ").next().unwrap_or(&msg).to_string();
                if seen_panics.insert(site) {
                    let small = shrink(t, input, 2000);
                    let path = corpus_dir(t.name).join(format!("crash-{:016x}", fnv(&small)));
                    std::fs::create_dir_all(corpus_dir(t.name)).unwrap();
                    std::fs::write(&path, &small).unwrap();
                    eprintln!("fuzz {}: PANIC {msg}; saved {} ({} bytes)", t.name, path.display(), small.len());
                    stats.crashes.push((path, msg));
                }
            }
        }
    }
    stats.seconds = start.elapsed().as_secs_f64();
    stats
}
