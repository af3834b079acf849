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
