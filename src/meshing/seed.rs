//! Interior points of a curved face placed up front, sized for the chordal
//! tolerance, so that one angle refinement and one chordal check usually
//! finish the face (each refinement call scans every triangle, and the
//! passes of "refine, then insert where the surface is missed" were most of
//! the meshing time).
//!
//! # Guarantees
//! - Points lie strictly inside the face's loops (even–odd rule) and outside
//!   a keep-out disk around every boundary segment (¾ of its length about
//!   its midpoint), which holds its diametral circle: no seed encroaches a
//!   boundary segment, so seeding never makes refinement split the boundary.
//! - Points are vertices of a subdivision of one equilateral triangle,
//!   refined where the chart's local size asks for it: the same input gives
//!   the same points in the same order (rows of the lattice), whatever the
//!   thread count.
//! - An empty result (nothing seeded) when the face is too small for a
//!   point or the lattice would exceed `max_points`.
//!
//! # Limitations
//! - Sizes step by factors of 2 (subdivision levels); spade's angle
//!   refinement smooths the steps, and the chordal check still inserts
//!   points wherever a triangle misses the surface.

use super::chart::Chart;

/// Deepest subdivision: lattice coordinates stay far inside `i64`.
const MAX_DEPTH: u32 = 24;
/// Keep-out radius about a segment's midpoint, in segment lengths (its
/// diametral circle is ½).
const KEEP_OUT: f64 = 0.75;

/// Points strictly inside `loops` (chart coordinates) where equilateral
/// triangles would have edges of about `edge` on the surface (`edge` over
/// the chart's local scale), in lattice row order.
pub(super) fn lattice_points(
    chart: &Chart,
    loops: &[Vec<[f64; 2]>],
    edge: f64,
    max_points: usize,
) -> Vec<[f64; 2]> {
    let Some(boundary) = Boundary::new(loops) else {
        return Vec::new();
    };
    if !(edge > 0.0 && edge.is_finite()) {
        return Vec::new();
    }
    let [lo, hi] = boundary.bbox;
    let (width, height) = (hi[0] - lo[0], hi[1] - lo[1]);
    let sqrt3 = 3f64.sqrt();
    // An equilateral triangle with its base under the box, wide enough at
    // the box's top.
    let side = 1.01 * (width + 2.0 * height / sqrt3) + 1e-12;
    let origin = [
        0.5 * (lo[0] + hi[0]) - 0.5 * side,
        lo[1] - 0.005 * side.min(height.max(width)),
    ];
    let n = 1i64 << MAX_DEPTH;
    let unit = side / n as f64;
    let to_uv = |[i, j]: [i64; 2]| {
        [
            origin[0] + unit * (i as f64 + 0.5 * j as f64),
            origin[1] + unit * (sqrt3 / 2.0) * j as f64,
        ]
    };
    let delta = 1e-7 * width.max(height);
    let size = |uv: [f64; 2]| -> Option<f64> {
        let p = chart.lift(uv)?;
        let du = chart.lift([uv[0] + delta, uv[1]])?;
        let dv = chart.lift([uv[0], uv[1] + delta])?;
        let scale = (du - p).norm().max((dv - p).norm()) / delta;
        (scale > 0.0 && scale.is_finite()).then(|| edge / scale)
    };
    // (corner, length of the smallest leaf it belongs to)
    let mut corners: Vec<([i64; 2], f64)> = Vec::new();
    let mut stack: Vec<([[i64; 2]; 3], u32)> = vec![([[0, 0], [n, 0], [0, n]], 0)];
    while let Some((t, level)) = stack.pop() {
        let uv = t.map(to_uv);
        let (mut tlo, mut thi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &uv {
            for k in 0..2 {
                tlo[k] = tlo[k].min(p[k]);
                thi[k] = thi[k].max(p[k]);
            }
        }
        if thi[0] < lo[0] || tlo[0] > hi[0] || thi[1] < lo[1] || tlo[1] > hi[1] {
            continue;
        }
        let length = side / (1u64 << level) as f64;
        let centroid = [
            (uv[0][0] + uv[1][0] + uv[2][0]) / 3.0,
            (uv[0][1] + uv[1][1] + uv[2][1]) / 3.0,
        ];
        // The smallest size at the centroid and the corners: a triangle
        // across the boundary takes the size inside (a chart's scale can
        // fall off outside the face).
        let finer = level < MAX_DEPTH
            && [centroid, uv[0], uv[1], uv[2]]
                .into_iter()
                .any(|p| size(p).is_some_and(|s| length > s));
        if !finer {
            corners.extend(t.map(|c| (c, length)));
            if corners.len() > 3 * max_points {
                return Vec::new();
            }
            continue;
        }
        let mid = |a: [i64; 2], b: [i64; 2]| [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2];
        let [a, b, c] = t;
        let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
        for child in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]] {
            stack.push((child, level + 1));
        }
    }
    // Row order (v, then u): consecutive points are neighbours, good hints
    // for insertion.
    corners.sort_unstable_by(|(a, la), (b, lb)| {
        (a[1], a[0]).cmp(&(b[1], b[0])).then(la.total_cmp(lb))
    });
    corners.dedup_by_key(|(c, _)| *c);
    // A front row first: the apex of the equilateral triangle inside each
    // boundary segment, so the triangles along the boundary are as fine as
    // the boundary (the lattice's own rows stop short of it, and triangles
    // across the gap missed the surface).
    let mut near = Near::new(boundary.cell);
    let mut points = Vec::new();
    let sqrt3_2 = 3f64.sqrt() / 2.0;
    for &(a, b) in &boundary.segments {
        let length = distance(a, b);
        let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
        let normal = [-(b[1] - a[1]) / length, (b[0] - a[0]) / length];
        for side in [1.0, -1.0] {
            let apex = [
                mid[0] + side * sqrt3_2 * length * normal[0],
                mid[1] + side * sqrt3_2 * length * normal[1],
            ];
            if boundary.admits(apex) {
                if !near.within(apex, 0.6 * length) {
                    near.add(apex);
                    points.push(apex);
                }
                break;
            }
        }
    }
    let front = points.len();
    points.extend(
        corners
            .into_iter()
            .map(|(c, length)| (to_uv(c), length))
            .filter(|(p, length)| {
                boundary.admits(*p) && !near.within_first(*p, 0.4 * length, front)
            })
            .map(|(p, _)| p),
    );
    if points.len() > max_points {
        return Vec::new();
    }
    points
}

/// The loops' segments in two bucket tables over their bounding box: by row
/// (for the even–odd test) and by cell (for the keep-out disks).
struct Boundary {
    segments: Vec<([f64; 2], [f64; 2])>,
    bbox: [[f64; 2]; 2],
    cell: f64,
    columns: usize,
    rows: usize,
    /// Segments crossing each row's v-range (CSR: offsets, then indices).
    row_start: Vec<u32>,
    row_items: Vec<u32>,
    /// Segments whose keep-out disk meets each cell.
    cell_start: Vec<u32>,
    cell_items: Vec<u32>,
}

/// Buckets per axis at most.
const MAX_BUCKETS: usize = 1024;

impl Boundary {
    fn new(loops: &[Vec<[f64; 2]>]) -> Option<Boundary> {
        let mut segments = Vec::new();
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for lp in loops {
            for (i, a) in lp.iter().enumerate() {
                let b = lp[(i + 1) % lp.len()];
                segments.push((*a, b));
                for k in 0..2 {
                    lo[k] = lo[k].min(a[k]);
                    hi[k] = hi[k].max(a[k]);
                }
            }
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        if segments.len() < 3 || !(extent > 0.0 && extent.is_finite()) {
            return None;
        }
        let mut lengths: Vec<f64> = segments.iter().map(|(a, b)| distance(*a, *b)).collect();
        let rank = lengths.len() / 2;
        let (_, median, _) = lengths.select_nth_unstable_by(rank, f64::total_cmp);
        let cell = median.max(extent / MAX_BUCKETS as f64);
        let columns = ((hi[0] - lo[0]) / cell) as usize + 1;
        let rows = ((hi[1] - lo[1]) / cell) as usize + 1;
        let mut boundary = Boundary {
            segments,
            bbox: [lo, hi],
            cell,
            columns,
            rows,
            row_start: Vec::new(),
            row_items: Vec::new(),
            cell_start: Vec::new(),
            cell_items: Vec::new(),
        };
        let row_spans: Vec<(usize, usize)> = boundary
            .segments
            .iter()
            .map(|(a, b)| (boundary.row(a[1].min(b[1])), boundary.row(a[1].max(b[1]))))
            .collect();
        (boundary.row_start, boundary.row_items) = csr(rows, &row_spans, |r0, r1, push| {
            for r in r0..=r1 {
                push(r);
            }
        });
        let disks: Vec<(usize, usize)> = (0..boundary.segments.len()).map(|s| (s, s)).collect();
        let boxes: Vec<[usize; 4]> = boundary
            .segments
            .iter()
            .map(|(a, b)| {
                let centre = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
                let r = KEEP_OUT * distance(*a, *b);
                [
                    boundary.column(centre[0] - r),
                    boundary.column(centre[0] + r),
                    boundary.row(centre[1] - r),
                    boundary.row(centre[1] + r),
                ]
            })
            .collect();
        let columns = boundary.columns;
        (boundary.cell_start, boundary.cell_items) = csr(columns * rows, &disks, |s, _, push| {
            let [c0, c1, r0, r1] = boxes[s];
            for r in r0..=r1 {
                for c in c0..=c1 {
                    push(r * columns + c);
                }
            }
        });
        Some(boundary)
    }

    fn row(&self, v: f64) -> usize {
        (((v - self.bbox[0][1]) / self.cell).max(0.0) as usize).min(self.rows - 1)
    }

    fn column(&self, u: f64) -> usize {
        (((u - self.bbox[0][0]) / self.cell).max(0.0) as usize).min(self.columns - 1)
    }

    /// Strictly inside the loops and outside every keep-out disk.
    fn admits(&self, p: [f64; 2]) -> bool {
        let [lo, hi] = self.bbox;
        if p[0] <= lo[0] || p[0] >= hi[0] || p[1] <= lo[1] || p[1] >= hi[1] {
            return false;
        }
        let cell = self.row(p[1]) * self.columns + self.column(p[0]);
        let near =
            &self.cell_items[self.cell_start[cell] as usize..self.cell_start[cell + 1] as usize];
        for &s in near {
            let (a, b) = self.segments[s as usize];
            let centre = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            if distance(centre, p) <= KEEP_OUT * distance(a, b) {
                return false;
            }
        }
        let row = self.row(p[1]);
        let crossing =
            &self.row_items[self.row_start[row] as usize..self.row_start[row + 1] as usize];
        let mut inside = false;
        for &s in crossing {
            let (a, b) = self.segments[s as usize];
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if x > p[0] {
                    inside = !inside;
                }
            }
        }
        inside
    }
}

/// A compressed bucket table: `register(item.0, item.1, push)` calls `push`
/// with each bucket of the item at `index`.
fn csr(
    buckets: usize,
    items: &[(usize, usize)],
    register: impl Fn(usize, usize, &mut dyn FnMut(usize)),
) -> (Vec<u32>, Vec<u32>) {
    let mut start = vec![0u32; buckets + 1];
    for &(x, y) in items {
        register(x, y, &mut |b| start[b + 1] += 1);
    }
    for b in 0..buckets {
        start[b + 1] += start[b];
    }
    let mut fill = start.clone();
    let mut out = vec![0u32; start[buckets] as usize];
    for (index, &(x, y)) in items.iter().enumerate() {
        register(x, y, &mut |b| {
            out[fill[b] as usize] = index as u32;
            fill[b] += 1;
        });
    }
    (start, out)
}

fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// Points already placed, bucketed by cell, for "is one within r?".
struct Near {
    cell: f64,
    points: Vec<[f64; 2]>,
    buckets: std::collections::HashMap<(i64, i64), Vec<u32>>,
}

impl Near {
    fn new(cell: f64) -> Near {
        Near {
            cell,
            points: Vec::new(),
            buckets: std::collections::HashMap::new(),
        }
    }

    fn key(&self, p: [f64; 2]) -> (i64, i64) {
        (
            (p[0] / self.cell).floor() as i64,
            (p[1] / self.cell).floor() as i64,
        )
    }

    fn add(&mut self, p: [f64; 2]) {
        let key = self.key(p);
        self.buckets
            .entry(key)
            .or_default()
            .push(self.points.len() as u32);
        self.points.push(p);
    }

    fn within(&self, p: [f64; 2], r: f64) -> bool {
        self.within_first(p, r, usize::MAX)
    }

    /// A point among the first `count` added within `r` of `p`.
    fn within_first(&self, p: [f64; 2], r: f64, count: usize) -> bool {
        let (ci, cj) = self.key(p);
        let reach = (r / self.cell).ceil().min(64.0) as i64;
        for i in ci - reach..=ci + reach {
            for j in cj - reach..=cj + reach {
                if let Some(bucket) = self.buckets.get(&(i, j))
                    && bucket
                        .iter()
                        .any(|&k| (k as usize) < count && distance(self.points[k as usize], p) < r)
                {
                    return true;
                }
            }
        }
        false
    }
}
