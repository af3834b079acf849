//! geomc: XML descriptions of computational domains → checked topology → meshes.
//!
//! The pipeline, one module a stage: [`syntax`] (XML with spans) → [`doc`] (the
//! typed document, names unresolved) → [`resolve`] (parameters, expressions,
//! coordinate systems, references, global coordinates) → [`lower`] (boundary
//! representations, welding, boolean subdomains) → [`ir`] (the model: geometry
//! and the topology graph, no spans) → [`valid`] (topology checks). [`driver`]
//! runs them all. The library never prints and never exits: only the CLI does.

// Bad input must become a diagnostic, never a panic (docs/reliability.md).
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod allocator;
mod cache_hint;
pub mod diag;
pub mod doc;
pub mod driver;
pub mod expr;
pub mod formats;
pub mod geom;
pub mod implicit;
pub mod inspect;
pub mod ir;
pub mod lower;
pub mod meshing;
pub mod render;
pub mod resolve;
pub mod span;
pub mod syntax;
#[cfg(test)]
mod test_rng;
#[cfg(test)]
mod test_threads;
pub mod trimmed;
pub mod valid;

/// A number as messages show it: no trailing zeros, exponent form only for
/// very large or very small magnitudes.
pub(crate) fn resolve_fmt(v: f64) -> String {
    let magnitude = v.abs();
    if magnitude != 0.0 && !(1e-4..1e9).contains(&magnitude) {
        format!("{v:.3e}")
    } else {
        let rounded = (v * 1e9).round() / 1e9;
        format!("{rounded}")
    }
}
pub mod convert;
pub mod mesh;
