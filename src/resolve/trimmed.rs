//! Paper 002's parametric surfaces and their trims: control points and
//! dimensions evaluated, coordinate and trim expressions compiled to
//! implicit-IR programs with parameters folded in.

use super::geometry::Geometry;
use super::objects::Resolver;
use crate::diag::{Code, Diagnostic};
use crate::doc::{CarrierSpec, Number, Object, TrimSpec, TrimmedSpec};
use crate::expr::{Expr, ExprKind};
use crate::geom::point_calculus::Patch9;
use crate::geom::{Frame, Point3};
use crate::implicit::ir::Ctx;
use crate::implicit::tape::Ssa;
use crate::trimmed::{Carrier, Trim, TrimmedSurface, program};

pub(super) fn surface(
    r: &mut Resolver,
    object: &Object,
    spec: &TrimmedSpec,
    frame: &Frame,
) -> Option<Geometry> {
    let name = object.name.text.as_str();
    let invalid = |r: &mut Resolver, message: String, help: &str| {
        r.diags.push(
            Diagnostic::new(Code::TrimmedCarrierInvalid, object.span, message).with_help(help),
        );
    };
    let (carrier, placement, rect) = match &spec.carrier {
        CarrierSpec::Bezier { rows } => {
            let width = rows.first().map_or(0, |row| row.len());
            if let Some((i, row)) = rows.iter().enumerate().find(|(_, row)| row.len() != width) {
                invalid(
                    r,
                    format!(
                        "bezier_surface '{name}': row {} has {} control points, row 1 has {width}",
                        i + 1,
                        row.len()
                    ),
                    "give every row the same number of <node>s",
                );
                return None;
            }
            let mut grid = Vec::with_capacity(rows.len());
            let mut ok = true;
            for row in rows {
                let mut points = Vec::with_capacity(row.len());
                for p in row {
                    match r.point(p, frame, false) {
                        Some(p) => points.push(p),
                        None => ok = false,
                    }
                }
                grid.push(points);
            }
            if !ok || rows.len() < 2 {
                return None;
            }
            (
                Carrier::Bezier { rows: grid },
                Frame::identity(),
                [0.0, 1.0, 0.0, 1.0],
            )
        }
        CarrierSpec::Cone {
            bottom_radius,
            top_radius,
            length,
            from_angle,
            to_angle,
        } => {
            let r1 = r.number(bottom_radius.as_ref()?)?;
            let r2 = r.number(top_radius.as_ref()?)?;
            let l = r.number(length.as_ref()?)?;
            let a0 = optional(r, from_angle, 0.0)?;
            let a1 = optional(r, to_angle, 360.0)?;
            let ok = l > 0.0 && r1 >= 0.0 && r2 >= 0.0 && r1 + r2 > 0.0 && a1 > a0;
            if !ok {
                invalid(
                    r,
                    format!(
                        "cone_surface '{name}': length {l}, radii {r1} and {r2}, angles {a0}° to {a1}°"
                    ),
                    "use a positive length, radii ≥ 0 (not both 0) and from_angle < to_angle",
                );
                return None;
            }
            (
                Carrier::Cone { r1, r2, length: l },
                *frame,
                [0.0, l, a0.to_radians(), a1.to_radians()],
            )
        }
        CarrierSpec::Sphere {
            radius,
            latitudes,
            angles,
        } => {
            let radius = r.number(radius.as_ref()?)?;
            let l0 = r.number(latitudes[0].as_ref()?)?;
            let l1 = r.number(latitudes[1].as_ref()?)?;
            let a0 = optional(r, &angles[0], 0.0)?;
            let a1 = optional(r, &angles[1], 360.0)?;
            let ok = radius > 0.0 && -90.0 <= l0 && l0 < l1 && l1 <= 90.0 && a0 < a1;
            if !ok {
                invalid(
                    r,
                    format!(
                        "sphere_surface '{name}': radius {radius}, latitudes {l0}° to {l1}°, angles {a0}° to {a1}°"
                    ),
                    "use a positive radius, -90 <= from_latitude < to_latitude <= 90 and from_angle < to_angle",
                );
                return None;
            }
            (
                Carrier::Sphere { radius },
                *frame,
                [
                    l0.to_radians(),
                    l1.to_radians(),
                    a0.to_radians(),
                    a1.to_radians(),
                ],
            )
        }
        CarrierSpec::Torus {
            radii,
            tube,
            angles,
        } => {
            let major = r.number(radii[0].as_ref()?)?;
            let minor = r.number(radii[1].as_ref()?)?;
            let t0 = r.number(tube[0].as_ref()?)?;
            let t1 = r.number(tube[1].as_ref()?)?;
            let a0 = optional(r, &angles[0], 0.0)?;
            let a1 = optional(r, &angles[1], 360.0)?;
            let ok = minor > 0.0 && major > minor && t0 < t1 && t1 - t0 <= 360.0 && a0 < a1;
            if !ok {
                invalid(
                    r,
                    format!(
                        "torus_surface '{name}': radii {major} and {minor}, tube angles {t0}° to {t1}°, angles {a0}° to {a1}°"
                    ),
                    "use 0 < minor_radius < major_radius, from_tube_angle < to_tube_angle at most a full turn apart, and from_angle < to_angle",
                );
                return None;
            }
            (
                Carrier::Torus { major, minor },
                *frame,
                [
                    t0.to_radians(),
                    t1.to_radians(),
                    a0.to_radians(),
                    a1.to_radians(),
                ],
            )
        }
        CarrierSpec::Patch9 { rows } => {
            let mut grid = [[Point3::origin(); 3]; 3];
            if rows.len() != 3 || rows.iter().any(|row| row.len() != 3) {
                // Reported by the structural check.
                return None;
            }
            let mut ok = true;
            for (i, row) in rows.iter().enumerate() {
                for (j, p) in row.iter().enumerate() {
                    match r.point(p, frame, false) {
                        Some(p) => grid[i][j] = p,
                        None => ok = false,
                    }
                }
            }
            if !ok {
                return None;
            }
            (
                Carrier::Patch9(Box::new(Patch9 { rows: grid })),
                Frame::identity(),
                [0.0, 1.0, 0.0, 1.0],
            )
        }
        CarrierSpec::Expressions { xyz, rect } => {
            let mut bounds = [0.0; 4];
            for (slot, n) in bounds.iter_mut().zip(rect) {
                *slot = r.number(n.as_ref()?)?;
            }
            if !(bounds[1] > bounds[0] && bounds[3] > bounds[2]) {
                invalid(
                    r,
                    format!(
                        "parametric_surface '{name}': the rectangle [{}, {}] × [{}, {}] is empty",
                        bounds[0], bounds[1], bounds[2], bounds[3]
                    ),
                    "give u_min < u_max and v_min < v_max",
                );
                return None;
            }
            let mut programs = Vec::with_capacity(3);
            for n in xyz {
                programs.push(compile(r, n.as_ref()?, &["u", "v"], name, "u and v")?);
            }
            let xyz: [Ssa; 3] = programs.try_into().ok()?;
            (Carrier::Expressions { xyz: Box::new(xyz) }, *frame, bounds)
        }
    };
    let trim = match &spec.trim {
        // The driver sets it from the tree (implicit::xml::lower).
        Some(t) if t.tree && t.equation.is_none() => None,
        Some(t) => Some(trim(r, t, name)?),
        None => None,
    };
    Some(Geometry::Trimmed(Box::new(TrimmedSurface {
        name: name.to_string(),
        carrier,
        frame: placement,
        rect,
        trim,
    })))
}

fn optional(r: &mut Resolver, n: &Option<Number>, default: f64) -> Option<f64> {
    match n {
        Some(n) => r.number(n),
        None => Some(default),
    }
}

fn trim(r: &mut Resolver, t: &TrimSpec, name: &str) -> Option<Trim> {
    let Some(equation) = t.equation.as_ref().filter(|_| !t.tree) else {
        let (what, help) = if t.tree {
            (
                "both equation= and an R-function tree",
                "keep one of the two",
            )
        } else {
            (
                "neither equation= nor an R-function tree",
                "give equation=\"F(x, y, z)\" or one tree such as <union>",
            )
        };
        r.diags.push(
            Diagnostic::new(
                Code::TrimmedTrimForm,
                Some(t.span),
                format!("the trim of '{name}' has {what}"),
            )
            .with_help(help),
        );
        return None;
    };
    let mut ctx = Ctx::new();
    let folded = fold(r, &*equation.expr()?, &["x", "y", "z"])?;
    match program::build(&mut ctx, &folded, &["x", "y", "z"]) {
        Ok(root) => Some(Trim::new(&ctx, root, t.negative)),
        Err(var) => {
            unknown(r, equation, name, &var, "x, y and z");
            None
        }
    }
}

fn compile(r: &mut Resolver, n: &Number, vars: &[&str], name: &str, what: &str) -> Option<Ssa> {
    let folded = fold(r, &*n.expr()?, vars)?;
    let mut ctx = Ctx::new();
    match program::build(&mut ctx, &folded, vars) {
        Ok(root) => Some(Ssa::from_ctx(&ctx, root)),
        Err(var) => {
            unknown(r, n, name, &var, what);
            None
        }
    }
}

fn unknown(r: &mut Resolver, n: &Number, name: &str, var: &str, what: &str) {
    r.diags.push(
        Diagnostic::new(
            Code::TrimmedUnknownVariable,
            n.span,
            format!(
                "'{name}': the expression uses '{var}', which is not one of {what} nor a parameter"
            ),
        )
        .with_help(format!(
            "write it in {what}, or define '{var}' in <parameters>"
        )),
    );
}

/// Replaces parameters and basis coordinates by their values; the free
/// variables `vars` (and names nothing defines) stay.
fn fold(r: &mut Resolver, expr: &Expr, vars: &[&str]) -> Option<Expr> {
    Some(match &expr.kind {
        ExprKind::Name(n) if vars.contains(&n.as_str()) || n == "pi" => expr.clone(),
        ExprKind::Name(n) => {
            if !r.values.knows(n) {
                // Left for `program::build` to report with the variables it expects.
                return Some(expr.clone());
            }
            let number = Number::new(Some(expr.clone()), expr.span);
            Expr::number(r.number(&number)?, expr.span)
        }
        ExprKind::Number(_) => expr.clone(),
        ExprKind::Neg(inner) => Expr {
            kind: ExprKind::Neg(Box::new(fold(r, inner, vars)?)),
            span: expr.span,
        },
        ExprKind::Binary(op, a, b) => Expr {
            kind: ExprKind::Binary(
                *op,
                Box::new(fold(r, a, vars)?),
                Box::new(fold(r, b, vars)?),
            ),
            span: expr.span,
        },
        ExprKind::Call(f, args) => Expr {
            kind: ExprKind::Call(
                *f,
                args.iter()
                    .map(|a| fold(r, a, vars))
                    .collect::<Option<Vec<_>>>()?,
            ),
            span: expr.span,
        },
    })
}

#[allow(dead_code)]
fn _point_type(_: Point3) {}
