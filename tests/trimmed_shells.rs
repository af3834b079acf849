//! Trimmed surfaces as faces of subdomains and fragments (issue 9): shells
//! closed by trimmed surfaces are watertight, consistently oriented and
//! enclose the right volume; a trim chain that meets another face's
//! boundary shares its nodes; fragments between subdomains can be trimmed
//! faces, and gmsh reads and tetrahedralizes the result.

mod writers_common;

use geomc::driver::{Options, check_file};
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, mesh_model, sanity_check};
use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::PI;
use std::path::Path;
use writers_common::run_json;

fn mesh_of(fixture: &str) -> Mesh {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(fixture);
    let checked = check_file(&path, &Options::default()).expect("readable");
    let model = checked.lowered.expect("a model").model;
    mesh_model(&model, &MeshOptions::default()).expect("meshes")
}

fn face_index(mesh: &Mesh, name: &str) -> usize {
    mesh.faces
        .iter()
        .position(|f| f.name == name)
        .unwrap_or_else(|| panic!("face {name}"))
}

/// The subdomain's boundary triangles, each turned to face outward.
fn outward_triangles(mesh: &Mesh, subdomain: &str) -> Vec<[u32; 3]> {
    let sub = mesh
        .subdomains
        .iter()
        .find(|s| s.name == subdomain)
        .expect("subdomain");
    sub.faces
        .iter()
        .flat_map(|&(f, outward)| {
            mesh.faces[f as usize]
                .triangles
                .iter()
                .map(move |&[a, b, c]| if outward { [a, b, c] } else { [a, c, b] })
        })
        .collect()
}

/// Asserts every directed edge is used once and its reverse once (closed,
/// consistently oriented), and returns the enclosed volume.
fn closed_volume(mesh: &Mesh, subdomain: &str) -> f64 {
    let triangles = outward_triangles(mesh, subdomain);
    let mut directed: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for t in &triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(
            n, 1,
            "{subdomain}: edge {a}-{b} runs the same way {n} times"
        );
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "{subdomain}: edge {a}-{b} is open"
        );
    }
    let p = |i: u32| nalgebra::Vector3::from(mesh.nodes[i as usize]);
    triangles
        .iter()
        .map(|t| p(t[0]).dot(&p(t[1]).cross(&p(t[2]))) / 6.0)
        .sum()
}

fn chain_nodes(mesh: &Mesh, edge: &str) -> BTreeSet<u32> {
    mesh.edges
        .iter()
        .find(|e| e.name == edge)
        .unwrap_or_else(|| panic!("edge {edge}"))
        .nodes
        .iter()
        .copied()
        .collect()
}

/// The radius of every node of a set, about the y axis.
fn radii(mesh: &Mesh, nodes: &BTreeSet<u32>) -> (f64, f64) {
    nodes
        .iter()
        .map(|&n| mesh.nodes[n as usize][0].hypot(mesh.nodes[n as usize][2]))
        .fold((f64::INFINITY, 0.0), |(lo, hi), r| (lo.min(r), hi.max(r)))
}

#[test]
fn an_annulus_closed_by_trimmed_surfaces_is_watertight_with_its_volume() {
    let mesh = mesh_of("fixtures/valid/trimmed_annulus_shell.xml");
    sanity_check(&mesh).expect("sane");
    let ring = &mesh.subdomains[0];
    assert_eq!(ring.name, "ring");
    assert_eq!(ring.faces.len(), 4);
    let volume = closed_volume(&mesh, "ring");
    let exact = PI * (1.0 - 0.16);
    // Polygonal rims lie inside the outer circle and outside nothing: the
    // mesh volume is within 1% of the exact one.
    assert!(
        (volume - exact).abs() < 0.01 * exact,
        "volume {volume} vs {exact}"
    );
    // The floor's two trim circles are the tubes' ends, node for node.
    let floor: BTreeSet<u32> = mesh.faces[face_index(&mesh, "floor")]
        .triangles
        .iter()
        .flatten()
        .copied()
        .collect();
    for tube in ["outer", "inner"] {
        let tube_nodes: BTreeSet<u32> = mesh.faces[face_index(&mesh, tube)]
            .triangles
            .iter()
            .flatten()
            .copied()
            .collect();
        let rim: BTreeSet<u32> = floor.intersection(&tube_nodes).copied().collect();
        let r = if tube == "outer" { 1.0 } else { 0.4 };
        assert!(rim.len() >= 24, "{tube}: {} shared nodes", rim.len());
        let (lo, hi) = radii(&mesh, &rim);
        assert!((lo - r).abs() < 1e-9 && (hi - r).abs() < 1e-9, "{lo} {hi}");
    }
    // One fragment, the exterior, holding the four faces.
    assert_eq!(mesh.fragments.len(), 1);
    assert_eq!(mesh.fragments[0].name, "ring|exterior");
    assert_eq!(mesh.fragments[0].faces.len(), 4);
}

#[test]
fn a_trimmed_face_between_two_subdomains_is_their_fragment() {
    let mesh = mesh_of("fixtures/valid/trimmed_stacked_cans.xml");
    let lower = closed_volume(&mesh, "lower");
    let upper = closed_volume(&mesh, "upper");
    assert!((lower - PI).abs() < 0.01 * PI, "lower {lower}");
    assert!(
        (upper - 0.36 * PI).abs() < 0.01 * 0.36 * PI,
        "upper {upper}"
    );
    let names = |f: &geomc::mesh::MeshFragment| -> Vec<String> {
        f.faces
            .iter()
            .map(|&i| mesh.faces[i as usize].name.clone())
            .collect()
    };
    let by_name: BTreeMap<String, Vec<String>> = mesh
        .fragments
        .iter()
        .map(|f| (f.name.clone(), names(f)))
        .collect();
    assert_eq!(by_name["lower|upper"], ["middle"]);
    assert_eq!(by_name["lower|exterior"], ["base", "lower_tube", "ring"]);
    assert_eq!(by_name["upper|exterior"], ["upper_tube", "roof"]);
    // The middle disk keeps its surface's normal R_u × R_v, which points
    // down (-y, the cans' axis): into `lower`, below it, and out of `upper`.
    let p = |i: u32| nalgebra::Vector3::from(mesh.nodes[i as usize]);
    let middle_normal: nalgebra::Vector3<f64> = mesh.faces[face_index(&mesh, "middle")]
        .triangles
        .iter()
        .map(|t| (p(t[1]) - p(t[0])).cross(&(p(t[2]) - p(t[0]))))
        .sum();
    assert!(
        middle_normal.y < 0.0 && middle_normal.y.abs() > 0.99 * middle_normal.norm(),
        "middle normal {middle_normal:?}"
    );
    let flag = |sub: &str| {
        let m = face_index(&mesh, "middle") as u32;
        mesh.subdomains
            .iter()
            .find(|s| s.name == sub)
            .and_then(|s| s.faces.iter().find(|f| f.0 == m))
            .map(|f| f.1)
    };
    assert_eq!((flag("lower"), flag("upper")), (Some(false), Some(true)));
}

#[test]
fn gmsh_reads_the_trimmed_fragments_and_fills_both_volumes() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let out = dir.path().join("cans.msh");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(["compile", "fixtures/valid/trimmed_stacked_cans.xml", "-o"])
        .arg(&out)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("geomc runs");
    assert_eq!(status.status.code(), Some(0), "{status:?}");
    let report = run_json("python3", "check_mesh.py", &[&out, Path::new("--tetra")]);
    assert_eq!(
        report["meshio"]["points"], report["gmsh"]["nodes"],
        "{report}"
    );
    let triangles = |name: &str| {
        report["gmsh"]["groups"]
            .as_array()
            .and_then(|g| g.iter().find(|g| g["name"] == name))
            .map(|g| g["elements"]["triangle"].as_u64().unwrap_or(0))
    };
    let mesh = mesh_of("fixtures/valid/trimmed_stacked_cans.xml");
    let middle = mesh.faces[face_index(&mesh, "middle")].triangles.len() as u64;
    assert_eq!(triangles("lower|upper"), Some(middle));
    for volume in ["lower", "upper"] {
        let n = report["tetra"]["tetrahedra"][volume].as_u64().unwrap_or(0);
        assert!(
            n > 100,
            "gmsh filled {volume} with {n} tetrahedra: {report}"
        );
    }
}

#[test]
fn a_hole_rim_on_a_model_edge_takes_its_nodes() {
    let mesh = mesh_of("fixtures/valid/trimmed_plate_on_post.xml");
    let rim = chain_nodes(&mesh, "post.top_rim");
    let plate = face_index(&mesh, "plate");
    let hole: BTreeSet<u32> = mesh.faces[plate]
        .boundary
        .iter()
        .map(|&(e, _)| chain_nodes(&mesh, &mesh.edges[e as usize].name))
        .find(|c| c.contains(rim.iter().next().expect("rim nodes")))
        .expect("a plate chain on the rim");
    assert_eq!(hole, rim);
    assert!(rim.len() >= 24, "{} rim nodes", rim.len());
    // The rim edges are used by the post's side, its top and the plate.
    let mut uses: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for t in mesh.faces.iter().flat_map(|f| &f.triangles) {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let rim_edges: Vec<usize> = uses
        .iter()
        .filter(|((a, b), _)| rim.contains(a) && rim.contains(b))
        .map(|(_, &n)| n)
        .collect();
    assert_eq!(rim_edges.len(), rim.len());
    assert!(rim_edges.iter().all(|&n| n == 3), "{rim_edges:?}");
}

#[test]
fn a_trimmed_face_that_does_not_meet_its_shell_is_refused() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let source = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/valid/trimmed_annulus_shell.xml"),
    )
    .expect("fixture");
    // The lid lifted off the tubes' ends.
    let lifted = source.replace("y=\"1\"", "y=\"1.5\"");
    let input = dir.path().join("lifted.xml");
    std::fs::write(&input, lifted).expect("write");
    let out = dir.path().join("lifted.msh");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(["compile"])
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .output()
        .expect("geomc runs");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_ne!(run.status.code(), Some(0));
    assert!(stderr.contains("E502"), "{stderr}");
    assert!(
        stderr.contains("`lid`") && stderr.contains("subdomain `ring`"),
        "{stderr}"
    );
    assert!(!out.exists());
}

/// The smallest angle of a triangle, in degrees, with corners in any
/// dimension given as coordinates.
fn smallest_angle<const N: usize>(p: [[f64; N]; 3]) -> f64 {
    (0..3)
        .map(|k| {
            let (a, b, c) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
            let u: Vec<f64> = (0..N).map(|i| b[i] - a[i]).collect();
            let v: Vec<f64> = (0..N).map(|i| c[i] - a[i]).collect();
            let dot: f64 = u.iter().zip(&v).map(|(x, y)| x * y).sum();
            let nu = u.iter().map(|x| x * x).sum::<f64>().sqrt();
            let nv = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            (dot / (nu * nv)).clamp(-1.0, 1.0).acos().to_degrees()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Issue 3 asks for 25° on planar faces: the post's top (whose rim the
/// plate's hole takes) and bottom have it. Its side is a cylinder, refined
/// in its conformal log-polar chart (ln R = y / r, θ): 25° holds there; on
/// the surface a straight chart triangle spanning a third of a unit of ln R
/// is bent, which left one triangle at 22.2° against the rim (26.2° in the
/// chart). The rim is not held fixed: the side is meshed in one round
/// before the plate takes the rim's nodes.
#[test]
fn plate_on_post_keeps_25_degrees_on_its_planes_and_in_the_side_chart() {
    let mesh = mesh_of("fixtures/valid/trimmed_plate_on_post.xml");
    let face_angles = |name: &str, map: &dyn Fn([f64; 3]) -> Vec<f64>| {
        mesh.faces[face_index(&mesh, name)]
            .triangles
            .iter()
            .map(|t| {
                let c = t.map(|n| map(mesh.nodes[n as usize]));
                smallest_angle([
                    [c[0][0], c[0][1], c[0].get(2).copied().unwrap_or(0.0)],
                    [c[1][0], c[1][1], c[1].get(2).copied().unwrap_or(0.0)],
                    [c[2][0], c[2][1], c[2].get(2).copied().unwrap_or(0.0)],
                ])
            })
            .fold(f64::INFINITY, f64::min)
    };
    let space = |p: [f64; 3]| p.to_vec();
    for plane in ["post.top", "post.bottom"] {
        let angle = face_angles(plane, &space);
        assert!(angle >= 25.0, "{plane}: smallest angle {angle:.2}°");
    }
    let chart = |p: [f64; 3]| {
        let scale = (p[1] / 0.4).exp();
        let theta = p[2].atan2(p[0]);
        vec![scale * theta.cos(), scale * theta.sin()]
    };
    let in_chart = face_angles("post.side", &chart);
    assert!(in_chart >= 25.0, "post.side in its chart: {in_chart:.2}°");
    // The chart's bend at this tolerance, not a bound the mesher promises.
    let on_surface = face_angles("post.side", &space);
    assert!(
        on_surface >= 22.0,
        "post.side on the surface: {on_surface:.2}°"
    );
}
