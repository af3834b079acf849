//! Size, quality and order options for 2D solver meshes (issue 6), shared by
//! `geomc compile` and `geomc inspect --mesh` and applied on top of the
//! options [`super::mesh_args`] checks.

use geomc::diag::{Code, Diagnostic};
use geomc::meshing::{MeshOptions, SizeField};

#[derive(clap::Args, Debug, Clone, Default)]
pub struct SolverMeshArgs {
    /// 2D: largest triangle area anywhere (a subdomain's area= may lower it).
    #[arg(long, value_name = "AREA", allow_hyphen_values = true)]
    pub max_area: Option<f64>,
    /// Size field: an expression in x, y, z (and d with --size-distance-to)
    /// giving the longest triangle edge wanted there, e.g. "0.01 + 0.2*d".
    #[arg(long, value_name = "EXPR")]
    pub size_field: Option<String>,
    /// Makes d in --size-field the distance to this boundary fragment or
    /// <boundary> (default field without --size-field: 0.2% of the model's
    /// size + 0.3 d).
    #[arg(long, value_name = "FRAGMENT")]
    pub size_distance_to: Option<String>,
    /// Element order: 1 (3-node triangles) or 2 (6-node triangles with
    /// mid-edge nodes on curved boundaries).
    #[arg(long, default_value_t = 1, value_name = "N")]
    pub order: u8,
}

impl SolverMeshArgs {
    /// Adds these options to `options`; the error (E501) names the bad value.
    pub fn apply(&self, options: &mut MeshOptions) -> Result<(), Diagnostic> {
        if let Some(area) = self.max_area
            && !(area.is_finite() && area > 0.0)
        {
            return Err(invalid(format!(
                "--max-area {area}: the largest triangle area must be a positive finite number"
            ))
            .with_help("give an area such as 0.01, or leave --max-area out for no limit"));
        }
        if !(1..=2).contains(&self.order) {
            return Err(invalid(format!(
                "--order {}: the element order must be 1 or 2",
                self.order
            ))
            .with_help("1 gives 3-node triangles, 2 gives 6-node triangles"));
        }
        options.max_area = self.max_area;
        options.order = self.order;
        options.size_field = match (&self.size_field, &self.size_distance_to) {
            (Some(text), target) => Some(SizeField::parse(text, target.clone()).map_err(invalid)?),
            (None, Some(target)) => Some(
                SizeField::parse("0.002*diagonal + 0.3*d", Some(target.clone()))
                    .map_err(invalid)?,
            ),
            (None, None) => None,
        };
        Ok(())
    }
}

fn invalid(message: String) -> Diagnostic {
    Diagnostic::new(Code::InvalidMeshOption, None, message)
}
