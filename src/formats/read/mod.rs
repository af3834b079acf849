//! Mesh readers: STL (ASCII and binary, told apart by content), Wavefront OBJ,
//! glTF 2.0 and GLB, Gmsh MSH 2.2 and 4.1 (ASCII and binary), VTK `.vtu` and
//! geomc's `.frag.xml` (with the mesh file it names) into the mesh IR.
//!
//! [`load_mesh`] picks a reader from the file's content and extension and
//! returns the mesh with warnings about what the IR could not hold (volume
//! cells, quads split into triangles) and how clean the surface is (open and
//! non-manifold edges, inconsistent orientation, degenerate triangles).
//! Bad input is a list of error diagnostics: text formats carry a byte span
//! (rendered as line:column), binary ones name the byte offset in the
//! message. Readers never panic and never allocate more than the file's
//! size justifies.

// User-controlled bytes and values: no panicking index (docs/reliability.md).
#![cfg_attr(not(test), deny(clippy::indexing_slicing))]

mod base64;
pub mod build;
pub mod clean;
mod clean_window;
mod f32_nodes;
mod frag;
mod gltf;
mod mapped;
mod msh;
mod obj;
mod stl;
mod summed;
mod text;
mod vtu;

pub use build::Builder;

use crate::diag::{Code, Diagnostic};
use crate::formats::MeshFacts;
use crate::mesh::Mesh;
use crate::span::Span;
use std::path::Path;

/// The formats [`load_mesh`] reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum ReadFormat {
    Stl,
    Obj,
    Gltf,
    Glb,
    Msh,
    Vtu,
    FragXml,
}

impl ReadFormat {
    pub const ALL: [ReadFormat; 7] = [
        ReadFormat::Stl,
        ReadFormat::Obj,
        ReadFormat::Gltf,
        ReadFormat::Glb,
        ReadFormat::Msh,
        ReadFormat::Vtu,
        ReadFormat::FragXml,
    ];

    /// The name used by `--from` and in messages (also the file ending).
    pub fn name(self) -> &'static str {
        match self {
            ReadFormat::Stl => "stl",
            ReadFormat::Obj => "obj",
            ReadFormat::Gltf => "gltf",
            ReadFormat::Glb => "glb",
            ReadFormat::Msh => "msh",
            ReadFormat::Vtu => "vtu",
            ReadFormat::FragXml => "frag.xml",
        }
    }

    pub fn parse(name: &str) -> Option<ReadFormat> {
        let name = name.trim_start_matches('.').to_ascii_lowercase();
        ReadFormat::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The format a path's ending names (case-insensitive).
    pub fn from_path(path: &Path) -> Option<ReadFormat> {
        let name = path.file_name()?.to_str()?.to_ascii_lowercase();
        if name.ends_with(".frag.xml") {
            return Some(ReadFormat::FragXml);
        }
        let ext = name.rsplit_once('.')?.1;
        ReadFormat::ALL
            .into_iter()
            .find(|f| f.name() == ext && *f != ReadFormat::FragXml)
    }
}

/// A mesh read from a file.
#[derive(Debug, Clone, Default)]
pub struct Loaded {
    pub mesh: Mesh,
    /// Warnings (never errors): what the mesh IR could not hold, and how
    /// clean the surface is.
    pub warnings: Vec<Diagnostic>,
    /// How the surface checks came out, for `inspect`.
    pub report: clean::CleanReport,
    /// Set for the formats that have two encodings: whether the file was binary.
    pub binary: Option<bool>,
}

/// Bounds on what a mesh file makes the readers read besides its own bytes
/// (issue 10): files it names, and glTF accessors read more than once.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReadLimits {
    /// Largest file named by the input (a glTF buffer file, the mesh of a
    /// `.frag.xml`), and most bytes of all a glTF's buffers together
    /// (`--max-file-size`).
    pub max_file_size: u64,
    /// Most accessor elements one glTF makes the reader decode, summed over
    /// every primitive (an accessor shared by many primitives counts each
    /// time) (`--max-mesh-elements`).
    pub max_elements: u64,
}

/// Largest file read, in bytes (the XML default).
pub const MAX_FILE_SIZE: u64 = 256 * 1024 * 1024;
/// Most glTF accessor elements decoded (about 2.4 GB as coordinates).
pub const MAX_ELEMENTS: u64 = 100_000_000;

impl Default for ReadLimits {
    fn default() -> ReadLimits {
        ReadLimits {
            max_file_size: MAX_FILE_SIZE,
            max_elements: MAX_ELEMENTS,
        }
    }
}

/// Refuses a file named by the input that is larger than `limit`, from its
/// size alone (E103). A file that cannot be inspected is left to the read.
pub(crate) fn check_named_file(path: &Path, what: &str, limit: u64) -> Result<(), Diagnostic> {
    match std::fs::metadata(path) {
        Ok(meta) if meta.len() > limit => Err(Diagnostic::new(
            Code::FileTooLarge,
            None,
            format!(
                "{what} {} is {} bytes, over the input size limit of {limit} bytes",
                path.display(),
                meta.len()
            ),
        )
        .with_help("raise the limit with --max-file-size BYTES")),
        _ => Ok(()),
    }
}

/// Reads a mesh file; the format comes from its content where that is
/// unambiguous (GLB, binary and ASCII STL, MSH, VTU) and else from its ending.
pub fn load_mesh(path: &Path) -> Result<Loaded, Vec<Diagnostic>> {
    load_mesh_as(path, None)
}

/// [`load_mesh`] with the format forced (`--from`).
pub fn load_mesh_as(path: &Path, format: Option<ReadFormat>) -> Result<Loaded, Vec<Diagnostic>> {
    load_mesh_limited(path, format, &ReadLimits::default())
}

/// [`load_mesh_as`] within `limits`.
pub fn load_mesh_limited(
    path: &Path,
    format: Option<ReadFormat>,
    limits: &ReadLimits,
) -> Result<Loaded, Vec<Diagnostic>> {
    let (mut loaded, checked) = load_mesh_unchecked(path, format, limits)?;
    if !checked {
        loaded.check();
    }
    Ok(loaded)
}

impl Loaded {
    /// Runs the surface checks: fills `report` and adds its warnings.
    pub fn check(&mut self) {
        self.report = clean::check(&self.mesh);
        self.warnings.extend(self.report.warnings());
    }
}

/// [`load_mesh_limited`] that may leave the surface checks to the caller:
/// the flag says whether they ran (a `.frag.xml` runs them on its mesh
/// file); when not, [`Loaded::check`] gives what `load_mesh_limited` would.
/// `convert` uses it to check while it writes.
pub fn load_mesh_unchecked(
    path: &Path,
    format: Option<ReadFormat>,
    limits: &ReadLimits,
) -> Result<(Loaded, bool), Vec<Diagnostic>> {
    load_unchecked(path, format, limits, false).map(|(loaded, kept)| (loaded, kept.checked))
}

/// The input file's bytes after reading, still mapped: unmapping a large
/// file takes the kernel a while (about 5 ms for 96 MB, on the thread that
/// drops it, while the others wait for it at the next join), so a caller
/// may drop this where a thread would otherwise be idle.
pub struct InputBytes {
    /// Held only to be dropped.
    _bytes: Option<mapped::FileBytes>,
}

/// What [`load_mesh_keeping_input`] hands back beside the mesh.
pub struct Kept {
    /// Whether the surface checks ran (as [`load_mesh_unchecked`] says).
    pub checked: bool,
    pub input: InputBytes,
    /// What the reader found on the mesh as read (`None` when the surface
    /// checks ran): for passes over the mesh before it is changed.
    pub facts: Option<MeshFacts>,
}

/// [`load_mesh_unchecked`] that hands back the input's bytes instead of
/// freeing them (`convert` frees them on the checks' thread once its
/// counting is done), and the mesh's facts.
pub fn load_mesh_keeping_input(
    path: &Path,
    format: Option<ReadFormat>,
    limits: &ReadLimits,
) -> Result<(Loaded, Kept), Vec<Diagnostic>> {
    load_unchecked(path, format, limits, true)
}

/// With `keep`, the input's bytes and the mesh's facts are kept.
fn load_unchecked(
    path: &Path,
    format: Option<ReadFormat>,
    limits: &ReadLimits,
    keep: bool,
) -> Result<(Loaded, Kept), Vec<Diagnostic>> {
    if matches!(format, None | Some(ReadFormat::Stl))
        && let Some(read) = stl::read_binary_file(path, format.is_some())
    {
        let (mut loaded, facts) = read?.finish_with(keep)?;
        loaded.binary = Some(true);
        let kept = Kept {
            checked: false,
            input: InputBytes { _bytes: None },
            facts,
        };
        return Ok((loaded, kept));
    }
    let file = mapped::FileBytes::open(path).map_err(|e| {
        vec![Diagnostic::new(
            Code::MeshReadFailed,
            None,
            format!("cannot read {}: {e}", path.display()),
        )]
    })?;
    let bytes: &[u8] = &file;
    let format = match format.or_else(|| detect(path, bytes)) {
        Some(f) => f,
        None => {
            return Err(vec![
                Diagnostic::new(
                    Code::UnknownMeshFormat,
                    None,
                    format!(
                        "cannot tell the mesh format of {} from its ending or content",
                        path.display()
                    ),
                )
                .with_help("name the format with --from (stl, obj, gltf, glb, msh, vtu, frag.xml)"),
            ]);
        }
    };
    if format == ReadFormat::FragXml {
        let kept = Kept {
            checked: true,
            input: InputBytes { _bytes: None },
            facts: None,
        };
        return frag::load(path, bytes, limits).map(|l| (l, kept));
    }
    let folder = path.parent().unwrap_or(Path::new(""));
    let (builder, binary) = parse(format, bytes, folder, limits)?;
    // The file's bytes are not needed for the checks: free them first,
    // unless the caller frees them later.
    let input = if keep {
        InputBytes { _bytes: Some(file) }
    } else {
        drop(file);
        InputBytes { _bytes: None }
    };
    let (mut loaded, facts) = builder.finish_with(keep)?;
    loaded.binary = binary;
    let kept = Kept {
        checked: false,
        input,
        facts,
    };
    Ok((loaded, kept))
}

/// Reads a mesh from bytes already in memory. `folder` is where relative
/// references (a `.gltf`'s buffer files) are looked up.
pub fn load_bytes(
    format: ReadFormat,
    bytes: &[u8],
    folder: &Path,
) -> Result<Loaded, Vec<Diagnostic>> {
    let (builder, binary) = parse(format, bytes, folder, &ReadLimits::default())?;
    let mut loaded = builder.finish()?;
    loaded.binary = binary;
    Ok(loaded)
}

/// Reads a `.frag.xml` from bytes already in memory; `frag_path` places it, so
/// the mesh file it names is read from `frag_path`'s folder (the fuzz target's
/// entry, which needs no file for the description itself).
pub fn load_frag_bytes(frag_path: &Path, bytes: &[u8]) -> Result<Loaded, Vec<Diagnostic>> {
    frag::load(frag_path, bytes, &ReadLimits::default())
}

type Parsed = (Builder, Option<bool>);

fn parse(
    format: ReadFormat,
    bytes: &[u8],
    folder: &Path,
    limits: &ReadLimits,
) -> Result<Parsed, Vec<Diagnostic>> {
    Ok(match format {
        ReadFormat::Stl => stl::read(bytes)?,
        ReadFormat::Obj => (obj::read(bytes)?, None),
        ReadFormat::Gltf | ReadFormat::Glb => (gltf::read(bytes, folder, limits)?, None),
        ReadFormat::Msh => msh::read(bytes)?,
        ReadFormat::Vtu => vtu::read(bytes)?,
        ReadFormat::FragXml => {
            return Err(vec![Diagnostic::new(
                Code::UnknownMeshFormat,
                None,
                "a .frag.xml describes a mesh file: read it from its path so the mesh file can be found",
            )]);
        }
    })
}

/// The format by content first, then by ending.
pub fn detect(path: &Path, bytes: &[u8]) -> Option<ReadFormat> {
    if bytes.starts_with(b"glTF") {
        return Some(ReadFormat::Glb);
    }
    let head = bytes.get(..512).unwrap_or(bytes);
    let head_text = String::from_utf8_lossy(head);
    let trimmed = head_text.trim_start();
    if trimmed.starts_with("$MeshFormat") {
        return Some(ReadFormat::Msh);
    }
    let by_name = ReadFormat::from_path(path);
    if by_name == Some(ReadFormat::FragXml) {
        return by_name;
    }
    if trimmed.starts_with("<?xml") || trimmed.starts_with("<VTKFile") {
        if head_text.contains("<VTKFile") {
            return Some(ReadFormat::Vtu);
        }
        return by_name;
    }
    if stl::looks_like_stl(bytes) {
        return Some(ReadFormat::Stl);
    }
    by_name
}

/// An error at a byte range of a text file.
pub(crate) fn error_at(
    code: Code,
    start: usize,
    end: usize,
    message: impl Into<String>,
) -> Diagnostic {
    Diagnostic::new(code, Span::new(start, end), message)
}

/// An error at a byte offset of a binary file: no span (the renderer would
/// look for lines), the offset in the message.
pub(crate) fn error_at_byte(code: Code, offset: usize, message: impl Into<String>) -> Diagnostic {
    Diagnostic::new(code, None, format!("at byte {offset}: {}", message.into()))
}

/// The `N` bytes at `at`, or `None` when they run past the end.
pub(crate) fn bytes_at<const N: usize>(data: &[u8], at: usize) -> Option<[u8; N]> {
    data.get(at..)?.first_chunk::<N>().copied()
}

/// A slice as an array of its length (`None` for any other length); with
/// `chunks_exact(N)` it never fails.
pub(crate) fn array<T: Copy, const N: usize>(s: &[T]) -> Option<[T; N]> {
    s.try_into().ok()
}
