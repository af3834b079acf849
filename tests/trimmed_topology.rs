//! Trimmed surfaces in the topology IR (issue 9): each surface is a face,
//! its trim curves and patch sides are edges between vertices at their ends,
//! a closed trim loop on a model edge uses that edge, and the fragments and
//! the validator see the trimmed faces like any other.

use geomc::driver::{Options, check_file};
use geomc::geom::Curve;
use geomc::ir::{IncidenceMatrices, Model, derive_fragments};
use std::path::Path;

fn model_of(fixture: &str) -> (Model, usize) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(fixture);
    let checked = check_file(&path, &Options::default()).expect("readable");
    let errors = checked.diagnostics.items.len();
    (checked.lowered.expect("a model").model, errors)
}

fn names<T, N: ToString + ?Sized>(items: &[T], name: impl Fn(&T) -> &N) -> Vec<String> {
    items.iter().map(|i| name(i).to_string()).collect()
}

fn edge(model: &Model, name: &str) -> usize {
    model
        .edges
        .iter()
        .position(|e| e.name == name)
        .unwrap_or_else(|| panic!("edge {name}"))
}

#[test]
fn a_bezier_patch_with_a_round_hole_has_four_sides_and_one_trim_loop() {
    let (model, diagnostics) = model_of("fixtures/valid/trimmed_bezier_hole.xml");
    assert_eq!(diagnostics, 0);
    assert_eq!(
        (model.vertices.len(), model.edges.len(), model.faces.len()),
        (5, 5, 1)
    );
    assert_eq!(
        names(&model.edges, |e| &e.name),
        [
            "panel.trim[1]",
            "panel.v_min[1]",
            "panel.u_max[1]",
            "panel.v_max[1]",
            "panel.u_min[1]"
        ]
    );
    let trim = &model.edges[edge(&model, "panel.trim[1]")];
    assert_eq!(trim.begin, trim.end, "the hole is a closed edge");
    // Every point of the trim chain on the hole's rim: the circle of
    // radius 0.4 about the patch's axis (paper 002's example).
    let Curve::Chain { points } = &*trim.curve(&model.solids) else {
        panic!("a chain")
    };
    for p in points {
        assert!((p.y.hypot(p.z) - 0.4).abs() < 1e-5, "{p:?}");
    }
    // Two loops: the hole, and the four sides counter-clockwise in (u, v).
    assert_eq!(model.faces[0].loops.len(), 2);
    assert_eq!(model.faces[0].loops[1].len(), 4);
    let m = IncidenceMatrices::of(&model);
    assert_eq!(m.ef.entries.len(), 5);
    assert!(m.ef.entries.iter().all(|&(_, f, v)| f == 0 && v == 1));
    // A closed edge has one entry (2), an open one two (−1 and +1).
    assert_eq!(m.ve.entries.len(), 1 + 4 * 2);
    assert_eq!(m.ve.get(0, 0), 2);
    assert_eq!(m.vf.entries.len(), 5);
}

#[test]
fn a_hole_rim_on_a_model_edge_uses_that_edge() {
    let (model, diagnostics) = model_of("fixtures/valid/trimmed_plate_on_post.xml");
    assert_eq!(diagnostics, 0);
    assert_eq!(
        (model.vertices.len(), model.edges.len(), model.faces.len()),
        (6, 6, 4)
    );
    assert!(
        !model
            .edges
            .iter()
            .any(|e| e.name.to_string().starts_with("plate.trim"))
    );
    let rim = edge(&model, "post.top_rim") as u32;
    let m = IncidenceMatrices::of(&model);
    let faces: Vec<u32> =
        m.ef.entries
            .iter()
            .filter(|e| e.0 == rim)
            .map(|e| e.1)
            .collect();
    let face_names: Vec<String> = faces
        .iter()
        .map(|&f| model.faces[f as usize].name.to_string())
        .collect();
    assert_eq!(face_names, ["post.top", "post.side", "plate"]);
}

#[test]
fn the_interstage_holes_are_closed_trim_edges_even_across_the_seam() {
    let (model, diagnostics) = model_of("fixtures/valid/trimmed_interstage.xml");
    assert_eq!(diagnostics, 0);
    // Two end circles and six cut-outs (one across the cone's seam, joined
    // again); the seam itself is no edge.
    assert_eq!(
        (model.vertices.len(), model.edges.len(), model.faces.len()),
        (8, 8, 1)
    );
    let trims = model
        .edges
        .iter()
        .filter(|e| e.name.to_string().contains(".trim["))
        .count();
    assert_eq!(trims, 6);
    assert!(model.edges.iter().all(|e| e.begin == e.end));
    assert!(
        !model
            .edges
            .iter()
            .any(|e| e.name.to_string().contains(".v_"))
    );
    // The end circles: r 2 at y = 0 and r 1.5 at y = 3.
    for (name, radius, y) in [
        ("interstage.u_min[1]", 2.0, 0.0),
        ("interstage.u_max[1]", 1.5, 3.0),
    ] {
        let Curve::Chain { points } = &*model.edges[edge(&model, name)].curve(&model.solids) else {
            panic!("a chain")
        };
        for p in points {
            assert!((p.x.hypot(p.z) - radius).abs() < 1e-9 && (p.y - y).abs() < 1e-9);
        }
    }
}

#[test]
fn trimmed_faces_between_subdomains_are_ir_fragments_and_msh_groups() {
    let (model, diagnostics) = model_of("fixtures/valid/trimmed_stacked_cans.xml");
    assert_eq!(diagnostics, 0);
    assert_eq!(model.faces.len(), 6);
    let fragments: Vec<(String, Vec<String>)> = derive_fragments(&model)
        .iter()
        .map(|f| {
            let faces = f
                .faces
                .iter()
                .map(|id| model.faces[id.index()].name.to_string())
                .collect();
            (f.name.clone(), faces)
        })
        .collect();
    let expect = |n: &str, f: &[&str]| (n.to_string(), f.iter().map(|s| s.to_string()).collect());
    assert_eq!(
        fragments,
        [
            expect("lower|exterior", &["base", "lower_tube", "ring"]),
            expect("lower|upper", &["middle"]),
            expect("upper|exterior", &["upper_tube", "roof"]),
        ]
    );
    let m = IncidenceMatrices::of(&model);
    // Seven (face, subdomain) pairs: four faces of `lower`, three of `upper`.
    assert_eq!(m.fd.entries.len(), 7);
    let dir = tempfile::tempdir().expect("temporary folder");
    let out = dir.path().join("cans.msh");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(["compile", "fixtures/valid/trimmed_stacked_cans.xml", "-o"])
        .arg(&out)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("geomc runs");
    assert_eq!(status.status.code(), Some(0), "{status:?}");
    let text = std::fs::read_to_string(&out).expect("an MSH file");
    let names = text
        .split("$PhysicalNames")
        .nth(1)
        .and_then(|s| s.split("$EndPhysicalNames").next())
        .expect("physical names");
    for name in [
        "\"lower|exterior\"",
        "\"lower|upper\"",
        "\"upper|exterior\"",
    ] {
        assert!(names.contains(name), "{name} in {names}");
    }
}
