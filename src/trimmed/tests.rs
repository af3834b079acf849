use super::*;
use crate::implicit::ir::Ctx;
use std::collections::BTreeMap;

/// Paper 002's bicubic patch: rows along u, four points along v in each.
pub(crate) fn paper_patch() -> Vec<Vec<Point3>> {
    let ys = [(0.0, -1.0), (4.0, -1.0), (4.0, 1.0), (0.0, 1.0)];
    let zs = [-1.0, -0.5, 0.5, 1.0];
    ys.iter()
        .map(|&(x, y)| zs.iter().map(|&z| Point3::new(x, y, z)).collect())
        .collect()
}

/// The round hole: F = r² − y² − z², material where F ≤ 0.
fn hole(r: f64) -> Trim {
    let mut c = Ctx::new();
    let (y, z) = (c.var(1), c.var(2));
    let (y2, z2) = (c.square(y), c.square(z));
    let rr = c.constant(r * r);
    let s = c.add(y2, z2);
    let f = c.sub(rr, s);
    Trim::new(&c, f, true)
}

fn paper_surface() -> TrimmedSurface {
    TrimmedSurface {
        name: "patch".into(),
        carrier: Carrier::Bezier {
            rows: paper_patch(),
        },
        frame: Frame::identity(),
        rect: [0.0, 1.0, 0.0, 1.0],
        trim: Some(hole(0.4)),
    }
}

const SETTINGS: TrimSettings = TrimSettings {
    tolerance: 0.005,
    min_angle: 20.0,
    max_edge: f64::INFINITY,
};

/// Every interior segment is shared by two triangles with opposite
/// directions, every boundary segment by one; the boundary segments are
/// exactly those of the boundary chains.
fn check_manifold(m: &TrimmedMesh) -> usize {
    let mut directed: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for t in &m.triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    let mut boundary: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "segment {a}→{b} used {n} times in one direction");
        if !directed.contains_key(&(b, a)) {
            *boundary.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut chains: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for c in &m.boundary {
        for w in c.windows(2) {
            *chains.entry((w[0].min(w[1]), w[0].max(w[1]))).or_default() += 1;
        }
    }
    assert_eq!(
        boundary, chains,
        "mesh boundary differs from the trim curves and patch sides"
    );
    boundary.len()
}

/// Area of the kept part by quadrature: Simpson in u, and in v over the
/// intervals outside the hole (z(v) is increasing, so the hole is one
/// interval found by bisection).
fn quadrature_area(s: &TrimmedSurface, r: f64) -> f64 {
    let density = |u: f64, v: f64| {
        let (a, b) = s.tangents(u, v);
        a.cross(&b).norm()
    };
    let simpson = |f: &dyn Fn(f64) -> f64, a: f64, b: f64, n: usize| {
        if b <= a {
            return 0.0;
        }
        let h = (b - a) / n as f64;
        let mut sum = f(a) + f(b);
        for k in 1..n {
            sum += f(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        sum * h / 3.0
    };
    let z_root = |u: f64, target: f64| {
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if s.point(u, mid).z < target {
                lo = mid
            } else {
                hi = mid
            }
        }
        0.5 * (lo + hi)
    };
    let line = |u: f64| {
        let y = s.point(u, 0.5).y;
        if y.abs() >= r {
            simpson(&|v| density(u, v), 0.0, 1.0, 200)
        } else {
            let h = (r * r - y * y).sqrt();
            let (v1, v2) = (z_root(u, -h), z_root(u, h));
            simpson(&|v| density(u, v), 0.0, v1, 100) + simpson(&|v| density(u, v), v2, 1.0, 100)
        }
    };
    simpson(&line, 0.0, 1.0, 1200)
}

#[test]
fn paper_bezier_patch_with_round_hole() {
    let s = paper_surface();
    let m = mesh_trimmed(&s, SETTINGS).expect("meshable");
    assert!(m.triangles.len() > 200, "{} triangles", m.triangles.len());
    // Two chains: the outer rectangle and the hole.
    assert_eq!(m.boundary.len(), 2);
    check_manifold(&m);
    // V − E + F = 0 for an annulus.
    let edges: std::collections::BTreeSet<(u32, u32)> = m
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    assert_eq!(
        m.nodes.len() as i64 - edges.len() as i64 + m.triangles.len() as i64,
        0
    );
    // The hole's nodes lie on the cylinder y² + z² = r².
    let hole = m
        .boundary
        .iter()
        .find(|c| {
            c.iter()
                .all(|&i| m.uv[i as usize][0] > 0.0 && m.uv[i as usize][0] < 1.0)
        })
        .expect("the hole's chain");
    for &i in hole {
        let p = m.nodes[i as usize];
        let d = (p.y.hypot(p.z) - 0.4).abs();
        assert!(d < 1e-9, "hole node {p} is {d} off the intersection curve");
    }
    let q = m.quality(&s);
    assert!(
        q.min_angle >= 20.0 - 1e-9
            || q.histogram[..4].iter().sum::<usize>() < m.triangles.len() / 100,
        "{q:?}"
    );
    assert!(q.max_centroid_distance <= SETTINGS.tolerance, "{q:?}");
    let exact = quadrature_area(&s, 0.4);
    let rel = (q.area - exact).abs() / exact;
    assert!(rel < 5e-3, "area {} vs quadrature {exact} ({rel})", q.area);
}

#[test]
fn untrimmed_full_cone_closes_its_seam() {
    let s = TrimmedSurface {
        name: "cone".into(),
        carrier: Carrier::Cone {
            r1: 2.0,
            r2: 1.5,
            length: 3.0,
        },
        frame: Frame::identity(),
        rect: [0.0, 3.0, 0.0, std::f64::consts::TAU],
        trim: None,
    };
    let m = mesh_trimmed(
        &s,
        TrimSettings {
            tolerance: 0.01,
            min_angle: 25.0,
            max_edge: f64::INFINITY,
        },
    )
    .expect("meshable");
    check_manifold(&m);
    // Two rims, no seam.
    assert_eq!(
        m.boundary.len(),
        2,
        "{:?}",
        m.boundary.iter().map(|c| c.len()).collect::<Vec<_>>()
    );
    let q = m.quality(&s);
    assert!(q.min_angle >= 25.0, "{q:?}");
    assert!(q.max_centroid_distance <= 0.01, "{q:?}");
    let slant = (3.0f64 * 3.0 + 0.25).sqrt();
    let exact = std::f64::consts::PI * (2.0 + 1.5) * slant;
    assert!(
        (q.area - exact).abs() / exact < 2e-3,
        "{} vs {exact}",
        q.area
    );
}

/// The interstage fixture: a cone with rounded-rectangle and bounded-cylinder
/// cut-outs, one of them across the seam v = 0.
#[test]
fn interstage_cone_with_cut_outs() {
    let source = crate::span::SourceFile::new(
        "trimmed_interstage.xml",
        include_str!("../../fixtures/valid/trimmed_interstage.xml"),
    );
    let checked = crate::driver::check_source(source, &crate::driver::Options::default());
    assert!(checked.is_valid(), "{:?}", checked.diagnostics);
    let model = &checked.lowered.as_ref().expect("lowered").model;
    assert_eq!(model.trimmed.len(), 1);
    let s = &model.trimmed[0];
    let settings = TrimSettings {
        tolerance: 0.005,
        min_angle: 20.0,
        max_edge: f64::INFINITY,
    };
    let m = mesh_trimmed(s, settings).expect("meshable");
    let boundary_segments = check_manifold(&m);
    assert!(boundary_segments > 100, "{boundary_segments}");
    let trim = s.trim.as_ref().expect("trim");
    // Every boundary node is on a rim (y = 0 or 3) or on the trim's zero set.
    let (mut rims, mut cuts) = (0.0, 0usize);
    for chain in &m.boundary {
        for w in chain.windows(2) {
            let (a, b) = (m.nodes[w[0] as usize], m.nodes[w[1] as usize]);
            if a.y.abs() < 1e-9 && b.y.abs() < 1e-9
                || (a.y - 3.0).abs() < 1e-9 && (b.y - 3.0).abs() < 1e-9
            {
                rims += (b - a).norm();
            }
        }
        for &i in chain {
            let p = m.nodes[i as usize];
            if p.y.abs() > 1e-9 && (p.y - 3.0).abs() > 1e-9 {
                let f = trim.program.eval_point([p.x, p.y, p.z]);
                assert!(f.abs() < 1e-8, "boundary node {p} has F = {f}");
                cuts += 1;
            }
        }
    }
    assert!(cuts > 100, "{cuts} nodes on the cut-outs");
    // The rims are whole circles (no cut-out reaches them), inscribed polygons.
    let circles = std::f64::consts::TAU * (2.0 + 1.5);
    assert!(
        rims < circles && circles - rims < 0.01 * circles,
        "{rims} vs {circles}"
    );
    let q = m.quality(s);
    assert!(q.max_centroid_distance <= settings.tolerance, "{q:?}");
    // The seam and the trim curves keep their boundary edges on a periodic
    // surface: a few triangles beside them fall short of the threshold.
    let below: usize = q.histogram[..4].iter().sum();
    assert!(
        below * 200 < m.triangles.len(),
        "{below} of {} below 20°: {q:?}",
        m.triangles.len()
    );
    assert!(q.min_angle > 10.0, "{q:?}");
    // Less area than the whole cone: the cut-outs took some.
    let slant = (9.0f64 + 0.25).sqrt();
    let whole = std::f64::consts::PI * 3.5 * slant;
    assert!(
        q.area < 0.97 * whole && q.area > 0.85 * whole,
        "{} of {whole}",
        q.area
    );
}
