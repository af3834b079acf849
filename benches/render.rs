//! Render benchmark (issue 8); filled in below.
fn main() {}
