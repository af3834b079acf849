//! Issue 6: 2D R-function regions whose contour runs along a curved kernel
//! edge (a material patch against the outer circle or a hole, a coating
//! around a kernel disk). The run of contour pieces is replaced by the kernel
//! arc, split at the run's ends, so both faces use one set of edges: the
//! meshes share their nodes there and every node on the arc lies on the true
//! circle. Checked on areas (against closed forms, and the subdomains
//! summing to the domain), the interface's nodes in both subdomains'
//! triangles, the minimum angle, the fragments, the MSH groups as gmsh and
//! meshio read them, and a scikit-fem solve whose flux is continuous across
//! the interface (the tools are installed by ./scripts/test.sh).

mod mesh2d_common;

use geomc::driver::{Options, check_source};
use geomc::mesh::Mesh;
use geomc::meshing::mesh_model;
use geomc::span::SourceFile;
use mesh2d_common::{
    area, assert_conforming, at_30_degrees, fragment_segments, gmsh_group, min_angle_degrees,
    python, triangles_of,
};
use std::collections::BTreeSet;
use std::f64::consts::PI;
use std::path::Path;
use std::process::Command;

/// The unit disk less the patch x ≥ 0.5 of it, carved: the patch's arc lies
/// on the disk's rim.
const SEGMENT: &str = r#"<geometry version="1" dimension="2">
  <circle name="disk"><center x="0" y="0"/><radius value="1"/></circle>
  <rfunction name="patch" nx="40" ny="40" x_min="0.4" x_max="1.1" y_min="-1.1" y_max="1.1">
    <intersection> <disk r="1" x0="0" y0="0"/> <formula value="x - 0.5"/> </intersection>
  </rfunction>
  <subdomain name="plate"><difference><solid ref="disk"/><solid ref="patch"/></difference></subdomain>
  <subdomain name="patch"><solid ref="patch"/></subdomain>
</geometry>"#;

/// A square plate with a hole of radius 0.3 and a half-ring patch
/// 0.3 ≤ r ≤ 0.6, x ≥ 0 against the hole, carved from the plate.
const HOLE: &str = r#"<geometry version="1" dimension="2">
  <rectangle name="sq"><first_point x="-1" y="-1"/><second_point x="1" y="1"/></rectangle>
  <circle name="hole"><center x="0" y="0"/><radius value="0.3"/></circle>
  <rfunction name="patch" nx="40" ny="40" x_min="-0.11" x_max="0.7" y_min="-0.7" y_max="0.7">
    <intersection> <disk r="0.6" x0="0" y0="0"/> <formula value="x"/>
      <formula value="x*x + y*y - 0.09"/> </intersection>
  </rfunction>
  <subdomain name="plate"><difference><solid ref="sq"/><solid ref="hole"/><solid ref="patch"/></difference></subdomain>
  <subdomain name="patch"><solid ref="patch"/></subdomain>
</geometry>"#;

/// A kernel disk of radius 0.5 inside a ring 0.5 ≤ r ≤ 0.8: neighbours, no
/// carve; the ring's inner contour is the disk's whole rim.
const COAT: &str = r#"<geometry version="1" dimension="2">
  <circle name="core_disk"><center x="0" y="0"/><radius value="0.5"/></circle>
  <rfunction name="coat" nx="40" ny="40" x_min="-1" x_max="1" y_min="-1" y_max="1">
    <difference> <disk r="0.8" x0="0" y0="0"/> <disk r="0.5" x0="0" y0="0"/> </difference>
  </rfunction>
  <subdomain name="core"><solid ref="core_disk"/></subdomain>
  <subdomain name="coat"><solid ref="coat"/></subdomain>
</geometry>"#;

fn mesh(xml: &str, max_area: f64) -> Mesh {
    let checked = check_source(
        SourceFile::new("t.xml", xml.to_string()),
        &Options::default(),
    );
    assert!(
        checked.diagnostics.items.is_empty(),
        "{:#?}",
        checked.diagnostics.items
    );
    let model = checked.lowered.expect("a model").model;
    mesh_model(&model, &at_30_degrees(Some(max_area))).expect("meshes")
}

fn fragment_names(m: &Mesh) -> BTreeSet<&str> {
    m.fragments.iter().map(|f| f.name.as_str()).collect()
}

/// The distance of node n from the origin.
fn radius(m: &Mesh, n: u32) -> f64 {
    let p = m.nodes[n as usize];
    p[0].hypot(p[1])
}

/// The area of the polygon of `segments` seen from the origin (a boundary
/// star-shaped about it, such as a circle's chords).
fn fan_area(m: &Mesh, segments: &[[u32; 2]]) -> f64 {
    segments
        .iter()
        .map(|s| {
            let (p, q) = (m.nodes[s[0] as usize], m.nodes[s[1] as usize]);
            0.5 * (p[0] * q[1] - p[1] * q[0]).abs()
        })
        .sum()
}

fn assert_min_angle(m: &Mesh) {
    let least = min_angle_degrees(m);
    assert!(least >= 30.0 - 1e-9, "min angle {least}");
}

#[test]
fn patch_against_the_outer_circle_shares_its_line_and_keeps_the_arc_on_the_circle() {
    let m = mesh(SEGMENT, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["plate|exterior", "plate|patch", "patch|exterior"])
    );
    // Every rim node, on either side of the split, lies on the unit circle.
    let rim: Vec<[u32; 2]> = ["plate|exterior", "patch|exterior"]
        .iter()
        .flat_map(|f| fragment_segments(&m, f))
        .collect();
    for &n in rim.iter().flatten() {
        assert!(
            (radius(&m, n) - 1.0).abs() < 1e-12,
            "rim node r = {}",
            radius(&m, n)
        );
    }
    // The interface is the chord x = 0.5, an open chain between the circle's
    // points (0.5, ±√0.75).
    let interface = fragment_segments(&m, "plate|patch");
    let nodes = assert_conforming(&m, "plate|patch", "plate", "patch");
    assert_eq!(interface.len() + 1, nodes);
    let ys: Vec<f64> = interface
        .iter()
        .flatten()
        .map(|&n| {
            let p = m.nodes[n as usize];
            assert!(
                (p[0] - 0.5).abs() < 1e-9,
                "interface node off x = 0.5: {p:?}"
            );
            p[1]
        })
        .collect();
    let (lo, hi) = ys
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &y| {
            (l.min(y), h.max(y))
        });
    let end = 0.75f64.sqrt();
    assert!(
        (lo + end).abs() < 1e-9 && (hi - end).abs() < 1e-9,
        "{lo}..{hi}"
    );
    let (patch, plate) = (
        area(&m, &triangles_of(&m, "patch")),
        area(&m, &triangles_of(&m, "plate")),
    );
    let exact = PI / 3.0 - 0.75f64.sqrt() / 2.0;
    assert!((patch - exact).abs() / exact < 2e-3, "patch area {patch}");
    assert!(
        (plate - (PI - exact)).abs() / PI < 2e-3,
        "plate area {plate}"
    );
    // Together they fill the disk's inscribed polygon exactly.
    let domain = fan_area(&m, &rim);
    assert!(
        (patch + plate - domain).abs() < 1e-12,
        "{} vs {domain}",
        patch + plate
    );
    assert_min_angle(&m);
}

#[test]
fn patch_against_a_hole_splits_the_hole_rim() {
    let m = mesh(HOLE, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["plate|exterior", "plate|patch", "patch|exterior"])
    );
    // The patch's outer boundary is the right half of the hole's rim; the
    // plate keeps the left half and the square.
    let patch_rim = fragment_segments(&m, "patch|exterior");
    for &n in patch_rim.iter().flatten() {
        assert!((radius(&m, n) - 0.3).abs() < 1e-12, "r = {}", radius(&m, n));
        assert!(m.nodes[n as usize][0] > -1e-9, "on the left half");
    }
    let hole: Vec<[u32; 2]> = fragment_segments(&m, "plate|exterior")
        .into_iter()
        .filter(|s| s.iter().all(|&n| (radius(&m, n) - 0.3).abs() < 1e-12))
        .chain(patch_rim.iter().copied())
        .collect();
    // The interface: the arc r = 0.6 and the two pieces of x = 0.
    let nodes = assert_conforming(&m, "plate|patch", "plate", "patch");
    let interface = fragment_segments(&m, "plate|patch");
    assert_eq!(interface.len() + 1, nodes);
    for &n in interface.iter().flatten() {
        let p = m.nodes[n as usize];
        let on_arc = (radius(&m, n) - 0.6).abs() < 1e-9;
        assert!(on_arc || p[0].abs() < 1e-9, "interface node {p:?}");
    }
    let (patch, plate) = (
        area(&m, &triangles_of(&m, "patch")),
        area(&m, &triangles_of(&m, "plate")),
    );
    let exact = PI / 2.0 * (0.36 - 0.09);
    assert!((patch - exact).abs() / exact < 2e-3, "patch area {patch}");
    let domain = 4.0 - fan_area(&m, &hole);
    assert!(
        (plate - (domain - exact)).abs() / domain < 2e-3,
        "plate area {plate}"
    );
    assert!(
        (patch + plate - domain).abs() < 1e-12,
        "{} vs {domain}",
        patch + plate
    );
    assert_min_angle(&m);
}

#[test]
fn coating_around_a_kernel_disk_uses_the_disk_rim() {
    let m = mesh(COAT, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["core|coat", "coat|exterior"])
    );
    let interface = fragment_segments(&m, "core|coat");
    let nodes = assert_conforming(&m, "core|coat", "core", "coat");
    // A closed loop on the circle r = 0.5.
    assert_eq!(interface.len(), nodes);
    for &n in interface.iter().flatten() {
        assert!((radius(&m, n) - 0.5).abs() < 1e-12, "r = {}", radius(&m, n));
    }
    let outer = fragment_segments(&m, "coat|exterior");
    for &n in outer.iter().flatten() {
        assert!((radius(&m, n) - 0.8).abs() < 1e-9, "r = {}", radius(&m, n));
    }
    let (core, coat) = (
        area(&m, &triangles_of(&m, "core")),
        area(&m, &triangles_of(&m, "coat")),
    );
    // The core is exactly the polygon of its rim nodes; the ring is what is
    // left of the outer contour's polygon.
    let inner = fan_area(&m, &interface);
    assert!((core - inner).abs() < 1e-12, "core area {core} vs {inner}");
    // The rim's chords follow the model's chordal tolerance (1e-3 of the
    // box diagonal, about 48 chords): a regular 48-gon is 2.85e-3 short.
    assert!(
        (core - PI * 0.25).abs() / (PI * 0.25) < 4e-3,
        "core area {core}"
    );
    let ring = PI * (0.64 - 0.25);
    assert!((coat - ring).abs() / ring < 2e-3, "coat area {coat}");
    assert!((core + coat - fan_area(&m, &outer)).abs() < 1e-12);
    assert_min_angle(&m);
}

fn compile(xml: &str, dir: &Path, name: &str, max_area: &str) -> std::path::PathBuf {
    let input = dir.join(format!("{name}.xml"));
    std::fs::write(&input, xml).expect("write input");
    let msh = dir.join(format!("{name}.msh"));
    let status = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(["compile", "-q"])
        .arg(&input)
        .args(["--min-angle", "30", "--max-area", max_area, "-o"])
        .arg(&msh)
        .status()
        .expect("run geomc");
    assert!(status.success(), "geomc compile {name}");
    msh
}

#[test]
fn msh_of_a_patch_against_a_hole_keeps_its_groups_for_gmsh_and_meshio() {
    let dir = tempfile::tempdir().expect("tempdir");
    let msh = compile(HOLE, dir.path(), "hole", "0.01");
    let expected = mesh(HOLE, 0.01);
    let r = python("check_mesh.py", &[&msh], &[]);
    for group in ["plate|patch", "patch|exterior", "plate|exterior"] {
        let lines = fragment_segments(&expected, group).len() as u64;
        assert_eq!(gmsh_group(&r, group)["elements"]["line"], lines, "{group}");
        assert_eq!(r["meshio"]["cell_sets"][group], lines, "{group}");
    }
    for sub in ["plate", "patch"] {
        assert_eq!(
            gmsh_group(&r, sub)["elements"]["triangle"],
            triangles_of(&expected, sub).len() as u64
        );
    }
    assert_eq!(r["gmsh"]["nodes"], expected.nodes.len() as u64);
}

#[test]
fn patch_against_the_circle_keeps_the_flux_continuous_across_the_interface() {
    // k = 1 for x < 0.5 (the plate) and 10 beyond (the patch), u = 0 on the
    // circle: the normal flux k ∂u/∂x agrees on both sides of x = 0.5.
    let dir = tempfile::tempdir().expect("tempdir");
    let outer = ["plate|exterior", "patch|exterior"];
    // Stated tolerance: the two sides' fluxes agree within 3%. The elements
    // along the interface are sized by the contour's pieces (about 0.008
    // apart), which an area limit does not change, so a finer limit does
    // not shrink the jump; both meshes must hold it.
    for (name, max_area) in [("coarse", "0.01"), ("fine", "0.0025")] {
        let msh = compile(SEGMENT, dir.path(), name, max_area);
        let r = python("fem_poisson.py", &[&msh], &["twomat", outer[0], outer[1]]);
        let jump = r["flux_jump"].as_f64().expect("flux_jump");
        assert!(jump < 0.03, "{name}: flux jump {jump}");
        // Both outer groups were found and pinned (the rim's nodes).
        assert!(r["fixed"].as_u64().expect("fixed") > 40, "{r}");
    }
}

fn diagnostics(xml: &str) -> Vec<geomc::diag::Diagnostic> {
    check_source(
        SourceFile::new("t.xml", xml.to_string()),
        &Options::default(),
    )
    .diagnostics
    .items
}

#[test]
fn a_region_touching_a_kernel_circle_at_a_point_is_refused_naming_the_curved_edge() {
    // A disk of radius 0.3 against the kernel circle r = 0.5 at (0.5, 0):
    // its contour meets the rim in one point, it does not run along it.
    let xml = r#"<geometry version="1" dimension="2">
      <circle name="core_disk"><center x="0" y="0"/><radius value="0.5"/></circle>
      <rfunction name="bead" nx="32" ny="32" x_min="0.4" x_max="1.2" y_min="-0.4" y_max="0.4">
        <disk r="0.3" x0="0.8" y0="0"/> </rfunction>
      <subdomain name="core"><solid ref="core_disk"/></subdomain>
      <subdomain name="bead"><solid ref="bead"/></subdomain>
    </geometry>"#;
    let found = diagnostics(xml);
    assert_eq!(found.len(), 1, "{found:#?}");
    let d = &found[0];
    assert_eq!(d.code, geomc::diag::Code::RegionTouches);
    assert!(
        d.message.starts_with(
            "region 'bead' touches the curved edge 'core_disk.rim' of subdomain 'core' at (0.5"
        ),
        "{}",
        d.message
    );
    assert!(
        d.message.ends_with(
            "without running along it: a contour shares a curved edge only where its points lie on that curve"
        ),
        "{}",
        d.message
    );
    assert_eq!(
        d.help.as_deref(),
        Some(
            "let the region's R-function contain the same circle or ellipse as the kernel edge, so its contour lies on it, or move the region clear of the edge"
        )
    );
    assert!(d.span.is_some(), "located");
}

#[test]
fn two_touching_regions_are_refused_naming_both_and_the_fix() {
    let xml = r#"<geometry version="1" dimension="2">
      <rfunction name="left" nx="32" ny="32" x_min="-1" x_max="0" y_min="-1" y_max="1">
        <disk r="0.5" x0="0" y0="0"/> </rfunction>
      <rfunction name="right" nx="32" ny="32" x_min="0" x_max="1" y_min="-1" y_max="1">
        <disk r="0.5" x0="0" y0="0"/> </rfunction>
      <subdomain name="left"><solid ref="left"/></subdomain>
      <subdomain name="right"><solid ref="right"/></subdomain>
    </geometry>"#;
    let touching: Vec<_> = diagnostics(xml)
        .into_iter()
        .filter(|d| d.code == geomc::diag::Code::RegionTouches)
        .collect();
    assert_eq!(touching.len(), 1, "{touching:#?}");
    let d = &touching[0];
    assert!(
        d.message
            .starts_with("region 'left' touches region 'right' at (0.000000, ")
            && d.message
                .ends_with(": two R-function regions do not share interface edges"),
        "{}",
        d.message
    );
    assert_eq!(
        d.help.as_deref(),
        Some(
            "move them apart, or make one of them a kernel shape (a circle, polygon or rectangle): a region's contour on a kernel edge becomes their interface"
        )
    );
}

#[test]
fn a_region_on_a_kernel_disk_without_a_carve_is_an_overlap() {
    // The region is the kernel disk itself: its whole contour becomes the
    // disk's rim, run the same way by both faces, so both cover the disk.
    let twin = COAT.replace(
        r#"<difference> <disk r="0.8" x0="0" y0="0"/> <disk r="0.5" x0="0" y0="0"/> </difference>"#,
        r#"<disk r="0.5" x0="0" y0="0"/>"#,
    );
    let found = diagnostics(&twin);
    assert_eq!(found.len(), 1, "{found:#?}");
    assert_eq!(found[0].code, geomc::diag::Code::SubdomainsOverlap);
    assert!(
        found[0]
            .message
            .starts_with("region 'coat' and subdomain 'core' overlap at ("),
        "{}",
        found[0].message
    );
}
