//! compile's part for implicit subdomains of an XML model (`<rfunction>`,
//! `<level_surface>`, `<density_volume>`): polygonize them into the mesh and,
//! with `--section AXIS=VALUE`, add the contour lines of the plane cut.

use geomc::diag::{Code, Diagnostic, render_human};
use geomc::driver::Checked;
use geomc::implicit::xml::ImplicitSolid;
use geomc::implicit::xml::mesh::{Plane, append};
use geomc::mesh::Mesh;

/// Parses `--section`, or the usage diagnostic E624.
pub fn parse_section(text: Option<&str>) -> Result<Option<Plane>, Diagnostic> {
    let Some(text) = text else {
        return Ok(None);
    };
    Plane::parse(text).map(Some).ok_or_else(|| {
        Diagnostic::new(
            Code::ImplicitBadSection,
            None,
            format!("--section {text}: expected AXIS=VALUE"),
        )
        .with_help("write for example --section z=0")
    })
}

/// Adds the implicit subdomains of `checked` to `mesh`: the messages to
/// print, or with `Err` the messages of a grid over the `--max-grid-cells`
/// limit (E800), checked before any grid is allocated.
pub fn add_to_mesh(
    mesh: &mut Mesh,
    checked: &Checked,
    cells: Option<usize>,
    section: Option<Plane>,
    quiet: bool,
    max_grid_cells: u64,
) -> Result<String, String> {
    let mut messages = String::new();
    for sub in &checked.implicit {
        let grid = match &sub.solid {
            ImplicitSolid::Function(m) => cells.map_or(m.geom.cells, |n| [n; 3]),
            ImplicitSolid::Samples { grid, .. } => grid.cells,
        };
        if let Err(d) = super::limits::check_grid(grid, max_grid_cells) {
            let d = Diagnostic {
                span: Some(sub.span),
                ..d
            };
            messages.push_str(&render_human(&checked.source, &d));
            return Err(messages);
        }
    }
    if checked.implicit.is_empty() {
        if section.is_some() && !quiet {
            messages.push_str(&format!(
                "{}: note: --section applies to implicit subdomains; this model has none\n",
                checked.source.name
            ));
        }
        return Ok(messages);
    }
    let appended = append(mesh, &checked.implicit, cells, section);
    if quiet {
        return Ok(messages);
    }
    for (sub, triangles) in checked.implicit.iter().zip(&appended.triangles) {
        messages.push_str(&format!(
            "{}: implicit subdomain '{}': {} triangles\n",
            checked.source.name, sub.name, triangles
        ));
    }
    for name in &appended.missed_by_section {
        if let Some(sub) = checked.implicit.iter().find(|s| &s.name == name) {
            let d = Diagnostic::new(
                Code::ImplicitSectionEmpty,
                sub.span,
                format!("the section plane does not cut the surface of '{name}'"),
            );
            messages.push_str(&render_human(&checked.source, &d));
        }
    }
    Ok(messages)
}
