//! Pictures of meshes without a GPU or system library: a z-buffered, shaded
//! PNG ([`render_png`]) and a vector SVG with hidden lines removed
//! ([`render_svg`]). Both use one orthographic [`Camera`] fitted to the model,
//! colour each boundary fragment (or subdomain) and name the colours in a
//! legend. Output is deterministic: the same mesh and options give the same
//! bytes for any number of threads.

mod bands;
mod camera;
mod font;
mod legend;
mod light;
mod normal_sum;
mod png_out;
mod project;
mod raster;
mod resolve;
mod resolve_unmarked;
mod scene;
mod section_fill;
mod shader;
mod smooth;
mod svg;
mod triangle;

pub use camera::{Camera, View};
pub use legend::LegendEntry;
pub use resolve::Image;
pub use scene::{Group, group_color};
pub use section_fill::CutFace;
pub use svg::SvgDrawing;

use crate::diag::Code;
use crate::mesh::Mesh;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Shading {
    Flat,
    #[default]
    Smooth,
}

/// What gets one colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ColorBy {
    /// Fragments when the mesh has face fragments, else subdomains, else faces.
    #[default]
    Auto,
    Fragment,
    Subdomain,
    Face,
}

/// Which edges are drawn: over the PNG, and as the SVG's lines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Edges {
    None,
    /// The model's edges (or sharp edges of a mesh without them) and silhouettes.
    Feature,
    /// Every triangle edge.
    All,
}

/// `AXIS=VALUE`: everything with a larger coordinate is cut away.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    pub axis: u8,
    pub value: f64,
}

impl Section {
    pub fn parse(text: &str) -> Result<Section, RenderError> {
        let bad = || RenderError::Section(text.to_string());
        let (axis, value) = text.split_once('=').ok_or_else(bad)?;
        let axis = match axis.trim().to_ascii_lowercase().as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return Err(bad()),
        };
        let value: f64 = value.trim().parse().map_err(|_| bad())?;
        if !value.is_finite() {
            return Err(bad());
        }
        Ok(Section { axis, value })
    }
}

/// Largest picture side accepted, in pixels.
pub const MAX_SIDE: u32 = 16384;

#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    pub view: View,
    pub shading: Shading,
    pub color_by: ColorBy,
    pub legend: bool,
    /// PNG overlay edges (default none); the SVG draws `Feature` when `None`.
    pub edges: Edges,
    /// Samples per pixel along each axis (1 = no anti-aliasing).
    pub antialias: u32,
    /// RGBA; alpha 0 gives a transparent background.
    pub background: [u8; 4],
    pub section: Option<Section>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 800,
            height: 600,
            view: View::ISO,
            shading: Shading::Smooth,
            color_by: ColorBy::Auto,
            legend: true,
            edges: Edges::None,
            antialias: 2,
            background: [255, 255, 255, 255],
            section: None,
        }
    }
}

/// Parses `WxH`.
pub fn parse_size(text: &str) -> Result<(u32, u32), RenderError> {
    let bad = || RenderError::Size(text.to_string());
    let (w, h) = text.trim().split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(bad());
    }
    Ok((w, h))
}

/// Parses `white`, `black`, `transparent` or `#rrggbb` / `#rrggbbaa`.
pub fn parse_background(text: &str) -> Result<[u8; 4], RenderError> {
    let t = text.trim().to_ascii_lowercase();
    match t.as_str() {
        "white" => return Ok([255, 255, 255, 255]),
        "black" => return Ok([0, 0, 0, 255]),
        "transparent" | "none" => return Ok([255, 255, 255, 0]),
        _ => {}
    }
    let bad = || RenderError::Background(text.to_string());
    let hex = t.strip_prefix('#').ok_or_else(bad)?;
    if !(hex.len() == 6 || hex.len() == 8) || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
        return Err(bad());
    }
    let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).map_err(|_| bad());
    Ok([
        byte(0)?,
        byte(2)?,
        byte(4)?,
        if hex.len() == 8 { byte(6)? } else { 255 },
    ])
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RenderError {
    #[error("--size {0}: give WIDTHxHEIGHT in pixels, each 1 to {MAX_SIDE} (e.g. 1024x768)")]
    Size(String),
    #[error(
        "--view {0}: give front, top, iso, or AZIMUTH,ELEVATION in degrees with the elevation in [-90, 90] (e.g. 30,20)"
    )]
    View(String),
    #[error("--section {0}: give AXIS=VALUE with AXIS x, y or z (e.g. z=0)")]
    Section(String),
    #[error("--background {0}: give white, black, transparent, or #rrggbb")]
    Background(String),
    #[error("--antialias {0}: give 1 (none) to 4 samples per pixel along each axis")]
    Antialias(u32),
    #[error("nothing to draw: the mesh has no triangles")]
    Empty,
    #[error("the picture would need {0} samples; lower --size or --antialias")]
    TooLarge(u64),
}

impl RenderError {
    pub fn code(&self) -> Code {
        match self {
            RenderError::Size(_) => Code::RenderBadSize,
            RenderError::View(_) => Code::RenderBadView,
            RenderError::Section(_) => Code::RenderBadSection,
            RenderError::Background(_) => Code::RenderBadBackground,
            RenderError::Antialias(_) => Code::RenderBadAntialias,
            RenderError::Empty => Code::RenderNothingToDraw,
            RenderError::TooLarge(_) => Code::RenderTooLarge,
        }
    }
}

/// Something the picture could not show, reported as a warning.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RenderWarning {
    pub code: Code,
    pub message: String,
}

/// A rendered picture and what it shows.
#[derive(Debug, Clone)]
pub struct Rendered {
    pub image: Image,
    pub camera: Camera,
    pub groups: Vec<Group>,
    pub legend: Vec<LegendEntry>,
    pub warnings: Vec<RenderWarning>,
}

/// Most samples in one picture (about 1 GB of depth buffer).
const MAX_SAMPLES: u64 = 1 << 27;

fn check(mesh: &Mesh, options: &RenderOptions) -> Result<(), RenderError> {
    if options.width == 0
        || options.height == 0
        || options.width > MAX_SIDE
        || options.height > MAX_SIDE
    {
        return Err(RenderError::Size(format!(
            "{}x{}",
            options.width, options.height
        )));
    }
    if !(1..=4).contains(&options.antialias) {
        return Err(RenderError::Antialias(options.antialias));
    }
    let samples = options.width as u64 * options.height as u64 * (options.antialias as u64).pow(2);
    if samples > MAX_SAMPLES {
        return Err(RenderError::TooLarge(samples));
    }
    if mesh.faces.iter().all(|f| f.triangles.is_empty()) {
        return Err(RenderError::Empty);
    }
    Ok(())
}

/// The camera for a mesh: fitted to its nodes as seen from the view.
pub fn camera_for(mesh: &Mesh, options: &RenderOptions) -> Camera {
    Camera::fit(options.view, &mesh.nodes, options.width, options.height)
}

fn section_warning(scene: &scene::Scene, options: &RenderOptions) -> Option<RenderWarning> {
    let s = options.section?;
    scene.tris.is_empty().then(|| RenderWarning {
        code: Code::RenderSectionEmpty,
        message: format!(
            "--section {}={}: the whole model lies beyond the plane, so nothing is left to draw; pick a value inside the model's extent",
            ["x", "y", "z"][s.axis as usize],
            s.value
        ),
    })
}

/// Renders the shaded raster picture.
pub fn render_image(mesh: &Mesh, options: &RenderOptions) -> Result<Rendered, RenderError> {
    check(mesh, options)?;
    let (camera, depths) =
        Camera::fit_with_depths(options.view, &mesh.nodes, options.width, options.height);
    let scene = scene::build(mesh, options, &camera);
    let mut warnings: Vec<RenderWarning> = section_warning(&scene, options).into_iter().collect();
    let ss = options.antialias as usize;
    // Without an edge overlay, shading reads a node's position and light
    // from one record when the nodes are the light slots.
    let light = (options.edges == Edges::None).then(|| scene.node_light());
    let proj = project::project(&scene.points, &camera, ss, Some(&depths), light.flatten());
    let (sw, sh) = (options.width as usize * ss, options.height as usize * ss);
    let mut image = if options.edges == Edges::None {
        let (w, h) = (options.width as usize, options.height as usize);
        bands::render(&scene, &proj, w, h, ss, options.background)
    } else {
        let zbuf = raster::rasterize(&scene, &proj, sw, sh);
        let mut mask = vec![false; sw * sh];
        let on_plane = |n: u32| {
            options
                .section
                .is_some_and(|s| scene.points[n as usize][s.axis as usize] == s.value)
        };
        let segments: Vec<([[f32; 3]; 2], bool)> =
            svg::edge_segments(mesh, &scene, &camera, options.edges)
                .into_iter()
                .map(|(a, b, _)| {
                    (
                        [a, b].map(|n| sample_point(&proj, n)),
                        on_plane(a) && on_plane(b),
                    )
                })
                .collect();
        let is_cap = |value: u64| {
            let id = value & 0xffff_ffff;
            scene.groups[scene.side_group((id >> 1) as usize, (id & 1) as usize) as usize].cap
        };
        raster::mark_edges(&zbuf, &segments, 0.75 * ss as f32, 0.01, is_cap, &mut mask);
        resolve::resolve(&scene, &proj, &zbuf, &mask, ss, options.background)
    };
    let mut entries = Vec::new();
    if options.legend {
        let (e, not_shown) = legend::layout(&scene.groups, options.width, options.height);
        legend::draw(&mut image, &e, not_shown);
        if not_shown > 0 {
            warnings.push(RenderWarning {
                code: Code::RenderLegendTruncated,
                message: format!(
                    "the legend shows {} of {} colour groups; the picture is too short for the rest (raise the height with --size, or colour by subdomain with --color-by subdomain)",
                    e.len(),
                    scene.groups.len()
                ),
            });
        }
        entries = e;
    }
    Ok(Rendered {
        image,
        camera,
        groups: scene.groups,
        legend: entries,
        warnings,
    })
}

fn sample_point(proj: &raster::Projected, node: u32) -> [f32; 3] {
    let p = proj.xy_f[node as usize];
    [p[0], p[1], proj.snapped[node as usize].z]
}

/// Renders and encodes a PNG.
pub fn render_png(
    mesh: &Mesh,
    options: &RenderOptions,
) -> Result<(Vec<u8>, Vec<RenderWarning>), RenderError> {
    let rendered = render_image(mesh, options)?;
    Ok((png_out::encode(&rendered.image), rendered.warnings))
}

/// Decodes a PNG written by [`render_png`] (for tests and tools).
pub fn decode_png(bytes: &[u8]) -> Option<Image> {
    png_out::decode(bytes)
}

pub use svg::render_svg;
