//! The 2D mesher (spade's constrained Delaunay triangulation + geomc's
//! refinement) on arbitrary point sets: a polygon with 3–12 vertices on a fine
//! grid (duplicates, collinear runs, slivers and self-touching outlines all
//! reachable) and up to four poly_line segments, decoded from the bytes and
//! fed through the real front end. The mesher must never panic (its own panic
//! guard turns one into `MeshError::Internal`, treated here as a crash), and a
//! mesh it returns must pass `sanity_check`, have only non-degenerate
//! triangles of one orientation covering exactly the polygon's area, and keep
//! every polygon corner as a node.
#![no_main]

use geomc::driver::{Options, check_source};
use geomc::meshing::{MeshError, MeshOptions, mesh_model, sanity_check};
use geomc::span::SourceFile;
use libfuzzer_sys::fuzz_target;
use std::fmt::Write;

/// Reads the bytes front to back; missing bytes read as zero.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn u8(&mut self) -> u8 {
        let (first, rest) = self.0.split_first().map_or((0, &[][..]), |(f, r)| (*f, r));
        self.0 = rest;
        first
    }

    /// A coordinate in [-8, 8) on a 1/4096 grid.
    fn coordinate(&mut self) -> f64 {
        let v = i16::from_le_bytes([self.u8(), self.u8()]);
        f64::from(v) / 4096.0
    }

    fn point(&mut self) -> [f64; 2] {
        [self.coordinate(), self.coordinate()]
    }
}

fn shoelace(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| {
            let (p, q) = (points[i], points[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum::<f64>()
        / 2.0
}

fuzz_target!(|data: &[u8]| {
    let mut bytes = Bytes(data);
    let flags = bytes.u8();
    let count = 3 + usize::from(bytes.u8() % 10);
    let polygon: Vec<[f64; 2]> = (0..count).map(|_| bytes.point()).collect();
    let segments: Vec<[[f64; 2]; 2]> = (0..usize::from(flags >> 6))
        .map(|_| [bytes.point(), bytes.point()])
        .collect();
    let mut xml = String::from(r#"<geometry version="1" dimension="2"><polygon name="p">"#);
    for [x, y] in &polygon {
        let _ = write!(xml, r#"<vertex x="{x}" y="{y}"/>"#);
    }
    xml.push_str("</polygon>");
    if !segments.is_empty() {
        xml.push_str(r#"<poly_line name="cut">"#);
        for [[x0, y0], [x1, y1]] in &segments {
            let _ = write!(
                xml,
                r#"<line><begin_point x="{x0}" y="{y0}"/><end_point x="{x1}" y="{y1}"/></line>"#
            );
        }
        xml.push_str("</poly_line>");
    }
    xml.push_str(r#"<subdomain name="inside"><solid ref="p"/></subdomain></geometry>"#);

    let checked = check_source(SourceFile::new("fuzz.xml", xml), &Options::default());
    if !checked.is_valid() {
        return;
    }
    let Some(lowered) = checked.lowered else {
        return;
    };
    let area = shoelace(&polygon).abs();
    let (lo, hi) = polygon.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        },
    );
    let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    // An area limit keeps every mesh small (at most a few thousand triangles
    // from the limit; small angles may add more).
    let options = MeshOptions {
        min_angle_degrees: [1.0, 15.0, 20.0, 25.0][usize::from(flags & 3)],
        max_area: Some((extent * extent / f64::from(8 + u16::from(flags >> 2 & 15) * 32)).max(1e-6)),
        order: 1 + (flags >> 2 & 1),
        ..MeshOptions::default()
    };
    let mesh = match mesh_model(&lowered.model, &options) {
        Ok(mesh) => mesh,
        Err(MeshError::Internal { entity, message }) => {
            panic!("internal meshing failure on {entity}: {message}")
        }
        Err(_) => return,
    };
    if let Err(e) = sanity_check(&mesh) {
        panic!("mesh fails its sanity check: {e}");
    }
    let node = |i: u32| mesh.nodes[i as usize];
    let mut sum = 0.0;
    let mut signs = [0usize; 2];
    for face in &mesh.faces {
        for &[a, b, c] in &face.triangles {
            let (p, q, r) = (node(a), node(b), node(c));
            let twice = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
            assert!(twice != 0.0, "degenerate triangle {p:?} {q:?} {r:?}");
            signs[usize::from(twice < 0.0)] += 1;
            sum += twice.abs() / 2.0;
        }
    }
    assert!(
        signs[0] == 0 || signs[1] == 0,
        "mixed orientations {signs:?}"
    );
    let scale = extent * extent;
    assert!(
        (sum - area).abs() <= 1e-9 * scale.max(1e-300),
        "triangles cover {sum}, the polygon has {area}"
    );
    for p in &polygon {
        assert!(
            mesh.nodes.iter().any(|n| n[0] == p[0] && n[1] == p[1]),
            "polygon corner {p:?} is not a node"
        );
    }
});
