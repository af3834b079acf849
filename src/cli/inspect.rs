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
    /// Mesh the model (with the meshing options below, as compile does) and
    /// report counts, triangle quality, and mesh vs exact volume and area.
    #[arg(long)]
    mesh: bool,
    #[command(flatten)]
    mesh_args: super::mesh_args::MeshArgs,
    #[command(flatten)]
    input: InputOptions,
}

pub fn run(args: &Args) -> i32 {
    if super::convert::is_mesh_file(&args.file) {
        return super::convert::inspect(&args.file, args.format);
    }
    if super::rfs::is_rfs(&args.file) {
        return super::rfs::inspect(&args.file, args.format);
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
    let mesh_report = if args.mesh {
        match super::inspect_mesh::report(&checked, lowered, &args.mesh_args) {
            Ok(r) => Some(r),
            Err(code) => return code,
        }
    } else {
        None
    };
    let report = geomc::inspect::Report::of(&lowered.model);
    match args.format {
        Format::Human => {
            let mut text = report.render_text(&lowered.model, args.matrices);
            if !checked.implicit.is_empty() {
                let entries = geomc::implicit::xml::report::entries(&checked.implicit);
                text.push_str(&geomc::implicit::xml::report::render_text(&entries));
            }
            if let Some(mesh) = &mesh_report {
                text.push('\n');
                text.push_str(&mesh.render_text());
            }
            out(&text)
        }
        Format::Json => {
            let mut json = report.render_json(&lowered.model, args.matrices);
            if !checked.implicit.is_empty() {
                json = with_implicit_json(&json, &checked.implicit);
            }
            if let Some(mesh) = &mesh_report {
                json = super::inspect_mesh::with_mesh_json(&json, mesh);
            }
            out(&format!("{json}\n"))
        }
    }
    super::keep_until_exit(checked);
    EXIT_OK
}

/// The report's JSON with the implicit subdomains added (`implicit_subdomains`).
fn with_implicit_json(json: &str, implicit: &[geomc::implicit::xml::ImplicitSubdomain]) -> String {
    let entries = geomc::implicit::xml::report::entries(implicit);
    let mut value: serde_json::Value = serde_json::from_str(json).unwrap_or_default();
    if let (Some(obj), Ok(list)) = (value.as_object_mut(), serde_json::to_value(entries)) {
        obj.insert("implicit_subdomains".into(), list);
    }
    serde_json::to_string_pretty(&value).unwrap_or_default()
}
