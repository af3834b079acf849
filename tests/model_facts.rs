//! Computed facts of small models: counts, fragments, orientations, resolved
//! coordinates and the diagnostics of paper 000's own example.

use geomc::diag::{Code, Severity};
use geomc::driver::{Checked, Options, check_source};
use geomc::ir::{IncidenceMatrices, Side, SubdomainCells, derive_fragments};
use geomc::resolve::parse_override;
use geomc::span::SourceFile;

fn check(xml: &str) -> Checked {
    check_with(xml, &[])
}

fn check_with(xml: &str, sets: &[&str]) -> Checked {
    let options = Options {
        overrides: sets
            .iter()
            .map(|s| parse_override(s).expect("valid --set"))
            .collect(),
        ..Options::default()
    };
    check_source(SourceFile::new("test.xml", xml), &options)
}

fn codes(checked: &Checked, severity: Severity) -> Vec<&'static str> {
    checked
        .diagnostics
        .items
        .iter()
        .filter(|d| d.severity == severity)
        .map(|d| d.code.as_str())
        .collect()
}

fn valid(xml: &str) -> geomc::lower::Lowered {
    let checked = check(xml);
    assert!(
        checked.is_valid(),
        "unexpected errors: {:#?}",
        checked.diagnostics.items
    );
    checked.lowered.expect("a model")
}

const BALL_IN_BOX: &str = r#"<geometry version="1">
  <parallelepiped name="box"><first_point x="0" y="0" z="0"/><second_point x="4" y="4" z="4"/></parallelepiped>
  <sphere name="ball"><center x="2" y="2" z="2"/><radius value="1"/></sphere>
  <subdomain name="outer"><difference><solid ref="box"/><solid ref="ball"/></difference></subdomain>
  <subdomain name="inner"><solid ref="ball"/></subdomain>
  <boundary name="wall" faces="box"/>
</geometry>"#;

#[test]
fn ball_in_a_box_gives_an_outer_and_an_interface_fragment() {
    let lowered = valid(BALL_IN_BOX);
    let model = &lowered.model;
    assert_eq!(
        (model.vertices.len(), model.edges.len(), model.faces.len()),
        (9, 13, 8)
    );
    let fragments = derive_fragments(model);
    let summary: Vec<(String, String, Vec<String>)> = fragments
        .iter()
        .map(|f| {
            let other = match f.other {
                Side::Exterior => "exterior".to_string(),
                Side::Subdomain(id) => model.subdomain(id).name.clone(),
            };
            let mut faces: Vec<String> = f
                .faces
                .iter()
                .map(|id| model.face(*id).name.to_string())
                .collect();
            faces.sort();
            (model.subdomain(f.subdomain).name.clone(), other, faces)
        })
        .collect();
    assert!(
        summary.contains(&(
            "outer".into(),
            "exterior".into(),
            [
                "box.xmax", "box.xmin", "box.ymax", "box.ymin", "box.zmax", "box.zmin"
            ]
            .map(String::from)
            .to_vec()
        ))
    );
    assert!(summary.contains(&(
        "outer".into(),
        "inner".into(),
        vec!["ball.north".into(), "ball.south".into()]
    )));
    assert_eq!(fragments.len(), 2);
    let wall = fragments
        .iter()
        .find(|f| f.other == Side::Exterior)
        .expect("outer fragment");
    assert_eq!(wall.name, "wall");
    // The sphere's faces point into the outer subdomain's cavity: inward for it.
    let SubdomainCells::Volume { boundary } = &model.subdomains[0].cells else {
        panic!("3D")
    };
    let inward: Vec<String> = boundary
        .iter()
        .filter(|f| !f.outward)
        .map(|f| model.face(f.face).name.to_string())
        .collect();
    assert_eq!(
        inward,
        vec!["ball.north".to_string(), "ball.south".to_string()]
    );
    let SubdomainCells::Volume { boundary } = &model.subdomains[1].cells else {
        panic!("3D")
    };
    assert!(boundary.iter().all(|f| f.outward));
}

#[test]
fn two_boxes_sharing_a_face_share_one_face_entity() {
    let lowered = valid(
        r#"<geometry version="1">
  <parallelepiped name="a"><first_point x="0" y="0" z="0"/><second_point x="1" y="1" z="1"/></parallelepiped>
  <parallelepiped name="b"><first_point x="1" y="0" z="0"/><second_point x="2" y="1" z="1"/></parallelepiped>
  <subdomain name="left"><solid ref="a"/></subdomain>
  <subdomain name="right"><solid ref="b"/></subdomain>
</geometry>"#,
    );
    let model = &lowered.model;
    assert_eq!(
        (model.vertices.len(), model.edges.len(), model.faces.len()),
        (12, 20, 11)
    );
    let fragments = derive_fragments(model);
    let sizes: Vec<(String, usize)> = fragments
        .iter()
        .map(|f| (f.name.clone(), f.faces.len()))
        .collect();
    assert_eq!(
        sizes,
        vec![
            ("left|exterior".to_string(), 5),
            ("left|right".to_string(), 1),
            ("right|exterior".to_string(), 5)
        ]
    );
    let m = IncidenceMatrices::of(model);
    // The shared face is outward for one subdomain and inward for the other.
    let shared: Vec<i8> =
        m.fd.entries
            .iter()
            .filter(|e| model.faces[e.0 as usize].name == "a.xmax")
            .map(|e| e.2)
            .collect();
    assert_eq!(shared, vec![1, -1]);
}

#[test]
fn a_box_has_the_incidence_of_a_cube() {
    let lowered = valid(
        r#"<geometry version="1">
  <parallelepiped name="p"><base_point x="0" y="0" z="0"/><vertex x="1.5" y="0" z="0"/><vertex x="0" y="1" z="0"/><vertex x="0" y="0" z="2"/></parallelepiped>
  <subdomain name="d"><solid ref="p"/></subdomain>
</geometry>"#,
    );
    let model = &lowered.model;
    let m = IncidenceMatrices::of(model);
    assert_eq!(
        (m.ve.entries.len(), m.ef.entries.len(), m.fd.entries.len()),
        (24, 24, 6)
    );
    assert!(m.fd.entries.iter().all(|e| e.2 == 1));
    let chi = model.vertices.len() as i64 - model.edges.len() as i64 + model.faces.len() as i64;
    assert_eq!(chi, 2);
    // Every edge is used once in each direction by the faces.
    for edge in 0..12u32 {
        let signs: Vec<i8> =
            m.ef.entries
                .iter()
                .filter(|e| e.0 == edge)
                .map(|e| e.2)
                .collect();
        assert_eq!(
            signs.iter().map(|&s| s as i32).sum::<i32>(),
            0,
            "edge {edge}: {signs:?}"
        );
    }
}

#[test]
fn nested_coordinate_systems_compose() {
    let lowered = valid(
        r#"<geometry version="1">
  <coordinate_system name="cs1"><origin x="1" y="0" z="0"/><rotation z="90"/></coordinate_system>
  <coordinate_system name="cs2" cs="cs1"><origin x="1" y="0" z="0"/></coordinate_system>
  <point name="p" cs="cs2"><value x="1" y="0" z="0"/></point>
</geometry>"#,
    );
    let p = lowered.model.point_sets[0].points[0];
    assert!(
        (p - geomc::geom::Point3::new(1.0, 2.0, 0.0)).norm() < 1e-12,
        "{p}"
    );
}

#[test]
fn parameters_and_overrides_reach_the_geometry() {
    let xml = r#"<geometry version="1">
  <parameters><parameter name="r" value="0.5"/><parameter name="d" value="2*r"/></parameters>
  <sphere name="s"><center x="0" y="0" z="0"/><radius value="d"/></sphere>
  <subdomain name="ball"><solid ref="s"/></subdomain>
</geometry>"#;
    let lowered = valid(xml);
    assert_eq!(
        lowered.model.parameters,
        vec![("r".to_string(), 0.5), ("d".to_string(), 1.0)]
    );
    let checked = check_with(xml, &["r=2"]);
    let model = checked.lowered.expect("model");
    assert_eq!(
        model.model.parameters,
        vec![("r".to_string(), 2.0), ("d".to_string(), 4.0)]
    );
    let bbox = model.model.bbox();
    assert!((bbox.max.x - 4.0).abs() < 1e-12);
    let checked = check_with(xml, &["R=2"]);
    assert_eq!(codes(&checked, Severity::Error), vec!["E204"]);
}

#[test]
fn paper_000_example_validates_with_one_warning_per_quirk() {
    let xml = r#"<geometry version="1">
<basis_coordinate>
  <coordinate name='X'> <value x1='1' x2='10' x3='4' /> </coordinate>
  <coordinate name='Y'> <value y1='2' y2='4' /> </coordinate>
  <coordinate name='Z'> <value z1='5' z2='1' z3='7' z4='9' /> </coordinate>
</basis_coordinate>
<point name='point 3D'> <value x='x1' y='y1' z='z1' /> <value x='x3' y='y2' z='z4' /> </point>
<point name='point 2D'> <value x='x2' y='y1' /> </point>
<ellipse name='ellipse_A'> <center x='0' y='0' /> <radius_vertex x='-1' y='0' /> <radius_vertex x='1' y='0' /> </ellipse>
<poly_line name='pline_A'>
  <line> <begin_point x='0' y='0' z='1' /> <end_point x='1' y='1' z='2.3' /> </line>
  <line> <begin_point x='1' y='1' z='2.3' /> <end_point x='5' y='1' z='4' /> </line>
</poly_line>
<truncated_cone name='cone_A'> <bottom_radius value='4' /> <bottom_center x='1' y='3' z='6' /> <top_center x='1' y='3' z='0' /> </truncated_cone>
<parallelepiped name='paral_A'> <base_point x='0' y='0' z='0' /> <vertex x='1.5' y='0' z='0' /> <vertex x='0' y='1' z='0' /> <vertex x='0' y='0' z='2' /> </parallelepiped>
<parallelepiped name='paral_B'> <first_point x='0' y='0' z='0' /> <second_point x='2.2' y='1.6' z='3' /> </parallelepiped>
<sphere name='sphere_A'> <center x='0' y='0' z='0' /> <radius value='10' /> </sphere>
</geometry>"#;
    let checked = check(xml);
    assert_eq!(codes(&checked, Severity::Error), Vec::<&str>::new());
    let mut warnings = codes(&checked, Severity::Warning);
    warnings.sort();
    assert_eq!(
        warnings,
        vec!["W001", "W001", "W002", "W003", "W005", "W005", "W009"]
    );
    let messages: Vec<&str> = checked
        .diagnostics
        .items
        .iter()
        .map(|d| d.message.as_str())
        .collect();
    assert!(messages.contains(
        &"basis coordinate x3 = 4 is not greater than x2 = 10; the values are used as given"
    ));
    assert!(
        messages
            .iter()
            .any(|m| m.contains("taken as 4, equal to bottom_radius (a cylinder)"))
    );
    assert!(
        messages
            .iter()
            .any(|m| m.contains("taken as a circle of radius 1"))
    );
    let model = checked.lowered.expect("model").model;
    assert_eq!(model.point_sets.len(), 2);
    assert_eq!(model.polylines[0].points.len(), 3);
    assert_eq!(model.solids.len(), 5);
}

#[test]
fn every_problem_of_a_file_is_reported_in_one_run() {
    let checked = check(
        r#"<geometry version="1">
  <parameters><parameter name="radius" value="1"/></parameters>
  <sphere name="s"><center x="0" y="0" z="0"/><radius value="radiu"/></sphere>
  <sphere name="s"><center x="0" y="0" z="0"/><radius value="-1"/></sphere>
  <sphre name="t"/>
</geometry>"#,
    );
    let mut errors = codes(&checked, Severity::Error);
    errors.sort();
    assert_eq!(errors, vec!["E110", "E200", "E201", "E300"]);
    let undefined = checked
        .diagnostics
        .items
        .iter()
        .find(|d| d.code == Code::UndefinedName)
        .expect("E200");
    assert_eq!(undefined.help.as_deref(), Some("did you mean 'radius'?"));
    let unknown = checked
        .diagnostics
        .items
        .iter()
        .find(|d| d.code == Code::UnknownElement)
        .expect("E110");
    assert_eq!(unknown.help.as_deref(), Some("did you mean <sphere>?"));
}

#[test]
fn crossing_balls_are_reported_with_a_location() {
    let checked = check(
        r#"<geometry version="1">
  <sphere name="a"><center x="0" y="0" z="0"/><radius value="1"/></sphere>
  <sphere name="b"><center x="1" y="0" z="0"/><radius value="1"/></sphere>
  <subdomain name="d"><union><solid ref="a"/><solid ref="b"/></union></subdomain>
</geometry>"#,
    );
    assert_eq!(codes(&checked, Severity::Error), vec!["E408"]);
    let d = &checked.diagnostics.items[0];
    assert!(
        d.message
            .starts_with("the boundaries of 'a' and 'b' cross near ("),
        "{}",
        d.message
    );
}

#[test]
fn overlapping_subdomains_are_reported() {
    let checked = check(
        r#"<geometry version="1">
  <parallelepiped name="box"><first_point x="0" y="0" z="0"/><second_point x="4" y="4" z="4"/></parallelepiped>
  <sphere name="ball"><center x="2" y="2" z="2"/><radius value="1"/></sphere>
  <subdomain name="outer"><solid ref="box"/></subdomain>
  <subdomain name="inner"><solid ref="ball"/></subdomain>
</geometry>"#,
    );
    assert_eq!(codes(&checked, Severity::Error), vec!["E407"]);
}

/// One-solid subdomains listed in another order than their solids: the
/// overlap check reuses the relation check's pairs of solids, relabelled to
/// subdomains, and must name each pair in subdomain order.
#[test]
fn overlaps_of_one_solid_subdomains_name_the_pairs_in_subdomain_order() {
    let checked = check(
        r#"<geometry version="1">
  <sphere name="s2"><center x="3" y="3" z="3"/><radius value="0.5"/></sphere>
  <parallelepiped name="big"><first_point x="0" y="0" z="0"/><second_point x="4" y="4" z="4"/></parallelepiped>
  <sphere name="far"><center x="9" y="9" z="9"/><radius value="0.5"/></sphere>
  <sphere name="s1"><center x="1" y="1" z="1"/><radius value="0.5"/></sphere>
  <subdomain name="inner1"><solid ref="s1"/></subdomain>
  <subdomain name="alone"><solid ref="far"/></subdomain>
  <subdomain name="outer"><solid ref="big"/></subdomain>
  <subdomain name="inner2"><solid ref="s2"/></subdomain>
</geometry>"#,
    );
    let found: Vec<(&str, u32, &str)> = checked
        .diagnostics
        .items
        .iter()
        .map(|d| {
            let line = (checked.source)
                .line_col(d.span.expect("located").range().start)
                .line;
            (d.code.as_str(), line, d.message.as_str())
        })
        .collect();
    assert_eq!(
        found,
        vec![
            ("E407", 8, "subdomains 'inner1' and 'outer' overlap"),
            ("E407", 9, "subdomains 'outer' and 'inner2' overlap"),
        ]
    );
}

#[test]
fn a_two_dimensional_disk_with_a_hole() {
    let lowered = valid(
        r#"<geometry version="1" dimension="2">
  <circle name="outer"><center x="0" y="0"/><radius value="2"/></circle>
  <circle name="hole"><center x="0" y="0"/><radius value="1"/></circle>
  <subdomain name="ring"><difference><solid ref="outer"/><solid ref="hole"/></difference></subdomain>
  <subdomain name="core"><solid ref="hole"/></subdomain>
  <boundary name="rim" edges="outer.rim"/>
</geometry>"#,
    );
    let model = &lowered.model;
    let fragments = derive_fragments(model);
    let summary: Vec<(String, usize)> = fragments
        .iter()
        .map(|f| (f.name.clone(), f.edges.len()))
        .collect();
    assert_eq!(
        summary,
        vec![("rim".to_string(), 1), ("ring|core".to_string(), 1)]
    );
    let ring = &model.faces[match &model.subdomains[0].cells {
        SubdomainCells::Region { faces } => faces[0].index(),
        _ => panic!("2D"),
    }];
    assert_eq!(ring.loops.len(), 2);
}
