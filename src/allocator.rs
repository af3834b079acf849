//! Tuning of mimalloc, the allocator of the `geomc` binary and the benches.
//!
//! mimalloc 3 keeps freed pages for a second (`purge_delay` 1000 ms) before
//! it returns them to the system: `compile` frees spade's triangulation of
//! one face after another and the face meshes during assembly, all within
//! that second, so the freed memory piled up. The seven balls of paper 001
//! at tolerance 2e-5 peaked at 114–141 MB before writing anything, and at
//! 70 MB with freed pages returned at once (load average 17, two threads).
//! Returning them at every free (purge delay 0) cost the binary writers
//! two thirds of their speed (GLB 976 → 369 MB/s into memory), so instead
//! the stages that free much collect at their end.

/// Returns the pages freed so far to the system now (mimalloc's forced
/// collection), at the end of a phase that freed much (a face's
/// triangulation, the face meshes after assembly): the same effect on the
/// peak as a zero purge delay, without purging on every free.
pub fn release_freed_memory() {
    // SAFETY: `mi_collect` may be called at any time from any thread; it
    // only frees memory no live allocation uses.
    unsafe {
        libmimalloc_sys::mi_collect(true);
    }
}

/// Called just before the process exits: mimalloc's exit handler collects
/// its heaps with a forced purge, a `madvise` for every freed range (5–6% of
/// the CPU time of a 2-million-triangle `convert` in `perf`), for memory the
/// kernel takes back at exit anyway. A negative purge delay turns purging
/// off, so that collection only walks the heaps.
pub fn skip_purge_at_exit() {
    // SAFETY: setting an option is allowed at any time from any thread; a
    // negative delay only stops freed pages from being returned early.
    unsafe {
        libmimalloc_sys::mi_option_set(PURGE_DELAY, -1);
    }
}

/// `mi_option_purge_delay` in mimalloc's `mi_option_e` (v2 and v3 alike);
/// libmimalloc-sys names no constant for it.
const PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// `n` copies of `value` in a vector whose pages are first touched by
/// writing them. A vector that is read before it is written (sums, counts)
/// should start this way: `vec![0; n]` takes fresh pages the system zeroed,
/// whose first touch as a read maps the shared zero page and the write after
/// it faults again (a copy and a TLB flush on every core the process runs
/// on): two faults per page instead of one.
pub fn filled_vec<T: Clone>(n: usize, value: T) -> Vec<T> {
    let mut v = Vec::with_capacity(n);
    // Without this the compiler may fold the fill below back into a zeroed
    // allocation (an allocation followed by zeroing is one to it).
    std::hint::black_box(&mut v);
    v.resize(n, value);
    v
}
