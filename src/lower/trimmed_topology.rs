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

use crate::geom::{Curve, Point3, Surface};
use crate::ir::{
    Edge, EdgeId, Face, Model, OrientedEdge, OrientedFace, SubdomainCells, Vertex, VertexId,
};
use crate::trimmed::boundary::{U_MAX, U_MIN, V_MAX, V_MIN};
use crate::trimmed::shared::{bbox, distance_to_polyline, nearest_point};
use crate::trimmed::topology::{Piece, pieces};

/// Appends the vertices, edges and faces of `model.trimmed` (3D models).
pub fn add(model: &mut Model) {
    if model.trimmed.is_empty() || model.trimmed_start.is_some() {
        return;
    }
    let start = [model.vertices.len(), model.edges.len(), model.faces.len()];
    let first_vertex = 0;
    let tol = 2.0 * model.tolerance;
    let surfaces = model.trimmed.clone();
    let mut faces = Vec::with_capacity(surfaces.len());
    for s in &surfaces {
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
                model.edges.push(Edge {
                    name: format!("{}.{}[{}]", s.name, SIDE_NAMES[slot], counts[slot]),
                    curve: Curve::Chain {
                        points: piece.points.clone(),
                    },
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
            name: s.name.clone(),
            surface: Surface::Parametric(Box::new(s.clone())),
            reversed: false,
            loops: chain_loops(&oriented),
        });
    }
    let first_face = model.faces.len();
    model.faces.extend(faces);
    for sub in &mut model.subdomains {
        if let SubdomainCells::Volume { boundary } = &mut sub.cells {
            for &k in &sub.trimmed {
                boundary.push(OrientedFace {
                    face: crate::ir::FaceId((first_face + k) as u32),
                    outward: true,
                });
            }
        }
    }
    model.trimmed_start = Some(start);
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
        name: format!("{surface}.vertex[{count}]"),
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
        if e.begin != e.end || (piece.side != 0 && !e.name.contains(".trim[")) {
            continue;
        }
        let line = match &e.curve {
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
