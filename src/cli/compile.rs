//! `geomc compile INPUT… -o OUTPUT…`: validate, mesh, and write every output
//! format; several inputs compile in parallel into a folder.

use super::{EXIT_INVALID, EXIT_OK, EXIT_USAGE, InputOptions, report_usage};
use geomc::diag::render_human;
use geomc::driver::{Options, check_file};
use geomc::formats::{self, Encoding, WriteOptions};
use geomc::meshing::{MeshOptions, mesh_model};
use rayon::prelude::*;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Domain files (XML), or implicit solids in paper 001's language (.rfs).
    #[arg(required = true, value_name = "INPUT")]
    inputs: Vec<PathBuf>,
    /// Output file (format from its extension; repeatable), or a folder ending
    /// in '/' when compiling several inputs.
    #[arg(short, long = "output", required = true, value_name = "OUTPUT")]
    outputs: Vec<PathBuf>,
    /// Output format when writing into a folder (repeatable): gltf, glb, obj, stl, msh, vtu, frag.xml.
    #[arg(long = "to", value_name = "FORMAT")]
    to: Vec<String>,
    /// Chordal tolerance: a length (0.01), or a percentage of the model's
    /// bounding-box diagonal (0.1%).
    #[arg(
        long,
        default_value = "0.1%",
        value_name = "TOL",
        allow_hyphen_values = true
    )]
    tolerance: String,
    /// Longest triangle edge allowed.
    #[arg(long, value_name = "LENGTH", allow_hyphen_values = true)]
    max_edge: Option<f64>,
    /// Smallest triangle angle refinement aims for, in degrees (at most 33).
    #[arg(
        long,
        default_value_t = 25.0,
        value_name = "DEGREES",
        allow_hyphen_values = true
    )]
    min_angle: f64,
    /// Text output where the format has both (STL, MSH, VTU).
    #[arg(long, conflicts_with = "binary")]
    ascii: bool,
    /// Binary output where the format has both.
    #[arg(long)]
    binary: bool,
    /// Threads for compiling several inputs (default: all cores).
    #[arg(short = 'j', long, value_name = "N")]
    jobs: Option<usize>,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
    #[command(flatten)]
    input: InputOptions,
    #[command(flatten)]
    solver_mesh: super::solver_args::SolverMeshArgs,
    #[command(flatten)]
    budget: super::limits::Budget,
    /// Grid cells per axis for implicit (.rfs) inputs, overriding Geom.nx/ny/nz.
    #[arg(long, value_name = "N")]
    cells: Option<usize>,
    /// Also draw the mesh: a PNG (or SVG) picture, written in the same run
    /// (into a folder: one STEM.png per input when it ends in '/').
    #[arg(long, value_name = "OUT.png")]
    preview: Option<PathBuf>,
    /// Contour lines of the plane cut AXIS=VALUE (e.g. z=0) of implicit subdomains, written as line elements.
    #[arg(long, value_name = "AXIS=VALUE", allow_hyphen_values = true)]
    section: Option<String>,
}

/// What one input produced, collected so output is printed in input order.
struct Outcome {
    input: PathBuf,
    messages: String,
    ok: bool,
}

pub fn run(args: &Args) -> i32 {
    let options = match args.input.to_options() {
        Ok(o) => o,
        Err(diagnostics) => {
            report_usage(&diagnostics);
            return EXIT_INVALID;
        }
    };
    let mesh_options = match mesh_options(args) {
        Ok(m) => m,
        Err(diagnostic) => {
            report_usage(&[diagnostic]);
            return EXIT_USAGE;
        }
    };
    let section = match super::implicit::parse_section(args.section.as_deref()) {
        Ok(s) => s,
        Err(diagnostic) => {
            report_usage(&[diagnostic]);
            return EXIT_USAGE;
        }
    };
    let plans = match plan_outputs(args) {
        Ok(p) => p,
        Err(message) => {
            eprintln!("geomc: {message}");
            return EXIT_USAGE;
        }
    };
    let encoding = if args.ascii {
        Some(Encoding::Ascii)
    } else if args.binary {
        Some(Encoding::Binary)
    } else {
        None
    };
    let pool = match rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build()
    {
        Ok(pool) => pool,
        Err(e) => {
            eprintln!("geomc: cannot start threads: {e}");
            return EXIT_USAGE;
        }
    };
    let progress = (!args.quiet && args.inputs.len() > 1 && std::io::stderr().is_terminal())
        .then(|| indicatif::ProgressBar::new(args.inputs.len() as u64));
    let outcomes: Vec<Outcome> = pool.install(|| {
        plans
            .par_iter()
            .map(|(input, outputs)| {
                let preview = super::render::preview_path(args.preview.as_deref(), input);
                let outcome = compile_one(
                    input,
                    outputs,
                    &options,
                    &mesh_options,
                    encoding,
                    args.quiet,
                    args.cells,
                    preview.as_deref(),
                    &args.budget,
                    section,
                );
                if let Some(bar) = &progress {
                    bar.inc(1);
                }
                outcome
            })
            .collect()
    });
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    let failed = outcomes.iter().filter(|o| !o.ok).count();
    for outcome in &outcomes {
        eprint!("{}", outcome.messages);
    }
    if (!args.quiet && outcomes.len() > 1) || failed > 0 {
        eprintln!(
            "compiled {} of {} input{}{}",
            outcomes.len() - failed,
            outcomes.len(),
            if outcomes.len() == 1 { "" } else { "s" },
            if failed > 0 {
                format!(
                    "; failed: {}",
                    outcomes
                        .iter()
                        .filter(|o| !o.ok)
                        .map(|o| o.input.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            } else {
                String::new()
            }
        );
    }
    if failed > 0 { EXIT_INVALID } else { EXIT_OK }
}

fn mesh_options(args: &Args) -> Result<MeshOptions, geomc::diag::Diagnostic> {
    let mut options =
        super::mesh_args::parse_mesh_options(&args.tolerance, args.max_edge, args.min_angle)?;
    args.solver_mesh.apply(&mut options)?;
    Ok(options)
}

/// The output files of each input: the -o files for one input, or
/// DIR/STEM.EXT for every --to format when -o names a folder.
fn plan_outputs(args: &Args) -> Result<Vec<(PathBuf, Vec<PathBuf>)>, String> {
    let into_folder = args.outputs.len() == 1
        && (args.outputs[0].is_dir() || args.outputs[0].to_string_lossy().ends_with('/'));
    if !into_folder {
        if args.inputs.len() > 1 {
            return Err(
                "several inputs compile into a folder: give -o DIR/ and --to FORMAT".into(),
            );
        }
        for output in &args.outputs {
            if formats::writer_for_path(output).is_none() {
                return Err(format!(
                    "{}: unknown output format; use one of .gltf .glb .obj .stl .msh .vtu .frag.xml",
                    output.display()
                ));
            }
        }
        return Ok(vec![(args.inputs[0].clone(), args.outputs.clone())]);
    }
    let folder = &args.outputs[0];
    let formats: Vec<String> = if args.to.is_empty() {
        vec!["msh".to_string()]
    } else {
        args.to
            .iter()
            .map(|f| f.trim_start_matches('.').to_ascii_lowercase())
            .collect()
    };
    for f in &formats {
        if formats::writer_for_path(Path::new(&format!("x.{f}"))).is_none() {
            return Err(format!(
                "--to {f}: unknown format; use gltf, glb, obj, stl, msh, vtu or frag.xml"
            ));
        }
    }
    std::fs::create_dir_all(folder)
        .map_err(|e| format!("cannot create {}: {e}", folder.display()))?;
    Ok(args
        .inputs
        .iter()
        .map(|input| {
            let stem = input
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("model");
            (
                input.clone(),
                formats
                    .iter()
                    .map(|f| folder.join(format!("{stem}.{f}")))
                    .collect(),
            )
        })
        .collect())
}

#[allow(clippy::too_many_arguments)] // one more option per feature; a struct would be the next step
fn compile_one(
    input: &Path,
    outputs: &[PathBuf],
    options: &Options,
    mesh_options: &MeshOptions,
    encoding: Option<Encoding>,
    quiet: bool,
    cells: Option<usize>,
    preview: Option<&Path>,
    budget: &super::limits::Budget,
    section: Option<geomc::implicit::xml::mesh::Plane>,
) -> Outcome {
    if super::rfs::is_rfs(input) {
        let limits = super::rfs::RfsLimits {
            budget: *budget,
            max_file_size: options.limits.max_file_size as u64,
        };
        let (messages, ok) =
            super::rfs::compile(input, outputs, encoding, quiet, cells, &limits, section);
        return Outcome {
            input: input.to_path_buf(),
            messages,
            ok,
        };
    }
    let mut messages = String::new();
    let fail = |messages: String| Outcome {
        input: input.to_path_buf(),
        messages,
        ok: false,
    };
    let checked = match check_file(input, options) {
        Ok(c) => c,
        Err(e) => return fail(format!("geomc: cannot read {}: {e}\n", input.display())),
    };
    for d in &checked.diagnostics.items {
        if d.is_error() || !quiet {
            messages.push_str(&render_human(&checked.source, d));
        }
    }
    let Some(lowered) = checked.lowered.as_ref().filter(|_| checked.is_valid()) else {
        return fail(messages);
    };
    // Refuse a mesh too fine for the limit before meshing spends the memory.
    let estimate = super::limits::estimate_triangles(&lowered.model, mesh_options);
    if estimate > budget.max_triangles {
        let d = super::limits::too_many_triangles(estimate, budget.max_triangles, true);
        messages.push_str(&render_human(&checked.source, &d));
        return fail(messages);
    }
    let model = &lowered.model;
    // A model of implicit subdomains only has nothing for the face mesher (and
    // no bounding box for a relative tolerance).
    let implicit_only = !checked.implicit.is_empty()
        && model.vertices.is_empty()
        && model.edges.is_empty()
        && model.faces.is_empty()
        && model.point_sets.is_empty();
    let meshed = if implicit_only {
        Ok(geomc::mesh::Mesh {
            dimension: 3,
            ..Default::default()
        })
    } else {
        mesh_model(model, mesh_options)
    };
    let mut mesh = match meshed {
        Ok(mesh) => mesh,
        Err(e) => {
            let diagnostic = e.to_diagnostic(&lowered.model, &lowered.source_map);
            messages.push_str(&render_human(&checked.source, &diagnostic));
            return fail(messages);
        }
    };
    match super::implicit::add_to_mesh(
        &mut mesh,
        &checked,
        cells,
        section,
        quiet,
        budget.max_grid_cells,
    ) {
        Ok(text) => messages.push_str(&text),
        Err(text) => {
            messages.push_str(&text);
            return fail(messages);
        }
    }
    let triangles: u64 = mesh.faces.iter().map(|f| f.triangles.len() as u64).sum();
    if triangles > budget.max_triangles {
        let d = super::limits::too_many_triangles(triangles, budget.max_triangles, false);
        messages.push_str(&render_human(&checked.source, &d));
        return fail(messages);
    }
    // A fragment description refers to the MSH written beside it, if any.
    let mesh_file = outputs
        .iter()
        .find(|p| formats::writer_for_path(p).is_some_and(|w| w.name() == "msh"))
        .and_then(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned());
    let mut ok = true;
    for output in outputs {
        let write_options = WriteOptions {
            encoding,
            file_name: None,
            mesh_file: mesh_file.clone(),
        };
        match formats::write_mesh_file(output, &mesh, &write_options) {
            Ok(warnings) => {
                if !quiet {
                    for w in warnings {
                        messages.push_str(&format!("{}: warning: {w}\n", output.display()));
                    }
                    messages.push_str(&format!("wrote {}\n", output.display()));
                }
            }
            Err(e) => {
                ok = false;
                messages.push_str(&format!("geomc: {}: {e}\n", output.display()));
            }
        }
    }
    if let Some(path) = preview {
        match super::render::preview(&mesh, path) {
            Ok(text) => messages.push_str(if quiet { "" } else { &text }),
            Err(text) => {
                ok = false;
                messages.push_str(&text);
            }
        }
    }
    Outcome {
        input: input.to_path_buf(),
        messages,
        ok,
    }
}
