//! Issue 6: poly_lines touching the region boundary at a tip. An edge crack
//! (first point on the plate's bottom side, going in) splits the boundary
//! edge at its mouth and opens there too: both sides are fragments of their
//! own, the mouth node is duplicated, the inner tip is shared, and the mesh
//! is conforming (every edge used by one triangle lies on a mesh edge).
//! Two poly_lines that cross are refused naming both.

use geomc::driver::{Options, check_source};
use geomc::mesh::Mesh;
use geomc::meshing::{MeshError, MeshOptions, mesh_model};
use geomc::span::SourceFile;
use std::collections::HashSet;

mod mesh2d_common;
use mesh2d_common::{edge_uses, key, length, min_angle_degrees};

fn mesh(lines: &str, max_area: f64) -> Result<Mesh, MeshError> {
    let xml = format!(
        r#"<geometry version="1" dimension="2">
      <polygon name="plate"><vertex x="0" y="0"/><vertex x="2" y="0"/><vertex x="2" y="1"/><vertex x="0" y="1"/></polygon>
      {lines}
      <subdomain name="sheet"><solid ref="plate"/></subdomain>
    </geometry>"#
    );
    let checked = check_source(SourceFile::new("t.xml", &xml), &Options::default());
    assert!(checked.is_valid(), "{:#?}", checked.diagnostics.items);
    let model = checked.lowered.expect("a model").model;
    let options = MeshOptions {
        max_area: Some(max_area),
        min_angle_degrees: 28.0,
        ..MeshOptions::default()
    };
    mesh_model(&model, &options)
}

fn line(name: &str, crack: bool, points: &[(f64, f64)]) -> String {
    let segments: String = points
        .windows(2)
        .map(|w| {
            format!(
                r#"<line><begin_point x="{}" y="{}"/><end_point x="{}" y="{}"/></line>"#,
                w[0].0, w[0].1, w[1].0, w[1].1
            )
        })
        .collect();
    format!(r#"<poly_line name="{name}" crack="{crack}">{segments}</poly_line>"#)
}

#[test]
fn edge_crack_opens_at_its_mouth_and_stays_conforming() {
    for max_area in [0.002, 0.0003] {
        // From the bottom side at (1, 0) up to (1.1, 0.5), in two pieces.
        let crack = line("cr", true, &[(1.0, 0.0), (1.0, 0.3), (1.1, 0.5)]);
        let mesh = mesh(&crack, max_area).expect("an edge crack meshes");
        let crack_length = 0.3 + 0.1f64.hypot(0.2);
        let side = |name: &str| {
            let fragment = mesh
                .fragments
                .iter()
                .find(|f| f.name == name)
                .unwrap_or_else(|| panic!("max-area {max_area}: no fragment {name}"));
            mesh.edges[fragment.edges[0] as usize].nodes.clone()
        };
        let (left, right) = (side("cr.left"), side("cr.right"));
        assert!(
            left.len() > 4,
            "max-area {max_area}: {} crack nodes",
            left.len()
        );
        assert_eq!(left.len(), right.len());
        for nodes in [&left, &right] {
            assert!((length(&mesh, nodes) - crack_length).abs() < 1e-12);
        }
        // The mouth is opened (two nodes at (1, 0)), the inner tip shared.
        assert_ne!(left[0], right[0]);
        assert_eq!(mesh.nodes[left[0] as usize], [1.0, 0.0, 0.0]);
        assert_eq!(mesh.nodes[right[0] as usize], [1.0, 0.0, 0.0]);
        assert_eq!(left.last(), right.last());
        let uses = edge_uses(&mesh);
        assert!(uses.values().all(|&n| n <= 2), "max-area {max_area}");
        // Every edge used by one triangle is a segment of a mesh edge (the
        // plate's sides, the split bottom side, the crack's sides) and vice
        // versa: no hanging nodes, nothing left open.
        let open: HashSet<(u32, u32)> = uses
            .iter()
            .filter(|&(_, &n)| n == 1)
            .map(|(&k, _)| k)
            .collect();
        let on_edges: HashSet<(u32, u32)> = mesh
            .edges
            .iter()
            .flat_map(|e| e.nodes.windows(2).map(|w| key(w[0], w[1])))
            .collect();
        assert_eq!(open, on_edges, "max-area {max_area}");
        let open_length: f64 = open.iter().map(|&(a, b)| length(&mesh, &[a, b])).sum();
        assert!((open_length - (6.0 + 2.0 * crack_length)).abs() < 1e-9);
        // The bottom side is cut at the mouth into two mesh edges, each
        // ending there on a different node, together 2 long.
        let bottom: Vec<&geomc::mesh::MeshEdge> = mesh
            .edges
            .iter()
            .filter(|e| e.nodes.iter().all(|&n| mesh.nodes[n as usize][1] == 0.0))
            .collect();
        assert_eq!(bottom.len(), 2, "max-area {max_area}");
        let bottom_length: f64 = bottom.iter().map(|e| length(&mesh, &e.nodes)).sum();
        assert!((bottom_length - 2.0).abs() < 1e-12);
        let area: f64 = mesh
            .faces
            .iter()
            .flat_map(|f| &f.triangles)
            .map(|t| {
                let [p, q, r] = t.map(|n| mesh.nodes[n as usize]);
                0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))
            })
            .inspect(|&a| assert!(a > 0.0))
            .sum();
        assert!((area - 2.0).abs() < 1e-12);
        let angle = min_angle_degrees(&mesh);
        assert!(
            angle >= 28.0 - 1e-9,
            "max-area {max_area}: min angle {angle}"
        );
    }
}

#[test]
fn interface_line_from_the_boundary_shares_its_nodes() {
    // Not a crack: the line ends on the right side, its tip is a node of
    // that side, and nothing is duplicated.
    let interface = line("sensor", false, &[(0.5, 0.5), (2.0, 0.5)]);
    let mesh = mesh(&interface, 0.002).expect("meshes");
    let chain = &mesh.polylines[0].nodes;
    assert_eq!(
        mesh.nodes[*chain.last().expect("nodes") as usize],
        [2.0, 0.5, 0.0]
    );
    assert!(
        mesh.edges
            .iter()
            .any(|e| e.nodes.contains(chain.last().expect("nodes")))
    );
    let uses = edge_uses(&mesh);
    for w in chain.windows(2) {
        assert_eq!(uses.get(&key(w[0], w[1])), Some(&2));
    }
    assert!((length(&mesh, chain) - 1.5).abs() < 1e-12);
}

#[test]
fn crossing_poly_lines_are_refused_naming_both() {
    let lines = line("one", true, &[(0.5, 0.5), (1.5, 0.5)])
        + &line("two", false, &[(1.0, 0.2), (1.0, 0.8)]);
    match mesh(&lines, 0.002) {
        Err(MeshError::Face { face, reason }) => {
            assert_eq!(face, "sheet");
            assert!(
                reason.contains("`one`") && reason.contains("`two`") && reason.contains("cross"),
                "{reason}"
            );
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
}

#[test]
fn touching_the_boundary_away_from_a_tip_is_still_refused() {
    // The middle point (1, 0) lies on the bottom side.
    let lines = line("dip", false, &[(0.5, 0.5), (1.0, 0.0), (1.5, 0.5)]);
    match mesh(&lines, 0.002) {
        Err(MeshError::Face { reason, .. }) => {
            assert!(
                reason.contains("touches or crosses") && reason.contains("`dip`"),
                "{reason}"
            );
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
}

/// A solver sees the open mouth: Laplace's equation on the 2 × 1 plate with
/// u = 1 on x = 0 and u = 0 on x = 2 and an insulated edge crack from
/// (1, 0) up to (1, 0.5), solved by scikit-fem on geomc's MSH
/// (tests/tools/fem_crack.py, installed by ./scripts/test.sh). Without the
/// crack u = 1 − x/2, so 1/2 on both sides of x = 1; the crack holds the
/// flow back, so the hot side is above 1/2 and the cold side below, and the
/// jump is the same on a finer mesh.
#[test]
fn scikit_fem_sees_the_edge_crack_open_to_the_boundary() {
    let xml = format!(
        r#"<geometry version="1" dimension="2">
      <polygon name="plate"><vertex x="0" y="0"/><vertex x="2" y="0"/><vertex x="2" y="1"/><vertex x="0" y="1"/></polygon>
      {}
      <subdomain name="sheet"><solid ref="plate"/></subdomain>
      <boundary name="hot" edges="plate.e4"/>
      <boundary name="cold" edges="plate.e2"/>
    </geometry>"#,
        line("cr", true, &[(1.0, 0.0), (1.0, 0.5)])
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let input = dir.path().join("edge_crack.xml");
    std::fs::write(&input, xml).expect("write input");
    let solve = |max_area: &str| {
        let msh = dir.path().join(format!("edge_crack_{max_area}.msh"));
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_geomc"))
            .args(["compile", "-q"])
            .arg(&input)
            .args(["--max-area", max_area, "-o"])
            .arg(&msh)
            .status()
            .expect("run geomc");
        assert!(status.success());
        let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/tools/fem_crack.py");
        let out = std::process::Command::new("python3")
            .arg(script)
            .arg(&msh)
            .args(["cr.left", "cr.right", "hot=1", "cold=0"])
            .output()
            .expect("run python3");
        assert!(
            out.status.success(),
            "fem_crack.py failed (./scripts/test.sh installs scikit-fem and meshio): {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let stdout = String::from_utf8_lossy(&out.stdout).to_string();
        let v: serde_json::Value =
            serde_json::from_str(stdout.lines().last().unwrap_or("")).expect("json");
        let num = |k: &str| v[k].as_f64().unwrap_or_else(|| panic!("no {k} in {v}"));
        (
            num("mid_left"),
            num("mid_right"),
            v["pairs"].as_u64().unwrap_or(0),
            num("u_min"),
            num("u_max"),
        )
    };
    let (left, right, pairs, lo, hi) = solve("0.002");
    // Walking up from the mouth, the left side is x < 1 (hot).
    assert!(
        left > 0.55 && right < 0.45,
        "crack middle: {left} | {right}"
    );
    assert!(
        (left + right - 1.0).abs() < 0.02,
        "symmetric about x = 1: {left} + {right}"
    );
    // The mouth is duplicated with the inner nodes.
    assert!(pairs >= 6, "{pairs} duplicated node pairs");
    assert!(lo >= -1e-12 && hi <= 1.0 + 1e-12, "u in [{lo}, {hi}]");
    let (fine_left, fine_right, ..) = solve("0.0005");
    let (jump, fine_jump) = (left - right, fine_left - fine_right);
    assert!(
        (jump - fine_jump).abs() < 0.02,
        "jump {jump} then {fine_jump}"
    );
}

/// Second order with an edge crack on a curved rim: the rim is cut at the
/// mouth into `EDGE` and `EDGE.beyond.NAME`, and the mid nodes of both
/// parts lie on the curve (circle x² + y² = 1, ellipse x²/4 + y² = 1), not
/// on the chords.
#[test]
fn second_order_mid_nodes_of_a_cut_curved_rim_lie_on_the_curve() {
    let shapes = [
        (
            r#"<circle name="disk"><center x="0" y="0"/><radius value="1"/></circle>"#,
            1.0,
        ),
        (
            r#"<ellipse name="disk"><center x="0" y="0"/><radius_vertex x="2" y="0"/><radius_vertex x="0" y="1"/></ellipse>"#,
            2.0,
        ),
    ];
    for (shape, a) in shapes {
        // From the bottom of the rim (0, −1) up to (0.1, −0.4).
        let crack = line("cr", true, &[(0.0, -1.0), (0.0, -0.7), (0.1, -0.4)]);
        let xml = format!(
            r#"<geometry version="1" dimension="2">{shape}{crack}
              <subdomain name="body"><solid ref="disk"/></subdomain></geometry>"#
        );
        let checked = check_source(SourceFile::new("t.xml", &xml), &Options::default());
        assert!(checked.is_valid(), "{:#?}", checked.diagnostics.items);
        let model = checked.lowered.expect("a model").model;
        let options = MeshOptions {
            max_area: Some(0.01),
            min_angle_degrees: 28.0,
            order: 2,
            ..MeshOptions::default()
        };
        let mesh = mesh_model(&model, &options).expect("meshes");
        let q = mesh.quadratic.as_ref().expect("second order");
        let on_curve = |p: [f64; 3]| ((p[0] / a).powi(2) + p[1] * p[1]).sqrt() - 1.0;
        let beyond = mesh
            .edges
            .iter()
            .position(|e| e.name.ends_with(".beyond.cr"))
            .unwrap_or_else(|| panic!("a = {a}: no beyond part"));
        let rim = mesh
            .edges
            .iter()
            .position(|e| mesh.edges[beyond].name == format!("{}.beyond.cr", e.name))
            .expect("the kept part of the rim");
        for e in [rim, beyond] {
            let nodes = &mesh.edges[e].nodes;
            assert!(nodes.len() > 5, "a = {a}: {} nodes", nodes.len());
            assert_eq!(q.edges[e].len(), nodes.len() - 1);
            for (k, &m) in q.edges[e].iter().enumerate() {
                let d = on_curve(mesh.nodes[m as usize]);
                assert!(d.abs() < 1e-12, "a = {a}, edge {e}, mid {k}: off by {d}");
                // The chord's middle lies inside the curve.
                let (p, r) = (
                    mesh.nodes[nodes[k] as usize],
                    mesh.nodes[nodes[k + 1] as usize],
                );
                let chord = on_curve([(p[0] + r[0]) / 2.0, (p[1] + r[1]) / 2.0, 0.0]);
                assert!(chord < -1e-7, "a = {a}, edge {e}, chord {k}: {chord}");
            }
        }
        // The mouth splits the rim: the two parts share no inner node.
        let first: HashSet<u32> = mesh.edges[rim].nodes.iter().copied().collect();
        let shared = mesh.edges[beyond]
            .nodes
            .iter()
            .filter(|n| first.contains(n))
            .count();
        assert!(shared <= 1, "a = {a}: {shared} shared nodes");
    }
}
