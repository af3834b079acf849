//! `geomc locate INPUT --points FILE.csv`: the subdomain (or `exterior`)
//! holding each point, as CSV. The model is meshed as `compile` would mesh
//! it (same tolerance options) and the points are located in that mesh
//! (`geomc::mesh::locate`).

use super::mesh_args::MeshArgs;
use super::{EXIT_INVALID, EXIT_OK, EXIT_USAGE, InputOptions, out, report_usage};
use geomc::diag::{Code, Diagnostic, render_human};
use geomc::driver::check_file;
use geomc::formats::write_atomic;
use geomc::mesh::locate::Locator;
use geomc::meshing::mesh_model;
use geomc::span::{SourceFile, Span};
use rayon::prelude::*;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// Domain file (XML).
    input: PathBuf,
    /// Points, one per row: x,y,z (or x,y in 2D); a header row is allowed.
    #[arg(long, value_name = "FILE.csv")]
    points: PathBuf,
    /// Write the CSV here instead of to standard output.
    #[arg(short, long = "output", value_name = "OUT.csv")]
    output: Option<PathBuf>,
    #[command(flatten)]
    mesh_args: MeshArgs,
    #[command(flatten)]
    input_options: InputOptions,
}

pub fn run(args: &Args) -> i32 {
    let options = match args.input_options.to_options() {
        Ok(o) => o,
        Err(diagnostics) => {
            report_usage(&diagnostics);
            return EXIT_INVALID;
        }
    };
    let mesh_options = match args.mesh_args.to_options() {
        Ok(o) => o,
        Err(d) => {
            report_usage(&[d]);
            return EXIT_USAGE;
        }
    };
    let text = match std::fs::read_to_string(&args.points) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("geomc: cannot read {}: {e}", args.points.display());
            return EXIT_USAGE;
        }
    };
    let source = SourceFile::new(args.points.display().to_string(), text);
    let points = match parse_points(&source) {
        Ok(p) => p,
        Err(diagnostics) => {
            for d in &diagnostics {
                eprint!("{}", render_human(&source, d));
            }
            return EXIT_INVALID;
        }
    };
    let checked = match check_file(&args.input, &options) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("geomc: cannot read {}: {e}", args.input.display());
            return EXIT_USAGE;
        }
    };
    for d in &checked.diagnostics.items {
        eprint!("{}", render_human(&checked.source, d));
    }
    let Some(lowered) = checked.lowered.as_ref().filter(|_| checked.is_valid()) else {
        eprintln!(
            "geomc: {} is invalid; fix the errors above to locate points in it",
            args.input.display()
        );
        return EXIT_INVALID;
    };
    let mesh = match mesh_model(&lowered.model, &mesh_options) {
        Ok(m) => m,
        Err(e) => {
            let d = e.to_diagnostic(&lowered.model, &lowered.source_map);
            eprint!("{}", render_human(&checked.source, &d));
            return EXIT_INVALID;
        }
    };
    let locator = Locator::new(&mesh);
    // Rows located in parallel, collected in input order.
    let rows: Vec<String> = points
        .par_iter()
        .map(|p| {
            let name = locator
                .locate(*p)
                .and_then(|s| mesh.subdomains.get(s as usize))
                .map_or("exterior", |s| s.name.as_str());
            format!("{},{},{},{}\n", p[0], p[1], p[2], csv_field(name))
        })
        .collect();
    let mut csv = String::from("x,y,z,subdomain\n");
    for row in rows {
        csv.push_str(&row);
    }
    match &args.output {
        None => out(&csv),
        Some(path) => {
            if let Err(e) = write_atomic(path, |w| Ok(w.write_all(csv.as_bytes())?)) {
                eprintln!("geomc: cannot write {}: {e}", path.display());
                return EXIT_USAGE;
            }
        }
    }
    EXIT_OK
}

/// A CSV field, quoted when it holds a comma, quote or line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The points of a CSV file: rows of 2 or 3 numbers separated by commas or
/// whitespace (z = 0 when absent); a first row that is not numbers is a
/// header; empty rows and `#` comments are skipped. Every bad row is an E504
/// at its line and column.
pub fn parse_points(source: &SourceFile) -> Result<Vec<[f64; 3]>, Vec<Diagnostic>> {
    let mut points = Vec::new();
    let mut errors = Vec::new();
    let mut first_row = true;
    let mut offset = 0;
    for line in source.text.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        let row = line.trim_end_matches(['\n', '\r']);
        if row.trim().is_empty() || row.trim_start().starts_with('#') {
            continue;
        }
        let header = std::mem::replace(&mut first_row, false);
        let fields = fields(row);
        let values: Vec<Result<f64, (usize, &str)>> = fields
            .iter()
            .map(|&(at, text)| {
                text.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or((at, text))
            })
            .collect();
        if header && values.iter().all(Result::is_err) {
            continue;
        }
        if let Some(&Err((at, text))) = values.iter().find(|v| v.is_err()) {
            errors.push(
                Diagnostic::new(
                    Code::LocateBadPoint,
                    Span::new(start + at, start + at + text.len()),
                    format!("`{text}` is not a finite number"),
                )
                .with_help("write each point as x,y,z with plain numbers (1.5, -2e-3)"),
            );
            continue;
        }
        let numbers: Vec<f64> = values.into_iter().flatten().collect();
        match numbers[..] {
            [x, y] => points.push([x, y, 0.0]),
            [x, y, z] => points.push([x, y, z]),
            _ => errors.push(
                Diagnostic::new(
                    Code::LocateBadPoint,
                    Span::new(start, start + row.len()),
                    format!("a row holds {} values; a point has 2 or 3", numbers.len()),
                )
                .with_help("write one point per row as x,y,z (or x,y)"),
            ),
        }
    }
    if errors.is_empty() {
        Ok(points)
    } else {
        Err(errors)
    }
}

/// The non-empty fields of a row with their byte offsets in it.
fn fields(row: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut begin = None;
    for (i, c) in row.char_indices().chain([(row.len(), ',')]) {
        let separator = c == ',' || c.is_whitespace();
        match (separator, begin) {
            (true, Some(b)) => {
                out.push((b, &row[b..i]));
                begin = None;
            }
            (false, None) => begin = Some(i),
            _ => {}
        }
    }
    out
}
