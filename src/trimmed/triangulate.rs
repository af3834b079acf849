//! Stages 2 and 3 of paper 002: a constrained Delaunay triangulation of the
//! boundary loops in parameter space (a chart scaled so lengths roughly match
//! 3D), then refinement by 3D criteria: a triangle is split while its
//! smallest angle measured on the surface is below the threshold or the
//! surface leaves it by more than the tolerance (the chord-to-arc control).
//! The point inserted is the parameter point whose surface point is nearest
//! the triangle's 3D circumcentre E3 (minimising |R(u, v) − E3|).

use super::TrimmedSurface;
use super::boundary::{self, Boundary, V_MAX, V_MIN};
use super::chart::ArcChart;
use crate::geom::{Point3, Vec3};
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};
use std::collections::HashMap;

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// Refinement rounds before the result is taken as it is.
const MAX_PASSES: usize = 40;
/// Passes that also split triangles whose 3D angles are too small.
const ANGLE_PASSES: usize = 6;
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
}

/// How finely to mesh.
#[derive(Debug, Clone, Copy)]
pub struct TrimSettings {
    pub tolerance: f64,
    pub min_angle: f64,
    pub max_edge: f64,
}

pub fn mesh_trimmed(s: &TrimmedSurface, settings: TrimSettings) -> Result<TrimmedMesh, String> {
    let [u0, u1, v0, v1] = s.rect;
    if !(u1 > u0 && v1 > v0) {
        return Err(format!(
            "the parameter rectangle [{u0}, {u1}] × [{v0}, {v1}] is empty"
        ));
    }
    let arc = ArcChart::new(s)?;
    let (lu, lv) = arc.lengths();
    let extent = lu.hypot(lv);
    let tol = settings.tolerance;
    // A chord of length h on a bend of radius ~extent/2 deviates h²/(4·extent).
    let h = (4.0 * extent * tol)
        .sqrt()
        .min(extent / 48.0)
        .min(settings.max_edge);
    let nu = ((lu / h).ceil() as usize).clamp(4, 2048);
    let nv = ((lv / h).ceil() as usize).clamp(4, 2048);
    let mut b = boundary::trace(s, [nu, nv])?;
    let cell = (lu / nu as f64).hypot(lv / nv as f64);
    b.merge_short(s, 0.4 * cell);
    let periodic = is_periodic_v(s, extent);
    // Boundary edges stay as they are on a periodic surface (both sides of
    // the seam must match), so they start shorter there.
    let side = if periodic { 0.5 * h } else { h.max(0.5 * cell) };
    b.refine_chords(s, 0.5 * tol, side);
    if b.loops.is_empty() {
        return Err("the trim leaves no material on the surface".into());
    }
    let chart = |uv: [f64; 2]| {
        let c = arc.to_chart(uv);
        Point2::new(c[0], c[1])
    };
    let mut cdt = Cdt::new();
    let mut handles = vec![usize::MAX; b.points.len()];
    let mut uvs: Vec<[f64; 2]> = Vec::new();
    for lp in &b.loops {
        for &p in lp {
            if handles[p] != usize::MAX {
                continue;
            }
            let h = cdt
                .insert(chart(b.points[p]))
                .map_err(|e| format!("a boundary point cannot be triangulated: {e:?}"))?;
            if h.index() == uvs.len() {
                uvs.push(b.points[p]);
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
    // Spade stops after this many insertions (triangles of side ~h cover the
    // surface about 2·area/h² times over; room for grading near the trim).
    let budget = ((8.0 * lu * lv / (h * h)) as usize + 4 * uvs.len() + 1000).min(MAX_VERTICES);
    let mut params = RefinementParameters::<f64>::new()
        .exclude_outer_faces(true)
        .with_angle_limit(AngleLimit::from_deg((settings.min_angle + 3.0).min(30.0)))
        .with_max_additional_vertices(budget);
    // A periodic seam must be split the same way on both sides: keep its
    // edges (and the trim's) as they are.
    if periodic {
        params = params.keep_constraint_edges();
    }
    let mut points3: Vec<Point3> = uvs.iter().map(|p| s.point(p[0], p[1])).collect();
    let mut inner: Vec<[usize; 3]> = Vec::new();
    // Triangles this small are left as they are (next to small input angles).
    let floor = (0.02 * h).min(tol);
    let fixed = uvs.len();
    for pass in 0..MAX_PASSES {
        let result = cdt.refine(params.clone());
        for v in uvs.len()..cdt.num_vertices() {
            let q = cdt
                .vertex(spade::handles::FixedVertexHandle::from_index(v))
                .position();
            let uv = arc.to_param([q.x, q.y]);
            uvs.push(uv);
            points3.push(s.point(uv[0], uv[1]));
        }
        let mut excluded = vec![false; cdt.num_all_faces()];
        for f in &result.excluded_faces {
            if let Some(slot) = excluded.get_mut(f.index()) {
                *slot = true;
            }
        }
        inner.clear();
        let mut inserts: Vec<([f64; 2], spade::handles::FixedVertexHandle)> = Vec::new();
        for f in cdt.inner_faces() {
            if excluded.get(f.fix().index()).copied().unwrap_or(true) {
                continue;
            }
            let t = f.vertices().map(|v| v.fix().index());
            inner.push(t);
            let p = t.map(|i| points3[i]);
            let q = t.map(|i| uvs[i]);
            // Angles at the boundary follow its discretisation (spade keeps
            // the constraint edges): the 3D angle test is for the interior,
            // and for the first passes (later ones only chase the tolerance).
            let angles = pass < ANGLE_PASSES && t.iter().all(|&i| i >= fixed);
            if let Some(point) = needs_split(s, &p, &q, &settings, floor, angles) {
                inserts.push((point, f.vertices()[0].fix()));
            }
        }
        if inserts.is_empty() {
            break;
        }
        if cdt.num_vertices() + inserts.len() > MAX_VERTICES {
            return Err(format!(
                "it needs more than {MAX_VERTICES} nodes for the tolerance"
            ));
        }
        for (uv, hint) in inserts {
            if encroaches(&cdt, chart(uv), hint) {
                continue;
            }
            let h = cdt
                .insert_with_hint(chart(uv), hint)
                .map_err(|e| format!("a refinement point cannot be inserted: {e:?}"))?;
            if h.index() == uvs.len() {
                uvs.push(uv);
                points3.push(s.point(uv[0], uv[1]));
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
    if !periodic {
        let mut sides = vec![0u8; uvs.len()];
        for (p, &h) in handles.iter().enumerate() {
            if h != usize::MAX {
                sides[h] = b.sides[p];
            }
        }
        snap_splits(
            &cdt,
            s,
            fixed,
            &sides,
            &mut boundary_chains,
            &mut uvs,
            &mut points3,
        );
    }
    let mut remap: Vec<usize> = (0..uvs.len()).collect();
    if periodic {
        weld_seam(&b, &handles, &uvs, s.rect, &mut remap, &mut boundary_chains);
    }
    Ok(assemble(&uvs, &points3, &inner, &remap, &boundary_chains))
}

/// True when the sides v = v_min and v = v_max are the same curve in 3D.
fn is_periodic_v(s: &TrimmedSurface, extent: f64) -> bool {
    let [u0, u1, v0, v1] = s.rect;
    (0..=8).all(|i| {
        let u = u0 + (u1 - u0) * i as f64 / 8.0;
        (s.point(u, v0) - s.point(u, v1)).norm() <= 1e-9 * extent
    })
}

/// The parameter point to insert when the triangle is too coarse or too
/// skinny on the surface, `None` when it is fine.
fn needs_split(
    s: &TrimmedSurface,
    p: &[Point3; 3],
    q: &[[f64; 2]; 3],
    settings: &TrimSettings,
    floor: f64,
    angles: bool,
) -> Option<[f64; 2]> {
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
    let on_surface = s.point(centroid_uv[0], centroid_uv[1]);
    let mut coarse =
        (on_surface - centroid).norm() > settings.tolerance || longest > settings.max_edge;
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
    let target = circumcentre(p).unwrap_or(centroid);
    let uv = nearest_parameter(s, target, centroid_uv);
    let inside = |uv: [f64; 2]| {
        let [u0, u1, v0, v1] = s.rect;
        uv[0] > u0 && uv[0] < u1 && uv[1] > v0 && uv[1] < v1 && s.material(uv[0], uv[1]) >= 0.0
    };
    // Far from the triangle (beyond twice its parameter size) or out of the
    // material, the circumcentre is not usable: split at the centroid.
    let size = (0..3)
        .map(|k| (q[k][0] - centroid_uv[0]).hypot(q[k][1] - centroid_uv[1]))
        .fold(0.0, f64::max);
    let near = (uv[0] - centroid_uv[0]).hypot(uv[1] - centroid_uv[1]) <= 2.0 * size;
    Some(if near && inside(uv) { uv } else { centroid_uv })
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

/// Merges the nodes of the side v = v_max into those of v = v_min with the
/// same u, and drops both sides from the boundary chains.
fn weld_seam(
    b: &Boundary,
    handles: &[usize],
    uvs: &[[f64; 2]],
    rect: [f64; 4],
    remap: &mut [usize],
    chains: &mut Vec<Vec<usize>>,
) {
    let eps = 1e-9 * (rect[1] - rect[0]);
    let mut low: Vec<(f64, usize)> = Vec::new();
    let mut seam = vec![false; uvs.len()];
    for (p, &side) in b.sides.iter().enumerate() {
        let h = handles[p];
        if h == usize::MAX {
            continue;
        }
        if side & (V_MIN | V_MAX) != 0 {
            seam[h] = true;
        }
        if side & V_MIN != 0 {
            low.push((uvs[h][0], h));
        }
    }
    low.sort_by(|x, y| x.0.total_cmp(&y.0));
    for (p, &side) in b.sides.iter().enumerate() {
        let h = handles[p];
        if h == usize::MAX || side & V_MAX == 0 {
            continue;
        }
        let u = uvs[h][0];
        let at = low.partition_point(|x| x.0 < u - eps);
        if let Some(&(lu, lh)) = low.get(at)
            && (lu - u).abs() <= eps
        {
            remap[h] = lh;
        }
    }
    // The side bits of each handle (a handle may come from several points).
    let mut side_of: HashMap<usize, u8> = HashMap::new();
    for (&bits, &h) in b.sides.iter().zip(handles) {
        if h != usize::MAX && seam.get(h).copied().unwrap_or(false) {
            *side_of.entry(h).or_default() |= bits & (V_MIN | V_MAX);
        }
    }
    let along_seam = |x: usize, y: usize| {
        let (sx, sy) = (
            side_of.get(&x).copied().unwrap_or(0),
            side_of.get(&y).copied().unwrap_or(0),
        );
        sx & sy & (V_MIN | V_MAX) != 0
    };
    let mut out = Vec::new();
    for chain in chains.drain(..) {
        // Cut the closed chain at segments along the seam; rotate so a cut
        // comes first, then collect the runs between cuts.
        let n = chain.len() - 1;
        let cut = (0..n).find(|&k| along_seam(chain[k], chain[k + 1]));
        let Some(cut) = cut else {
            out.push(chain);
            continue;
        };
        let ring: Vec<usize> = (0..=n).map(|k| chain[(cut + 1 + k) % n]).collect();
        let mut run: Vec<usize> = vec![ring[0]];
        for w in ring.windows(2) {
            if along_seam(w[0], w[1]) {
                if run.len() >= 2 {
                    out.push(std::mem::take(&mut run));
                }
                run = vec![w[1]];
            } else {
                run.push(w[1]);
            }
        }
        if run.len() >= 2 {
            out.push(run);
        }
    }
    for chain in &mut out {
        for h in chain.iter_mut() {
            *h = remap[*h];
        }
    }
    *chains = out;
}

fn assemble(
    uvs: &[[f64; 2]],
    points3: &[Point3],
    inner: &[[usize; 3]],
    remap: &[usize],
    chains: &[Vec<usize>],
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
    mesh
}

/// True when `p` falls on a vertex or edge, or inside the diametral circle
/// of a constraint edge of the triangle holding it: a point there would
/// make a sliver against the boundary, which refinement keeps as it is.
fn encroaches(cdt: &Cdt, p: Point2<f64>, hint: spade::handles::FixedVertexHandle) -> bool {
    use spade::PositionInTriangulation::OnFace;
    let OnFace(face) = cdt.locate_with_hint(p, hint) else {
        return true;
    };
    cdt.face(face).adjacent_edges().iter().any(|e| {
        if !cdt.is_constraint_edge(e.as_undirected().fix()) {
            return false;
        }
        let [a, b] = e.positions();
        let m = Point2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y));
        let r2 = 0.25 * ((a.x - b.x).powi(2) + (a.y - b.y).powi(2));
        (p.x - m.x).powi(2) + (p.y - m.y).powi(2) < r2
    })
}

/// Puts the boundary points spade added (splitting constraint edges at
/// their chart midpoints) back on the boundary: on the side they split, or
/// on W = 0; and threads them into the boundary chains.
fn snap_splits(
    cdt: &Cdt,
    s: &TrimmedSurface,
    fixed: usize,
    sides: &[u8],
    chains: &mut [Vec<usize>],
    uvs: &mut [[f64; 2]],
    points3: &mut [Point3],
) {
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
            // Walk from x through added points (each on two constraint edges) to y.
            let starts: Vec<usize> = next.get(&x).map_or(Vec::new(), |n| {
                n.iter().copied().filter(|&n| n >= fixed).collect()
            });
            for start in starts {
                let mut path = vec![start];
                let (mut prev, mut cur) = (x, start);
                while cur >= fixed && path.len() <= uvs.len() {
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
                    let (ux, uy) = (uvs[x], uvs[y]);
                    let common = sides[x] & sides[y];
                    for &p in &path {
                        let uv = if common != 0 {
                            snap_to_side(uvs[p], common, s.rect)
                        } else {
                            boundary::project(s, uvs[p], ux, uy)
                        };
                        uvs[p] = uv;
                        points3[p] = s.point(uv[0], uv[1]);
                    }
                    out.extend(path);
                    break;
                }
            }
        }
        out.push(*chain.last().unwrap_or(&0));
        *chain = out;
    }
}

fn snap_to_side(uv: [f64; 2], side: u8, rect: [f64; 4]) -> [f64; 2] {
    let mut uv = uv;
    if side & boundary::U_MIN != 0 {
        uv[0] = rect[0];
    }
    if side & boundary::U_MAX != 0 {
        uv[0] = rect[1];
    }
    if side & V_MIN != 0 {
        uv[1] = rect[2];
    }
    if side & V_MAX != 0 {
        uv[1] = rect[3];
    }
    uv
}
