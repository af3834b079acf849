//! Size, quality and order options of `geomc compile` for solver meshes
//! (issue 6), kept apart from compile's own arguments.

use super::{EXIT_INVALID, EXIT_USAGE};
use geomc::meshing::{MeshOptions, MeshReport, SizeField, mesh_model, mesh_report};

#[derive(clap::Args, Debug, Clone, Default)]
pub struct MeshArgs {
    /// 2D: largest triangle area anywhere (a subdomain's area= may lower it).
    #[arg(long, value_name = "AREA")]
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

impl MeshArgs {
    /// Adds these options to `options`, or says what is wrong with them.
    pub fn apply(&self, options: &mut MeshOptions) -> Result<(), String> {
        if let Some(area) = self.max_area
            && !(area.is_finite() && area > 0.0)
        {
            return Err(format!("--max-area {area}: give a positive area"));
        }
        if !(1..=2).contains(&self.order) {
            return Err(format!("--order {}: give 1 or 2", self.order));
        }
        options.max_area = self.max_area;
        options.order = self.order;
        options.size_field = match (&self.size_field, &self.size_distance_to) {
            (Some(text), target) => Some(SizeField::parse(text, target.clone())?),
            (None, Some(target)) => Some(SizeField::parse(
                "0.002*diagonal + 0.3*d",
                Some(target.clone()),
            )?),
            (None, None) => None,
        };
        Ok(())
    }
}

/// `geomc inspect --mesh`: mesh the model as compile would and report the
/// achieved quality.
#[derive(clap::Args, Debug, Clone)]
pub struct InspectMeshArgs {
    /// Also mesh the model and report the minimum angle, the angle
    /// histogram and the area range per subdomain.
    #[arg(long)]
    pub mesh: bool,
    /// With --mesh: the smallest angle refinement aims for, degrees.
    #[arg(
        long,
        default_value_t = 25.0,
        value_name = "DEGREES",
        requires = "mesh"
    )]
    pub min_angle: f64,
    #[command(flatten)]
    pub solver: MeshArgs,
}

impl InspectMeshArgs {
    /// Meshes `model` as compile would; on failure prints why and gives the exit code.
    pub fn report(&self, model: &geomc::ir::Model) -> Result<MeshReport, i32> {
        let mut options = MeshOptions {
            min_angle_degrees: self.min_angle,
            ..MeshOptions::default()
        };
        if let Err(message) = self.solver.apply(&mut options) {
            eprintln!("geomc: {message}");
            return Err(EXIT_USAGE);
        }
        match mesh_model(model, &options) {
            Ok(mesh) => Ok(mesh_report(&mesh)),
            Err(e) => {
                eprintln!("geomc: {e}");
                Err(EXIT_INVALID)
            }
        }
    }
}
