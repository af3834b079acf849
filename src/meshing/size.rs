//! Mesh size control: a size field h(x, y, z, d) given as an expression —
//! d is the distance to a named boundary fragment — and the per-subdomain
//! area limits of 2D models. Edges are split until no chord is longer than
//! h at its midpoint; faces insert points in triangles longer than h.

use super::MeshError;
use crate::expr::{Expr, eval};
use crate::geom::Point3;
use crate::ir::{Model, derive_fragments};

/// A user's size field: `expression` in x, y, z and, with `distance_to`, in
/// d = the distance to that fragment (or `<boundary>`) of the model.
#[derive(Debug, Clone, PartialEq)]
pub struct SizeField {
    pub expression: Expr,
    /// The source text, for messages.
    pub text: String,
    pub distance_to: Option<String>,
}

impl SizeField {
    /// Parses `text`; a bad expression is an error naming it.
    pub fn parse(text: &str, distance_to: Option<String>) -> Result<SizeField, String> {
        let expression = crate::expr::parse(text, 0).map_err(|e| {
            let why = match e {
                crate::expr::ParseError::Syntax { message, .. } => message,
                crate::expr::ParseError::UnknownFunction { name, .. } => {
                    format!("unknown function {name}")
                }
                crate::expr::ParseError::WrongArgumentCount { function, .. } => {
                    format!("wrong number of arguments to {}", function.name())
                }
                crate::expr::ParseError::TooLarge { .. } => "too large".to_string(),
            };
            format!("--size-field {text}: not an expression in x, y, z, d: {why}")
        })?;
        Ok(SizeField {
            expression,
            text: text.to_string(),
            distance_to,
        })
    }
}

/// A size field ready to evaluate: the expression and the segments d is
/// measured to.
pub(crate) struct Sizing {
    field: Option<SizeField>,
    segments: SegmentGrid,
    max_edge: f64,
    diagonal: f64,
}

impl Sizing {
    /// Only `max_edge`: the size is the same everywhere.
    pub(crate) fn uniform(max_edge: f64) -> Sizing {
        Sizing {
            field: None,
            segments: SegmentGrid::new(Vec::new()),
            max_edge,
            diagonal: 0.0,
        }
    }

    /// Checks the field against the model: the fragment exists, and the
    /// expression gives a positive finite size at the model's centre.
    pub(crate) fn new(
        model: &Model,
        field: Option<&SizeField>,
        max_edge: f64,
        edge_nodes: &[super::edges::EdgeNodes],
    ) -> Result<Sizing, MeshError> {
        let Some(field) = field else {
            return Ok(Sizing::uniform(max_edge));
        };
        let mut segments = Vec::new();
        if let Some(name) = &field.distance_to {
            let mut edges: Vec<usize> = model
                .boundaries
                .iter()
                .filter(|b| &b.name == name)
                .flat_map(|b| b.edges.iter().map(|e| e.index()))
                .collect();
            let fragments = derive_fragments(model);
            edges.extend(
                fragments
                    .iter()
                    .filter(|f| &f.name == name)
                    .flat_map(|f| f.edges.iter().map(|e| e.index())),
            );
            if edges.is_empty() {
                let mut names: Vec<String> = fragments.iter().map(|f| f.name.clone()).collect();
                names.sort();
                names.dedup();
                return Err(MeshError::Options(format!(
                    "--size-distance-to {name}: the model has no fragment or boundary of edges by that name (fragments: {})",
                    names.join(", ")
                )));
            }
            edges.sort_unstable();
            edges.dedup();
            for e in edges {
                if let Some(nodes) = edge_nodes.get(e) {
                    segments.extend(nodes.points.windows(2).map(|w| (w[0], w[1])));
                }
            }
        }
        let bbox = model.bbox();
        let sizing = Sizing {
            field: Some(field.clone()),
            segments: SegmentGrid::new(segments),
            max_edge,
            diagonal: bbox.diagonal(),
        };
        let centre = Point3::from((bbox.min.coords + bbox.max.coords) / 2.0);
        sizing.eval(&centre).map_err(MeshError::Options)?;
        Ok(sizing)
    }

    pub(crate) fn is_uniform(&self) -> bool {
        self.field.is_none()
    }

    /// The size wanted at `p`: the field's value, at most `max_edge`.
    pub(crate) fn at(&self, p: &Point3) -> f64 {
        match self.eval(p) {
            Ok(h) => h.min(self.max_edge),
            Err(_) => self.max_edge,
        }
    }

    fn eval(&self, p: &Point3) -> Result<f64, String> {
        let Some(field) = &self.field else {
            return Ok(self.max_edge);
        };
        let d = || self.segments.distance(p);
        let with_d = field.distance_to.is_some();
        let h = eval(&field.expression, &mut |name, _| match name {
            "x" => Some(p.x),
            "y" => Some(p.y),
            "z" => Some(p.z),
            "diagonal" => Some(self.diagonal),
            "d" if with_d => Some(d()),
            _ => None,
        })
        .map_err(|e| match e {
            crate::expr::EvalError::Unknown { name, .. } => format!(
                "--size-field {}: unknown name '{name}' (the field may use x, y, z, diagonal{})",
                field.text,
                if with_d {
                    " and d"
                } else {
                    ", and d with --size-distance-to"
                }
            ),
            crate::expr::EvalError::NonFinite { .. } => {
                format!("--size-field {}: the value is not finite", field.text)
            }
        })?;
        if h > 0.0 && h.is_finite() {
            Ok(h)
        } else {
            Err(format!(
                "--size-field {}: the size at ({}, {}, {}) is {h}; it must be positive",
                field.text, p.x, p.y, p.z
            ))
        }
    }
}

/// Segments bucketed in a uniform grid of the xy plane, so the distance to
/// the nearest one is found by searching rings of cells outwards.
struct SegmentGrid {
    segments: Vec<(Point3, Point3)>,
    min: [f64; 2],
    cell: f64,
    dims: [usize; 2],
    cells: Vec<Vec<u32>>,
}

impl SegmentGrid {
    fn new(segments: Vec<(Point3, Point3)>) -> SegmentGrid {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for (a, b) in &segments {
            for p in [a, b] {
                lo = [lo[0].min(p.x), lo[1].min(p.y)];
                hi = [hi[0].max(p.x), hi[1].max(p.y)];
            }
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        if segments.is_empty() || !(extent.is_finite() && extent > 0.0) {
            return SegmentGrid {
                segments,
                min: [0.0; 2],
                cell: 1.0,
                dims: [1, 1],
                cells: vec![Vec::new()],
            };
        }
        let per_axis = ((segments.len() as f64).sqrt().ceil() as usize).clamp(1, 1024);
        let cell = extent / per_axis as f64 * 1.000_001;
        let dims = [
            (((hi[0] - lo[0]) / cell) as usize + 1).min(per_axis + 1),
            (((hi[1] - lo[1]) / cell) as usize + 1).min(per_axis + 1),
        ];
        let mut cells = vec![Vec::new(); dims[0] * dims[1]];
        for (k, (a, b)) in segments.iter().enumerate() {
            let i0 = (((a.x.min(b.x) - lo[0]) / cell) as usize).min(dims[0] - 1);
            let i1 = (((a.x.max(b.x) - lo[0]) / cell) as usize).min(dims[0] - 1);
            let j0 = (((a.y.min(b.y) - lo[1]) / cell) as usize).min(dims[1] - 1);
            let j1 = (((a.y.max(b.y) - lo[1]) / cell) as usize).min(dims[1] - 1);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    cells[j * dims[0] + i].push(k as u32);
                }
            }
        }
        SegmentGrid {
            segments,
            min: lo,
            cell,
            dims,
            cells,
        }
    }

    /// Distance from `p` (its xy) to the nearest segment; infinite when there is none.
    fn distance(&self, p: &Point3) -> f64 {
        if self.segments.is_empty() {
            return f64::INFINITY;
        }
        let q = Point3::new(p.x, p.y, 0.0);
        let flat = |k: u32| {
            let (a, b) = &self.segments[k as usize];
            crate::geom::polygon::segment_distance(
                &q,
                &Point3::new(a.x, a.y, 0.0),
                &Point3::new(b.x, b.y, 0.0),
            )
        };
        let ci = ((p.x - self.min[0]) / self.cell).floor() as i64;
        let cj = ((p.y - self.min[1]) / self.cell).floor() as i64;
        let (nx, ny) = (self.dims[0] as i64, self.dims[1] as i64);
        // Ring r holds the cells at Chebyshev distance r from p's cell; once
        // the best distance is below r·cell no farther ring can improve it.
        let mut best = f64::INFINITY;
        let max_ring = nx.max(ny) + ci.abs().max(cj.abs()) + 1;
        for r in 0..=max_ring {
            if best <= (r as f64 - 1.0).max(0.0) * self.cell {
                break;
            }
            for j in (cj - r)..=(cj + r) {
                for i in (ci - r)..=(ci + r) {
                    if (i - ci).abs() != r && (j - cj).abs() != r {
                        continue;
                    }
                    if i < 0 || j < 0 || i >= nx || j >= ny {
                        continue;
                    }
                    for &k in &self.cells[(j * nx + i) as usize] {
                        best = best.min(flat(k));
                    }
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_distance_matches_brute_force() {
        let segments: Vec<(Point3, Point3)> = (0..200)
            .map(|k| {
                let t = k as f64 / 200.0 * std::f64::consts::TAU;
                let u = (k + 1) as f64 / 200.0 * std::f64::consts::TAU;
                (
                    Point3::new(t.cos(), t.sin(), 0.0),
                    Point3::new(u.cos(), u.sin(), 0.0),
                )
            })
            .collect();
        let grid = SegmentGrid::new(segments.clone());
        for p in [
            [0.0, 0.0],
            [0.3, -0.2],
            [2.5, 1.0],
            [-7.0, 3.0],
            [0.99, 0.01],
        ] {
            let p = Point3::new(p[0], p[1], 0.0);
            let brute = segments
                .iter()
                .map(|(a, b)| crate::geom::polygon::segment_distance(&p, a, b))
                .fold(f64::INFINITY, f64::min);
            assert!((grid.distance(&p) - brute).abs() < 1e-12, "{p:?}");
        }
    }
}
