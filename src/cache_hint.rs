//! A cache hint for loops whose next loads are known ahead but depend on
//! data (a triangle's corners, a hashed node slot): fetching them early hides
//! the memory latency that the hardware prefetcher cannot predict.

/// Asks for the cache line of `value` without waiting for it (a hint: it
/// reads nothing; nothing at all off x86-64).
#[inline(always)]
pub(crate) fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: a prefetch reads nothing (it is only a hint, and the
        // pointer comes from a reference), and SSE is part of every x86-64.
        unsafe { _mm_prefetch::<_MM_HINT_T0>((value as *const T).cast()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

/// [`prefetch`] of an address that need not be a valid reference (a slice's
/// base plus an index not checked against its length): a prefetch of any
/// address is harmless, so a hint needs no bounds check.
#[inline(always)]
pub(crate) fn prefetch_at<T>(address: *const T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: a prefetch reads nothing and cannot fault, whatever the
        // address; SSE is part of every x86-64.
        unsafe { _mm_prefetch::<_MM_HINT_T0>(address.cast()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = address;
}
