//! Implicit solids (issue 5): the paper-001 listings, exact volumes and areas
//! converging with resolution, watertight/manifold/oriented meshes with the
//! right Euler characteristic, marching-cubes face ambiguities one by one,
//! and `.rfs` diagnostics with exact codes and positions.

mod implicit_common;

use geomc::implicit::polygonize::{self, Grid, Options, Surface, cell_links};
use geomc::implicit::{ImplicitModel, lang};
use geomc::span::SourceFile;
use implicit_common::{area, volume};
use std::collections::HashMap;

const SEVEN_BALLS: &str = include_str!("../fixtures/rfs/seven_balls.rfs");
const RIBBON: &str = include_str!("../fixtures/rfs/ribbon.rfs");

fn compile(text: &str) -> ImplicitModel {
    let (model, diags) = lang::compile(&SourceFile::new("t.rfs", text));
    assert!(!diags.has_errors(), "{:?}", diags.items);
    model.expect("a model when there are no errors")
}

/// (code, line, column, message) of every diagnostic.
fn diagnostics(text: &str) -> Vec<(String, u32, u32, String)> {
    let source = SourceFile::new("t.rfs", text);
    let (_, diags) = lang::compile(&source);
    diags
        .items
        .iter()
        .map(|d| {
            let at = d.span.map(|s| source.line_col(s.start as usize));
            (
                d.code.as_str().to_string(),
                at.map_or(0, |p| p.line),
                at.map_or(0, |p| p.column),
                d.message.clone(),
            )
        })
        .collect()
}

/// Checks that the mesh is closed, edge- and vertex-manifold and consistently
/// oriented; returns (components, Euler characteristic).
fn check_closed_manifold(s: &Surface) -> (usize, i64) {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &s.triangles {
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "triangle repeats a vertex: {t:?}"
        );
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(
            n, 1,
            "edge {a}-{b} used {n} times in one direction (non-manifold or flipped)"
        );
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "edge {a}-{b} has no opposite half-edge (hole or flipped triangle)"
        );
    }
    // Vertex-manifold: the triangles around each vertex form one fan.
    let mut around: HashMap<u32, Vec<(u32, u32)>> = HashMap::new();
    for t in &s.triangles {
        for k in 0..3 {
            around
                .entry(t[k])
                .or_default()
                .push((t[(k + 1) % 3], t[(k + 2) % 3]));
        }
    }
    for (v, fan) in &around {
        let next: HashMap<u32, u32> = fan.iter().copied().collect();
        let mut cur = fan[0].0;
        let mut steps = 0;
        loop {
            cur = next[&cur];
            steps += 1;
            if cur == fan[0].0 {
                break;
            }
            assert!(steps <= fan.len(), "vertex {v}: open fan");
        }
        assert_eq!(
            steps,
            fan.len(),
            "vertex {v}: its triangles form more than one fan"
        );
    }
    let used: Vec<u32> = around.keys().copied().collect();
    assert_eq!(used.len(), s.positions.len(), "every vertex is used");
    // Components by union-find over triangle edges.
    let mut parent: Vec<usize> = (0..s.positions.len()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for t in &s.triangles {
        for k in 0..3 {
            let (a, b) = (
                find(&mut parent, t[k] as usize),
                find(&mut parent, t[(k + 1) % 3] as usize),
            );
            parent[a] = b;
        }
    }
    let components = (0..parent.len())
        .filter(|&i| find(&mut parent, i) == i)
        .count();
    let v = s.positions.len() as i64;
    let e = directed.len() as i64 / 2;
    let f = s.triangles.len() as i64;
    (components, v - e + f)
}

#[test]
fn seven_balls_listing_compiles_as_printed() {
    let source = SourceFile::new("seven_balls.rfs", SEVEN_BALLS);
    let (model, diags) = lang::compile(&source);
    let model = model.expect("the listing compiles");
    // No diagnostics: optiterations is applied (W131 is no longer emitted).
    let codes: Vec<&str> = diags.items.iter().map(|d| d.code.as_str()).collect();
    assert!(codes.is_empty(), "{codes:?}");
    assert_eq!(model.name(), "balls");
    assert_eq!(model.geom.cells, [20, 20, 20]);
    assert_eq!(model.geom.min, [-1.0; 3]);
    assert_eq!(model.geom.max, [1.0; 3]);
    assert_eq!(model.geom.optiterations, 2);
    // f at a point equals the left fold of Rvachev unions of the seven balls.
    let p = [0.31, -0.52, 0.17];
    let ball = |r: f64, c: [f64; 3]| r * r - (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>();
    let or = |a: f64, b: f64| a + b + (a * a + b * b).sqrt();
    let centres = [
        [0.7, 0.0, 0.0],
        [-0.7, 0.0, 0.0],
        [0.0, 0.7, 0.0],
        [0.0, -0.7, 0.0],
        [0.0, 0.0, 0.7],
        [0.0, 0.0, -0.7],
    ];
    let want = centres
        .iter()
        .fold(ball(0.7, [0.0; 3]), |acc, &c| or(acc, ball(0.3, c)));
    let got = model.ssa().eval_point(p);
    assert!((got - want).abs() < 1e-12, "{got} vs {want}");
}

#[test]
fn ribbon_listing_compiles_as_printed() {
    let model = compile(RIBBON);
    assert_eq!(model.name(), "r_main");
    assert_eq!(model.geom.cells, [40, 40, 40]);
    assert_eq!(model.geom.min, [-3.0; 3]);
    let and = |a: f64, b: f64| a + b - (a * a + b * b).sqrt();
    for p in [[0.5f64, 0.25, 0.8], [-2.0, 1.0, -0.3], [2.9, -2.9, 0.1]] {
        let s = (p[0] + p[1]).sin();
        let ribbon = and(s - p[2] + 1.0, p[2] - s);
        let want = and(and(9.0 - p[0] * p[0], 9.0 - p[1] * p[1]), ribbon);
        let got = model.ssa().eval_point(p);
        assert!((got - want).abs() < 1e-12, "{p:?}: {got} vs {want}");
    }
    // The ribbon is a slab of thickness 1 (in z) over the 6 × 6 square: volume 36.
    let surface = model.polygonize(Some([48, 48, 48]));
    let (components, chi) = check_closed_manifold(&surface);
    assert_eq!((components, chi), (1, 2));
    let v = volume(&surface);
    assert!((v - 36.0).abs() < 0.5, "ribbon volume {v}");
}

#[test]
fn seven_balls_volume_and_area_converge() {
    let model = compile(SEVEN_BALLS);
    let (exact_v, exact_a) = (1.830576, 8.581036);
    let mut errors = Vec::new();
    for n in [24, 48, 96] {
        let s = model.polygonize(Some([n, n, n]));
        let (components, chi) = check_closed_manifold(&s);
        assert_eq!(
            (components, chi),
            (1, 2),
            "at {n}³ the seven balls are one sphere-like surface"
        );
        let (ev, ea) = (
            (volume(&s) - exact_v).abs() / exact_v,
            (area(&s) - exact_a).abs() / exact_a,
        );
        errors.push((n, ev, ea));
    }
    for w in errors.windows(2) {
        assert!(
            w[1].1 < w[0].1 && w[1].2 < w[0].2,
            "errors must shrink with resolution: {errors:?}"
        );
    }
    let (_, ev, ea) = errors[2];
    assert!(
        ev < 1e-3 && ea < 8e-3,
        "at 96³: volume error {ev}, area error {ea}"
    );
}

#[test]
fn ball_and_box_have_their_exact_measures() {
    let ball = compile(
        "Geom.nx = 64; Geom.ny = 64; Geom.nz = 64;\nfunction r_main(x, y, z) { return Ball(x, y, z, 0.8, 0.05, -0.02, 0.03); }",
    );
    let s = ball.polygonize(None);
    assert_eq!(check_closed_manifold(&s), (1, 2));
    let (v, a) = (volume(&s), area(&s));
    let (ev, ea) = (
        4.0 / 3.0 * std::f64::consts::PI * 0.512,
        4.0 * std::f64::consts::PI * 0.64,
    );
    assert!((v - ev).abs() / ev < 2e-3, "ball volume {v} vs {ev}");
    assert!((a - ea).abs() / ea < 5e-3, "ball area {a} vs {ea}");
    assert!(v > 0.0, "outward orientation gives a positive volume");
    // A box 1.1 × 0.9 × 0.7 whose faces do not lie on grid planes.
    let bx = compile(
        "Geom.nx = 64; Geom.ny = 64; Geom.nz = 64;\nfunction r_main(x, y, z) { return Box(x, y, z, -0.53, -0.41, -0.33, 1.1, 0.9, 0.7); }",
    );
    let s = bx.polygonize(None);
    assert_eq!(check_closed_manifold(&s), (1, 2));
    let (v, a) = (volume(&s), area(&s));
    let (ev, ea) = (1.1 * 0.9 * 0.7, 2.0 * (1.1 * 0.9 + 1.1 * 0.7 + 0.9 * 0.7));
    // Marching cubes chamfers the box's edges by about a cell.
    assert!((v - ev).abs() / ev < 0.01, "box volume {v} vs {ev}");
    assert!((a - ea).abs() / ea < 0.02, "box area {a} vs {ea}");
}

#[test]
fn a_torus_has_genus_one_and_a_solid_leaving_the_box_is_capped() {
    let torus = compile(
        "Geom.nx = 40; Geom.ny = 40; Geom.nz = 40;\nfunction r_main(x, y, z) { var d = Math.sqrt(x * x + y * y) - 0.6; return 0.25 * 0.25 - d * d - z * z; }",
    );
    let s = torus.polygonize(None);
    assert_eq!(check_closed_manifold(&s), (1, 0), "χ = 0: genus 1");
    // A ball of radius 1.3 in the unit box [-1, 1]³ is cut by the box: capped, closed.
    let big = compile(
        "Geom.nx = 32; Geom.ny = 32; Geom.nz = 32;\nfunction r_main(x, y, z) { return Ball(x, y, z, 1.3, 0, 0, 0); }",
    );
    let s = big.polygonize(None);
    assert_eq!(check_closed_manifold(&s), (1, 2));
    assert!(s.positions.iter().all(|p| p.iter().all(|c| c.abs() <= 1.0)));
    // Two balls apart: two components, χ = 4.
    let two = compile(
        "Geom.rsystem = \"minmax\";\nfunction r_main(x, y, z) { return Union(Ball(x, y, z, 0.3, -0.5, 0, 0), Ball(x, y, z, 0.3, 0.5, 0, 0)); }",
    );
    assert_eq!(check_closed_manifold(&two.polygonize(None)), (2, 4));
}

#[test]
fn pruning_does_not_change_the_mesh_topology_or_volume_much() {
    let model = compile(SEVEN_BALLS);
    let grid = Grid {
        min: [-1.0; 3],
        max: [1.0; 3],
        cells: [40, 40, 40],
    };
    let pruned = polygonize::polygonize(&model.ssa(), &grid, &Options::default());
    let dense = polygonize::polygonize(
        &model.ssa(),
        &grid,
        &Options {
            prune: false,
            ..Options::default()
        },
    );
    assert!(pruned.pruned_blocks > 0 && dense.pruned_blocks == 0);
    // Same zero set, same samples' signs: the same crossed edges.
    assert_eq!(pruned.positions.len(), dense.positions.len());
    assert_eq!(check_closed_manifold(&pruned), (1, 2));
    assert!((volume(&pruned) - volume(&dense)).abs() < 1e-3);
}

#[test]
fn output_is_the_same_for_any_thread_count() {
    let run = on_threads(compile(SEVEN_BALLS), [33, 30, 27]);
    assert_eq!(run(1), run(3));
}

#[test]
fn output_is_the_same_for_any_thread_count_with_runs_of_several_slabs() {
    // 100 cells in z: runs of 4 slabs (32 runs), whose inner planes are
    // refined together and straddle block layers.
    let run = on_threads(compile(SEVEN_BALLS), [24, 21, 100]);
    let one = run(1);
    assert_eq!(check_closed_manifold(&one), (1, 2));
    assert_eq!(one, run(2));
    assert_eq!(one, run(3));
}

/// Polygonizes `model` on a grid of `cells` in a pool of the given thread count.
fn on_threads(model: ImplicitModel, cells: [usize; 3]) -> impl Fn(usize) -> Surface {
    move |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| model.polygonize(Some(cells)))
    }
}

/// The faces of a cell in [`cell_links`]' corner numbering, (corner, corner) pairs
/// for each face's edges; corner c is at (c & 1, c >> 1 & 1, c >> 2 & 1).
fn corner(c: usize) -> [usize; 3] {
    [c & 1, c >> 1 & 1, c >> 2 & 1]
}

const EDGES: [(usize, usize); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// The segments a cell draws on its face x = 1 (corners 1, 3, 5, 7), as pairs
/// of edge midpoints in global coordinates, unordered.
fn face_segments(
    values: &[f64; 8],
    offset: [usize; 3],
    axis: usize,
    side: usize,
) -> Vec<[[usize; 3]; 2]> {
    let next = cell_links(values);
    let on_face = |e: usize| {
        let (a, b) = EDGES[e];
        corner(a)[axis] == side && corner(b)[axis] == side
    };
    let key = |e: usize| {
        let (a, b) = EDGES[e];
        let (ca, cb) = (corner(a), corner(b));
        // Twice the midpoint, in global integer coordinates.
        [0, 1, 2].map(|k| 2 * offset[k] + ca[k] + cb[k])
    };
    let mut segs: Vec<[[usize; 3]; 2]> = (0..12)
        .filter(|&e| next[e] != u8::MAX && on_face(e) && on_face(next[e] as usize))
        .map(|e| {
            let mut s = [key(e), key(next[e] as usize)];
            s.sort();
            s
        })
        .collect();
    segs.sort();
    segs
}

#[test]
fn ambiguous_faces_agree_between_neighbouring_cells() {
    // Face x = 1 of the left cell is face x = 0 of the right cell. Corners on it:
    // left 1, 3, 5, 7 = right 0, 2, 4, 6. Every sign pattern of that face with two
    // magnitudes per corner (both decider outcomes for the ambiguous patterns).
    let mut ambiguous = 0;
    for pattern in 0..16u32 {
        for scale in 0..16u32 {
            let face: [f64; 4] = std::array::from_fn(|m| {
                let sign = if pattern >> m & 1 == 1 { 1.0 } else { -1.0 };
                sign * if scale >> m & 1 == 1 { 2.0 } else { 0.5 }
            });
            // Face corners (y, z) = (0,0), (1,0), (0,1), (1,1).
            let mut left = [-1.0, face[0], 0.7, face[1], -0.3, face[2], 1.2, face[3]];
            let mut right = [face[0], -0.8, face[1], 0.4, face[2], 1.5, face[3], -0.6];
            // Vary the far corners too, so the cells are not mirror images.
            left[0] = if pattern & 1 == 1 { 0.9 } else { -0.9 };
            right[7] = if scale & 1 == 1 { 0.2 } else { -1.1 };
            let l = face_segments(&left, [0, 0, 0], 0, 1);
            let r = face_segments(&right, [1, 0, 0], 0, 0);
            assert_eq!(l, r, "pattern {pattern:04b} scale {scale:04b}");
            let crossings = (0..4)
                .filter(|&m| (face[m] > 0.0) != (face[[1, 3, 0, 2][m]] > 0.0))
                .count();
            assert_eq!(l.len(), crossings / 2);
            if crossings == 4 {
                ambiguous += 1;
            }
        }
    }
    assert_eq!(ambiguous, 2 * 16);
}

#[test]
fn the_asymptotic_decider_joins_by_the_saddle_value() {
    // Face z = 0: corners 0 (0,0), 1 (1,0), 3 (1,1), 2 (0,1); 0 and 3 inside.
    // v0 v3 > v1 v2: the centre is inside, the inside corners are joined, so
    // the segments cut off corners 1 and 2.
    let joined = [1.0, -0.2, -0.2, 1.0, -1.0, -1.0, -1.0, -1.0];
    let separate = [0.2, -1.0, -1.0, 0.2, -1.0, -1.0, -1.0, -1.0];
    let segs = |v: &[f64; 8]| face_segments(v, [0, 0, 0], 2, 0);
    // Midpoints ×2: edge 0–1 → (1,0,0), 1–3 → (2,1,0), 0–2 → (0,1,0), 2–3 → (1,2,0).
    assert_eq!(
        segs(&joined),
        vec![[[0, 1, 0], [1, 2, 0]], [[1, 0, 0], [2, 1, 0]]]
    );
    assert_eq!(
        segs(&separate),
        vec![[[0, 1, 0], [1, 0, 0]], [[1, 2, 0], [2, 1, 0]]]
    );
    // Exactly on the saddle (v0 v3 = v1 v2) counts as outside: separate.
    let tie = [0.5, -0.5, -0.5, 0.5, -1.0, -1.0, -1.0, -1.0];
    assert_eq!(segs(&tie), segs(&separate));
}

#[test]
fn every_cell_configuration_gives_closed_cycles() {
    // All 256 sign patterns, magnitudes varied: every crossed edge is in exactly
    // one cycle (one successor, one predecessor).
    for pattern in 0..256u32 {
        for scale in [0u32, 0x5a, 0xa5, 0xff] {
            let v: [f64; 8] = std::array::from_fn(|c| {
                let m = if scale >> c & 1 == 1 { 1.7 } else { 0.4 };
                if pattern >> c & 1 == 1 { m } else { -m }
            });
            let next = cell_links(&v);
            let crossed: Vec<usize> = (0..12)
                .filter(|&e| (v[EDGES[e].0] > 0.0) != (v[EDGES[e].1] > 0.0))
                .collect();
            let linked: Vec<usize> = (0..12).filter(|&e| next[e] != u8::MAX).collect();
            assert_eq!(crossed, linked, "pattern {pattern:08b}");
            let mut targets: Vec<usize> = linked.iter().map(|&e| next[e] as usize).collect();
            targets.sort();
            assert_eq!(
                targets, crossed,
                "pattern {pattern:08b}: a crossing is entered twice"
            );
        }
    }
}

#[test]
fn random_fields_give_closed_manifold_meshes() {
    // Sampled fields with many ambiguous faces, polygonized without a function.
    let mut state = 12345u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f64 / u32::MAX as f64 * 2.0 - 1.0
    };
    for _ in 0..20 {
        let grid = Grid {
            min: [0.0; 3],
            max: [1.0; 3],
            cells: [9, 8, 10],
        };
        let values: Vec<f64> = (0..10 * 9 * 11).map(|_| next()).collect();
        let s = polygonize::polygonize_samples(values, &grid, &Options::default());
        let (components, chi) = check_closed_manifold(&s);
        assert!(components >= 1);
        assert_eq!(chi % 2, 0, "closed orientable surfaces have even χ");
        assert!(volume(&s) > 0.0);
    }
}

#[test]
fn rfs_errors_have_codes_and_positions() {
    let cases: &[(&str, (&str, u32, u32))] = &[
        (
            "Geom.nx = 20\nfunction r_main(x, y, z) { return 1; }",
            ("E600", 2, 1),
        ),
        (
            "function r_main(x, y, z) {\n  return Bal(x, y, z, 1, 0, 0, 0);\n}",
            ("E601", 2, 10),
        ),
        (
            "function r_main(x, y, z) {\n  return Ball(x, y, z, 1);\n}",
            ("E602", 2, 10),
        ),
        (
            "Geom.nx = 0;\nfunction r_main(x, y, z) { return x; }",
            ("E603", 1, 11),
        ),
        (
            "Geom.ny = 5000;\nfunction r_main(x, y, z) { return x; }",
            ("E603", 1, 11),
        ),
        (
            "Geom.name = \"body\";\nfunction r_main(x, y, z) { return x; }",
            ("E604", 1, 13),
        ),
        (
            "function f(a) { return f(a); }\nfunction r_main(x, y, z) { return f(x); }",
            ("E605", 1, 24),
        ),
        (
            "function r_main(x, y, z) { return RegularPolygon(x, y, 1, 0, 0, z); }",
            ("E606", 1, 35),
        ),
        (
            "function r_main(x, y, z) { return x; }\nfunction r_main(x, y, z) { return y; }",
            ("E607", 2, 10),
        ),
        ("function r_main(x, y) { return x; }", ("E608", 1, 10)),
        (
            "Geom.name = 3;\nfunction r_main(x, y, z) { return x; }",
            ("E610", 1, 13),
        ),
        ("function r_main(x, y, z) { var a = x; }", ("E611", 1, 10)),
        (
            "function r_main(x, y, z) { return x # y; }",
            ("E600", 1, 37),
        ),
        (
            "/* open\nfunction r_main(x, y, z) { return x; }",
            ("E600", 1, 1),
        ),
        (
            "function r_main(x, y, z) { return Math.sine(x); }",
            ("E601", 1, 35),
        ),
        (
            "Geom.x_min = 1; Geom.x_max = -1;\nfunction r_main(x, y, z) { return x; }",
            ("E603", 1, 30),
        ),
    ];
    for (text, (code, line, column)) in cases {
        let d = diagnostics(text);
        let first = d
            .iter()
            .find(|d| d.0.starts_with('E'))
            .unwrap_or_else(|| panic!("no error for {text:?}: {d:?}"));
        assert_eq!(
            (first.0.as_str(), first.1, first.2),
            (*code, *line, *column),
            "{text:?}: {}",
            first.3
        );
    }
    let deep = format!(
        "function r_main(x, y, z) {{ return {}x{}; }}",
        "(".repeat(500),
        ")".repeat(500)
    );
    assert_eq!(diagnostics(&deep)[0].0, "E609");
    let unknown_field = diagnostics("Geom.nxx = 4;\nfunction r_main(x, y, z) { return x; }");
    assert_eq!(unknown_field[0].0, "W130");
    assert_eq!(unknown_field.len(), 1);
}

#[test]
fn r_systems_change_values_but_not_the_solid() {
    let body = "function r_main(x, y, z) { return Union(Ball(x, y, z, 0.5, -0.3, 0, 0), Ball(x, y, z, 0.5, 0.3, 0, 0)); }";
    let mut volumes = Vec::new();
    for system in [
        "Geom.rsystem = \"rvachev\";",
        "Geom.rsystem = \"minmax\";",
        "Geom.rsystem = \"alpha\"; Geom.alpha = 0.5;",
    ] {
        let model = compile(&format!(
            "{system} Geom.nx = 40; Geom.ny = 40; Geom.nz = 40;\n{body}"
        ));
        let s = model.polygonize(None);
        assert_eq!(check_closed_manifold(&s), (1, 2));
        volumes.push(volume(&s));
    }
    assert!(
        volumes
            .iter()
            .all(|v| (v - volumes[1]).abs() < 0.01 * volumes[1]),
        "{volumes:?}"
    );
    assert_eq!(
        diagnostics("Geom.alpha = -1;\nfunction r_main(x, y, z) { return x; }")[0].0,
        "E603"
    );
}

#[test]
fn two_dimensional_primitives_make_prisms() {
    // A 2D primitive of (x, y) ∧ a z slab: volume = area × height.
    let cases = [
        ("Rectangle(x, y, -0.5, -0.3, 0.9, 0.6)", 0.9 * 0.6),
        ("Disk(x, y, 0.6, 0.05, 0)", std::f64::consts::PI * 0.36),
        ("Ellipse(x, y, 0, 0, 0.7, 0.4)", std::f64::consts::PI * 0.28),
        (
            "RegularPolygon(x, y, 0.7, 0, 0, 6)",
            1.5 * 3f64.sqrt() * 0.49,
        ),
        (
            "ConvexPolygon(x, y, -0.5, -0.5, -0.5, 0.5, 0.5, 0.5, 0.5, -0.5)",
            1.0,
        ),
        ("Parallelogram(x, y, -0.6, -0.4, 0.8, 0.7, 1.2)", 0.8 * 0.7),
        (
            "RoundedRectangle(x, y, -0.6, -0.4, 1.2, 0.8, 0.2)",
            1.2 * 0.8 - (4.0 - std::f64::consts::PI) * 0.04,
        ),
        ("Sector(x, y, 0, 0, 0.8, 0.3, 2.0)", 0.5 * 0.64 * 1.7),
        ("Sector(x, y, 0, 0, 0.8, 0, 4.5)", 0.5 * 0.64 * 4.5),
        ("HalfPlane(x, y, 0.2, -1, 0.2, 1)", 0.8 * 2.0),
    ];
    for (shape, area2d) in cases {
        let text = format!(
            "Geom.nx = 64; Geom.ny = 64; Geom.nz = 32;\nfunction r_main(x, y, z) {{ return Intersection({shape}, Box(x, y, z, -2, -2, -0.5, 4, 4, 1)); }}"
        );
        let s = compile(&text).polygonize(None);
        assert_eq!(check_closed_manifold(&s), (1, 2), "{shape}");
        let v = volume(&s);
        assert!(
            (v - area2d).abs() / area2d < 0.02,
            "{shape}: volume {v} vs {area2d}"
        );
    }
}

#[test]
fn geomc_compile_meshes_an_rfs_file_and_refuses_a_bad_one() {
    let dir = tempfile::tempdir().expect("temp dir");
    let glb = dir.path().join("balls.glb");
    let stl = dir.path().join("balls.stl");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args([
            "compile",
            "fixtures/rfs/seven_balls.rfs",
            "--cells",
            "16",
            "-o",
        ])
        .arg(&glb)
        .arg("-o")
        .arg(&stl)
        .output()
        .expect("geomc runs");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(&std::fs::read(&glb).expect("glb written")[..4], b"glTF");
    // Binary STL: 80-byte header, then the triangle count.
    let bytes = std::fs::read(&stl).expect("stl written");
    let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
    let model = compile(SEVEN_BALLS);
    assert_eq!(count, model.polygonize(Some([16, 16, 16])).triangles.len());

    let bad = dir.path().join("bad.rfs");
    std::fs::write(
        &bad,
        "Geom.nx = 20\nfunction r_main(x, y, z) { return x; }\n",
    )
    .expect("write");
    let out = dir.path().join("bad.glb");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_geomc"))
        .arg("compile")
        .arg(&bad)
        .arg("-o")
        .arg(&out)
        .output()
        .expect("geomc runs");
    assert_eq!(run.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("bad.rfs:2:1: error[E600]: expected ';', found 'function'"),
        "{stderr}"
    );
    assert!(!out.exists(), "no output for a failed compile");
}

/// Found by the `rfs_language` fuzz target (30-minute run, 2026-11-26): a
/// function that is NaN on part of the box (sqrt of a negative) crosses
/// "zero" between a NaN sample and a positive one; root refinement then
/// carried the NaN into its bracket and `f64::clamp` panicked.
#[test]
fn a_function_that_is_nan_on_part_of_the_box_polygonizes_without_panic() {
    let model = compile("function r_main(x, y, z) { return Math.sqrt(x + 0.03) - 0.1 * y; }");
    let surface = model.polygonize(Some([8, 8, 8]));
    // Every vertex that was written is a real point of the box.
    assert!(!surface.triangles.is_empty());
    for p in &surface.positions {
        assert!(
            p.iter().all(|c| c.is_finite() && (-1.0..=1.0).contains(c)),
            "{p:?}"
        );
    }
}
