//! Issue 6: a crack poly_line survives fine area limits. At `--max-area`
//! 0.0006 and below, the vertical crack x = 1, y ∈ [0.2, 0.8] through the
//! 2 × 1 plate (in line with boundary nodes) used to lose its inner points:
//! the last meshing round kept every constraint edge whole, the poly_line's
//! included, so the crack was neither split nor opened and slivers lay
//! along it. Each case checks the line elements, both sides and their
//! lengths, conformity and the minimum angle.

use geomc::driver::{Options, check_source};
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, mesh_model};
use geomc::span::SourceFile;
mod mesh2d_common;
use mesh2d_common::{edge_uses, length, min_angle_degrees};

fn cracked_plate(max_area: f64) -> Mesh {
    let xml = r#"<geometry version="1" dimension="2">
      <polygon name="plate"><vertex x="0" y="0"/><vertex x="2" y="0"/><vertex x="2" y="1"/><vertex x="0" y="1"/></polygon>
      <poly_line name="cr" crack="true">
        <line><begin_point x="1" y="0.2"/><end_point x="1" y="0.8"/></line>
      </poly_line>
      <subdomain name="sheet"><solid ref="plate"/></subdomain>
    </geometry>"#;
    let checked = check_source(SourceFile::new("t.xml", xml), &Options::default());
    assert!(checked.is_valid(), "{:#?}", checked.diagnostics.items);
    let model = checked.lowered.expect("a model").model;
    let options = MeshOptions {
        max_area: Some(max_area),
        min_angle_degrees: 28.0,
        ..MeshOptions::default()
    };
    mesh_model(&model, &options).expect("meshes")
}

#[test]
fn vertical_crack_is_split_and_opened_at_every_area_limit() {
    for max_area in [0.002, 0.001, 0.0007, 0.0006, 0.0005, 0.0003] {
        let mesh = cracked_plate(max_area);
        let chain = &mesh.polylines[0].nodes;
        // Refinement splits a 0.6-long line: its segments are at most about
        // the side of an equilateral triangle of the area limit.
        let side = (4.0 * max_area / 3f64.sqrt()).sqrt();
        let segments = chain.len() - 1;
        assert!(
            segments >= (0.6 / side).floor() as usize,
            "max-area {max_area}: only {segments} crack segments"
        );
        for &n in chain {
            let p = mesh.nodes[n as usize];
            assert_eq!(p[0], 1.0, "max-area {max_area}: crack node off the line");
        }
        assert!((length(&mesh, chain) - 0.6).abs() < 1e-12);
        let side_nodes = |name: &str| {
            let fragment = mesh
                .fragments
                .iter()
                .find(|f| f.name == name)
                .unwrap_or_else(|| panic!("max-area {max_area}: no fragment {name}"));
            mesh.edges[fragment.edges[0] as usize].nodes.clone()
        };
        let (left, right) = (side_nodes("cr.left"), side_nodes("cr.right"));
        assert_eq!(left.len(), chain.len());
        assert_eq!(right.len(), chain.len());
        assert!((length(&mesh, &left) - 0.6).abs() < 1e-12);
        assert!((length(&mesh, &right) - 0.6).abs() < 1e-12);
        // Every crack segment on either side is a mesh edge of exactly one
        // triangle (the slit is open); every other interior edge has two.
        let uses = edge_uses(&mesh);
        for nodes in [&left, &right] {
            for w in nodes.windows(2) {
                assert_eq!(uses.get(&(w[0].min(w[1]), w[0].max(w[1]))), Some(&1));
            }
        }
        let boundary: f64 = uses
            .iter()
            .filter(|&(_, &n)| n == 1)
            .map(|(&(a, b), _)| length(&mesh, &[a, b]))
            .sum();
        assert!(
            (boundary - (6.0 + 1.2)).abs() < 1e-9,
            "max-area {max_area}: boundary length {boundary}"
        );
        assert!(uses.values().all(|&n| n <= 2));
        let angle = min_angle_degrees(&mesh);
        assert!(
            angle >= 28.0 - 1e-9,
            "max-area {max_area}: min angle {angle}"
        );
    }
}
