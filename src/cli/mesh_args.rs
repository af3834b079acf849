//! The meshing options shared by `geomc compile` and `geomc inspect --mesh`,
//! checked into [`MeshOptions`] or an E501 diagnostic naming the bad value.

use super::solver_args::SolverMeshArgs;
use geomc::diag::{Code, Diagnostic};
use geomc::meshing::{MeshOptions, Tolerance};

/// The options as `inspect` takes them (compile declares the same three and
/// flattens the same [`SolverMeshArgs`]).
#[derive(clap::Args, Clone, Debug)]
pub struct MeshArgs {
    /// Chordal tolerance: a length (0.01), or a percentage of the model's
    /// bounding-box diagonal (0.1%).
    #[arg(
        long,
        default_value = "0.1%",
        value_name = "TOL",
        allow_hyphen_values = true
    )]
    pub tolerance: String,
    /// Longest triangle edge allowed.
    #[arg(long, value_name = "LENGTH", allow_hyphen_values = true)]
    pub max_edge: Option<f64>,
    /// Smallest triangle angle refinement aims for, in degrees (at most 33).
    #[arg(
        long,
        default_value_t = 25.0,
        value_name = "DEGREES",
        allow_hyphen_values = true
    )]
    pub min_angle: f64,
    /// Most triangles in the mesh (estimated before meshing, counted after).
    #[arg(long, value_name = "N", default_value_t = super::limits::MAX_TRIANGLES)]
    pub max_triangles: u64,
    #[command(flatten)]
    pub solver: SolverMeshArgs,
}

impl MeshArgs {
    pub fn to_options(&self) -> Result<MeshOptions, Diagnostic> {
        let mut options = parse_mesh_options(&self.tolerance, self.max_edge, self.min_angle)?;
        self.solver.apply(&mut options)?;
        Ok(options)
    }
}

/// Checks the three meshing options; the error names the offending value.
pub fn parse_mesh_options(
    tolerance: &str,
    max_edge: Option<f64>,
    min_angle: f64,
) -> Result<MeshOptions, Diagnostic> {
    let text = tolerance.trim();
    let positive = |v: &f64| v.is_finite() && *v > 0.0;
    let tolerance = match text.strip_suffix('%') {
        Some(percent) => percent
            .trim()
            .parse::<f64>()
            .ok()
            .filter(positive)
            .map(|v| Tolerance::Relative(v / 100.0)),
        None => text
            .parse::<f64>()
            .ok()
            .filter(positive)
            .map(Tolerance::Absolute),
    }
    .ok_or_else(|| {
        invalid(format!(
            "--tolerance {text}: the chordal tolerance must be a positive finite length or percentage"
        ))
        .with_help("give a length such as 0.01, or a percentage of the model's size such as 0.1%")
    })?;
    if let Some(max_edge) = max_edge
        && !positive(&max_edge)
    {
        return Err(invalid(format!(
            "--max-edge {max_edge}: the longest edge must be a positive finite length"
        ))
        .with_help("give a length such as 0.2, or leave --max-edge out for no limit"));
    }
    if !(min_angle > 0.0 && min_angle <= 33.0) {
        return Err(invalid(format!(
            "--min-angle {min_angle}: the angle must lie above 0 and at most 33 degrees"
        ))
        .with_help("the default is 25; refinement may not terminate above about 33"));
    }
    Ok(MeshOptions {
        tolerance,
        max_edge,
        min_angle_degrees: min_angle,
        ..MeshOptions::default()
    })
}

fn invalid(message: String) -> Diagnostic {
    Diagnostic::new(Code::InvalidMeshOption, None, message)
}
