//! The typed document: what the XML says, names unresolved, spans on every value.
//! [`grammar`] is the format's structure as data, [`structure`] checks a tree
//! against it, [`build`] turns the checked tree into a [`Document`].

mod build;
pub mod grammar;
pub mod model;
pub mod structure;

pub use build::{
    DocumentBuilder, PartBuilder, Parts, build, build_with, parse_attribute_expr, parse_ref,
};
pub use model::*;
