//! Trimmed faces meshed against the topology IR (issue 9): mesh edge k is
//! IR edge k (trim pieces and patch sides discretised once, a shared rim
//! written once), IR vertices are mesh nodes, the face's free mesh boundary
//! is exactly its IR edges; pieces along another face's edge without
//! sharing it are refused (E743, E744); a closed shell with trimmed faces
//! has the IR's outward flags and encloses its exact volume.

use geomc::diag::Code;
use geomc::driver::{Options, check_file, check_source};
use geomc::ir::{Model, SubdomainCells};
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, mesh_model, sanity_check};
use geomc::span::SourceFile;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

fn model_of(fixture: &str) -> Model {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(fixture);
    let checked = check_file(&path, &Options::default()).expect("readable");
    assert!(checked.is_valid(), "{:?}", checked.diagnostics);
    checked.lowered.expect("a model").model
}

/// Undirected segments of a node chain.
fn segments(nodes: &[u32]) -> Vec<(u32, u32)> {
    nodes
        .windows(2)
        .map(|w| (w[0].min(w[1]), w[0].max(w[1])))
        .collect()
}

/// Mesh edges and vertices are the IR's, in order, and no segment is in two
/// mesh edges (no duplicate line elements).
fn assert_edges_are_the_irs(model: &Model, mesh: &Mesh) {
    let ir: Vec<String> = model.edges.iter().map(|e| e.name.to_string()).collect();
    let got: Vec<&str> = mesh.edges.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(got, ir);
    let ir: Vec<String> = model.vertices.iter().map(|v| v.name.to_string()).collect();
    let got: Vec<&str> = mesh.vertices.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(got, ir);
    let mut seen: BTreeMap<(u32, u32), &str> = BTreeMap::new();
    for e in &mesh.edges {
        for s in segments(&e.nodes) {
            if let Some(other) = seen.insert(s, &e.name) {
                panic!("segment {s:?} in both {other} and {}", e.name);
            }
        }
    }
    // Each edge runs from its begin vertex's node to its end vertex's node.
    for (e, me) in model.edges.iter().zip(&mesh.edges) {
        let first = *me.nodes.first().expect("nodes");
        let last = *me.nodes.last().expect("nodes");
        assert_eq!(first, mesh.vertices[e.begin.index()].node, "{}", e.name);
        assert_eq!(last, mesh.vertices[e.end.index()].node, "{}", e.name);
    }
}

/// The segments used by one triangle of the face.
fn free_boundary(mesh: &Mesh, face: usize) -> BTreeSet<(u32, u32)> {
    let mut uses: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for t in &mesh.faces[face].triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    assert!(uses.values().all(|&n| n <= 2), "a segment in 3 triangles");
    uses.into_iter()
        .filter(|&(_, n)| n == 1)
        .map(|(s, _)| s)
        .collect()
}

#[test]
fn the_bezier_hole_mesh_has_the_irs_four_sides_and_trim_as_its_boundary() {
    let model = model_of("fixtures/valid/trimmed_bezier_hole.xml");
    let mesh = mesh_model(&model, &MeshOptions::default()).expect("meshes");
    sanity_check(&mesh).expect("sane");
    assert_edges_are_the_irs(&model, &mesh);
    assert_eq!(mesh.edges.len(), 5);
    // Corner vertices are mesh nodes at their places.
    for (v, mv) in model.vertices.iter().zip(&mesh.vertices) {
        let p = mesh.nodes[mv.node as usize];
        let d = (v.position - nalgebra::Point3::new(p[0], p[1], p[2])).norm();
        let closed_trim = model.edges.iter().any(|e| {
            e.name.to_string().contains(".trim[")
                && e.begin == e.end
                && e.begin.index() == v_index(&model, &v.name.to_string())
        });
        if !closed_trim {
            assert!(d < 1e-9, "{}: node {d} from the vertex", v.name);
        }
    }
    // The face's free boundary (a 2-manifold with boundary) is exactly its
    // edges' segments: the trim curve and the four patch sides.
    let face = &mesh.faces[0];
    let edges: BTreeSet<(u32, u32)> = face
        .boundary
        .iter()
        .flat_map(|&(e, _)| segments(&mesh.edges[e as usize].nodes))
        .collect();
    assert_eq!(free_boundary(&mesh, 0), edges);
    let names: BTreeSet<&str> = face
        .boundary
        .iter()
        .map(|&(e, _)| mesh.edges[e as usize].name.as_str())
        .collect();
    assert_eq!(
        names,
        BTreeSet::from([
            "panel.trim[1]",
            "panel.u_min[1]",
            "panel.u_max[1]",
            "panel.v_min[1]",
            "panel.v_max[1]"
        ])
    );
}

fn v_index(model: &Model, name: &str) -> usize {
    model
        .vertices
        .iter()
        .position(|v| v.name == name)
        .expect("vertex")
}

#[test]
fn a_hole_rim_on_a_model_edge_is_one_mesh_edge_used_by_both_faces() {
    let model = model_of("fixtures/valid/trimmed_plate_on_post.xml");
    let mesh = mesh_model(&model, &MeshOptions::default()).expect("meshes");
    sanity_check(&mesh).expect("sane");
    assert_edges_are_the_irs(&model, &mesh);
    let rim = mesh
        .edges
        .iter()
        .position(|e| e.name == "post.top_rim")
        .expect("rim") as u32;
    assert!(!mesh.edges.iter().any(|e| e.name.starts_with("plate.trim")));
    let plate = mesh
        .faces
        .iter()
        .position(|f| f.name == "plate")
        .expect("plate");
    assert!(mesh.faces[plate].boundary.iter().any(|&(e, _)| e == rim));
    // The plate's free boundary is its four sides and the rim, node for node.
    let edges: BTreeSet<(u32, u32)> = mesh.faces[plate]
        .boundary
        .iter()
        .flat_map(|&(e, _)| segments(&mesh.edges[e as usize].nodes))
        .collect();
    assert_eq!(free_boundary(&mesh, plate), edges);
}

#[test]
fn the_interstage_cut_outs_are_mesh_edges_of_the_ir() {
    let model = model_of("fixtures/valid/trimmed_interstage.xml");
    let mesh = mesh_model(&model, &MeshOptions::default()).expect("meshes");
    assert_edges_are_the_irs(&model, &mesh);
    for (f, face) in mesh.faces.iter().enumerate() {
        let edges: BTreeSet<(u32, u32)> = face
            .boundary
            .iter()
            .flat_map(|&(e, _)| segments(&mesh.edges[e as usize].nodes))
            .collect();
        assert_eq!(free_boundary(&mesh, f), edges, "{}", face.name);
    }
}

fn diagnostics_of(text: &str) -> Vec<(Code, String, String)> {
    let checked = check_source(SourceFile::new("t.xml", text), &Options::default());
    checked
        .diagnostics
        .items
        .iter()
        .filter(|d| d.is_error())
        .map(|d| {
            let at = d
                .span
                .map(|s| {
                    let before = &text[..s.range().start];
                    let line = before.matches('\n').count() + 1;
                    let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                    format!("{line}:{column}")
                })
                .unwrap_or_default();
            (d.code, d.message.clone(), at)
        })
        .collect()
}

const POST: &str = r#"<geometry version="1">
  <truncated_cone name="post">
    <bottom_center x="0" y="-1" z="0"/> <top_center x="0" y="0" z="0"/>
    <bottom_radius value="0.4"/> <top_radius value="0.4"/>
  </truncated_cone>
"#;

#[test]
fn a_trim_curve_along_part_of_a_model_edge_is_refused_with_e743() {
    let text = format!(
        "{POST}  <bezier_surface name=\"plate\">
    <row> <node x=\"-1\" y=\"0\" z=\"-1\"/> <node x=\"-1\" y=\"0\" z=\"1\"/> </row>
    <row> <node x=\"1\" y=\"0\" z=\"-1\"/> <node x=\"1\" y=\"0\" z=\"1\"/> </row>
    <trim equation=\"min(0.16 - x^2 - z^2, 0.1 - x)\" material=\"negative\"/>
  </bezier_surface>
  <subdomain name=\"support\"> <solid ref=\"post\"/> </subdomain>
</geometry>"
    );
    let d = diagnostics_of(&text);
    assert_eq!(d.len(), 1, "{d:?}");
    let (code, message, at) = &d[0];
    assert_eq!(*code, Code::TrimmedPartlyShared);
    assert_eq!(code.as_str(), "E743");
    assert_eq!(at, "6:4");
    assert!(
        message.starts_with(
            "the trim curve `plate.trim[1]` of surface `plate` runs along edge `post.top_rim` of faces `post.top` and `post.side` for "
        ),
        "{message}"
    );
    assert!(message.contains("make the trim loop coincide with the whole edge"));
}

#[test]
fn a_patch_side_on_a_model_edge_is_refused_with_e744() {
    let text = format!(
        "{POST}  <cone_surface name=\"sleeve\" bottom_radius=\"0.4\" top_radius=\"0.4\" length=\"1\"/>
  <subdomain name=\"support\"> <solid ref=\"post\"/> </subdomain>
</geometry>"
    );
    let d = diagnostics_of(&text);
    assert_eq!(d.len(), 1, "{d:?}");
    let (code, message, at) = &d[0];
    assert_eq!(code.as_str(), "E744");
    assert_eq!(at, "6:4");
    assert_eq!(
        message,
        "the patch side `sleeve.u_min[1]` of surface `sleeve` lies along edge `post.top_rim` of faces `post.top` and `post.side` (100% of the side); patch sides keep their own nodes, so the faces would not meet: extend the parameter rectangle past the edge and trim it back with a <trim> whose loop is the whole edge"
    );
}

/// The IR flags of a subdomain's faces by name.
fn ir_flags(model: &Model, subdomain: &str) -> BTreeMap<String, bool> {
    let sub = model
        .subdomains
        .iter()
        .find(|s| s.name == subdomain)
        .expect("subdomain");
    let SubdomainCells::Volume { boundary } = &sub.cells else {
        panic!("a volume")
    };
    boundary
        .iter()
        .map(|of| (model.faces[of.face.index()].name.to_string(), of.outward))
        .collect()
}

#[test]
fn trimmed_faces_have_real_outward_flags_and_the_shell_its_exact_volume() {
    let model = model_of("fixtures/valid/trimmed_stacked_cans.xml");
    let mesh = mesh_model(&model, &MeshOptions::default()).expect("meshes");
    // R_u × R_v: the tubes' point out of their axis, the plates' down (-y).
    let lower = ir_flags(&model, "lower");
    let upper = ir_flags(&model, "upper");
    assert_eq!(
        lower,
        BTreeMap::from([
            ("base".to_string(), true),
            ("lower_tube".to_string(), true),
            ("ring".to_string(), false),
            ("middle".to_string(), false),
        ])
    );
    assert_eq!(
        upper,
        BTreeMap::from([
            ("middle".to_string(), true),
            ("upper_tube".to_string(), true),
            ("roof".to_string(), false),
        ])
    );
    for (name, exact) in [
        ("lower", std::f64::consts::PI),
        ("upper", std::f64::consts::PI * 0.36),
    ] {
        let s = mesh
            .subdomains
            .iter()
            .find(|s| s.name == name)
            .expect("subdomain");
        // The mesh's flags are the IR's, and its triangles the IR faces'.
        let flags: BTreeMap<String, bool> = s
            .faces
            .iter()
            .map(|&(f, o)| (mesh.faces[f as usize].name.clone(), o))
            .collect();
        assert_eq!(flags, ir_flags(&model, name));
        let p = |i: u32| nalgebra::Vector3::from(mesh.nodes[i as usize]);
        let volume: f64 = s
            .faces
            .iter()
            .flat_map(|&(f, o)| {
                mesh.faces[f as usize]
                    .triangles
                    .iter()
                    .map(move |t| if o { *t } else { [t[0], t[2], t[1]] })
            })
            .map(|t| p(t[0]).dot(&p(t[1]).cross(&p(t[2]))) / 6.0)
            .sum();
        assert!(volume > 0.0, "{name}: {volume}");
        assert!(
            (volume - exact).abs() < 0.01 * exact,
            "{name}: {volume} vs {exact}"
        );
    }
}
