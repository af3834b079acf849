//! One density-volume fuzz case, shared by the fuzz target and
//! tests/fuzz_regressions.rs. The input is either an NRRD file (it starts
//! with `NRRD`: written as `vol.nrrd`, the bytes after its first empty line
//! also as `data.raw` for a detached `data file:`) or a raw volume whose first
//! line is the `<density_volume>` attributes (`type="u8" dims="2 2 2"`) and
//! the rest the samples (`vol.raw`). A domain naming the file is then checked
//! by the XML front end, which reads the volume.

use std::path::Path;

/// Writes the case into `dir` and checks its domain.
pub fn check(dir: &Path, data: &[u8]) -> geomc::driver::Checked {
    let (file, attributes) = if data.starts_with(b"NRRD") {
        let _ = std::fs::write(dir.join("vol.nrrd"), data);
        let body = data
            .windows(2)
            .position(|w| w == b"\n\n")
            .map_or(&data[..0], |p| &data[p + 2..]);
        let _ = std::fs::write(dir.join("data.raw"), body);
        ("vol.nrrd", String::new())
    } else {
        let split = data.iter().position(|&b| b == b'\n').unwrap_or(data.len());
        let _ = std::fs::write(dir.join("vol.raw"), data.get(split + 1..).unwrap_or(&[]));
        (
            "vol.raw",
            String::from_utf8_lossy(&data[..split]).into_owned(),
        )
    };
    let xml = format!(
        "<geometry version=\"1\">\n  <density_volume name=\"v\" file=\"{file}\" level=\"0.5\" {attributes}/>\n  <subdomain name=\"s\"> <solid ref=\"v\"/> </subdomain>\n</geometry>\n"
    );
    let name = dir.join("fuzz.xml").to_string_lossy().into_owned();
    let options = geomc::driver::Options::default();
    geomc::driver::check_bytes(name, xml.into_bytes(), &options)
}
