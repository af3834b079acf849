//! `--max-expression-nodes` and `--max-expression-depth` (issue 10): the
//! bounds of one attribute expression, raised per run. The depth has a hard
//! ceiling because parsing, evaluating and dropping an expression recurse
//! over its tree, so a deeper one would risk the stack.

use geomc::expr::{ExprLimits, MAX_DEPTH, MAX_NODES};

/// Deepest nesting the option may ask for.
pub const DEPTH_CEILING: u64 = 1024;

#[derive(clap::Args, Clone, Copy, Debug)]
pub struct ExprLimitArgs {
    /// Most nodes (numbers, names, operators, calls) in one attribute expression.
    #[arg(long, value_name = "N", default_value_t = MAX_NODES)]
    pub max_expression_nodes: usize,
    /// Deepest nesting of one attribute expression (at most 1024).
    #[arg(long, value_name = "N", default_value_t = MAX_DEPTH as u64,
          value_parser = clap::value_parser!(u64).range(1..=DEPTH_CEILING))]
    pub max_expression_depth: u64,
}

impl ExprLimitArgs {
    pub fn limits(&self) -> ExprLimits {
        ExprLimits {
            max_nodes: self.max_expression_nodes,
            max_depth: self.max_expression_depth as usize,
        }
    }
}
