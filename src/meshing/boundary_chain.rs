//! The boundary points one refinement call added to a face, found through
//! the triangulation's constraint edges, and their move onto curved edges.
//!
//! Spade splits an encroached boundary segment on its chord. On a straight
//! edge that point is on the edge already; on a curve it is not, so the
//! chord points of one segment are replaced by points on the curve at the
//! same parameters, in the same triangulation (the constraint chain is cut
//! out and put back through the new points), and refinement goes on from
//! there instead of meshing the face again from scratch.
//!
//! # Guarantees
//! - A chain's points are found by walking its constraint edges from each
//!   new point to the nearest checked ones, so the cost is the chain's
//!   length, not the number of boundary segments.
//! - A move that spade cannot represent (a point landing on a node or on
//!   another constraint, a new segment crossing one) is reported, and the
//!   caller falls back to sending the splits back for a new meshing round.

use super::chart::Chart;
use super::face::{Cdt, Segments, on_segment, point2};
use crate::geom::Point3;
use crate::ir::Model;
use spade::handles::FixedVertexHandle;
use spade::{Point2, Triangulation};
use std::collections::HashSet;

/// The new points on one former boundary segment `ends[0]`–`ends[1]`
/// (checked vertices), in order from `ends[0]`.
pub(super) struct Chain {
    pub edge: usize,
    pub ends: [usize; 2],
    pub s_ends: [f64; 2],
    /// Each point: its position in the chart, its curve parameter, and its
    /// node on the curve once moved there.
    pub inner: Vec<(Point2<f64>, f64, Option<Point3>)>,
}

fn vertex(cdt: &Cdt, v: usize) -> Point2<f64> {
    cdt.vertex(FixedVertexHandle::from_index(v)).position()
}

/// The vertices joined to `v` by constraint edges: the first two, and how
/// many there are (no allocation: this runs for every new vertex of a
/// face, hundreds of thousands under an area limit).
fn constraint_neighbours(cdt: &Cdt, v: usize) -> ([usize; 2], usize) {
    let mut found = [usize::MAX; 2];
    let mut count = 0;
    for e in cdt
        .vertex(FixedVertexHandle::from_index(v))
        .out_edges()
        .filter(|e| e.is_constraint_edge())
    {
        if let Some(slot) = found.get_mut(count) {
            *slot = e.to().fix().index();
        }
        count += 1;
    }
    (found, count)
}

/// The chains of vertices from index `first` on that refinement put on
/// boundary segments (`segments` holds every boundary segment between
/// vertices below `first`). `candidates`, when given, are the only new
/// vertices that can be on a segment (ascending; geomc's own refinement
/// records the ones it put there), so the others need no look. `known`
/// (ascending) are new vertices already in `segments` (put on a curve by
/// the refinement): chains end at them as at checked ones.
pub(super) fn chains(
    cdt: &Cdt,
    first: usize,
    candidates: Option<&[usize]>,
    known: &[usize],
    segments: &Segments,
    polyline_segments: &[(usize, usize)],
) -> Result<Vec<Chain>, String> {
    const AWAY: &str = "refinement put a node on its boundary away from every edge";
    let mut seen: HashSet<usize> = HashSet::new();
    let mut chains = Vec::new();
    let all: Vec<usize>;
    let candidates = match candidates {
        Some(c) => c,
        None => {
            all = (first..cdt.num_vertices()).collect();
            &all
        }
    };
    for &w in candidates {
        if w < first || seen.contains(&w) || known.binary_search(&w).is_ok() {
            continue;
        }
        let (around, count) = constraint_neighbours(cdt, w);
        if count == 0 {
            continue;
        }
        let p = vertex(cdt, w);
        if polyline_segments
            .iter()
            .any(|&(a, b)| on_segment(cdt, a, b, p).is_some())
        {
            continue;
        }
        if count != 2 {
            return Err(AWAY.to_string());
        }
        let [left, right] = around;
        // Walk each way to the first checked vertex.
        let walk = |start: usize| -> Result<(Vec<usize>, usize), String> {
            let (mut prev, mut cur, mut path) = (w, start, Vec::new());
            while cur >= first && known.binary_search(&cur).is_err() {
                if path.len() > cdt.num_vertices() {
                    return Err(AWAY.to_string());
                }
                path.push(cur);
                let next = match constraint_neighbours(cdt, cur) {
                    ([a, b], 2) if a == prev => b,
                    ([a, b], 2) if b == prev => a,
                    _ => return Err(AWAY.to_string()),
                };
                (prev, cur) = (cur, next);
            }
            Ok((path, cur))
        };
        let (mut before, x) = walk(left)?;
        let (after, y) = walk(right)?;
        before.reverse();
        before.push(w);
        before.extend(after);
        let &(edge, s_lo, s_hi) = segments.get(&(x.min(y), x.max(y))).ok_or(AWAY)?;
        let (sx, sy) = if x < y { (s_lo, s_hi) } else { (s_hi, s_lo) };
        let mut inner = Vec::with_capacity(before.len());
        for &v in &before {
            seen.insert(v);
            let t = on_segment(cdt, x, y, vertex(cdt, v)).ok_or(AWAY)?;
            inner.push((vertex(cdt, v), sx + t * (sy - sx), None));
        }
        chains.push(Chain {
            edge,
            ends: [x, y],
            s_ends: [sx, sy],
            inner,
        });
    }
    Ok(chains)
}

/// Replaces the chord points of `chain` by points on its curve: removes
/// them (with their constraint edges), inserts the curve points and
/// constrains the chain through them. `None` when spade cannot take the
/// move (the triangulation is then spoilt for this face).
pub(super) fn move_onto_curve(
    cdt: &mut Cdt,
    chart: &Chart,
    model: &Model,
    chain: &mut Chain,
) -> Option<()> {
    let curve = model.edges.get(chain.edge)?.curve(&model.solids);
    for (uv, _, _) in &chain.inner {
        let handle = cdt.locate_vertex(*uv)?.fix();
        // Removal moves the last vertex into the freed slot: the checked
        // vertices (chain ends included) sit below every new one.
        cdt.remove(handle);
    }
    let mut handles = vec![chain.ends[0]];
    for (uv, s, node) in &mut chain.inner {
        let p = curve.point(*s);
        let before = cdt.num_vertices();
        let handle = cdt.insert(point2(chart.to_param(&p)?)).ok()?;
        if cdt.num_vertices() != before + 1 {
            return None;
        }
        *uv = cdt.vertex(handle).position();
        *node = Some(p);
        handles.push(handle.index());
    }
    handles.push(chain.ends[1]);
    for w in handles.windows(2) {
        let (a, b) = (
            FixedVertexHandle::from_index(w[0]),
            FixedVertexHandle::from_index(w[1]),
        );
        if !cdt.can_add_constraint(a, b) {
            return None;
        }
        cdt.add_constraint(a, b);
    }
    // A point that fell on another constraint split it: not a chain.
    handles[1..handles.len() - 1]
        .iter()
        .all(|&v| constraint_neighbours(cdt, v).1 == 2)
        .then_some(())
}

/// The chain's points as vertex indices (found again by position: moves on
/// other chains may have renumbered them).
pub(super) fn indices(cdt: &Cdt, chain: &Chain) -> Option<Vec<usize>> {
    chain
        .inner
        .iter()
        .map(|(uv, _, _)| cdt.locate_vertex(*uv).map(|h| h.fix().index()))
        .collect()
}

/// Replaces the chain's former segment in `segments` by its pieces.
pub(super) fn update_segments(segments: &mut Segments, chain: &Chain, indices: &[usize]) {
    let [x, y] = chain.ends;
    segments.remove(&(x.min(y), x.max(y)));
    let nodes: Vec<(usize, f64)> = std::iter::once((x, chain.s_ends[0]))
        .chain(indices.iter().zip(&chain.inner).map(|(&v, i)| (v, i.1)))
        .chain(std::iter::once((y, chain.s_ends[1])))
        .collect();
    for w in nodes.windows(2) {
        let ((a, sa), (b, sb)) = (w[0], w[1]);
        let entry = if a < b {
            (chain.edge, sa, sb)
        } else {
            (chain.edge, sb, sa)
        };
        segments.insert((a.min(b), a.max(b)), entry);
    }
}
