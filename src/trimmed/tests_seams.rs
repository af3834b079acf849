//! Poles (degenerate sides closed by a fan) and seams closed both ways.

use super::tests::check_manifold;
use super::*;
use crate::implicit::ir::Ctx;
use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

fn settings(max_edge: f64) -> TrimSettings {
    TrimSettings {
        tolerance: 0.002,
        min_angle: 20.0,
        max_edge,
    }
}

fn sphere(radius: f64, latitudes: [f64; 2], trim: Option<Trim>) -> TrimmedSurface {
    TrimmedSurface {
        name: "ball".into(),
        carrier: Carrier::Sphere { radius },
        frame: Frame::identity(),
        rect: [
            latitudes[0].to_radians(),
            latitudes[1].to_radians(),
            0.0,
            TAU,
        ],
        trim,
    }
}

/// V − E + F of the triangles.
fn euler(m: &TrimmedMesh) -> i64 {
    let mut edges = BTreeSet::new();
    let mut used = BTreeSet::new();
    for t in &m.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.insert((a.min(b), a.max(b)));
            used.insert(a);
        }
    }
    used.len() as i64 - edges.len() as i64 + m.triangles.len() as i64
}

/// F = |p − c|² − ρ²: material outside the ball.
fn outside_ball(c: [f64; 3], rho: f64) -> Trim {
    let mut x = Ctx::new();
    let mut sum = x.constant(-rho * rho);
    for (axis, &ci) in c.iter().enumerate() {
        let v = x.var(axis as u8);
        let k = x.constant(ci);
        let d = x.sub(v, k);
        let d2 = x.square(d);
        sum = x.add(sum, d2);
    }
    Trim::new(&x, sum, false)
}

/// F = k − y: material below the plane y = k.
fn below(k: f64) -> Trim {
    let mut x = Ctx::new();
    let y = x.var(1);
    let c = x.constant(k);
    let f = x.sub(c, y);
    Trim::new(&x, f, false)
}

/// A whole sphere of radius `r` about the y axis: one node per pole, the
/// area 4πr² within 2e-3, minimum angle 20°, centroids within 0.002.
fn check_whole_sphere(s: &TrimmedSurface, m: &TrimmedMesh, r: f64) -> TrimmedQuality {
    let poles = m
        .nodes
        .iter()
        .filter(|p| (p.y.abs() - r).abs() < 1e-9)
        .count();
    assert_eq!(poles, 2);
    let q = m.quality(s);
    let exact = 2.0 * TAU * r * r;
    assert!(
        (q.area - exact).abs() / exact < 2e-3,
        "{} vs {exact}",
        q.area
    );
    assert!(q.min_angle >= 20.0, "{q:?}");
    assert!(q.max_centroid_distance <= 0.002, "{q:?}");
    q
}

#[test]
fn full_sphere_is_closed_with_one_vertex_per_pole() {
    let r = 1.5;
    let s = sphere(r, [-90.0, 90.0], None);
    let m = mesh_trimmed(&s, settings(0.15)).expect("meshable");
    assert_eq!(check_manifold(&m), 0, "no boundary segments");
    assert!(m.boundary.is_empty(), "{:?}", m.boundary.len());
    assert_eq!(euler(&m), 2);
    for p in &m.nodes {
        assert!((p.coords.norm() - r).abs() < 1e-9, "{p}");
    }
    let q = check_whole_sphere(&s, &m, r);
    eprintln!("full sphere: {} triangles, {q:?}", m.triangles.len());
}

#[test]
fn sphere_zone_reaching_high_latitudes() {
    // −20° … 75°: no pole, but the rings at 75° are a quarter of the equator.
    let s = sphere(1.0, [-20.0, 75.0], None);
    let m = mesh_trimmed(&s, settings(0.1)).expect("meshable");
    check_manifold(&m);
    assert_eq!(m.boundary.len(), 2);
    let q = m.quality(&s);
    let exact = TAU * (75f64.to_radians().sin() + 20f64.to_radians().sin());
    assert!(
        (q.area - exact).abs() / exact < 3e-3,
        "{} vs {exact}",
        q.area
    );
    assert!(q.min_angle >= 20.0, "{q:?}");
    eprintln!("zone to 75°: {} triangles, {q:?}", m.triangles.len());
}

#[test]
fn sphere_with_the_north_cap_cut_away_keeps_the_south_pole() {
    // Material below y = 0.8 on the unit sphere: the cap above is gone
    // (height 0.2), the south pole is closed by its fan.
    let s = sphere(1.0, [-90.0, 90.0], Some(below(0.8)));
    let m = mesh_trimmed(&s, settings(0.1)).expect("meshable");
    check_manifold(&m);
    assert_eq!(m.boundary.len(), 1);
    for &i in &m.boundary[0] {
        assert!((m.nodes[i as usize].y - 0.8).abs() < 1e-8);
    }
    assert_eq!(euler(&m), 1);
    let q = m.quality(&s);
    let exact = 2.0 * TAU - TAU * 0.2;
    assert!(
        (q.area - exact).abs() / exact < 3e-3,
        "{} vs {exact}",
        q.area
    );
    assert!(q.min_angle >= 20.0, "{q:?}");
}

#[test]
fn quarter_lune_runs_its_boundary_through_both_poles() {
    // v ∈ [0, 90°] over all latitudes: a lune of area r²·π (a quarter of
    // 4πr²), one boundary chain through both poles.
    let mut s = sphere(1.0, [-90.0, 90.0], None);
    s.rect[3] = FRAC_PI_2;
    let m = mesh_trimmed(&s, settings(0.1)).expect("meshable");
    check_manifold(&m);
    assert_eq!(m.boundary.len(), 1);
    let on_chain = m.boundary[0]
        .iter()
        .filter(|&&i| (m.nodes[i as usize].y.abs() - 1.0).abs() < 1e-9)
        .count();
    assert_eq!(on_chain, 2, "both poles on the chain");
    let q = m.quality(&s);
    assert!((q.area - PI).abs() / PI < 3e-3, "{}", q.area);
    assert!(q.min_angle >= 20.0, "{q:?}");
}

fn torus(trim: Option<Trim>) -> TrimmedSurface {
    TrimmedSurface {
        name: "ring".into(),
        carrier: Carrier::Torus {
            major: 2.0,
            minor: 0.5,
        },
        frame: Frame::identity(),
        rect: [0.0, TAU, 0.0, TAU],
        trim,
    }
}

/// Every segment is used once each way.
fn watertight(m: &TrimmedMesh) {
    let mut directed: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for t in &m.triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for &(a, b) in directed.keys() {
        assert!(directed.contains_key(&(b, a)), "open segment {a}→{b}");
    }
}

#[test]
fn full_torus_closes_both_seams() {
    let s = torus(None);
    let m = mesh_trimmed(&s, settings(0.15)).expect("meshable");
    assert_eq!(check_manifold(&m), 0);
    assert!(m.boundary.is_empty());
    watertight(&m);
    assert_eq!(euler(&m), 0);
    let q = m.quality(&s);
    let exact = TAU * TAU * 2.0 * 0.5;
    assert!(
        (q.area - exact).abs() / exact < 3e-3,
        "{} vs {exact}",
        q.area
    );
    assert!(q.min_angle >= 20.0, "{q:?}");
}

/// The torus area outside the ball |p − (0, 0, R + r)| < ρ by a 1D integral:
/// at tube angle u the ball holds the v with sin v > k(u).
fn torus_area_outside(major: f64, minor: f64, rho: f64) -> f64 {
    let c = major + minor;
    let n = 20_000;
    let h = TAU / n as f64;
    let mut removed = 0.0;
    for i in 0..n {
        let u = (i as f64 + 0.5) * h;
        let ring = major + minor * u.cos();
        let p2 = ring * ring + (minor * u.sin()).powi(2);
        let k = (p2 + c * c - rho * rho) / (2.0 * ring * c);
        if k < 1.0 {
            removed += minor * ring * (PI - 2.0 * k.asin()) * h;
        }
    }
    TAU * TAU * major * minor - removed
}

#[test]
fn torus_hole_across_the_tube_seam_is_one_chain() {
    // The ball sits on the outer equator at v = 90°, where the tube's seam
    // u = 0 runs: the hole's rim is cut by the seam in (u, v) but is one
    // closed chain on the mesh; everything else is closed.
    let (rho, c) = (0.3, [0.0, 0.0, 2.5]);
    let s = torus(Some(outside_ball(c, rho)));
    let m = mesh_trimmed(&s, settings(0.1)).expect("meshable");
    check_manifold(&m);
    assert_eq!(m.boundary.len(), 1, "{:?}", m.boundary);
    let chain = &m.boundary[0];
    assert_eq!(chain.first(), chain.last(), "closed");
    for &i in chain {
        let p = m.nodes[i as usize];
        let d = ((p.x - c[0]).powi(2) + (p.y - c[1]).powi(2) + (p.z - c[2]).powi(2)).sqrt();
        assert!((d - rho).abs() < 1e-8, "{p}");
    }
    // Disc with a hole: V − E + F = 0 − 1.
    assert_eq!(euler(&m), -1);
    let q = m.quality(&s);
    let exact = torus_area_outside(2.0, 0.5, rho);
    assert!(
        (q.area - exact).abs() / exact < 3e-3,
        "{} vs {exact}",
        q.area
    );
    assert!(q.min_angle >= 20.0, "{q:?}");
    assert!(q.max_centroid_distance <= 0.002, "{q:?}");
    eprintln!(
        "torus with hole: {} triangles, {q:?}, exact {exact}",
        m.triangles.len()
    );
}

#[test]
fn closed_surfaces_fixture_through_the_mesher() {
    let text = include_str!("../../fixtures/valid/trimmed_closed_surfaces.xml");
    let source = crate::span::SourceFile::new("closed.xml", text);
    let checked = crate::driver::check_source(source, &crate::driver::Options::default());
    assert!(checked.is_valid(), "{:?}", checked.diagnostics);
    let model = &checked.lowered.as_ref().expect("lowered").model;
    assert_eq!(model.trimmed.len(), 3);
    let mesh = crate::meshing::mesh_model(model, &crate::meshing::MeshOptions::default())
        .expect("meshable");
    crate::meshing::sanity_check(&mesh).expect("sane");
    // Mesh edge k is IR edge k: the saddle's hole and its four sides (the
    // sides cut at its corners), the ring's hole across its seam.
    let names = |v: Vec<&str>| v.into_iter().map(String::from).collect::<Vec<_>>();
    let mesh_edges: Vec<String> = mesh.edges.iter().map(|e| e.name.clone()).collect();
    let ir_edges: Vec<String> = model.edges.iter().map(|e| e.name.to_string()).collect();
    assert_eq!(mesh_edges, ir_edges);
    for (face, chains) in [
        ("ball", names(vec![])),
        ("ring", names(vec!["ring.trim[1]"])),
        (
            "saddle",
            names(vec![
                "saddle.u_min[1]",
                "saddle.v_min[1]",
                "saddle.u_max[1]",
                "saddle.v_max[1]",
                "saddle.trim[1]",
            ]),
        ),
    ] {
        let f = mesh.faces.iter().find(|f| f.name == face).expect("face");
        let mut got: Vec<String> = f
            .boundary
            .iter()
            .map(|&(e, _)| mesh.edges[e as usize].name.clone())
            .collect();
        let mut want = chains.clone();
        got.sort();
        want.sort();
        assert_eq!(got, want, "{face}");
        assert!(!f.triangles.is_empty());
    }
}

#[test]
fn cone_apex_is_one_vertex() {
    // r from 0 to 1 over a length of 2: the side u = 0 is the apex. Lateral
    // area π r s with the slant s = √5; the fan spans 360°·sin(26.57°) ≈ 161°
    // in 4 steps of about 40°.
    let s = TrimmedSurface {
        name: "tip".into(),
        carrier: Carrier::Cone {
            r1: 0.0,
            r2: 1.0,
            length: 2.0,
        },
        frame: Frame::identity(),
        rect: [0.0, 2.0, 0.0, TAU],
        trim: None,
    };
    let m = mesh_trimmed(&s, settings(0.1)).expect("meshable");
    check_manifold(&m);
    assert_eq!(m.boundary.len(), 1, "only the rim");
    let apex = m.nodes.iter().filter(|p| p.coords.norm() < 1e-12).count();
    assert_eq!(apex, 1);
    let fan = m
        .triangles
        .iter()
        .filter(|t| t.iter().any(|&i| m.nodes[i as usize].coords.norm() < 1e-12))
        .count();
    assert_eq!(fan, 4);
    assert_eq!(euler(&m), 1);
    let q = m.quality(&s);
    let exact = PI * 5f64.sqrt();
    assert!(
        (q.area - exact).abs() / exact < 3e-3,
        "{} vs {exact}",
        q.area
    );
    assert!(q.min_angle >= 20.0, "{q:?}");
    assert!(q.max_centroid_distance <= 0.002, "{q:?}");
}

/// A sphere with its poles on the sides v = const (the latitude as v).
fn sphere_latitude_in_v(radius: f64, latitudes: [f64; 2], trim: Option<Trim>) -> TrimmedSurface {
    let s = sphere(radius, latitudes, trim).transposed();
    assert!(matches!(s.carrier, Carrier::Swapped(_)));
    s
}

#[test]
fn poles_on_the_v_sides_are_meshed_through_the_transpose() {
    let r = 1.5;
    let s = sphere_latitude_in_v(r, [-90.0, 90.0], None);
    assert_eq!(s.rect[2], -FRAC_PI_2);
    let m = mesh_trimmed(&s, settings(0.15)).expect("meshable");
    assert_eq!(check_manifold(&m), 0, "no boundary segments");
    assert_eq!(euler(&m), 2);
    check_whole_sphere(&s, &m, r);
    // The triangles turn about R_u × R_v of the surface as given, which
    // the transpose turns over: the enclosed volumes have opposite signs.
    let volume = |m: &TrimmedMesh| {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.nodes[i as usize].coords);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum::<f64>()
    };
    let original = mesh_trimmed(&sphere(r, [-90.0, 90.0], None), settings(0.15)).expect("meshable");
    let exact = 4.0 / 3.0 * PI * r * r * r;
    let (v, v0) = (volume(&m), volume(&original));
    assert!(
        v0.abs() > 0.99 * exact && v.abs() > 0.99 * exact,
        "{v} {v0}"
    );
    assert!(v * v0 < 0.0, "{v} {v0}");
}

#[test]
fn a_north_cap_cut_from_a_v_pole_sphere_keeps_the_zone_area() {
    // Material below y = 0.75 on the sphere of radius 1.5: the zone from
    // the south pole up to height 0.75 has area 2π r (0.75 + r).
    let r = 1.5;
    let s = sphere_latitude_in_v(r, [-90.0, 90.0], Some(below(0.75)));
    let m = mesh_trimmed(&s, settings(0.15)).expect("meshable");
    let q = m.quality(&s);
    let exact = TAU * r * (0.75 + r);
    assert!(
        (q.area - exact).abs() / exact < 3e-3,
        "{} vs {exact}",
        q.area
    );
    assert!(q.min_angle >= 20.0, "{q:?}");
    assert_eq!(m.boundary.len(), 1, "the cut circle");
}
