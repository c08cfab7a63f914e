//! A run's timeline: when each phase of the solve started and ended, on which
//! thread. With `SC_TIMELINE=1` in the environment `sc-solve` prints it to standard
//! error at the end (milliseconds since the process started: `main`'s first line),
//! one span a line, in the order the spans started — what a profile of a short run
//! cannot show: which phases overlap, which wait, where a core stands idle
//! (docs/performance.md, "Where a short run's time goes").
//!
//! Off (the default) a span costs one relaxed atomic load; on, two clock reads and
//! a push under a mutex (spans are per phase, never per element).

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::Instant;

/// One finished span: its name, the thread it ran on, start and end (seconds
/// since [`epoch`]).
#[derive(Debug, Clone)]
pub struct Entry {
    pub name: &'static str,
    pub thread: String,
    pub start: f64,
    pub end: f64,
}

/// 0 not read yet, 1 on, 2 off.
static STATE: AtomicU8 = AtomicU8::new(0);
static EPOCH: OnceLock<Instant> = OnceLock::new();
static ENTRIES: Mutex<Vec<Entry>> = Mutex::new(Vec::new());

/// Whether `SC_TIMELINE` is set (to anything but empty or `0`).
pub fn enabled() -> bool {
    match STATE.load(Ordering::Relaxed) {
        1 => true,
        2 => false,
        _ => {
            let on = std::env::var_os("SC_TIMELINE").is_some_and(|v| !v.is_empty() && v != "0");
            STATE.store(if on { 1 } else { 2 }, Ordering::Relaxed);
            on
        }
    }
}

/// The time origin: the first call (a binary calls it first thing in `main`).
pub fn epoch() -> Instant {
    *EPOCH.get_or_init(Instant::now)
}

/// A phase being timed: recorded when dropped.
#[must_use = "a span records when it is dropped"]
pub struct Span {
    name: &'static str,
    start: Option<Instant>,
}

/// Start timing the phase `name` (nothing is recorded unless [`enabled`]).
pub fn span(name: &'static str) -> Span {
    Span { name, start: enabled().then(Instant::now) }
}

impl Drop for Span {
    fn drop(&mut self) {
        let Some(start) = self.start else { return };
        let e = epoch();
        let end = Instant::now();
        let t = std::thread::current();
        let thread = t.name().map_or_else(|| format!("{:?}", t.id()), str::to_owned);
        let entry = Entry { name: self.name, thread, start: start.saturating_duration_since(e).as_secs_f64(), end: end.saturating_duration_since(e).as_secs_f64() };
        if let Ok(mut v) = ENTRIES.lock() {
            v.push(entry);
        }
    }
}

/// The spans recorded so far, in the order they started.
pub fn entries() -> Vec<Entry> {
    let mut v = ENTRIES.lock().map(|v| v.clone()).unwrap_or_default();
    v.sort_by(|a, b| a.start.total_cmp(&b.start));
    v
}

/// Print the timeline to standard error when [`enabled`] (what a binary does at
/// its end).
pub fn report() {
    if enabled() {
        eprint!("{}", render(&entries()));
    }
}

/// The timeline as text: a header, then `start end duration thread name` a line (ms).
pub fn render(entries: &[Entry]) -> String {
    let mut s = String::from("timeline (ms since main started):    start      end   length  thread            phase\n");
    for e in entries {
        s.push_str(&format!("{:>46.2} {:>8.2} {:>8.2}  {:<16}  {}\n", 1e3 * e.start, 1e3 * e.end, 1e3 * (e.end - e.start), e.thread, e.name));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_span_is_recorded_with_its_length_when_the_timeline_is_on() {
        STATE.store(1, Ordering::Relaxed);
        epoch();
        {
            let _s = span("test: sleep 2 ms");
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        let e = entries().into_iter().find(|e| e.name == "test: sleep 2 ms").expect("the span is recorded");
        // a sleep lasts at least what it asks for
        assert!(e.end - e.start >= 2e-3, "{e:?}");
        assert!(render(&[e]).contains("test: sleep 2 ms"));
    }
}
