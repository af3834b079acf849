//! `geomc inspect FILE`: the model's facts as text or JSON.

use super::{EXIT_INVALID, EXIT_OK, EXIT_USAGE, Format, InputOptions, out, report_usage};
use geomc::diag::render_human;
use geomc::driver::check_file;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    file: PathBuf,
    /// Output format: human text or json.
    #[arg(long, value_enum, default_value_t = Format::Human)]
    format: Format,
    /// Print the incidence matrices M_VE, M_EF, M_FD and the derived V–F, E–D.
    #[arg(long)]
    matrices: bool,
    #[command(flatten)]
    input: InputOptions,
    #[command(flatten)]
    mesh_quality: super::mesh_args::InspectMeshArgs,
}

pub fn run(args: &Args) -> i32 {
    if super::convert::is_mesh_file(&args.file) {
        return super::convert::inspect(&args.file, args.format);
    }
    let options = match args.input.to_options() {
        Ok(o) => o,
        Err(diagnostics) => {
            report_usage(&diagnostics);
            return EXIT_INVALID;
        }
    };
    let checked = match check_file(&args.file, &options) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("geomc: cannot read {}: {e}", args.file.display());
            return EXIT_USAGE;
        }
    };
    for d in &checked.diagnostics.items {
        eprint!("{}", render_human(&checked.source, d));
    }
    let Some(lowered) = checked.lowered.as_ref().filter(|_| checked.is_valid()) else {
        eprintln!(
            "geomc: {} is invalid; fix the errors above to inspect it",
            args.file.display()
        );
        return EXIT_INVALID;
    };
    let report = geomc::inspect::Report::of(&lowered.model);
    // --mesh: the mesh-quality section after the model's facts (JSON: both
    // in one object, {"model": …, "mesh": …}).
    let mesh_section = if args.mesh_quality.mesh {
        match args.mesh_quality.report(&lowered.model) {
            Ok(r) => Some(r),
            Err(code) => return code,
        }
    } else {
        None
    };
    match (args.format, mesh_section) {
        (Format::Human, section) => {
            out(&report.render_text(&lowered.model, args.matrices));
            if let Some(r) = section {
                out(&r.render_text());
            }
        }
        (Format::Json, None) => out(&format!(
            "{}\n",
            report.render_json(&lowered.model, args.matrices)
        )),
        (Format::Json, Some(r)) => out(&format!(
            "{{\"model\": {}, \"mesh\": {}}}\n",
            report.render_json(&lowered.model, args.matrices),
            serde_json::to_string_pretty(&r).unwrap_or_default()
        )),
    }
    EXIT_OK
}
