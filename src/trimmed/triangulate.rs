//! Stages 2 and 3 of paper 002: a constrained Delaunay triangulation of the
//! boundary loops in parameter space (a chart scaled so lengths roughly match
//! 3D), then refinement by 3D criteria: a triangle is split while its
//! smallest angle measured on the surface is below the threshold or the
//! surface leaves it by more than the tolerance (the chord-to-arc control).
//! The point inserted is the parameter point whose surface point is nearest
//! the triangle's 3D circumcentre E3 (minimising |R(u, v) − E3|).

use super::TrimmedSurface;
use super::boundary::{self, U_MAX, V_MAX};
use super::chart::ArcChart;
use super::pole;
use super::shared;
use super::split::{Cdt, Nodes, SEAM, split_constraint};
use crate::geom::{Point3, Vec3};
use spade::{AngleLimit, Point2, RefinementParameters, Triangulation};
use std::collections::{HashMap, HashSet};

/// Refinement rounds before the result is taken as it is.
const MAX_PASSES: usize = 40;
/// A triangle is split while its 3D circumradius exceeds this many
/// requested edge lengths (an equilateral triangle of side L has 0.577 L).
const SIZE_RADIUS: f64 = 0.8;
/// Nodes one trimmed surface may have.
const MAX_VERTICES: usize = 4_000_000;

/// The mesh of one trimmed surface.
#[derive(Debug, Clone, Default)]
pub struct TrimmedMesh {
    pub nodes: Vec<Point3>,
    pub uv: Vec<[f64; 2]>,
    /// Counter-clockwise about R_u × R_v.
    pub triangles: Vec<[u32; 3]>,
    /// Boundary chains: trim curves and patch sides (a closed chain repeats
    /// its first node at the end). Sides joined by a periodic seam are not
    /// boundary.
    pub boundary: Vec<Vec<u32>>,
    /// Per boundary chain: true when it is a closed trim loop (no point on a
    /// patch side), which can take the nodes of a chain it coincides with.
    pub trim_loop: Vec<bool>,
    /// Nodes taken from shared chains: (node, chain, index in the chain).
    pub shared: Vec<(u32, usize, usize)>,
}

/// How finely to mesh.
#[derive(Debug, Clone, Copy)]
pub struct TrimSettings {
    pub tolerance: f64,
    pub min_angle: f64,
    pub max_edge: f64,
}

pub fn mesh_trimmed(s: &TrimmedSurface, settings: TrimSettings) -> Result<TrimmedMesh, String> {
    mesh_trimmed_shared(s, settings, &[])
}

/// As [`mesh_trimmed`], with each closed trim loop that coincides (within
/// twice the tolerance) with a closed chain of `chains` meshed on that
/// chain's nodes (`shared.rs`).
pub fn mesh_trimmed_shared(
    s: &TrimmedSurface,
    settings: TrimSettings,
    chains: &[Vec<Point3>],
) -> Result<TrimmedMesh, String> {
    let [u0, u1, v0, v1] = s.rect;
    if !(u1 > u0 && v1 > v0) {
        return Err(format!(
            "the parameter rectangle [{u0}, {u1}] × [{v0}, {v1}] is empty"
        ));
    }
    if pole::has_v_pole(s) {
        // Poles are capped on sides u = const: mesh the transpose, then
        // turn its parameters, triangles and chains back.
        let t = s.transposed();
        if pole::has_v_pole(&t) {
            return Err(format!(
                "sides u = const and v = const of the parameter rectangle [{u0}, {u1}] × \
                 [{v0}, {v1}] are both single points (poles); poles are supported along one \
                 parameter only: split the rectangle so that each part has its poles on sides \
                 of one kind"
            ));
        }
        let mut m = mesh_trimmed_shared(&t, settings, chains)?;
        m.uv.iter_mut().for_each(|uv| uv.swap(0, 1));
        m.triangles.iter_mut().for_each(|t| t.swap(1, 2));
        m.boundary.iter_mut().for_each(|c| c.reverse());
        return Ok(m);
    }
    let arc = ArcChart::new(s)?;
    let (lu, lv) = arc.lengths();
    let h = element_size(lu, lv, &settings);
    let caps = pole::plan(s, &settings, h)?;
    if caps.is_empty() {
        return mesh_band(s, settings, &[], chains);
    }
    let mut band = s.clone();
    for c in &caps {
        band.rect[c.side_index()] = c.u_ring;
    }
    let mut mesh = mesh_band(&band, settings, &caps, chains)?;
    for c in caps.iter().filter(|c| c.material) {
        pole::close(&mut mesh, s, c);
    }
    // A cap changes the side chains: only closed trim loops stay sharable.
    if mesh.trim_loop.len() != mesh.boundary.len() {
        mesh.trim_loop = vec![false; mesh.boundary.len()];
    }
    Ok(mesh)
}

/// The element size: the smaller of `--max-edge` and the length whose chord
/// on a bend of radius ~extent/2 deviates by the tolerance (h²/(4·extent)).
pub(super) fn element_size(lu: f64, lv: f64, settings: &TrimSettings) -> f64 {
    let extent = lu.hypot(lv);
    (4.0 * extent * settings.tolerance)
        .sqrt()
        .min(extent / 48.0)
        .min(settings.max_edge)
}

/// Meshes the rectangle of `s`; the sides of `caps` with material become
/// fixed rings of their caps' segments.
fn mesh_band(
    s: &TrimmedSurface,
    settings: TrimSettings,
    caps: &[pole::Cap],
    chains: &[Vec<Point3>],
) -> Result<TrimmedMesh, String> {
    let arc = ArcChart::new(s)?;
    let (lu, lv) = arc.lengths();
    let extent = lu.hypot(lv);
    let tol = settings.tolerance;
    let h = element_size(lu, lv, &settings);
    let nu = ((lu / h).ceil() as usize).clamp(4, 2048);
    let nv = ((lv / h).ceil() as usize).clamp(4, 2048);
    let mut b = boundary::trace(s, [nu, nv])?;
    let cell = (lu / nu as f64).hypot(lv / nv as f64);
    b.merge_short(s, 0.4 * cell);
    let periodic = [is_periodic(s, 0, extent), is_periodic(s, 1, extent)];
    let seams = (0..2)
        .filter(|&a| periodic[a])
        .fold(0, |bits, a| bits | SEAM[a]);
    for c in caps.iter().filter(|c| c.material) {
        b.fix_ring(c.bit, c.u_ring, [s.rect[2], s.rect[3]], c.segments);
    }
    // Boundary edges start at the element size; refinement splits them
    // (a seam edge with its twin) where they are encroached.
    let side = h.max(0.5 * cell);
    b.refine_chords(s, 0.5 * tol, side);
    let shared = shared::share_loops(s, &mut b, chains, 2.0 * tol);
    if b.loops.is_empty() {
        return Err("the trim leaves no material on the surface".into());
    }
    let chart = |uv: [f64; 2]| {
        let c = arc.to_chart(uv);
        Point2::new(c[0], c[1])
    };
    let mut cdt = Cdt::new();
    let mut handles = vec![usize::MAX; b.points.len()];
    let mut nodes = Nodes {
        uv: Vec::new(),
        xyz: Vec::new(),
        sides: Vec::new(),
        twin: [HashMap::new(), HashMap::new()],
        fixed: 0,
    };
    for lp in &b.loops {
        for &p in lp {
            if handles[p] != usize::MAX {
                continue;
            }
            let h = cdt
                .insert(chart(b.points[p]))
                .map_err(|e| format!("a boundary point cannot be triangulated: {e:?}"))?;
            if h.index() == nodes.uv.len() {
                nodes.uv.push(b.points[p]);
            }
            handles[p] = h.index();
        }
    }
    for lp in &b.loops {
        for k in 0..lp.len() {
            let (x, y) = (handles[lp[k]], handles[lp[(k + 1) % lp.len()]]);
            if x == y {
                continue;
            }
            let (hx, hy) = (
                spade::handles::FixedVertexHandle::from_index(x),
                spade::handles::FixedVertexHandle::from_index(y),
            );
            if !cdt.can_add_constraint(hx, hy) {
                return Err("the trim curve crosses itself or a side of the patch".into());
            }
            cdt.add_constraint(hx, hy);
        }
    }
    nodes.xyz = nodes.uv.iter().map(|p| s.point(p[0], p[1])).collect();
    nodes.mark_boundary(&b, &handles, periodic, s.rect);
    // Spade stops after this many insertions (triangles of side ~h cover the
    // surface about 2·area/h² times over; room for grading near the trim).
    let budget = ((8.0 * lu * lv / (h * h)) as usize + 4 * nodes.uv.len() + 1000).min(MAX_VERTICES);
    // Spade refines by angle in the chart and never splits a constraint
    // edge: boundary splits are made here, on the true boundary (split.rs).
    let params = RefinementParameters::<f64>::new()
        .exclude_outer_faces(true)
        .with_angle_limit(AngleLimit::from_deg((settings.min_angle + 3.0).min(30.0)))
        .with_max_additional_vertices(budget)
        .keep_constraint_edges();
    let mut inner: Vec<[usize; 3]> = Vec::new();
    // Triangles this small are left as they are, and boundary edges this
    // short are not split: the guard that ends refinement at an input angle
    // smaller than the threshold (Ruppert's corner cascade). A tenth of the
    // tolerance, so no triangle of the size the tolerance asks for is left.
    let floor = (0.002 * h).min(0.1 * tol);
    let fixed = nodes.uv.len();
    // Triangles found fine stay fine while they exist (their nodes and
    // the criteria do not change): they are not measured again.
    let mut fine: HashSet<[usize; 3]> = HashSet::new();
    for pass in 0..=MAX_PASSES {
        let last = pass == MAX_PASSES;
        let round = if last {
            params.clone().with_max_additional_vertices(0)
        } else {
            params.clone()
        };
        let result = cdt.refine(round);
        nodes.sync(&cdt, &arc, s);
        let mut excluded = vec![false; cdt.num_all_faces()];
        for f in &result.excluded_faces {
            if let Some(slot) = excluded.get_mut(f.index()) {
                *slot = true;
            }
        }
        inner.clear();
        let mut actions: Vec<Action> = Vec::new();
        for f in cdt.inner_faces() {
            if excluded.get(f.fix().index()).copied().unwrap_or(true) {
                continue;
            }
            let t = f.vertices().map(|v| v.fix().index());
            inner.push(t);
            if last {
                continue;
            }
            let mut key = t;
            key.sort_unstable();
            if fine.contains(&key) {
                continue;
            }
            let p = t.map(|i| nodes.xyz[i]);
            let q = t.map(|i| nodes.uv[i]);
            let constraints: Vec<(usize, usize)> = f
                .adjacent_edges()
                .iter()
                .filter(|e| cdt.is_constraint_edge(e.as_undirected().fix()))
                .map(|e| (e.from().fix().index(), e.to().fix().index()))
                .collect();
            // A seam is no boundary on the surface: its edges make no angle.
            let on_seam = |&(a, b): &(usize, usize)| nodes.sides[a] & nodes.sides[b] & seams != 0;
            let walls: Vec<(usize, usize)> = constraints
                .iter()
                .copied()
                .filter(|e| !on_seam(e))
                .collect();
            let angles = !input_corner(&walls, &t, &p, &nodes, settings.min_angle);
            match needs_split(s, &arc, &p, &q, &settings, floor, angles) {
                Some(mut split) => {
                    split.corners = t;
                    if let Some(a) = choose(&cdt, &arc, &nodes, split, &constraints, t[0], floor) {
                        actions.push(a);
                    }
                }
                None => {
                    fine.insert(key);
                }
            }
        }
        if actions.is_empty() {
            break;
        }
        if cdt.num_vertices() + actions.len() > MAX_VERTICES {
            return Err(format!(
                "it needs more than {MAX_VERTICES} nodes for the tolerance"
            ));
        }
        for a in actions {
            match a {
                Action::Split(x, y) => {
                    split_constraint(&mut cdt, &arc, s, &mut nodes, x, y);
                }
                Action::Insert { uv, hint, spacing } => {
                    if !clear(&cdt, chart(uv), hint, spacing) {
                        continue;
                    }
                    let h = cdt
                        .insert_with_hint(chart(uv), hint)
                        .map_err(|e| format!("a refinement point cannot be inserted: {e:?}"))?;
                    if h.index() == nodes.uv.len() {
                        nodes.uv.push(uv);
                        nodes.xyz.push(s.point(uv[0], uv[1]));
                        nodes.sides.push(0);
                    }
                }
            }
        }
    }
    let mut boundary_chains: Vec<Vec<usize>> = b
        .loops
        .iter()
        .map(|lp| {
            let mut c: Vec<usize> = lp.iter().map(|&p| handles[p]).collect();
            c.dedup();
            c.push(c[0]);
            c
        })
        .collect();
    thread_splits(&cdt, fixed, &mut boundary_chains);
    let mut remap: Vec<usize> = (0..nodes.uv.len()).collect();
    if periodic.contains(&true) {
        weld_seams(&nodes, periodic, &mut remap, &mut boundary_chains);
    }
    let trim_loop: Vec<bool> = boundary_chains
        .iter()
        .map(|c| c.iter().all(|&h| nodes.sides[h] & !shared::SHARED == 0))
        .collect();
    let shared: Vec<(usize, usize, usize)> =
        shared.iter().map(|&(p, c, i)| (handles[p], c, i)).collect();
    let (uvs, points3) = (nodes.uv, nodes.xyz);
    let mut mesh = assemble(&uvs, &points3, &inner, &remap, &boundary_chains, &shared);
    mesh.trim_loop = trim_loop;
    Ok(mesh)
}

/// True when the two sides across parameter `axis` (0: u = u_min and
/// u = u_max; 1: v = v_min and v = v_max) are the same curve in 3D.
pub(super) fn is_periodic(s: &TrimmedSurface, axis: usize, extent: f64) -> bool {
    let r = s.rect;
    let (lo, hi) = (r[2 * axis], r[2 * axis + 1]);
    let (a, b) = (r[2 - 2 * axis], r[3 - 2 * axis]);
    (0..=8).all(|i| {
        let t = a + (b - a) * i as f64 / 8.0;
        let (p, q) = if axis == 0 {
            (s.point(lo, t), s.point(hi, t))
        } else {
            (s.point(t, lo), s.point(t, hi))
        };
        (p - q).norm() <= 1e-9 * extent
    })
}

/// Where a triangle that is too coarse or too skinny on the surface would be
/// split.
struct Split {
    /// The parameter point nearest the 3D circumcentre, when it is in the
    /// material and near the triangle (else a boundary edge must be split).
    circumcentre: Option<[f64; 2]>,
    centroid: [f64; 2],
    triangle: [[f64; 2]; 3],
    /// The triangle's vertices.
    corners: [usize; 3],
}

/// What one refinement step does.
enum Action {
    Split(usize, usize),
    Insert {
        uv: [f64; 2],
        hint: spade::handles::FixedVertexHandle,
        spacing: f64,
    },
}

/// `None` when the triangle is fine: small enough for the size (its 3D
/// circumradius at most SIZE_RADIUS × max_edge, so the triangles come out
/// with edges near max_edge, as other meshers make them), close enough to
/// the surface, and with its angles above the threshold.
fn needs_split(
    s: &TrimmedSurface,
    arc: &ArcChart,
    p: &[Point3; 3],
    q: &[[f64; 2]; 3],
    settings: &TrimSettings,
    floor: f64,
    angles: bool,
) -> Option<Split> {
    let edges = [p[1] - p[0], p[2] - p[1], p[0] - p[2]];
    let lengths = edges.map(|e| e.norm());
    let longest = lengths.iter().cloned().fold(0.0, f64::max);
    if longest <= floor {
        return None;
    }
    let centroid_uv = [
        (q[0][0] + q[1][0] + q[2][0]) / 3.0,
        (q[0][1] + q[1][1] + q[2][1]) / 3.0,
    ];
    let centroid = Point3::from((p[0].coords + p[1].coords + p[2].coords) / 3.0);
    let circle = circumcentre(p);
    let radius = circle.map_or(f64::INFINITY, |c| (c - p[0]).norm());
    let on_surface = s.point(centroid_uv[0], centroid_uv[1]);
    let mut coarse = (on_surface - centroid).norm() > settings.tolerance
        || radius > SIZE_RADIUS * settings.max_edge;
    if !coarse {
        for k in 0..3 {
            let (a, b) = (q[k], q[(k + 1) % 3]);
            let m = s.point((a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0);
            let chord = Point3::from((p[k].coords + p[(k + 1) % 3].coords) / 2.0);
            if (m - chord).norm() > settings.tolerance {
                coarse = true;
                break;
            }
        }
    }
    let skinny = angles && min_angle(p) < settings.min_angle;
    if !(coarse || skinny) {
        return None;
    }
    let inside = |uv: [f64; 2]| {
        let [u0, u1, v0, v1] = s.rect;
        uv[0] > u0 && uv[0] < u1 && uv[1] > v0 && uv[1] < v1 && s.material(uv[0], uv[1]) >= 0.0
    };
    // Far from the triangle (beyond twice its size) or out of the material,
    // the circumcentre is not usable. Distances are measured in the chart,
    // not in (u, v): u and v may have different units (a cone's height and
    // angle), and a (u, v) measure called an obtuse triangle's circumcentre
    // across its long edge far when its long edge ran along the shorter unit
    // (it then got no split at all, issue 9's 16.5° interstage triangle).
    let chart_distance = |a: [f64; 2], b: [f64; 2]| {
        let (x, y) = (arc.to_chart(a), arc.to_chart(b));
        (x[0] - y[0]).hypot(x[1] - y[1])
    };
    let size = (0..3)
        .map(|k| chart_distance(q[k], centroid_uv))
        .fold(0.0, f64::max);
    let circumcentre = circle
        .map(|c| nearest_parameter(s, c, centroid_uv))
        .filter(|&uv| chart_distance(uv, centroid_uv) <= 2.0 * size)
        .filter(|&uv| inside(uv));
    Some(Split {
        circumcentre,
        centroid: centroid_uv,
        triangle: *q,
        corners: [0; 3],
    })
}

/// Ruppert's choice: the circumcentre, unless it encroaches on a boundary
/// edge (falls in its diametral circle) or lies beyond the boundary; then
/// that boundary edge is split instead.
fn choose(
    cdt: &Cdt,
    arc: &ArcChart,
    nodes: &Nodes,
    split: Split,
    constraints: &[(usize, usize)],
    corner: usize,
    floor: f64,
) -> Option<Action> {
    let corners = split.triangle.map(|uv| arc.to_chart(uv));
    let mid = [
        (corners[0][0] + corners[1][0] + corners[2][0]) / 3.0,
        (corners[0][1] + corners[1][1] + corners[2][1]) / 3.0,
    ];
    let spacing = 0.3
        * corners
            .iter()
            .map(|c| (c[0] - mid[0]).hypot(c[1] - mid[1]))
            .fold(0.0, f64::max);
    let splittable = |(x, y): (usize, usize)| {
        nodes.sides[x] & nodes.sides[y] & nodes.fixed == 0
            && (nodes.xyz[x] - nodes.xyz[y]).norm() > 2.0 * floor
    };
    // The longest of some boundary edges that may be split.
    let longest_splittable = |edges: &mut dyn Iterator<Item = (usize, usize)>| {
        edges.filter(|&e| splittable(e)).max_by(|a, b| {
            let la = (nodes.xyz[a.0] - nodes.xyz[a.1]).norm();
            let lb = (nodes.xyz[b.0] - nodes.xyz[b.1]).norm();
            la.total_cmp(&lb)
        })
    };
    let hint = spade::handles::FixedVertexHandle::from_index(corner);
    let candidates = match split.circumcentre {
        Some(c) => vec![c, split.centroid],
        None => {
            if let Some(e) = longest_splittable(&mut constraints.iter().copied()) {
                return Some(Action::Split(e.0, e.1));
            }
            // The circumcentre lies beyond the boundary at a corner of the
            // triangle: Ruppert splits the boundary edge there.
            if let Some(e) =
                longest_splittable(&mut corner_constraints(cdt, &split.corners).into_iter())
            {
                return Some(Action::Split(e.0, e.1));
            }
            vec![split.centroid]
        }
    };
    for uv in candidates {
        match encroached(cdt, chart_point(arc, uv), hint) {
            Some(Some(e)) => {
                return splittable(e).then_some(Action::Split(e.0, e.1));
            }
            // The 3D circumcentre may land next to a vertex the chart's
            // Delaunay triangle does not see: then the next candidate.
            Some(None) if clear(cdt, chart_point(arc, uv), hint, spacing) => {
                return Some(Action::Insert { uv, hint, spacing });
            }
            _ => continue,
        }
    }
    None
}

/// True when two of the triangle's boundary edges (`walls`, seams left
/// out) meet at an input angle the angle test cannot be met at: one smaller
/// than the threshold, where refinement would cascade into the corner (the
/// triangle's angle there is the boundary's own, measured on the surface),
/// or one between edges that are never split (a pole cap's ring, another
/// face's chain). Two boundary edges meeting at a wider angle (a patch's
/// 90° corner) are no excuse: the triangle is refined like any other, and
/// Ruppert's choice splits a boundary edge there (issue 9's 23.7° triangle
/// at the Bezier patch's corner).
fn input_corner(
    walls: &[(usize, usize)],
    t: &[usize; 3],
    p: &[Point3; 3],
    nodes: &Nodes,
    threshold: f64,
) -> bool {
    let fixed = |&(a, b): &(usize, usize)| nodes.sides[a] & nodes.sides[b] & nodes.fixed != 0;
    (0..3).any(|k| {
        let at = |&&(a, b): &&(usize, usize)| a == t[k] || b == t[k];
        let meeting: Vec<&(usize, usize)> = walls.iter().filter(at).collect();
        if meeting.len() < 2 {
            return false;
        }
        let (a, b) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
        a.angle(&b).to_degrees() < threshold || meeting.iter().any(|e| fixed(e))
    })
}

/// The constraint edges at the corners of a triangle (each once).
fn corner_constraints(cdt: &Cdt, corners: &[usize; 3]) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for &c in corners {
        let v = cdt.vertex(spade::handles::FixedVertexHandle::from_index(c));
        for e in v.out_edges() {
            if cdt.is_constraint_edge(e.as_undirected().fix()) {
                let (a, b) = (e.from().fix().index(), e.to().fix().index());
                if !out.contains(&(a, b)) && !out.contains(&(b, a)) {
                    out.push((a, b));
                }
            }
        }
    }
    out
}

fn chart_point(arc: &ArcChart, uv: [f64; 2]) -> Point2<f64> {
    let c = arc.to_chart(uv);
    Point2::new(c[0], c[1])
}

/// The smallest angle of a 3D triangle, degrees.
pub(crate) fn min_angle(p: &[Point3; 3]) -> f64 {
    let angle = |a: Vec3, b: Vec3| a.angle(&b).to_degrees();
    angle(p[1] - p[0], p[2] - p[0])
        .min(angle(p[0] - p[1], p[2] - p[1]))
        .min(angle(p[0] - p[2], p[1] - p[2]))
}

/// The centre of the circle through three 3D points.
fn circumcentre(p: &[Point3; 3]) -> Option<Point3> {
    let (a, b) = (p[1] - p[0], p[2] - p[0]);
    let n = a.cross(&b);
    let d = 2.0 * n.norm_squared();
    if d <= 0.0 {
        return None;
    }
    let offset = (n.cross(&a) * b.norm_squared() + b.cross(&n) * a.norm_squared()) / d;
    Some(p[0] + offset)
}

/// Gauss–Newton on |R(u, v) − target|² from `start`.
pub(crate) fn nearest_parameter(s: &TrimmedSurface, target: Point3, start: [f64; 2]) -> [f64; 2] {
    let mut uv = start;
    for _ in 0..6 {
        let r = s.point(uv[0], uv[1]) - target;
        let (du, dv) = s.tangents(uv[0], uv[1]);
        let (a, b, c) = (du.dot(&du), du.dot(&dv), dv.dot(&dv));
        let det = a * c - b * b;
        if det.is_nan() || det == 0.0 {
            break;
        }
        let (gu, gv) = (du.dot(&r), dv.dot(&r));
        let step = [(c * gu - b * gv) / det, (a * gv - b * gu) / det];
        if !(step[0].is_finite() && step[1].is_finite()) {
            break;
        }
        uv = [uv[0] - step[0], uv[1] - step[1]];
    }
    uv
}

/// Merges each node of a seam's high side (u = u_max, v = v_max) into its
/// twin on the low side, drops the seam sides from the boundary chains, and
/// joins the pieces a seam cut (a hole across it) into one chain again.
fn weld_seams(
    nodes: &Nodes,
    periodic: [bool; 2],
    remap: &mut [usize],
    chains: &mut Vec<Vec<usize>>,
) {
    let mut seams = 0;
    for axis in 0..2 {
        if !periodic[axis] {
            continue;
        }
        seams |= SEAM[axis];
        let high = SEAM[axis] & (U_MAX | V_MAX);
        for (&a, &b) in &nodes.twin[axis] {
            if nodes.sides[a] & high != 0 {
                remap[a] = b;
            }
        }
    }
    // A corner of a surface closed both ways goes through two twins.
    for h in 0..remap.len() {
        let mut t = remap[h];
        for _ in 0..3 {
            t = remap[t];
        }
        remap[h] = t;
    }
    let along_seam = |x: usize, y: usize| nodes.sides[x] & nodes.sides[y] & seams != 0;
    let mut runs = Vec::new();
    for chain in chains.drain(..) {
        // Cut the closed chain at segments along the seam; rotate so a cut
        // comes first, then collect the runs between cuts.
        let n = chain.len() - 1;
        let cut = (0..n).find(|&k| along_seam(chain[k], chain[k + 1]));
        let Some(cut) = cut else {
            runs.push(chain);
            continue;
        };
        let ring: Vec<usize> = (0..=n).map(|k| chain[(cut + 1 + k) % n]).collect();
        let mut run: Vec<usize> = vec![ring[0]];
        for w in ring.windows(2) {
            if along_seam(w[0], w[1]) {
                if run.len() >= 2 {
                    runs.push(std::mem::take(&mut run));
                }
                run = vec![w[1]];
            } else {
                run.push(w[1]);
            }
        }
        if run.len() >= 2 {
            runs.push(run);
        }
    }
    for run in &mut runs {
        for h in run.iter_mut() {
            *h = remap[*h];
        }
        run.dedup();
    }
    runs.retain(|r| r.len() >= 2);
    *chains = join_runs(runs);
}

/// Joins open runs end to start (or end to end, one reversed) until each is
/// closed or has no continuation; in input order, so deterministic.
pub(super) fn join_runs(mut runs: Vec<Vec<usize>>) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    while !runs.is_empty() {
        let mut cur = runs.remove(0);
        while cur.first() != cur.last() {
            let end = cur[cur.len() - 1];
            let next = runs
                .iter()
                .position(|r| r[0] == end || r[r.len() - 1] == end);
            let Some(k) = next else { break };
            let mut r = runs.remove(k);
            if r[0] != end {
                r.reverse();
            }
            cur.extend_from_slice(&r[1..]);
        }
        out.push(cur);
    }
    out
}

fn assemble(
    uvs: &[[f64; 2]],
    points3: &[Point3],
    inner: &[[usize; 3]],
    remap: &[usize],
    chains: &[Vec<usize>],
    shared: &[(usize, usize, usize)],
) -> TrimmedMesh {
    let mut number = vec![u32::MAX; uvs.len()];
    let mut mesh = TrimmedMesh::default();
    let node = |h: usize, mesh: &mut TrimmedMesh, number: &mut Vec<u32>| {
        let h = remap[h];
        if number[h] == u32::MAX {
            number[h] = mesh.nodes.len() as u32;
            mesh.nodes.push(points3[h]);
            mesh.uv.push(uvs[h]);
        }
        number[h]
    };
    for t in inner {
        let tri = t.map(|h| node(h, &mut mesh, &mut number));
        if tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2] {
            mesh.triangles.push(tri);
        }
    }
    for chain in chains {
        let c: Vec<u32> = chain
            .iter()
            .map(|&h| node(h, &mut mesh, &mut number))
            .collect();
        mesh.boundary.push(c);
    }
    for &(h, c, i) in shared {
        let n = node(h, &mut mesh, &mut number);
        mesh.shared.push((n, c, i));
    }
    mesh
}

/// `None` when `p` falls on a vertex or edge or outside; else the
/// constraint edge whose diametral circle holds `p` (a point there would
/// make a sliver against the boundary), if any, among those of the triangle
/// holding it and of that triangle's neighbours: the circumcentre of a
/// right or obtuse triangle lies on or beyond its longest edge, in the
/// neighbour, while the edge it encroaches is one of its own triangle's.
fn encroached(
    cdt: &Cdt,
    p: Point2<f64>,
    hint: spade::handles::FixedVertexHandle,
) -> Option<Option<(usize, usize)>> {
    use spade::PositionInTriangulation::OnFace;
    let OnFace(face) = cdt.locate_with_hint(p, hint) else {
        return None;
    };
    let face = cdt.face(face);
    let neighbours = face.adjacent_edges().map(|e| e.rev().face().as_inner());
    let faces = std::iter::once(face).chain(neighbours.into_iter().flatten());
    for f in faces {
        let hit = f.adjacent_edges().into_iter().find(|e| {
            if !cdt.is_constraint_edge(e.as_undirected().fix()) {
                return false;
            }
            let [a, b] = e.positions();
            let m = Point2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y));
            let r2 = 0.25 * ((a.x - b.x).powi(2) + (a.y - b.y).powi(2));
            (p.x - m.x).powi(2) + (p.y - m.y).powi(2) < r2
        });
        if let Some(e) = hit {
            return Some(Some((e.from().fix().index(), e.to().fix().index())));
        }
    }
    Some(None)
}

/// True when `p` lies in a triangle, off its constraint edges' diametral
/// circles and at least `spacing` from its corners (another point of the
/// same round may have landed nearby).
fn clear(cdt: &Cdt, p: Point2<f64>, hint: spade::handles::FixedVertexHandle, spacing: f64) -> bool {
    use spade::PositionInTriangulation::OnFace;
    if encroached(cdt, p, hint) != Some(None) {
        return false;
    }
    let OnFace(face) = cdt.locate_with_hint(p, hint) else {
        return false;
    };
    cdt.face(face)
        .positions()
        .iter()
        .all(|c| (c.x - p.x).hypot(c.y - p.y) >= spacing)
}

/// Threads the boundary points split in (each on two constraint edges) into
/// the boundary chains.
fn thread_splits(cdt: &Cdt, fixed: usize, chains: &mut [Vec<usize>]) {
    let mut next: HashMap<usize, Vec<usize>> = HashMap::new();
    for e in cdt.undirected_edges() {
        if cdt.is_constraint_edge(e.fix()) {
            let [a, b] = e.vertices().map(|v| v.fix().index());
            next.entry(a).or_default().push(b);
            next.entry(b).or_default().push(a);
        }
    }
    for chain in chains.iter_mut() {
        let mut out = Vec::with_capacity(chain.len());
        for w in chain.windows(2) {
            let (x, y) = (w[0], w[1]);
            out.push(x);
            let direct = next.get(&x).is_some_and(|n| n.contains(&y));
            if direct {
                continue;
            }
            // Walk from x through added points to y.
            let starts: Vec<usize> = next.get(&x).map_or(Vec::new(), |n| {
                n.iter().copied().filter(|&n| n >= fixed).collect()
            });
            for start in starts {
                let mut path = vec![start];
                let (mut prev, mut cur) = (x, start);
                while cur >= fixed && path.len() <= cdt.num_vertices() {
                    let Some(&n) = next.get(&cur).and_then(|n| n.iter().find(|&&n| n != prev))
                    else {
                        break;
                    };
                    prev = cur;
                    cur = n;
                    if cur >= fixed {
                        path.push(cur);
                    }
                }
                if cur == y {
                    out.extend(path);
                    break;
                }
            }
        }
        out.push(*chain.last().unwrap_or(&0));
        *chain = out;
    }
}
