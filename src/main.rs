//! The `geomc` command: parse arguments, run a subcommand, exit 0 (success),
//! 1 (invalid input), 2 (usage or I/O error) or 3 (internal error).

mod cli;

// mimalloc instead of the system allocator: the front end makes millions of
// small allocations on large files, and glibc's frees (chunk consolidation)
// took a fifth of `validate`'s time on a 100,000-solid file.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    std::process::exit(cli::run());
}
