//! Issue 6: two 2D R-function regions whose contours' runs along each other
//! do not pair one to one. A notch in one region cuts the stretch it shares
//! with its neighbour in two (the neighbour's one run lies along two runs),
//! a ring around two half disks lies along both with one loop, and a ring
//! around a disk with bumps left out meets it in four stretches. The
//! earlier contour is split where the later one leaves it, so the meshes
//! share their nodes there. Checked on the shared nodes (on the curves, the
//! corners found), areas adding up, the minimum angle, and the MSH groups as
//! gmsh and meshio read them.

mod mesh2d_common;

use geomc::mesh::Mesh;
use mesh2d_common::{
    area, assert_conforming, assert_groups_read, assert_min_angle_30, compile_msh as compile,
    coordinate_range, fan_area, fragment_names, fragment_segments, mesh_clean as mesh, python,
    sides, triangles_of,
};
use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::PI;

/// The unit disk cut along x = 0.5; the right part has a half-disk notch of
/// radius 0.3 centred on the cut (the fixture).
const NOTCHED: &str = include_str!("../fixtures/valid/2d_regions_notched_interface.xml");

/// Two half disks of radius 0.5 and a ring 0.5 ≤ r ≤ 0.8 around both, on
/// different grids: the ring's inner loop lies along two regions.
const RING_AROUND_HALVES: &str = r#"<geometry version="1" dimension="2">
  <rfunction name="west" nx="40" ny="40" x_min="-1" x_max="0.3" y_min="-1" y_max="1">
    <intersection> <disk r="0.5" x0="0" y0="0"/> <formula value="-x"/> </intersection> </rfunction>
  <rfunction name="east" nx="40" ny="40" x_min="-0.3" x_max="1" y_min="-1" y_max="1">
    <intersection> <disk r="0.5" x0="0" y0="0"/> <formula value="x"/> </intersection> </rfunction>
  <rfunction name="coat" nx="37" ny="37" x_min="-1" x_max="1" y_min="-1" y_max="1">
    <difference> <disk r="0.8" x0="0" y0="0"/> <disk r="0.5" x0="0" y0="0"/> </difference>
  </rfunction>
  <subdomain name="west"><solid ref="west"/></subdomain>
  <subdomain name="east"><solid ref="east"/></subdomain>
  <subdomain name="coat"><solid ref="coat"/></subdomain>
</geometry>"#;

/// A disk of radius 0.5 and a ring 0.5 ≤ r ≤ 0.8 around it with four
/// bumps of radius 0.12 centred on r = 0.5 left out: the two contours run
/// along each other in four stretches, each broken off by a bump.
const BUMPED_RING: &str = r#"<geometry version="1" dimension="2">
  <rfunction name="core" nx="40" ny="40" x_min="-1" x_max="1" y_min="-1" y_max="1">
    <disk r="0.5" x0="0" y0="0"/> </rfunction>
  <rfunction name="coat" nx="37" ny="37" x_min="-1" x_max="1" y_min="-1" y_max="1">
    <difference> <disk r="0.8" x0="0" y0="0"/>
      <union> <disk r="0.5" x0="0" y0="0"/> <disk r="0.12" x0="0.5" y0="0"/> <disk r="0.12" x0="-0.5" y0="0"/>
        <disk r="0.12" x0="0" y0="0.5"/> <disk r="0.12" x0="0" y0="-0.5"/> </union>
    </difference>
  </rfunction>
  <subdomain name="core"><solid ref="core"/></subdomain>
  <subdomain name="coat"><solid ref="coat"/></subdomain>
</geometry>"#;

fn radius(m: &Mesh, n: u32) -> f64 {
    let p = m.nodes[n as usize];
    p[0].hypot(p[1])
}

/// The area enclosed by the outer boundary of `subdomains`: their sides
/// used by one of their triangles only, each taken the way its
/// (counter-clockwise) triangle runs it. Equal to their area exactly only if
/// the named fragments hold all of those sides (no gap between them).
fn outline_area(m: &Mesh, subdomains: &[&str], fragments: &[&str]) -> f64 {
    let tris: Vec<[u32; 3]> = subdomains.iter().flat_map(|s| triangles_of(m, s)).collect();
    let mut uses: BTreeMap<[u32; 2], usize> = BTreeMap::new();
    for t in &tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    let outer: BTreeSet<[u32; 2]> = fragments
        .iter()
        .flat_map(|f| fragment_segments(m, f))
        .map(|[a, b]| [a.min(b), a.max(b)])
        .collect();
    let mut total = 0.0;
    for t in &tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let key = [a.min(b), a.max(b)];
            if uses[&key] == 1 {
                assert!(outer.contains(&key), "boundary side {key:?} in no fragment");
                let (p, q) = (m.nodes[a as usize], m.nodes[b as usize]);
                total += 0.5 * (p[0] * q[1] - q[0] * p[1]);
            }
        }
    }
    assert_eq!(
        outer.len(),
        uses.values().filter(|&&u| u == 1).count(),
        "fragment sides inside"
    );
    total
}

#[test]
fn a_notch_splits_the_shared_stretch_at_its_corners() {
    let m = mesh(NOTCHED, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["left|exterior", "left|right", "right|exterior"])
    );
    // Two open chains on x = 0.5: above and below the notch.
    let interface = fragment_segments(&m, "left|right");
    let nodes = assert_conforming(&m, "left|right", "left", "right");
    assert_eq!(interface.len() + 2, nodes);
    assert!(nodes >= 20, "{nodes} shared nodes");
    let (lo, hi) = coordinate_range(&m, &interface, 1, |p| {
        assert!(
            (p[0] - 0.5).abs() < 1e-12,
            "interface node off x = 0.5: {p:?}"
        );
        assert!(
            p[1].abs() >= 0.3 - 1e-12,
            "interface node in the notch: {p:?}"
        );
    });
    // The chains end at the true corners: on the circle and at the notch.
    let end = 0.75f64.sqrt();
    assert!(
        (lo + end).abs() < 1e-12 && (hi - end).abs() < 1e-12,
        "{lo}..{hi}"
    );
    let inner = interface
        .iter()
        .flatten()
        .map(|&n| m.nodes[n as usize][1].abs())
        .fold(f64::INFINITY, f64::min);
    assert!((inner - 0.3).abs() < 1e-12, "notch corner at |y| = {inner}");
    // Between the notch's corners x = 0.5 is the left region's own boundary.
    let notch_side: Vec<[u32; 2]> = fragment_segments(&m, "left|exterior")
        .into_iter()
        .filter(|s| {
            s.iter()
                .all(|&n| (m.nodes[n as usize][0] - 0.5).abs() < 1e-12)
        })
        .collect();
    let (nlo, nhi) = coordinate_range(&m, &notch_side, 1, |_| {});
    assert!(
        (nlo + 0.3).abs() < 1e-12 && (nhi - 0.3).abs() < 1e-12,
        "{nlo}..{nhi}"
    );
    let (left, right) = (
        area(&m, &triangles_of(&m, "left")),
        area(&m, &triangles_of(&m, "right")),
    );
    let cap = PI / 3.0 - end / 2.0;
    let notched = cap - PI * 0.09 / 2.0;
    assert!((left - (PI - cap)).abs() / PI < 2e-3, "left area {left}");
    assert!(
        (right - notched).abs() / notched < 2e-3,
        "right area {right}"
    );
    // No gap and no overlap: together the polygon of the exterior fragments.
    let domain = outline_area(&m, &["left", "right"], &["left|exterior", "right|exterior"]);
    assert!(
        (left + right - domain).abs() < 1e-12,
        "{} vs {domain}",
        left + right
    );
    assert_min_angle_30(&m);
}

#[test]
fn a_ring_around_two_half_disks_shares_its_inner_loop_with_both() {
    let m = mesh(RING_AROUND_HALVES, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["west|east", "west|coat", "east|coat", "coat|exterior"])
    );
    assert_conforming(&m, "west|east", "west", "east");
    let mut arcs = Vec::new();
    for (fragment, half) in [("west|coat", "west"), ("east|coat", "east")] {
        let arc = fragment_segments(&m, fragment);
        // Each half's arc is one open chain shared with the ring.
        let shared_sides = sides(&triangles_of(&m, "coat"));
        let nodes: BTreeSet<u32> = arc.iter().flatten().copied().collect();
        assert_eq!(arc.len() + 1, nodes.len(), "{fragment} one chain");
        assert!(nodes.len() >= 40, "{fragment}: {} nodes", nodes.len());
        for s in &arc {
            assert!(shared_sides.contains(&[s[0].min(s[1]), s[0].max(s[1])]));
            assert!(sides(&triangles_of(&m, half)).contains(&[s[0].min(s[1]), s[0].max(s[1])]));
        }
        // On r = 0.5; the two triple points (0, ±0.5), restored on the
        // straight west|east interface from the contour's parabola, to 1e-9.
        for &n in &nodes {
            let p = m.nodes[n as usize];
            let tolerance = if p[0].abs() < 1e-12 { 1e-9 } else { 1e-12 };
            assert!(
                (radius(&m, n) - 0.5).abs() < tolerance,
                "{fragment} node {p:?}"
            );
        }
        arcs.extend(arc);
    }
    // The three interfaces meet at two triple points on x = 0.
    let ends = |segments: &[[u32; 2]]| -> BTreeSet<u32> {
        let mut count: BTreeMap<u32, usize> = BTreeMap::new();
        for &n in segments.iter().flatten() {
            *count.entry(n).or_default() += 1;
        }
        count
            .into_iter()
            .filter(|&(_, c)| c == 1)
            .map(|(n, _)| n)
            .collect()
    };
    let straight = ends(&fragment_segments(&m, "west|east"));
    assert_eq!(straight.len(), 2);
    assert_eq!(straight, ends(&fragment_segments(&m, "west|coat")));
    assert_eq!(straight, ends(&fragment_segments(&m, "east|coat")));
    for &n in &straight {
        let p = m.nodes[n as usize];
        assert!(
            p[0].abs() < 1e-12 && (p[1].abs() - 0.5).abs() < 1e-9,
            "{p:?}"
        );
    }
    let (west, east, coat) = (
        area(&m, &triangles_of(&m, "west")),
        area(&m, &triangles_of(&m, "east")),
        area(&m, &triangles_of(&m, "coat")),
    );
    let half = PI * 0.125;
    assert!((west - half).abs() / half < 2e-3, "west {west}");
    assert!((east - half).abs() / half < 2e-3, "east {east}");
    let ring = PI * (0.64 - 0.25);
    assert!((coat - ring).abs() / ring < 2e-3, "coat {coat}");
    // The halves fill the ring's hole, the three the outer circle.
    assert!((west + east - fan_area(&m, &arcs, [0.0, 0.0])).abs() < 1e-12);
    let outer = fragment_segments(&m, "coat|exterior");
    assert!((west + east + coat - fan_area(&m, &outer, [0.0, 0.0])).abs() < 1e-12);
    assert_min_angle_30(&m);
}

#[test]
fn a_ring_with_bumps_shares_four_stretches_ending_at_the_bumps() {
    let m = mesh(BUMPED_RING, 0.01);
    assert_eq!(
        fragment_names(&m),
        BTreeSet::from(["core|exterior", "core|coat", "coat|exterior"])
    );
    // Four open chains on r = 0.5, each ending where a bump meets the circle.
    let interface = fragment_segments(&m, "core|coat");
    let nodes = assert_conforming(&m, "core|coat", "core", "coat");
    assert_eq!(interface.len() + 4, nodes);
    for &n in interface.iter().flatten() {
        assert!((radius(&m, n) - 0.5).abs() < 1e-12, "r = {}", radius(&m, n));
    }
    let bumps = [[0.5, 0.0], [-0.5, 0.0], [0.0, 0.5], [0.0, -0.5]];
    let mut count: BTreeMap<u32, usize> = BTreeMap::new();
    for &n in interface.iter().flatten() {
        *count.entry(n).or_default() += 1;
    }
    let ends: Vec<u32> = count
        .into_iter()
        .filter(|&(_, c)| c == 1)
        .map(|(n, _)| n)
        .collect();
    assert_eq!(ends.len(), 8);
    for n in ends {
        let p = m.nodes[n as usize];
        let to_bump = bumps
            .iter()
            .map(|c| (p[0] - c[0]).hypot(p[1] - c[1]))
            .fold(f64::INFINITY, f64::min);
        assert!((to_bump - 0.12).abs() < 1e-9, "corner {p:?}: {to_bump}");
    }
    // The core's rim inside the bumps is its own boundary.
    for &n in fragment_segments(&m, "core|exterior").iter().flatten() {
        assert!((radius(&m, n) - 0.5).abs() < 1e-12, "r = {}", radius(&m, n));
    }
    let (core, coat) = (
        area(&m, &triangles_of(&m, "core")),
        area(&m, &triangles_of(&m, "coat")),
    );
    assert!((core - PI * 0.25).abs() / (PI * 0.25) < 2e-3, "core {core}");
    // Each bump's part outside the core: its disk less the lens they share.
    let (r, big, d) = (0.12f64, 0.5f64, 0.5f64);
    let lens = r * r * ((d * d + r * r - big * big) / (2.0 * d * r)).acos()
        + big * big * ((d * d + big * big - r * r) / (2.0 * d * big)).acos()
        - 0.5 * ((-d + r + big) * (d + r - big) * (d - r + big) * (d + r + big)).sqrt();
    let ring = PI * (0.64 - 0.25) - 4.0 * (PI * r * r - lens);
    assert!((coat - ring).abs() / ring < 2e-3, "coat {coat} vs {ring}");
    let domain = outline_area(&m, &["core", "coat"], &["core|exterior", "coat|exterior"]);
    assert!(
        (core + coat - domain).abs() < 1e-12,
        "{} vs {domain}",
        core + coat
    );
    assert_min_angle_30(&m);
}

#[test]
fn msh_of_split_stretches_keeps_the_groups_for_gmsh_and_meshio() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (name, xml, groups, subdomains) in [
        (
            "notched",
            NOTCHED,
            &["left|right", "left|exterior", "right|exterior"][..],
            &["left", "right"][..],
        ),
        (
            "ring",
            RING_AROUND_HALVES,
            &["west|east", "west|coat", "east|coat", "coat|exterior"][..],
            &["west", "east", "coat"][..],
        ),
    ] {
        let msh = compile(xml, dir.path(), name, "0.01");
        let expected = mesh(xml, 0.01);
        let r = python("check_mesh.py", &[&msh], &[]);
        assert_groups_read(&r, &expected, groups, subdomains);
        assert_eq!(r["gmsh"]["nodes"], expected.nodes.len() as u64, "{name}");
    }
}
