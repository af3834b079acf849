//! Issue 6: a 2D R-function region whose contour runs along a straight
//! kernel edge and on past its end onto a collinear kernel edge (two
//! squares stacked, a polygon with a vertex on a straight side). The contour
//! piece over the joint is cut at the kernel vertex, each edge takes its run,
//! and both interfaces meet at the joint: no hanging node. Checked on the
//! interface nodes (on the line, conforming, the joint shared), the
//! interfaces' ends, the areas, the minimum angle and the MSH groups as
//! gmsh and meshio read them.

mod mesh2d_common;

use geomc::mesh::Mesh;
use mesh2d_common::{
    area, assert_conforming, assert_groups_read, assert_min_angle_30, compile_msh,
    coordinate_range, fan_area, fragment_names, fragment_segments, mesh_clean as mesh,
    min_angle_degrees, python, triangles_of,
};
use std::collections::BTreeSet;
use std::f64::consts::PI;

/// Two unit squares stacked (low below y = 1, high above) and a half disk
/// of radius 0.31 about (1, 1) right of x = 1: its flat side runs along both
/// squares' right sides, over their common vertex (1, 1).
const STACKED: &str = r#"<geometry version="1" dimension="2">
  <rectangle name="lo"><first_point x="0" y="0"/><second_point x="1" y="1"/></rectangle>
  <rectangle name="hi"><first_point x="0" y="1"/><second_point x="1" y="2"/></rectangle>
  <rfunction name="cap" nx="40" ny="40" x_min="0.5" x_max="1.5" y_min="0.5" y_max="1.5">
    <intersection> <disk r="0.31" x0="1" y0="1"/> <formula value="x - 1"/> </intersection>
  </rfunction>
  <subdomain name="low"><solid ref="lo"/></subdomain>
  <subdomain name="high"><solid ref="hi"/></subdomain>
  <subdomain name="cap"><solid ref="cap"/></subdomain>
</geometry>"#;

/// A unit square as a polygon with a fifth vertex (1, 0.5) on its right
/// side, and the half disk about that vertex.
const POLYGON: &str = r#"<geometry version="1" dimension="2">
  <polygon name="pg"><vertex x="0" y="0"/><vertex x="1" y="0"/><vertex x="1" y="0.5"/><vertex x="1" y="1"/><vertex x="0" y="1"/></polygon>
  <rfunction name="cap" nx="40" ny="40" x_min="0.5" x_max="1.5" y_min="0" y_max="1">
    <intersection> <disk r="0.31" x0="1" y0="0.5"/> <formula value="x - 1"/> </intersection>
  </rfunction>
  <subdomain name="plate"><solid ref="pg"/></subdomain>
  <subdomain name="cap"><solid ref="cap"/></subdomain>
</geometry>"#;

/// The y range of an interface on x = 1, every node on the line exactly.
fn on_the_side(m: &Mesh, fragment: &str) -> (f64, f64) {
    coordinate_range(m, &fragment_segments(m, fragment), 1, |p| {
        assert!(
            (p[0] - 1.0).abs() < 1e-12,
            "{fragment} node off x = 1: {p:?}"
        )
    })
}

fn node_at(m: &Mesh, p: [f64; 2]) -> u32 {
    let found: Vec<u32> = (0..m.nodes.len() as u32)
        .filter(|&n| {
            let q = m.nodes[n as usize];
            q[0] == p[0] && q[1] == p[1]
        })
        .collect();
    assert_eq!(found.len(), 1, "nodes at {p:?}");
    found[0]
}

#[test]
fn contour_along_two_stacked_squares_follows_onto_the_upper_side() {
    let m = mesh(STACKED, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from([
            "low|exterior",
            "high|exterior",
            "low|high",
            "low|cap",
            "high|cap",
            "cap|exterior"
        ])
    );
    let below = assert_conforming(&m, "low|cap", "low", "cap");
    let above = assert_conforming(&m, "high|cap", "high", "cap");
    assert_eq!(fragment_segments(&m, "low|cap").len() + 1, below);
    assert_eq!(fragment_segments(&m, "high|cap").len() + 1, above);
    // The interfaces meet at the squares' common vertex; the run's far ends
    // are the half disk's corners (restored by extending the last chord).
    let (lo_a, hi_a) = on_the_side(&m, "low|cap");
    let (lo_b, hi_b) = on_the_side(&m, "high|cap");
    assert_eq!((hi_a, lo_b), (1.0, 1.0));
    assert!(
        (lo_a - 0.69).abs() < 1e-4 && (hi_b - 1.31).abs() < 1e-4,
        "{lo_a}, {hi_b}"
    );
    // The joint is one node of all three subdomains.
    let joint = node_at(&m, [1.0, 1.0]);
    for sub in ["low", "high", "cap"] {
        assert!(
            triangles_of(&m, sub).iter().flatten().any(|&n| n == joint),
            "{sub} misses the joint"
        );
    }
    // Both squares keep their areas exactly; the cap is its boundary polygon.
    for sub in ["low", "high"] {
        let a = area(&m, &triangles_of(&m, sub));
        assert!((a - 1.0).abs() < 1e-12, "{sub} area {a}");
    }
    let cap = area(&m, &triangles_of(&m, "cap"));
    let outline: Vec<[u32; 2]> = ["cap|exterior", "low|cap", "high|cap"]
        .iter()
        .flat_map(|f| fragment_segments(&m, f))
        .collect();
    let polygon = fan_area(&m, &outline, [1.0, 1.0]);
    assert!((cap - polygon).abs() < 1e-12, "{cap} vs {polygon}");
    let exact = PI * 0.31 * 0.31 / 2.0;
    assert!((cap - exact).abs() / exact < 2e-3, "cap area {cap}");
    assert_min_angle_30(&m);
}

#[test]
fn contour_over_a_polygon_vertex_on_a_straight_side_shares_both_sides() {
    let m = mesh(POLYGON, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["plate|exterior", "plate|cap", "cap|exterior"])
    );
    let nodes = assert_conforming(&m, "plate|cap", "plate", "cap");
    let interface = fragment_segments(&m, "plate|cap");
    // One open chain through the polygon's vertex (1, 0.5).
    assert_eq!(interface.len() + 1, nodes);
    let vertex = node_at(&m, [1.0, 0.5]);
    assert!(interface.iter().flatten().any(|&n| n == vertex));
    let (lo, hi) = on_the_side(&m, "plate|cap");
    assert!(
        (lo - 0.19).abs() < 1e-4 && (hi - 0.81).abs() < 1e-4,
        "{lo}..{hi}"
    );
    let plate = area(&m, &triangles_of(&m, "plate"));
    assert!((plate - 1.0).abs() < 1e-12, "plate area {plate}");
    let cap = area(&m, &triangles_of(&m, "cap"));
    let outline: Vec<[u32; 2]> = ["cap|exterior", "plate|cap"]
        .iter()
        .flat_map(|f| fragment_segments(&m, f))
        .collect();
    assert!((cap - fan_area(&m, &outline, [1.0, 0.5])).abs() < 1e-12);
    assert!(min_angle_degrees(&m) >= 30.0 - 1e-9);
}

#[test]
fn msh_of_the_stacked_squares_keeps_its_groups_for_gmsh_and_meshio() {
    let dir = tempfile::tempdir().expect("tempdir");
    let msh = compile_msh(STACKED, dir.path(), "stacked", "0.01");
    let expected = mesh(STACKED, 0.01);
    let r = python("check_mesh.py", &[&msh], &[]);
    assert_groups_read(
        &r,
        &expected,
        &["low|cap", "high|cap", "low|high", "cap|exterior"],
        &["low", "high", "cap"],
    );
    assert_eq!(r["gmsh"]["nodes"], expected.nodes.len() as u64);
}
