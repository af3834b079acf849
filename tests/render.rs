//! `geomc render` (issue 8): facts checked in the pixels and in the SVG's
//! segments, determinism across thread counts, and the command line.

use geomc::driver::{Options, check_source};
use geomc::mesh::Mesh;
use geomc::meshing::{MeshOptions, mesh_model};
use geomc::render::{
    self, ColorBy, Edges, RenderOptions, Section, View, decode_png, render_image, render_png,
    render_svg,
};
use geomc::span::SourceFile;
use std::process::Command;

fn mesh_of(xml: &str) -> Mesh {
    let checked = check_source(SourceFile::new("test.xml", xml), &Options::default());
    assert!(checked.is_valid(), "{:?}", checked.diagnostics.items);
    let lowered = checked.lowered.expect("a model");
    mesh_model(&lowered.model, &MeshOptions::default()).expect("meshes")
}

fn ball_in_box() -> Mesh {
    mesh_of(include_str!("../examples/ball_in_box.xml"))
}

fn unit_box() -> Mesh {
    mesh_of(
        r#"<geometry version="1">
  <parallelepiped name="box"><first_point x="0" y="0" z="0"/><second_point x="1" y="1" z="1"/></parallelepiped>
  <subdomain name="cube"><solid ref="box"/></subdomain>
</geometry>"#,
    )
}

fn bare(width: u32, height: u32, view: View) -> RenderOptions {
    RenderOptions {
        width,
        height,
        view,
        legend: false,
        background: [255, 255, 255, 0],
        ..RenderOptions::default()
    }
}

#[test]
fn same_input_same_png_for_any_thread_count() {
    let mesh = ball_in_box();
    let options = RenderOptions {
        section: Some(Section {
            axis: 2,
            value: 2.0,
        }),
        edges: Edges::Feature,
        width: 320,
        height: 240,
        ..RenderOptions::default()
    };
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| render_png(&mesh, &options).expect("renders").0)
    };
    let one = run(1);
    assert_eq!(one, run(1));
    assert_eq!(one, run(2));
    assert_eq!(one, run(3));
    let svg = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| render_svg(&mesh, &options).expect("draws").text)
    };
    assert_eq!(svg(1), svg(3));
    // And it really is a PNG of the asked size.
    let image = decode_png(&one).expect("decodes");
    assert_eq!((image.width, image.height), (320, 240));
}

/// The default picture (no edge overlay) is drawn band by band, each band's
/// samples resolved as soon as it is drawn: the same bytes for any thread
/// count there too, with and without a section, at each anti-aliasing level.
#[test]
fn banded_picture_is_the_same_for_any_thread_count() {
    let mesh = ball_in_box();
    for (section, antialias) in [(None, 2), (Some(2.0), 2), (None, 1), (Some(2.0), 3)] {
        let options = RenderOptions {
            section: section.map(|value| Section { axis: 2, value }),
            antialias,
            width: 300,
            height: 200,
            ..RenderOptions::default()
        };
        assert_eq!(options.edges, Edges::None);
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool")
                .install(|| render_png(&mesh, &options).expect("renders").0)
        };
        let one = run(1);
        assert_eq!(one, run(2), "{section:?} antialias {antialias}");
        assert_eq!(one, run(4), "{section:?} antialias {antialias}");
        let image = decode_png(&one).expect("decodes");
        // Something is drawn: the model covers pixels that are not the background.
        let drawn = image
            .rgba
            .chunks(4)
            .filter(|p| p != &[255, 255, 255, 255])
            .count();
        assert!(drawn > 300 * 200 / 10, "{drawn} pixels drawn");
    }
}

#[test]
fn sphere_covers_its_projected_disc_within_one_pixel_ring() {
    let mesh = mesh_of(
        r#"<geometry version="1">
  <sphere name="ball"><center x="1" y="-2" z="0.5"/><radius value="2"/></sphere>
  <subdomain name="inside"><solid ref="ball"/></subdomain>
</geometry>"#,
    );
    for view in [View::FRONT, View::TOP, View::ISO] {
        let rendered = render_image(&mesh, &bare(300, 200, view)).expect("renders");
        let covered: f64 = rendered
            .image
            .rgba
            .chunks(4)
            .map(|p| p[3] as f64 / 255.0)
            .sum();
        let r = 2.0 * rendered.camera.scale;
        let disc = std::f64::consts::PI * r * r;
        // The fit leaves 10% of the height free above and below.
        assert!((r - 80.0).abs() < 0.5, "radius {r} px");
        assert!(
            (covered - disc).abs() <= 2.0 * std::f64::consts::PI * r,
            "{view:?}: covered {covered:.1} px², disc {disc:.1} px²"
        );
        // Finer than a ring: the mesh is within 0.1% of the sphere.
        assert!((covered - disc).abs() / disc < 0.01, "{covered} vs {disc}");
    }
}

#[test]
fn cube_from_the_front_covers_exactly_its_square() {
    let mesh = unit_box();
    let rendered = render_image(&mesh, &bare(100, 100, View::FRONT)).expect("renders");
    let image = &rendered.image;
    for y in 0..100 {
        for x in 0..100 {
            let alpha = image.pixel(x, y)[3];
            let inside = (10..90).contains(&x) && (10..90).contains(&y);
            assert_eq!(alpha, if inside { 255 } else { 0 }, "pixel {x},{y}");
        }
    }
    // Seen straight on, the front face is one flat colour.
    let c = image.pixel(50, 50);
    assert!((10..90).all(|y| (10..90).all(|x| image.pixel(x, y) == c)));
}

#[test]
fn bands_no_triangle_reaches_show_the_background_of_either_path() {
    // A cube from the front in a tall picture: its square spans rows 110..190,
    // so the 16-row bands above row 96 and from row 192 hold no triangle.
    let mesh = unit_box();
    for (background, pixel) in [
        ([255, 255, 255, 0], [0, 0, 0, 0]),
        ([32, 48, 64, 255], [32, 48, 64, 255]),
    ] {
        for antialias in [1, 2, 3] {
            let options = RenderOptions {
                background,
                antialias,
                ..bare(100, 300, View::FRONT)
            };
            let banded = render_image(&mesh, &options).expect("renders").image;
            // With an edge overlay the whole sample buffer is built and resolved.
            let overlay = RenderOptions {
                edges: Edges::Feature,
                ..options
            };
            let full = render_image(&mesh, &overlay).expect("renders").image;
            for y in 0..300 {
                for x in 0..100 {
                    let inside = (10..90).contains(&x) && (110..190).contains(&y);
                    let got = banded.pixel(x, y);
                    if inside {
                        assert_eq!(got[3], 255, "pixel {x},{y}");
                    } else {
                        assert_eq!(got, pixel, "pixel {x},{y} antialias {antialias}");
                    }
                    if !(105..195).contains(&y) {
                        assert_eq!(full.pixel(x, y), pixel, "overlay pixel {x},{y}");
                    }
                }
            }
        }
    }
}

#[test]
fn box_in_iso_view_draws_only_its_nine_visible_edges() {
    let mesh = unit_box();
    let drawing = render_svg(&mesh, &bare(400, 400, View::ISO)).expect("draws");
    assert_eq!(drawing.segments, 9, "{}", drawing.text);
    assert_eq!(drawing.text.matches('M').count(), 9);
    // The three edges at the back corner (0, 1, 0) are hidden; the other
    // nine each lie under a drawn segment.
    let camera = render_image(&mesh, &bare(400, 400, View::ISO))
        .expect("renders")
        .camera;
    let drawn = segments_of(&drawing.text);
    let on_drawing = |a: [f64; 3], b: [f64; 3]| {
        let (pa, pb) = (camera.project(a), camera.project(b));
        let mid = [0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])];
        drawn
            .iter()
            .any(|s| distance_to_segment(mid, s[0], s[1]) < 0.5)
    };
    let corners: Vec<[f64; 3]> = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    let mut visible = 0;
    for a in &corners {
        for b in &corners {
            let differ = (0..3).filter(|&k| a[k] != b[k]).count();
            if differ == 1 && a < b {
                let hidden = [*a, *b].contains(&[0.0, 1.0, 0.0]);
                assert_eq!(on_drawing(*a, *b), !hidden, "edge {a:?}-{b:?}");
                visible += usize::from(!hidden);
            }
        }
    }
    assert_eq!(visible, 9);
    // Seen from the front only the front face's four edges remain.
    let front = render_svg(&mesh, &bare(400, 400, View::FRONT)).expect("draws");
    assert_eq!(front.segments, 4, "{}", front.text);
    // Every triangle edge: the 9 edges plus the visible faces' diagonals (one
    // or more per face), still nothing from the three hidden faces.
    let all = render_svg(
        &mesh,
        &RenderOptions {
            edges: Edges::All,
            ..bare(400, 400, View::ISO)
        },
    )
    .expect("draws");
    assert!(all.segments >= 12, "{}", all.segments);
}

/// The `M x y L x y` pieces of an SVG's paths.
fn segments_of(svg: &str) -> Vec<[[f64; 2]; 2]> {
    let mut out = Vec::new();
    for path in svg.split(" d=\"").skip(1) {
        let d = &path[..path.find('"').unwrap_or(path.len())];
        for piece in d.split('M').filter(|p| !p.is_empty()) {
            let nums: Vec<f64> = piece
                .split(['L', ' '])
                .filter(|t| !t.is_empty())
                .map(|t| t.parse().expect("a number"))
                .collect();
            out.push([[nums[0], nums[1]], [nums[2], nums[3]]]);
        }
    }
    out
}

fn distance_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((p[0] - a[0] - t * dx).powi(2) + (p[1] - a[1] - t * dy).powi(2)).sqrt()
}

#[test]
fn legend_lists_every_fragment() {
    let mesh = ball_in_box();
    let options = RenderOptions {
        width: 640,
        height: 480,
        ..RenderOptions::default()
    };
    let rendered = render_image(&mesh, &options).expect("renders");
    let names: Vec<&str> = rendered.legend.iter().map(|e| e.name.as_str()).collect();
    let fragments: Vec<&str> = mesh.fragments.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, fragments);
    assert_eq!(fragments.len(), 4);
    for entry in &rendered.legend {
        let [x, y, w, h] = entry.swatch;
        let p = rendered.image.pixel(x + w / 2, y + h / 2);
        assert_eq!([p[0], p[1], p[2]], entry.color, "{}", entry.name);
        let [tx, ty, tw, th] = entry.text;
        let dark = (ty..ty + th)
            .flat_map(|y| (tx..tx + tw).map(move |x| (x, y)))
            .filter(|&(x, y)| rendered.image.pixel(x, y)[..3] == [0, 0, 0])
            .count();
        // At least a few font pixels per character.
        assert!(dark >= 4 * entry.name.len(), "{}: {dark}", entry.name);
    }
    // The colours differ, so the legend tells fragments apart.
    let mut colors: Vec<[u8; 3]> = rendered.legend.iter().map(|e| e.color).collect();
    colors.dedup();
    assert_eq!(colors.len(), 4);
    let svg = render_svg(&mesh, &options).expect("draws");
    for f in &fragments {
        let escaped = f.replace('&', "&amp;").replace('<', "&lt;");
        assert!(svg.text.contains(&format!(">{escaped}</text>")), "{f}");
    }
    // By subdomain: the two subdomains.
    let by_sub = render_image(
        &mesh,
        &RenderOptions {
            color_by: ColorBy::Subdomain,
            ..options.clone()
        },
    )
    .expect("renders");
    let names: Vec<&str> = by_sub.legend.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names, ["matrix", "inclusion"]);
}

#[test]
fn section_shows_the_cut_material_of_each_subdomain() {
    let mesh = ball_in_box();
    let options = RenderOptions {
        section: Some(Section {
            axis: 2,
            value: 2.0,
        }),
        view: View::TOP,
        ..bare(200, 200, View::TOP)
    };
    let rendered = render_image(&mesh, &options).expect("renders");
    let cap = |name: &str| {
        rendered
            .groups
            .iter()
            .find(|g| g.name == name)
            .expect("cap group")
            .color
    };
    let shades = |c: [u8; 3], p: [u8; 4]| {
        [0.6f32, 0.95]
            .iter()
            .any(|l| (0..3).all(|k| (c[k] as f32 * l).round() as u8 == p[k]))
    };
    // The ball's centre (2, 2, 2) projects to the picture's centre, inside
    // the inclusion's cut; a point near the box's corner is the matrix's cut.
    assert!(shades(
        cap("section: inclusion"),
        rendered.image.pixel(100, 100)
    ));
    assert!(shades(cap("section: matrix"), rendered.image.pixel(25, 25)));
    // Without the section the top view shows the box's top face instead.
    let plain = render_image(&mesh, &bare(200, 200, View::TOP)).expect("renders");
    assert!(!shades(
        cap("section: inclusion"),
        plain.image.pixel(100, 100)
    ));
    // A plane below the model cuts everything away, with a warning.
    let empty = render_image(
        &mesh,
        &RenderOptions {
            section: Some(Section {
                axis: 2,
                value: -1.0,
            }),
            ..bare(50, 50, View::ISO)
        },
    )
    .expect("renders");
    assert_eq!(empty.warnings.len(), 1);
    assert_eq!(empty.warnings[0].code.as_str(), "W171");
    assert!(empty.image.rgba.chunks(4).all(|p| p[3] == 0));
}

#[test]
fn options_parse_and_refuse_bad_values() {
    assert_eq!(render::parse_size("1024x768").ok(), Some((1024, 768)));
    assert_eq!(
        render::parse_size("0x5").unwrap_err().code().as_str(),
        "E721"
    );
    assert_eq!(
        View::parse("45, 35").ok(),
        Some(View {
            azimuth: 45.0,
            elevation: 35.0
        })
    );
    assert_eq!(View::parse("up").unwrap_err().code().as_str(), "E722");
    assert_eq!(Section::parse("w=1").unwrap_err().code().as_str(), "E723");
    assert_eq!(
        render::parse_background("#ff000080").ok(),
        Some([255, 0, 0, 128])
    );
    assert_eq!(
        render::parse_background("red").unwrap_err().code().as_str(),
        "E725"
    );
    let mesh = unit_box();
    let bad = RenderOptions {
        antialias: 9,
        ..RenderOptions::default()
    };
    assert_eq!(
        render_image(&mesh, &bad).unwrap_err().code().as_str(),
        "E726"
    );
    assert_eq!(
        render_image(&Mesh::default(), &RenderOptions::default())
            .unwrap_err()
            .code()
            .as_str(),
        "E727"
    );
}

fn geomc(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_geomc"))
        .args(args)
        .output()
        .expect("runs geomc")
}

#[test]
fn cli_renders_png_and_svg_and_refuses_bad_input() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let png = dir.path().join("ball.png");
    let svg = dir.path().join("ball.svg");
    let out = geomc(&[
        "render",
        "examples/ball_in_box.xml",
        "-o",
        png.to_str().unwrap(),
        "--size",
        "200x150",
        "--section",
        "z=2",
        "--edges",
        "feature",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let image = decode_png(&std::fs::read(&png).expect("written")).expect("a PNG");
    assert_eq!((image.width, image.height), (200, 150));
    let out = geomc(&[
        "render",
        "examples/ball_in_box.xml",
        "-o",
        svg.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert!(
        std::fs::read_to_string(&svg)
            .expect("written")
            .starts_with("<?xml")
    );

    let bad = dir.path().join("bad.png");
    let out = geomc(&[
        "render",
        "examples/ball_in_box.xml",
        "-o",
        bad.to_str().unwrap(),
        "--size",
        "12",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("error[E721]"));
    let out = geomc(&[
        "render",
        "examples/ball_in_box.xml",
        "-o",
        dir.path().join("x.jpg").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("error[E724]"));
    let rfs = dir.path().join("model.rfs");
    std::fs::write(&rfs, "Geom.dimension = 3;\n").expect("write");
    let out = geomc(&["render", rfs.to_str().unwrap(), "-o", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    // An .rfs program without a result function: the language's own code, at 1:1.
    assert!(String::from_utf8_lossy(&out.stderr).contains("error[E604]"));
    // A good .rfs model is polygonized and drawn: same bytes twice.
    let balls = dir.path().join("balls.png");
    let again = dir.path().join("balls2.png");
    for target in [&balls, &again] {
        let out = geomc(&[
            "render",
            "fixtures/rfs/seven_balls.rfs",
            "-o",
            target.to_str().unwrap(),
        ]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let bytes = std::fs::read(&balls).expect("picture written");
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(bytes, std::fs::read(&again).expect("second picture"));
    // A broken mesh file: the reader's own code, and no picture.
    let stl = dir.path().join("model.stl");
    std::fs::write(&stl, "solid x\nfacet normal 0 0 1\nouter loop\n").expect("write");
    let out = geomc(&["render", stl.to_str().unwrap(), "-o", bad.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("error[E5"));
    assert!(!bad.exists(), "no partial output");
}

#[test]
fn renders_a_mesh_file_like_the_domain_it_came_from() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let glb = dir.path().join("ball.glb");
    let out = geomc(&[
        "compile",
        "examples/ball_in_box.xml",
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let from_mesh = dir.path().join("from_mesh.png");
    let out = geomc(&[
        "render",
        glb.to_str().unwrap(),
        "-o",
        from_mesh.to_str().unwrap(),
        "--size",
        "160x120",
        "--no-legend",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let image = decode_png(&std::fs::read(&from_mesh).expect("written")).expect("a PNG");
    assert_eq!((image.width, image.height), (160, 120));
    // The box covers the middle of the picture; the corner is background.
    assert_ne!(image.pixel(80, 60), [255, 255, 255, 255]);
    assert_eq!(image.pixel(1, 1), [255, 255, 255, 255]);
}

#[test]
fn compile_writes_a_preview_in_the_same_run() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let msh = dir.path().join("ball.msh");
    let preview = dir.path().join("ball.png");
    let out = geomc(&[
        "compile",
        "examples/ball_in_box.xml",
        "-o",
        msh.to_str().unwrap(),
        "--preview",
        preview.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(msh.exists());
    let image = decode_png(&std::fs::read(&preview).expect("written")).expect("a PNG");
    assert_eq!((image.width, image.height), (800, 600));
    // The same picture as geomc render with its defaults.
    let direct = dir.path().join("direct.png");
    let out = geomc(&[
        "render",
        "examples/ball_in_box.xml",
        "-o",
        direct.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert_eq!(
        std::fs::read(&preview).unwrap(),
        std::fs::read(&direct).unwrap()
    );
}

/// The `d` of every filled section path: its loops as point lists.
fn section_paths(svg: &str) -> Vec<Vec<Vec<[f64; 2]>>> {
    svg.lines()
        .filter(|l| l.contains(r#"class="section""#))
        .map(|l| {
            let d = l
                .split(" d=\"")
                .nth(1)
                .expect("a d")
                .trim_end_matches("\"/>");
            d.split('Z')
                .filter(|lp| !lp.is_empty())
                .map(|lp| {
                    lp.split(['M', 'L'])
                        .filter(|p| !p.is_empty())
                        .map(|p| {
                            let (x, y) = p.split_once(' ').expect("x y");
                            [x.parse().expect("x"), y.parse().expect("y")]
                        })
                        .collect()
                })
                .collect()
        })
        .collect()
}

fn even_odd_area(loops: &[Vec<[f64; 2]>]) -> f64 {
    loops
        .iter()
        .map(|lp| {
            let n = lp.len();
            0.5 * (0..n)
                .map(|i| lp[i][0] * lp[(i + 1) % n][1] - lp[(i + 1) % n][0] * lp[i][1])
                .sum::<f64>()
        })
        .sum::<f64>()
}

#[test]
fn svg_section_fills_the_cut_face_of_each_subdomain() {
    let mesh = ball_in_box();
    let options = RenderOptions {
        section: Some(Section {
            axis: 2,
            value: 2.0,
        }),
        ..bare(400, 400, View::TOP)
    };
    let drawing = render_svg(&mesh, &options).expect("draws");
    let paths = section_paths(&drawing.text);
    // One filled path per subdomain: the matrix's square with the ball's
    // circle as a hole (two loops), the inclusion's disc (one loop).
    assert_eq!(paths.len(), 2);
    assert_eq!(paths.iter().map(|p| p.len()).collect::<Vec<_>>(), [2, 1]);
    assert_eq!(drawing.cut_faces.len(), 2);
    // Areas in square pixels against the exact cut (box 4×4, ball radius 1).
    let camera = render::camera_for(&mesh, &options);
    let k2 = camera.scale * camera.scale;
    let (matrix, inclusion) = (even_odd_area(&paths[0]), even_odd_area(&paths[1]));
    let disc = std::f64::consts::PI * k2;
    assert!(
        (inclusion - disc).abs() < 0.01 * disc,
        "{inclusion} vs {disc}"
    );
    let rest = 16.0 * k2 - disc;
    assert!((matrix - rest).abs() < 0.01 * rest, "{matrix} vs {rest}");
    // Loops come oriented by nesting: the hole runs against the outline.
    assert!((drawing.cut_faces[0].area() - matrix).abs() < 1.0);
    assert!((drawing.cut_faces[1].area() - inclusion).abs() < 1.0);
    // From below, the kept material hides the cut face: nothing is filled.
    let below = render_svg(
        &mesh,
        &RenderOptions {
            view: View {
                azimuth: 0.0,
                elevation: -90.0,
            },
            ..options.clone()
        },
    )
    .expect("draws");
    assert!(section_paths(&below.text).is_empty());
    // Without --section there is no fill.
    let plain = render_svg(&mesh, &bare(400, 400, View::TOP)).expect("draws");
    assert!(section_paths(&plain.text).is_empty());
}

#[test]
fn render_checks_implicit_grids_against_max_grid_cells() {
    let dir = tempfile::tempdir().expect("temporary folder");
    let xml = dir.path().join("ball.xml");
    std::fs::write(
        &xml,
        r#"<?xml version="1.0"?>
<geometry version="1">
<rfunction name="part" nx="20" ny="20" nz="20"> <ball r="0.5" x0="0" y0="0" z0="0"/> </rfunction>
<subdomain name="ball"> <solid ref="part"/> </subdomain>
</geometry>
"#,
    )
    .expect("write");
    let png = dir.path().join("ball.png");
    let (x, p) = (xml.to_str().unwrap(), png.to_str().unwrap());
    // 20³ = 8000 cells: one under the grid is refused, at the grid drawn.
    let out = geomc(&["render", x, "-o", p, "--max-grid-cells", "7999"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("error[E800]") && stderr.contains(":4:2:"),
        "{stderr}"
    );
    assert!(!png.exists(), "no partial output");
    let out = geomc(&["render", x, "-o", p, "--max-grid-cells", "8000"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let image =
        geomc::render::decode_png(&std::fs::read(&png).expect("PNG written")).expect("decodes");
    assert_eq!((image.width, image.height), (800, 600));
}
