//! Convergence of compiled curved solids to their exact shapes: as the
//! chordal tolerance shrinks, the volume and area errors against the exact
//! measures (`meshing::exact`) decrease and stay within the tolerance bound,
//! and every node, edge midpoint and triangle sample lies within the
//! tolerance of the exact surface (the one-sided Hausdorff distance, with
//! distances computed exactly for each shape, not by the mesher's own
//! first-order estimate).

use geomc::driver::{Options, check_source};
use geomc::ir::Model;
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, MeshReport, Tolerance, mesh_model, sanity_check};
use geomc::span::SourceFile;
use nalgebra::Vector3;

type V = Vector3<f64>;

fn model(xml: &str) -> Model {
    let checked = check_source(SourceFile::new("t.xml", xml), &Options::default());
    assert!(checked.is_valid(), "{:#?}", checked.diagnostics.items);
    checked.lowered.expect("a model").model
}

fn solid(shape: &str) -> String {
    format!(
        r#"<geometry version="1">{shape}<subdomain name="s"><solid ref="a"/></subdomain></geometry>"#
    )
}

/// Distance in a meridian half-plane (ρ, z) from a point to a polyline profile.
fn profile_distance(rho: f64, z: f64, profile: &[(f64, f64)]) -> f64 {
    profile
        .windows(2)
        .map(|w| {
            let (a, b) = (V::new(w[0].0, w[0].1, 0.0), V::new(w[1].0, w[1].1, 0.0));
            let p = V::new(rho, z, 0.0);
            let d = b - a;
            let t = ((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
            (p - (a + d * t)).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Exact distance from p to the ellipsoid with semi-axes `axes` centred at
/// the origin: the foot point's Lagrange parameter t solves
/// Σ (aᵢ yᵢ / (t + aᵢ²))² = 1, monotone in t, found by bisection.
fn ellipsoid_distance(p: V, axes: V) -> f64 {
    let y = p.abs();
    let f = |t: f64| {
        (0..3)
            .map(|i| (axes[i] * y[i] / (t + axes[i] * axes[i])).powi(2))
            .sum::<f64>()
            - 1.0
    };
    let min_axis = axes.min();
    let (mut lo, mut hi) = (-min_axis * min_axis, 1e3);
    // A point on or near a principal plane inside can have its foot on the
    // singular branch; those lie within the mesh's tolerance anyway, and
    // bisection then returns the nearest regular foot point, an upper bound.
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let t = 0.5 * (lo + hi);
    let foot = V::from_fn(|i, _| axes[i] * axes[i] * y[i] / (t + axes[i] * axes[i]));
    (y - foot).norm()
}

/// Points to test: every node, every triangle's edge midpoints, and a
/// barycentric grid inside every triangle.
fn probes(mesh: &Mesh) -> Vec<V> {
    let node = |i: u32| V::from(mesh.nodes[i as usize]);
    let mut points: Vec<V> = mesh.nodes.iter().map(|p| V::from(*p)).collect();
    for face in &mesh.faces {
        for t in &face.triangles {
            let [a, b, c] = t.map(node);
            for (i, j) in [(1, 1), (2, 0), (0, 2), (1, 0), (0, 1), (2, 2), (1, 2)] {
                // Grid points (i, j, 4 − i − j)/4 with interior and edge samples.
                let k = 4 - i - j;
                points.push((a * i as f64 + b * j as f64 + c * k as f64) / 4.0);
            }
            points.push((a + b) / 2.0);
            points.push((b + c) / 2.0);
            points.push((c + a) / 2.0);
        }
    }
    points
}

struct Case {
    xml: String,
    distance: Box<dyn Fn(V) -> f64>,
}

fn check(case: &Case, tolerances: &[f64]) {
    let m = model(&case.xml);
    let mut last = (f64::INFINITY, f64::INFINITY);
    for &tolerance in tolerances {
        let options = MeshOptions {
            tolerance: Tolerance::Absolute(tolerance),
            ..MeshOptions::default()
        };
        let mesh = mesh_model(&m, &options).expect("meshable");
        sanity_check(&mesh).expect("sane");
        let report = MeshReport::of(&m, &mesh, tolerance, None, 25.0);
        let s = &report.subdomains[0];
        let (dv, da) = (s.volume_error.expect("exact"), s.area_error.expect("exact"));
        let bound = s.volume_bound.expect("bound");
        let hausdorff = probes(&mesh)
            .into_iter()
            .map(|p| (case.distance)(p))
            .fold(0.0, f64::max);
        eprintln!(
            "tol {tolerance}: {} triangles, volume err {dv:.2e} (bound {bound:.2e}), area err {da:.2e}, Hausdorff {hausdorff:.2e}",
            report.triangles
        );
        assert!(dv <= bound, "volume error {dv} above {bound}");
        // Area: at most twice the volume bound's relative slack.
        assert!(da <= 2.0 * bound, "area error {da}");
        assert!(
            hausdorff <= tolerance,
            "Hausdorff distance {hausdorff} above tolerance {tolerance}"
        );
        assert!(dv < last.0 && da < last.1, "errors must decrease");
        last = (dv, da);
    }
}

const TOLERANCES: [f64; 3] = [0.02, 0.008, 0.003];

#[test]
fn ball_converges() {
    let centre = V::new(0.5, -1.0, 2.0);
    check(
        &Case {
            xml: solid(
                r#"<sphere name="a"><center x="0.5" y="-1" z="2"/><radius value="1.2"/></sphere>"#,
            ),
            distance: Box::new(move |p| ((p - centre).norm() - 1.2).abs()),
        },
        &TOLERANCES,
    );
}

fn revolution(xml: &str, profile: Vec<(f64, f64)>) -> Case {
    Case {
        xml: solid(xml),
        distance: Box::new(move |p| profile_distance(p.x.hypot(p.y), p.z, &profile)),
    }
}

#[test]
fn cylinder_converges() {
    check(
        &revolution(
            r#"<truncated_cone name="a"><bottom_center x="0" y="0" z="0"/><top_center x="0" y="0" z="2"/><bottom_radius value="1"/><top_radius value="1"/></truncated_cone>"#,
            vec![(0.0, 0.0), (1.0, 0.0), (1.0, 2.0), (0.0, 2.0)],
        ),
        &TOLERANCES,
    );
}

#[test]
fn cone_converges() {
    check(
        &revolution(
            r#"<truncated_cone name="a"><bottom_center x="0" y="0" z="0"/><top_center x="0" y="0" z="2"/><bottom_radius value="1"/><top_radius value="0.4"/></truncated_cone>"#,
            vec![(0.0, 0.0), (1.0, 0.0), (0.4, 2.0), (0.0, 2.0)],
        ),
        &TOLERANCES,
    );
}

#[test]
fn torus_converges() {
    check(
        &Case {
            xml: solid(
                r#"<torus name="a"><center x="0" y="0" z="0"/><major_radius value="2"/><minor_radius value="0.5"/></torus>"#,
            ),
            distance: Box::new(|p| ((p.x.hypot(p.y) - 2.0).hypot(p.z) - 0.5).abs()),
        },
        &TOLERANCES,
    );
}

#[test]
fn ellipsoid_converges() {
    let axes = V::new(2.0, 1.0, 0.6);
    check(
        &Case {
            xml: solid(
                r#"<ellipsoid name="a"><center x="0" y="0" z="0"/><semi_axes x="2" y="1" z="0.6"/></ellipsoid>"#,
            ),
            distance: Box::new(move |p| ellipsoid_distance(p, axes)),
        },
        &TOLERANCES,
    );
}

#[test]
fn exact_distances_are_right() {
    assert!((ellipsoid_distance(V::new(3.0, 0.0, 0.0), V::new(2.0, 1.0, 0.6)) - 1.0).abs() < 1e-12);
    assert!((ellipsoid_distance(V::new(0.0, 0.0, 0.3), V::new(2.0, 1.0, 0.6)) - 0.3).abs() < 1e-9);
    let profile = [(0.0, 0.0), (1.0, 0.0), (1.0, 2.0), (0.0, 2.0)];
    assert!((profile_distance(0.5, 1.0, &profile) - 0.5).abs() < 1e-15);
    assert!((profile_distance(2.0, 3.0, &profile) - 2f64.sqrt()).abs() < 1e-15);
}
