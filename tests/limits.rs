//! Resource limits (issue 10): each is refused with its code, a message
//! naming the limit and the option that raises it, before the memory it
//! guards is spent (bounded peak memory, no output), and raising the option
//! lets the same input through.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

struct Run {
    code: Option<i32>,
    stderr: String,
    peak_bytes: u64,
}

fn geomc(args: &[&str]) -> Run {
    let out: Output = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .env("GEOMC_STATS", "1")
        .args(args)
        .output()
        .expect("geomc runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let peak_bytes = stderr
        .lines()
        .find_map(|l| l.strip_prefix("peak memory: "))
        .and_then(|l| l.trim_end_matches(" bytes").parse().ok())
        .unwrap_or(0);
    Run {
        code: out.status.code(),
        stderr,
        peak_bytes,
    }
}

fn fixture(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(path)
        .to_string_lossy()
        .into_owned()
}

fn assert_refused(run: &Run, code: &str, option: &str, out: &Path) {
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert!(
        run.stderr.contains(&format!("error[{code}]")),
        "{}",
        run.stderr
    );
    assert!(run.stderr.contains(option), "{}", run.stderr);
    assert!(!out.exists(), "an output was written");
    if run.peak_bytes > 0 {
        assert!(
            run.peak_bytes < 150_000_000,
            "peak memory {} bytes",
            run.peak_bytes
        );
    }
}

fn out_path(dir: &tempfile::TempDir, name: &str) -> PathBuf {
    dir.path().join(name)
}

/// The number in "has N triangles" of an E801 message.
fn counted_triangles(stderr: &str) -> u64 {
    let after = stderr
        .split("the mesh has ")
        .nth(1)
        .expect("a counted E801");
    after
        .split_whitespace()
        .next()
        .and_then(|n| n.parse().ok())
        .expect("a triangle count")
}

#[test]
fn a_tolerance_too_fine_for_the_triangle_limit_is_refused_before_meshing() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let out = out_path(&dir, "ball.msh");
    let ball = fixture("fixtures/valid/sphere_center_coordinates.xml");
    // A unit-scale ball at 1e-9: billions of triangles; refused from the estimate.
    let run = geomc(&[
        "compile",
        &ball,
        "-o",
        out.to_str().unwrap(),
        "--tolerance",
        "1e-9",
    ]);
    assert_refused(&run, "E801", "--max-triangles", &out);
    assert!(
        run.stderr.contains("would have at least about"),
        "{}",
        run.stderr
    );
    assert!(
        run.stderr.contains("over the limit of 20000000 triangles"),
        "{}",
        run.stderr
    );
}

#[test]
fn the_triangle_limit_counts_the_real_mesh_and_can_be_raised() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let out = out_path(&dir, "ball.msh");
    let ball = fixture("fixtures/valid/sphere_center_coordinates.xml");
    let o = out.to_str().unwrap();
    // Below the estimate: refused before meshing.
    let run = geomc(&["compile", &ball, "-o", o, "--max-triangles", "10"]);
    assert_refused(&run, "E801", "--max-triangles", &out);
    assert!(
        run.stderr.contains("would have at least about"),
        "{}",
        run.stderr
    );
    // Above the (low) estimate, below the real count: refused before writing.
    let run = geomc(&["compile", &ball, "-o", o, "--max-triangles", "1000"]);
    assert_refused(&run, "E801", "--max-triangles", &out);
    let triangles = counted_triangles(&run.stderr);
    assert!(triangles > 100, "{triangles} triangles");
    // The estimate is a low one: a limit of exactly the real count passes it.
    let run = geomc(&[
        "compile",
        &ball,
        "-o",
        o,
        "--max-triangles",
        &triangles.to_string(),
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(out.exists());
    let run = geomc(&[
        "compile",
        &ball,
        "-o",
        o,
        "--max-triangles",
        &(triangles - 1).to_string(),
    ]);
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert_eq!(counted_triangles(&run.stderr), triangles);
}

#[test]
fn an_implicit_grid_over_the_cell_limit_is_refused_before_sampling() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let out = out_path(&dir, "balls.msh");
    let o = out.to_str().unwrap();
    let balls = fixture("fixtures/rfs/seven_balls.rfs");
    // 1000³ cells would take 8 GB of samples.
    let run = geomc(&["compile", &balls, "-o", o, "--cells", "1000"]);
    assert_refused(&run, "E800", "--max-grid-cells", &out);
    assert!(
        run.stderr.contains("1000 x 1000 x 1000 = 1000000000 cells"),
        "{}",
        run.stderr
    );
    assert!(
        run.stderr.contains("limit of 16777216 cells"),
        "{}",
        run.stderr
    );
    let run = geomc(&[
        "compile",
        &balls,
        "-o",
        o,
        "--cells",
        "30",
        "--max-grid-cells",
        "26999",
    ]);
    assert_refused(&run, "E800", "--max-grid-cells", &out);
    let run = geomc(&[
        "compile",
        &balls,
        "-o",
        o,
        "--cells",
        "30",
        "--max-grid-cells",
        "27000",
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(out.exists());
}

#[test]
fn mesh_and_rfs_inputs_over_the_file_size_limit_are_refused_unread() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let obj = out_path(&dir, "tet.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .expect("write");
    let out = out_path(&dir, "tet.stl");
    let (i, o) = (obj.to_str().unwrap(), out.to_str().unwrap());
    let run = geomc(&["convert", i, o, "--max-file-size", "20"]);
    assert_refused(&run, "E103", "--max-file-size", &out);
    assert!(
        run.stderr
            .contains("is 64 bytes, over the input size limit of 20 bytes"),
        "{}",
        run.stderr
    );
    let run = geomc(&["convert", i, o, "--max-file-size", "64"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    // A sparse 300 MB mesh file is refused from its size, not read.
    let huge = out_path(&dir, "huge.stl");
    std::fs::File::create(&huge)
        .and_then(|f| f.set_len(300 * 1024 * 1024))
        .expect("sparse file");
    let out2 = out_path(&dir, "huge.obj");
    let run = geomc(&["convert", huge.to_str().unwrap(), out2.to_str().unwrap()]);
    assert_refused(&run, "E103", "--max-file-size", &out2);
    let rfs = fixture("fixtures/rfs/seven_balls.rfs");
    let out3 = out_path(&dir, "balls.msh");
    let run = geomc(&[
        "compile",
        &rfs,
        "-o",
        out3.to_str().unwrap(),
        "--max-file-size",
        "100",
    ]);
    assert_refused(&run, "E103", "--max-file-size", &out3);
}

/// A glTF whose one triangle (a side buffer file) is drawn by `primitives`
/// primitives sharing the same two accessors.
fn shared_accessor_gltf(dir: &Path, primitives: usize) -> PathBuf {
    let mut bin = Vec::new();
    for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    std::fs::write(dir.join("tri.bin"), &bin).expect("write buffer");
    let primitive = r#"{"attributes":{"POSITION":0},"indices":1}"#;
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0,"name":"tri"}}],
"meshes":[{{"primitives":[{}]}}],
"buffers":[{{"uri":"tri.bin","byteLength":44}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}},{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]}}"#,
        vec![primitive; primitives].join(",")
    );
    let path = dir.join("shared.gltf");
    std::fs::write(&path, json).expect("write glTF");
    path
}

#[test]
fn gltf_accessors_shared_by_many_primitives_hit_the_element_limit() {
    let dir = tempfile::tempdir().expect("temporary folder");
    // 50 primitives × (3 positions + 3 indices) = 300 elements decoded.
    let gltf = shared_accessor_gltf(dir.path(), 50);
    let out = out_path(&dir, "shared.stl");
    let (i, o) = (gltf.to_str().unwrap(), out.to_str().unwrap());
    let run = geomc(&["convert", i, o, "--max-mesh-elements", "100"]);
    assert_refused(&run, "E805", "--max-mesh-elements", &out);
    assert!(
        run.stderr
            .contains("elements read to 102, over the limit of 100"),
        "{}",
        run.stderr
    );
    let png = out_path(&dir, "shared.png");
    let run = geomc(&[
        "render",
        i,
        "-o",
        png.to_str().unwrap(),
        "--max-mesh-elements",
        "299",
    ]);
    assert_refused(&run, "E805", "--max-mesh-elements", &png);
    let run = geomc(&["convert", i, o, "--max-mesh-elements", "300"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(out.exists());
}

#[test]
fn gltf_buffers_over_the_file_size_limit_are_refused_before_reading() {
    let dir = tempfile::tempdir().expect("temporary folder");
    std::fs::write(dir.path().join("a.bin"), [0u8; 300]).expect("write");
    std::fs::write(dir.path().join("b.bin"), [0u8; 300]).expect("write");
    let gltf = dir.path().join("two.gltf");
    std::fs::write(
        &gltf,
        r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"a.bin","byteLength":300},{"uri":"b.bin","byteLength":300}]}"#,
    )
    .expect("write");
    let out = out_path(&dir, "two.stl");
    let (i, o) = (gltf.to_str().unwrap(), out.to_str().unwrap());
    // Each buffer fits 500 bytes; together they do not.
    let run = geomc(&["convert", i, o, "--max-file-size", "500"]);
    assert_refused(&run, "E804", "--max-file-size", &out);
    assert!(
        run.stderr.contains("buffers[1]") && run.stderr.contains("hold 600 bytes"),
        "{}",
        run.stderr
    );
    // One buffer file over the limit is refused from its size alone.
    let run = geomc(&["convert", i, o, "--max-file-size", "299"]);
    assert_refused(&run, "E103", "--max-file-size", &out);
    assert!(run.stderr.contains("a.bin is 300 bytes"), "{}", run.stderr);
    // A sparse 300 MB buffer file under the default limit: refused unread.
    std::fs::File::create(dir.path().join("a.bin"))
        .and_then(|f| f.set_len(300 * 1024 * 1024))
        .expect("sparse file");
    let run = geomc(&["convert", i, o]);
    assert_refused(&run, "E103", "--max-file-size", &out);
}

#[test]
fn the_mesh_file_a_frag_xml_names_is_held_to_the_file_size_limit() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let msh = out_path(&dir, "ball.msh");
    let frag = out_path(&dir, "ball.frag.xml");
    let run = geomc(&[
        "compile",
        &fixture("examples/ball_in_box.xml"),
        "-o",
        msh.to_str().unwrap(),
        "-o",
        frag.to_str().unwrap(),
        // Fine enough that the mesh is bigger than its description.
        "--tolerance",
        "0.5%",
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let frag_size = std::fs::metadata(&frag).expect("frag").len();
    let msh_size = std::fs::metadata(&msh).expect("msh").len();
    assert!(frag_size < msh_size);
    let out = out_path(&dir, "ball.stl");
    let (i, o) = (frag.to_str().unwrap(), out.to_str().unwrap());
    // The description fits the limit; the mesh it names does not.
    let limit = frag_size.to_string();
    let run = geomc(&["convert", i, o, "--max-file-size", &limit]);
    assert_refused(&run, "E103", "--max-file-size", &out);
    assert!(run.stderr.contains("the mesh file"), "{}", run.stderr);
    let run = geomc(&["convert", i, o, "--max-file-size", &msh_size.to_string()]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    // A sparse 300 MB mesh under the default limit: refused unread.
    std::fs::File::create(&msh)
        .and_then(|f| f.set_len(300 * 1024 * 1024))
        .expect("sparse file");
    let _ = std::fs::remove_file(&out);
    let run = geomc(&["convert", i, o]);
    assert_refused(&run, "E103", "--max-file-size", &out);
}

#[test]
fn render_and_inspect_mesh_honour_the_triangle_limit() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let xml = fixture("examples/ball_in_box.xml");
    let png = out_path(&dir, "ball.png");
    let p = png.to_str().unwrap();
    // An absurd tolerance is refused from the estimate, before meshing.
    let run = geomc(&["render", &xml, "-o", p, "--tolerance", "1e-9"]);
    assert_refused(&run, "E801", "--max-triangles", &png);
    assert!(
        run.stderr.contains("would have at least about"),
        "{}",
        run.stderr
    );
    let run = geomc(&[
        "render",
        &xml,
        "-o",
        p,
        "--tolerance",
        "2%",
        "--max-triangles",
        "50",
    ]);
    assert_refused(&run, "E801", "--max-triangles", &png);
    let run = geomc(&["render", &xml, "-o", p, "--tolerance", "2%"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let _ = std::fs::remove_file(&png);
    // A mesh file is counted once read.
    let obj = out_path(&dir, "tet.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .expect("write");
    let o = obj.to_str().unwrap();
    let run = geomc(&["render", o, "-o", p, "--max-triangles", "3"]);
    assert_refused(&run, "E801", "--max-triangles", &png);
    assert!(run.stderr.contains("has 4 triangles"), "{}", run.stderr);
    let run = geomc(&["render", o, "-o", p, "--max-triangles", "4"]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    // inspect --mesh: estimated, then counted.
    let run = geomc(&["inspect", &xml, "--mesh", "--tolerance", "1e-9"]);
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert!(run.stderr.contains("error[E801]") && run.stderr.contains("--max-triangles"));
    let run = geomc(&[
        "inspect",
        &xml,
        "--mesh",
        "--tolerance",
        "2%",
        "--max-triangles",
        "50",
    ]);
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    let counted = counted_triangles(&run.stderr);
    assert!(counted > 50, "{counted}");
    let limit = counted.to_string();
    let run = geomc(&[
        "inspect",
        &xml,
        "--mesh",
        "--tolerance",
        "2%",
        "--max-triangles",
        &limit,
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
}

/// A domain whose box half-width is `expression`.
fn box_with(dir: &Path, expression: &str) -> PathBuf {
    let path = dir.join("expr.xml");
    let xml = format!(
        r#"<geometry version="1"><parameters><parameter name="a" value="{expression}"/></parameters></geometry>"#
    );
    std::fs::write(&path, xml).expect("write");
    path
}

#[test]
fn expression_limits_are_named_and_can_be_raised() {
    let dir = tempfile::tempdir().expect("temporary folder");
    // 300 levels of parentheses: over the default depth of 256.
    let deep = format!("{}1{}", "(".repeat(300), ")".repeat(300));
    let xml = box_with(dir.path(), &deep);
    let x = xml.to_str().unwrap();
    let run = geomc(&["validate", x]);
    assert_eq!(run.code, Some(1), "{}", run.stderr);
    assert!(run.stderr.contains("error[E124]"), "{}", run.stderr);
    assert!(
        run.stderr.contains("256 levels") && run.stderr.contains("--max-expression-depth"),
        "{}",
        run.stderr
    );
    let run = geomc(&["validate", x, "--max-expression-depth", "400"]);
    assert!(!run.stderr.contains("E124"), "{}", run.stderr);
    // The depth option has a ceiling: the parser and evaluator recurse.
    let run = geomc(&["validate", x, "--max-expression-depth", "5000"]);
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    // max() of 20,000 arguments: two levels deep, over the default 10,000 nodes.
    let long = format!("max({})", vec!["1"; 20_000].join(","));
    let xml = box_with(dir.path(), &long);
    let x = xml.to_str().unwrap();
    let run = geomc(&["validate", x]);
    assert!(
        run.stderr.contains("error[E124]")
            && run.stderr.contains("10000 nodes")
            && run.stderr.contains("--max-expression-nodes"),
        "{}",
        run.stderr
    );
    let run = geomc(&["validate", x, "--max-expression-nodes", "50000"]);
    assert!(!run.stderr.contains("E124"), "{}", run.stderr);
}
