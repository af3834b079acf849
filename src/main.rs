//! The `geomc` command: parse arguments, run a subcommand, exit 0 (success),
//! 1 (invalid input), 2 (usage or I/O error) or 3 (internal error).

mod cli;

// mimalloc instead of the system allocator: the front end makes millions of
// small allocations on large files, and glibc's frees (chunk consolidation)
// took a fifth of `validate`'s time on a 100,000-solid file. Built without
// transparent huge pages (`no_thp`): zeroing 2 MB pages for memory touched once
// was a sixth of `compile`'s CPU and raised its peak by a fifth.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

unsafe extern "C" {
    /// mimalloc's own collection (always in the linked library; the `mimalloc`
    /// crate exposes it only with a feature that needs another crate).
    safe fn mi_collect(force: bool);
}

/// Gives freed memory back to the system at once. mimalloc keeps freed pages
/// for `purge_delay` (1 s) first, so on a large file the pages of the syntax
/// tree and the document were still resident when the model reached its peak
/// (a fifth of the peak of `validate` on a 100,000-solid file). Called by the
/// driver between stages, so a few times a run rather than at every free.
pub(crate) fn release_freed_memory() {
    mi_collect(true);
}

fn main() {
    let code = cli::run();
    // Any subcommand: `GEOMC_STATS=1` prints the peak memory, so tests can
    // bound it for compile and convert too (`validate --stats` prints time as well).
    if std::env::var_os("GEOMC_STATS").is_some()
        && let Some(bytes) = cli::peak_memory()
    {
        eprintln!("peak memory: {bytes} bytes");
    }
    std::process::exit(code);
}
