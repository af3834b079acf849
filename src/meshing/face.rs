//! Meshing one face: its loops, mapped through the face's [`Chart`], become the
//! constraint edges of a constrained Delaunay triangulation (spade), refined
//! for angles in the parameter plane and then for chordal deviation and edge
//! length on the surface.
//!
//! # Guarantees
//! - Boundary nodes are exactly the edges' nodes: when refinement wants to
//!   split a boundary segment, the face returns [`Outcome::Split`] with the
//!   curve parameters instead of a mesh, the caller adds those points to the
//!   edge for every face that uses it, and meshes again. On a plane the split
//!   is kept instead (a point on a curve first moved onto it,
//!   [`super::boundary_chain`]) and reported in [`FaceMesh::added`]. In the
//!   last round (`keep_boundary`) splitting is forbidden instead.
//! - Every triangle's distance from the surface at its centroid and edge
//!   midpoints is at most `tolerance` and its longest edge at most `max_edge`,
//!   unless the pass limit is reached first.
//! - Triangles run counter-clockwise about the face normal.
//!
//! # Limitations
//! - Angles are refined in the parameter plane; on the surface they are only
//!   as good as the chart is conformal (exact for planes, spheres, circular
//!   cones and tori), and a conformal chart keeps them only in the small: a
//!   triangle across which the chart's scale changes is bent on the surface
//!   (a cylinder's log-polar chart left 22.2° for 26.2° in the chart,
//!   `tests/trimmed_shells.rs`).
//! - Loops of a periodic chart (torus) are unwrapped one at a time: a face
//!   with several loops on a torus may place them a period apart.

use super::MeshError;
use super::boundary_chain;
use super::chart::Chart;
use super::edges::EdgeNodes;
use super::polyline_split;
use super::refine;
use super::size::Sizing;
use crate::geom::{Point3, Surface, Vec3};
use crate::ir::{Face, Model};
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};
use std::collections::BTreeMap;

pub(super) type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// Rounds of "refine in the plane, then insert points where the surface is
/// missed" before giving up on a face's tolerance.
const MAX_PASSES: usize = 60;
/// The first area limit of a curved face, in equilateral triangles on a
/// long boundary segment (`guide_area`): 2–4 made refinement split the
/// boundary (another meshing round); at 6–8 a sphere face takes 2–3 passes
/// instead of 9–10, with 8% more triangles at the same tolerance.
const GUIDE_FACTOR: f64 = 8.0;
/// Nodes one face may have.
const MAX_FACE_VERTICES: usize = 2_000_000;

/// A node of a face mesh that is a node of the model's edges, before
/// global numbering. Every other node of a face mesh is interior to it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum FacePoint {
    Vertex(u32),
    /// Interior node of an edge's discretisation, at curve parameter `s`
    /// (a parameter, not an index, so the key stays valid when the edge
    /// gets more nodes).
    Edge {
        edge: usize,
        s: f64,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FaceMesh {
    /// Every node's position (24 bytes a node: interior nodes, the bulk of
    /// a curved face, carry no key beside it).
    pub positions: Vec<Point3>,
    /// The nodes that belong to the model's edges, as (index into
    /// `positions`, key), each index once, in increasing order; the others
    /// are interior nodes.
    pub on_edges: Vec<(u32, FacePoint)>,
    /// Indices into `positions` (a face has at most `MAX_FACE_VERTICES` nodes).
    pub triangles: Vec<[u32; 3]>,
    /// Constrained poly_lines: (poly_line index, its points in order, as
    /// indices into `positions`, refinement points included).
    pub polylines: Vec<(usize, Vec<usize>)>,
    /// Nodes refinement added on straight boundary edges and kept (edge,
    /// curve parameter): the caller adds them to the edges and re-meshes
    /// only the other faces using those edges.
    pub added: Vec<(usize, f64)>,
}

pub(crate) enum Outcome {
    Meshed(FaceMesh),
    /// Boundary points to add: (edge index, curve parameter).
    Split(Vec<(usize, f64)>),
}

#[derive(Clone, Copy)]
pub(crate) struct Settings<'a> {
    pub tolerance: f64,
    pub sizing: &'a Sizing,
    pub min_angle: f64,
    pub keep_boundary: bool,
    /// Largest triangle area (2D subdomains' `area=` and `--max-area`).
    pub max_area: f64,
}

/// One point of a loop: its node, position, and the segment to the next point.
struct LoopPoint {
    key: FacePoint,
    point: Point3,
    edge: usize,
    s: f64,
    s_next: f64,
}

/// A boundary segment of the triangulation: its edge and curve parameters
/// at its lower- and higher-numbered vertex.
pub(super) type Segments = BTreeMap<(usize, usize), (usize, f64, f64)>;

pub(crate) fn mesh_face(
    model: &Model,
    face: &Face,
    edges: &[EdgeNodes],
    settings: &Settings,
    constraints: &[(usize, Vec<Point3>)],
) -> Result<Outcome, MeshError> {
    let failed = |reason: String| MeshError::Face {
        face: face.name.to_string(),
        reason,
    };
    let loops = walk_loops(model, face, edges).map_err(failed)?;
    let boundary: Vec<Point3> = loops.iter().flatten().map(|p| p.point).collect();
    let surface = face.surface(&model.solids);
    let chart = Chart::new(&surface, &boundary, area_vector(face, &loops)).map_err(failed)?;
    let uv_loops = unwrap_loops(&chart, &loops).map_err(failed)?;

    // Sized up front for the nodes the area limit will ask for: growing
    // spade's tables by doubling copied them and touched twice the memory.
    let expected = expected_vertices(
        &uv_loops,
        settings.max_area.min(guide_area(&uv_loops, &surface)),
    )
    .max(curved_vertices(
        &chart,
        &uv_loops,
        &surface,
        settings.tolerance,
    ));
    let bulk = bulk_load_loops(&uv_loops);
    let bulk_loaded = bulk.is_some();
    let mut cdt = bulk.unwrap_or_else(|| Cdt::with_capacity(expected, 3 * expected, 2 * expected));
    // Keys of the loops' nodes, which come first; later nodes are interior
    // unless a plane face keeps a boundary split (`kept_keys`).
    let mut keys: Vec<FacePoint> = Vec::new();
    let mut kept_keys: Vec<(u32, FacePoint)> = Vec::new();
    let mut positions: Vec<Point3> = Vec::with_capacity(expected);
    let mut segments = Segments::new();
    if bulk_loaded {
        // Vertex i is loop point i (loops in order): the keys, positions
        // and segments follow from the loops alone. The segments go into
        // the map in one bulk build (one insert each was 2% of meshing a
        // 10,000-sided polygon; a repeated key keeps the last entry either
        // way).
        let mut first = 0;
        let mut loop_segments = Vec::with_capacity(loops.iter().map(Vec::len).sum());
        for lp in &loops {
            for (i, point) in lp.iter().enumerate() {
                keys.push(point.key.clone());
                positions.push(point.point);
                let (a, b) = (first + i, first + (i + 1) % lp.len());
                let entry = if a < b {
                    (point.edge, point.s, point.s_next)
                } else {
                    (point.edge, point.s_next, point.s)
                };
                loop_segments.push(((a.min(b), a.max(b)), entry));
            }
            first += lp.len();
        }
        segments = loop_segments.into_iter().collect();
    }
    for (lp, uv) in loops.iter().zip(&uv_loops).filter(|_| !bulk_loaded) {
        let mut handles = Vec::with_capacity(lp.len());
        for (point, uv) in lp.iter().zip(uv) {
            let handle = cdt
                .insert(point2(*uv))
                .map_err(|e| failed(format!("a boundary node cannot be triangulated: {e:?}")))?;
            let index = handle.index();
            if index == positions.len() {
                keys.push(point.key.clone());
                positions.push(point.point);
            } else if keys.get(index) != Some(&point.key) {
                return Err(failed(
                    "two boundary nodes share one point of its parametrisation".into(),
                ));
            }
            handles.push(handle);
        }
        for (i, point) in lp.iter().enumerate() {
            let (a, b) = (handles[i], handles[(i + 1) % handles.len()]);
            if a == b {
                return Err(failed("a loop segment has no length".into()));
            }
            if !cdt.can_add_constraint(a, b) {
                return Err(failed("its loops cross in the parameter plane".into()));
            }
            cdt.add_constraint(a, b);
            let entry = if a.index() < b.index() {
                (point.edge, point.s, point.s_next)
            } else {
                (point.edge, point.s_next, point.s)
            };
            segments.insert((a.index().min(b.index()), a.index().max(b.index())), entry);
        }
    }
    if let Some((uv, p)) = chart.singular_point()
        && winding_odd(&uv_loops, uv)
    {
        let handle = cdt
            .insert(Point2::new(uv[0], uv[1]))
            .map_err(|e| failed(format!("the apex cannot be triangulated: {e:?}")))?;
        if handle.index() == positions.len() {
            positions.push(p);
        }
    }
    // Poly_lines inside the face: constraint chains the mesh must follow.
    let mut polyline_handles: Vec<(usize, Vec<usize>)> = Vec::new();
    // A poly_line tip may be a boundary node (`constraints::assign` put it
    // on a boundary edge); no other poly_line point may coincide with one.
    let boundary_nodes = positions.len();
    for (index, points) in constraints {
        let mut handles = Vec::with_capacity(points.len());
        for (k, p) in points.iter().enumerate() {
            let tip = k == 0 || k + 1 == points.len();
            let uv = chart
                .to_param(p)
                .ok_or_else(|| failed("a poly_line point has no parameters".into()))?;
            let handle = cdt
                .insert(point2(uv))
                .map_err(|e| failed(format!("a poly_line point cannot be triangulated: {e:?}")))?;
            if handle.index() == positions.len() {
                positions.push(*p);
            } else if handles.last() != Some(&handle.index())
                && !(tip && handle.index() < boundary_nodes)
            {
                return Err(failed(format!(
                    "a point of poly_line #{} coincides with another node",
                    index + 1
                )));
            }
            if handles.last() != Some(&handle.index()) {
                handles.push(handle.index());
            }
        }
        for w in handles.windows(2) {
            let (a, b) = (
                spade::handles::FixedVertexHandle::from_index(w[0]),
                spade::handles::FixedVertexHandle::from_index(w[1]),
            );
            if !cdt.can_add_constraint(a, b) {
                return Err(failed(format!(
                    "poly_line #{} crosses its boundary or another poly_line",
                    index + 1
                )));
            }
            cdt.add_constraint(a, b);
        }
        polyline_handles.push((*index, handles));
    }
    let polyline_segments: Vec<(usize, usize)> = polyline_handles
        .iter()
        .flat_map(|(_, h)| h.windows(2).map(|w| (w[0], w[1])))
        .collect();
    // With poly_lines spade cannot tell the outside (its peeling takes an
    // open poly_line for a loop) and refines every face of the hull. Where a
    // straight boundary's nodes are collinear only up to rounding, the
    // slivers between it and the hull encroach each other without end (a
    // tilted square with a crack ran for minutes). Four points far around a
    // plane face move the hull away; the faces out there are refined for
    // their angles only (the area limit is checked on the face's own
    // triangles, `Coarse`) and dropped with the rest of the outside.
    let framed = !polyline_segments.is_empty() && matches!(*surface, Surface::Plane { .. });
    if framed {
        insert_frame(&mut cdt, &chart, &uv_loops, &mut positions).map_err(failed)?;
    }
    let fixed = cdt.num_vertices();

    let small_angle = has_small_input_angle(&cdt, settings.min_angle);
    let guide = if small_angle {
        f64::INFINITY
    } else {
        guide_area(&uv_loops, &surface)
    };
    // Spade finds the outside by peeling the whole triangulation into hash
    // sets on every call (a tenth of the meshing time); a single loop that is
    // the convex hull (a hemisphere's circle, a convex polygon) has no outside.
    let peel = polyline_segments.is_empty() && !loop_is_hull(&cdt, &uv_loops);
    let mut parameters = RefinementParameters::<f64>::new()
        // Spade's peeling takes an open poly_line for a loop: with poly_lines
        // the outside is found here instead (`outside_faces`).
        .exclude_outer_faces(peel)
        .with_angle_limit(AngleLimit::from_deg(settings.min_angle))
        .with_max_additional_vertices(vertex_budget(
            &uv_loops,
            settings.max_area.min(guide),
            settings,
            small_angle,
        ));
    if settings.keep_boundary {
        parameters = parameters.keep_constraint_edges();
    }
    if settings.max_area.min(guide).is_finite() && !framed {
        parameters = parameters.with_max_allowed_area(settings.max_area.min(guide));
    }
    // Next to an input angle below the limit no triangle can meet it, and
    // chasing it ran to the vertex budget (a 0.02° sliver took minutes): in
    // such a face, triangles smaller than the tolerance squared (below the
    // model's resolution) are not refined for their angles, and the budget
    // follows from that size (`vertex_budget`).
    if small_angle {
        parameters = parameters.with_min_required_area(settings.tolerance * settings.tolerance);
    }
    // Two triangles a node: sized with the triangulation.
    let mut inner = Vec::with_capacity(2 * expected);
    // Triangles already found fine, by face slot: the key of the triangle
    // (its corner nodes, which never move) that was fine there. Later passes
    // only check the triangles insertions created or moved.
    let mut fine: Vec<u64> = Vec::new();
    let mut excluded: Vec<bool>;
    let deviation = Deviation::of(&surface);
    let coarse = Coarse {
        deviation: &deviation,
        settings,
        area_limited: settings.max_area.is_finite() && matches!(*surface, Surface::Plane { .. }),
    };
    // Vertices from this index on have not been checked for boundary splits.
    let mut unchecked = fixed;
    // Constraint segments at the last check: refinement puts a vertex on a
    // boundary segment only by splitting it, which adds one, so while the
    // count stands no new vertex needs looking at (the look walks every new
    // vertex's edges: 3% of meshing a sphere).
    let mut checked_constraints = usize::MAX;
    let mut added = Vec::new();
    // A face without poly_lines or small input angles is refined by geomc's
    // own off-centre refinement (`refine`): spade's inserts circumcentres (a
    // third more triangles than Triangle on a long polygon), and on a curved
    // face it rescanned the whole face on each of its 2–3 calls between the
    // chordal passes (95% of meshing), where ours checks the surface on each
    // new triangle in the same loop.
    let plane = matches!(*surface, Surface::Plane { .. });
    // Periodic charts (a torus) stay with spade: their seam segments, split
    // by our loop, fell between the unwrapped copies of an edge (E502).
    let periodic = chart.periods().iter().any(Option::is_some);
    let own = !framed
        && !small_angle
        && !settings.keep_boundary
        && polyline_segments.is_empty()
        && (plane || !periodic);
    let budget = vertex_budget(
        &uv_loops,
        settings.max_area.min(guide),
        settings,
        small_angle,
    );
    // The surface check inside the refinement (curved faces): the same
    // criteria as the scan after it (`Coarse`), except for triangles whose
    // longest edge is below the tolerance, which no chart of a smooth
    // surface makes stray by the tolerance; they are left to the scan (a
    // degenerate point of a general surface would otherwise be refined
    // without end). `skipped` says whether any was.
    let skipped = std::cell::Cell::new(false);
    let lift = |uv: Point2<f64>| chart.lift([uv.x, uv.y]);
    let surface_coarse = |[a, b, c]: [&Point3; 3]| {
        let longest2 = (b - a)
            .norm_squared()
            .max((c - b).norm_squared())
            .max((a - c).norm_squared());
        if longest2 < settings.tolerance * settings.tolerance {
            skipped.set(true);
            return false;
        }
        too_coarse(&deviation, [a, b, c], settings)
    };
    // Refinement splits a segment on a curved edge at the curve's point
    // (`refine::Curves`): in the chart, and on the curve for the node.
    let curve_point = |edge: usize, s: f64| -> Option<(Point2<f64>, Point3)> {
        let curve = model.edges.get(edge)?.curve(&model.solids);
        if matches!(*curve, crate::geom::Curve::Segment { .. }) {
            return None;
        }
        let p = curve.point(s);
        let uv = chart.to_param(&p)?;
        Some((point2(uv), p))
    };
    for pass in 0..MAX_PASSES {
        let result = if own {
            // After the first pass a point put on a concave curve may have
            // left part of the hull outside even without peeling.
            let outside = if peel || pass > 0 {
                outside_faces(&cdt, &[])
            } else {
                vec![false; cdt.num_all_faces()]
            };
            refine::refine(
                &mut cdt,
                refine::Params {
                    min_angle_degrees: settings.min_angle,
                    // Curved faces: the surface check sets the size (the
                    // guide area, a uniform chart size, only over-refined
                    // where the chart shrinks the surface).
                    max_area: if plane {
                        settings.max_area.min(guide)
                    } else {
                        settings.max_area
                    },
                    max_additional_vertices: budget,
                    outside,
                    curves: Some(refine::Curves {
                        segments: &mut segments,
                        point: &curve_point,
                    }),
                    surface: (!plane).then_some(refine::SurfaceCheck {
                        positions: &mut positions,
                        lift: &lift,
                        coarse: &surface_coarse,
                    }),
                },
            )
        } else {
            let result = cdt.refine(parameters.clone());
            let mut outside = vec![false; cdt.num_all_faces()];
            for f in &result.excluded_faces {
                if let Some(slot) = outside.get_mut(f.index()) {
                    *slot = true;
                }
            }
            refine::Refined {
                outside,
                complete: result.refinement_complete,
                on_segments: None,
                curved: Vec::new(),
                all_checked: false,
            }
        };
        if settings.keep_boundary && !polyline_segments.is_empty() {
            // Spade keeps the poly_lines whole with the loops: split them
            // here where they are in the way, and refine again.
            for _ in 0..MAX_PASSES {
                let split = polyline_split::split_pieces(
                    &mut cdt,
                    &polyline_segments,
                    settings.min_angle,
                    settings.max_area,
                    settings.tolerance,
                )
                .map_err(failed)?;
                if split == 0 {
                    break;
                }
                cdt.refine(parameters.clone());
            }
        }
        if small_angle && !result.complete && !settings.keep_boundary {
            // Segments at a tiny angle split each other without end, and
            // each round would start over from the splits sent back: mesh
            // the face against its boundary as it is instead.
            let keep = Settings {
                keep_boundary: true,
                ..*settings
            };
            return mesh_face(model, face, edges, &keep, constraints);
        }
        let mut kept = Vec::new();
        let mut moved = false;
        if !settings.keep_boundary {
            // Only the vertices added since the last check.
            let known: Vec<usize> = result.curved.iter().map(|c| c.1).collect();
            let mut chains = if cdt.num_constraints() == checked_constraints {
                Vec::new()
            } else {
                boundary_chain::chains(
                    &cdt,
                    unchecked,
                    result.on_segments.as_deref(),
                    &known,
                    &segments,
                    &polyline_segments,
                )
                .map_err(failed)?
            };
            let plane = matches!(*surface, Surface::Plane { .. });
            let straight = |edge: usize| {
                matches!(
                    model
                        .edges
                        .get(edge)
                        .map(|e| e.curve(&model.solids))
                        .as_deref(),
                    Some(crate::geom::Curve::Segment { .. })
                )
            };
            let sent_back = |chains: &[boundary_chain::Chain]| {
                Outcome::Split(
                    chains
                        .iter()
                        .flat_map(|c| c.inner.iter().map(|i| (c.edge, i.1)))
                        .chain(result.curved.iter().map(|c| (c.0, c.2)))
                        .collect(),
                )
            };
            // On a plane a split on a straight edge is on the curve already,
            // and one on a curve moves onto it in place: the face keeps its
            // triangulation (the caller adds the nodes to the edges) instead
            // of being meshed again from scratch. Other surfaces send the
            // splits back, as does a move spade cannot take.
            if !chains.is_empty() && !plane {
                return Ok(sent_back(&chains));
            }
            for chain in &mut chains {
                if straight(chain.edge) {
                    continue;
                }
                // A move removes vertices, which renumbers the last ones:
                // with points already put on curves (numbered in
                // `segments`), the splits go back instead (rare: the curve
                // point was refused only when its segments crossed another).
                if pass + 1 == MAX_PASSES
                    || !result.curved.is_empty()
                    || boundary_chain::move_onto_curve(&mut cdt, &chart, model, chain).is_none()
                {
                    return Ok(sent_back(&chains));
                }
                moved = true;
            }
            // Without peeling the loop is the hull: a point moved inwards
            // (a concave arc of one segment) would leave part of the hull
            // outside the face and unexcluded.
            if moved && !peel && !framed && !loop_is_hull(&cdt, &uv_loops) {
                return Ok(sent_back(&chains));
            }
            for chain in &chains {
                let indices = boundary_chain::indices(&cdt, chain).ok_or_else(|| {
                    failed("a boundary node moved onto its curve was lost".into())
                })?;
                boundary_chain::update_segments(&mut segments, chain, &indices);
                for (&v, &(_, s, node)) in indices.iter().zip(&chain.inner) {
                    kept.push((chain.edge, v, s, node));
                }
            }
            for &(edge, v, s, node) in &result.curved {
                kept.push((edge, v, s, Some(node)));
            }
        }
        unchecked = cdt.num_vertices();
        checked_constraints = cdt.num_constraints();
        lift_new_vertices(&cdt, &chart, &mut positions).map_err(failed)?;
        for (edge, v, s, node) in kept {
            // Node indices fit in 32 bits (`MAX_FACE_VERTICES`).
            kept_keys.push((v as u32, FacePoint::Edge { edge, s }));
            if let Some(node) = node {
                positions[v] = node;
            }
            added.push((edge, s));
        }
        if moved {
            // Refine again around the moved points before the surface checks.
            continue;
        }
        if polyline_segments.is_empty() {
            excluded = result.outside;
            excluded.resize(cdt.num_all_faces(), true);
        } else {
            excluded = outside_faces(&cdt, &polyline_segments);
        }
        // geomc's refinement, when complete, left every triangle within the
        // area limit; on a plane with no edge-length limit nothing else can
        // make one coarse, and the check (a second lookup of every
        // triangle) is skipped.
        // On a curved face the refinement checked every triangle it left
        // against the surface, unless it skipped some (`skipped`).
        let cannot_be_coarse = own
            && result.complete
            && result.all_checked
            && if plane {
                matches!(deviation, Deviation::Plane)
                    && settings.sizing.is_uniform()
                    && settings.sizing.at(&Point3::origin()) == f64::INFINITY
            } else {
                !skipped.get()
            };
        // Only read when triangles are checked (24 MB of slots at 1.5 M
        // triangles otherwise written for nothing).
        if !cannot_be_coarse {
            fine.resize(cdt.num_all_faces(), NOT_FINE);
        }
        inner.clear();
        let mut bad = Vec::new();
        for f in cdt.inner_faces() {
            let slot = f.fix().index();
            if excluded.get(slot).copied().unwrap_or(true) {
                continue;
            }
            let [a, b, c] = f.vertices().map(|v| v.fix().index());
            // Node indices fit in 32 bits (`MAX_FACE_VERTICES`).
            inner.push([a as u32, b as u32, c as u32]);
            if cannot_be_coarse {
                continue;
            }
            let key = triangle_key(a, b, c);
            if key.is_some_and(|k| fine[slot] == k) {
                continue;
            }
            if coarse.is(f, &positions) {
                let [pa, pb, pc] = f.positions();
                let centroid = point2([(pa.x + pb.x + pc.x) / 3.0, (pa.y + pb.y + pc.y) / 3.0]);
                // A corner of the triangle is a good start for locating it.
                bad.push((centroid, f.vertices()[0].fix()));
            } else if let Some(key) = key {
                fine[slot] = key;
            }
        }
        if bad.is_empty() {
            break;
        }
        if cdt.num_vertices() + bad.len() > MAX_FACE_VERTICES {
            return Err(failed(format!(
                "it needs more than {MAX_FACE_VERTICES} nodes for the tolerance"
            )));
        }
        for (point, hint) in bad {
            cdt.insert_with_hint(point, hint)
                .map_err(|e| failed(format!("a refinement point cannot be inserted: {e:?}")))?;
        }
    }
    if inner.is_empty() {
        return Err(failed("its loops enclose no area".into()));
    }
    // Spade's triangles run counter-clockwise in the chart; the loops run
    // counter-clockwise about the face normal, so their signed area in the
    // chart says whether the chart keeps or mirrors that orientation. (The
    // loops are trusted over `reversed`, which some explicit faces get wrong.)
    let signed: f64 = uv_loops.iter().map(|lp| shoelace(lp)).sum();
    if signed < 0.0 {
        for t in &mut inner {
            t.swap(1, 2);
        }
    }
    let polylines = polyline_handles
        .iter()
        .map(|(index, handles)| (*index, polyline_chain(&cdt, fixed, handles)))
        .collect();
    // Kept until every face is meshed: without the room to spare the pass
    // buffers had.
    drop(cdt);
    let mut triangles = inner;
    triangles.shrink_to_fit();
    positions.shrink_to_fit();
    let mut on_edges: Vec<(u32, FacePoint)> = (0u32..).zip(keys).chain(kept_keys).collect();
    // A later key for the same node replaces an earlier one (stable sort,
    // then the last of each run is kept).
    on_edges.sort_by_key(|&(i, _)| i);
    on_edges.reverse();
    on_edges.dedup_by_key(|&mut (i, _)| i);
    on_edges.reverse();
    on_edges.shrink_to_fit();
    Ok(Outcome::Meshed(FaceMesh {
        positions,
        on_edges,
        triangles,
        polylines,
        added,
    }))
}

/// The face's loops as point sequences, each point with the segment after it.
fn walk_loops(
    model: &Model,
    face: &Face,
    edges: &[EdgeNodes],
) -> Result<Vec<Vec<LoopPoint>>, String> {
    let mut loops = Vec::new();
    for lp in &face.loops {
        let mut points = Vec::new();
        for (k, oe) in lp.iter().enumerate() {
            let i = oe.edge.index();
            let (edge, nodes) = model
                .edges
                .get(i)
                .zip(edges.get(i))
                .ok_or("a loop names an edge that does not exist")?;
            let last = if oe.forward { edge.end } else { edge.begin };
            let next = &lp[(k + 1) % lp.len()];
            let next_first = model
                .edges
                .get(next.edge.index())
                .map(|e| if next.forward { e.begin } else { e.end });
            if next_first != Some(last) {
                return Err(format!("its loop is not closed after edge {}", edge.name));
            }
            let n = nodes.points.len();
            let key = |j: usize| {
                if j == 0 {
                    FacePoint::Vertex(edge.begin.0)
                } else if j + 1 == n {
                    FacePoint::Vertex(edge.end.0)
                } else {
                    FacePoint::Edge {
                        edge: i,
                        s: nodes.params[j],
                    }
                }
            };
            // The k-th node along the loop's direction (no order `Vec` per
            // edge: 10,000 allocations on a 10,000-sided polygon).
            let along = |k: usize| if oe.forward { k } else { n - 1 - k };
            points.reserve(n.saturating_sub(1));
            for k in 1..n {
                let (j, next) = (along(k - 1), along(k));
                points.push(LoopPoint {
                    key: key(j),
                    point: nodes.points[j],
                    edge: i,
                    s: nodes.params[j],
                    s_next: nodes.params[next],
                });
            }
        }
        if points.len() >= 2 {
            loops.push(points);
        } else if !points.is_empty() {
            return Err("a loop has fewer than two nodes".into());
        }
    }
    if loops.is_empty() {
        return Err("it has no loops".into());
    }
    Ok(loops)
}

/// ∫ n dA over the face along the gradient side: ½ Σ p × p' over its loops,
/// negated for reversed faces.
fn area_vector(face: &Face, loops: &[Vec<LoopPoint>]) -> Vec3 {
    let mut sum = Vec3::zeros();
    for lp in loops {
        for (i, p) in lp.iter().enumerate() {
            let q = &lp[(i + 1) % lp.len()];
            sum += p.point.coords.cross(&q.point.coords);
        }
    }
    if face.reversed { -0.5 * sum } else { 0.5 * sum }
}

/// Parameters of every loop point, periodic coordinates made continuous
/// along each loop.
fn unwrap_loops(chart: &Chart, loops: &[Vec<LoopPoint>]) -> Result<Vec<Vec<[f64; 2]>>, String> {
    let periods = chart.periods();
    let mut out = Vec::new();
    for lp in loops {
        let mut uv: Vec<[f64; 2]> = Vec::with_capacity(lp.len());
        for p in lp {
            let mut q = chart
                .to_param(&p.point)
                .ok_or("a boundary node has no parameters in its surface's chart")?;
            if let Some(prev) = uv.last() {
                for k in 0..2 {
                    if let Some(period) = periods[k] {
                        q[k] += period * ((prev[k] - q[k]) / period).round();
                    }
                }
            }
            uv.push(q);
        }
        if let (Some(first), Some(last)) = (uv.first(), uv.last()) {
            for k in 0..2 {
                if let Some(period) = periods[k]
                    && ((first[k] - last[k]) / period).round() != 0.0
                {
                    return Err("a loop winds around its periodic surface".into());
                }
            }
        }
        out.push(uv);
    }
    Ok(out)
}

/// Four corners of a square twice the loops' extent beyond their bounding
/// box: the hull of the triangulation, far from every boundary segment.
fn insert_frame(
    cdt: &mut Cdt,
    chart: &Chart,
    uv_loops: &[Vec<[f64; 2]>],
    positions: &mut Vec<Point3>,
) -> Result<(), String> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in uv_loops.iter().flatten() {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let margin = 2.0 * (hi[0] - lo[0]).max(hi[1] - lo[1]);
    for corner in [
        [lo[0] - margin, lo[1] - margin],
        [hi[0] + margin, lo[1] - margin],
        [hi[0] + margin, hi[1] + margin],
        [lo[0] - margin, hi[1] + margin],
    ] {
        let handle = cdt
            .insert(point2(corner))
            .map_err(|e| format!("the outside frame cannot be triangulated: {e:?}"))?;
        let p = chart
            .lift(corner)
            .ok_or("the outside frame does not lift onto the face's plane")?;
        if handle.index() != positions.len() {
            return Err("the outside frame meets the face".into());
        }
        positions.push(p);
    }
    Ok(())
}

/// Even–odd point-in-polygon test over all loops.
fn winding_odd(loops: &[Vec<[f64; 2]>], p: [f64; 2]) -> bool {
    let mut inside = false;
    for lp in loops {
        for (i, a) in lp.iter().enumerate() {
            let b = &lp[(i + 1) % lp.len()];
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if x > p[0] {
                    inside = !inside;
                }
            }
        }
    }
    inside
}

/// True when the face has one loop and every convex-hull edge of the
/// triangulation is one of its segments: then nothing lies outside the loop.
fn loop_is_hull(cdt: &Cdt, uv_loops: &[Vec<[f64; 2]>]) -> bool {
    uv_loops.len() == 1 && cdt.convex_hull().all(|e| e.is_constraint_edge())
}

/// True when two constraint segments (loop or poly_line) meet at a vertex at
/// an angle below `min_angle` degrees. Runs over every vertex of a face:
/// directions go to a small array (a `Vec` per vertex was 4% of a
/// 10,000-vertex polygon's meshing time) and are compared by their dot
/// product (an `atan2` per direction was another 2%); a vertex with more
/// constraint edges than fit is checked through a `Vec`.
fn has_small_input_angle(cdt: &Cdt, min_angle: f64) -> bool {
    // The angle between u and v is below the limit when u·v > cos(limit)·|u||v|
    // (the limit is at most 33°, so its cosine is positive).
    let cos_limit = min_angle.to_radians().cos();
    let small = |directions: &[[f64; 2]]| {
        directions.iter().enumerate().any(|(i, u)| {
            directions[i + 1..].iter().any(|v| {
                let dot = u[0] * v[0] + u[1] * v[1];
                dot > 0.0
                    && dot * dot
                        > cos_limit
                            * cos_limit
                            * (u[0] * u[0] + u[1] * u[1])
                            * (v[0] * v[0] + v[1] * v[1])
            })
        })
    };
    cdt.vertices().any(|v| {
        let p = v.position();
        let direction = |e: spade::handles::DirectedEdgeHandle<'_, _, _, _, _>| {
            let q: Point2<f64> = e.to().position();
            [q.x - p.x, q.y - p.y]
        };
        let mut few = [[0.0f64; 2]; 8];
        let mut count = 0;
        for e in v.out_edges().filter(|e| e.is_constraint_edge()) {
            if count == few.len() {
                let all: Vec<[f64; 2]> = v
                    .out_edges()
                    .filter(|e| e.is_constraint_edge())
                    .map(direction)
                    .collect();
                return small(&all);
            }
            few[count] = direction(e);
            count += 1;
        }
        small(&few[..count])
    })
}

/// Points one refinement call may add: enough for the area limit (about two
/// triangles per vertex, with room for grading), at least 200,000 (spade's
/// guard against non-termination), at most the face's node limit. A face
/// with an input angle below the minimum gets four points per
/// tolerance-squared of its area (the smallest triangle refined for its
/// angles there) and 1,000 more instead of the 200,000 floor: segments
/// meeting at a tiny angle keep encroaching each other, which no area
/// threshold stops.
fn vertex_budget(
    uv_loops: &[Vec<[f64; 2]>],
    max_area: f64,
    settings: &Settings,
    small_angle: bool,
) -> usize {
    let area = uv_loops.iter().map(|lp| shoelace(lp)).sum::<f64>().abs() / 2.0;
    let for_area = if max_area.is_finite() {
        2.0 * area / max_area
    } else {
        0.0
    };
    let cap = MAX_FACE_VERTICES as f64;
    if small_angle {
        let for_angles = 1_000.0 + 4.0 * area / (settings.tolerance * settings.tolerance);
        (for_area + for_angles).min(cap) as usize
    } else {
        for_area.clamp(200_000.0, cap) as usize
    }
}

/// About the nodes a face will have: its boundary nodes and one per
/// `max_area` of its chart area (refinement leaves triangles of about half
/// the limit, two per node), capped by the face's node limit.
fn expected_vertices(uv_loops: &[Vec<[f64; 2]>], max_area: f64) -> usize {
    let boundary: usize = uv_loops.iter().map(Vec::len).sum();
    let area = uv_loops.iter().map(|lp| shoelace(lp)).sum::<f64>().abs() / 2.0;
    let interior = if max_area.is_finite() && max_area > 0.0 {
        (area / max_area).min(MAX_FACE_VERTICES as f64) as usize
    } else {
        0
    };
    (boundary + interior).min(MAX_FACE_VERTICES)
}

/// Cells per side of the grid [`curved_vertices`] samples the chart on.
const ESTIMATE_GRID: usize = 24;

/// Triangles per unit of area × curvature / tolerance that the surface
/// check leaves (0.70 measured on spheres of radius 0.3 and 0.7 at 2e-5).
const TRIANGLES_PER_CURVATURE: f64 = 0.7;

/// The nodes the chordal check will give a curved face, estimated from a
/// coarse grid over its chart: each cell inside the loops contributes its
/// area on the surface times the curvature its diagonals' midpoints show
/// (a chord of length l at distance d from the surface: κ ≈ 8d / l²). The
/// triangulation and node tables are sized from it once: the area-based
/// guess was 2–5 times short on spheres, and each doubling of spade's tables
/// left the old ones resident until the face was done (a fifth of the
/// meshing peak of paper 001's seven balls). Only memory depends on it.
fn curved_vertices(
    chart: &Chart,
    uv_loops: &[Vec<[f64; 2]>],
    surface: &Surface,
    tolerance: f64,
) -> usize {
    if matches!(surface, Surface::Plane { .. }) || tolerance.is_nan() || tolerance <= 0.0 {
        return 0;
    }
    let deviation = Deviation::of(surface);
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in uv_loops.iter().flatten() {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let n = ESTIMATE_GRID;
    let step = [(hi[0] - lo[0]) / n as f64, (hi[1] - lo[1]) / n as f64];
    if !(step[0] > 0.0 && step[1] > 0.0 && step[0].is_finite() && step[1].is_finite()) {
        return 0;
    }
    let at = |i: usize, j: usize| [lo[0] + i as f64 * step[0], lo[1] + j as f64 * step[1]];
    let mut triangles = 0.0;
    for i in 0..n {
        for j in 0..n {
            let centre = [
                lo[0] + (i as f64 + 0.5) * step[0],
                lo[1] + (j as f64 + 0.5) * step[1],
            ];
            if !winding_odd(uv_loops, centre) {
                continue;
            }
            let corners = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let Some([a, b, c, d]) = corners
                .map(|uv| chart.lift(uv))
                .into_iter()
                .collect::<Option<Vec<_>>>()
                .and_then(|v| <[Point3; 4]>::try_from(v).ok())
            else {
                continue;
            };
            let area = 0.5 * ((b - a).cross(&(d - a)).norm() + (b - c).cross(&(d - c)).norm());
            let curvature = [(a, c), (b, d)]
                .iter()
                .map(|(p, q)| {
                    let chord2 = (q - p).norm_squared();
                    let mid = Point3::from((p.coords + q.coords) / 2.0);
                    let d = deviation.signed_distance(&mid).abs();
                    if chord2 > 0.0 && d.is_finite() {
                        8.0 * d / chord2
                    } else {
                        0.0
                    }
                })
                .fold(0.0, f64::max);
            triangles += TRIANGLES_PER_CURVATURE * area * curvature / tolerance;
        }
    }
    // Two triangles a node, and a third to spare: a reservation a little
    // short costs a whole doubling, one too long costs no touched memory.
    let vertices = 0.65 * triangles;
    if vertices.is_finite() {
        (vertices as usize).min(MAX_FACE_VERTICES)
    } else {
        0
    }
}

/// Boundaries from this many points on are bulk loaded (`bulk_load_loops`).
const BULK_LOAD_POINTS: usize = 4096;

/// The loops of a large boundary as one constrained triangulation, bulk
/// loaded, with vertex i the i-th loop point (loops in order). Inserting a
/// long loop point by point put every point outside the hull of the ones
/// before it: on a 10,000-point polygon that took longer than the whole
/// refinement. `None` (insert one by one, which also reports the errors)
/// for small boundaries, repeated points, crossing loops, or a loop
/// segment through another point.
fn bulk_load_loops(uv_loops: &[Vec<[f64; 2]>]) -> Option<Cdt> {
    let count: usize = uv_loops.iter().map(Vec::len).sum();
    if count < BULK_LOAD_POINTS {
        return None;
    }
    let mut points = Vec::with_capacity(count);
    let mut segments = Vec::with_capacity(count);
    for lp in uv_loops {
        let first = points.len();
        if lp.len() < 3 {
            return None;
        }
        for (i, uv) in lp.iter().enumerate() {
            points.push(point2(*uv));
            segments.push([first + i, first + (i + 1) % lp.len()]);
        }
    }
    let mut conflict = false;
    let cdt = Cdt::try_bulk_load_cdt(points, segments.clone(), |_| conflict = true).ok()?;
    let whole = !conflict
        && cdt.num_vertices() == count
        && cdt.num_constraints() == segments.len()
        && segments.iter().all(|&[a, b]| {
            cdt.get_edge_from_neighbors(
                spade::handles::FixedVertexHandle::from_index(a),
                spade::handles::FixedVertexHandle::from_index(b),
            )
            .is_some_and(|e| e.is_constraint_edge())
        });
    whole.then_some(cdt)
}

/// A first area limit for the angle refinement of a curved face, in chart
/// units: a multiple of the equilateral triangle on a long boundary
/// segment. The boundary is discretised to the same tolerance as the
/// surface, so the interior needs triangles of about that size; spade meets
/// the limit in the same sweep as the angles, and the chordal passes after
/// it only finish the places where the chart magnifies. Planes (nothing to
/// follow) get none.
fn guide_area(uv_loops: &[Vec<[f64; 2]>], surface: &Surface) -> f64 {
    if matches!(surface, Surface::Plane { .. }) {
        return f64::INFINITY;
    }
    let mut lengths: Vec<f64> = uv_loops
        .iter()
        .flat_map(|lp| {
            (0..lp.len()).map(move |i| {
                let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
                (b[0] - a[0]).hypot(b[1] - a[1])
            })
        })
        .filter(|l| *l > 0.0 && l.is_finite())
        .collect();
    if lengths.len() < 8 {
        return f64::INFINITY;
    }
    // The 90th percentile: a loop's few long straight segments (a seam) are
    // left out, and where curved edges differ (a cone's two circles) the
    // coarser one sets the limit, so no part of the face is refined beyond
    // what its own boundary asks for.
    let rank = lengths.len() * 9 / 10;
    let (_, length, _) = lengths.select_nth_unstable_by(rank, f64::total_cmp);
    GUIDE_FACTOR * 3f64.sqrt() / 4.0 * *length * *length
}

/// The parameter t ∈ (0, 1) of `p` on the segment between vertices `a` and
/// `b`, when it lies on it.
pub(super) fn on_segment(cdt: &Cdt, a: usize, b: usize, p: Point2<f64>) -> Option<f64> {
    let pa = cdt
        .vertex(spade::handles::FixedVertexHandle::from_index(a))
        .position();
    let pb = cdt
        .vertex(spade::handles::FixedVertexHandle::from_index(b))
        .position();
    let (dx, dy) = (pb.x - pa.x, pb.y - pa.y);
    let len2 = dx * dx + dy * dy;
    let t = ((p.x - pa.x) * dx + (p.y - pa.y) * dy) / len2;
    let off = ((p.x - pa.x) * dy - (p.y - pa.y) * dx).abs() / len2.sqrt();
    (t > 0.0 && t < 1.0 && off <= 1e-9 * len2.sqrt()).then_some(t)
}

/// Faces outside the loops (indexed by face index): a flood fill from the
/// convex hull that flips inside/outside when it crosses a loop segment but
/// not a poly_line.
pub(super) fn outside_faces(cdt: &Cdt, polyline_segments: &[(usize, usize)]) -> Vec<bool> {
    let mut outside: Vec<Option<bool>> = vec![None; cdt.num_all_faces()];
    let crosses_loop = |constraint: bool, ia: usize, ib: usize| {
        if !constraint {
            return false;
        }
        let (a, b) = (
            cdt.vertex(spade::handles::FixedVertexHandle::from_index(ia))
                .position(),
            cdt.vertex(spade::handles::FixedVertexHandle::from_index(ib))
                .position(),
        );
        let mid = Point2::new(0.5 * (a.x + b.x), 0.5 * (a.y + b.y));
        !polyline_segments.iter().any(|&(p, q)| {
            (p == ia && q == ib) || (p == ib && q == ia) || on_segment(cdt, p, q, mid).is_some()
        })
    };
    let mut stack = Vec::new();
    for e in cdt.convex_hull() {
        let inner = e.rev();
        if let Some(face) = inner.face().as_inner() {
            let state = !crosses_loop(
                inner.is_constraint_edge(),
                inner.from().fix().index(),
                inner.to().fix().index(),
            );
            if outside[face.fix().index()].is_none() {
                outside[face.fix().index()] = Some(state);
                stack.push(face.fix());
            }
        }
    }
    while let Some(f) = stack.pop() {
        let face = cdt.face(f);
        let state = outside[f.index()].unwrap_or(true);
        for e in face.adjacent_edges() {
            let twin = e.rev();
            if let Some(next) = twin.face().as_inner() {
                let slot = &mut outside[next.fix().index()];
                if slot.is_none() {
                    *slot = Some(
                        state
                            != crosses_loop(
                                e.is_constraint_edge(),
                                e.from().fix().index(),
                                e.to().fix().index(),
                            ),
                    );
                    stack.push(next.fix());
                }
            }
        }
    }
    outside.into_iter().map(|s| s.unwrap_or(true)).collect()
}

/// A constrained poly_line's vertices in order: its own points with the
/// points refinement added on each segment, sorted along it.
fn polyline_chain(cdt: &Cdt, fixed: usize, handles: &[usize]) -> Vec<usize> {
    let added: Vec<(usize, Point2<f64>)> = (fixed..cdt.num_vertices())
        .filter_map(|v| {
            let vertex = cdt.vertex(spade::handles::FixedVertexHandle::from_index(v));
            vertex
                .out_edges()
                .any(|e| e.is_constraint_edge())
                .then(|| (v, vertex.position()))
        })
        .collect();
    let mut chain = Vec::new();
    for w in handles.windows(2) {
        chain.push(w[0]);
        let mut on: Vec<(f64, usize)> = added
            .iter()
            .filter_map(|&(v, p)| on_segment(cdt, w[0], w[1], p).map(|t| (t, v)))
            .collect();
        on.sort_by(|x, y| x.0.total_cmp(&y.0));
        chain.extend(on.into_iter().map(|(_, v)| v));
    }
    chain.extend(handles.last().copied());
    chain
}

/// Lifts the vertices the triangulation has beyond `positions` onto the
/// surface, as interior nodes.
fn lift_new_vertices(cdt: &Cdt, chart: &Chart, positions: &mut Vec<Point3>) -> Result<(), String> {
    for v in positions.len()..cdt.num_vertices() {
        let uv = cdt
            .vertex(spade::handles::FixedVertexHandle::from_index(v))
            .position();
        let p = chart.lift([uv.x, uv.y]).ok_or_else(|| {
            format!(
                "the parameter point ({}, {}) does not lift onto its surface",
                uv.x, uv.y
            )
        })?;
        positions.push(p);
    }
    Ok(())
}

/// The surface criteria of a face's triangles: area limit (planes), longest
/// edge and chordal deviation.
struct Coarse<'a> {
    deviation: &'a Deviation<'a>,
    settings: &'a Settings<'a>,
    area_limited: bool,
}

impl Coarse<'_> {
    fn is(
        &self,
        f: spade::handles::FaceHandle<
            '_,
            spade::handles::InnerTag,
            Point2<f64>,
            (),
            spade::CdtEdge<()>,
            (),
        >,
        positions: &[Point3],
    ) -> bool {
        let [a, b, c] = f.vertices().map(|v| v.fix().index());
        if self.area_limited {
            let [pa, pb, pc] = f.positions();
            let uv_area =
                0.5 * ((pb.x - pa.x) * (pc.y - pa.y) - (pb.y - pa.y) * (pc.x - pa.x)).abs();
            if uv_area > self.settings.max_area {
                return true;
            }
        }
        too_coarse(
            self.deviation,
            [&positions[a], &positions[b], &positions[c]],
            self.settings,
        )
    }
}

/// True when a triangle is longer than `max_edge` or strays from the surface
/// by more than the tolerance. The deviation is measured at the centroid and
/// the edge midpoints, and its largest value inside the triangle is
/// estimated from the quadratic that vanishes at the corners and matches the
/// midpoints (on a sphere the deviation peaks at the circumcentre, which the
/// centroid misses on skewed triangles).
fn too_coarse(surface: &Deviation, [a, b, c]: [&Point3; 3], settings: &Settings) -> bool {
    let longest = (b - a).norm().max((c - b).norm()).max((a - c).norm());
    let size = if settings.sizing.is_uniform() {
        settings.sizing.at(a)
    } else {
        settings
            .sizing
            .at(&Point3::from((a.coords + b.coords + c.coords) / 3.0))
    };
    if longest > size {
        return true;
    }
    if matches!(surface, Deviation::Plane) {
        return false;
    }
    let mid = |p: &Point3, q: &Point3| Point3::from((p.coords + q.coords) / 2.0);
    let deviation = |p: &Point3| surface.signed_distance(p);
    let (ab, bc, ca) = (
        deviation(&mid(a, b)),
        deviation(&mid(b, c)),
        deviation(&mid(c, a)),
    );
    let centroid = deviation(&Point3::from((a.coords + b.coords + c.coords) / 3.0));
    let tolerance = settings.tolerance;
    [ab, bc, ca, centroid, quadratic_peak(ab, bc, ca)]
        .iter()
        .any(|d| d.abs() > tolerance)
}

/// The interior extremum of q = 4(m_ab λa λb + m_bc λb λc + m_ca λc λa) over
/// the triangle (barycentric λ), or 0 when it has none inside.
fn quadratic_peak(m_ab: f64, m_bc: f64, m_ca: f64) -> f64 {
    // With λc = 1 − λa − λb, ∇q = 0 is a 2×2 linear system.
    let k = m_ab - m_bc - m_ca;
    let det = 4.0 * m_bc * m_ca - k * k;
    if det.is_nan() || det.abs() <= 1e-300 {
        return 0.0;
    }
    let la = (2.0 * m_bc * m_ca + k * m_bc) / det;
    let lb = (2.0 * m_bc * m_ca + k * m_ca) / det;
    let lc = 1.0 - la - lb;
    if la < 0.0 || lb < 0.0 || lc < 0.0 {
        return 0.0;
    }
    4.0 * (m_ab * la * lb + m_bc * lb * lc + m_ca * lc * la)
}

/// A face slot with no triangle known to be fine ([`triangle_key`] never
/// gives it: its nodes would have to be equal).
const NOT_FINE: u64 = u64::MAX;

/// The sorted corner nodes of a triangle packed into 64 bits, 21 bits each
/// (`None`, so not cached, for the rare node index beyond that).
fn triangle_key(a: usize, b: usize, c: usize) -> Option<u64> {
    let mut key = [a as u64, b as u64, c as u64];
    key.sort_unstable();
    (key[2] < 1 << 21).then(|| key[0] | (key[1] << 21) | (key[2] << 42))
}

/// A face's surface, prepared once for the many distance queries of
/// refinement.
enum Deviation<'a> {
    Plane,
    Sphere { centre: Point3, radius: f64 },
    General(&'a Surface),
}

impl Deviation<'_> {
    fn of(surface: &Surface) -> Deviation<'_> {
        match surface {
            Surface::Plane { .. } => Deviation::Plane,
            Surface::Ellipsoid { frame } => match frame.similarity_scale() {
                Some(radius) => Deviation::Sphere {
                    centre: frame.origin,
                    radius,
                },
                None => Deviation::General(surface),
            },
            _ => Deviation::General(surface),
        }
    }

    /// Signed distance from the surface: exact for planes and spheres,
    /// value / |gradient| otherwise; infinite where the gradient vanishes off
    /// the surface.
    fn signed_distance(&self, p: &Point3) -> f64 {
        match self {
            Deviation::Plane => 0.0,
            Deviation::Sphere { centre, radius } => (p - centre).norm() - radius,
            Deviation::General(surface) => {
                let (value, gradient) = surface.value_and_gradient(p);
                let norm = gradient.norm();
                if value == 0.0 {
                    0.0
                } else if value.is_finite() && norm.is_finite() && norm > 0.0 {
                    value / norm
                } else {
                    f64::INFINITY
                }
            }
        }
    }
}

/// Twice the signed area of a closed polygon.
fn shoelace(points: &[[f64; 2]]) -> f64 {
    (0..points.len())
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % points.len()]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum()
}

/// Spade refuses coordinates below about 1e-43 in magnitude: such values
/// are zero for meshing purposes.
pub(super) fn point2([u, v]: [f64; 2]) -> Point2<f64> {
    let snap = |x: f64| if x.abs() < 1e-30 { 0.0 } else { x };
    Point2::new(snap(u), snap(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_peak_finds_the_interior_extremum() {
        // Equal midpoint deviations m: the peak is 4m/3 at the centroid.
        assert!((quadratic_peak(0.3, 0.3, 0.3) - 0.4).abs() < 1e-15);
        // The deviation of a chord plane under a unit sphere, q = ¼(R² − |x − c|²)·…:
        // for a right triangle the circumcentre is the hypotenuse midpoint, so
        // no interior extremum exceeds it.
        let peak = quadratic_peak(1.0, 0.5, 0.5);
        assert!(peak <= 1.0 + 1e-12, "{peak}");
        // One large midpoint value: the peak lies inside and above the others.
        let peak = quadratic_peak(1.0, 0.8, 0.8);
        assert!(peak > 1.0, "{peak}");
        assert_eq!(quadratic_peak(0.0, 0.0, 0.0), 0.0);
    }
}
