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

fn main() {
    let code = cli::run();
    // Any subcommand: `GEOMC_STATS=1` prints the peak memory, so tests can
    // bound it for compile and convert too (`validate --stats` prints time as well).
    if std::env::var_os("GEOMC_STATS").is_some()
        && let Some(bytes) = cli::peak_memory()
    {
        eprintln!("peak memory: {bytes} bytes");
    }
    geomc::allocator::skip_purge_at_exit();
    std::process::exit(code);
}
