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
pub mod valid;
