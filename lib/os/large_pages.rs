//! The binaries' allocator: large blocks on transparent huge pages.
//!
//! The first touch of a 4 KiB page costs 1.5–2.3 µs on the reference machine (a
//! virtual machine; a 2 MiB page costs 0.5 µs for each 4 KiB it holds). A solve
//! touches almost every page it allocates once (the sparsity pattern, the slot
//! maps, the tangent's values, the factor, the results' buffers): at 10k unknowns
//! 14,600 faults, about 26 ms of CPU in a 140 ms run. Blocks of at least
//! [`THRESHOLD`] bytes (half a huge page) are therefore mapped on their own, from a
//! 2 MiB boundary, and
//! advised `MADV_HUGEPAGE` (honoured when the kernel's transparent huge pages are
//! `madvise` or `always`); smaller ones go to the system allocator. Measured on the
//! Parisch blocks and the crossed beams: docs/performance.md.
//!
//! `SC_HUGE_PAGES=0` in the environment turns it off (every block from the system
//! allocator), for a kernel whose huge-page compaction stalls.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU8, Ordering};

/// A transparent huge page (x86-64): mappings start on a multiple of it.
const HUGE: usize = 2 << 20;
/// Blocks from this size on are mapped with huge pages advised ([`mapped_len`]:
/// one from half a huge page on takes a whole one).
pub const THRESHOLD: usize = HUGE / 2;
/// The largest alignment a mapping gives by itself.
const PAGE: usize = 4096;

/// [`GlobalAlloc`] of the binaries: [`System`] below [`THRESHOLD`], an anonymous
/// mapping advised for huge pages from it.
pub struct LargePages;

/// 0: not read yet, 1: on, 2: off (`SC_HUGE_PAGES=0`).
static STATE: AtomicU8 = AtomicU8::new(0);

/// Huge pages are wanted (read once; `getenv` does not allocate, as the allocator
/// must not).
fn enabled() -> bool {
    match STATE.load(Ordering::Relaxed) {
        1 => true,
        2 => false,
        _ => {
            // SAFETY: a NUL-terminated name; the value is only read, at once
            let off = unsafe {
                let v = libc::getenv(c"SC_HUGE_PAGES".as_ptr());
                !v.is_null() && *v == b'0' as libc::c_char && *v.add(1) == 0
            };
            STATE.store(if off { 2 } else { 1 }, Ordering::Relaxed);
            !off
        }
    }
}

/// Whether a block of this layout is (or would be) one of ours. A page-aligned
/// request is someone's own paging: `private-gemm-x86` (faer's dense products)
/// reserves 64 MiB of 4 KiB-aligned pages per thread for its packing and touches a
/// few; on huge pages each touch would zero 2 MiB (three such blocks made the
/// kernel's page clearing a tenth of a Parisch r = 6 run). It stays the system
/// allocator's.
fn mapped(size: usize, align: usize) -> bool {
    size >= THRESHOLD && align < PAGE && enabled()
}

/// The mapping's length for a block of `size` bytes: its whole huge pages, and a
/// tail of at least half a huge page rounded up to a whole one, a shorter tail to
/// whole 4 KiB pages. A huge page's first touch costs a quarter of its 512 small
/// pages' (module documentation), so a tail of half of one or more is cheaper on
/// one, for at most as much memory again; rounding every tail up cost the
/// frictional crossed beams n = 4 17 MB of peak, a quarter (the last huge page of
/// each 2–6 MB block). Measured: docs/performance.md.
fn mapped_len(size: usize) -> usize {
    let whole = size / HUGE * HUGE;
    if size - whole >= HUGE / 2 {
        whole + HUGE
    } else {
        size.div_ceil(PAGE) * PAGE
    }
}

/// A fresh anonymous mapping (zeroed) of `mapped_len(size)` bytes starting on a
/// huge-page boundary, advised for huge pages, or null.
unsafe fn map(size: usize) -> *mut u8 {
    let len = mapped_len(size);
    // one huge page more, then the parts before the boundary and after the block
    // given back: the block starts where a huge page can
    let over = len + HUGE;
    // SAFETY: an anonymous private mapping of `over` bytes, trimmed below to the
    // `len` bytes owned by the caller
    let p = unsafe { libc::mmap(std::ptr::null_mut(), over, libc::PROT_READ | libc::PROT_WRITE, libc::MAP_PRIVATE | libc::MAP_ANONYMOUS, -1, 0) };
    if p == libc::MAP_FAILED {
        return std::ptr::null_mut();
    }
    let start = p as usize;
    let aligned = start.next_multiple_of(HUGE);
    unsafe {
        if aligned > start {
            libc::munmap(p, aligned - start);
        }
        let end = aligned + len;
        if start + over > end {
            libc::munmap(end as *mut libc::c_void, start + over - end);
        }
        // advice only: a kernel without huge pages keeps 4 KiB ones
        libc::madvise(aligned as *mut libc::c_void, len, libc::MADV_HUGEPAGE);
    }
    aligned as *mut u8
}

// SAFETY: blocks below the threshold are System's; those from it on are whole
// mappings of `mapped_len(size)` bytes, page-aligned (more than the alignment asked,
// which `mapped` bounds below PAGE), released by munmap of the same length. The
// decision depends on (size, align) and a flag read once, so `dealloc` and `realloc`
// see the same decision as the `alloc` that made the block.
unsafe impl GlobalAlloc for LargePages {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if mapped(layout.size(), layout.align()) {
            unsafe { map(layout.size()) }
        } else {
            unsafe { System.alloc(layout) }
        }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if mapped(layout.size(), layout.align()) {
            // a fresh anonymous mapping reads as zeros
            unsafe { map(layout.size()) }
        } else {
            unsafe { System.alloc_zeroed(layout) }
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if mapped(layout.size(), layout.align()) {
            unsafe { libc::munmap(ptr.cast(), mapped_len(layout.size())) };
        } else {
            unsafe { System.dealloc(ptr, layout) }
        }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let (old, new) = (mapped(layout.size(), layout.align()), mapped(new_size, layout.align()));
        match (old, new) {
            (false, false) => unsafe { System.realloc(ptr, layout, new_size) },
            (true, true) if mapped_len(layout.size()) == mapped_len(new_size) => ptr,
            (true, true) => {
                let (from, to) = (mapped_len(layout.size()), mapped_len(new_size));
                // SAFETY: the whole mapping of this block, moved or grown in place
                let p = unsafe { libc::mremap(ptr.cast(), from, to, libc::MREMAP_MAYMOVE) };
                if p == libc::MAP_FAILED {
                    return std::ptr::null_mut();
                }
                unsafe { libc::madvise(p, to, libc::MADV_HUGEPAGE) };
                p.cast()
            }
            _ => {
                // across the threshold: a new block, the contents copied
                // SAFETY: `new_size` is non-zero and, rounded to `align`, fits isize (GlobalAlloc's contract)
                let new_layout = unsafe { Layout::from_size_align_unchecked(new_size, layout.align()) };
                let q = unsafe { self.alloc(new_layout) };
                if !q.is_null() {
                    unsafe { std::ptr::copy_nonoverlapping(ptr, q, layout.size().min(new_size)) };
                    unsafe { self.dealloc(ptr, layout) };
                }
                q
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fill `n` bytes at `p` with a pattern of `seed`, and check it.
    unsafe fn fill(p: *mut u8, n: usize, seed: u8) {
        for i in (0..n).step_by(4099) {
            unsafe { *p.add(i) = seed.wrapping_add(i as u8) };
        }
    }
    unsafe fn holds(p: *const u8, n: usize, seed: u8) -> bool {
        (0..n).step_by(4099).all(|i| unsafe { *p.add(i) } == seed.wrapping_add(i as u8))
    }

    #[test]
    fn blocks_keep_their_contents_across_every_kind_of_resize() {
        let a = LargePages;
        let sizes = [100usize, THRESHOLD - 1, THRESHOLD, THRESHOLD + 1, 3 * THRESHOLD + 5, 10 << 20, 64];
        let mut layout = Layout::from_size_align(sizes[0], 8).unwrap();
        let p = unsafe { a.alloc(layout) };
        assert!(!p.is_null());
        unsafe { fill(p, layout.size(), 7) };
        let mut p = p;
        for &s in &sizes[1..] {
            let q = unsafe { a.realloc(p, layout, s) };
            assert!(!q.is_null(), "realloc to {s}");
            let kept = layout.size().min(s);
            assert!(unsafe { holds(q, kept, 7) }, "contents lost from {} to {s} bytes", layout.size());
            layout = Layout::from_size_align(s, 8).unwrap();
            unsafe { fill(q, s, 7) };
            p = q;
        }
        unsafe { a.dealloc(p, layout) };
    }

    #[test]
    fn a_large_zeroed_block_reads_as_zeros_and_is_page_aligned() {
        let a = LargePages;
        let layout = Layout::from_size_align(THRESHOLD + 12345, 64).unwrap();
        let p = unsafe { a.alloc_zeroed(layout) };
        assert!(!p.is_null());
        assert_eq!(p as usize % PAGE, 0);
        assert!((0..layout.size()).step_by(511).all(|i| unsafe { *p.add(i) } == 0));
        unsafe { a.dealloc(p, layout) };
        // a page-aligned request is not ours (the system allocator's), and its
        // alignment holds
        for align in [PAGE, 2 * PAGE] {
            assert!(!mapped(THRESHOLD, align));
            let big = Layout::from_size_align(THRESHOLD, align).unwrap();
            let q = unsafe { a.alloc(big) };
            assert!(!q.is_null() && q as usize % align == 0);
            unsafe { a.dealloc(q, big) };
        }
        assert!(mapped(THRESHOLD, 64) && !mapped(THRESHOLD - 1, 64));
    }

    #[test]
    fn mappings_are_whole_small_pages_from_a_huge_page_boundary() {
        // half a huge page and more: a whole one; a shorter tail: small pages
        assert_eq!(mapped_len(THRESHOLD), HUGE);
        assert_eq!(mapped_len(HUGE - 1), HUGE);
        assert_eq!(mapped_len(HUGE), HUGE);
        assert_eq!(mapped_len(HUGE + 1), HUGE + PAGE);
        assert_eq!(mapped_len(HUGE + HUGE / 2), 2 * HUGE);
        assert_eq!(mapped_len(3 * HUGE + 12345), 3 * HUGE + 4 * PAGE);
        let a = LargePages;
        for size in [THRESHOLD, THRESHOLD + 1, HUGE + 1, 3 * HUGE + 12345] {
            let layout = Layout::from_size_align(size, 8).unwrap();
            let p = unsafe { a.alloc(layout) };
            assert!(!p.is_null() && p as usize % HUGE == 0, "{size} bytes at {p:?}");
            unsafe { *p.add(size - 1) = 1 };
            unsafe { a.dealloc(p, layout) };
        }
    }
}
