//! Trimmed surfaces in the topology IR (issue 9): each surface becomes a
//! `Face` (`Surface::Parametric`) whose loops are its boundary pieces
//! (`trimmed::topology`): trim curves and patch sides as edges
//! (`Curve::Chain`, named `S.trim[k]`, `S.u_min[k]`, …) between vertices at
//! the pieces' ends (`S.vertex[k]`). A closed trim piece that runs along a
//! closed model edge or a closed piece of an earlier surface uses that edge
//! (as the mesh shares its nodes, `trimmed/shared.rs`); ends welded with
//! existing vertices within twice the tolerance. A subdomain whose `faces=`
//! names the surface lists its face, outward provisionally: the outward
//! side is settled on the mesh (`meshing/trimmed_shell.rs`). The entities
//! are appended after every other (`Model::trimmed_start`), so the chart
//! mesher can leave them out.

use crate::diag::{Code, Diagnostics};
use crate::geom::{Curve, Point3, Surface};
use crate::ir::SourceMap;
use crate::ir::{
    Carrier, Edge, EdgeId, Face, FaceId, Model, OrientedEdge, OrientedFace, SubdomainCells, Vertex,
    VertexId,
};
use crate::trimmed::boundary::{U_MAX, U_MIN, V_MAX, V_MIN};
use crate::trimmed::shared::{bbox, distance_to_polyline, nearest_point};
use crate::trimmed::topology::{Piece, pieces};

/// Appends the vertices, edges and faces of `model.trimmed` (3D models),
/// refusing pieces that lie along another face's edge without sharing it
/// (E743, E744), and sets the trimmed faces' outward flags.
pub fn add(model: &mut Model, source_map: &SourceMap, diags: &mut Diagnostics) {
    if model.trimmed.is_empty() || model.trimmed_start.is_some() {
        return;
    }
    let start = [model.vertices.len(), model.edges.len(), model.faces.len()];
    let first_vertex = 0;
    let tol = 2.0 * model.tolerance;
    let surfaces = model.trimmed.clone();
    let mut faces = Vec::with_capacity(surfaces.len());
    for (j, s) in surfaces.iter().enumerate() {
        let span = source_map.trimmed.get(j).copied();
        let own_edges = model.edges.len();
        let loops = pieces(s, model.tolerance).unwrap_or_default();
        let mut counts = [0usize; 5];
        let mut vertex_count = 0usize;
        let mut oriented: Vec<(OrientedEdge, VertexId, VertexId)> = Vec::new();
        for lp in &loops {
            for piece in lp {
                let Some((&a, &b)) = piece.points.first().zip(piece.points.last()) else {
                    continue;
                };
                let closed = (a - b).norm() <= tol;
                let shared = closed.then(|| shared_edge(model, piece)).flatten();
                if let Some(oe) = shared {
                    let v = model.edges[oe.edge.index()].begin;
                    oriented.push((oe, v, v));
                    continue;
                }
                let begin = vertex(model, first_vertex, a, tol, &s.name, &mut vertex_count);
                let end = if closed {
                    begin
                } else {
                    vertex(model, first_vertex, b, tol, &s.name, &mut vertex_count)
                };
                let slot = side_slot(piece.side);
                counts[slot] += 1;
                let name = format!("{}.{}[{}]", s.name, SIDE_NAMES[slot], counts[slot]);
                if let Some((other, share)) = along_other_edge(model, own_edges, piece, tol) {
                    refuse(model, diags, span, s, &name, piece.side, other, share);
                }
                model.edges.push(Edge {
                    name: name.into(),
                    carrier: Carrier::own(Curve::Chain {
                        points: piece.points.clone(),
                    }),
                    begin,
                    end,
                });
                let oe = OrientedEdge {
                    edge: EdgeId((model.edges.len() - 1) as u32),
                    forward: true,
                };
                oriented.push((oe, begin, end));
            }
        }
        faces.push(Face {
            name: s.name.as_str().into(),
            carrier: Carrier::own(Surface::Parametric(Box::new(s.clone()))),
            reversed: false,
            loops: chain_loops(&oriented).into(),
        });
    }
    let first_face = model.faces.len();
    model.faces.extend(faces);
    // The outward flags as for any face list: propagated across shared
    // edges from the shell's faces, the sign fixed by the enclosed volume.
    for k in 0..model.subdomains.len() {
        let sub = &model.subdomains[k];
        let SubdomainCells::Volume { boundary } = &sub.cells else {
            continue;
        };
        if sub.trimmed.is_empty() {
            continue;
        }
        let mut ids: Vec<FaceId> = boundary.iter().map(|of| of.face).collect();
        ids.extend(sub.trimmed.iter().map(|&t| FaceId((first_face + t) as u32)));
        let oriented: Vec<OrientedFace> = super::booleans::orient_shell(model, &ids);
        if let SubdomainCells::Volume { boundary } = &mut model.subdomains[k].cells {
            *boundary = oriented;
        }
    }
    model.trimmed_start = Some(start);
}

/// A piece of a trimmed surface's boundary that runs along an edge it does
/// not share, for part of the piece's length (a crossing is no run): the
/// edge and the length of the run against the piece's length.
fn along_other_edge(
    model: &Model,
    own_edges: usize,
    piece: &Piece,
    tol: f64,
) -> Option<(EdgeId, (f64, f64))> {
    let own = &piece.points;
    let length: f64 = own.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    let longest = |l: &[Point3]| {
        l.windows(2)
            .map(|w| (w[1] - w[0]).norm())
            .fold(0.0, f64::max)
    };
    let (lo, hi) = bbox(own);
    for (i, e) in model.edges.iter().enumerate().take(own_edges) {
        let line = match &*e.curve(&model.solids) {
            Curve::Chain { points } => points.clone(),
            c => c.samples(1024),
        };
        let d = tol + 0.05 * longest(&line).max(longest(own));
        let (a, b) = bbox(&line);
        if (0..3).any(|k| a[k] > hi[k] + d || b[k] < lo[k] - d) {
            continue;
        }
        // The longest run of consecutive piece points near the edge.
        let (mut best, mut run, mut count, mut best_count) = (0.0f64, 0.0, 0usize, 0usize);
        for (k, p) in own.iter().enumerate() {
            if distance_to_polyline(&line, p) <= d {
                if count > 0 {
                    run += (own[k] - own[k - 1]).norm();
                }
                count += 1;
                if run > best {
                    (best, best_count) = (run, count);
                }
            } else {
                (run, count) = (0.0, 0);
            }
        }
        if best_count >= 3 && best > (20.0 * d).max(0.02 * length) {
            return Some((EdgeId(i as u32), (best, length)));
        }
    }
    None
}

/// Reports a piece along another face's edge (E743 for a trim curve, E744
/// for a patch side).
#[allow(clippy::too_many_arguments)]
fn refuse(
    model: &Model,
    diags: &mut Diagnostics,
    span: Option<crate::span::Span>,
    s: &crate::trimmed::TrimmedSurface,
    piece: &str,
    side: u8,
    other: EdgeId,
    (run, length): (f64, f64),
) {
    let edge = &model.edges[other.index()];
    let faces: Vec<String> = model
        .faces
        .iter()
        .filter(|f| f.loops.iter().flatten().any(|oe| oe.edge == other))
        .map(|f| format!("`{}`", f.name))
        .collect();
    let of_faces = match faces.as_slice() {
        [] => String::new(),
        [f] => format!(" of face {f}"),
        fs => format!(" of faces {}", fs.join(" and ")),
    };
    let share = format!("{:.0}%", 100.0 * run / length.max(f64::MIN_POSITIVE));
    if side == 0 {
        diags.error(
            Code::TrimmedPartlyShared,
            span,
            format!(
                "the trim curve `{piece}` of surface `{}` runs along edge `{}`{of_faces} for {share} of its length without being that edge; only a whole closed trim loop on a whole closed edge is shared: make the trim loop coincide with the whole edge within twice the tolerance, or move it clear of the edge",
                s.name, edge.name
            ),
        );
    } else {
        diags.error(
            Code::TrimmedSideOnEdge,
            span,
            format!(
                "the patch side `{piece}` of surface `{}` lies along edge `{}`{of_faces} ({share} of the side); patch sides keep their own nodes, so the faces would not meet: extend the parameter rectangle past the edge and trim it back with a <trim> whose loop is the whole edge",
                s.name, edge.name
            ),
        );
    }
}

const SIDE_NAMES: [&str; 5] = ["trim", "u_min", "u_max", "v_min", "v_max"];

fn side_slot(side: u8) -> usize {
    match side {
        U_MIN => 1,
        U_MAX => 2,
        V_MIN => 3,
        V_MAX => 4,
        _ => 0,
    }
}

/// An existing vertex within `tol` of `p`, else a new one named after the surface.
fn vertex(
    model: &mut Model,
    first: usize,
    p: Point3,
    tol: f64,
    surface: &str,
    count: &mut usize,
) -> VertexId {
    if let Some(i) = model.vertices[first..]
        .iter()
        .position(|v| (v.position - p).norm() <= tol)
    {
        return VertexId((first + i) as u32);
    }
    *count += 1;
    model.vertices.push(Vertex {
        name: format!("{surface}.vertex[{count}]").into(),
        position: p,
    });
    VertexId((model.vertices.len() - 1) as u32)
}

/// A closed edge of the model the closed piece runs along: every piece
/// point within a small distance of the edge (its samples, or its chain),
/// and the two bounding boxes alike. The distance allows for the coarser
/// polyline's chords: 5% of its longest segment. As the mesh shares only
/// closed trim loops (`trimmed/shared.rs`), a closed trim piece may take any
/// closed edge, a closed patch side only an earlier surface's trim loop.
fn shared_edge(model: &Model, piece: &Piece) -> Option<OrientedEdge> {
    let own = &piece.points;
    let longest = |l: &[Point3]| {
        l.windows(2)
            .map(|w| (w[1] - w[0]).norm())
            .fold(0.0, f64::max)
    };
    for (i, e) in model.edges.iter().enumerate() {
        if e.begin != e.end || (piece.side != 0 && !e.name.to_string().contains(".trim[")) {
            continue;
        }
        let line = match &*e.curve(&model.solids) {
            Curve::Chain { points } => points.clone(),
            c => c.samples(1024),
        };
        let d = 0.05 * longest(&line).max(longest(own));
        let (a, b) = (bbox(own), bbox(&line));
        if line.len() < 4
            || own.len() < 4
            || (0..3).any(|k| (a.0[k] - b.0[k]).abs() > d || (a.1[k] - b.1[k]).abs() > d)
        {
            continue;
        }
        let near = |p: &Point3, l: &[Point3]| distance_to_polyline(l, p) <= d;
        if !(own.iter().all(|p| near(p, &line)) && line.iter().all(|p| near(p, own))) {
            continue;
        }
        // The direction: the index steps along the edge's points from the
        // piece's first point to a point an eighth of the way along it.
        let n = line.len() - 1;
        let i0 = nearest_point(&line[..n], &own[0]) as i64;
        let i1 = nearest_point(&line[..n], &own[(own.len() / 8).max(1)]) as i64;
        let n = n as i64;
        let step = (i1 - i0 + n + n / 2).rem_euclid(n) - n / 2;
        return Some(OrientedEdge {
            edge: EdgeId(i as u32),
            forward: step >= 0,
        });
    }
    None
}

/// The face's loops: the oriented pieces chained end to begin (a closed
/// piece is a loop of its own); a chain that does not close is kept as it
/// is (the validator reports it).
fn chain_loops(pieces: &[(OrientedEdge, VertexId, VertexId)]) -> Vec<Vec<OrientedEdge>> {
    let ends = |k: usize| {
        let (oe, b, e) = pieces[k];
        if oe.forward { (b, e) } else { (e, b) }
    };
    let mut used = vec![false; pieces.len()];
    let mut loops = Vec::new();
    while let Some(first) = used.iter().position(|u| !u) {
        used[first] = true;
        let (start, mut at) = ends(first);
        let mut lp = vec![pieces[first].0];
        while at != start {
            let Some(next) = (0..pieces.len()).find(|&k| !used[k] && ends(k).0 == at) else {
                break;
            };
            used[next] = true;
            lp.push(pieces[next].0);
            at = ends(next).1;
        }
        loops.push(lp);
    }
    loops
}
