//! Edge discretisation: each model edge becomes one polyline shared by every
//! face that uses it, so the face meshes conform along it.
//!
//! # Guarantees
//! - The first and last points are the edge's vertex positions exactly; the
//!   others lie on the curve (`Curve::point`/`samples`).
//! - Every chord deviates from the curve by at most the given tolerance,
//!   judged at the curve point halfway in parameter between the chord's ends
//!   after uniform doubling, and is no longer than `max_edge`.
//! - Closed edges get at least three segments and arcs at least two, so no
//!   loop collapses to a segment.
//!
//! # Limitations
//! - Deviation is measured at parameter midpoints only: wiggles finer than the
//!   sampling go unseen (not a concern for segments, conics and intersection
//!   curves of quadrics).

use super::MeshError;
use crate::geom::point_calculus::adaptive_samples;
use crate::geom::{Curve, Point3};
use crate::ir::{Edge, Model};

/// Largest number of segments tried for one edge.
const MAX_SEGMENTS: usize = 1 << 16;

/// An edge's discretisation: curve parameters s ∈ [0, 1] ascending and the
/// points there.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct EdgeNodes {
    pub params: Vec<f64>,
    pub points: Vec<Point3>,
}

/// Discretises `edge` to chordal `tolerance` and chord length `max_edge`.
pub(crate) fn discretise(
    model: &Model,
    edge: &Edge,
    tolerance: f64,
    max_edge: f64,
) -> Result<EdgeNodes, MeshError> {
    let failed = |reason: &str| MeshError::Edge {
        edge: edge.name.to_string(),
        reason: reason.to_string(),
    };
    let begin = model
        .vertices
        .get(edge.begin.index())
        .ok_or_else(|| failed("its begin vertex does not exist"))?
        .position;
    let end = model
        .vertices
        .get(edge.end.index())
        .ok_or_else(|| failed("its end vertex does not exist"))?
        .position;
    let curve = edge.curve(&model.solids);
    let mut n = match &*curve {
        _ if edge.is_closed() => 3,
        Curve::Segment { .. } | Curve::Contour { .. } => 1,
        _ => 2,
    };
    if let Curve::PointCalculus(curve) = &*curve {
        // Point-calculus curves are sampled adaptively (denser where they bend).
        let (params, points) = adaptive_samples(curve, tolerance, max_edge, n)
            .ok_or_else(|| failed("its curve has points that are not finite"))?;
        if params.len() > MAX_SEGMENTS + 1 {
            return Err(failed("its discretisation did not reach the tolerance"));
        }
        let n = params.len() - 1;
        let mut nodes = finish(points, n, begin, end);
        nodes.params = params;
        return Ok(nodes);
    }
    if let Curve::Segment { a, b } | Curve::Contour { a, b, .. } = &*curve {
        // A straight edge only needs the length limit (a contour piece is
        // within the tolerance of its chord already).
        let length = (b - a).norm();
        if max_edge.is_finite() && max_edge > 0.0 {
            n = n.max((length / max_edge).ceil() as usize);
        }
        if n > MAX_SEGMENTS {
            return Err(failed("it needs too many segments for max_edge"));
        }
        return Ok(finish(curve.samples(n), n, begin, end));
    }
    loop {
        if n > MAX_SEGMENTS {
            return Err(failed("its discretisation did not reach the tolerance"));
        }
        let fine = curve.samples(2 * n);
        if !fine.iter().all(|p| p.coords.iter().all(|x| x.is_finite())) {
            return Err(failed("its curve has points that are not finite"));
        }
        let good = (0..n).all(|i| {
            let (a, m, b) = (&fine[2 * i], &fine[2 * i + 1], &fine[2 * i + 2]);
            (b - a).norm() <= max_edge && distance_to_segment(m, a, b) <= tolerance
        });
        if good {
            let coarse: Vec<Point3> = fine.iter().step_by(2).copied().collect();
            return Ok(finish(coarse, n, begin, end));
        }
        n *= 2;
    }
}

fn finish(mut points: Vec<Point3>, n: usize, begin: Point3, end: Point3) -> EdgeNodes {
    if let Some(first) = points.first_mut() {
        *first = begin;
    }
    if let Some(last) = points.last_mut() {
        *last = end;
    }
    EdgeNodes {
        params: (0..=n).map(|i| i as f64 / n as f64).collect(),
        points,
    }
}

impl EdgeNodes {
    /// Splits chords longer than the size field at their curve midpoint (in
    /// parameter) until none is; the new points lie on the curve.
    pub(crate) fn refine_to_size(&mut self, curve: &Curve, sizing: &super::size::Sizing) {
        if sizing.is_uniform() {
            return;
        }
        loop {
            let mut params = Vec::with_capacity(self.params.len());
            let mut points = Vec::with_capacity(self.points.len());
            let mut split = false;
            for i in 0..self.params.len() {
                params.push(self.params[i]);
                points.push(self.points[i]);
                if i + 1 == self.params.len() {
                    break;
                }
                let (a, b) = (&self.points[i], &self.points[i + 1]);
                let s = 0.5 * (self.params[i] + self.params[i + 1]);
                let m = curve.point(s);
                if (b - a).norm() > sizing.at(&m)
                    && self.params.len() + params.len() < MAX_SEGMENTS
                    && m.coords.iter().all(|x| x.is_finite())
                {
                    params.push(s);
                    points.push(m);
                    split = true;
                }
            }
            self.params = params;
            self.points = points;
            if !split {
                return;
            }
        }
    }

    /// Adds the curve point at parameter `s` (a split requested by a face's
    /// refinement); false when it is already there.
    pub(crate) fn insert(&mut self, curve: &Curve, s: f64) -> bool {
        if !(s > 0.0 && s < 1.0) {
            return false;
        }
        let at = self.params.partition_point(|&t| t < s);
        let near = |i: usize| self.params.get(i).is_some_and(|t| (t - s).abs() <= 1e-12);
        if near(at) || (at > 0 && near(at - 1)) {
            return false;
        }
        let point = curve.point(s);
        if !point.coords.iter().all(|x| x.is_finite()) {
            return false;
        }
        self.params.insert(at, s);
        self.points.insert(at, point);
        true
    }
}

impl EdgeNodes {
    /// The index of the node whose parameter is nearest to `s`.
    pub(crate) fn index_of(&self, s: f64) -> usize {
        let at = self.params.partition_point(|&t| t < s);
        match (at.checked_sub(1), self.params.get(at)) {
            (Some(before), Some(&after)) if s - self.params[before] < after - s => before,
            (Some(before), None) => before,
            _ => at,
        }
    }
}

pub(crate) fn distance_to_segment(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    let d = b - a;
    let len2 = d.norm_squared();
    if len2 <= 0.0 {
        return (p - a).norm();
    }
    let t = ((p - a).dot(&d) / len2).clamp(0.0, 1.0);
    (p - (a + d * t)).norm()
}

/// The points of a standalone line: its exact curve sampled to the
/// tolerance when it has one, else its own points.
pub(crate) fn polyline_points(
    line: &crate::ir::Polyline,
    tolerance: f64,
    max_edge: f64,
) -> Result<Vec<Point3>, MeshError> {
    match &line.curve {
        Some(Curve::PointCalculus(curve)) => adaptive_samples(curve, tolerance, max_edge, 2)
            .map(|(_, points)| points)
            .ok_or_else(|| MeshError::Edge {
                edge: line.name.clone(),
                reason: "its curve has points that are not finite".into(),
            }),
        Some(curve) => Ok(curve.samples(64)),
        None => Ok(line.points.clone()),
    }
}
