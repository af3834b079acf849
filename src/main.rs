//! The `geomc` command: parse arguments, run a subcommand, exit 0 (success),
//! 1 (invalid input), 2 (usage or I/O error) or 3 (internal error).

mod cli;

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
