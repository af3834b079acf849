//! Issue 6: a carved 2D R-function region touching its kernel region's
//! boundary from inside (a disk tangent to a square's side, a bead against
//! the inside of a kernel circle) meshes conformingly: the touch point is
//! one node of the kernel side, of the plate's hole and of the bead, the
//! plate keeps everything but the bead, and the small angles of the plate's
//! two cusps there are the mesher's documented exception — every triangle
//! under 30° lies where the two boundaries are closer than the chordal
//! tolerance. Checked on the touch node (on both true curves), the areas
//! (against the boundary polygons to 1e-12 and the closed forms), the
//! angles, conformity of the interface, and the MSH groups as gmsh and
//! meshio read them.

mod mesh2d_common;

use geomc::diag::Code;
use geomc::mesh::Mesh;
use mesh2d_common::{
    area, assert_conforming, assert_groups_read, compile_msh as compile, diagnostics, fan_area,
    fragment_names, fragment_segments, mesh_clean as mesh, python, triangles_of,
};
use std::collections::BTreeSet;
use std::f64::consts::PI;

/// The unit square less a disk of radius 0.3 about (0.7, 0.47), tangent to
/// the side x = 1 at (1, 0.47).
const ON_SIDE: &str = r#"<geometry version="1" dimension="2">
  <rectangle name="sq"><first_point x="0" y="0"/><second_point x="1" y="1"/></rectangle>
  <rfunction name="bead" nx="32" ny="32" x_min="0.3" x_max="1.1" y_min="0.1" y_max="0.9">
    <disk r="0.3" x0="0.7" y0="0.47"/> </rfunction>
  <subdomain name="plate"><difference><solid ref="sq"/><solid ref="bead"/></difference></subdomain>
  <subdomain name="bead"><solid ref="bead"/></subdomain>
</geometry>"#;

/// The bead's centre 0.7 from the origin at 60°: it touches the unit
/// circle from inside at (0.5, √0.75).
const BEAD_X: f64 = 0.35;
const BEAD_Y: f64 = 0.606_217_782_649_107;

/// The unit disk less that bead (the fixture `2d_rfunction_inside_touch`).
const IN_CIRCLE: &str = r#"<geometry version="1" dimension="2">
  <circle name="disk"><center x="0" y="0"/><radius value="1"/></circle>
  <rfunction name="bead" nx="40" ny="40" x_min="-0.05" x_max="0.75" y_min="0.2" y_max="1.0">
    <disk r="0.3" x0="0.35" y0="0.606217782649107"/> </rfunction>
  <subdomain name="plate"><difference><solid ref="disk"/><solid ref="bead"/></difference></subdomain>
  <subdomain name="bead"><solid ref="bead"/></subdomain>
</geometry>"#;

/// The one node the plate's and the bead's triangles share outside the
/// interface `plate|bead`: none — the touch node is on the interface too,
/// so it is found as the node ending two `plate|exterior` segments and two
/// `plate|bead` segments.
fn touch_node(m: &Mesh) -> [f64; 3] {
    let ends = |name: &str| -> BTreeSet<u32> {
        fragment_segments(m, name).into_iter().flatten().collect()
    };
    let common: Vec<u32> = ends("plate|exterior")
        .intersection(&ends("plate|bead"))
        .copied()
        .collect();
    assert_eq!(
        common.len(),
        1,
        "outer boundary and hole meet at {common:?}"
    );
    for name in ["plate|exterior", "plate|bead"] {
        let uses = fragment_segments(m, name)
            .iter()
            .flatten()
            .filter(|&&n| n == common[0])
            .count();
        assert_eq!(uses, 2, "{name} around the touch node");
    }
    m.nodes[common[0] as usize]
}

/// The smallest angle of a triangle, in degrees.
fn least_angle(m: &Mesh, t: [u32; 3]) -> f64 {
    let p = t.map(|n| m.nodes[n as usize]);
    (0..3)
        .map(|i| {
            let (a, b, c) = (p[i], p[(i + 1) % 3], p[(i + 2) % 3]);
            let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
            let cos = (u[0] * v[0] + u[1] * v[1]) / (u[0].hypot(u[1]) * v[0].hypot(v[1]));
            cos.clamp(-1.0, 1.0).acos().to_degrees()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Every triangle under 30° has a corner within `reach` of the touch point
/// (where the two boundaries are closer than the chordal tolerance), at
/// least one does (the cusp), and the bead's are all at 30° or more.
fn assert_small_angles_only_at(m: &Mesh, touch: [f64; 3], reach: f64) {
    let mut small = 0;
    for t in triangles_of(m, "plate") {
        if least_angle(m, t) >= 30.0 - 1e-9 {
            continue;
        }
        small += 1;
        let near = t
            .iter()
            .map(|&n| {
                let q = m.nodes[n as usize];
                (q[0] - touch[0]).hypot(q[1] - touch[1])
            })
            .fold(f64::INFINITY, f64::min);
        assert!(near < reach, "a triangle under 30° {near} from the touch");
    }
    assert!(small > 0, "the cusp has no small angle");
    for t in triangles_of(m, "bead") {
        assert!(least_angle(m, t) >= 30.0 - 1e-9, "bead triangle {t:?}");
    }
}

/// The distance from a tangency within which two curves of curvatures
/// differing by `dk` are closer than the default chordal tolerance (1e-3
/// of the model's diagonal `diagonal`): 1.5 times √(2·tol/dk).
fn cusp_reach(diagonal: f64, dk: f64) -> f64 {
    1.5 * (2.0 * 1e-3 * diagonal / dk).sqrt()
}

#[test]
fn disk_tangent_to_a_square_side_from_inside_shares_the_touch_point() {
    let m = mesh(ON_SIDE, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["plate|exterior", "plate|bead"])
    );
    let p = touch_node(&m);
    assert_eq!(p[0], 1.0, "off the side: {p:?}");
    assert!((p[1] - 0.47).abs() < 1e-8, "touch node {p:?}");
    let shared = assert_conforming(&m, "plate|bead", "plate", "bead");
    assert!(shared >= 40, "{shared} interface nodes");
    // The bead is the polygon of its contour; the plate the square less it.
    let (plate, bead) = (
        area(&m, &triangles_of(&m, "plate")),
        area(&m, &triangles_of(&m, "bead")),
    );
    let polygon = fan_area(&m, &fragment_segments(&m, "plate|bead"), [0.7, 0.47]);
    assert!((bead - polygon).abs() < 1e-12, "{bead} vs {polygon}");
    assert!((plate + bead - 1.0).abs() < 1e-12, "plate {plate}");
    assert!(
        (bead - 0.09 * PI).abs() / (0.09 * PI) < 2e-3,
        "bead area {bead}"
    );
    // The side x = 1 and the circle r = 0.3: curvatures 0 and 1/0.3; the
    // model's box reaches x = 1.1.
    assert_small_angles_only_at(&m, p, cusp_reach(1.1f64.hypot(1.0), 1.0 / 0.3));
}

#[test]
fn bead_touching_a_kernel_circle_from_inside_shares_the_touch_point() {
    let m = mesh(IN_CIRCLE, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["plate|exterior", "plate|bead"])
    );
    let p = touch_node(&m);
    assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-12, "off the rim: {p:?}");
    assert!(
        (p[0] - 0.5).abs() < 1e-8 && (p[1] - 0.75f64.sqrt()).abs() < 1e-8,
        "touch node {p:?}"
    );
    let r = (p[0] - BEAD_X).hypot(p[1] - BEAD_Y);
    assert!((r - 0.3).abs() < 1e-8, "off the bead's circle: {p:?}");
    // Every rim node on the unit circle (the rim's cuts next to the touch
    // point are on it too).
    let rim = fragment_segments(&m, "plate|exterior");
    for &n in rim.iter().flatten() {
        let q = m.nodes[n as usize];
        assert!((q[0].hypot(q[1]) - 1.0).abs() < 1e-12, "rim node {q:?}");
    }
    assert_conforming(&m, "plate|bead", "plate", "bead");
    let (plate, bead) = (
        area(&m, &triangles_of(&m, "plate")),
        area(&m, &triangles_of(&m, "bead")),
    );
    let rim_polygon = fan_area(&m, &rim, [0.0, 0.0]);
    let bead_polygon = fan_area(&m, &fragment_segments(&m, "plate|bead"), [BEAD_X, BEAD_Y]);
    assert!(
        (bead - bead_polygon).abs() < 1e-12,
        "{bead} vs {bead_polygon}"
    );
    assert!(
        (plate - (rim_polygon - bead_polygon)).abs() < 1e-12,
        "plate {plate}"
    );
    assert!(
        (bead - 0.09 * PI).abs() / (0.09 * PI) < 2e-3,
        "bead area {bead}"
    );
    assert!((rim_polygon - PI).abs() / PI < 3e-3, "rim {rim_polygon}");
    // Curvatures 1 and 1/0.3; the model's box is the unit circle's.
    assert_small_angles_only_at(&m, p, cusp_reach(8f64.sqrt(), 1.0 / 0.3 - 1.0));
}

#[test]
fn bead_touching_a_hole_rim_from_outside_shares_the_touch_point() {
    // A square plate with a circular hole of radius 0.2 about (0.5, 0.5),
    // less a disk of radius 0.12 about (0.5, 0.82) touching the hole's rim
    // at (0.5, 0.7): the rim bends away from the bead there.
    let xml = r#"<geometry version="1" dimension="2">
  <rectangle name="sq"><first_point x="0" y="0"/><second_point x="1" y="1"/></rectangle>
  <circle name="hole"><center x="0.5" y="0.5"/><radius value="0.2"/></circle>
  <rfunction name="bead" nx="32" ny="32" x_min="0.3" x_max="0.7" y_min="0.65" y_max="0.99">
    <disk r="0.12" x0="0.5" y0="0.82"/> </rfunction>
  <subdomain name="plate"><difference><solid ref="sq"/><solid ref="hole"/><solid ref="bead"/></difference></subdomain>
  <subdomain name="bead"><solid ref="bead"/></subdomain>
</geometry>"#;
    let found = diagnostics(xml);
    assert!(found.is_empty(), "{found:#?}");
    let m = mesh(xml, 0.01);
    let shared = assert_conforming(&m, "plate|bead", "plate", "bead");
    assert!(shared >= 30, "{shared}");
    let p = touch_node(&m);
    assert!(
        (p[0] - 0.5).abs() < 1e-8 && (p[1] - 0.7).abs() < 1e-12,
        "touch node {p:?}"
    );
    let hole = fragment_segments(&m, "plate|exterior")
        .into_iter()
        .filter(|s| {
            s.iter().all(|&n| {
                let q = m.nodes[n as usize];
                ((q[0] - 0.5).hypot(q[1] - 0.5) - 0.2).abs() < 1e-12
            })
        })
        .collect::<Vec<_>>();
    let (plate, bead) = (
        area(&m, &triangles_of(&m, "plate")),
        area(&m, &triangles_of(&m, "bead")),
    );
    let polygon = fan_area(&m, &fragment_segments(&m, "plate|bead"), [0.5, 0.82]);
    let hole_polygon = fan_area(&m, &hole, [0.5, 0.5]);
    assert!((bead - polygon).abs() < 1e-12, "{bead} vs {polygon}");
    assert!(
        (plate - (1.0 - hole_polygon - polygon)).abs() < 1e-12,
        "plate {plate}"
    );
    assert!((bead - 0.0144 * PI).abs() / (0.0144 * PI) < 3e-3, "{bead}");
    // Both curves bend away from each other: curvatures 1/0.2 and 1/0.12.
    assert_small_angles_only_at(&m, p, cusp_reach(2f64.sqrt(), 5.0 + 1.0 / 0.12));
}

#[test]
fn inside_touch_groups_are_read_by_gmsh_and_meshio() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (xml, name) in [(ON_SIDE, "side"), (IN_CIRCLE, "circle")] {
        let msh = compile(xml, dir.path(), name, "0.01");
        let expected = mesh(xml, 0.01);
        let r = python("check_mesh.py", &[&msh], &[]);
        assert_groups_read(
            &r,
            &expected,
            &["plate|exterior", "plate|bead"],
            &["plate", "bead"],
        );
    }
}

#[test]
fn contour_running_close_along_a_side_from_inside_is_refused() {
    // Clipped at x = 0.9999 the bead runs 1e-4 from the side x = 1 over a
    // stretch (inside the touch distance, not on the edge): no tangency.
    let xml = ON_SIDE.replace(
        r#"<disk r="0.3" x0="0.7" y0="0.47"/>"#,
        r#"<intersection> <disk r="0.3" x0="0.8" y0="0.47"/> <formula value="0.9999 - x"/> </intersection>"#,
    );
    let found = diagnostics(&xml);
    assert_eq!(found.len(), 1, "{found:#?}");
    assert_eq!(found[0].code, Code::RegionCarveOutside);
    assert!(
        found[0].message.starts_with(
            "subdomain 'plate' subtracts region 'bead', whose contour comes within its chordal tolerance of the kernel edge 'sq.e2' from inside near (0.9999"
        ),
        "{}",
        found[0].message
    );
    assert!(
        found[0]
            .help
            .as_deref()
            .is_some_and(|h| h.starts_with("move the region clear of the kernel boundary")),
        "{:?}",
        found[0].help
    );
}
