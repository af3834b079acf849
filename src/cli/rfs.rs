//! `geomc compile model.rfs -o out.glb`: an implicit solid written in paper
//! 001's language, polygonized on its Geom grid (or `--cells N` per axis) and
//! written in every requested format.

use geomc::diag::render_human;
use geomc::formats::{self, Encoding, WriteOptions};
use geomc::implicit::{lang, surface_to_mesh};
use geomc::span::SourceFile;
use std::path::{Path, PathBuf};

/// Whether a path names an `.rfs` program.
pub fn is_rfs(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("rfs"))
}

/// Compiles one `.rfs` input; returns the messages to print and success.
pub fn compile(
    input: &Path,
    outputs: &[PathBuf],
    encoding: Option<Encoding>,
    quiet: bool,
    cells: Option<usize>,
) -> (String, bool) {
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
                    false,
                );
            }
        },
        Err(e) => {
            return (
                format!("geomc: cannot read {}: {e}\n", input.display()),
                false,
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
        return (messages, false);
    };
    if let Some(n) = cells {
        if !(1..=1024).contains(&n) {
            messages.push_str(&format!(
                "geomc: --cells {n}: give a whole number from 1 to 1024 (the grid holds (n + 1)³ samples of 8 bytes)\n"
            ));
            return (messages, false);
        }
    }
    let surface = model.polygonize(cells.map(|n| [n; 3]));
    let mesh = surface_to_mesh(&surface, model.name());
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
                        surface.triangles.len()
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
