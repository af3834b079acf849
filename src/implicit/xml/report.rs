//! What `geomc inspect` says about the implicit subdomains of an XML model
//! (they are not in the boundary-representation model the rest of the
//! report describes): name, material, kind, box and grid.

use super::{ImplicitSolid, ImplicitSubdomain};
use serde::Serialize;
use std::fmt::Write;

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Entry {
    pub name: String,
    pub material: Option<String>,
    /// `function` (R-functions, formulas, level surfaces) or `density` (samples).
    pub kind: &'static str,
    pub min: [f64; 3],
    pub max: [f64; 3],
    pub cells: [usize; 3],
    /// Mesh optimisation iterations (functions only).
    pub optiterations: u32,
}

pub fn entries(subdomains: &[ImplicitSubdomain]) -> Vec<Entry> {
    subdomains
        .iter()
        .map(|s| {
            let (kind, grid, optiterations) = match &s.solid {
                ImplicitSolid::Function(m) => ("function", m.geom.grid(), m.geom.optiterations),
                ImplicitSolid::Samples { grid, .. } => ("density", *grid, 0),
            };
            Entry {
                name: s.name.clone(),
                material: s.material.clone(),
                kind,
                min: grid.min,
                max: grid.max,
                cells: grid.cells,
                optiterations,
            }
        })
        .collect()
}

/// One line per implicit subdomain, after a count.
pub fn render_text(entries: &[Entry]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "implicit subdomains: {}", entries.len());
    for e in entries {
        let _ = write!(
            s,
            "  {} ({}): box [{}, {}, {}] – [{}, {}, {}], grid {}×{}×{}",
            e.name,
            e.kind,
            e.min[0],
            e.min[1],
            e.min[2],
            e.max[0],
            e.max[1],
            e.max[2],
            e.cells[0],
            e.cells[1],
            e.cells[2]
        );
        if let Some(m) = &e.material {
            let _ = write!(s, ", material {m}");
        }
        if e.optiterations > 0 {
            let _ = write!(s, ", {} optimisation iterations", e.optiterations);
        }
        s.push('\n');
    }
    s
}
