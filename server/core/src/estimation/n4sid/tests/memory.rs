//! Memory independent of N beyond the caller's signals, measured by a
//! per-thread counting allocator around the system allocator.
//!
//! Largest allocation: the QR work matrix (c + r) × r doubles with
//! r = 2i(m + l) and c the chunk rows (default 8r), i.e. 9r² doubles:
//! i = 8, m = l = 2 → r = 64, 295 kB; i = 10, m = l = 6 → r = 240, 4.1 MB.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use nalgebra::DVector;

use super::super::{N4sidSettings, n4sid};
use super::*;
use crate::estimation::NoProgress;

struct Counting;

thread_local! {
    static LIVE: Cell<usize> = const { Cell::new(0) };
    static PEAK: Cell<usize> = const { Cell::new(0) };
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn on_alloc(size: usize) {
    let _ = LIVE.try_with(|live| {
        let now = live.get() + size;
        live.set(now);
        let _ = PEAK.try_with(|p| p.set(p.get().max(now)));
        let _ = LARGEST.try_with(|l| l.set(l.get().max(size)));
    });
}

fn on_dealloc(size: usize) {
    let _ = LIVE.try_with(|live| live.set(live.get().saturating_sub(size)));
}

// SAFETY: forwards to System unchanged; the bookkeeping is thread-local
// const-initialized cells (no allocation, no destructor).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        on_alloc(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        on_dealloc(layout.size());
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        on_alloc(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        on_dealloc(layout.size());
        on_alloc(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static COUNTING: Counting = Counting;

/// (peak live bytes above the start, largest single allocation) of `f` on
/// this thread.
fn measure<T>(f: impl FnOnce() -> T) -> (usize, usize, T) {
    let base = LIVE.with(|l| l.get());
    PEAK.with(|p| p.set(base));
    LARGEST.with(|l| l.set(0));
    let out = f();
    (
        PEAK.with(|p| p.get()) - base,
        LARGEST.with(|l| l.get()),
        out,
    )
}

#[test]
fn memory_does_not_grow_with_the_number_of_samples() {
    let sys = truth(false);
    let set = N4sidSettings {
        horizon: 8,
        ..N4sidSettings::new(0.1)
    };
    let r = 2 * 8 * (2 + 2);
    let work = (8 * r + r) * r * 8;
    // Warm-up: the matmul backend keeps a per-thread packing buffer
    // (4 MiB) across calls; it is not per estimation.
    let (u, y) = simulate(&sys, 2_000, 1, 0.1, &DVector::zeros(4));
    let _ = n4sid(&[(&u, &y)], &set, &mut NoProgress);
    let mut seen = Vec::new();
    for n in [40_000usize, 160_000] {
        let (u, y) = simulate(&sys, n, 1, 0.1, &DVector::zeros(4));
        let signals = (u.len() + y.len()) * 8;
        let (peak, largest, model) = measure(|| n4sid(&[(&u, &y)], &set, &mut NoProgress));
        assert_eq!(model.unwrap().order, 4);
        eprintln!(
            "N {n}: signals {signals} B, peak extra {peak} B, largest {largest} B, work {work} B"
        );
        // The Gram route needs r × r; the QR route's work matrix bounds both.
        assert!(
            largest <= work,
            "largest allocation {largest} B exceeds the QR work matrix {work} B"
        );
        assert!(peak < 2 * work, "peak {peak} B vs work matrix {work} B");
        seen.push(peak);
    }
    assert_eq!(seen[0], seen[1], "peak memory must not depend on N");
}
