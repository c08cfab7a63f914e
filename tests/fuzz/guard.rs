//! What counts as a crash, and how it is caught in-process:
//! - **panic**: `catch_unwind` around the reader; the message is kept (the panic
//!   hook records it instead of printing while a fuzz input runs);
//! - **allocation beyond the input**: the test binary's global allocator refuses,
//!   on the fuzzing thread, any single allocation larger than
//!   `ALLOC_FLOOR + ALLOC_PER_BYTE × input length` — a header count that the file's
//!   size cannot hold asking for a `Vec` of it — and any allocation that takes the
//!   thread's live bytes (allocated minus freed since the input started) past
//!   `TOTAL_FLOOR + TOTAL_PER_BYTE × input length`: many small allocations driven
//!   by a count (a `Vec` per claimed node) add up as surely as one large one. That
//!   cannot be unwound, so the input is saved to the regression corpus and the
//!   process aborts with a message naming the file;
//! - **hang**: a watchdog thread aborts the same way when one input runs longer
//!   than the time limit (`SC_FUZZ_INPUT_SECONDS`, default 10 s; the largest
//!   shipped seed reads in milliseconds).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::{Cell, RefCell};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, Once};
use std::time::{Duration, Instant};

/// Every input may allocate this much at once, whatever its size (64 MiB).
pub const ALLOC_FLOOR: usize = 64 << 20;
/// ... plus this many bytes per byte of input.
pub const ALLOC_PER_BYTE: usize = 64;
/// Every input may hold this much live at once, whatever its size (64 MiB, as for
/// one allocation: the readers' fixed cost is under 1 MB, and the largest a valid
/// setup may ask for, the 10⁶ load factors of `increments.count`, is 8 MB) ...
pub const TOTAL_FLOOR: usize = 64 << 20;
/// ... plus this many bytes per byte of input (the shipped seeds hold at most 2.9:
/// ASCII MSH read into its mesh is the densest).
pub const TOTAL_PER_BYTE: usize = 32;

/// The live bytes an input of `len` bytes may hold.
pub fn total_allowance(len: usize) -> usize {
    TOTAL_FLOOR.saturating_add(TOTAL_PER_BYTE.saturating_mul(len))
}

thread_local! {
    /// The largest single allocation allowed on this thread (`usize::MAX`: no limit).
    static LIMIT: Cell<usize> = const { Cell::new(usize::MAX) };
    /// The most live bytes allowed on this thread (`usize::MAX`: no limit, no count).
    static TOTAL: Cell<usize> = const { Cell::new(usize::MAX) };
    /// Bytes allocated minus freed on this thread since the input started (frees of
    /// older memory make it negative), and its peak.
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
    /// The message of the last panic caught while an input ran.
    static LAST_PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// The input running now, for the allocator and the watchdog to save.
struct Current {
    save_to: PathBuf,
    input: Vec<u8>,
}
static CURRENT: Mutex<Option<Current>> = Mutex::new(None);
/// When the current input started (ns since `epoch()`), 0 when none runs.
static STARTED: AtomicU64 = AtomicU64::new(0);

fn epoch() -> Instant {
    static E: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    *E.get_or_init(Instant::now)
}

/// The global allocator of the test binary: the system's, with the per-thread limit.
pub struct Guarded;

#[inline]
fn check(size: usize, freed: usize) {
    if size > LIMIT.with(|l| l.get()) {
        over_limit(size);
    }
    let total = TOTAL.with(|t| t.get());
    if total != usize::MAX {
        let live = LIVE.with(|l| {
            let v = l.get() + size as isize - freed as isize;
            l.set(v);
            v
        });
        PEAK.with(|p| p.set(p.get().max(live)));
        if live > total as isize {
            over_total(live);
        }
    }
}

#[inline]
fn freed(size: usize) {
    if TOTAL.with(|t| t.get()) != usize::MAX {
        LIVE.with(|l| l.set(l.get() - size as isize));
    }
}

#[cold]
fn over_total(live: isize) -> ! {
    LIMIT.with(|l| l.set(usize::MAX));
    TOTAL.with(|t| t.set(usize::MAX));
    let saved = save_current("oom");
    eprintln!("fuzz: {live} bytes live at once exceed what the input can hold; input saved as {saved}");
    std::process::abort()
}

#[cold]
fn over_limit(size: usize) -> ! {
    LIMIT.with(|l| l.set(usize::MAX));
    TOTAL.with(|t| t.set(usize::MAX));
    let saved = save_current("oom");
    eprintln!("fuzz: an allocation of {size} bytes exceeds what the input can hold; input saved as {saved}");
    std::process::abort()
}

fn save_current(kind: &str) -> String {
    let Ok(cur) = CURRENT.try_lock() else { return "<busy>".into() };
    match cur.as_ref() {
        Some(c) => {
            let path = c.save_to.join(format!("{kind}-{:016x}", super::engine::fnv(&c.input)));
            let _ = std::fs::create_dir_all(&c.save_to);
            match std::fs::write(&path, &c.input) {
                Ok(()) => path.display().to_string(),
                Err(e) => format!("<not saved: {e}>"),
            }
        }
        None => "<no input registered>".into(),
    }
}

unsafe impl GlobalAlloc for Guarded {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        check(layout.size(), 0);
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        check(layout.size(), 0);
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        check(new_size, layout.size());
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        freed(layout.size());
        unsafe { System.dealloc(ptr, layout) }
    }
}

fn install_hook_and_watchdog() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if QUIET.with(|q| q.get()) {
                let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
                let msg = info.payload().downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| info.payload().downcast_ref::<String>().cloned()).unwrap_or_default();
                LAST_PANIC.with(|p| *p.borrow_mut() = Some(format!("{msg}{at}")));
            } else {
                previous(info)
            }
        }));
        let limit = std::env::var("SC_FUZZ_INPUT_SECONDS").ok().and_then(|s| s.parse::<f64>().ok()).unwrap_or(10.0);
        std::thread::spawn(move || loop {
            std::thread::sleep(Duration::from_millis(100));
            let s = STARTED.load(Ordering::Relaxed);
            if s != 0 && epoch().elapsed().as_nanos() as u64 > s + (limit * 1e9) as u64 {
                let saved = save_current("hang");
                eprintln!("fuzz: an input ran longer than {limit} s; input saved as {saved}");
                std::process::abort();
            }
        });
    });
}

/// How one input ended.
pub enum Outcome {
    /// The reader accepted it.
    Accepted,
    /// The reader refused it with this error (the expected end of most inputs).
    Refused(String),
    /// The reader panicked: the message and where.
    Panicked(String),
}

/// Run `f` on `input` under the guards; `save_to` is where an input that aborts the
/// process (allocation, hang) is saved first.
pub fn run_guarded(input: &[u8], save_to: PathBuf, f: impl FnOnce(&[u8]) -> Result<(), String>) -> Outcome {
    install_hook_and_watchdog();
    *CURRENT.lock().unwrap() = Some(Current { save_to, input: input.to_vec() });
    let limit = ALLOC_FLOOR.saturating_add(ALLOC_PER_BYTE.saturating_mul(input.len()));
    let total = total_allowance(input.len());
    QUIET.with(|q| q.set(true));
    LAST_PANIC.with(|p| p.borrow_mut().take());
    STARTED.store((epoch().elapsed().as_nanos() as u64).max(1), Ordering::Relaxed);
    LIVE.with(|l| l.set(0));
    PEAK.with(|p| p.set(0));
    LIMIT.with(|l| l.set(limit));
    TOTAL.with(|t| t.set(total));
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(input)));
    LIMIT.with(|l| l.set(usize::MAX));
    TOTAL.with(|t| t.set(usize::MAX));
    STARTED.store(0, Ordering::Relaxed);
    QUIET.with(|q| q.set(false));
    match r {
        Ok(Ok(())) => Outcome::Accepted,
        Ok(Err(e)) => Outcome::Refused(e),
        Err(_) => Outcome::Panicked(LAST_PANIC.with(|p| p.borrow_mut().take()).unwrap_or_else(|| "<no message>".into())),
    }
}

/// The most bytes the last input held live at once (allocated on its thread
/// while it ran, minus what it freed).
pub fn last_peak() -> usize {
    PEAK.with(|p| p.get().max(0) as usize)
}
