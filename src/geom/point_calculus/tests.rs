//! Unit tests of the point equations: conic types by fitted discriminant, the
//! rational Bezier identity, end points and tangents, the Desargues weight
//! identity, patch interpolation, SoA evaluation and adaptive sampling.

use super::*;

fn p(x: f64, y: f64, z: f64) -> Point3 {
    Point3::new(x, y, z)
}

fn arc(k: f64) -> PcCurve {
    PcCurve::Conic {
        a: p(0.0, 0.0, 0.0),
        b: p(3.0, 0.5, 0.0),
        c: p(1.0, 2.0, 0.0),
        k,
    }
}

/// The conic a·x² + b·xy + c·y² + d·x + e·y + f = 0 through the points
/// (least squares: the right singular vector of the smallest singular value),
/// scaled to unit norm.
fn fit_conic(points: &[Point3]) -> [f64; 6] {
    let rows: Vec<f64> = points
        .iter()
        .flat_map(|q| [q.x * q.x, q.x * q.y, q.y * q.y, q.x, q.y, 1.0])
        .collect();
    let m = nalgebra::DMatrix::from_row_slice(points.len(), 6, &rows);
    let svd = (m.transpose() * &m).symmetric_eigen();
    let (i, _) = svd
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .expect("six eigenvalues");
    let v = svd.eigenvectors.column(i);
    let n = v.norm();
    [v[0] / n, v[1] / n, v[2] / n, v[3] / n, v[4] / n, v[5] / n]
}

#[test]
fn fitted_conic_type_follows_k() {
    for (k, kind) in [
        (0.1, ConicKind::Hyperbola),
        (0.3, ConicKind::Hyperbola),
        (0.45, ConicKind::Hyperbola),
        (0.5, ConicKind::Parabola),
        (0.55, ConicKind::Ellipse),
        (0.7, ConicKind::Ellipse),
        (0.9, ConicKind::Ellipse),
    ] {
        assert_eq!(ConicKind::of(k), Some(kind));
        let curve = arc(k);
        let samples = curve.samples(40);
        let [a, b, c, d, e, f] = fit_conic(&samples);
        // Every sample satisfies the fitted conic.
        for q in &samples {
            let r = a * q.x * q.x + b * q.x * q.y + c * q.y * q.y + d * q.x + e * q.y + f;
            assert!(r.abs() < 1e-10, "k = {k}: residual {r}");
        }
        let disc = b * b - 4.0 * a * c;
        match kind {
            ConicKind::Hyperbola => assert!(disc > 1e-4, "k = {k}: {disc}"),
            ConicKind::Ellipse => assert!(disc < -1e-4, "k = {k}: {disc}"),
            ConicKind::Parabola => assert!(disc.abs() < 1e-10, "k = {k}: {disc}"),
        }
    }
    assert_eq!(ConicKind::of(0.0), None);
    assert_eq!(ConicKind::of(1.0), None);
    assert_eq!(ConicKind::of(f64::NAN), None);
}

#[test]
fn half_gives_the_exact_parabola() {
    let (a, b, c) = (p(0.0, 0.0, 1.0), p(3.0, 0.5, -1.0), p(1.0, 2.0, 0.5));
    let curve = PcCurve::Conic { a, b, c, k: 0.5 };
    for i in 0..=100 {
        let u = i as f64 / 100.0;
        let ub = 1.0 - u;
        let bezier = a.coords * (ub * ub) + c.coords * (2.0 * u * ub) + b.coords * (u * u);
        assert!((curve.point(u).coords - bezier).norm() < 1e-14, "u = {u}");
    }
}

#[test]
fn conic_is_the_rational_bezier_with_middle_weight() {
    let (a, b, c) = (p(0.0, 0.0, 1.0), p(3.0, 0.5, -1.0), p(1.0, 2.0, 0.5));
    for k in [0.05, 0.2, 0.5, 0.6, 0.8, 0.95] {
        let curve = PcCurve::Conic { a, b, c, k };
        let w = (1.0 - k) / k;
        for i in 0..=64 {
            let u = i as f64 / 64.0;
            let ub = 1.0 - u;
            let num = a.coords * (ub * ub) + c.coords * (2.0 * w * u * ub) + b.coords * (u * u);
            let den = ub * ub + 2.0 * w * u * ub + u * u;
            let diff = (curve.point(u).coords - num / den).norm();
            assert!(diff < 1e-13, "k = {k}, u = {u}: {diff}");
        }
        // The paper's own form, written out.
        let u: f64 = 0.3;
        let ub = 1.0 - u;
        let paper = ((a - c) * (k * ub * ub) + (b - c) * (k * u * u))
            / (k * (1.0 - 2.0 * u).powi(2) + 2.0 * u * ub)
            + c.coords;
        assert!((curve.point(u).coords - paper).norm() < 1e-14);
    }
}

#[test]
fn conic_ends_and_tangents_are_exact() {
    let (a, b, c) = (p(0.1, 0.2, 0.3), p(3.0, 0.5, -1.0), p(1.0, 2.0, 0.5));
    for k in [0.2, 0.5, 0.75] {
        let curve = PcCurve::Conic { a, b, c, k };
        assert_eq!(curve.point(0.0), a);
        assert_eq!(curve.point(1.0), b);
        let t0 = curve.tangent(0.0);
        let t1 = curve.tangent(1.0);
        let ac = (c - a).normalize();
        let cb = (b - c).normalize();
        assert!((t0 - ac).norm() < 1e-15, "{t0} vs {ac}");
        assert!((t1 - cb).norm() < 1e-15, "{t1} vs {cb}");
        // Reversal runs the same points backwards.
        let r = curve.reversed();
        for u in [0.1, 0.5, 0.9] {
            assert!((r.point(u) - curve.point(1.0 - u)).norm() < 1e-14);
        }
        // The derivative agrees with central differences inside.
        let h = 1e-6;
        let fd = (curve.point(0.4 + h) - curve.point(0.4 - h)) / (2.0 * h);
        assert!((fd - curve.derivative(0.4)).norm() < 1e-7);
    }
}

#[test]
fn desargues_arc_ends_tangents_and_weight_identity() {
    let pts = [
        p(0.0, 0.0, 0.0),
        p(1.0, 2.0, 0.0),
        p(2.0, 2.0, 1.0),
        p(3.0, 0.0, 1.0),
    ];
    let curve = PcCurve::Desargues { points: pts };
    assert_eq!(curve.point(0.0), pts[0]);
    assert_eq!(curve.point(1.0), pts[3]);
    for i in 0..=1000 {
        let u = i as f64 / 1000.0;
        let (w, d) = desargues_weights(u);
        // ū³ + u²ū + ū²u + u³ = 2u² − 2u + 1: the weights sum to one.
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15, "u = {u}");
        assert!(d.iter().sum::<f64>().abs() < 1e-13, "u = {u}");
    }
    // Exact ends of the weights themselves.
    assert_eq!(desargues_weights(0.0).0, [1.0, 0.0, 0.0, 0.0]);
    assert_eq!(desargues_weights(1.0).0, [0.0, 0.0, 0.0, 1.0]);
    // The end tangents run along AC and BD.
    let t0 = curve.tangent(0.0);
    let t1 = curve.tangent(1.0);
    assert!((t0 - (pts[2] - pts[0]).normalize()).norm() < 1e-15);
    assert!((t1 - (pts[3] - pts[1]).normalize()).norm() < 1e-15);
    let r = curve.reversed();
    for u in [0.2, 0.5, 0.7] {
        assert!((r.point(u) - curve.point(1.0 - u)).norm() < 1e-14);
    }
}

fn patch() -> Patch9 {
    Patch9 {
        rows: [
            [p(0.0, 0.0, 0.0), p(1.0, 0.0, 0.3), p(2.0, 0.0, 0.0)],
            [p(0.0, 1.0, 0.2), p(1.0, 1.0, 0.8), p(2.0, 1.0, 0.1)],
            [p(0.0, 2.0, 0.0), p(1.0, 2.0, 0.4), p(2.0, 2.0, -0.2)],
        ],
    }
}

#[test]
fn patch_interpolates_its_nine_points() {
    let s = patch();
    let grid = [0.0, 0.5, 1.0];
    for (i, &v) in grid.iter().enumerate() {
        for (j, &u) in grid.iter().enumerate() {
            assert_eq!(s.point(u, v), s.rows[i][j], "u = {u}, v = {v}");
        }
    }
    let mut out = Streams::default();
    eval_patch_grid(&s, &grid, &grid, &mut out);
    for i in 0..3 {
        for j in 0..3 {
            let k = 3 * i + j;
            assert_eq!(p(out.x[k], out.y[k], out.z[k]), s.rows[i][j]);
        }
    }
    // Sides are the parabolas through the rows and columns.
    let side = s.side(0, 2).expect("adjacent corners");
    for v in [0.1, 0.5, 0.8] {
        assert!((side.point(v) - s.point(0.0, v)).norm() < 1e-15);
    }
    let back = s.side(3, 1).expect("adjacent corners");
    assert!((back.point(0.25) - s.point(1.0, 0.75)).norm() < 1e-15);
    assert!(s.side(0, 3).is_none());
    // Projection finds parameters back.
    let q = s.point(0.3, 0.7);
    let (uv, foot) = s.project(&q).expect("projects");
    assert!((foot - q).norm() < 1e-12 && (uv[0] - 0.3).abs() < 1e-9 && (uv[1] - 0.7).abs() < 1e-9);
}

#[test]
fn stream_evaluation_matches_pointwise_for_any_thread_count() {
    let curves = [
        arc(0.3),
        arc(0.5),
        arc(0.8),
        PcCurve::Segment {
            a: p(0.0, 1.0, 2.0),
            b: p(-1.0, 0.5, 4.0),
        },
        PcCurve::Desargues {
            points: [
                p(0.0, 0.0, 0.0),
                p(1.0, 2.0, 0.0),
                p(2.0, 2.0, 1.0),
                p(3.0, 0.0, 1.0),
            ],
        },
    ];
    let params: Vec<f64> = (1..100_000).map(|i| i as f64 / 100_000.0).collect();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .expect("pool");
    for c in &curves {
        let mut a = Streams::default();
        let mut b = Streams::default();
        one.install(|| eval_curve(c, &params, &mut a));
        three.install(|| eval_curve(c, &params, &mut b));
        assert_eq!(a, b);
        for i in (0..params.len()).step_by(997) {
            assert_eq!(p(a.x[i], a.y[i], a.z[i]), c.point(params[i]));
        }
    }
    let s = patch();
    let us: Vec<f64> = (0..=300).map(|i| i as f64 / 300.0).collect();
    let mut a = Streams::default();
    let mut b = Streams::default();
    one.install(|| eval_patch_grid(&s, &us, &us, &mut a));
    three.install(|| eval_patch_grid(&s, &us, &us, &mut b));
    assert_eq!(a, b);
    assert_eq!(a.len(), 301 * 301);
    let k = 301 * 120 + 77;
    assert_eq!(p(a.x[k], a.y[k], a.z[k]), s.point(us[77], us[120]));
}

#[test]
fn adaptive_samples_meet_the_tolerance() {
    for k in [0.1, 0.5, 0.9] {
        let c = arc(k);
        let tol = 1e-3;
        let (params, points) = adaptive_samples(&c, tol, f64::INFINITY, 2).expect("samples");
        assert_eq!(points[0], c.begin());
        assert_eq!(*points.last().expect("points"), c.end());
        assert_eq!(params.len(), points.len());
        assert!(params.windows(2).all(|w| w[0] < w[1]));
        // Dense check: every curve point lies within tol of its chord.
        for w in 0..params.len() - 1 {
            for f in 1..16 {
                let u = params[w] + (params[w + 1] - params[w]) * f as f64 / 16.0;
                let d = sampling_distance(&c.point(u), &points[w], &points[w + 1]);
                assert!(d <= tol * 1.01, "k = {k}: {d}");
            }
        }
        // Adaptive: fewer samples than uniform doubling would need near the
        // flat parts, and more than two.
        assert!(points.len() > 4 && points.len() < 200, "{}", points.len());
        let (_, short) = adaptive_samples(&c, tol, 0.1, 1).expect("samples");
        assert!(short.windows(2).all(|w| (w[1] - w[0]).norm() <= 0.1));
    }
    assert!(adaptive_samples(&arc(0.5), 0.0, 1.0, 1).is_none());
}

fn sampling_distance(q: &Point3, a: &Point3, b: &Point3) -> f64 {
    let d = b - a;
    let t = ((q - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
    (q - (a + d * t)).norm()
}

#[test]
fn affine_maps_move_the_curve_exactly() {
    let c = arc(0.7);
    let shift = Vec3::new(1.0, -2.0, 0.5);
    let moved = c.mapped(|q| q + shift);
    for u in [0.0, 0.25, 0.5, 1.0] {
        assert!((moved.point(u) - (c.point(u) + shift)).norm() < 1e-14);
    }
}
