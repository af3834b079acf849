//! Paper 003's 9-point patch as the carrier of a trim (through the front end).

use super::tests::check_manifold;
use super::*;

/// The saddle y = 0.3 (x² − z²) over [−1, 1]² as a patch9 (a biquadratic
/// surface, so the patch is exactly the saddle), with the cylinder
/// x² + z² < 0.4² cut out.
const SADDLE: &str = r#"<geometry version="1">
  <patch9 name="saddle">
    <row> <node x="-1" y="0" z="-1"/> <node x="0" y="-0.3" z="-1"/> <node x="1" y="0" z="-1"/> </row>
    <row> <node x="-1" y="0.3" z="0"/> <node x="0" y="0" z="0"/> <node x="1" y="0.3" z="0"/> </row>
    <row> <node x="-1" y="0" z="1"/> <node x="0" y="-0.3" z="1"/> <node x="1" y="0" z="1"/> </row>
    <trim equation="0.16 - x^2 - z^2" material="negative"/>
  </patch9>
</geometry>"#;

fn saddle() -> (TrimmedSurface, crate::diag::Diagnostics) {
    let source = crate::span::SourceFile::new("saddle.xml", SADDLE);
    let checked = crate::driver::check_source(source, &crate::driver::Options::default());
    let model = &checked.lowered.as_ref().expect("lowered").model;
    assert_eq!(model.trimmed.len(), 1);
    (model.trimmed[0].clone(), checked.diagnostics)
}

/// ∫∫ √(1 + 0.36 (x² + z²)) over the square (Simpson, 400 × 400) minus the
/// same over the disk ρ < 0.4 in closed form.
fn saddle_area() -> f64 {
    let n = 400;
    let h = 2.0 / n as f64;
    let w = |k: usize| match k {
        0 => 1.0,
        k if k == n => 1.0,
        k if k % 2 == 1 => 4.0,
        _ => 2.0,
    };
    let mut square = 0.0;
    for i in 0..=n {
        for j in 0..=n {
            let (x, z) = (-1.0 + i as f64 * h, -1.0 + j as f64 * h);
            square += w(i) * w(j) * (1.0 + 0.36 * (x * x + z * z)).sqrt();
        }
    }
    square *= h * h / 9.0;
    let disk = std::f64::consts::TAU / (3.0 * 0.36) * ((1.0 + 0.36 * 0.16f64).powf(1.5) - 1.0);
    square - disk
}

#[test]
fn patch9_saddle_with_a_round_hole() {
    let (s, diags) = saddle();
    assert!(!diags.has_errors(), "{diags:?}");
    assert!(diags.items.is_empty(), "{diags:?}");
    assert!(matches!(s.carrier, Carrier::Patch9(_)));
    let settings = TrimSettings {
        tolerance: 1e-3,
        min_angle: 20.0,
        max_edge: 0.08,
    };
    let m = mesh_trimmed(&s, settings).expect("meshable");
    check_manifold(&m);
    // The square's four sides as one chain, and the hole.
    assert_eq!(m.boundary.len(), 2);
    for p in &m.nodes {
        assert!((p.y - 0.3 * (p.x * p.x - p.z * p.z)).abs() < 1e-12, "{p}");
    }
    let rim = m
        .boundary
        .iter()
        .flatten()
        .map(|&i| m.nodes[i as usize])
        .filter(|p| p.x.abs() < 0.99 && p.z.abs() < 0.99)
        .inspect(|p| assert!((p.x.hypot(p.z) - 0.4).abs() < 1e-8, "{p}"))
        .count();
    assert!(rim >= 30, "{rim}");
    let q = m.quality(&s);
    let exact = saddle_area();
    assert!(
        (q.area - exact).abs() / exact < 1e-3,
        "{} vs {exact}",
        q.area
    );
    assert!(q.min_angle >= 20.0, "{q:?}");
    assert!(q.max_centroid_distance <= 1e-3, "{q:?}");
    eprintln!(
        "patch9 saddle: {} triangles, area {} vs {exact}, {q:?}",
        m.triangles.len(),
        q.area
    );
}
