//! `geomc compile model.rfs -o out.glb`: an implicit solid written in paper
//! 001's language, polygonized on its Geom grid (or `--cells N` per axis) and
//! written in every requested format.

use super::{EXIT_INVALID, EXIT_USAGE};
use geomc::diag::{Code, Diagnostic, render_human};
use geomc::formats::{self, Encoding, WriteOptions};
use geomc::implicit::xml::mesh::{Plane, add_section};
use geomc::implicit::{lang, surface_to_mesh};
use geomc::mesh::Mesh;
use geomc::span::SourceFile;
use std::path::{Path, PathBuf};

/// The limits an `.rfs` input is held to.
#[derive(Clone, Copy, Debug)]
pub struct RfsLimits {
    pub budget: super::limits::Budget,
    pub max_file_size: u64,
}

impl Default for RfsLimits {
    fn default() -> RfsLimits {
        RfsLimits {
            budget: super::limits::Budget::default(),
            max_file_size: super::limits::MAX_FILE_SIZE,
        }
    }
}

/// Whether a path names an `.rfs` program.
pub fn is_rfs(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("rfs"))
}

/// Reads one `.rfs` program and polygonizes it: the messages to print
/// (diagnostics with line:column) and the mesh with its triangle count, or
/// the exit code (2 when the file cannot be read, 1 when the program is bad).
pub fn load(
    input: &Path,
    quiet: bool,
    cells: Option<usize>,
    limits: &RfsLimits,
) -> (String, Result<(Mesh, usize), i32>) {
    load_with_section(input, quiet, cells, limits, None)
}

/// [`load`], adding the contour lines of a `--section` plane.
pub fn load_with_section(
    input: &Path,
    quiet: bool,
    cells: Option<usize>,
    limits: &RfsLimits,
    section: Option<Plane>,
) -> (String, Result<(Mesh, usize), i32>) {
    let mut messages = String::new();
    let refuse = |d: Diagnostic| {
        let source = SourceFile::new(input.display().to_string(), "");
        (render_human(&source, &d), Err(EXIT_INVALID))
    };
    if let Err(d) = super::limits::check_file_size(input, limits.max_file_size) {
        return refuse(d);
    }
    let text = match std::fs::read(input) {
        Ok(bytes) => match String::from_utf8(bytes) {
            Ok(t) => t,
            Err(e) => {
                let at = e.utf8_error().valid_up_to();
                return refuse(
                    Diagnostic::new(
                        Code::NotUtf8,
                        None,
                        format!("the file is not UTF-8 text: byte {at} starts an invalid sequence"),
                    )
                    .with_help("save the program as UTF-8 text"),
                );
            }
        },
        Err(e) => {
            return (
                format!("geomc: cannot read {}: {e}\n", input.display()),
                Err(EXIT_USAGE),
            );
        }
    };
    let source = SourceFile::new(input.display().to_string(), text);
    let (model, diagnostics) = lang::compile(&source);
    for d in &diagnostics.items {
        if d.is_error() || !quiet {
            messages.push_str(&render_human(&source, d));
        }
    }
    let Some(model) = model.filter(|_| !diagnostics.has_errors()) else {
        return (messages, Err(EXIT_INVALID));
    };
    if let Some(n) = cells
        && !(1..=1024).contains(&n)
    {
        messages.push_str(&format!(
                "geomc: --cells {n}: give a whole number from 1 to 1024 (the grid holds (n + 1)³ samples of 8 bytes)\n"
            ));
        return (messages, Err(EXIT_USAGE));
    }
    let grid = cells.map_or(model.geom.cells, |n| [n; 3]);
    if let Err(d) = super::limits::check_grid(grid, limits.budget.max_grid_cells) {
        messages.push_str(&render_human(&source, &d));
        return (messages, Err(EXIT_INVALID));
    }
    let surface = model.polygonize(cells.map(|n| [n; 3]));
    let triangles = surface.triangles.len() as u64;
    if triangles == 0 {
        let d = Diagnostic::new(
            Code::EmptySurface,
            None,
            format!(
                "no triangles: the solid's boundary does not cross the Geom box sampled on {} x {} x {} cells",
                grid[0], grid[1], grid[2]
            ),
        )
        .with_help("check the Geom box against where the solid lies, or use more cells for thin features");
        messages.push_str(&render_human(&source, &d));
        return (messages, Err(EXIT_INVALID));
    }
    if triangles > limits.budget.max_triangles {
        let d = super::limits::too_many_triangles(triangles, limits.budget.max_triangles, false);
        messages.push_str(&render_human(&source, &d));
        return (messages, Err(EXIT_INVALID));
    }
    let mut mesh = surface_to_mesh(&surface, model.name(), model.geom.min, model.geom.max);
    if let Some(plane) = section
        && !add_section(
            &mut mesh,
            &surface.positions,
            &surface.triangles,
            model.name(),
            plane,
        )
        && !quiet
    {
        let d = Diagnostic::new(
            Code::ImplicitSectionEmpty,
            None,
            format!(
                "the section plane does not cut the surface of '{}'",
                model.name()
            ),
        )
        .with_help("move the --section plane into the solid's bounding box, or drop --section");
        messages.push_str(&render_human(&source, &d));
    }
    (messages, Ok((mesh, surface.triangles.len())))
}

/// Compiles one `.rfs` input; returns the messages to print and success.
pub fn compile(
    input: &Path,
    outputs: &[PathBuf],
    encoding: Option<Encoding>,
    quiet: bool,
    cells: Option<usize>,
    limits: &RfsLimits,
    section: Option<Plane>,
) -> (String, bool) {
    let (mut messages, loaded) = load_with_section(input, quiet, cells, limits, section);
    let Ok((mesh, triangles)) = loaded else {
        return (messages, false);
    };
    let mut ok = true;
    for output in outputs {
        let write_options = WriteOptions {
            encoding,
            file_name: None,
            mesh_file: None,
        };
        match formats::write_mesh_file(output, &mesh, &write_options) {
            Ok(warnings) => {
                if !quiet {
                    for w in warnings {
                        messages.push_str(&format!("{}: warning: {w}\n", output.display()));
                    }
                    messages.push_str(&format!(
                        "wrote {} ({} triangles)\n",
                        output.display(),
                        triangles
                    ));
                }
            }
            Err(e) => {
                ok = false;
                messages.push_str(&format!("geomc: {}: {e}\n", output.display()));
            }
        }
    }
    (messages, ok)
}

/// `geomc inspect MODEL.rfs`: the polygonized surface on the program's own
/// grid, reported as `inspect` reports a mesh file (counts, groups, bounding
/// box, watertightness), so a user can check a model before compiling it.
pub fn inspect(input: &Path, format: super::Format) -> i32 {
    let (messages, loaded) = load(input, false, None, &RfsLimits::default());
    eprint!("{messages}");
    let mesh = match loaded {
        Ok((mesh, _)) => mesh,
        Err(code) => return code,
    };
    let report = geomc::formats::read::clean::check(&mesh);
    let loaded = geomc::formats::read::Loaded {
        mesh,
        warnings: Vec::new(),
        report,
        binary: None,
    };
    let report = geomc::convert::inspect::MeshReport::of(&loaded, "rfs");
    match format {
        super::Format::Human => super::out(&report.render_text()),
        super::Format::Json => super::out(&format!("{}\n", report.render_json())),
    }
    super::EXIT_OK
}
