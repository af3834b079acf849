//! The typed document: what the XML says, names unresolved, spans on every value.

pub mod grammar;
pub mod structure;
