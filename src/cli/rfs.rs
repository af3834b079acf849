//! `geomc compile model.rfs -o out.glb`: an implicit solid written in paper
//! 001's language, polygonized on its Geom grid (or `--cells N` per axis) and
//! written in every requested format.

use super::{EXIT_INVALID, EXIT_USAGE};
use geomc::diag::render_human;
use geomc::formats::{self, Encoding, WriteOptions};
use geomc::implicit::xml::mesh::{Plane, add_section};
use geomc::implicit::{lang, surface_to_mesh};
use geomc::mesh::Mesh;
use geomc::span::SourceFile;
use std::path::{Path, PathBuf};

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
) -> (String, Result<(Mesh, usize), i32>) {
    load_with_section(input, quiet, cells, None)
}

/// [`load`], adding the contour lines of a `--section` plane.
pub fn load_with_section(
    input: &Path,
    quiet: bool,
    cells: Option<usize>,
    section: Option<Plane>,
) -> (String, Result<(Mesh, usize), i32>) {
    let mut messages = String::new();
    let text = match std::fs::read(input) {
        Ok(bytes) => match String::from_utf8(bytes) {
            Ok(t) => t,
            Err(e) => {
                return (
                    format!(
                        "{}: error: not UTF-8 text (byte {})\n",
                        input.display(),
                        e.utf8_error().valid_up_to()
                    ),
                    Err(EXIT_INVALID),
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
    if let Some(n) = cells {
        if !(1..=1024).contains(&n) {
            messages.push_str(&format!(
                "geomc: --cells {n}: give a whole number from 1 to 1024 (the grid holds (n + 1)³ samples of 8 bytes)\n"
            ));
            return (messages, Err(EXIT_USAGE));
        }
    }
    let surface = model.polygonize(cells.map(|n| [n; 3]));
    let mut mesh = surface_to_mesh(&surface, model.name());
    if let Some(plane) = section {
        if !add_section(
            &mut mesh,
            &surface.positions,
            &surface.triangles,
            model.name(),
            plane,
        ) && !quiet
        {
            messages.push_str(&format!(
                "{}: warning[W133]: the section plane does not cut the surface of '{}'\n",
                input.display(),
                model.name()
            ));
        }
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
    section: Option<Plane>,
) -> (String, bool) {
    let (mut messages, loaded) = load_with_section(input, quiet, cells, section);
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
