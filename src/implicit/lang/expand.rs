//! Semantics of an `.rfs` program: Geom settings become a [`Geom`], and the
//! result function is expanded (every call inlined, arguments positional)
//! into one IR expression of the coordinates.

use super::ast::{Expr, Function, Program, Stmt};
use crate::diag::{Code, Diagnostic, Diagnostics, did_you_mean};
use crate::implicit::Geom;
use crate::implicit::ir::{Binary, Ctx, NodeId, Unary};
use crate::implicit::library::{self, LIBRARY};
use crate::implicit::rfs::RSystem;
use crate::span::Span;
use std::collections::HashMap;

/// Deepest call nesting.
pub const MAX_CALL_DEPTH: usize = 64;
/// Largest expanded expression.
pub const MAX_NODES: usize = 2_000_000;
/// Most expressions visited while inlining calls (the work of expansion).
pub const MAX_STEPS: usize = 1_000_000;

const GEOM_FIELDS: &[&str] = &[
    "dimension",
    "x_min",
    "x_max",
    "y_min",
    "y_max",
    "z_min",
    "z_max",
    "nx",
    "ny",
    "nz",
    "name",
    "optiterations",
    "rsystem",
    "alpha",
];

const MATH_FUNCTIONS: &[&str] = &[
    "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "exp", "log", "sqrt", "abs", "pow",
    "min", "max", "floor", "ceil",
];

#[derive(Debug, Clone)]
enum Value {
    Num(NodeId),
    Str(String),
}

struct Expander<'p> {
    functions: HashMap<&'p str, &'p Function>,
    ctx: Ctx,
    sys: RSystem,
    stack: Vec<&'p str>,
    /// Expressions expanded so far: hash-consing keeps the result small even
    /// when calls double at every level, so the work needs its own bound.
    steps: usize,
}

fn err(code: Code, span: Span, message: impl Into<String>) -> Diagnostic {
    Diagnostic::new(code, span, message)
}

/// Reads the Geom settings (evaluated as constants, in file order).
pub fn read_geom(program: &Program, diags: &mut Diagnostics) -> Geom {
    let mut geom = Geom::default();
    let mut rsystem: Option<(String, Span)> = None;
    let mut alpha: Option<(f64, Span)> = None;
    let mut values: HashMap<String, f64> = HashMap::new();
    for (field, span, expr) in &program.geom {
        let mut ex = Expander {
            functions: HashMap::new(),
            ctx: Ctx::new(),
            sys: RSystem::Rvachev,
            stack: Vec::new(),
            steps: 0,
        };
        let mut env = HashMap::new();
        for (k, v) in &values {
            let id = ex.ctx.constant(*v);
            env.insert(format!("Geom.{k}"), Value::Num(id));
        }
        let value = match ex.expr(expr, &mut env) {
            Ok(v) => v,
            Err(d) => {
                diags.push(d);
                continue;
            }
        };
        let number = |ex: &Expander, v: &Value| match v {
            Value::Num(id) => ex.ctx.const_value(*id).ok_or_else(|| {
                err(
                    Code::RfsGeomValue,
                    expr.span(),
                    format!("Geom.{field} must be a constant"),
                )
            }),
            Value::Str(s) => Err(err(
                Code::RfsType,
                expr.span(),
                format!("Geom.{field} takes a number, not the string \"{s}\""),
            )),
        };
        let whole = |v: f64, lo: f64, hi: f64| v.fract() == 0.0 && v >= lo && v <= hi;
        let result: Result<(), Diagnostic> = (|| {
            match field.as_str() {
                "name" | "rsystem" => {
                    let Value::Str(s) = &value else {
                        return Err(err(
                            Code::RfsType,
                            expr.span(),
                            format!("Geom.{field} takes a string such as \"balls\""),
                        ));
                    };
                    if field == "name" {
                        geom.name = Some((s.clone(), expr.span()));
                    } else {
                        rsystem = Some((s.clone(), expr.span()));
                    }
                }
                "dimension" => {
                    let v = number(&ex, &value)?;
                    if v != 3.0 {
                        return Err(err(
                            Code::RfsGeomValue,
                            expr.span(),
                            format!("Geom.dimension = {v}: only 3 is meshed by this geomc"),
                        ));
                    }
                }
                "nx" | "ny" | "nz" => {
                    let v = number(&ex, &value)?;
                    if !whole(v, 1.0, 1024.0) {
                        return Err(err(
                            Code::RfsGeomValue,
                            expr.span(),
                            format!(
                                "Geom.{field} = {v}: give a whole number of cells from 1 to 1024"
                            ),
                        ));
                    }
                    let axis = match field.as_str() {
                        "nx" => 0,
                        "ny" => 1,
                        _ => 2,
                    };
                    if let Some(cells) = geom.cells.get_mut(axis) {
                        *cells = v as usize;
                    }
                    values.insert(field.clone(), v);
                }
                "optiterations" => {
                    let v = number(&ex, &value)?;
                    if !whole(v, 0.0, 1000.0) {
                        return Err(err(
                            Code::RfsGeomValue,
                            expr.span(),
                            format!("Geom.optiterations = {v}: give a whole number from 0 to 1000"),
                        ));
                    }
                    geom.optiterations = v as u32;
                    geom.optiterations_span = Some(*span);
                }
                "alpha" => alpha = Some((number(&ex, &value)?, expr.span())),
                "x_min" | "x_max" | "y_min" | "y_max" | "z_min" | "z_max" => {
                    let v = number(&ex, &value)?;
                    if !v.is_finite() {
                        return Err(err(
                            Code::RfsGeomValue,
                            expr.span(),
                            format!("Geom.{field} = {v}: give a finite number"),
                        ));
                    }
                    let axis = match field.as_bytes().first() {
                        Some(b'x') => 0,
                        Some(b'y') => 1,
                        _ => 2,
                    };
                    let bound = if field.ends_with("min") {
                        geom.min.get_mut(axis)
                    } else {
                        geom.max.get_mut(axis)
                    };
                    if let Some(bound) = bound {
                        *bound = v;
                    }
                    values.insert(field.clone(), v);
                }
                _ => {
                    let mut d = Diagnostic::new(
                        Code::RfsUnknownGeomField,
                        *span,
                        format!("unknown Geom field '{field}' is ignored"),
                    );
                    if let Some(s) = did_you_mean(field, GEOM_FIELDS.iter().copied()) {
                        d = d.with_help(format!("did you mean '{s}'?"));
                    }
                    diags.push(d);
                }
            }
            Ok(())
        })();
        if let Err(d) = result {
            diags.push(d);
        }
    }
    for ((name, &lo), &hi) in ["x", "y", "z"].into_iter().zip(&geom.min).zip(&geom.max) {
        if lo >= hi {
            let span = program
                .geom
                .iter()
                .find(|(f, _, _)| f == &format!("{name}_max"))
                .map(|g| g.2.span());
            diags.push(Diagnostic::new(
                Code::RfsGeomValue,
                span,
                format!(
                    "Geom.{name}_min = {} is not below Geom.{name}_max = {}",
                    lo, hi
                ),
            ));
        }
    }
    geom.rsystem = match rsystem {
        None => alpha.map_or(RSystem::Rvachev, |(a, _)| RSystem::Alpha(a)),
        Some((s, span)) => match s.as_str() {
            "rvachev" => RSystem::Rvachev,
            "minmax" => RSystem::MinMax,
            "alpha" => RSystem::Alpha(alpha.map_or(0.0, |a| a.0)),
            _ => {
                diags.push(err(
                    Code::RfsGeomValue,
                    span,
                    format!("Geom.rsystem = \"{s}\": use \"rvachev\", \"minmax\" or \"alpha\""),
                ));
                RSystem::Rvachev
            }
        },
    };
    if !geom.rsystem.is_valid() {
        let span = alpha.map(|a| a.1);
        diags.push(Diagnostic::new(
            Code::RfsGeomValue,
            span,
            format!(
                "Geom.alpha = {}: give a value in (−1, 1]",
                geom.rsystem.alpha()
            ),
        ));
        geom.rsystem = RSystem::Rvachev;
    }
    geom
}

/// Expands the result function into `(ctx, root)`.
pub fn expand(program: &Program, geom: &Geom, diags: &mut Diagnostics) -> Option<(Ctx, NodeId)> {
    let mut functions: HashMap<&str, &Function> = HashMap::new();
    for f in &program.functions {
        if functions.insert(f.name.as_str(), f).is_some() {
            diags.push(err(
                Code::RfsDuplicate,
                f.span,
                format!("function '{}' is defined twice", f.name),
            ));
        }
        if library::lookup(&f.name).is_some_and(|l| l.name == f.name) {
            diags.push(err(
                Code::RfsDuplicate,
                f.span,
                format!(
                    "function '{}' hides the library function of that name",
                    f.name
                ),
            ));
        }
        for (i, (p, span)) in f.params.iter().enumerate() {
            if f.params.iter().take(i).any(|(q, _)| q == p) {
                diags.push(err(
                    Code::RfsDuplicate,
                    *span,
                    format!("parameter '{p}' of '{}' is listed twice", f.name),
                ));
            }
        }
    }
    let result = match &geom.name {
        Some((name, span)) => match functions.get(name.as_str()) {
            Some(f) => *f,
            None => {
                let mut d = err(
                    Code::RfsNoResult,
                    *span,
                    format!("Geom.name = \"{name}\" names no function of this file"),
                );
                if let Some(s) = did_you_mean(name, functions.keys().copied()) {
                    d = d.with_help(format!("did you mean '{s}'?"));
                }
                diags.push(d);
                return None;
            }
        },
        None => {
            match functions.get("r_main") {
                Some(f) => *f,
                None => {
                    diags.push(Diagnostic::new(Code::RfsNoResult, None, "no result function: set Geom.name = \"…\" or define function r_main(x, y, z)"));
                    return None;
                }
            }
        }
    };
    if result.params.len() != 3 {
        diags.push(err(
            Code::RfsResultSignature,
            result.span,
            format!(
                "'{}' takes {} arguments; the result function takes the coordinates (x, y, z)",
                result.name,
                result.params.len()
            ),
        ));
        return None;
    }
    if diags.has_errors() {
        return None;
    }
    let mut ex = Expander {
        functions,
        ctx: Ctx::new(),
        sys: geom.rsystem,
        stack: Vec::new(),
        steps: 0,
    };
    let args: Vec<Value> = (0..3).map(|a| Value::Num(ex.ctx.var(a))).collect();
    match ex.call_user(result, args, result.span) {
        Ok(Value::Num(root)) => Some((ex.ctx, root)),
        Ok(Value::Str(_)) => {
            diags.push(err(
                Code::RfsType,
                result.span,
                format!("'{}' returns a string, not a function value", result.name),
            ));
            None
        }
        Err(d) => {
            diags.push(d);
            None
        }
    }
}

impl<'p> Expander<'p> {
    fn call_user(
        &mut self,
        f: &'p Function,
        args: Vec<Value>,
        span: Span,
    ) -> Result<Value, Diagnostic> {
        if self.stack.contains(&f.name.as_str()) {
            return Err(err(
                Code::RfsRecursion,
                span,
                format!(
                    "'{}' calls itself (through {})",
                    f.name,
                    self.stack.join(" → ")
                ),
            ));
        }
        if self.stack.len() >= MAX_CALL_DEPTH {
            return Err(err(
                Code::RfsRecursion,
                span,
                format!("calls nest deeper than {MAX_CALL_DEPTH}"),
            ));
        }
        self.stack.push(f.name.as_str());
        let mut env: HashMap<String, Value> =
            f.params.iter().map(|(p, _)| p.clone()).zip(args).collect();
        let mut result = None;
        for stmt in &f.body {
            match stmt {
                Stmt::Var(decls) => {
                    for (name, vspan, e) in decls {
                        let v = self.expr(e, &mut env)?;
                        if f.params.iter().any(|(p, _)| p == name) {
                            return Err(err(
                                Code::RfsDuplicate,
                                *vspan,
                                format!(
                                    "variable '{name}' has the name of a parameter of '{}'",
                                    f.name
                                ),
                            ));
                        }
                        env.insert(name.clone(), v);
                    }
                }
                Stmt::Assign(name, vspan, e) => {
                    if !env.contains_key(name) {
                        return Err(self.unknown(name, *vspan, &env));
                    }
                    let v = self.expr(e, &mut env)?;
                    env.insert(name.clone(), v);
                }
                Stmt::Return(e, _) => {
                    result = Some(self.expr(e, &mut env)?);
                    break;
                }
            }
        }
        self.stack.pop();
        result.ok_or_else(|| {
            err(
                Code::RfsNoReturn,
                f.span,
                format!("function '{}' ends without `return …;`", f.name),
            )
        })
    }

    fn unknown(&self, name: &str, span: Span, env: &HashMap<String, Value>) -> Diagnostic {
        let mut candidates: Vec<&str> = env.keys().map(String::as_str).collect();
        candidates.extend(self.functions.keys().copied());
        candidates.extend(LIBRARY.iter().map(|l| l.name));
        candidates.sort_unstable();
        let mut d = err(Code::RfsUnknownName, span, format!("unknown name '{name}'"));
        if let Some(s) = did_you_mean(name, candidates) {
            d = d.with_help(format!("did you mean '{s}'?"));
        }
        d
    }

    fn num(&self, v: Value, span: Span) -> Result<NodeId, Diagnostic> {
        match v {
            Value::Num(id) => Ok(id),
            Value::Str(s) => Err(err(
                Code::RfsType,
                span,
                format!("the string \"{s}\" is used as a number"),
            )),
        }
    }

    fn check_size(&mut self, span: Span) -> Result<(), Diagnostic> {
        self.steps += 1;
        if self.steps > MAX_STEPS {
            return Err(err(
                Code::RfsTooLarge,
                span,
                format!(
                    "expanding the program visits over {MAX_STEPS} expressions (calls inlined repeatedly)"
                ),
            )
            .with_help("a function calling another twice per level doubles the work at every level; compute shared values once in a variable"));
        }
        if self.ctx.nodes.len() > MAX_NODES {
            return Err(err(
                Code::RfsTooLarge,
                span,
                format!("the expanded expression exceeds {MAX_NODES} nodes"),
            ));
        }
        Ok(())
    }

    fn expr(&mut self, e: &Expr, env: &mut HashMap<String, Value>) -> Result<Value, Diagnostic> {
        self.check_size(e.span())?;
        Ok(match e {
            Expr::Num(v, _) => Value::Num(self.ctx.constant(*v)),
            Expr::Str(s, _) => Value::Str(s.clone()),
            Expr::Name(name, span) => match env.get(name) {
                Some(v) => v.clone(),
                None => return Err(self.unknown(name, *span, env)),
            },
            Expr::Member(obj, field, span) => match (obj.as_str(), field.as_str()) {
                ("Math", "PI") => Value::Num(self.ctx.constant(std::f64::consts::PI)),
                ("Math", "E") => Value::Num(self.ctx.constant(std::f64::consts::E)),
                ("Math", "SQRT2") => Value::Num(self.ctx.constant(std::f64::consts::SQRT_2)),
                _ => match env.get(&format!("{obj}.{field}")) {
                    Some(v) => v.clone(),
                    None => {
                        return Err(err(
                            Code::RfsUnknownName,
                            *span,
                            format!("unknown name '{obj}.{field}'"),
                        ));
                    }
                },
            },
            Expr::Neg(inner, span) => {
                let v = self.expr(inner, env)?;
                let v = self.num(v, *span)?;
                Value::Num(self.ctx.neg(v))
            }
            Expr::Binary(op, a, b, _) => {
                let va = self.expr(a, env)?;
                let va = self.num(va, a.span())?;
                let vb = self.expr(b, env)?;
                let vb = self.num(vb, b.span())?;
                Value::Num(match op {
                    '+' => self.ctx.add(va, vb),
                    '-' => self.ctx.sub(va, vb),
                    '*' => self.ctx.mul(va, vb),
                    '/' => self.ctx.div(va, vb),
                    _ => {
                        // a % b = a − b·trunc(a / b), as in ECMAScript.
                        let q = self.ctx.div(va, vb);
                        let fl = self.ctx.unary(Unary::Floor, q);
                        let ce = self.ctx.unary(Unary::Ceil, q);
                        let zero = self.ctx.constant(0.0);
                        let truncated = {
                            // trunc(q) = floor(q) for q ≥ 0, ceil(q) for q < 0:
                            // max(floor(q), 0) + min(ceil(q), 0).
                            let a = self.ctx.binary(Binary::Max, fl, zero);
                            let b = self.ctx.binary(Binary::Min, ce, zero);
                            self.ctx.add(a, b)
                        };
                        let m = self.ctx.mul(vb, truncated);
                        self.ctx.sub(va, m)
                    }
                })
            }
            Expr::Call {
                callee,
                callee_span,
                args,
                span,
            } => {
                let mut values = Vec::with_capacity(args.len());
                for a in args {
                    values.push(self.expr(a, env)?);
                }
                self.call(callee, *callee_span, *span, values, args, env)?
            }
        })
    }

    fn call(
        &mut self,
        callee: &str,
        callee_span: Span,
        span: Span,
        values: Vec<Value>,
        args: &[Expr],
        env: &HashMap<String, Value>,
    ) -> Result<Value, Diagnostic> {
        if let Some(name) = callee.strip_prefix("Math.") {
            let nums = values
                .into_iter()
                .zip(args)
                .map(|(v, a)| self.num(v, a.span()))
                .collect::<Result<Vec<_>, _>>()?;
            return self.math(name, callee_span, span, &nums).map(Value::Num);
        }
        if let Some(&f) = self.functions.get(callee) {
            if values.len() != f.params.len() {
                return Err(err(
                    Code::RfsArity,
                    span,
                    format!(
                        "'{callee}' takes {} arguments, got {}",
                        f.params.len(),
                        values.len()
                    ),
                ));
            }
            return self.call_user(f, values, span);
        }
        if let Some(lib) = LIBRARY.iter().find(|l| l.name == callee) {
            if !lib.arity.accepts(values.len()) {
                return Err(err(
                    Code::RfsArity,
                    span,
                    format!(
                        "'{callee}' got {} arguments; it takes {}",
                        values.len(),
                        lib.signature
                    ),
                ));
            }
            let nums = values
                .into_iter()
                .zip(args)
                .map(|(v, a)| self.num(v, a.span()))
                .collect::<Result<Vec<_>, _>>()?;
            return (lib.build)(&mut self.ctx, self.sys, &nums)
                .map(Value::Num)
                .map_err(|m| err(Code::RfsLibraryArgument, span, format!("{callee}: {m}")));
        }
        Err(self.unknown(callee, callee_span, env))
    }

    fn math(
        &mut self,
        name: &str,
        callee_span: Span,
        span: Span,
        a: &[NodeId],
    ) -> Result<NodeId, Diagnostic> {
        let unary = match name {
            "sin" => Some(Unary::Sin),
            "cos" => Some(Unary::Cos),
            "tan" => Some(Unary::Tan),
            "asin" => Some(Unary::Asin),
            "acos" => Some(Unary::Acos),
            "atan" => Some(Unary::Atan),
            "exp" => Some(Unary::Exp),
            "log" => Some(Unary::Ln),
            "sqrt" => Some(Unary::Sqrt),
            "abs" => Some(Unary::Abs),
            "floor" => Some(Unary::Floor),
            "ceil" => Some(Unary::Ceil),
            _ => None,
        };
        let wrong_arity = |n: usize| {
            err(
                Code::RfsArity,
                span,
                format!(
                    "Math.{name} takes {n} argument{}, got {}",
                    if n == 1 { "" } else { "s" },
                    a.len()
                ),
            )
        };
        if let Some(u) = unary {
            let &[x] = a else {
                return Err(wrong_arity(1));
            };
            return Ok(self.ctx.unary(u, x));
        }
        match (name, a.split_first()) {
            ("pow" | "atan2", _) => {
                let &[x, y] = a else {
                    return Err(wrong_arity(2));
                };
                let op = if name == "pow" {
                    Binary::Pow
                } else {
                    Binary::Atan2
                };
                Ok(self.ctx.binary(op, x, y))
            }
            ("min" | "max", Some((&first, rest))) => {
                let op = if name == "min" {
                    Binary::Min
                } else {
                    Binary::Max
                };
                Ok(rest
                    .iter()
                    .fold(first, |acc, &x| self.ctx.binary(op, acc, x)))
            }
            ("min" | "max", None) => Err(err(
                Code::RfsArity,
                span,
                format!("Math.{name} needs at least one argument"),
            )),
            (_, _) => {
                let mut d = err(
                    Code::RfsUnknownName,
                    callee_span,
                    format!("unknown function 'Math.{name}'"),
                );
                if let Some(s) = did_you_mean(name, MATH_FUNCTIONS.iter().copied()) {
                    d = d.with_help(format!("did you mean 'Math.{s}'?"));
                }
                Err(d)
            }
        }
    }
}
