//! Plane polygon helpers for the 2D kernel: orientation, convexity, the
//! even–odd inside test, a point strictly inside a non-convex polygon, and the
//! search for crossing edges that makes a vertex list a simple polygon.

use super::Point3;

/// Twice the signed area of the polygon (x, y of each vertex), positive when
/// counter-clockwise.
pub fn twice_signed_area(vertices: &[Point3]) -> f64 {
    let n = vertices.len();
    (0..n)
        .map(|i| {
            let (v, w) = (vertices[i], vertices[(i + 1) % n]);
            v.x * w.y - w.x * v.y
        })
        .sum()
}

/// True when every turn has the same sign (collinear turns allowed).
pub fn is_convex(vertices: &[Point3]) -> bool {
    let n = vertices.len();
    let (mut pos, mut neg) = (false, false);
    for i in 0..n {
        let (a, b, c) = (vertices[i], vertices[(i + 1) % n], vertices[(i + 2) % n]);
        let turn = (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x);
        pos |= turn > 0.0;
        neg |= turn < 0.0;
    }
    !(pos && neg)
}

/// Even–odd test of `p` against the closed polygon `vertices` (x, y).
pub fn contains<V: XY>(vertices: &[V], p: [f64; 2]) -> bool {
    let n = vertices.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (vertices[i].xy(), vertices[(i + 1) % n].xy());
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if x > p[0] {
                inside = !inside;
            }
        }
    }
    inside
}

/// Anything with plane coordinates.
pub trait XY {
    fn xy(&self) -> [f64; 2];
}

impl XY for Point3 {
    fn xy(&self) -> [f64; 2] {
        [self.x, self.y]
    }
}

impl XY for nalgebra::Vector2<f64> {
    fn xy(&self) -> [f64; 2] {
        [self.x, self.y]
    }
}

impl XY for [f64; 2] {
    fn xy(&self) -> [f64; 2] {
        *self
    }
}

/// Distance from `p` to the segment `a`–`b`.
pub fn segment_distance(p: &Point3, a: &Point3, b: &Point3) -> f64 {
    let d = b - a;
    let len2 = d.norm_squared();
    if len2 <= 0.0 {
        return (p - a).norm();
    }
    let t = ((p - a).dot(&d) / len2).clamp(0.0, 1.0);
    (p - (a + d * t)).norm()
}

/// A point strictly inside a simple polygon: the middle of the widest
/// inside stretch of the horizontal line halfway between the two middle
/// distinct vertex heights.
pub fn interior_point(vertices: &[Point3]) -> Point3 {
    let mut ys: Vec<f64> = vertices.iter().map(|v| v.y).collect();
    ys.sort_by(f64::total_cmp);
    ys.dedup();
    let y = match ys.len() {
        0 => 0.0,
        1 => ys[0],
        k => 0.5 * (ys[(k - 1) / 2] + ys[(k - 1) / 2 + 1]),
    };
    let n = vertices.len();
    let mut xs = Vec::new();
    for i in 0..n {
        let (a, b) = (vertices[i], vertices[(i + 1) % n]);
        if (a.y > y) != (b.y > y) {
            xs.push(a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x));
        }
    }
    xs.sort_by(f64::total_cmp);
    let best = xs
        .chunks_exact(2)
        .max_by(|p, q| (p[1] - p[0]).total_cmp(&(q[1] - q[0])));
    match best {
        Some(pair) => Point3::new(0.5 * (pair[0] + pair[1]), y, 0.0),
        None => vertices.first().copied().unwrap_or_else(Point3::origin),
    }
}

/// The first pair of edges (i, j), i < j, that cross or touch other than at
/// the vertex consecutive edges share; edge i runs from vertex i to i + 1.
/// Sweeps the edges in order of their smallest x, so polygons with many
/// vertices stay fast.
pub fn first_crossing(vertices: &[Point3]) -> Option<(usize, usize)> {
    let n = vertices.len();
    let seg = |i: usize| (vertices[i], vertices[(i + 1) % n]);
    let mut order: Vec<usize> = (0..n).collect();
    let lo = |i: usize| {
        let (a, b) = seg(i);
        a.x.min(b.x)
    };
    order.sort_by(|&i, &j| lo(i).total_cmp(&lo(j)).then(i.cmp(&j)));
    let mut found: Option<(usize, usize)> = None;
    let mut active: Vec<usize> = Vec::new();
    for &i in &order {
        let (a, b) = seg(i);
        let x = a.x.min(b.x);
        active.retain(|&j| {
            let (c, d) = seg(j);
            c.x.max(d.x) >= x
        });
        for &j in &active {
            let adjacent = (i + 1) % n == j || (j + 1) % n == i;
            let (c, d) = seg(j);
            let hit = if adjacent {
                // Consecutive edges may only share their common vertex: they
                // overlap when they fold back along one line.
                let shared = if (i + 1) % n == j { b } else { a };
                let (p, q) = if (i + 1) % n == j { (a, d) } else { (b, c) };
                let cross =
                    (p.x - shared.x) * (q.y - shared.y) - (p.y - shared.y) * (q.x - shared.x);
                let dot = (p.x - shared.x) * (q.x - shared.x) + (p.y - shared.y) * (q.y - shared.y);
                cross == 0.0 && dot > 0.0
            } else {
                segments_meet(a, b, c, d)
            };
            if hit {
                let pair = (i.min(j), i.max(j));
                if found.is_none_or(|f| pair < f) {
                    found = Some(pair);
                }
            }
        }
        active.push(i);
    }
    found
}

fn orient(a: Point3, b: Point3, c: Point3) -> f64 {
    (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)
}

/// Closed segments a–b and c–d share a point.
fn segments_meet(a: Point3, b: Point3, c: Point3, d: Point3) -> bool {
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: Point3, q: Point3, r: Point3, o: f64| {
        o == 0.0
            && r.x >= p.x.min(q.x)
            && r.x <= p.x.max(q.x)
            && r.y >= p.y.min(q.y)
            && r.y <= p.y.max(q.y)
    };
    on(c, d, a, d1) || on(c, d, b, d2) || on(a, b, c, d3) || on(a, b, d, d4)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn poly(xy: &[[f64; 2]]) -> Vec<Point3> {
        xy.iter().map(|p| Point3::new(p[0], p[1], 0.0)).collect()
    }

    #[test]
    fn l_shape_is_simple_nonconvex_and_has_an_inside_point() {
        let l = poly(&[[0., 0.], [2., 0.], [2., 1.], [1., 1.], [1., 2.], [0., 2.]]);
        assert!(!is_convex(&l));
        assert_eq!(first_crossing(&l), None);
        assert_eq!(twice_signed_area(&l), 6.0);
        let p = interior_point(&l);
        assert!(contains(&l, [p.x, p.y]), "{p:?}");
        assert!(!contains(&l, [1.5, 1.5]));
    }

    #[test]
    fn bow_tie_crosses() {
        let bow = poly(&[[0., 0.], [1., 1.], [1., 0.], [0., 1.]]);
        assert_eq!(first_crossing(&bow), Some((0, 2)));
        let folded = poly(&[[0., 0.], [2., 0.], [1., 0.], [1., 1.]]);
        assert!(first_crossing(&folded).is_some());
    }
}
