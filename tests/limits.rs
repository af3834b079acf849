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
