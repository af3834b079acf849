//! The command line: the only code that prints, reads files for the user, and
//! decides exit codes. Each subcommand has its own file.

mod compile;
mod convert;
mod explain;
mod expr_limits;
mod implicit;
mod inspect;
mod inspect_mesh;
mod limits;
mod locate;
mod mesh_args;
mod panic_probe;
mod render;
mod rfs;
mod solver_args;
mod validate;

use clap::{Parser, Subcommand};
use geomc::diag::render_human;
use geomc::driver::Options;
use geomc::resolve::parse_override;
use geomc::syntax::Limits;
use std::io::Write;

pub const EXIT_OK: i32 = 0;
pub const EXIT_INVALID: i32 = 1;
pub const EXIT_USAGE: i32 = 2;
pub const EXIT_INTERNAL: i32 = 3;

#[derive(Parser)]
#[command(
    name = "geomc",
    version,
    about = "Compile XML descriptions of computational domains into checked topology and meshes"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Check files (or folders, recursively) and report every problem.
    Validate(validate::Args),
    /// Mesh domains and write glTF/GLB, OBJ, STL, Gmsh MSH, VTU and fragment descriptions.
    Compile(compile::Args),
    /// Summarise a model: counts, subdomains, fragments, bounding box, parameters.
    Inspect(inspect::Args),
    /// Explain a diagnostic code, e.g. `geomc explain E201`.
    Explain(explain::Args),
    /// Convert a mesh between STL, OBJ, glTF/GLB, Gmsh MSH, VTU and .frag.xml, keeping its groups.
    Convert(convert::Args),
    /// Draw a domain or mesh: a shaded PNG or a hidden-line SVG.
    Render(render::Args),
    /// Which subdomain (or the exterior) each point of a CSV file lies in.
    Locate(locate::Args),
}

/// Options shared by every subcommand that reads XML.
#[derive(clap::Args, Clone, Debug)]
pub struct InputOptions {
    /// Override a parameter: --set r=0.8 (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Largest accepted input file, in bytes.
    #[arg(long, value_name = "BYTES", default_value_t = Limits::default().max_file_size)]
    pub max_file_size: usize,
    /// Deepest accepted element nesting.
    #[arg(long, value_name = "N", default_value_t = Limits::default().max_depth)]
    pub max_depth: usize,
    /// Most XML nodes in one file.
    #[arg(long, value_name = "N", default_value_t = Limits::default().max_nodes)]
    pub max_nodes: u32,
    /// Also read data files (density volumes, .rfs) from this folder (repeatable).
    #[arg(long = "allow-path", value_name = "DIR")]
    pub allow_path: Vec<std::path::PathBuf>,
    #[command(flatten)]
    pub expressions: expr_limits::ExprLimitArgs,
}

impl InputOptions {
    /// The driver options, or the diagnostics of malformed --set options.
    pub fn to_options(&self) -> Result<Options, Vec<geomc::diag::Diagnostic>> {
        let mut overrides = Vec::new();
        let mut errors = Vec::new();
        for text in &self.set {
            match parse_override(text) {
                Ok(o) => overrides.push(o),
                Err(d) => errors.push(d),
            }
        }
        if !errors.is_empty() {
            return Err(errors);
        }
        Ok(Options {
            overrides,
            limits: Limits {
                max_file_size: self.max_file_size,
                max_depth: self.max_depth,
                max_nodes: self.max_nodes,
            },
            allowed_paths: self.allow_path.clone(),
            expressions: self.expressions.limits(),
            release_memory: Some(geomc::allocator::release_freed_memory),
        })
    }
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Format {
    #[default]
    Human,
    Json,
}

pub fn run() -> i32 {
    // A panic is a bug: say so, and exit with its own code.
    std::panic::set_hook(Box::new(|info| {
        // The mesher turns its own panics into E500 diagnostics.
        if geomc::meshing::panics_are_caught() {
            return;
        }
        eprintln!("geomc: internal error: {info}");
        eprintln!("this is a bug in geomc; please report it with the input that caused it");
    }));
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let code = if e.use_stderr() { EXIT_USAGE } else { EXIT_OK };
            let _ = e.print();
            return code;
        }
    };
    let result = std::panic::catch_unwind(|| match panic_probe::checked(cli.command) {
        Command::Validate(args) => validate::run(&args),
        Command::Compile(args) => compile::run(&args),
        Command::Inspect(args) => inspect::run(&args),
        Command::Explain(args) => explain::run(&args),
        Command::Convert(args) => convert::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Locate(args) => locate::run(&args),
    });
    result.unwrap_or(EXIT_INTERNAL)
}

/// Writes to stdout, exiting quietly when the reader has gone (a broken pipe).
pub fn out(text: &str) {
    let mut stdout = std::io::stdout().lock();
    if stdout
        .write_all(text.as_bytes())
        .and_then(|_| stdout.flush())
        .is_err()
    {
        std::process::exit(EXIT_OK);
    }
}

/// Leaves `value` to the exit instead of freeing it. The command is about to
/// exit, and the kernel takes a process's memory back at once, whereas
/// freeing a checked file of many primitives entity by entity (names, loops,
/// lists) was about 4% of `geomc validate`'s instructions. Only for what a
/// command holds at its end: the library (`geomc::driver`) still frees
/// everything, and a command looping over files frees all but the last.
pub fn keep_until_exit<T>(value: T) {
    std::mem::forget(value);
}

/// Diagnostics of the command line itself (malformed --set).
pub fn report_usage(diagnostics: &[geomc::diag::Diagnostic]) {
    let source = geomc::span::SourceFile::new("geomc", "");
    for d in diagnostics {
        eprint!("{}", render_human(&source, d));
    }
}

/// The process's peak resident memory (Linux: VmHWM in /proc/self/status).
pub fn peak_memory() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kilobytes: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kilobytes * 1024)
}
