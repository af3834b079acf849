//! Render benchmark (issue 8): a 1-million-triangle torus rendered to a
//! 1024×1024 PNG with the default options, against reading the same mesh from
//! GLB (written by geomc, read with the `gltf` crate: file, JSON, buffer,
//! positions and indices) in the same run. Target: render time below read
//! time. Also the SVG hidden-line drawing of a 50,000-triangle torus.
//!
//! Run: `cargo bench --bench render`. Under `cargo test --all-targets` it runs
//! as a smoke test on small meshes.

use geomc::formats::{WriteOptions, write_mesh_file};
use geomc::mesh::{Mesh, MeshFace, MeshFragment, MeshSubdomain};
use geomc::render::{Edges, RenderOptions, render_png, render_svg};
use std::time::{Duration, Instant};

/// A torus of `nu × nv × 2` triangles, outward-oriented, as one face bounding one subdomain.
fn torus(nu: usize, nv: usize) -> Mesh {
    let (big, small) = (1.0, 0.35);
    let mut nodes = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        let u = i as f64 / nu as f64 * std::f64::consts::TAU;
        for j in 0..nv {
            let v = j as f64 / nv as f64 * std::f64::consts::TAU;
            let ring = big + small * v.cos();
            nodes.push([ring * u.cos(), ring * u.sin(), small * v.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + (j % nv)) as u32;
    let mut triangles = Vec::with_capacity(2 * nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            // Counter-clockwise seen from outside: u then v turns outward.
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Mesh {
        dimension: 3,
        nodes,
        faces: vec![MeshFace {
            name: "torus".into(),
            triangles,
            boundary: Vec::new(),
        }],
        subdomains: vec![MeshSubdomain {
            name: "ring".into(),
            material: None,
            faces: vec![(0, true)],
        }],
        fragments: vec![MeshFragment {
            name: "surface".into(),
            subdomain: 0,
            other: None,
            faces: vec![0],
            edges: Vec::new(),
        }],
        ..Mesh::default()
    }
}

fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut best = Duration::MAX;
    let mut last = None;
    for _ in 0..runs {
        let start = Instant::now();
        let value = f();
        best = best.min(start.elapsed());
        last = Some(value);
    }
    (best, last.expect("at least one run"))
}

/// Reads a GLB's first primitive with the gltf crate: positions and indices.
fn read_glb(path: &std::path::Path) -> (Vec<[f32; 3]>, Vec<u32>) {
    let bytes = std::fs::read(path).expect("read GLB");
    let gltf = gltf::Gltf::from_slice(&bytes).expect("parse GLB");
    let blob = gltf.blob.as_deref().expect("GLB binary chunk");
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for mesh in gltf.meshes() {
        for primitive in mesh.primitives() {
            let reader = primitive.reader(|_| Some(blob));
            let base = positions.len() as u32;
            if let Some(p) = reader.read_positions() {
                positions.extend(p);
            }
            if let Some(i) = reader.read_indices() {
                indices.extend(i.into_u32().map(|i| i + base));
            }
        }
    }
    (positions, indices)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let smoke = !args.iter().any(|a| a == "--bench");
    let (nu, nv, svg_nu, svg_nv, runs) = if smoke {
        (100, 50, 50, 25, 1)
    } else {
        (1000, 500, 250, 100, 3)
    };
    let mesh = torus(nu, nv);
    let n_tris = mesh.faces[0].triangles.len();
    let dir = std::env::temp_dir().join(format!("geomc-render-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let glb = dir.join("torus.glb");
    write_mesh_file(&glb, &mesh, &WriteOptions::default()).expect("write GLB");
    let mb = std::fs::metadata(&glb).map(|m| m.len()).unwrap_or(0) as f64 / 1e6;
    println!(
        "render: torus of {n_tris} triangles, GLB {mb:.1} MB, {} threads",
        rayon::current_num_threads()
    );

    let (read, (positions, indices)) = best_of(runs, || read_glb(&glb));
    assert!(indices.len() >= 3 * n_tris);
    assert!(positions.len() >= mesh.nodes.len());
    let options = RenderOptions {
        width: 1024,
        height: 1024,
        ..RenderOptions::default()
    };
    let (render, (png, _)) = best_of(runs, || render_png(&mesh, &options).expect("renders"));
    let (render_aa1, _) = best_of(runs, || {
        render_png(
            &mesh,
            &RenderOptions {
                antialias: 1,
                ..options.clone()
            },
        )
        .expect("renders")
    });
    let ratio = render.as_secs_f64() / read.as_secs_f64();
    println!(
        "  gltf crate: read GLB (positions + indices): {:8.3} s",
        read.as_secs_f64()
    );
    println!(
        "  geomc render 1024x1024 PNG (default, 2x2 AA): {:8.3} s  ({:.1} kB)",
        render.as_secs_f64(),
        png.len() as f64 / 1e3
    );
    println!(
        "  geomc render 1024x1024 PNG, --antialias 1:    {:8.3} s",
        render_aa1.as_secs_f64()
    );
    println!(
        "  render / read: {ratio:.2} (target < 1) {}",
        verdict(ratio < 1.0)
    );

    let small = torus(svg_nu, svg_nv);
    let svg_tris = small.faces[0].triangles.len();
    let svg_options = RenderOptions {
        width: 1024,
        height: 1024,
        ..RenderOptions::default()
    };
    let (svg_time, drawing) = best_of(runs, || render_svg(&small, &svg_options).expect("draws"));
    let (svg_all, all) = best_of(runs, || {
        render_svg(
            &small,
            &RenderOptions {
                edges: Edges::All,
                ..svg_options.clone()
            },
        )
        .expect("draws")
    });
    let (png_small, _) = best_of(runs, || render_png(&small, &svg_options).expect("renders"));
    println!(
        "  SVG hidden lines, {svg_tris} triangles, silhouettes: {:8.3} s ({} pieces); every edge: {:8.3} s ({} pieces); PNG of the same: {:8.3} s",
        svg_time.as_secs_f64(),
        drawing.segments,
        svg_all.as_secs_f64(),
        all.segments,
        png_small.as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

fn verdict(ok: bool) -> &'static str {
    if ok { "PASS" } else { "FAIL" }
}
