//! `geomc inspect` and `geomc render` show the implicit subdomains of an XML
//! model (issue 5): they are not in the boundary-representation model, so
//! both commands add them (inspect lists them, render polygonizes them as
//! compile does, with their fragments in the legend).

use std::path::{Path, PathBuf};
use std::process::Command;

const MODEL: &str = r#"<?xml version="1.0"?>
<geometry version="1">
<rfunction name="cyl" rsystem="minmax" nx="24" ny="24" nz="24">
  <intersection> <disk r="0.3" x0="0" y0="0"/> <formula value="0.9 - abs(z)"/> </intersection>
</rfunction>
<rfunction name="box" rsystem="minmax" nx="24" ny="24" nz="24" optiterations="2"> <box x0="-0.6" y0="-0.6" z0="-0.5" w="1.2" h="1.2" d="1"/> </rfunction>
<subdomain name="pin" material="steel"> <solid ref="cyl"/> </subdomain>
<subdomain name="block"> <difference> <solid ref="box"/> <solid ref="cyl"/> </difference> </subdomain>
</geometry>
"#;

fn model(dir: &Path) -> PathBuf {
    let path = dir.join("pin.xml");
    std::fs::write(&path, MODEL).expect("write the model");
    path
}

fn geomc(args: &[&str], input: &Path) -> (String, String, Option<i32>) {
    let out = Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(args)
        .arg(input)
        .output()
        .expect("run geomc");
    (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        out.status.code(),
    )
}

#[test]
fn inspect_lists_the_implicit_subdomains() {
    let dir = tempfile::tempdir().expect("temp dir");
    let xml = model(dir.path());
    let (text, err, code) = geomc(&["inspect"], &xml);
    assert_eq!(code, Some(0), "{err}");
    assert!(text.contains("implicit subdomains: 2\n"), "{text}");
    assert!(
        text.contains(
            "  pin (function): box [-1, -1, -1] – [1, 1, 1], grid 24×24×24, material steel\n"
        ),
        "{text}"
    );
    assert!(
        text.contains("  block (function): box [-1, -1, -1] – [1, 1, 1], grid 24×24×24, 2 optimisation iterations\n"),
        "{text}"
    );
    let (json, err, code) = geomc(&["inspect", "--format", "json"], &xml);
    assert_eq!(code, Some(0), "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).expect("JSON");
    let list = v["implicit_subdomains"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    let names: Vec<&str> = list.iter().filter_map(|e| e["name"].as_str()).collect();
    assert_eq!(names, ["pin", "block"]);
    assert_eq!(list[0]["cells"], serde_json::json!([24, 24, 24]));
    assert_eq!(list[0]["material"], "steel");
    assert_eq!(list[1]["optiterations"], 2);
}

#[test]
fn render_draws_the_implicit_subdomains_with_their_fragments() {
    let dir = tempfile::tempdir().expect("temp dir");
    let xml = model(dir.path());
    let svg = dir.path().join("pin.svg");
    let (_, err, code) = geomc(&["render", "-o", svg.to_str().expect("utf-8")], &xml);
    assert_eq!(code, Some(0), "{err}");
    let text = std::fs::read_to_string(&svg).expect("the SVG");
    for name in [">pin|exterior<", ">block|exterior<", ">pin|block<"] {
        assert!(text.contains(name), "legend without {name}");
    }
    let png = dir.path().join("pin.png");
    let (_, err, code) = geomc(&["render", "-o", png.to_str().expect("utf-8")], &xml);
    assert_eq!(code, Some(0), "{err}");
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(&png).expect("the PNG"),
    ));
    let mut reader = decoder.read_info().expect("a PNG header");
    let mut buf = vec![0; reader.output_buffer_size().expect("a size")];
    let info = reader.next_frame(&mut buf).expect("a frame");
    assert_eq!((info.width, info.height), (800, 600));
    let channels = info.line_size / info.width as usize;
    let drawn = buf[..info.buffer_size()]
        .chunks(channels)
        .filter(|p| p[..3].iter().any(|&c| c < 200))
        .count();
    // The block and pin cover about a third of the picture.
    let fraction = drawn as f64 / (800.0 * 600.0);
    assert!(fraction > 0.2, "drawn fraction {fraction}");
}
