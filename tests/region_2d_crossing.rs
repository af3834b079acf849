//! Issue 6: a carved 2D R-function region whose contour crosses a kernel
//! edge (a disk sticking out of a square's side, across a kernel circle, or
//! across the edge between two stacked rectangles) is split at the
//! crossings: the kernel edge and the contour are cut there, the kernel face
//! keeps its part outside the region and the region keeps its whole solid.
//! Checked on the crossing nodes (on both true curves to 1e-12), the areas
//! (against the boundary polygons to 1e-12 and closed forms), the minimum
//! angle, conformity of the interfaces, the MSH groups as gmsh and meshio
//! read them, and a scikit-fem solve over the whole square (the tools are
//! installed by ./scripts/test.sh).

mod mesh2d_common;

use geomc::diag::Code;
use geomc::driver::{Options, check_source};
use geomc::mesh::Mesh;
use geomc::meshing::mesh_model;
use geomc::span::SourceFile;
use mesh2d_common::{
    area, assert_conforming, assert_groups_read, assert_min_angle_30, at_30_degrees,
    compile_msh as compile, diagnostics, fan_area, fragment_names, fragment_segments,
    mesh_clean as mesh, min_angle_degrees, python, triangles_of,
};
use std::collections::BTreeSet;
use std::f64::consts::PI;

/// The unit square less a disk of radius 0.3 about (1, 0.5), on its side
/// x = 1: the contour crosses the side at (1, 0.2) and (1, 0.8).
const ON_SIDE: &str = r#"<geometry version="1" dimension="2">
  <rectangle name="sq"><first_point x="0" y="0"/><second_point x="1" y="1"/></rectangle>
  <rfunction name="bead" nx="40" ny="40" x_min="0.5" x_max="1.5" y_min="0" y_max="1">
    <disk r="0.3" x0="1" y0="0.5"/> </rfunction>
  <subdomain name="plate"><difference><solid ref="sq"/><solid ref="bead"/></difference></subdomain>
  <subdomain name="bead"><solid ref="bead"/></subdomain>
</geometry>"#;

/// The bead's centre across the unit circle: on it, at 60°.
const RIM_X: f64 = 0.5;
const RIM_Y: f64 = 0.866_025_403_784_438_6;

/// The unit disk less a disk of radius 0.3 centred on its rim at 60°.
const ACROSS_RIM: &str = r#"<geometry version="1" dimension="2">
  <circle name="disk"><center x="0" y="0"/><radius value="1"/></circle>
  <rfunction name="bead" nx="40" ny="40" x_min="0.1" x_max="0.9" y_min="0.466" y_max="1.266">
    <disk r="0.3" x0="0.5" y0="0.8660254037844386"/> </rfunction>
  <subdomain name="plate"><difference><solid ref="disk"/><solid ref="bead"/></difference></subdomain>
  <subdomain name="bead"><solid ref="bead"/></subdomain>
</geometry>"#;

/// Two rectangles stacked into the unit square, both less a disk of radius
/// 0.25 about the square's centre, across the edge y = 0.5 they share.
const STACKED: &str = r#"<geometry version="1" dimension="2">
  <rectangle name="lo"><first_point x="0" y="0"/><second_point x="1" y="0.5"/></rectangle>
  <rectangle name="hi"><first_point x="0" y="0.5"/><second_point x="1" y="1"/></rectangle>
  <rfunction name="bead" nx="40" ny="40" x_min="0.2" x_max="0.8" y_min="0.2" y_max="0.8">
    <disk r="0.25" x0="0.5" y0="0.5"/> </rfunction>
  <subdomain name="low"><difference><solid ref="lo"/><solid ref="bead"/></difference></subdomain>
  <subdomain name="high"><difference><solid ref="hi"/><solid ref="bead"/></difference></subdomain>
  <subdomain name="bead"><solid ref="bead"/></subdomain>
</geometry>"#;

/// The nodes of fragment `a` that end segments of fragment `b` too (where
/// an interface meets the outer boundary: the crossings), sorted by y.
fn meeting_nodes(m: &Mesh, a: &str, b: &str) -> Vec<[f64; 3]> {
    let of = |name: &str| -> BTreeSet<u32> {
        fragment_segments(m, name).into_iter().flatten().collect()
    };
    let mut out: Vec<[f64; 3]> = of(a)
        .intersection(&of(b))
        .map(|&n| m.nodes[n as usize])
        .collect();
    out.sort_by(|p, q| p[1].total_cmp(&q[1]));
    out
}

#[test]
fn disk_across_a_square_side_is_split_at_the_crossings() {
    let m = mesh(ON_SIDE, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["plate|exterior", "plate|bead", "bead|exterior"])
    );
    // The crossings: the side x = 1 meets the circle at y = 0.5 ± 0.3.
    let crossings = meeting_nodes(&m, "plate|bead", "bead|exterior");
    assert_eq!(crossings.len(), 2, "{crossings:?}");
    for (p, y) in crossings.iter().zip([0.2, 0.8]) {
        assert!((p[0] - 1.0).abs() < 1e-12, "off the side: {p:?}");
        assert!((p[1] - y).abs() < 1e-12, "crossing {p:?}, expected y = {y}");
    }
    assert_eq!(
        meeting_nodes(&m, "plate|exterior", "bead|exterior"),
        crossings,
        "the side's parts end at the crossings"
    );
    // The interface is the circle's left half, every node on it.
    let interface = fragment_segments(&m, "plate|bead");
    for &n in interface.iter().flatten() {
        let q = m.nodes[n as usize];
        let r = (q[0] - 1.0).hypot(q[1] - 0.5);
        assert!((r - 0.3).abs() < 1e-6 && q[0] <= 1.0 + 1e-12, "{q:?}");
    }
    let shared = assert_conforming(&m, "plate|bead", "plate", "bead");
    assert!(shared >= 20, "{shared} interface nodes");
    // The plate is the square less the polygon of the interface (closed by
    // the side, through the centre); the bead is its whole polygon.
    let (plate, bead) = (
        area(&m, &triangles_of(&m, "plate")),
        area(&m, &triangles_of(&m, "bead")),
    );
    let inside = fan_area(&m, &interface, [1.0, 0.5]);
    assert!((plate - (1.0 - inside)).abs() < 1e-12, "plate {plate}");
    let mut outline = interface.clone();
    outline.extend(fragment_segments(&m, "bead|exterior"));
    let bead_polygon = fan_area(&m, &outline, [1.0, 0.5]);
    assert!(
        (bead - bead_polygon).abs() < 1e-12,
        "{bead} vs {bead_polygon}"
    );
    assert!(
        (inside - 0.045 * PI).abs() / (0.045 * PI) < 2e-3,
        "{inside}"
    );
    assert!((bead - 0.09 * PI).abs() / (0.09 * PI) < 2e-3, "{bead}");
    assert_min_angle_30(&m);
}

#[test]
fn disk_across_a_kernel_circle_cuts_the_rim_at_both_crossings() {
    let m = mesh(ACROSS_RIM, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["plate|exterior", "plate|bead", "bead|exterior"])
    );
    // |p| = 1 and |p − c| = 0.3 with |c| = 1: p at 60° ± acos(1 − 0.3²/2).
    let half = (1.0 - 0.045f64).acos();
    let crossings = meeting_nodes(&m, "plate|bead", "bead|exterior");
    assert_eq!(crossings.len(), 2, "{crossings:?}");
    let mut angles: Vec<f64> = crossings.iter().map(|p| p[1].atan2(p[0])).collect();
    angles.sort_by(f64::total_cmp);
    for (p, expected) in crossings.iter().zip([PI / 3.0 + half, PI / 3.0 - half]) {
        assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-12, "off the rim: {p:?}");
        let r = (p[0] - RIM_X).hypot(p[1] - RIM_Y);
        assert!((r - 0.3).abs() < 1e-12, "off the bead's circle: {p:?}");
        assert!(
            angles.iter().any(|a| (a - expected).abs() < 1e-12),
            "{angles:?} vs {expected}"
        );
    }
    let rim = fragment_segments(&m, "plate|exterior");
    for &n in rim.iter().flatten() {
        let q = m.nodes[n as usize];
        assert!((q[0].hypot(q[1]) - 1.0).abs() < 1e-12, "rim node {q:?}");
    }
    assert_conforming(&m, "plate|bead", "plate", "bead");
    // Both subdomains together: the polygon of the outer boundary, seen
    // from a point of the lens both disks share.
    let (plate, bead) = (
        area(&m, &triangles_of(&m, "plate")),
        area(&m, &triangles_of(&m, "bead")),
    );
    let mut outer = rim.clone();
    outer.extend(fragment_segments(&m, "bead|exterior"));
    let polygon = fan_area(&m, &outer, [0.45, 0.78]);
    assert!(
        (plate + bead - polygon).abs() < 1e-12,
        "{} vs {polygon}",
        plate + bead
    );
    let mut bead_outline = fragment_segments(&m, "plate|bead");
    bead_outline.extend(fragment_segments(&m, "bead|exterior"));
    let bead_polygon = fan_area(&m, &bead_outline, [RIM_X, RIM_Y]);
    assert!(
        (bead - bead_polygon).abs() < 1e-12,
        "{bead} vs {bead_polygon}"
    );
    assert!((bead - 0.09 * PI).abs() / (0.09 * PI) < 2e-3, "{bead}");
    assert!(min_angle_degrees(&m) >= 30.0 - 1e-9);
}

#[test]
fn disk_across_two_stacked_rectangles_splits_their_common_edge() {
    let m = mesh(STACKED, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from([
            "low|exterior",
            "high|exterior",
            "low|high",
            "low|bead",
            "high|bead"
        ])
    );
    // The common edge keeps its name and its part beyond the bead is
    // `lo.e3.3` (`lo.e3.2`, inside the bead, is gone).
    let low_high = m
        .fragments
        .iter()
        .find(|f| f.name == "low|high")
        .expect("low|high");
    let names: BTreeSet<&str> = low_high
        .edges
        .iter()
        .map(|&e| m.edges[e as usize].name.as_str())
        .collect();
    assert_eq!(names, BTreeSet::from(["lo.e3", "lo.e3.3"]));
    let crossings = meeting_nodes(&m, "low|bead", "high|bead");
    assert_eq!(crossings.len(), 2, "{crossings:?}");
    let mut xs: Vec<f64> = crossings.iter().map(|p| p[0]).collect();
    xs.sort_by(f64::total_cmp);
    for p in &crossings {
        assert!((p[1] - 0.5).abs() < 1e-12, "off the edge: {p:?}");
    }
    assert!(
        (xs[0] - 0.25).abs() < 1e-12 && (xs[1] - 0.75).abs() < 1e-12,
        "{xs:?}"
    );
    let n_low = assert_conforming(&m, "low|bead", "low", "bead");
    let n_high = assert_conforming(&m, "high|bead", "high", "bead");
    assert!(n_low >= 20 && n_high >= 20, "{n_low} / {n_high}");
    // The three make the square exactly; each rectangle is its half less
    // the half-disk polygon (the fan about the centre, closed through it).
    let [low, high, bead] = ["low", "high", "bead"].map(|s| area(&m, &triangles_of(&m, s)));
    assert!((low + high + bead - 1.0).abs() < 1e-12, "square");
    let low_cut = fan_area(&m, &fragment_segments(&m, "low|bead"), [0.5, 0.5]);
    let high_cut = fan_area(&m, &fragment_segments(&m, "high|bead"), [0.5, 0.5]);
    assert!((low - (0.5 - low_cut)).abs() < 1e-12, "low {low}");
    assert!((high - (0.5 - high_cut)).abs() < 1e-12, "high {high}");
    assert!((bead - (low_cut + high_cut)).abs() < 1e-12, "bead {bead}");
    assert!((bead - PI / 16.0).abs() / (PI / 16.0) < 2e-3, "{bead}");
    assert!(min_angle_degrees(&m) >= 30.0 - 1e-9);
}

#[test]
fn band_across_the_square_cuts_the_plate_in_two() {
    // 0.4 ≤ y ≤ 0.6 over the whole square and beyond (its box's sides at
    // x = −0.2 and 1.2 bound it): the plate keeps two loops, below and above.
    let xml = r#"<geometry version="1" dimension="2">
  <rectangle name="sq"><first_point x="0" y="0"/><second_point x="1" y="1"/></rectangle>
  <rfunction name="band" nx="40" ny="40" x_min="-0.2" x_max="1.2" y_min="0.3" y_max="0.7">
    <formula value="0.1 - abs(y - 0.5)"/> </rfunction>
  <subdomain name="plate"><difference><solid ref="sq"/><solid ref="band"/></difference></subdomain>
  <subdomain name="band"><solid ref="band"/></subdomain>
</geometry>"#;
    let checked = check_source(
        SourceFile::new("t.xml", xml.to_string()),
        &Options::default(),
    );
    let codes: Vec<Code> = checked.diagnostics.items.iter().map(|d| d.code).collect();
    assert_eq!(codes, vec![Code::RegionCutByBox]);
    let model = checked.lowered.expect("a model").model;
    let m = mesh_model(&model, &at_30_degrees(Some(0.01))).expect("meshes");
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["plate|exterior", "plate|band", "band|exterior"])
    );
    let mut crossings = meeting_nodes(&m, "plate|band", "band|exterior");
    crossings.sort_by(|p, q| p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1])));
    assert_eq!(crossings.len(), 4, "{crossings:?}");
    for (p, q) in crossings
        .iter()
        .zip([[0.0, 0.4], [0.0, 0.6], [1.0, 0.4], [1.0, 0.6]])
    {
        assert!(
            (p[0] - q[0]).abs() < 1e-12 && (p[1] - q[1]).abs() < 1e-12,
            "{p:?} vs {q:?}"
        );
    }
    // Each side is cut in three; the middle part, inside the band, is gone.
    let outer = m
        .fragments
        .iter()
        .find(|f| f.name == "plate|exterior")
        .expect("plate|exterior");
    let names: BTreeSet<&str> = outer
        .edges
        .iter()
        .map(|&e| m.edges[e as usize].name.as_str())
        .collect();
    assert_eq!(
        names,
        BTreeSet::from(["sq.e1", "sq.e2", "sq.e2.3", "sq.e3", "sq.e4", "sq.e4.3"])
    );
    let plate = triangles_of(&m, "plate");
    let centre_y = |t: &[u32; 3]| t.iter().map(|&n| m.nodes[n as usize][1]).sum::<f64>() / 3.0;
    let (below, above): (Vec<[u32; 3]>, Vec<[u32; 3]>) =
        plate.iter().partition(|t| centre_y(t) < 0.5);
    assert!((area(&m, &below) - 0.4).abs() < 1e-12, "below");
    assert!((area(&m, &above) - 0.4).abs() < 1e-12, "above");
    let band = area(&m, &triangles_of(&m, "band"));
    assert!((band - 0.28).abs() < 1e-12, "band {band}");
    assert!(min_angle_degrees(&m) >= 30.0 - 1e-9);
}

#[test]
fn disk_over_a_corner_drops_the_corner() {
    let xml = ON_SIDE
        .replace(r#"x0="1" y0="0.5""#, r#"x0="1" y0="1""#)
        .replace(r#"y_min="0" y_max="1""#, r#"y_min="0.5" y_max="1.5""#);
    let m = mesh(&xml, 0.01);
    let crossings = meeting_nodes(&m, "plate|bead", "bead|exterior");
    assert_eq!(crossings.len(), 2, "{crossings:?}");
    let [a, b] = [crossings[0], crossings[1]];
    assert!(
        (a[0] - 1.0).abs() < 1e-12 && (a[1] - 0.7).abs() < 1e-12,
        "{a:?}"
    );
    assert!(
        (b[0] - 0.7).abs() < 1e-12 && (b[1] - 1.0).abs() < 1e-12,
        "{b:?}"
    );
    // No plate node inside the bead: the corner (1, 1) went with its parts.
    for n in triangles_of(&m, "plate").into_iter().flatten() {
        let p = m.nodes[n as usize];
        assert!((p[0] - 1.0).hypot(p[1] - 1.0) > 0.3 - 1e-6, "{p:?}");
    }
    let plate = area(&m, &triangles_of(&m, "plate"));
    let quarter = fan_area(&m, &fragment_segments(&m, "plate|bead"), [1.0, 1.0]);
    assert!((plate - (1.0 - quarter)).abs() < 1e-12, "plate {plate}");
    assert!(
        (quarter - 0.0225 * PI).abs() / (0.0225 * PI) < 2e-3,
        "{quarter}"
    );
    assert_conforming(&m, "plate|bead", "plate", "bead");
    assert!(min_angle_degrees(&m) >= 30.0 - 1e-9);
}

#[test]
fn small_disk_on_a_long_edge_is_found_between_samples() {
    // Crossings 0.1 apart on an edge 100 long: the edge is sampled by the
    // region's extent, not in 512 steps of 0.195 (which step over both).
    let xml = r#"<geometry version="1" dimension="2">
  <rectangle name="strip"><first_point x="0" y="0"/><second_point x="100" y="1"/></rectangle>
  <rfunction name="bead" nx="32" ny="32" x_min="49.8" x_max="50.4" y_min="0.7" y_max="1.3">
    <disk r="0.05" x0="50.09" y0="1"/> </rfunction>
  <subdomain name="plate"><difference><solid ref="strip"/><solid ref="bead"/></difference></subdomain>
  <subdomain name="bead"><solid ref="bead"/></subdomain>
</geometry>"#;
    let m = mesh(xml, 10.0);
    let mut crossings = meeting_nodes(&m, "plate|bead", "bead|exterior");
    crossings.sort_by(|p, q| p[0].total_cmp(&q[0]));
    assert_eq!(crossings.len(), 2, "{crossings:?}");
    for (p, x) in crossings.iter().zip([50.04, 50.14]) {
        assert!(
            (p[0] - x).abs() < 1e-12 && (p[1] - 1.0).abs() < 1e-12,
            "{p:?}"
        );
    }
    let plate = area(&m, &triangles_of(&m, "plate"));
    let half = fan_area(&m, &fragment_segments(&m, "plate|bead"), [50.09, 1.0]);
    assert!((plate - (100.0 - half)).abs() < 1e-10, "plate {plate}");
    assert!(min_angle_degrees(&m) >= 30.0 - 1e-9);
}

#[test]
fn msh_of_crossings_keeps_every_group_for_gmsh_and_meshio() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (name, xml, groups, subdomains) in [
        (
            "side",
            ON_SIDE,
            &["plate|exterior", "plate|bead", "bead|exterior"][..],
            &["plate", "bead"][..],
        ),
        (
            "stacked",
            STACKED,
            &[
                "low|exterior",
                "high|exterior",
                "low|high",
                "low|bead",
                "high|bead",
            ][..],
            &["low", "high", "bead"][..],
        ),
    ] {
        let msh = compile(xml, dir.path(), name, "0.01");
        let expected = mesh(xml, 0.01);
        let r = python("check_mesh.py", &[&msh], &[]);
        assert_groups_read(&r, &expected, groups, subdomains);
        assert_eq!(r["gmsh"]["nodes"], expected.nodes.len() as u64, "{name}");
    }
}

#[test]
fn poisson_over_the_stacked_square_matches_the_series() {
    // −Δu = 1 on the unit square (low, high and the bead across their
    // edge), u = 0 on its sides: the double sine series. The P1 nodal error
    // falls with the mesh size (stated: under 2e-3 at area 0.01, under
    // 4e-4 at 0.0025).
    let dir = tempfile::tempdir().expect("tempdir");
    let mut errors = Vec::new();
    for (name, max_area, bound) in [("coarse", "0.01", 2e-3), ("fine", "0.0025", 4e-4)] {
        let msh = compile(STACKED, dir.path(), name, max_area);
        let r = python(
            "fem_poisson.py",
            &[&msh],
            &["square", "low|exterior", "high|exterior"],
        );
        let error = r["max_error"].as_f64().expect("max_error");
        assert!(error < bound, "{name}: max error {error}");
        let max_u = r["max_u"].as_f64().expect("max_u");
        assert!((max_u - 0.073_671_35).abs() < 2e-3, "{name}: max u {max_u}");
        errors.push(error);
    }
    assert!(errors[1] < errors[0] / 3.0, "{errors:?}");
}

#[test]
fn box_side_across_the_kernel_edge_is_refused_naming_the_fix() {
    // The bead's box stops at y = 0.6, so its side there (not f = 0) bounds
    // it where it crosses x = 1.
    let xml = ON_SIDE.replace(r#"y_min="0" y_max="1""#, r#"y_min="0" y_max="0.6""#);
    let found = diagnostics(&xml);
    let errors: Vec<_> = found
        .iter()
        .filter(|d| d.code != Code::RegionCutByBox)
        .collect();
    assert_eq!(errors.len(), 1, "{found:#?}");
    let d = errors[0];
    assert_eq!(d.code, Code::RegionCarveOutside);
    assert_eq!(
        d.message,
        "subdomain 'plate' subtracts region 'bead', a side of whose box crosses the kernel edge 'sq.e2' at (1.000000, 0.600000): only the contour f = 0 is split at a crossing"
    );
    assert_eq!(
        d.help.as_deref(),
        Some(
            "widen the region's box (x_min … y_max) so that f = 0 bounds the region where it crosses the kernel boundary, or clip its R-function to the kernel shape"
        )
    );
    assert!(d.span.is_some(), "located");
}

#[test]
fn uncarved_disk_across_a_side_still_overlaps() {
    // Without the carve the bead overlaps the square: E407, as before.
    let xml = ON_SIDE.replace(
        r#"<difference><solid ref="sq"/><solid ref="bead"/></difference>"#,
        r#"<solid ref="sq"/>"#,
    );
    let codes: Vec<Code> = diagnostics(&xml).iter().map(|d| d.code).collect();
    assert_eq!(codes, vec![Code::SubdomainsOverlap]);
}
