//! Resource limits of the command line (issue 10): each is checked before the
//! memory it guards is spent, and hitting one is an error naming the limit and
//! the option that raises it. The XML limits (file size, nesting, nodes) live
//! in `geomc::syntax::Limits`; these are the ones of meshing and mesh files.

use geomc::diag::{Code, Diagnostic};
use geomc::ir::Model;
use geomc::meshing::MeshOptions;
use std::path::Path;

/// Largest implicit grid, in cells: (nx + 1)(ny + 1)(nz + 1) samples of 8
/// bytes, so 256³ cells take about 135 MB of samples.
pub const MAX_GRID_CELLS: u64 = 1 << 24;
/// Most triangles in one compiled mesh (several hundred bytes each while meshing).
pub const MAX_TRIANGLES: u64 = 20_000_000;
/// Largest mesh or `.rfs` input file, in bytes (the XML default).
pub const MAX_FILE_SIZE: u64 = 256 * 1024 * 1024;

/// Refuses a file larger than `limit` from its size alone, without reading it.
pub fn check_file_size(path: &Path, limit: u64) -> Result<(), Diagnostic> {
    let Ok(meta) = std::fs::metadata(path) else {
        return Ok(()); // the reader reports the I/O error with its own code
    };
    if meta.len() <= limit {
        return Ok(());
    }
    Err(Diagnostic::new(
        Code::FileTooLarge,
        None,
        format!(
            "{} is {} bytes, over the input size limit of {limit} bytes",
            path.display(),
            meta.len()
        ),
    )
    .with_help("split the input, or raise the limit with --max-file-size BYTES"))
}

/// Refuses an implicit grid of more than `limit` cells before it is allocated.
pub fn check_grid(cells: [usize; 3], limit: u64) -> Result<(), Diagnostic> {
    let total = cells
        .iter()
        .try_fold(1u64, |acc, &n| acc.checked_mul(n as u64))
        .unwrap_or(u64::MAX);
    if total <= limit {
        return Ok(());
    }
    Err(Diagnostic::new(
        Code::GridTooLarge,
        None,
        format!(
            "the grid of {} x {} x {} = {total} cells is over the limit of {limit} cells",
            cells[0], cells[1], cells[2]
        ),
    )
    .with_help(
        "use fewer cells (Geom.nx/ny/nz or --cells), or raise the limit with --max-grid-cells N",
    ))
}

/// A low estimate of the triangles meshing `model` makes, from the exact
/// areas of its faces: no triangle is larger than about 2h², where h is the
/// edge length the chordal tolerance allows on a curvature radius of half the
/// model's diagonal (curved faces), or --max-edge (every face).
pub fn estimate_triangles(model: &Model, options: &MeshOptions) -> u64 {
    let tolerance = options.tolerance.absolute(model);
    let radius = model.bbox().diagonal() / 2.0;
    let chordal = (8.0 * tolerance * radius).sqrt();
    let measures = geomc::meshing::exact::face_measures(model);
    let mut total = 0.0;
    for (face, measure) in model.faces.iter().zip(measures) {
        let Some(area) = measure.map(|m| m.area).filter(|a| a.is_finite()) else {
            continue;
        };
        let curved = !matches!(
            *face.surface(&model.solids),
            geomc::geom::Surface::Plane { .. }
        );
        let mut h = if curved { chordal } else { f64::INFINITY };
        if let Some(edge) = options.max_edge {
            h = h.min(edge);
        }
        let mut per_face = if h.is_finite() && h > 0.0 {
            area / (2.0 * h * h)
        } else {
            0.0
        };
        if let Some(max_area) = options.max_area.filter(|a| *a > 0.0) {
            per_face = per_face.max(area / max_area);
        }
        total += per_face;
    }
    if total.is_finite() {
        total as u64
    } else {
        u64::MAX
    }
}

/// The error for a mesh of `triangles` (estimated or counted) over `limit`.
pub fn too_many_triangles(triangles: u64, limit: u64, estimated: bool) -> Diagnostic {
    Diagnostic::new(
        Code::TooManyTriangles,
        None,
        format!(
            "the mesh {} {triangles} triangles, over the limit of {limit} triangles",
            if estimated {
                "would have at least about"
            } else {
                "has"
            }
        ),
    )
    .with_help(
        "use a coarser --tolerance or a longer --max-edge, or raise the limit with --max-triangles N",
    )
}

/// The meshing limits as options (flattened into `compile`).
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct Budget {
    /// Most triangles in an output mesh (estimated before meshing, counted before writing).
    #[arg(long, value_name = "N", default_value_t = MAX_TRIANGLES)]
    pub max_triangles: u64,
    /// Most cells in the grid of an implicit (.rfs) input.
    #[arg(long, value_name = "N", default_value_t = MAX_GRID_CELLS)]
    pub max_grid_cells: u64,
}

impl Default for Budget {
    fn default() -> Budget {
        Budget {
            max_triangles: MAX_TRIANGLES,
            max_grid_cells: MAX_GRID_CELLS,
        }
    }
}
