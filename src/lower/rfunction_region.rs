//! 2D R-function regions (issue 6): in a `dimension="2"` model an implicit
//! subdomain (`<rfunction>`, `<level_surface>`) is the region f(x, y, 0) ≥ 0
//! inside its box. Its zero contour is traced by marching squares on the
//! rfunction's nx × ny grid (paper 002's boundary stage, reused from
//! `trimmed::boundary`: ambiguous cells split in four, crossings found by
//! root finding), short pieces merged, and chords split until they are within
//! half the default chordal tolerance of the curve, each new point placed on
//! f = 0. The contour becomes ordinary model entities — a vertex per contour
//! point, straight edges between them, one planar face and a 2D subdomain —
//! so the 2D mesher (minimum angle, area limits, size field, poly_line
//! constraints, cracks) and the fragments (`NAME|exterior`, interfaces)
//! treat it like any kernel region.

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::geom::Frame;
use crate::geom::{Curve, Point3, Surface, Vec3};
use crate::implicit::ImplicitModel;
use crate::implicit::ir::Ctx;
use crate::implicit::tape::Ssa;
use crate::implicit::xml::{ImplicitSolid, ImplicitSubdomain};
use crate::ir::{
    Edge, EdgeId, Face, FaceId, Model, OrientedEdge, Subdomain, SubdomainCells, SubdomainId,
    Vertex, VertexId,
};
use crate::ir::{Origin, SourceMap};
use crate::trimmed::boundary::{self, Boundary};
use crate::trimmed::{Carrier, Trim, TrimmedSurface};

/// The chordal tolerance of a traced contour, as a fraction of its box's
/// diagonal: half the mesher's default (1e-3), as for model edges.
const CHORD_FRACTION: f64 = 0.5e-3;

/// Moves every function subdomain of `implicit` into `model` as a 2D region;
/// density volumes are E542 and stay out of both.
pub fn add_regions(
    model: &mut Model,
    source_map: &mut SourceMap,
    implicit: &mut Vec<ImplicitSubdomain>,
    diags: &mut Diagnostics,
) {
    for sub in std::mem::take(implicit) {
        match &sub.solid {
            ImplicitSolid::Function(f) => add_region(model, source_map, &sub, f, diags),
            ImplicitSolid::Samples { .. } => diags.push(Diagnostic::new(
                Code::RegionNotFunction,
                sub.span,
                format!(
                    "subdomain '{}' is a density volume, which has no region in a 2D model",
                    sub.name
                ),
            )),
        }
    }
    model.tolerance = (1e-6 * model.bbox().diagonal()).max(1e-12);
}

/// The region {f(x, y, 0) ≥ 0} of `f`'s box as a planar surface trimmed by f.
pub fn region_surface(name: &str, f: &ImplicitModel) -> TrimmedSurface {
    let mut ctx = Ctx::new();
    let (u, v, zero) = (ctx.var(0), ctx.var(1), ctx.constant(0.0));
    let xyz = [
        Ssa::from_ctx(&ctx, u),
        Ssa::from_ctx(&ctx, v),
        Ssa::from_ctx(&ctx, zero),
    ];
    TrimmedSurface {
        name: name.to_string(),
        carrier: Carrier::Expressions { xyz: Box::new(xyz) },
        frame: Frame::identity(),
        rect: [f.geom.min[0], f.geom.max[0], f.geom.min[1], f.geom.max[1]],
        trim: Some(Trim::new(&f.ctx, f.root, false)),
    }
}

/// Closed loops of points (x, y); the last joins the first.
pub type Loops = Vec<Vec<[f64; 2]>>;

/// The region's boundary loops in (x, y), each with the region on its left
/// (outer loops counter-clockwise, holes clockwise), and whether the box
/// cuts the region.
pub fn trace(f: &ImplicitModel, s: &TrimmedSurface) -> Result<(Loops, bool), String> {
    let (loops, cut) = trace_with_sides(f, s)?;
    Ok((loops.into_iter().map(|(points, _)| points).collect(), cut))
}

/// A closed loop of points (x, y), each with its box-side flags (0 on
/// f = 0, else the sides of the box it lies on).
type SidedLoop = (Vec<[f64; 2]>, Vec<u8>);

/// [`trace`], each point with its box-side flags.
fn trace_with_sides(
    f: &ImplicitModel,
    s: &TrimmedSurface,
) -> Result<(Vec<SidedLoop>, bool), String> {
    let [nx, ny] = [f.geom.cells[0], f.geom.cells[1]];
    let mut b: Boundary = boundary::trace(s, [nx, ny])?;
    let [x0, x1, y0, y1] = s.rect;
    let (dx, dy) = ((x1 - x0) / nx as f64, (y1 - y0) / ny as f64);
    // Paper 002: drop contour points closer than 40% of a cell diagonal
    // (crossings next to a grid node); the chord refinement puts back what
    // the tolerance needs.
    b.merge_short(s, 0.4 * dx.hypot(dy));
    let tolerance = CHORD_FRACTION * (x1 - x0).hypot(y1 - y0);
    b.refine_chords(s, tolerance, f64::INFINITY);
    let cut = b.loops.iter().flatten().any(|&p| b.sides[p] != 0);
    let min_area = (1e-6 * (x1 - x0).hypot(y1 - y0)).powi(2);
    let loops = b
        .loops
        .iter()
        .map(|lp| {
            let mut points: Vec<[f64; 2]> = lp.iter().map(|&p| b.points[p]).collect();
            let sides: Vec<u8> = lp.iter().map(|&p| b.sides[p]).collect();
            let mut sides = grade(s, &mut points, sides);
            // Straight stretches laid out graded from their ends (within
            // the bound by construction), not cut to the shortest piece.
            let straight = super::contour_straight::STRAIGHT_FRACTION * (x1 - x0).hypot(y1 - y0);
            super::contour_straight::merge_straight_runs(s, &mut points, &mut sides, straight);
            if !material_on_left(s, &points) {
                points.reverse();
                sides.reverse();
            }
            (points, sides)
        })
        // A loop without area (f ≥ 0 only on a point or a line, where f
        // touches zero from below) bounds nothing.
        .filter(|(points, _): &SidedLoop| shoelace(points).abs() > min_area)
        .collect();
    Ok((loops, cut))
}

/// Twice the signed area of a closed polygon.
fn shoelace(points: &[[f64; 2]]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|k| {
            let (a, b) = (points[k], points[(k + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum()
}

/// Most length ratio of neighbouring contour segments after [`grade`].
const GRADING: f64 = 1.5;

/// Splits contour segments (at the middle, moved onto f = 0 or kept on the
/// box side) until none is more than [`GRADING`] times as long as a
/// neighbour. Ruppert refinement splits a boundary segment next to a much
/// shorter one anyway, and each such split costs the 2D mesher a round of
/// re-meshing (at most 8, after which the angle bound may fail): graded
/// contours leave it nothing to split.
fn grade(s: &TrimmedSurface, points: &mut Vec<[f64; 2]>, mut sides: Vec<u8>) -> Vec<u8> {
    let len = |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]).hypot(b[1] - a[1]);
    // Each pass halves segments; 40 passes cover any ratio a grid gives.
    for _ in 0..40 {
        let n = points.len();
        let lengths: Vec<f64> = (0..n)
            .map(|k| len(points[k], points[(k + 1) % n]))
            .collect();
        let mut out = Vec::with_capacity(2 * n);
        let mut out_sides = Vec::with_capacity(2 * n);
        let mut split = false;
        for k in 0..n {
            out.push(points[k]);
            out_sides.push(sides[k]);
            let shortest = lengths[(k + n - 1) % n].min(lengths[(k + 1) % n]);
            if lengths[k] > GRADING * shortest {
                let (a, b) = (points[k], points[(k + 1) % n]);
                let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
                let common = sides[k] & sides[(k + 1) % n];
                out.push(if common != 0 {
                    mid
                } else {
                    boundary::project(s, mid, a, b)
                });
                out_sides.push(common);
                split = true;
            }
        }
        *points = out;
        sides = out_sides;
        if !split {
            break;
        }
    }
    sides
}

/// Whether the region lies on the left of the loop, judged across its
/// longest segment.
fn material_on_left(s: &TrimmedSurface, points: &[[f64; 2]]) -> bool {
    let n = points.len();
    let Some(k) = (0..n).max_by(|&i, &j| {
        let len = |k: usize| {
            let (a, b) = (points[k], points[(k + 1) % n]);
            (b[0] - a[0]).hypot(b[1] - a[1])
        };
        len(i).total_cmp(&len(j))
    }) else {
        return true;
    };
    let (a, b) = (points[k], points[(k + 1) % n]);
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let m = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
    // A step a tenth of the segment across it, to either side.
    let left = s.material(m[0] - 0.1 * dy, m[1] + 0.1 * dx);
    let right = s.material(m[0] + 0.1 * dy, m[1] - 0.1 * dx);
    if left.is_nan() || right.is_nan() {
        return true;
    }
    left >= right
}

fn add_region(
    model: &mut Model,
    source_map: &mut SourceMap,
    sub: &ImplicitSubdomain,
    f: &ImplicitModel,
    diags: &mut Diagnostics,
) {
    let surface = region_surface(&sub.name, f);
    let (loops, cut) =
        match trace_with_sides(f, &surface) {
            Ok(traced) => traced,
            Err(reason) => {
                diags.push(
                Diagnostic::new(
                    Code::RegionContour,
                    sub.span,
                    format!("the boundary of region '{}' cannot be traced: {reason}", sub.name),
                )
                .with_help(format!(
                    "use more cells than nx = {}, ny = {}, or keep the pieces of the region apart",
                    f.geom.cells[0], f.geom.cells[1]
                )),
            );
                return;
            }
        };
    if loops.is_empty() {
        diags.push(
            Diagnostic::new(
                Code::RegionEmpty,
                sub.span,
                format!(
                    "region '{}' has no area where f >= 0 on its grid over x {}..{}, y {}..{}",
                    sub.name, f.geom.min[0], f.geom.max[0], f.geom.min[1], f.geom.max[1]
                ),
            )
            .with_help("check x_min..y_max against where the region lies, or use more cells"),
        );
        return;
    }
    if cut {
        diags.push(Diagnostic::new(
            Code::RegionCutByBox,
            sub.span,
            format!(
                "region '{}' reaches the sides of its box x {}..{}, y {}..{}: they bound it there",
                sub.name, f.geom.min[0], f.geom.max[0], f.geom.min[1], f.geom.max[1]
            ),
        ));
    }
    let origin = Origin { span: sub.span };
    // Each contour piece carries f, so splits by refinement land on f = 0.
    let contour = f.ssa();
    let mut face_loops = Vec::with_capacity(loops.len());
    for (l, (points, sides)) in loops.iter().enumerate() {
        let first = model.vertices.len();
        for (k, p) in points.iter().enumerate() {
            let id = VertexId(model.vertices.len() as u32);
            model.vertices.push(Vertex {
                name: format!("{}.contour[{}].v{}", sub.name, l + 1, k + 1).into(),
                position: Point3::new(p[0], p[1], 0.0),
            });
            source_map.vertices.insert(id, origin);
        }
        let n = points.len();
        let mut lp = Vec::with_capacity(n);
        for k in 0..n {
            let (a, b) = (first + k, first + (k + 1) % n);
            let id = EdgeId(model.edges.len() as u32);
            let (pa, pb) = (model.vertices[a].position, model.vertices[b].position);
            // A piece along a side of the box is straight: a split stays on
            // the side (f = 0 may be near, but it is not this edge).
            let curve = if sides[k] & sides[(k + 1) % n] != 0 {
                Curve::Segment { a: pa, b: pb }
            } else {
                Curve::Contour {
                    a: pa,
                    b: pb,
                    f: Box::new(contour.clone()),
                }
            };
            model.edges.push(Edge {
                name: format!("{}.contour[{}].e{}", sub.name, l + 1, k + 1).into(),
                carrier: crate::ir::Carrier::own(curve),
                begin: VertexId(a as u32),
                end: VertexId(b as u32),
            });
            source_map.edges.insert(id, origin);
            lp.push(OrientedEdge {
                edge: id,
                forward: true,
            });
        }
        face_loops.push(lp);
    }
    let face = FaceId(model.faces.len() as u32);
    model.faces.push(Face {
        name: format!("{}.region", sub.name).into(),
        carrier: crate::ir::Carrier::own(Surface::Plane {
            origin: Point3::origin(),
            normal: Vec3::z(),
        }),
        reversed: false,
        loops: face_loops.into(),
    });
    source_map.faces.insert(face, origin);
    let id = SubdomainId(model.subdomains.len() as u32);
    model.subdomains.push(Subdomain {
        name: sub.name.clone(),
        material: sub.material.clone(),
        cells: SubdomainCells::Region { faces: vec![face] },
        max_area: sub.max_area,
        ..Default::default()
    });
    source_map.subdomains.insert(id, origin);
}
