//! Grids aligned with the surface (issue 5): when the surface passes through
//! grid samples, the crossings there are one mesh node, no triangle has zero
//! area, and the mesh stays closed, manifold and oriented with the right
//! volume.

mod implicit_common;
mod writers_common;

use geomc::implicit::polygonize::Surface;
use geomc::implicit::{ImplicitModel, lang};
use geomc::span::SourceFile;
use implicit_common::{folded_edges, geomc_ok, volume};
use std::collections::HashMap;
use std::path::Path;
use writers_common::run_json;

const SEVEN_BALLS: &str = include_str!("../fixtures/rfs/seven_balls.rfs");

fn compile(text: &str) -> ImplicitModel {
    let (model, diags) = lang::compile(&SourceFile::new("t.rfs", text));
    assert!(!diags.has_errors(), "{:?}", diags.items);
    model.expect("a model when there are no errors")
}

/// Triangles with a repeated node or (near) zero area, as `geomc inspect`
/// counts them (twice the area below 1e-14 of the squared diagonal).
fn degenerate(s: &Surface) -> usize {
    let floor = 12.0 * 1e-14;
    s.triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|i| s.positions[i as usize]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            t[0] == t[1]
                || t[1] == t[2]
                || t[0] == t[2]
                || n.iter().map(|x| x * x).sum::<f64>().sqrt() <= floor
        })
        .count()
}

/// Every edge in exactly two triangles, once in each direction; every node
/// used; the triangles around each node one fan. Returns V − E + F.
fn euler_of_closed_manifold(s: &Surface) -> i64 {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    let mut around: HashMap<u32, Vec<(u32, u32)>> = HashMap::new();
    for t in &s.triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            around
                .entry(t[k])
                .or_default()
                .push((t[(k + 1) % 3], t[(k + 2) % 3]));
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "edge {a}-{b} used {n} times in one direction");
        assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}-{b} is open");
    }
    assert_eq!(around.len(), s.positions.len(), "every node is used");
    for (v, fan) in &around {
        let next: HashMap<u32, u32> = fan.iter().copied().collect();
        let (mut cur, mut steps) = (fan[0].0, 0);
        loop {
            cur = next[&cur];
            steps += 1;
            if cur == fan[0].0 || steps > fan.len() {
                break;
            }
        }
        assert_eq!(steps, fan.len(), "node {v}: more than one fan (a pinch)");
    }
    s.positions.len() as i64 - directed.len() as i64 / 2 + s.triangles.len() as i64
}

/// Nodes at a grid sample (every coordinate a multiple of the spacing `h`
/// from -1): the crossings the weld made one node.
fn nodes_on_samples(s: &Surface, h: f64) -> usize {
    s.positions
        .iter()
        .filter(|p| {
            p.iter().all(|&c| {
                let q = (c + 1.0) / h;
                (q - q.round()).abs() < 1e-9
            })
        })
        .count()
}

/// Checks a model meshed on a grid aligned with its surface: no degenerate
/// triangle, closed and manifold with Euler characteristic `chi`, volume
/// within `tolerance` of `exact`; returns the nodes on samples.
fn check_aligned(text: &str, iterations: u32, chi: i64, exact: f64, tolerance: f64) -> usize {
    let mut m = compile(text);
    m.geom.optiterations = iterations;
    let s = m.polygonize(None);
    assert_eq!(degenerate(&s), 0, "{text} with {iterations} iterations");
    assert_eq!(euler_of_closed_manifold(&s), chi, "{text}");
    let v = volume(&s);
    assert!(
        (v - exact).abs() / exact < tolerance,
        "{text}: volume {v} vs {exact}"
    );
    let h = (m.geom.max[0] - m.geom.min[0]) / m.geom.cells[0] as f64;
    nodes_on_samples(&s, h)
}

#[test]
fn spheres_with_a_radius_on_the_grid_are_clean() {
    // h = 0.1: radius 0.5 at the origin passes through samples (±0.5, 0, 0)…
    // and (0.3, 0.4, 0), (0.4, 0, 0.3)…: 30 of them.
    let ball = "Geom.nx = 20; Geom.ny = 20; Geom.nz = 20;
function r_main(x, y, z) { return Ball(x, y, z, 0.5, 0, 0, 0); }";
    let exact = 4.0 / 3.0 * std::f64::consts::PI * 0.125;
    for iterations in [0, 3] {
        let on = check_aligned(ball, iterations, 2, exact, 0.03);
        assert!(on >= 6, "{on} nodes on samples");
    }
    // Two balls touching at the sample (0, 0, 0): one closed surface each,
    // the touching point one node per ball (χ = 4).
    let touching = "Geom.nx = 20; Geom.ny = 20; Geom.nz = 20; Geom.rsystem = \"minmax\";
function r_main(x, y, z) { return Union(Ball(x, y, z, 0.4, -0.4, 0, 0), Ball(x, y, z, 0.4, 0.4, 0, 0)); }";
    let exact = 2.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.064;
    check_aligned(touching, 0, 4, exact, 0.05);
}

#[test]
fn planes_through_grid_samples_are_clean() {
    // A box whose six faces lie on sample planes (h = 0.1), and a diagonal
    // plane x + y = 0.2 through samples, capped by the grid's box.
    let block = "Geom.nx = 20; Geom.ny = 20; Geom.nz = 20; Geom.rsystem = \"minmax\";
function r_main(x, y, z) { return Box(x, y, z, -0.5, -0.4, -0.3, 1.0, 0.8, 0.9); }";
    // Marching cubes chamfers the box's edges (half a cell): 4.5% at 20³.
    let on = check_aligned(block, 0, 2, 1.0 * 0.8 * 0.9, 0.05);
    assert!(on > 300, "{on} nodes on samples");
    let diagonal = "Geom.nx = 20; Geom.ny = 20; Geom.nz = 20;
function r_main(x, y, z) { return 0.2 - x - y; }";
    // Below x + y = 0.2 in [-1, 1]³: 8 − 1.8²; the cap on the box chamfers
    // the edges where the plane meets it (1.9%).
    let on = check_aligned(diagonal, 0, 2, 8.0 - 1.8 * 1.8, 0.03);
    assert!(on >= 19 * 21, "{on} nodes on samples");
    check_aligned(diagonal, 2, 2, 8.0 - 1.8 * 1.8, 0.03);
}

#[test]
fn seven_balls_at_20_cells_have_no_degenerate_triangles() {
    let model = compile(SEVEN_BALLS);
    let exact = 1.830576;
    for iterations in [0, 2] {
        let mut m = model.clone();
        m.geom.optiterations = iterations;
        let s = m.polygonize(None);
        assert_eq!(m.geom.cells, [20, 20, 20]);
        assert_eq!(degenerate(&s), 0, "optiterations {iterations}");
        assert_eq!(euler_of_closed_manifold(&s), 2);
        let v = volume(&s);
        assert!((v - exact).abs() / exact < 0.02, "volume {v}");
        // The balls' extreme points (±0.7, 0, 0), (±1.0…) lie on samples.
        assert!(nodes_on_samples(&s, 0.1) >= 6);
    }
}

/// The seven balls written by `geomc compile` as MSH at 20³ (aligned), 32³
/// and 48³ (not): gmsh reads the surface, and its 3D mesher fills the volume
/// (tests/tools/check_mesh.py --tetra; ./scripts/test.sh installs gmsh).
/// At 32³ the crease snap of the two optimisation rounds used to turn a
/// triangle over where ball 6 meets ball 1 (gmsh: "a segment and a facet
/// intersect").
#[test]
fn gmsh_tetrahedralizes_the_seven_balls() {
    let dir = tempfile::tempdir().expect("temp dir");
    let rfs = dir.path().join("balls.rfs");
    std::fs::write(&rfs, SEVEN_BALLS).expect("write the listing");
    for cells in ["20", "32", "48"] {
        let msh = dir.path().join(format!("balls{cells}.msh"));
        geomc_ok(&["compile", "-q", "--cells", cells, "-o"], &[&msh, &rfs]);
        let report = run_json("python3", "check_mesh.py", &[&msh, Path::new("--tetra")]);
        assert_eq!(report["tetra"]["ok"], true, "{cells}: {report}");
        let tets = report["tetra"]["tetrahedra"]["balls"].as_u64().unwrap_or(0);
        assert!(tets > 1000, "{cells}: {tets} tetrahedra: {report}");
    }
}

/// The crease snap and smoothing never fold a triangle back onto its
/// neighbour: at 32³ the unguarded snap left two folded edges at the rim of
/// ball 6 (normals 175° apart); every grid from 16³ to 40³ has none.
#[test]
fn optimisation_folds_no_triangle_of_the_seven_balls() {
    let model = compile(SEVEN_BALLS);
    assert_eq!(model.geom.optiterations, 2);
    for n in [16, 24, 30, 32, 36, 40] {
        let s = model.polygonize(Some([n; 3]));
        assert_eq!(folded_edges(&s), 0, "{n}³");
        assert_eq!(euler_of_closed_manifold(&s), 2, "{n}³");
        assert_eq!(degenerate(&s), 0, "{n}³");
    }
}
