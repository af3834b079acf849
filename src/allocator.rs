//! Tuning of mimalloc, the allocator of the `geomc` binary and the benches.
//!
//! mimalloc 3 keeps freed pages for a second (`purge_delay` 1000 ms) before
//! it returns them to the system: `compile` frees spade's triangulation of
//! one face after another and the face meshes during assembly, all within
//! that second, so the freed memory piled up. The seven balls of paper 001
//! at tolerance 2e-5 peaked at 114–141 MB before writing anything, and at
//! 70 MB with freed pages returned at once (load average 17, two threads).

/// Returns freed pages to the system at once, unless the user set
/// `MIMALLOC_PURGE_DELAY` (mimalloc's own variable) to choose otherwise.
/// Harmless where mimalloc is not the global allocator (it then holds no
/// memory).
pub fn return_freed_memory_promptly() {
    if std::env::var_os("MIMALLOC_PURGE_DELAY").is_some() {
        return;
    }
    // SAFETY: `mi_option_set` only stores an option value; any option and
    // value are valid, at any time and from any thread.
    unsafe {
        libmimalloc_sys::mi_option_set(PURGE_DELAY, 0);
    }
}

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

/// `mi_option_purge_delay` in mimalloc's `mi_option_e` (v2 and v3 alike);
/// libmimalloc-sys 0.1.49 does not name it.
const PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

#[cfg(test)]
mod tests {
    #[test]
    fn the_purge_delay_is_set_to_zero() {
        if std::env::var_os("MIMALLOC_PURGE_DELAY").is_some() {
            return;
        }
        super::return_freed_memory_promptly();
        // SAFETY: reading an option has no preconditions.
        let delay = unsafe { libmimalloc_sys::mi_option_get(super::PURGE_DELAY) };
        assert_eq!(delay, 0);
    }
}
