//! `geomc convert INPUT OUTPUT`: read a mesh file, apply the mesh options,
//! write it in another format; and `geomc inspect MESHFILE` for mesh files.
//! Warnings name everything the input or the output format could not hold.

use super::{EXIT_INVALID, EXIT_OK, EXIT_USAGE, Format, out};
use geomc::convert::{ConvertOptions, apply, inspect::MeshReport};
use geomc::diag::{Code, Diagnostic, render_human};
use geomc::formats::read::{ReadFormat, ReadLimits, load_mesh_keeping_input, load_mesh_limited};
use geomc::formats::{
    Encoding, MeshFacts, MeshWriter, WRITERS, WriteError, WriteOptions, write_atomic,
    write_atomic_file, writer_for_path,
};
use geomc::span::SourceFile;
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// The mesh to read: .stl .obj .gltf .glb .msh .vtu .frag.xml.
    input: PathBuf,
    /// The file to write: .gltf .glb .obj .stl .msh .vtu .frag.xml.
    output: PathBuf,
    /// The input format, when its ending or content does not tell.
    #[arg(long, value_name = "FORMAT")]
    from: Option<String>,
    /// The output format, when the output's ending does not tell; `msh22`
    /// writes Gmsh MSH 2.2 (a `.msh` file is otherwise MSH 4.1).
    #[arg(long, value_name = "FORMAT")]
    to: Option<String>,
    /// Text output for STL, MSH and VTU.
    #[arg(long, conflicts_with = "binary")]
    ascii: bool,
    /// Binary output for STL, MSH and VTU.
    #[arg(long)]
    binary: bool,
    /// Merge nodes closer than EPS (STL and glTF give triangle soup).
    #[arg(long, value_name = "EPS", value_parser = non_negative)]
    weld: Option<f64>,
    /// Orient each connected surface's triangles consistently (outward when
    /// closed), so the recomputed vertex normals agree.
    #[arg(long)]
    normals: bool,
    /// Scale: one factor, or SX,SY,SZ.
    #[arg(long, value_name = "S|SX,SY,SZ", value_parser = scale, allow_hyphen_values = true)]
    scale: Option<[f64; 3]>,
    /// Translate by X,Y,Z (after scaling and rotating).
    #[arg(long, value_name = "X,Y,Z", value_parser = triple, allow_hyphen_values = true)]
    translate: Option<[f64; 3]>,
    /// Rotate by AX,AY,AZ degrees about the x, then y, then z axis.
    #[arg(long, value_name = "AX,AY,AZ", value_parser = triple, allow_hyphen_values = true)]
    rotate: Option<[f64; 3]>,
    /// Keep only this group (repeatable): a face, physical group, solid or object name.
    #[arg(long = "group", value_name = "NAME")]
    groups: Vec<String>,
    /// Largest accepted input file, in bytes.
    #[arg(long, value_name = "BYTES", default_value_t = super::limits::MAX_FILE_SIZE)]
    max_file_size: u64,
    /// Most glTF accessor elements decoded (shared accessors count per use).
    #[arg(long, value_name = "N", default_value_t = geomc::formats::read::MAX_ELEMENTS)]
    max_mesh_elements: u64,
}

fn non_negative(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v >= 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("`{s}` is not a non-negative number")),
    }
}

fn triple(s: &str) -> Result<[f64; 3], String> {
    let parts: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("`{s}` is not three numbers X,Y,Z"))?;
    match parts[..] {
        [x, y, z] if parts.iter().all(|v| v.is_finite()) => Ok([x, y, z]),
        _ => Err(format!("`{s}` is not three finite numbers X,Y,Z")),
    }
}

fn scale(s: &str) -> Result<[f64; 3], String> {
    if let Ok(v) = s.parse::<f64>() {
        if v.is_finite() && v != 0.0 {
            return Ok([v; 3]);
        }
        return Err(format!("`{s}` is not a finite, non-zero scale"));
    }
    let t = triple(s)?;
    if t.contains(&0.0) {
        return Err(format!("`{s}` has a zero factor: the mesh would collapse"));
    }
    Ok(t)
}

/// Prints diagnostics of a file, with its source line where they have a span.
fn report(path: &Path, diagnostics: &[Diagnostic]) {
    let name = path.display().to_string();
    let needs_text = diagnostics.iter().any(|d| d.span.is_some());
    let text = if needs_text {
        std::fs::read(path)
            .map(|b| String::from_utf8_lossy(&b).into_owned())
            .unwrap_or_default()
    } else {
        String::new()
    };
    let source = SourceFile::new(name, text);
    for d in diagnostics {
        eprint!("{}", render_human(&source, d));
    }
}

fn read_format(name: Option<&str>) -> Result<Option<ReadFormat>, i32> {
    match name {
        None => Ok(None),
        Some(n) => match ReadFormat::parse(n) {
            Some(f) => Ok(Some(f)),
            None => {
                eprintln!(
                    "geomc: --from {n}: unknown format; use one of stl obj gltf glb msh vtu frag.xml"
                );
                Err(EXIT_USAGE)
            }
        },
    }
}

fn load(
    path: &Path,
    from: Option<ReadFormat>,
    limits: &ReadLimits,
) -> Result<geomc::formats::read::Loaded, i32> {
    load_mesh_limited(path, from, limits).map_err(|d| read_failed(path, &d))
}

fn read_failed(path: &Path, diagnostics: &[Diagnostic]) -> i32 {
    report(path, diagnostics);
    if diagnostics.iter().any(|d| d.code == Code::MeshReadFailed) {
        EXIT_USAGE
    } else {
        EXIT_INVALID
    }
}

/// A mesh with nothing a writer could carry.
fn is_empty(mesh: &geomc::mesh::Mesh) -> bool {
    mesh.faces.iter().all(|f| f.triangles.is_empty())
        && mesh.polylines.iter().all(|p| p.nodes.is_empty())
        && mesh.point_sets.iter().all(|p| p.nodes.is_empty())
        && mesh.edges.iter().all(|e| e.nodes.len() < 2)
        && mesh.volumes.iter().all(|v| v.nodes.is_empty())
}

pub fn run(args: &Args) -> i32 {
    let from = match read_format(args.from.as_deref()) {
        Ok(f) => f,
        Err(code) => return code,
    };
    let writer: &'static dyn MeshWriter = match &args.to {
        Some(name) => {
            let name = name.trim_start_matches('.').to_ascii_lowercase();
            match WRITERS
                .iter()
                .find(|w| w.name() == name || w.extensions().contains(&name.as_str()))
            {
                Some(w) => *w,
                None => {
                    eprintln!(
                        "geomc: --to {name}: unknown format; use one of gltf glb obj stl msh msh22 vtu frag.xml"
                    );
                    return EXIT_USAGE;
                }
            }
        }
        None => match writer_for_path(&args.output) {
            Some(w) => w,
            None => {
                eprintln!(
                    "geomc: cannot tell the output format of {} from its ending; name it with --to",
                    args.output.display()
                );
                return EXIT_USAGE;
            }
        },
    };
    if let Err(d) = super::limits::check_file_size(&args.input, args.max_file_size) {
        report(&args.input, &[d]);
        return EXIT_INVALID;
    }
    let limits = ReadLimits {
        max_file_size: args.max_file_size,
        max_elements: args.max_mesh_elements,
    };
    let (mut loaded, kept) = match load_mesh_keeping_input(&args.input, from, &limits) {
        Ok(l) => l,
        Err(d) => return read_failed(&args.input, &d),
    };
    let checked = kept.checked;
    if is_empty(&loaded.mesh) {
        report(
            &args.input,
            &[Diagnostic::new(
                Code::EmptyMesh,
                None,
                "the file holds no triangles, lines or points: there is nothing to convert",
            )
            .with_help("check that the file is complete and is the format its ending says (or pass --from)")],
        );
        return EXIT_INVALID;
    }
    let options = ConvertOptions {
        groups: args.groups.clone(),
        scale: args.scale,
        rotate: args.rotate,
        translate: args.translate,
        weld: args.weld,
        normals: args.normals,
    };
    // The surface checks only warn: when nothing changes the mesh before it
    // is written, they run on a second thread while the writer runs, and
    // their warnings are printed where they would have been.
    let volumes_only = !writer.keeps_volume_cells()
        && !loaded.mesh.volumes.is_empty()
        && loaded.mesh.faces.iter().all(|f| f.triangles.is_empty());
    let check_while_writing = !checked && options == ConvertOptions::default() && !volumes_only;
    // The input's bytes: unmapped at once, or by the checks' thread once its
    // counting is done (while the writer finishes; unmapping 96 MB took
    // about 5 ms with both threads waiting).
    let input = check_while_writing.then_some(kept.input);
    // What the reader found holds for the mesh as read: only when nothing
    // changes it before it is written.
    let facts = kept.facts.filter(|_| check_while_writing);
    if !checked && !check_while_writing {
        loaded.check();
    }
    report(&args.input, &loaded.warnings);
    match apply(&mut loaded.mesh, &options) {
        Ok(applied) => {
            for note in applied.notes {
                eprintln!("geomc: {note}");
            }
        }
        Err(diagnostics) => {
            report(&args.input, &diagnostics);
            return EXIT_INVALID;
        }
    }
    if options.weld.is_some() || options.normals {
        // The checks again, on the mesh as written.
        let checks = geomc::formats::read::clean::check_whole(&loaded.mesh);
        for d in checks.warnings() {
            eprint!(
                "{}",
                render_human(&SourceFile::new(args.output.display().to_string(), ""), &d)
            );
        }
    }
    let mesh = &mut loaded.mesh;
    if !writer.keeps_volume_cells()
        && !mesh.volumes.is_empty()
        && mesh.faces.iter().all(|f| f.triangles.is_empty())
    {
        // Volume cells only, for a surface format: their boundary is the surface.
        let b = geomc::convert::boundary::extract(mesh);
        eprintln!(
            "geomc: the mesh has volume cells only: writing their boundary surface ({} triangles in {} group{})",
            b.triangles,
            b.groups,
            if b.groups == 1 { "" } else { "s" }
        );
    }
    let encoding = if args.ascii {
        Some(Encoding::Ascii)
    } else if args.binary {
        Some(Encoding::Binary)
    } else {
        None
    };
    let write_options = WriteOptions {
        encoding,
        file_name: args
            .output
            .file_name()
            .and_then(|n| n.to_str())
            .map(String::from),
        mesh_file: None,
    };
    let written = if check_while_writing {
        let (checks, written) = rayon::join(
            || {
                let counts = match &facts {
                    Some(f) => geomc::formats::read::clean::check_whole_known(&loaded.mesh, f),
                    None => geomc::formats::read::clean::check_whole(&loaded.mesh),
                };
                drop(input);
                counts
            },
            || {
                write(
                    &args.output,
                    writer,
                    &loaded.mesh,
                    facts.as_ref(),
                    &write_options,
                )
            },
        );
        report(&args.input, &checks.warnings());
        written
    } else {
        write(&args.output, writer, &loaded.mesh, None, &write_options)
    };
    match written {
        Ok(warnings) => {
            let source = SourceFile::new(args.output.display().to_string(), "");
            for w in warnings {
                let d = Diagnostic::new(Code::TargetNotCarried, None, w.to_string());
                eprint!("{}", render_human(&source, &d));
            }
            let mesh = &loaded.mesh;
            let cells = if mesh.volumes.is_empty() || !writer.keeps_volume_cells() {
                String::new()
            } else {
                format!(", {}", geomc::mesh::volume::describe(&mesh.volumes))
            };
            eprintln!(
                "geomc: wrote {} ({} nodes, {} triangles{cells}, {} groups)",
                args.output.display(),
                mesh.nodes.len(),
                mesh.faces.iter().map(|f| f.triangles.len()).sum::<usize>(),
                mesh.faces.len() + mesh.polylines.len() + mesh.point_sets.len()
            );
            EXIT_OK
        }
        Err(WriteError::Unsupported(message)) => {
            let d = Diagnostic::new(Code::TargetCannotHold, None, message);
            report(&args.output, &[d]);
            EXIT_INVALID
        }
        Err(e) => {
            eprintln!("geomc: cannot write {}: {e}", args.output.display());
            EXIT_USAGE
        }
    }
}

/// Like `formats::write_mesh_file`, with the writer chosen by the caller,
/// and the reader's facts of the mesh when it is as read.
fn write(
    path: &Path,
    writer: &dyn MeshWriter,
    mesh: &geomc::mesh::Mesh,
    facts: Option<&MeshFacts>,
    options: &WriteOptions,
) -> Result<Vec<geomc::formats::Warning>, WriteError> {
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut written = Vec::new();
    let result = (|| {
        for side in writer.side_files(mesh, options)? {
            let side_path = folder.join(&side.name);
            write_atomic(&side_path, |w| Ok(w.write_all(&side.bytes)?))?;
            written.push(side_path);
        }
        write_atomic_file(path, |out| {
            writer.write_file_known(mesh, facts, options, out)
        })
    })();
    if result.is_err() {
        for side_path in written {
            let _ = std::fs::remove_file(side_path);
        }
    }
    result
}

/// Whether `inspect` should read `path` as a mesh file (by its ending).
pub fn is_mesh_file(path: &Path) -> bool {
    ReadFormat::from_path(path).is_some()
}

/// `geomc inspect MESHFILE`.
pub fn inspect(path: &Path, format: Format) -> i32 {
    let loaded = match load(path, None, &ReadLimits::default()) {
        Ok(l) => l,
        Err(code) => return code,
    };
    let name = std::fs::read(path)
        .ok()
        .and_then(|b| geomc::formats::read::detect(path, &b))
        .map_or("mesh", ReadFormat::name);
    let report = MeshReport::of(&loaded, name);
    match format {
        Format::Human => out(&report.render_text()),
        Format::Json => out(&format!("{}\n", report.render_json())),
    }
    EXIT_OK
}
