//! Placeholder until the topology checks land.
use crate::diag::Diagnostics;
use crate::ir::{Model, SourceMap};
pub fn check_topology(_model: &Model, _source_map: &SourceMap) -> Diagnostics {
    Diagnostics::default()
}
