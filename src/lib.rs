//! geomc: XML descriptions of computational domains → checked topology → meshes.
//!
//! The pipeline, one module a stage: [`syntax`] (XML with spans) → [`doc`] (the
//! typed document, names unresolved) → [`resolve`] (parameters, expressions,
//! coordinate systems, references, global coordinates) → [`ir`] (the model:
//! geometry and the topology graph, no spans) → [`valid`] (geometry and
//! topology checks). The library never prints and never exits: only the CLI does.

pub mod diag;
pub mod expr;
pub mod span;
pub mod syntax;
pub mod doc;
pub mod geom;
pub mod ir;
pub mod resolve;
pub mod lower;

/// A number as messages show it (no trailing zeros).
pub(crate) fn resolve_fmt(v: f64) -> String {
    let magnitude = v.abs();
    if magnitude != 0.0 && !(1e-4..1e9).contains(&magnitude) {
        format!("{v:.3e}")
    } else {
        let rounded = (v * 1e9).round() / 1e9;
        format!("{rounded}")
    }
}
pub mod driver;
pub mod valid;
pub mod inspect;
