//! Mesh writers: the output mesh IR ([`crate::mesh::Mesh`]) to files for
//! viewers (glTF, OBJ, STL) and solvers (Gmsh MSH 4.1 and 2.2, VTK `.vtu`), plus the
//! `.frag.xml` side description of subdomains and fragments.
//!
//! Every writer implements [`MeshWriter`] and is listed in [`WRITERS`];
//! [`writer_for_path`] picks one from an output path's extension and
//! [`write_mesh_file`] writes a file (and its side files) atomically. What a
//! format cannot carry is reported as a [`Warning`], never dropped silently.
//! Writers are deterministic (same mesh and options, same bytes) and return
//! [`WriteError::InvalidMesh`] for a malformed mesh instead of panicking.

mod atomic;
mod base64;
mod file_ranges;
pub mod frag;
mod gltf;
mod groups;
mod mesh_facts;
mod msh;
mod msh22;
mod msh_bounds;
pub(crate) mod node_window;
mod obj;
pub mod read;
mod stl;
mod vtu;

pub use atomic::{FileOutput, Parts, write_atomic, write_atomic_file};
pub use frag::{FragDocument, read_frag_xml};
pub use mesh_facts::MeshFacts;

use crate::mesh::Mesh;
use std::fmt;
use std::io::Write;
use std::path::Path;

/// Text or binary, for the formats that have both (STL, MSH, VTU).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    Ascii,
    Binary,
}

/// What the caller chooses beyond the mesh itself.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// `None`: the format's default (binary STL, ASCII MSH, ASCII VTU).
    pub encoding: Option<Encoding>,
    /// The written file's name without its folder (`part.gltf`). A `.gltf`
    /// writer given one puts its buffer in the side file `part.bin`; without
    /// one (writing to a stream) it embeds the buffer as a data URI.
    pub file_name: Option<String>,
    /// The mesh file a `.frag.xml` refers to (`part.msh`).
    pub mesh_file: Option<String>,
}

/// Something the chosen format could not carry, said once per kind.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Warning {
    /// The writer's name (`"stl"`).
    pub format: &'static str,
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.format, self.message)
    }
}

#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    #[error("cannot write: {0}")]
    Io(#[from] std::io::Error),
    /// The mesh breaks the IR's rules (an index out of range, a coordinate that
    /// is not finite): a bug upstream, reported instead of a panic.
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    #[error("no mesh format for `{0}`: use one of {list}", list = extension_list())]
    UnknownFormat(String),
    #[error("{0}")]
    Unsupported(String),
}

/// A file written beside the main one (the `.bin` of a `.gltf`), named
/// relative to the main file's folder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SideFile {
    pub name: String,
    pub bytes: Vec<u8>,
}

/// One output format.
pub trait MeshWriter: Sync {
    /// A short lowercase name, used in warnings (`"gltf"`).
    fn name(&self) -> &'static str;
    /// File name endings without the leading dot (`"frag.xml"`).
    fn extensions(&self) -> &'static [&'static str];
    /// Writes the main file to `out`.
    fn write(
        &self,
        mesh: &Mesh,
        options: &WriteOptions,
        out: &mut dyn Write,
    ) -> Result<Vec<Warning>, WriteError>;
    /// Writes the main file to an output file: the same bytes as
    /// [`MeshWriter::write`]. A writer that can have parts of its file
    /// made and written by other threads at their offsets overrides it.
    fn write_file(
        &self,
        mesh: &Mesh,
        options: &WriteOptions,
        out: &mut FileOutput,
    ) -> Result<Vec<Warning>, WriteError> {
        self.write(mesh, options, out)
    }
    /// [`MeshWriter::write_file`] for a mesh as a reader left it, with what
    /// the reader found on it (`facts`, see [`MeshFacts`]): a writer that
    /// would scan the mesh for the same takes them instead. The same bytes.
    fn write_file_known(
        &self,
        mesh: &Mesh,
        _facts: Option<&MeshFacts>,
        options: &WriteOptions,
        out: &mut FileOutput,
    ) -> Result<Vec<Warning>, WriteError> {
        self.write_file(mesh, options, out)
    }
    /// Files the main file refers to, for the same mesh and options. Most
    /// formats are self-contained.
    fn side_files(
        &self,
        _mesh: &Mesh,
        _options: &WriteOptions,
    ) -> Result<Vec<SideFile>, WriteError> {
        Ok(Vec::new())
    }
    /// Whether the format holds volume cells (MSH, VTU); the others warn
    /// that they drop them.
    fn keeps_volume_cells(&self) -> bool {
        false
    }
}

/// Every writer, in the order `--help` lists them.
pub static WRITERS: &[&dyn MeshWriter] = &[
    &gltf::GLTF,
    &gltf::GLB,
    &obj::Obj,
    &stl::Stl,
    &msh::Msh,
    &msh22::Msh22,
    &vtu::Vtu,
    &frag::FragXml,
];

fn extension_list() -> String {
    WRITERS
        .iter()
        .flat_map(|w| w.extensions().iter().map(|e| format!(".{e}")))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The writer for a path, by its ending (case-insensitive). The longest
/// matching ending wins, so `a.frag.xml` is a `.frag.xml`, not some `.xml`.
pub fn writer_for_path(path: &Path) -> Option<&'static dyn MeshWriter> {
    let name = path.file_name()?.to_str()?.to_ascii_lowercase();
    WRITERS
        .iter()
        .flat_map(|w| w.extensions().iter().map(move |e| (*w, *e)))
        .filter(|(_, e)| {
            name.len() > e.len() + 1
                && name.ends_with(e)
                && name.as_bytes()[name.len() - e.len() - 1] == b'.'
        })
        .max_by_key(|(_, e)| e.len())
        .map(|(w, _)| w)
}

/// Writes `mesh` to `path` in the format its extension names: side files
/// first, then the main file, each atomically. `options.file_name` is filled
/// from `path` when unset. On error no partial file is left.
pub fn write_mesh_file(
    path: &Path,
    mesh: &Mesh,
    options: &WriteOptions,
) -> Result<Vec<Warning>, WriteError> {
    let writer = writer_for_path(path)
        .ok_or_else(|| WriteError::UnknownFormat(path.display().to_string()))?;
    let mut options = options.clone();
    if options.file_name.is_none() {
        options.file_name = path.file_name().and_then(|n| n.to_str()).map(String::from);
    }
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut written = Vec::new();
    let result = (|| {
        for side in writer.side_files(mesh, &options)? {
            let side_path = folder.join(&side.name);
            write_atomic(&side_path, |w| Ok(w.write_all(&side.bytes)?))?;
            written.push(side_path);
        }
        write_atomic_file(path, |out| writer.write_file(mesh, &options, out))
    })();
    if result.is_err() {
        // A side file without its main file is a partial output too.
        for side_path in written {
            let _ = std::fs::remove_file(side_path);
        }
    }
    result
}

/// A number for text formats: the shortest text that reads back to the same
/// `f64`, in exponent form only far from 1 so no line grows hundreds of digits.
pub(crate) fn fmt_num(v: f64) -> String {
    if v == 0.0 {
        // Also turns -0 into 0: one spelling for one value.
        "0".to_string()
    } else if (1e-5..1e15).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// [`fmt_num`] appended to `out`, without an allocation of its own.
pub(crate) fn push_num(out: &mut String, v: f64) {
    use std::fmt::Write as _;
    let _ = if v == 0.0 {
        out.write_str("0")
    } else if (1e-5..1e15).contains(&v.abs()) {
        write!(out, "{v}")
    } else {
        write!(out, "{v:e}")
    };
}

/// [`push_num`] for the `f32` values of viewer formats.
pub(crate) fn push_num32(out: &mut String, v: f32) {
    use std::fmt::Write as _;
    let _ = if v == 0.0 {
        out.write_str("0")
    } else if (1e-5..1e15).contains(&v.abs()) {
        write!(out, "{v}")
    } else {
        write!(out, "{v:e}")
    };
}

fn warning(format: &'static str, message: impl Into<String>) -> Warning {
    Warning {
        format,
        message: message.into(),
    }
}

/// "1 edge" / "3 edges".
pub(crate) fn count(n: usize, singular: &str) -> String {
    if n == 1 {
        format!("1 {singular}")
    } else {
        format!("{n} {singular}s")
    }
}
