//! A deliberate panic for the test that proves any panic ends as
//! `geomc: internal error: …`, a request to report it, and exit code 3
//! (`tests/internal_error.rs`). Only debug builds read the variable: a release
//! binary cannot be made to panic on purpose.

/// Set (to anything) in a debug build, every subcommand panics before it starts.
pub const VARIABLE: &str = "GEOMC_DEBUG_PANIC";

/// The command, unless a debug build was asked to panic instead.
pub fn checked<T>(command: T) -> T {
    if cfg!(debug_assertions) && std::env::var_os(VARIABLE).is_some() {
        panic!("deliberate panic requested by {VARIABLE} (debug builds only)");
    }
    command
}
