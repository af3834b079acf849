//! `geomc inspect --mesh`: meshes the model as `compile` would and measures
//! the result (`geomc::meshing::MeshReport`).

use super::mesh_args::MeshArgs;
use super::{EXIT_INVALID, EXIT_USAGE, report_usage};
use geomc::diag::render_human;
use geomc::driver::Checked;
use geomc::lower::Lowered;
use geomc::meshing::{MeshReport, mesh_model};

/// The mesh report, or the exit code after printing why there is none.
pub fn report(checked: &Checked, lowered: &Lowered, args: &MeshArgs) -> Result<MeshReport, i32> {
    let options = args.to_options().map_err(|d| {
        report_usage(&[d]);
        EXIT_USAGE
    })?;
    // Refused before meshing spends the memory, then counted, as compile does.
    let max = args.max_triangles;
    let estimate = super::limits::estimate_triangles(&lowered.model, &options);
    if estimate > max {
        let d = super::limits::too_many_triangles(estimate, max, true);
        eprint!("{}", render_human(&checked.source, &d));
        return Err(EXIT_INVALID);
    }
    let mesh = mesh_model(&lowered.model, &options).map_err(|e| {
        let diagnostic = e.to_diagnostic(&lowered.model, &lowered.source_map);
        eprint!("{}", render_human(&checked.source, &diagnostic));
        EXIT_INVALID
    })?;
    let triangles: u64 = mesh.faces.iter().map(|f| f.triangles.len() as u64).sum();
    if triangles > max {
        let d = super::limits::too_many_triangles(triangles, max, false);
        eprint!("{}", render_human(&checked.source, &d));
        return Err(EXIT_INVALID);
    }
    Ok(MeshReport::of(
        &lowered.model,
        &mesh,
        options.tolerance.absolute(&lowered.model),
        options.max_edge,
        options.min_angle_degrees,
    ))
}

/// The model's JSON report with the mesh report under "mesh".
pub fn with_mesh_json(model_json: &str, mesh: &MeshReport) -> String {
    let mut value: serde_json::Value = serde_json::from_str(model_json).unwrap_or_default();
    if let (Some(object), Ok(mesh)) = (value.as_object_mut(), serde_json::to_value(mesh)) {
        object.insert("mesh".into(), mesh);
    }
    serde_json::to_string_pretty(&value).unwrap_or_default()
}
