//! `geomc validate PATH…`: every problem of every file, as text or JSON.

use super::{EXIT_INVALID, EXIT_OK, EXIT_USAGE, Format, InputOptions, out, report_usage};
use geomc::diag::{Severity, render_human, render_json};
use geomc::driver::check_file;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Files or folders (searched recursively for *.xml).
    #[arg(required = true, value_name = "PATH")]
    paths: Vec<PathBuf>,
    /// Output format: human (with source snippets) or json (an array of diagnostics).
    #[arg(long, value_enum, default_value_t = Format::Human)]
    format: Format,
    /// Treat warnings as errors.
    #[arg(long)]
    deny_warnings: bool,
    /// Print the time taken and the peak memory to stderr.
    #[arg(long)]
    stats: bool,
    #[command(flatten)]
    input: InputOptions,
}

pub fn run(args: &Args) -> i32 {
    let started = std::time::Instant::now();
    let code = validate(args);
    if args.stats {
        eprintln!("time: {:.3} s", started.elapsed().as_secs_f64());
        if let Some(bytes) = super::peak_memory() {
            eprintln!("peak memory: {bytes} bytes");
        }
    }
    code
}

fn validate(args: &Args) -> i32 {
    let options = match args.input.to_options() {
        Ok(o) => o,
        Err(diagnostics) => {
            if args.format == Format::Json {
                let source = geomc::span::SourceFile::new("<command line>", "");
                let json: Vec<_> = diagnostics
                    .iter()
                    .map(|d| render_json(&source, d))
                    .collect();
                out(&format!(
                    "{}\n",
                    serde_json::to_string_pretty(&json).unwrap_or_default()
                ));
            } else {
                report_usage(&diagnostics);
            }
            return EXIT_INVALID;
        }
    };
    let mut files = Vec::new();
    for path in &args.paths {
        if let Err(e) = collect(path, &mut files) {
            eprintln!("geomc: cannot read {}: {e}", path.display());
            return EXIT_USAGE;
        }
    }
    let mut json = Vec::new();
    let (mut errors, mut warnings, mut invalid_files) = (0, 0, 0);
    let mut io_failed = false;
    for (k, file) in files.iter().enumerate() {
        let checked = match check_file(file, &options) {
            Ok(c) => c,
            Err(e) => {
                eprintln!("geomc: cannot read {}: {e}", file.display());
                io_failed = true;
                continue;
            }
        };
        let mut file_failed = false;
        for d in &checked.diagnostics.items {
            let mut d = d.clone();
            if args.deny_warnings && d.severity == Severity::Warning {
                d.severity = Severity::Error;
            }
            match d.severity {
                Severity::Error => {
                    errors += 1;
                    file_failed = true;
                }
                Severity::Warning => warnings += 1,
            }
            match args.format {
                Format::Human => eprint!("{}", render_human(&checked.source, &d)),
                Format::Json => json.push(render_json(&checked.source, &d)),
            }
        }
        invalid_files += usize::from(file_failed);
        if k + 1 == files.len() {
            super::keep_until_exit(checked);
        }
    }
    match args.format {
        Format::Json => out(&format!(
            "{}\n",
            serde_json::to_string_pretty(&json).unwrap_or_default()
        )),
        Format::Human => eprintln!(
            "checked {} file{}: {} invalid, {errors} error{}, {warnings} warning{}",
            files.len(),
            plural(files.len()),
            invalid_files,
            plural(errors),
            plural(warnings)
        ),
    }
    if io_failed {
        EXIT_USAGE
    } else if invalid_files > 0 {
        EXIT_INVALID
    } else {
        EXIT_OK
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

/// A file as given, or every *.xml below a folder, sorted.
fn collect(path: &Path, files: &mut Vec<PathBuf>) -> std::io::Result<()> {
    let metadata = std::fs::metadata(path)?;
    if !metadata.is_dir() {
        files.push(path.to_path_buf());
        return Ok(());
    }
    let mut entries: Vec<PathBuf> = std::fs::read_dir(path)?
        .map(|e| e.map(|e| e.path()))
        .collect::<Result<_, _>>()?;
    entries.sort();
    for entry in entries {
        if entry.is_dir() {
            collect(&entry, files)?;
        } else if entry.extension().is_some_and(|e| e == "xml") {
            files.push(entry);
        }
    }
    Ok(())
}
