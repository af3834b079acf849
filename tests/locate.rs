//! `geomc locate`: which subdomain each point of a CSV file lies in.

use std::process::{Command, Output};

fn geomc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("geomc runs")
}

fn points_file(dir: &tempfile::TempDir, text: &str) -> String {
    let path = dir.path().join("points.csv");
    std::fs::write(&path, text).expect("write the points");
    path.display().to_string()
}

/// The subdomain column of the output, row by row.
fn located(o: &Output) -> Vec<String> {
    let text = String::from_utf8_lossy(&o.stdout);
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("x,y,z,subdomain"));
    lines
        .map(|l| l.rsplit(',').next().unwrap_or_default().to_string())
        .collect()
}

#[test]
fn ball_in_box_points_fall_in_the_ball_the_shell_or_outside() {
    let dir = tempfile::tempdir().expect("temp dir");
    // The ball has radius 1 inside the box [-2, 2]³; a header row and a
    // comment are skipped; 0.9 and 1.1 sit a tenth from the sphere, far
    // beyond the default tolerance (0.1% of the diagonal, 0.007).
    let points = points_file(
        &dir,
        "x,y,z\n# centre, near the sphere inside and out, the shell, outside\n0,0,0\n0.9,0,0\n0,1.1,0\n1.5,1.5,1.5\n0,0,-1.9\n3,0,0\n0 0 2.5\n",
    );
    let o = geomc(&[
        "locate",
        "fixtures/valid/subdomain_ball_in_box.xml",
        "--points",
        &points,
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(
        located(&o),
        [
            "inner", "inner", "outer", "outer", "outer", "exterior", "exterior"
        ]
    );
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("\n0.9,0,0,inner\n"), "{text}");
}

#[test]
fn two_boxes_sharing_a_face_split_at_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    // Rows along y = z = 0.5 cross the shared face x = 1; y = z = 0 runs along
    // the boxes' edges, where every tie must still be broken once.
    let points = points_file(
        &dir,
        "0.5,0.5,0.5\n1.5,0.5,0.5\n0.999,0.5,0.5\n1.001,0.5,0.5\n0.5,0,0\n1.5,0,0\n2.5,0.5,0.5\n-0.5,0.5,0.5\n",
    );
    let output = dir.path().join("out.csv");
    let o = geomc(&[
        "locate",
        "fixtures/valid/subdomain_shared_face.xml",
        "--points",
        &points,
        "-o",
        &output.display().to_string(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.stdout.is_empty());
    let text = std::fs::read_to_string(&output).expect("the output file");
    let names: Vec<&str> = text
        .lines()
        .skip(1)
        .map(|l| l.rsplit(',').next().unwrap_or_default())
        .collect();
    assert_eq!(
        names,
        ["a", "b", "a", "b", "a", "b", "exterior", "exterior"]
    );
}

#[test]
fn a_2d_disk_in_a_square() {
    let dir = tempfile::tempdir().expect("temp dir");
    let points = points_file(&dir, "0,0\n0.5,-0.5\n1.5,1.5\n-1.9,0\n2.5,0\n");
    let o = geomc(&[
        "locate",
        "fixtures/valid/2d_disk_in_square.xml",
        "--points",
        &points,
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(
        located(&o),
        ["inner", "inner", "outer", "outer", "exterior"]
    );
}

#[test]
fn a_bad_row_is_e504_at_its_line_and_column_with_no_output() {
    let dir = tempfile::tempdir().expect("temp dir");
    let points = points_file(&dir, "x,y,z\n0,0,0\n1,abc,0\n1,2,3,4\n");
    let output = dir.path().join("out.csv");
    let o = geomc(&[
        "locate",
        "fixtures/valid/subdomain_ball_in_box.xml",
        "--points",
        &points,
        "-o",
        &output.display().to_string(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("points.csv:3:3: error[E504]"), "{err}");
    assert!(err.contains("`abc` is not a finite number"), "{err}");
    assert!(err.contains("points.csv:4:1: error[E504]"), "{err}");
    assert!(err.contains("a row holds 4 values"), "{err}");
    assert!(!output.exists(), "no output after an error");
}
