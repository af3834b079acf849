//! Issue 6's real test: a finite-element solver (scikit-fem, through
//! meshio) reads geomc's MSH files and solves −∇·(k∇u) = 1 with u = 0 on
//! named boundary fragments; the answers match the exact solutions and
//! improve under refinement. Needs `pip install scikit-fem meshio` (done by
//! ./scripts/test.sh).

use std::path::Path;
use std::process::Command;

fn compile(xml: &str, dir: &Path, name: &str, args: &[&str]) -> std::path::PathBuf {
    let input = dir.join(format!("{name}.xml"));
    std::fs::write(&input, xml).expect("write input");
    let output = dir.join(format!("{name}.msh"));
    let status = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .arg("compile")
        .arg("-q")
        .arg(&input)
        .args(args)
        .arg("-o")
        .arg(&output)
        .status()
        .expect("run geomc");
    assert!(status.success(), "geomc compile {name} {args:?}");
    output
}

fn solve(mesh: &Path, case: &str, boundaries: &[&str]) -> serde_json::Value {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/tools/fem_poisson.py");
    let out = Command::new("python3")
        .arg(script)
        .arg(mesh)
        .arg(case)
        .args(boundaries)
        .output()
        .expect("run python3");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "fem_poisson.py failed (run ./scripts/test.sh, which installs scikit-fem and meshio): {stderr}"
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().last().unwrap_or("");
    serde_json::from_str(line).unwrap_or_else(|e| panic!("bad output {stdout:?}: {e}"))
}

fn num(v: &serde_json::Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("no {key} in {v}"))
}

const DISK: &str = r#"<geometry version="1" dimension="2">
  <circle name="disk"><center x="0" y="0"/><radius value="1"/></circle>
  <subdomain name="inside"><solid ref="disk"/></subdomain>
  <boundary name="wall" edges="disk.rim"/>
</geometry>"#;

#[test]
fn unit_disk_matches_the_exact_solution_and_converges() {
    let dir = tempfile::tempdir().expect("tempdir");
    let coarse = solve(
        &compile(DISK, dir.path(), "c", &["--max-area", "0.02"]),
        "disk",
        &["wall"],
    );
    let fine = solve(
        &compile(DISK, dir.path(), "f", &["--max-area", "0.005"]),
        "disk",
        &["wall"],
    );
    assert!((num(&fine, "max_u") - 0.25).abs() < 0.0025, "{fine}");
    let (e1, e2) = (num(&coarse, "max_error"), num(&fine, "max_error"));
    assert!(e1 < 0.01 && e2 < 0.5 * e1, "errors {e1} then {e2}");
    assert!(num(&fine, "triangles") > 2.0 * num(&coarse, "triangles"));
    // Second order: 6-node triangles with mid nodes on the circle, solved
    // isoparametrically, are exact to the solver's precision.
    let quadratic = solve(
        &compile(
            DISK,
            dir.path(),
            "q",
            &["--max-area", "0.02", "--order", "2"],
        ),
        "disk",
        &["wall"],
    );
    assert!(num(&quadratic, "max_error") < 1e-4, "{quadratic}");
}

#[test]
fn annulus_matches_the_radial_solution() {
    let xml = r#"<geometry version="1" dimension="2">
      <circle name="outer"><center x="0" y="0"/><radius value="1"/></circle>
      <circle name="hole"><center x="0" y="0"/><radius value="0.5"/></circle>
      <subdomain name="ring"><difference><solid ref="outer"/><solid ref="hole"/></difference></subdomain>
      <boundary name="out" edges="outer.rim"/>
      <boundary name="in" edges="hole.rim"/>
    </geometry>"#;
    let dir = tempfile::tempdir().expect("tempdir");
    let coarse = solve(
        &compile(xml, dir.path(), "c", &["--max-area", "0.01"]),
        "annulus",
        &["out", "in"],
    );
    let fine = solve(
        &compile(xml, dir.path(), "f", &["--max-area", "0.0025"]),
        "annulus",
        &["out", "in"],
    );
    let (e1, e2) = (num(&coarse, "max_error"), num(&fine, "max_error"));
    assert!(e2 < 0.6 * e1 && e2 < 0.002, "errors {e1} then {e2}");
}

#[test]
fn two_materials_keep_the_flux_continuous_across_the_interface() {
    let xml = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/valid/2d_rectangles_interface.xml"
    ))
    .expect("fixture");
    let dir = tempfile::tempdir().expect("tempdir");
    let outer = ["walls", "soft|exterior", "hard|exterior"];
    let coarse = solve(
        &compile(&xml, dir.path(), "c", &["--max-area", "0.01"]),
        "twomat",
        &outer,
    );
    let fine = solve(
        &compile(&xml, dir.path(), "f", &["--max-area", "0.0025"]),
        "twomat",
        &outer,
    );
    let (j1, j2) = (num(&coarse, "flux_jump"), num(&fine, "flux_jump"));
    // Stated tolerance: the interface fluxes of the two sides agree within 3%
    // on the finer mesh, and closer than on the coarse one.
    assert!(j2 < 0.03 && j2 < j1, "flux jumps {j1} then {j2}");
}
