//! Fuzzing every reader, on stable Rust, inside the normal test binary.
//!
//! A structure-aware mutator ([`mutate`], [`stage_records`]) changes the files the
//! repository ships and feeds each reader ([`targets`]); the guards ([`guard`])
//! turn a panic, an allocation the input's size cannot justify, or a hang into a
//! saved input. What crashed once is kept in `tests/data/fuzz/<target>/` and
//! replayed by [`fuzz_corpus_replays_without_a_crash`].
//!
//! - `cargo test --release --locked fuzz_` — what CI runs: the seeds, the corpus,
//!   and 3 s per target (about half a minute in all: a regression check of the
//!   readers on every run; the searching is done by the long runs below);
//! - `SC_FUZZ_SECONDS=120 SC_FUZZ_SEED=7 cargo test --release --locked
//!   fuzz_every_reader -- --nocapture` — longer, with another generator seed;
//!   prints inputs per target (docs/reliability.md).

mod engine;
mod guard;
mod mutate;
mod rng;
mod stage_records;
mod targets;

use std::sync::Mutex;
use std::time::Duration;

use guard::{run_guarded, Outcome};
use targets::TARGETS;

#[global_allocator]
static GUARD: guard::Guarded = guard::Guarded;

/// One fuzz test at a time: the guards keep one current input. The short tests are
/// named to sort before [`fuzz_every_reader`] (libtest starts tests in name order):
/// started after it, one would hold a test thread idle for its whole minute.
static SERIAL: Mutex<()> = Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// Every seed is read as it is: a seed a reader refuses (a stale committed stage
/// file after a format change) would make its target fuzz nothing deep.
#[test]
fn fuzz_accepts_every_seed() {
    let _s = serial();
    // the largest share of its live-bytes allowance a seed uses: a reader that
    // holds more than half of it on a valid file leaves mutated ones too little
    // headroom (measured: the 1.6 MB hertz3d.msh peaks at 2.6 MB, 1.6 bytes a byte)
    let mut worst = (0.0f64, String::new());
    for t in TARGETS {
        let seeds = (t.seeds)();
        assert!(!seeds.is_empty(), "target {} has no seeds", t.name);
        for (name, b) in seeds {
            let outcome = run_guarded(&b, engine::corpus_dir(t.name), t.run);
            let share = guard::last_peak() as f64 / guard::total_allowance(b.len()) as f64;
            if share > worst.0 {
                worst = (share, format!("{}: {name} ({} bytes, {} bytes live at most)", t.name, b.len(), guard::last_peak()));
            }
            match outcome {
                Outcome::Accepted => {}
                Outcome::Refused(why) => {
                    panic!("{}: seed {name} is refused: {why} (regenerate it: docs/reliability.md)", t.name)
                }
                Outcome::Panicked(m) => panic!("{}: seed {name} panics: {m}", t.name),
            }
        }
    }
    eprintln!("seeds: at most {:.1} % of the live-bytes allowance ({})", 100.0 * worst.0, worst.1);
    assert!(worst.0 <= 0.5, "{} uses {:.0} % of its live-bytes allowance", worst.1, 100.0 * worst.0);
}

/// Every input that once crashed a reader is read without a panic, within the
/// allocation limit (else the process aborts naming it) and the time limit.
#[test]
fn fuzz_corpus_replays_without_a_crash() {
    let _s = serial();
    let mut failures = Vec::new();
    let mut n = 0;
    for t in TARGETS {
        let dir = engine::corpus_dir(t.name);
        let Ok(entries) = std::fs::read_dir(&dir) else { continue };
        let mut paths: Vec<_> = entries.filter_map(|e| e.ok()).map(|e| e.path()).collect();
        paths.sort();
        for p in paths {
            let b = std::fs::read(&p).unwrap();
            n += 1;
            if let Outcome::Panicked(m) = run_guarded(&b, std::env::temp_dir(), t.run) {
                failures.push(format!("{}: {m}", p.display()));
            }
        }
    }
    eprintln!("replayed {n} corpus inputs");
    assert!(failures.is_empty(), "corpus inputs that still crash:\n{}", failures.join("\n"));
}

/// Each target for `SC_FUZZ_SECONDS` (default 3) from generator seed `SC_FUZZ_SEED`
/// (default 27): no panic, no allocation beyond the input, no hang.
#[test]
fn fuzz_every_reader() {
    let _s = serial();
    let secs: f64 = std::env::var("SC_FUZZ_SECONDS").ok().and_then(|s| s.parse().ok()).unwrap_or(3.0);
    let seed: u64 = std::env::var("SC_FUZZ_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(27);
    let only = std::env::var("SC_FUZZ_TARGET").ok();
    let mut crashes = Vec::new();
    eprintln!("{:<14} {:>10} {:>10} {:>10} {:>8} {:>8} {:>8} {:>9} {:>7}", "target", "inputs", "accepted", "refused", "reasons", "seconds", "crashes", "peak MB", "B/byte");
    for t in TARGETS.iter().filter(|t| only.as_deref().is_none_or(|o| o == t.name)) {
        let s = engine::fuzz(t, Duration::from_secs_f64(secs), seed);
        eprintln!(
            "{:<14} {:>10} {:>10} {:>10} {:>8} {:>8.1} {:>8} {:>9.1} {:>7.1}",
            t.name,
            s.inputs,
            s.accepted,
            s.refused,
            s.reasons,
            s.seconds,
            s.crashes.len(),
            s.peak as f64 / 1e6,
            s.peak_per_byte
        );
        crashes.extend(s.crashes.into_iter().map(|(p, m)| format!("{}: {m}", p.display())));
    }
    assert!(crashes.is_empty(), "crashes (saved to the corpus):\n{}", crashes.join("\n"));
}
