//! `geomc render INPUT -o OUT.png|OUT.svg`: a picture of a domain (compiled
//! on the fly) or of a mesh, and the `--preview` picture of `geomc compile`.

use super::{EXIT_INVALID, EXIT_OK, EXIT_USAGE, InputOptions, report_usage};
use geomc::diag::{Code, Diagnostic, render_human};
use geomc::driver::check_file;
use geomc::formats::read::{ReadLimits, load_mesh_limited};
use geomc::formats::{WriteError, write_atomic};
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, Tolerance, mesh_model};
use geomc::render::{self, ColorBy, Edges, RenderOptions, Section, Shading, View};
use geomc::span::SourceFile;
use std::path::{Path, PathBuf};

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum ShadingArg {
    Flat,
    Smooth,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum ColorByArg {
    Auto,
    Fragment,
    Subdomain,
    Face,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum EdgesArg {
    None,
    Feature,
    All,
}

#[derive(clap::Args)]
pub struct Args {
    /// A domain file (.xml, compiled on the fly) or a mesh file (.stl .obj .gltf .glb .msh .vtu .frag.xml).
    #[arg(value_name = "INPUT")]
    input: PathBuf,
    /// The picture: .png (shaded raster) or .svg (hidden-line drawing).
    #[arg(short, long = "output", value_name = "OUTPUT")]
    output: PathBuf,
    /// Picture size in pixels.
    #[arg(long, default_value = "800x600", value_name = "WxH")]
    size: String,
    /// front, top, iso, or AZIMUTH,ELEVATION in degrees.
    #[arg(long, default_value = "iso", value_name = "VIEW")]
    view: String,
    #[arg(long, value_enum, default_value = "smooth")]
    shading: ShadingArg,
    /// What gets one colour (auto: fragments, else subdomains, else faces).
    #[arg(long, value_enum, default_value = "auto")]
    color_by: ColorByArg,
    /// Leave the legend out.
    #[arg(long)]
    no_legend: bool,
    /// Edges drawn over the PNG (default none) or as the SVG's lines (default feature: model edges and silhouettes).
    #[arg(long, value_enum)]
    edges: Option<EdgesArg>,
    /// Samples per pixel along each axis, 1 to 4 (1: no anti-aliasing).
    #[arg(long, default_value_t = 2, value_name = "N")]
    antialias: u32,
    /// white, black, transparent, or #rrggbb.
    #[arg(long, default_value = "white", value_name = "COLOR")]
    background: String,
    /// Cut the model at a plane, AXIS=VALUE (e.g. z=0), removing the part above it.
    #[arg(long, value_name = "AXIS=VALUE")]
    section: Option<String>,
    /// Chordal tolerance when compiling a domain: a length or a percentage of its size.
    #[arg(long, default_value = "0.1%", value_name = "TOL")]
    tolerance: String,
    /// Threads (default: all cores); the picture is the same for any number.
    #[arg(short = 'j', long, value_name = "N")]
    jobs: Option<usize>,
    /// Print nothing but errors.
    #[arg(short, long)]
    quiet: bool,
    #[command(flatten)]
    input_options: InputOptions,
    #[command(flatten)]
    budget: super::limits::Budget,
    /// Most glTF accessor elements decoded (shared accessors count per use).
    #[arg(long, value_name = "N", default_value_t = geomc::formats::read::MAX_ELEMENTS)]
    max_mesh_elements: u64,
}

/// What an input may cost before it is drawn (issue 10).
struct InputLimits {
    read: ReadLimits,
    budget: super::limits::Budget,
}

/// A failure with its code, printed as `geomc: error[E72x]: …`.
struct Failure {
    code: Code,
    message: String,
    exit: i32,
}

fn report(failure: &Failure) {
    report_usage(&[Diagnostic::new(failure.code, None, failure.message.clone())]);
}

fn render_options(args: &Args) -> Result<RenderOptions, render::RenderError> {
    let (width, height) = render::parse_size(&args.size)?;
    Ok(RenderOptions {
        width,
        height,
        view: View::parse(&args.view)?,
        shading: match args.shading {
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Smooth => Shading::Smooth,
        },
        color_by: match args.color_by {
            ColorByArg::Auto => ColorBy::Auto,
            ColorByArg::Fragment => ColorBy::Fragment,
            ColorByArg::Subdomain => ColorBy::Subdomain,
            ColorByArg::Face => ColorBy::Face,
        },
        legend: !args.no_legend,
        edges: match args.edges {
            None | Some(EdgesArg::None) => Edges::None,
            Some(EdgesArg::Feature) => Edges::Feature,
            Some(EdgesArg::All) => Edges::All,
        },
        antialias: args.antialias,
        background: render::parse_background(&args.background)?,
        section: args.section.as_deref().map(Section::parse).transpose()?,
    })
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Png,
    Svg,
}

fn output_kind(path: &Path) -> Option<Kind> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "png" => Some(Kind::Png),
        "svg" => Some(Kind::Svg),
        _ => None,
    }
}

pub fn run(args: &Args) -> i32 {
    let usage = |code: Code, message: String| {
        report(&Failure {
            code,
            message,
            exit: EXIT_USAGE,
        });
        EXIT_USAGE
    };
    let options = match render_options(args) {
        Ok(o) => o,
        Err(e) => return usage(e.code(), e.to_string()),
    };
    let Some(kind) = output_kind(&args.output) else {
        return usage(
            Code::RenderBadOutput,
            format!(
                "{}: unknown picture format; name the output .png or .svg",
                args.output.display()
            ),
        );
    };
    let driver_options = match args.input_options.to_options() {
        Ok(o) => o,
        Err(diagnostics) => {
            report_usage(&diagnostics);
            return EXIT_INVALID;
        }
    };
    let Some(tolerance) = parse_tolerance(&args.tolerance) else {
        eprintln!(
            "geomc: --tolerance {}: give a positive length (0.01) or a percentage of the model's size (0.1%)",
            args.tolerance
        );
        return EXIT_USAGE;
    };
    let mesh_options = MeshOptions {
        tolerance,
        ..MeshOptions::default()
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
    pool.install(|| {
        let limits = InputLimits {
            read: ReadLimits {
                max_file_size: args.input_options.max_file_size as u64,
                max_elements: args.max_mesh_elements,
            },
            budget: args.budget,
        };
        let loaded = load_input(
            &args.input,
            &driver_options,
            &mesh_options,
            &limits,
            args.quiet,
        );
        let mesh = match loaded {
            Ok(mesh) => mesh,
            Err(exit) => return exit,
        };
        match write_picture(&mesh, &args.output, kind, &options, args.quiet) {
            Ok(()) => EXIT_OK,
            Err(f) => {
                report(&f);
                f.exit
            }
        }
    })
}

fn parse_tolerance(text: &str) -> Option<Tolerance> {
    let text = text.trim();
    match text.strip_suffix('%') {
        Some(p) => p
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .map(|v| Tolerance::Relative(v / 100.0)),
        None => text
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .map(Tolerance::Absolute),
    }
}

/// Reads any input geomc can draw, or prints why not and gives the exit code.
fn load_input(
    path: &Path,
    options: &geomc::driver::Options,
    mesh_options: &MeshOptions,
    limits: &InputLimits,
    quiet: bool,
) -> Result<Mesh, i32> {
    let fail = |f: Failure| {
        report(&f);
        f.exit
    };
    let refuse = |d: Diagnostic| {
        report_usage(&[d]);
        EXIT_INVALID
    };
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if name.ends_with(".rfs") {
        let rfs_limits = super::rfs::RfsLimits {
            budget: limits.budget,
            max_file_size: limits.read.max_file_size,
        };
        let (messages, loaded) = super::rfs::load(path, quiet, None, &rfs_limits);
        eprint!("{messages}");
        return loaded.map(|(mesh, _)| mesh);
    }
    if !name.ends_with(".xml") || name.ends_with(".frag.xml") {
        super::limits::check_file_size(path, limits.read.max_file_size).map_err(refuse)?;
        let mesh = load_mesh_file(path, &limits.read, quiet)?;
        // The file was read within its limits; drawing it is bounded too.
        let triangles: u64 = mesh.faces.iter().map(|f| f.triangles.len() as u64).sum();
        if triangles > limits.budget.max_triangles {
            let d =
                super::limits::too_many_triangles(triangles, limits.budget.max_triangles, false);
            return Err(refuse(
                d.with_help("raise the limit with --max-triangles N"),
            ));
        }
        return Ok(mesh);
    }
    let checked = match check_file(path, options) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("geomc: cannot read {}: {e}", path.display());
            return Err(EXIT_USAGE);
        }
    };
    for d in &checked.diagnostics.items {
        if d.is_error() || !quiet {
            eprint!("{}", render_human(&checked.source, d));
        }
    }
    let Some(lowered) = checked.lowered.as_ref().filter(|_| checked.is_valid()) else {
        return Err(EXIT_INVALID);
    };
    let model = &lowered.model;
    // Refused before meshing spends the memory, then counted, as compile does.
    let max = limits.budget.max_triangles;
    let estimate = super::limits::estimate_triangles(model, mesh_options);
    if estimate > max {
        let d = super::limits::too_many_triangles(estimate, max, true);
        eprint!("{}", render_human(&checked.source, &d));
        return Err(EXIT_INVALID);
    }
    // A model of implicit subdomains only has nothing for the face mesher.
    let implicit_only = !checked.implicit.is_empty()
        && model.vertices.is_empty()
        && model.edges.is_empty()
        && model.faces.is_empty()
        && model.point_sets.is_empty();
    let meshed = if implicit_only {
        Ok(Mesh {
            dimension: 3,
            ..Default::default()
        })
    } else {
        mesh_model(model, mesh_options)
    };
    let mut mesh = meshed.map_err(|e| {
        fail(Failure {
            code: Code::RenderInputFailed,
            message: format!("{}: {e}", path.display()),
            exit: EXIT_INVALID,
        })
    })?;
    // Implicit subdomains are not in the model: polygonized as compile does,
    // within the user's --max-grid-cells.
    let limit = limits.budget.max_grid_cells;
    if let Err(messages) =
        super::implicit::add_to_mesh(&mut mesh, &checked, None, None, true, limit)
    {
        eprint!("{messages}");
        return Err(EXIT_INVALID);
    }
    let triangles: u64 = mesh.faces.iter().map(|f| f.triangles.len() as u64).sum();
    if triangles > max {
        let d = super::limits::too_many_triangles(triangles, max, false);
        eprint!("{}", render_human(&checked.source, &d));
        return Err(EXIT_INVALID);
    }
    Ok(mesh)
}

/// A mesh file in any format geomc reads (its own codes on failure).
fn load_mesh_file(path: &Path, limits: &ReadLimits, quiet: bool) -> Result<Mesh, i32> {
    match load_mesh_limited(path, None, limits) {
        Ok(loaded) => {
            if !quiet {
                let source = SourceFile::new(path.display().to_string(), "");
                for d in &loaded.warnings {
                    eprint!("{}", render_human(&source, d));
                }
            }
            Ok(loaded.mesh)
        }
        Err(diagnostics) => {
            // Positions in a text mesh need its text to show the line.
            let text = std::fs::read(path)
                .map(|b| String::from_utf8_lossy(&b).into_owned())
                .unwrap_or_default();
            let source = SourceFile::new(path.display().to_string(), text);
            for d in &diagnostics {
                eprint!("{}", render_human(&source, d));
            }
            Err(
                if diagnostics.iter().any(|d| d.code == Code::MeshReadFailed) {
                    EXIT_USAGE
                } else {
                    EXIT_INVALID
                },
            )
        }
    }
}

fn write_picture(
    mesh: &Mesh,
    output: &Path,
    kind: Kind,
    options: &RenderOptions,
    quiet: bool,
) -> Result<(), Failure> {
    let failed = |e: render::RenderError| Failure {
        code: e.code(),
        message: e.to_string(),
        exit: EXIT_INVALID,
    };
    let (bytes, warnings) = match kind {
        Kind::Png => render::render_png(mesh, options).map_err(failed)?,
        Kind::Svg => {
            let drawing = render::render_svg(mesh, options).map_err(failed)?;
            (drawing.text.into_bytes(), drawing.warnings)
        }
    };
    if !quiet {
        for w in &warnings {
            report_usage(&[Diagnostic::new(w.code, None, w.message.clone())]);
        }
    }
    write_atomic(output, |w| Ok::<(), WriteError>(w.write_all(&bytes)?)).map_err(|e| Failure {
        code: Code::RenderBadOutput,
        message: format!("{}: {e}", output.display()),
        exit: EXIT_USAGE,
    })?;
    if !quiet {
        eprintln!("wrote {}", output.display());
    }
    Ok(())
}

/// `geomc compile --preview OUT.png`: a default picture of a compiled mesh.
/// Returns the lines to print (warnings, "wrote …") or the error line.
pub fn preview(mesh: &Mesh, output: &Path) -> Result<String, String> {
    let kind = output_kind(output).ok_or_else(|| {
        format!(
            "geomc: error[{}]: {}: --preview writes a .png or .svg\n",
            Code::RenderBadOutput.as_str(),
            output.display()
        )
    })?;
    let options = RenderOptions::default();
    let (bytes, warnings) = match kind {
        Kind::Png => render::render_png(mesh, &options),
        Kind::Svg => render::render_svg(mesh, &options).map(|d| (d.text.into_bytes(), d.warnings)),
    }
    .map_err(|e| {
        format!(
            "geomc: error[{}]: {}: {e}\n",
            e.code().as_str(),
            output.display()
        )
    })?;
    write_atomic(output, |w| Ok::<(), WriteError>(w.write_all(&bytes)?))
        .map_err(|e| format!("geomc: {}: {e}\n", output.display()))?;
    let mut text = String::new();
    for w in warnings {
        text.push_str(&format!(
            "{}: warning[{}]: {}\n",
            output.display(),
            w.code.as_str(),
            w.message
        ));
    }
    text.push_str(&format!("wrote {}\n", output.display()));
    Ok(text)
}

/// Where `--preview` writes for one input: the path itself, or FOLDER/STEM.png
/// when it names a folder (ends in '/' or exists as one).
pub fn preview_path(preview: Option<&Path>, input: &Path) -> Option<PathBuf> {
    let preview = preview?;
    if preview.is_dir() || preview.to_string_lossy().ends_with('/') {
        let stem = input
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("model");
        Some(preview.join(format!("{stem}.png")))
    } else {
        Some(preview.to_path_buf())
    }
}
