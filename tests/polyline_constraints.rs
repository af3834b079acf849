//! Issue 6: which region a 2D poly_line constrains. A line on (or a few ulps
//! off) the slanted side of a thin polygon, or one passing through it between
//! its points, touches the boundary and is refused; the even–odd test alone
//! put the first one inside the polygon and left the second a free line.

use geomc::driver::{Options, check_source};
use geomc::meshing::{MeshError, MeshOptions, mesh_model};
use geomc::span::SourceFile;

/// A thin triangle (0, 0), (10, 0), (0, 0.3) and one poly_line.
fn mesh_with_line(points: &[(f64, f64)]) -> Result<geomc::mesh::Mesh, MeshError> {
    let lines: String = points
        .windows(2)
        .map(|w| {
            format!(
                r#"<line><begin_point x="{}" y="{}"/><end_point x="{}" y="{}"/></line>"#,
                w[0].0, w[0].1, w[1].0, w[1].1
            )
        })
        .collect();
    let xml = format!(
        r#"<geometry version="1" dimension="2">
      <polygon name="thin"><vertex x="0" y="0"/><vertex x="10" y="0"/><vertex x="0" y="0.3"/></polygon>
      <poly_line name="probe">{lines}</poly_line>
      <subdomain name="sliver"><solid ref="thin"/></subdomain>
    </geometry>"#
    );
    let checked = check_source(SourceFile::new("t.xml", &xml), &Options::default());
    assert!(checked.is_valid(), "{:#?}", checked.diagnostics.items);
    let model = checked.lowered.expect("a model").model;
    mesh_model(&model, &MeshOptions::default())
}

fn refused_as_touching(result: Result<geomc::mesh::Mesh, MeshError>) {
    match result {
        Err(MeshError::Face { face, reason }) => {
            assert_eq!(face, "sliver");
            assert!(reason.contains("touches or crosses"), "{reason}");
            assert!(reason.contains("`probe`"), "{reason}");
        }
        other => panic!("expected the touching error, got {other:?}"),
    }
}

#[test]
fn line_along_the_slanted_side_of_a_thin_polygon_is_refused() {
    // Both points lie on y = 0.03 (10 − x) in decimals; in binary they are
    // a few ulps outside, and the old even–odd test called them inside.
    refused_as_touching(mesh_with_line(&[(1.48, 0.2556), (2.89, 0.2133)]));
}

#[test]
fn line_just_outside_within_the_tolerance_is_refused() {
    // 1e-9 above the slanted side: under the model tolerance (1e-6 × the
    // diagonal ≈ 1.0e-5).
    let y = |x: f64| 0.03 * (10.0 - x) + 1e-9;
    refused_as_touching(mesh_with_line(&[(2.0, y(2.0)), (6.0, y(6.0))]));
}

#[test]
fn line_through_the_polygon_between_its_probes_is_refused() {
    // Its ends and middle (5, 0.5) are all outside the polygon, but it
    // crosses both the bottom and the slanted side.
    refused_as_touching(mesh_with_line(&[(5.0, -1.0), (5.0, 2.0)]));
}

#[test]
fn line_clearly_outside_stays_free_and_line_inside_is_followed() {
    let free = mesh_with_line(&[(2.0, 1.0), (6.0, 1.0)]).expect("meshes");
    assert_eq!(
        free.polylines[0].nodes.len(),
        2,
        "a free line keeps its two nodes"
    );
    let inside = mesh_with_line(&[(1.0, 0.1), (5.0, 0.1)]).expect("meshes");
    let nodes = &inside.polylines[0].nodes;
    // Followed by the triangulation: every consecutive pair is a triangle edge.
    let edges: std::collections::HashSet<(u32, u32)> = inside
        .faces
        .iter()
        .flat_map(|f| &f.triangles)
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    assert!(nodes.len() >= 2);
    for w in nodes.windows(2) {
        assert!(edges.contains(&(w[0].min(w[1]), w[0].max(w[1]))));
        let [p, q] = [w[0], w[1]].map(|n| inside.nodes[n as usize]);
        assert!((p[1] - 0.1).abs() < 1e-12 && (q[1] - 0.1).abs() < 1e-12);
    }
}

/// The smallest angle of a triangle, in degrees.
fn smallest_angle(p: [f64; 3], q: [f64; 3], r: [f64; 3]) -> f64 {
    let angle = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
        let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
        (u[0] * v[1] - u[1] * v[0])
            .abs()
            .atan2(u[0] * v[0] + u[1] * v[1])
            .to_degrees()
    };
    angle(p, q, r).min(angle(q, r, p)).min(angle(r, p, q))
}

/// A crack inside a tilted square (sides 3·√0.1 ≈ 0.949, area 0.9). The
/// sides' nodes are collinear only up to rounding, and with a poly_line
/// spade refined the slivers between them and its hull without end: this
/// ran for minutes. It now meshes at each area limit, covering the square at
/// the default minimum angle (25°), with the crack followed over its whole
/// length (√0.1 ≈ 0.316).
#[test]
fn crack_in_a_tilted_square_meshes_at_every_area_limit() {
    let xml = r#"<geometry version="1" dimension="2">
      <polygon name="p"><vertex x="0" y="0"/><vertex x="0.9" y="0.3"/><vertex x="0.6" y="1.2"/><vertex x="-0.3" y="0.9"/></polygon>
      <poly_line name="cut"><line><begin_point x="0.2" y="0.4"/><end_point x="0.5" y="0.5"/></line></poly_line>
      <subdomain name="inside"><solid ref="p"/></subdomain>
    </geometry>"#;
    let checked = check_source(SourceFile::new("t.xml", xml), &Options::default());
    assert!(checked.is_valid(), "{:#?}", checked.diagnostics.items);
    let model = checked.lowered.expect("a model").model;
    let mut previous = 0;
    for max_area in [0.05, 0.01, 0.002] {
        let options = MeshOptions {
            max_area: Some(max_area),
            ..MeshOptions::default()
        };
        let mesh = mesh_model(&model, &options).expect("meshes");
        let mut area = 0.0;
        let mut count = 0;
        for t in mesh.faces.iter().flat_map(|f| &f.triangles) {
            let [p, q, r] = t.map(|n| mesh.nodes[n as usize]);
            let twice = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
            assert!(twice.abs() / 2.0 <= max_area * (1.0 + 1e-9), "{max_area}");
            assert!(smallest_angle(p, q, r) >= 25.0 - 1e-9, "{max_area}");
            area += twice.abs() / 2.0;
            count += 1;
        }
        assert!((area - 0.9).abs() < 1e-12, "{max_area}: area {area}");
        assert!(
            count >= (0.9 / max_area) as usize,
            "{max_area}: {count} triangles"
        );
        assert!(count > previous, "{max_area}: {count} ≤ {previous}");
        previous = count;
        let crack = &mesh.polylines[0].nodes;
        let length: f64 = crack
            .windows(2)
            .map(|w| {
                let [p, q] = [w[0], w[1]].map(|n| mesh.nodes[n as usize]);
                (q[0] - p[0]).hypot(q[1] - p[1])
            })
            .sum();
        assert!(
            (length - 0.1f64.sqrt()).abs() < 1e-12,
            "{max_area}: {length}"
        );
    }
}
