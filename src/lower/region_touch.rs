//! Regions touching a kernel edge at a point (issue 6): a 2D R-function
//! region whose contour comes to a kernel edge without running along it (a
//! disk against a kernel circle or a square's side, tangent there) shares one
//! vertex with it. The touch point is found on the kernel curve where the
//! region's function is largest (its contour's tangency), the contour vertex
//! nearest it is moved there (or becomes the kernel vertex it falls on), and
//! the kernel edge is split at it, so both meshes have that node.
//!
//! Only a touch is taken: a short run of contour vertices within the touch
//! distance of the edge (as short as a tangency's), at most one of them on
//! it and no chord on it (a
//! contour running along an edge is `region_arcs`' case), next to no vertex
//! the region shares with the kernel already. Anything else stays with the
//! checks (E543, E407).

use super::region_arcs::{KernelCurve, ON_ARC_FRACTION, extent, split_kernel_edge};
use crate::geom::{Curve, Point3};
use crate::ir::{EdgeId, FaceId, Model, OrientedEdge, SourceMap, VertexId};
use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::TAU;

/// Golden-section steps for the touch point: 0.618⁸⁰ of a chord's parameter
/// span is far below the model tolerance.
const SEARCH_STEPS: usize = 80;

/// A kernel edge a region may touch, with the kernel subdomains using it.
pub(super) struct KernelEdge {
    pub(super) edge: EdgeId,
    pub(super) curve: KernelCurve,
    pub(super) subdomains: Vec<usize>,
}

/// Where a region vertex goes: onto the kernel edge at parameter `u`, or
/// onto an existing kernel vertex.
pub(super) enum Landing {
    Split { edge: EdgeId, u: f64, at: Point3 },
    Merge(VertexId),
}

/// Joins each region that touches a kernel edge at a point to it (moved
/// vertex, split edge). `reported` pairs (kernel subdomain, region) are left
/// alone. Returns the region vertices of the touches, which the overlap and
/// touch checks must not count against the pair.
pub(super) fn share_touch_points(
    model: &mut Model,
    source_map: &mut SourceMap,
    first_region: usize,
    touch_of: impl Fn(&Model, usize) -> f64,
    reported: &BTreeSet<(usize, usize)>,
) -> BTreeSet<VertexId> {
    let n = model.subdomains.len();
    let region_edges: BTreeSet<EdgeId> =
        super::region_interfaces::face_edges(model, first_region..n).collect();
    let mut users: BTreeMap<EdgeId, Vec<usize>> = BTreeMap::new();
    for k in 0..first_region {
        for e in super::region_interfaces::face_edges(model, k..k + 1) {
            if !region_edges.contains(&e) {
                users.entry(e).or_default().push(k);
            }
        }
    }
    let kernel: Vec<KernelEdge> = users
        .into_iter()
        .filter_map(|(edge, mut subdomains)| {
            subdomains.dedup();
            KernelCurve::of(&model.edge_curve(edge)).map(|curve| KernelEdge {
                edge,
                curve,
                subdomains,
            })
        })
        .collect();
    if kernel.is_empty() {
        return BTreeSet::new();
    }
    let kernel_vertices: BTreeSet<VertexId> = kernel
        .iter()
        .flat_map(|k| [model.edge(k.edge).begin, model.edge(k.edge).end])
        .chain(
            super::region_interfaces::face_edges(model, 0..first_region)
                .flat_map(|e| [model.edge(e).begin, model.edge(e).end]),
        )
        .collect();
    let mut landings: BTreeMap<VertexId, Landing> = BTreeMap::new();
    let mut touched = BTreeSet::new();
    for r in first_region..n {
        let Some(fr) = super::region_interfaces::face_of(model, r) else {
            continue;
        };
        let touch = touch_of(model, r);
        let loops: Vec<Vec<OrientedEdge>> = model.faces[fr.index()].loops.to_vecs();
        for lp in &loops {
            for k in &kernel {
                // A region carved from or running along the kernel face is
                // the other modules' case.
                if k.subdomains.iter().any(|&s| reported.contains(&(s, r))) {
                    continue;
                }
                for run in near_runs(model, lp, &k.curve, touch, &kernel_vertices) {
                    let Some((v, landing)) = land(model, lp, &run, k, (fr, touch)) else {
                        continue;
                    };
                    // One landing per vertex, one vertex per kernel vertex: a
                    // touch at a kernel vertex is seen from both its edges.
                    let same = |l: &Landing| matches!((l, &landing), (Landing::Merge(a), Landing::Merge(b)) if a == b);
                    let seen = landings.values().any(same);
                    if seen || !landings.contains_key(&v) {
                        touched.extend(run.iter().map(|&i| vertex_at(model, lp, i)));
                    }
                    if !seen && !landings.contains_key(&v) {
                        landings.insert(v, landing);
                    }
                }
            }
        }
    }
    if landings.is_empty() {
        return touched;
    }
    apply(
        model,
        source_map,
        &kernel,
        landings,
        BTreeMap::new(),
        touched,
    )
}

/// The loop's vertex i (the start of its piece i).
pub(super) fn vertex_at(model: &Model, lp: &[OrientedEdge], i: usize) -> VertexId {
    let oe = lp[i % lp.len()];
    let e = model.edge(oe.edge);
    if oe.forward { e.begin } else { e.end }
}

/// The nearest point of the kernel edge to p: (parameter, distance).
pub(super) fn nearest(curve: &KernelCurve, p: &Point3) -> (f64, f64) {
    let span = curve.span();
    let u = curve.parameter(p);
    let u = if (0.0..=span).contains(&u) {
        u
    } else if (curve.point(0.0) - p).norm() <= (curve.point(span) - p).norm() {
        0.0
    } else {
        span
    };
    (u, (curve.point(u) - p).norm())
}

/// The maximal cyclic runs of loop vertices (as indices) within `touch` of
/// the kernel edge, none of them and neither neighbour a kernel vertex.
pub(super) fn near_runs(
    model: &Model,
    lp: &[OrientedEdge],
    curve: &KernelCurve,
    touch: f64,
    kernel_vertices: &BTreeSet<VertexId>,
) -> Vec<Vec<usize>> {
    let n = lp.len();
    let vertices: Vec<VertexId> = (0..n).map(|i| vertex_at(model, lp, i)).collect();
    let near: Vec<bool> = vertices
        .iter()
        .map(|&v| nearest(curve, &model.vertex(v).position).1 <= touch)
        .collect();
    if near.iter().all(|&x| x) {
        return Vec::new();
    }
    let mut runs = Vec::new();
    for start in 0..n {
        if !near[start] || near[(start + n - 1) % n] {
            continue;
        }
        let len = (0..n).take_while(|i| near[(start + i) % n]).count();
        let shared = (0..len + 2)
            .map(|i| vertices[(start + n - 1 + i) % n])
            .any(|v| kernel_vertices.contains(&v));
        if !shared {
            runs.push((start..start + len).collect());
        }
    }
    runs
}

/// Where a touch run meets the kernel edge and which of its vertices goes
/// there; None when the run is no single touch (more than one vertex or any
/// chord on the edge) or the touch point lies away from the run.
pub(super) fn land(
    model: &Model,
    lp: &[OrientedEdge],
    run: &[usize],
    k: &KernelEdge,
    (face, touch): (FaceId, f64),
) -> Option<(VertexId, Landing)> {
    let on = ON_ARC_FRACTION * extent(model, face);
    let n = lp.len();
    let position = |i: usize| model.vertex(vertex_at(model, lp, i)).position;
    let on_edge = run
        .iter()
        .filter(|&&i| nearest(&k.curve, &position(i)).1 <= on)
        .count();
    let chord_on = run[..run.len() - 1]
        .iter()
        .any(|&i| nearest(&k.curve, &model.edge_curve(lp[i % n].edge).point(0.5)).1 <= on);
    if on_edge > 1 || chord_on {
        return None;
    }
    let closest = *run.iter().min_by(|&&a, &&b| {
        let d = |i| nearest(&k.curve, &position(i)).1;
        d(a).total_cmp(&d(b))
    })?;
    // Near a tangency the gap grows as s²/(2ρ) with the distance s from
    // it; ρ below the region's extent keeps the run within √(2·touch·extent)
    // of its closest vertex. A longer run follows the edge without lying on it.
    let reach = (2.0 * touch * extent(model, face)).sqrt();
    if run
        .iter()
        .any(|&i| (position(i) - position(closest)).norm() > reach)
    {
        return None;
    }
    let (before, after) = (closest + n - 1, closest + 1);
    let u0 = nearest(&k.curve, &position(closest)).0;
    // The search window: as far along the edge as the neighbours reach.
    let reach = [before, after]
        .iter()
        .map(|&i| unwrap(&k.curve, nearest(&k.curve, &position(i)).0 - u0).abs())
        .fold(0.0, f64::max);
    let f =
        [lp[before % n], lp[closest % n]]
            .iter()
            .find_map(|oe| match &*model.edge_curve(oe.edge) {
                Curve::Contour { f, .. } => Some(f.clone()),
                _ => None,
            });
    let u = match f {
        Some(f) => {
            let g = |u: f64| {
                let p = k.curve.point(u);
                f.eval_point([p.x, p.y, p.z])
            };
            normalise(&k.curve, peak(&g, u0 - reach, u0 + reach))
        }
        None => u0,
    };
    let at = k.curve.point(u);
    // The vertex nearest the touch point goes there; it must be one of the
    // run's chords away at most.
    let chord = [before, closest]
        .iter()
        .map(|&i| (position(i) - position(i + 1)).norm())
        .fold(0.0, f64::max);
    let i = [before, closest, after].into_iter().min_by(|&a, &b| {
        (position(a) - at)
            .norm()
            .total_cmp(&(position(b) - at).norm())
    })?;
    if (position(i) - at).norm() > chord {
        return None;
    }
    let v = vertex_at(model, lp, i);
    let merge = 16.0 * model.tolerance;
    let edge = model.edge(k.edge);
    let landing = [edge.begin, edge.end]
        .into_iter()
        .find(|&w| (model.vertex(w).position - at).norm() <= merge)
        .map(Landing::Merge)
        .unwrap_or(Landing::Split {
            edge: k.edge,
            u,
            at,
        });
    Some((v, landing))
}

/// A parameter difference on a closed arc taken the short way round.
fn unwrap(curve: &KernelCurve, du: f64) -> f64 {
    if curve.is_line() {
        du
    } else {
        (du + TAU / 2.0).rem_euclid(TAU) - TAU / 2.0
    }
}

/// A parameter of the search brought back onto the edge.
fn normalise(curve: &KernelCurve, u: f64) -> f64 {
    let span = curve.span();
    if !curve.is_line() && span >= TAU * (1.0 - 1e-12) {
        u.rem_euclid(TAU)
    } else {
        u.clamp(0.0, span)
    }
}

/// The maximum of g on [a, b] by golden-section search (g is the region's
/// function along the edge, largest at the tangency).
fn peak(g: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - ratio * (b - a), a + ratio * (b - a));
    let (mut gc, mut gd) = (g(c), g(d));
    for _ in 0..SEARCH_STEPS {
        if gc >= gd {
            (b, d, gd) = (d, c, gc);
            c = b - ratio * (b - a);
            gc = g(c);
        } else {
            (a, c, gc) = (c, d, gd);
            d = a + ratio * (b - a);
            gd = g(d);
        }
    }
    (a + b) / 2.0
}

/// Moves or merges the touching vertices, splits the kernel edges at the
/// moved ones (and at the further `cuts`, new vertices) and drops the
/// merged ones. Returns `touched` renumbered.
pub(super) fn apply(
    model: &mut Model,
    source_map: &mut SourceMap,
    kernel: &[KernelEdge],
    landings: BTreeMap<VertexId, Landing>,
    mut cuts: BTreeMap<EdgeId, Vec<(f64, VertexId)>>,
    touched: BTreeSet<VertexId>,
) -> BTreeSet<VertexId> {
    let mut merged: BTreeMap<VertexId, VertexId> = BTreeMap::new();
    let moved: BTreeSet<VertexId> = landings.keys().copied().collect();
    for (v, landing) in landings {
        match landing {
            Landing::Split { edge, u, at } => {
                model.vertices[v.index()].position = at;
                cuts.entry(edge).or_default().push((u, v));
            }
            Landing::Merge(w) => {
                merged.insert(v, w);
            }
        }
    }
    for k in kernel {
        if let Some(mut list) = cuts.remove(&k.edge) {
            list.sort_by(|a, b| a.0.total_cmp(&b.0));
            let chain = split_kernel_edge(model, source_map, k.edge, &k.curve, &list);
            super::region_interfaces::replace_edge(model, k.edge, &chain);
        }
    }
    // The region's pieces at a moved or merged vertex end there.
    for e in 0..model.edges.len() {
        let edge = &mut model.edges[e];
        if !moved.contains(&edge.begin) && !moved.contains(&edge.end) {
            continue;
        }
        for v in [&mut edge.begin, &mut edge.end] {
            if let Some(&w) = merged.get(v) {
                *v = w;
            }
        }
        super::edge_parts::follow_vertices(model, EdgeId(e as u32));
    }
    let keep_edge = vec![true; model.edges.len()];
    let keep_vertex: Vec<bool> = (0..model.vertices.len())
        .map(|v| !merged.contains_key(&VertexId(v as u32)))
        .collect();
    super::prune::drop_entities(model, source_map, &keep_edge, &keep_vertex);
    // Ids after the drop: each loses the number of dropped ones before it.
    touched
        .into_iter()
        .map(|v| merged.get(&v).copied().unwrap_or(v))
        .map(|v| {
            let before = merged.keys().take_while(|&&w| w < v).count() as u32;
            VertexId(v.0 - before)
        })
        .collect()
}
