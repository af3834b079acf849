//! Paper 001's primitive library and R-operations, as builders over IR nodes.
//! Arguments are positional and may be any expression; coordinates come first
//! (x, y[, z]), as in the paper's listings (`Ball(x, y, z, r, x0, y0, z0)`).
//! Angles are in radians. Every primitive is positive inside.

use super::ir::{Ctx, NodeId, Unary};
use super::rfs::RSystem;

/// How many arguments a library function takes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Arity {
    Exactly(usize),
    /// At least this many.
    AtLeast(usize),
}

type Build = fn(&mut Ctx, RSystem, &[NodeId]) -> Result<NodeId, String>;

pub struct LibFn {
    pub name: &'static str,
    pub arity: Arity,
    /// The parameter list as documentation shows it.
    pub signature: &'static str,
    pub build: Build,
}

/// The library; names as paper 001 spells them. `Con`/`Dis` are the paper's
/// conjunction/disjunction, synonyms of `Intersection`/`Union`.
pub static LIBRARY: &[LibFn] = &[
    LibFn {
        name: "Union",
        arity: Arity::AtLeast(1),
        signature: "Union(f1, f2, …)",
        build: union,
    },
    LibFn {
        name: "Dis",
        arity: Arity::AtLeast(1),
        signature: "Dis(f1, f2, …)",
        build: union,
    },
    LibFn {
        name: "Intersection",
        arity: Arity::AtLeast(1),
        signature: "Intersection(f1, f2, …)",
        build: intersection,
    },
    LibFn {
        name: "Con",
        arity: Arity::AtLeast(1),
        signature: "Con(f1, f2, …)",
        build: intersection,
    },
    LibFn {
        name: "Difference",
        arity: Arity::Exactly(2),
        signature: "Difference(f1, f2)",
        build: difference,
    },
    LibFn {
        name: "Not",
        arity: Arity::Exactly(1),
        signature: "Not(f)",
        build: not,
    },
    LibFn {
        name: "Neg",
        arity: Arity::Exactly(1),
        signature: "Neg(f)",
        build: not,
    },
    LibFn {
        name: "HalfPlane",
        arity: Arity::Exactly(6),
        signature: "HalfPlane(x, y, x1, y1, x2, y2)",
        build: half_plane_fn,
    },
    LibFn {
        name: "HalfSpace",
        arity: Arity::Exactly(9),
        signature: "HalfSpace(x, y, z, xp, yp, zp, nx, ny, nz)",
        build: half_space,
    },
    LibFn {
        name: "Ellipse",
        arity: Arity::Exactly(6),
        signature: "Ellipse(x, y, x0, y0, a, b)",
        build: ellipse,
    },
    LibFn {
        name: "Disk",
        arity: Arity::Exactly(5),
        signature: "Disk(x, y, r, x0, y0)",
        build: disk,
    },
    LibFn {
        name: "Ellipsoid",
        arity: Arity::Exactly(9),
        signature: "Ellipsoid(x, y, z, x0, y0, z0, a, b, c)",
        build: ellipsoid,
    },
    LibFn {
        name: "Ball",
        arity: Arity::Exactly(7),
        signature: "Ball(x, y, z, r, x0, y0, z0)",
        build: ball,
    },
    LibFn {
        name: "ConvexPolygon",
        arity: Arity::AtLeast(8),
        signature: "ConvexPolygon(x, y, x1, y1, x2, y2, x3, y3, …) with vertices clockwise",
        build: convex_polygon,
    },
    LibFn {
        name: "RegularPolygon",
        arity: Arity::Exactly(6),
        signature: "RegularPolygon(x, y, r, x0, y0, n)",
        build: regular_polygon,
    },
    LibFn {
        name: "Parallelogram",
        arity: Arity::Exactly(7),
        signature: "Parallelogram(x, y, x0, y0, a, h, alpha)",
        build: parallelogram_fn,
    },
    LibFn {
        name: "Rectangle",
        arity: Arity::Exactly(6),
        signature: "Rectangle(x, y, x0, y0, w, h)",
        build: rectangle_fn,
    },
    LibFn {
        name: "Parallelepiped",
        arity: Arity::Exactly(11),
        signature: "Parallelepiped(x, y, z, x0, y0, z0, a, h, d, alpha, beta)",
        build: parallelepiped,
    },
    LibFn {
        name: "Box",
        arity: Arity::Exactly(9),
        signature: "Box(x, y, z, x0, y0, z0, w, h, d)",
        build: box_fn,
    },
    LibFn {
        name: "RoundedRectangle",
        arity: Arity::Exactly(7),
        signature: "RoundedRectangle(x, y, x0, y0, w, h, r)",
        build: rounded_rectangle,
    },
    LibFn {
        name: "Sector",
        arity: Arity::Exactly(7),
        signature: "Sector(x, y, x0, y0, r, angle1, angle2)",
        build: sector,
    },
];

/// Finds a library function by its paper name (`Ball`) or its XML name
/// (`ball`, `half_plane`): case and underscores are ignored.
pub fn lookup(name: &str) -> Option<&'static LibFn> {
    let key: String = name
        .chars()
        .filter(|c| *c != '_')
        .collect::<String>()
        .to_ascii_lowercase();
    LIBRARY.iter().find(|f| f.name.to_ascii_lowercase() == key)
}

impl Arity {
    pub fn accepts(self, n: usize) -> bool {
        match self {
            Arity::Exactly(k) => n == k,
            Arity::AtLeast(k) => n >= k,
        }
    }
}

fn union(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    sys.or_all(ctx, a)
        .ok_or_else(|| "needs at least one argument".into())
}

fn intersection(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    sys.and_all(ctx, a)
        .ok_or_else(|| "needs at least one argument".into())
}

fn difference(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    Ok(sys.difference(ctx, a[0], a[1]))
}

fn not(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    Ok(sys.not(ctx, a[0]))
}

/// (3): positive right of the directed line (x1, y1) → (x2, y2).
pub fn half_plane(ctx: &mut Ctx, x: NodeId, y: NodeId, p1: [NodeId; 2], p2: [NodeId; 2]) -> NodeId {
    let dx = ctx.sub(x, p1[0]);
    let dy = ctx.sub(y, p1[1]);
    let ey = ctx.sub(p2[1], p1[1]);
    let ex = ctx.sub(p2[0], p1[0]);
    let a = ctx.mul(dx, ey);
    let b = ctx.mul(dy, ex);
    ctx.sub(a, b)
}

fn half_plane_fn(ctx: &mut Ctx, _: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    Ok(half_plane(ctx, a[0], a[1], [a[2], a[3]], [a[4], a[5]]))
}

/// (4): −n · (p − p0), positive on the side opposite the outer normal.
fn half_space(ctx: &mut Ctx, _: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    let mut sum = ctx.constant(0.0);
    for axis in 0..3 {
        let d = ctx.sub(a[axis], a[3 + axis]);
        let t = ctx.mul(a[6 + axis], d);
        sum = ctx.sub(sum, t);
    }
    Ok(sum)
}

/// 1 − Σ ((p − c) / s)².
fn scaled_sphere(ctx: &mut Ctx, coords: &[NodeId], centre: &[NodeId], semi: &[NodeId]) -> NodeId {
    let mut f = ctx.constant(1.0);
    for i in 0..coords.len() {
        let d = ctx.sub(coords[i], centre[i]);
        let q = ctx.div(d, semi[i]);
        let s = ctx.square(q);
        f = ctx.sub(f, s);
    }
    f
}

/// r² − |p − c|².
fn round(ctx: &mut Ctx, coords: &[NodeId], r: NodeId, centre: &[NodeId]) -> NodeId {
    let mut f = ctx.square(r);
    for i in 0..coords.len() {
        let d = ctx.sub(coords[i], centre[i]);
        let s = ctx.square(d);
        f = ctx.sub(f, s);
    }
    f
}

fn ellipse(ctx: &mut Ctx, _: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    Ok(scaled_sphere(ctx, &a[0..2], &a[2..4], &a[4..6]))
}

fn disk(ctx: &mut Ctx, _: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    Ok(round(ctx, &a[0..2], a[2], &a[3..5]))
}

fn ellipsoid(ctx: &mut Ctx, _: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    Ok(scaled_sphere(ctx, &a[0..3], &a[3..6], &a[6..9]))
}

fn ball(ctx: &mut Ctx, _: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    Ok(round(ctx, &a[0..3], a[3], &a[4..7]))
}

/// (9): the R-conjunction of the half-planes right of each side, vertices
/// clockwise and closing back to the first.
fn polygon(ctx: &mut Ctx, sys: RSystem, x: NodeId, y: NodeId, vertices: &[[NodeId; 2]]) -> NodeId {
    let sides: Vec<NodeId> = (0..vertices.len())
        .map(|i| half_plane(ctx, x, y, vertices[i], vertices[(i + 1) % vertices.len()]))
        .collect();
    sys.and_all(ctx, &sides)
        .unwrap_or_else(|| ctx.constant(-1.0))
}

fn convex_polygon(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    if !a.len().is_multiple_of(2) {
        return Err(format!(
            "takes x, y and pairs of vertex coordinates, got {} arguments (odd)",
            a.len()
        ));
    }
    let vertices: Vec<[NodeId; 2]> = a[2..].chunks(2).map(|c| [c[0], c[1]]).collect();
    Ok(polygon(ctx, sys, a[0], a[1], &vertices))
}

/// (10): vertices x0 + r sin α_i, y0 + r cos α_i, α_i = 2π(i − 1)/n (clockwise).
fn regular_polygon(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    let n = ctx
        .const_value(a[5])
        .ok_or("the number of sides n must be a constant")?;
    if n.fract() != 0.0 || !(3.0..=10_000.0).contains(&n) {
        return Err(format!(
            "the number of sides n must be a whole number from 3 to 10000, got {n}"
        ));
    }
    let n = n as usize;
    let vertices: Vec<[NodeId; 2]> = (0..n)
        .map(|i| {
            let angle = ctx.constant(2.0 * std::f64::consts::PI * i as f64 / n as f64);
            let s = ctx.unary(Unary::Sin, angle);
            let c = ctx.unary(Unary::Cos, angle);
            let rs = ctx.mul(a[2], s);
            let rc = ctx.mul(a[2], c);
            [ctx.add(a[3], rs), ctx.add(a[4], rc)]
        })
        .collect();
    Ok(polygon(ctx, sys, a[0], a[1], &vertices))
}

/// (11): A(x0, y0), B(x0 + Δx, y0 + h), C(x0 + a + Δx, y0 + h), D(x0 + a, y0),
/// Δx = h·cot α.
pub fn parallelogram(ctx: &mut Ctx, sys: RSystem, x: NodeId, y: NodeId, p: [NodeId; 5]) -> NodeId {
    let [x0, y0, side, h, alpha] = p;
    let tan = ctx.unary(Unary::Tan, alpha);
    let dx = ctx.div(h, tan);
    let xb = ctx.add(x0, dx);
    let yb = ctx.add(y0, h);
    let xc = ctx.add(xb, side);
    let xd = ctx.add(x0, side);
    polygon(ctx, sys, x, y, &[[x0, y0], [xb, yb], [xc, yb], [xd, y0]])
}

fn parallelogram_fn(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    Ok(parallelogram(
        ctx,
        sys,
        a[0],
        a[1],
        [a[2], a[3], a[4], a[5], a[6]],
    ))
}

/// (w/2)² − (x − x0 − w/2)²: positive on the slab x0 < x < x0 + w.
fn slab(ctx: &mut Ctx, x: NodeId, x0: NodeId, w: NodeId) -> NodeId {
    let two = ctx.constant(2.0);
    let half = ctx.div(w, two);
    let mid = ctx.add(x0, half);
    let d = ctx.sub(x, mid);
    let hh = ctx.square(half);
    let dd = ctx.square(d);
    ctx.sub(hh, dd)
}

/// (12).
pub fn rectangle(ctx: &mut Ctx, sys: RSystem, x: NodeId, y: NodeId, p: [NodeId; 4]) -> NodeId {
    let sx = slab(ctx, x, p[0], p[2]);
    let sy = slab(ctx, y, p[1], p[3]);
    sys.and(ctx, sx, sy)
}

fn rectangle_fn(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    Ok(rectangle(ctx, sys, a[0], a[1], [a[2], a[3], a[4], a[5]]))
}

/// (13): Parallelogram(x, y, x0, y0, a, h, α) ∧ Parallelogram(z, y, z0, y0, d, h, β).
fn parallelepiped(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    let [x, y, z, x0, y0, z0, side, h, d, alpha, beta] =
        <[NodeId; 11]>::try_from(a).map_err(|_| "needs 11 arguments".to_string())?;
    let front = parallelogram(ctx, sys, x, y, [x0, y0, side, h, alpha]);
    let side_view = parallelogram(ctx, sys, z, y, [z0, y0, d, h, beta]);
    Ok(sys.and(ctx, front, side_view))
}

/// (14): the conjunction of three slabs; (x0, y0, z0) is the low corner.
fn box_fn(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    let sx = slab(ctx, a[0], a[3], a[6]);
    let sy = slab(ctx, a[1], a[4], a[7]);
    let sz = slab(ctx, a[2], a[5], a[8]);
    Ok(sys.and_all(ctx, &[sx, sy, sz]).unwrap_or(sx))
}

/// Paper 002's srect: two rectangles and four corner disks of radius r.
fn rounded_rectangle(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    let [x, y, x0, y0, w, h, r] =
        <[NodeId; 7]>::try_from(a).map_err(|_| "needs 7 arguments".to_string())?;
    let two = ctx.constant(2.0);
    let d = ctx.mul(two, r);
    let xr = ctx.add(x0, r);
    let yr = ctx.add(y0, r);
    let wd = ctx.sub(w, d);
    let hd = ctx.sub(h, d);
    let wide = rectangle(ctx, sys, x, y, [x0, yr, w, hd]);
    let tall = rectangle(ctx, sys, x, y, [xr, y0, wd, h]);
    let xw = ctx.add(x0, w);
    let yh = ctx.add(y0, h);
    let x1 = ctx.sub(xw, r);
    let y1 = ctx.sub(yh, r);
    let mut parts = vec![wide, tall];
    for (cx, cy) in [(xr, yr), (x1, yr), (x1, y1), (xr, y1)] {
        parts.push(round(ctx, &[x, y], r, &[cx, cy]));
    }
    Ok(sys.or_all(ctx, &parts).unwrap_or(wide))
}

/// A circular sector of radius r from angle1 to angle2 (counter-clockwise,
/// radians, constants): the disk ∧ the two bounding half-planes (∨ when the
/// opening is over π).
fn sector(ctx: &mut Ctx, sys: RSystem, a: &[NodeId]) -> Result<NodeId, String> {
    let [x, y, x0, y0, r, a1, a2] =
        <[NodeId; 7]>::try_from(a).map_err(|_| "needs 7 arguments".to_string())?;
    let (Some(t1), Some(t2)) = (ctx.const_value(a1), ctx.const_value(a2)) else {
        return Err("the angles must be constants".into());
    };
    let opening = t2 - t1;
    if !(opening > 0.0 && opening <= 2.0 * std::f64::consts::PI) {
        return Err(format!("angle2 − angle1 must be in (0, 2π], got {opening}"));
    }
    let disk = round(ctx, &[x, y], r, &[x0, y0]);
    let ray = |ctx: &mut Ctx, t: f64| {
        let cx = ctx.constant(t.cos());
        let cy = ctx.constant(t.sin());
        [ctx.add(x0, cx), ctx.add(y0, cy)]
    };
    let p1 = ray(ctx, t1);
    let p2 = ray(ctx, t2);
    // Left of centre → p1 (counter-clockwise from the first ray), right of centre → p2.
    let h1 = half_plane(ctx, x, y, p1, [x0, y0]);
    let h2 = half_plane(ctx, x, y, [x0, y0], p2);
    let wedge = if opening <= std::f64::consts::PI {
        sys.and(ctx, h1, h2)
    } else {
        sys.or(ctx, h1, h2)
    };
    Ok(sys.and(ctx, disk, wedge))
}
