//! Measures of a polygonized surface shared by the implicit tests.
#![allow(dead_code)] // each test binary uses its own subset

use geomc::implicit::polygonize::Surface;

/// Enclosed volume by the divergence theorem (outward-oriented triangles).
pub fn volume(s: &Surface) -> f64 {
    s.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| s.positions[i as usize]);
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

pub fn area(s: &Surface) -> f64 {
    s.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| s.positions[i as usize]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
        })
        .sum()
}

/// Runs the geomc binary on `args` followed by `paths` and asserts it
/// succeeded (its stderr in the failure message).
pub fn geomc_ok(args: &[&str], paths: &[&std::path::Path]) {
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(args)
        .args(paths)
        .output()
        .expect("run geomc");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// Edges whose two triangles' normals are more than 120° apart (a triangle
/// folded back onto its neighbour, which gmsh's tetrahedralizer refuses as
/// a segment crossing a facet).
pub fn folded_edges(s: &Surface) -> usize {
    let normal = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| s.positions[i as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-300);
        n.map(|x| x / l)
    };
    let mut by_edge: std::collections::HashMap<(u32, u32), Vec<usize>> = Default::default();
    for (i, t) in s.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push(i);
        }
    }
    by_edge
        .values()
        .filter(|ts| ts.len() == 2)
        .filter(|ts| {
            let (m, n) = (normal(&s.triangles[ts[0]]), normal(&s.triangles[ts[1]]));
            m[0] * n[0] + m[1] * n[1] + m[2] * n[2] < -0.5
        })
        .count()
}
