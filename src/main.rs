//! The `geomc` command: parse arguments, run a subcommand, exit 0 (success),
//! 1 (invalid input), 2 (usage or I/O error) or 3 (internal error).

mod cli;

fn main() {
    std::process::exit(cli::run());
}
