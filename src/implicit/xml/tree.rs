//! R-function trees of the XML into the implicit IR: operations, primitives
//! with paper 001's parameters as attributes, `<formula>` expressions,
//! `<call>`s of `<function>`s with named arguments, and embedded `.rfs`
//! programs.

use super::{Def, Env, paths, settings};
use crate::diag::{Code, Diagnostic, Diagnostics, did_you_mean};
use crate::doc::grammar::R_TREE;
use crate::expr::{Expr, ExprKind};
use crate::implicit::ImplicitModel;
use crate::implicit::expr_ops;
use crate::implicit::ir::{Ctx, NodeId};
use crate::implicit::lang;
use crate::implicit::library;
use crate::implicit::rfs::RSystem;
use crate::span::SourceFile;
use crate::syntax::{Attribute, Element};
use std::collections::{BTreeSet, HashMap};

/// Deepest nesting of `<call>`s.
const MAX_CALL_DEPTH: usize = 64;
/// Largest expression an implicit solid may expand to.
const MAX_NODES: usize = 2_000_000;
/// Most operands expanded for one solid: calls are inlined, and hash-consing
/// keeps repeated results small, so the work, not the size, is what a
/// doubling chain of calls (f = union(g, g), g = union(h, h), …) blows up.
const MAX_WORK: usize = 200_000;

/// Names in scope: coordinates and function arguments.
pub type Scope = HashMap<String, NodeId>;

/// A `<function>`: its body and argument names.
pub struct UserFunction<'a, 's> {
    pub body: Option<&'a Element<'s>>,
    pub args: Vec<String>,
}

pub type Functions<'a, 's> = HashMap<String, UserFunction<'a, 's>>;

/// The `<function>` elements by name (a repeated name or argument is W132).
pub fn collect_functions<'a, 's>(
    defs: &'a [Element<'s>],
    diags: &mut Diagnostics,
) -> Functions<'a, 's> {
    let mut out = Functions::new();
    for e in defs.iter().filter(|e| e.name == "function") {
        let (Some(name), Some(args)) = (e.attribute("name"), e.attribute("args")) else {
            continue;
        };
        let mut list: Vec<String> = Vec::new();
        for a in args.value.split_whitespace() {
            if list.iter().any(|b| b == a) || ["x", "y", "z"].contains(&a) {
                diags.push(Diagnostic::new(
                    Code::ImplicitDuplicate,
                    args.value_span,
                    format!("argument '{a}' of function '{}' is listed twice or hides a coordinate; it is ignored", name.value.trim()),
                ));
                continue;
            }
            list.push(a.to_string());
        }
        let key = name.value.trim().to_string();
        if out.contains_key(&key) {
            diags.push(Diagnostic::new(
                Code::ImplicitDuplicate,
                name.value_span,
                format!("function '{key}' is defined twice; the later definition is ignored"),
            ));
            continue;
        }
        out.insert(
            key,
            UserFunction {
                body: e.children.first(),
                args: list,
            },
        );
    }
    out
}

pub struct Lowerer<'e, 'a, 's> {
    pub ctx: Ctx,
    pub sys: RSystem,
    pub used: BTreeSet<String>,
    env: &'e Env<'e>,
    functions: Option<&'a Functions<'a, 's>>,
    stack: Vec<String>,
    work: usize,
}

/// The scope of the three coordinates named `names`.
fn coordinates(ctx: &mut Ctx, names: [&str; 3]) -> Scope {
    (0..3u8)
        .map(|axis| (names[axis as usize].to_string(), ctx.var(axis)))
        .collect()
}

/// `<rfunction>`: its Geom attributes and its one tree.
pub(super) fn rfunction(
    e: &Element,
    env: &Env,
    functions: &Functions,
    used: &mut BTreeSet<String>,
    diags: &mut Diagnostics,
) -> Option<Def> {
    let geom = settings::geom(e, env, used, diags);
    let mut lw = Lowerer::new(env, Some(functions));
    lw.sys = geom.as_ref().map_or(RSystem::Rvachev, |g| g.rsystem);
    let scope = coordinates(&mut lw.ctx, ["x", "y", "z"]);
    let root = e.children.first().and_then(|c| lw.node(c, &scope, diags));
    used.extend(std::mem::take(&mut lw.used));
    let (geom, root) = (geom?, root?);
    Some(Def::Function(ImplicitModel {
        geom,
        ctx: lw.ctx,
        root,
    }))
}

/// A `<trim>`'s one tree over the global x, y, z (paper 002's F).
pub(super) fn trim_tree(
    e: &Element,
    env: &Env,
    functions: &Functions,
    used: &mut BTreeSet<String>,
    diags: &mut Diagnostics,
) -> Option<(Ctx, NodeId)> {
    let mut lw = Lowerer::new(env, Some(functions));
    let scope = coordinates(&mut lw.ctx, ["x", "y", "z"]);
    let root = e.children.first().and_then(|c| lw.node(c, &scope, diags));
    used.extend(std::mem::take(&mut lw.used));
    Some((lw.ctx, root?))
}

/// `<level_surface>`: the solid {f > c} in the three named variables, which
/// are the mesh's x, y and z in order.
pub(super) fn level_surface(
    e: &Element,
    env: &Env,
    used: &mut BTreeSet<String>,
    diags: &mut Diagnostics,
) -> Option<Def> {
    let geom = settings::geom(e, env, used, diags);
    let names: Vec<&str> = e.attribute("variables").map_or(vec!["x", "y", "z"], |a| {
        a.value.split_whitespace().collect()
    });
    let distinct = names.len() == 3
        && names[0] != names[1]
        && names[1] != names[2]
        && names[0] != names[2]
        && names
            .iter()
            .all(|n| crate::resolve::is_plain_name(n) && *n != "pi");
    if !distinct {
        let span = e.attribute("variables").map(|a| a.value_span);
        diags.push(Diagnostic::new(
            Code::ImplicitBadSetting,
            span,
            format!(
                "variables=\"{}\": give three distinct names such as \"t x y\"",
                names.join(" ")
            ),
        ));
        return None;
    }
    let level = match settings::constant(e, "level", env, used, diags) {
        Some(None) => return None,
        Some(Some(v)) => v,
        None => 0.0,
    };
    let mut lw = Lowerer::new(env, None);
    let scope = coordinates(&mut lw.ctx, [names[0], names[1], names[2]]);
    let f = e
        .attribute("expression")
        .and_then(|a| lw.attr_expr(a, &scope, diags));
    used.extend(std::mem::take(&mut lw.used));
    let (geom, f) = (geom?, f?);
    let c = lw.ctx.constant(level);
    let root = lw.ctx.sub(f, c);
    Some(Def::Function(ImplicitModel {
        geom,
        ctx: lw.ctx,
        root,
    }))
}

impl<'e, 'a, 's> Lowerer<'e, 'a, 's> {
    pub fn new(env: &'e Env<'e>, functions: Option<&'a Functions<'a, 's>>) -> Self {
        Lowerer {
            ctx: Ctx::new(),
            sys: RSystem::Rvachev,
            used: BTreeSet::new(),
            env,
            functions,
            stack: Vec::new(),
            work: 0,
        }
    }

    /// An attribute's expression as a node.
    pub fn attr_expr(
        &mut self,
        a: &Attribute,
        scope: &Scope,
        diags: &mut Diagnostics,
    ) -> Option<NodeId> {
        let expr = crate::doc::parse_attribute_expr(self.env.source, a, diags)?;
        match self.expr(&expr, scope) {
            Ok(id) => Some(id),
            Err(d) => {
                diags.push(d);
                None
            }
        }
    }

    fn expr(&mut self, e: &Expr, scope: &Scope) -> Result<NodeId, Diagnostic> {
        Ok(match &e.kind {
            ExprKind::Number(v) => self.ctx.constant(*v),
            ExprKind::Name(n) => {
                if let Some(&id) = scope.get(n) {
                    id
                } else if let Some((_, v)) = self.env.parameters.iter().find(|(p, _)| p == n) {
                    self.used.insert(n.clone());
                    self.ctx.constant(*v)
                } else if n == "pi" {
                    self.ctx.constant(std::f64::consts::PI)
                } else {
                    let mut names: Vec<&str> = scope.keys().map(String::as_str).collect();
                    names.extend(self.env.parameters.iter().map(|(p, _)| p.as_str()));
                    names.sort_unstable();
                    let mut d = Diagnostic::new(
                        Code::ImplicitUnknownName,
                        e.span,
                        format!("unknown name '{n}': not a coordinate, argument or parameter"),
                    );
                    if let Some(s) = did_you_mean(n, names.iter().copied()) {
                        d = d.with_help(format!("did you mean '{s}'?"));
                    }
                    return Err(d);
                }
            }
            ExprKind::Neg(a) => {
                let a = self.expr(a, scope)?;
                self.ctx.neg(a)
            }
            ExprKind::Binary(op, a, b) => {
                let a = self.expr(a, scope)?;
                let b = self.expr(b, scope)?;
                self.ctx.binary(expr_ops::binary(*op), a, b)
            }
            ExprKind::Call(f, args) => {
                let mut ids = Vec::with_capacity(args.len());
                for a in args {
                    ids.push(self.expr(a, scope)?);
                }
                expr_ops::apply(&mut self.ctx, *f, &ids).ok_or_else(|| {
                    Diagnostic::new(
                        Code::WrongArgumentCount,
                        e.span,
                        format!("{}() needs an argument", f.name()),
                    )
                })?
            }
        })
    }

    /// One operand of a tree; `None` after reporting its errors.
    pub fn node(&mut self, e: &Element, scope: &Scope, diags: &mut Diagnostics) -> Option<NodeId> {
        self.work += 1;
        if self.ctx.nodes.len() > MAX_NODES || self.work > MAX_WORK {
            // Report once, at the operand where the budget ran out.
            if self.work <= MAX_WORK + 1 {
                diags.push(Diagnostic::new(
                    Code::ImplicitRecursion,
                    e.name_span,
                    format!("the implicit solid expands to more than {MAX_NODES} nodes or {MAX_WORK} operands"),
                ));
            }
            self.work = MAX_WORK + 2;
            return None;
        }
        match e.name {
            "union" | "intersection" | "difference" | "not" => {
                let parts: Vec<Option<NodeId>> = e
                    .children
                    .iter()
                    .map(|c| self.node(c, scope, diags))
                    .collect();
                let parts: Vec<NodeId> = parts.into_iter().collect::<Option<_>>()?;
                let (&first, rest) = parts.split_first()?;
                let sys = self.sys;
                Some(match e.name {
                    "union" => sys.or_all(&mut self.ctx, &parts)?,
                    "intersection" => sys.and_all(&mut self.ctx, &parts)?,
                    "not" => sys.not(&mut self.ctx, first),
                    _ => rest
                        .iter()
                        .fold(first, |acc, &b| sys.difference(&mut self.ctx, acc, b)),
                })
            }
            "formula" => self.attr_expr(e.attribute("value")?, scope, diags),
            "call" => self.call(e, scope, diags),
            "rfs" => self.rfs(e, diags),
            "convex_polygon" => {
                let mut args = vec![*scope.get("x")?, *scope.get("y")?];
                let mut ok = true;
                for v in &e.children {
                    for c in ["x", "y"] {
                        match v.attribute(c).and_then(|a| self.attr_expr(a, scope, diags)) {
                            Some(id) => args.push(id),
                            None => ok = false,
                        }
                    }
                }
                if !ok {
                    return None;
                }
                self.library(e, "ConvexPolygon", &args, diags)
            }
            name => {
                let rule = R_TREE.iter().find(|r| r.name == name)?;
                let lib = library::lookup(name)?;
                let mut args: Vec<NodeId> = coordinate_count(lib.signature)
                    .iter()
                    .filter_map(|c| scope.get(*c).copied())
                    .collect();
                let mut ok = true;
                for attr in rule.attrs {
                    match e
                        .attribute(attr.name)
                        .and_then(|a| self.attr_expr(a, scope, diags))
                    {
                        Some(id) => args.push(id),
                        None => ok = false,
                    }
                }
                if !ok {
                    return None;
                }
                self.library(e, lib.name, &args, diags)
            }
        }
    }

    fn library(
        &mut self,
        e: &Element,
        name: &str,
        args: &[NodeId],
        diags: &mut Diagnostics,
    ) -> Option<NodeId> {
        let lib = library::LIBRARY.iter().find(|l| l.name == name)?;
        if !lib.arity.accepts(args.len()) {
            diags.push(Diagnostic::new(
                Code::ImplicitLibraryArgument,
                e.name_span,
                format!(
                    "<{}> got {} values; it takes {}",
                    e.name,
                    args.len(),
                    lib.signature
                ),
            ));
            return None;
        }
        match (lib.build)(&mut self.ctx, self.sys, args) {
            Ok(id) => Some(id),
            Err(m) => {
                diags.push(Diagnostic::new(
                    Code::ImplicitLibraryArgument,
                    e.name_span,
                    format!("<{}>: {m}", e.name),
                ));
                None
            }
        }
    }

    fn call(&mut self, e: &Element, scope: &Scope, diags: &mut Diagnostics) -> Option<NodeId> {
        let fattr = e.attribute("function")?;
        let fname = fattr.value.trim();
        let functions = self.functions?;
        let Some(f) = functions.get(fname) else {
            let mut d = Diagnostic::new(
                Code::ImplicitUnknownFunction,
                fattr.value_span,
                format!("no <function name=\"{fname}\"> in this file"),
            );
            if let Some(s) = did_you_mean(fname, functions.keys().map(String::as_str)) {
                d = d.with_help(format!("did you mean '{s}'?"));
            }
            diags.push(d);
            return None;
        };
        if self.stack.iter().any(|s| s == fname) || self.stack.len() >= MAX_CALL_DEPTH {
            diags.push(Diagnostic::new(
                Code::ImplicitRecursion,
                fattr.value_span,
                format!(
                    "'{fname}' is called inside itself (through {}) or calls nest deeper than {MAX_CALL_DEPTH}",
                    self.stack.join(" → ")
                ),
            ));
            return None;
        }
        let mut inner: Scope = ["x", "y", "z"]
            .iter()
            .filter_map(|c| scope.get(*c).map(|&id| (c.to_string(), id)))
            .collect();
        let mut ok = true;
        for a in e.attributes.iter().filter(|a| a.name != "function") {
            if !f.args.iter().any(|x| x == a.name) {
                let mut d = Diagnostic::new(
                    Code::ImplicitUnknownFunction,
                    a.name_span,
                    format!(
                        "function '{fname}' has no argument '{}'; it takes: {}",
                        a.name,
                        f.args.join(" ")
                    ),
                );
                if let Some(s) = did_you_mean(a.name, f.args.iter().map(String::as_str)) {
                    d = d.with_help(format!("did you mean '{s}'?"));
                }
                diags.push(d);
                ok = false;
                continue;
            }
            match self.attr_expr(a, scope, diags) {
                Some(id) => {
                    inner.insert(a.name.to_string(), id);
                }
                None => ok = false,
            }
        }
        let missing: Vec<&str> = f
            .args
            .iter()
            .filter(|x| e.attribute(x).is_none())
            .map(String::as_str)
            .collect();
        if !missing.is_empty() {
            diags.push(Diagnostic::new(
                Code::ImplicitUnknownFunction,
                e.name_span,
                format!(
                    "the call of '{fname}' gives no value for: {}",
                    missing.join(" ")
                ),
            ));
            ok = false;
        }
        if !ok {
            return None;
        }
        self.stack.push(fname.to_string());
        let result = f.body.and_then(|b| self.node(b, &inner, diags));
        self.stack.pop();
        result
    }

    /// `<rfs program="…"/>` or `<rfs file="…"/>`: the program's result function.
    fn rfs(&mut self, e: &Element, diags: &mut Diagnostics) -> Option<NodeId> {
        let (label, text, span) = match (e.attribute("program"), e.attribute("file")) {
            (Some(p), None) => ("program".to_string(), p.value.to_string(), p.value_span),
            (None, Some(f)) => {
                let path = match paths::resolve(self.env, f) {
                    Ok(p) => p,
                    Err(d) => {
                        diags.push(d);
                        return None;
                    }
                };
                match std::fs::read_to_string(&path) {
                    Ok(t) => (f.value.trim().to_string(), t, f.value_span),
                    Err(err) => {
                        diags.push(Diagnostic::new(
                            Code::ImplicitFileUnreadable,
                            f.value_span,
                            format!("cannot read {}: {err}", path.display()),
                        ));
                        return None;
                    }
                }
            }
            _ => {
                diags.push(Diagnostic::new(
                    Code::ImplicitRfsProgram,
                    e.name_span,
                    "<rfs> takes either program=\"…\" or file=\"…\"",
                ));
                return None;
            }
        };
        let source = SourceFile::new(label.clone(), text);
        let (model, inner) = lang::compile(&source);
        let mut failed = false;
        for d in inner.items.iter().filter(|d| d.is_error()) {
            failed = true;
            let at = d.span.map_or(String::new(), |s| {
                let lc = source.line_col(s.start as usize);
                format!(":{}:{}", lc.line, lc.column)
            });
            let mut outer = Diagnostic::new(
                Code::ImplicitRfsProgram,
                span,
                format!("{label}{at}: error[{}]: {}", d.code.as_str(), d.message),
            );
            if let Some(help) = &d.help {
                outer = outer.with_help(help.clone());
            }
            diags.push(outer);
        }
        let model = model.filter(|_| !failed)?;
        Some(super::import(&mut self.ctx, &model.ctx, model.root))
    }
}

/// The leading coordinate parameters of a library signature ("Ball(x, y, z, r, …)").
fn coordinate_count(signature: &str) -> Vec<&'static str> {
    let inside = signature.split_once('(').map_or("", |p| p.1);
    inside
        .split(',')
        .map(str::trim)
        .take_while(|p| ["x", "y", "z"].contains(p))
        .map(|p| match p {
            "x" => "x",
            "y" => "y",
            _ => "z",
        })
        .collect()
}
