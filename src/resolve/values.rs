//! Parameters and basis coordinates: their values (with `--set` overrides),
//! evaluated on demand with cycle detection, and the evaluation of every other
//! numeric attribute against them.

use crate::diag::{Code, Diagnostic, Diagnostics, did_you_mean};
use crate::doc::{Axis, Document, Number};
use crate::expr::{self, EvalError, Expr};
use crate::span::Span;
use foldhash::{HashMap, HashMapExt, HashSet};
use std::collections::BTreeMap;

/// Where a number is used: basis coordinates are allowed only as coordinates
/// of their own axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ctx {
    Any,
    Coordinate(Axis),
}

#[derive(Debug, Clone)]
enum Source {
    Parameter {
        expr: Option<Expr>,
        span: Span,
    },
    Basis {
        axis: Axis,
        expr: Option<Expr>,
        span: Span,
    },
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum State {
    InProgress,
    Done(Option<f64>),
}

/// The parameters and basis coordinates some expressions used, by their
/// index in [`Values`]. A resolver on each thread keeps its own; unions of
/// them are what the unused-parameter check reads, so the order in which
/// they are merged does not matter.
#[derive(Debug, Clone, Default)]
pub struct Used(HashSet<u32>);

impl Used {
    pub fn merge(&mut self, other: Used) {
        self.0.extend(other.0);
    }
}

/// What a name in an expression stands for where it is used.
enum Admitted {
    /// A parameter, or a basis coordinate of the expected axis: its value.
    Value,
    /// A basis coordinate where it cannot be used (reported): used, no value.
    UsedOnly,
    /// Not a parameter or basis coordinate (reported unless `pi`).
    No,
}

/// The evaluator of numeric attributes. Parameters and basis coordinates are
/// evaluated first ([`Values::evaluate_all`], which needs `&mut`); after that
/// the values are frozen and every other number is evaluated through `&self`
/// with a [`Used`] of the caller's, so resolvers on several threads share one.
pub struct Values<'d> {
    /// Each name's index (for [`Used`]) and definition.
    sources: HashMap<String, (u32, Source)>,
    /// Parameter names in definition order.
    parameter_order: Vec<String>,
    state: HashMap<String, State>,
    /// Names used by parameters and basis coordinates themselves.
    used: Used,
    /// Every defined name with its kind, to say "wrong kind" instead of
    /// "undefined".
    names: &'d super::NameTable<'d>,
    stack: Vec<String>,
}

impl<'d> Values<'d> {
    /// Collects parameters and basis coordinates; `overrides` (from `--set`)
    /// replace parameter expressions. Duplicate names are reported by the name
    /// table, so the first definition wins here.
    pub fn new(
        doc: &Document,
        overrides: &[(String, Expr)],
        names: &'d super::NameTable<'d>,
    ) -> Values<'d> {
        let mut sources = HashMap::new();
        let mut parameter_order = Vec::new();
        for p in &doc.parameters {
            if sources.contains_key(&p.name.text) {
                continue;
            }
            parameter_order.push(p.name.text.clone());
            let id = sources.len() as u32;
            sources.insert(
                p.name.text.clone(),
                (
                    id,
                    Source::Parameter {
                        expr: p.value.expr().map(std::borrow::Cow::into_owned),
                        span: p.name.span,
                    },
                ),
            );
        }
        for b in &doc.basis {
            let id = sources.len() as u32;
            sources.entry(b.name.text.clone()).or_insert((
                id,
                Source::Basis {
                    axis: b.axis,
                    expr: b.value.expr().map(std::borrow::Cow::into_owned),
                    span: b.name.span,
                },
            ));
        }
        for (name, expr) in overrides {
            if let Some((_, Source::Parameter { expr: slot, .. })) = sources.get_mut(name) {
                *slot = Some(expr.clone());
            }
        }
        Values {
            sources,
            parameter_order,
            state: HashMap::new(),
            used: Used::default(),
            names,
            stack: Vec::new(),
        }
    }

    /// True for a parameter or basis coordinate.
    pub fn knows(&self, name: &str) -> bool {
        self.sources.contains_key(name)
    }

    pub fn is_parameter(&self, name: &str) -> bool {
        matches!(self.sources.get(name), Some((_, Source::Parameter { .. })))
    }

    pub fn parameter_names(&self) -> Vec<&str> {
        self.parameter_order.iter().map(String::as_str).collect()
    }

    /// The value of a numeric attribute, or `None` after reporting why not.
    /// Reads the values [`Values::evaluate_all`] fixed; the names it uses go
    /// into `used`.
    pub fn eval(
        &self,
        number: &Number,
        ctx: Ctx,
        used: &mut Used,
        diags: &mut Diagnostics,
    ) -> Option<f64> {
        let expr = number.expr()?;
        // Most numbers of large files are plain: no name to look up, and
        // the evaluator would return the value as it is when finite.
        if let expr::ExprKind::Number(value) = expr.kind
            && value.is_finite()
        {
            return Some(value);
        }
        self.eval_frozen(&expr, ctx, used, diags)
    }

    pub fn eval_opt(
        &self,
        number: &Option<Number>,
        ctx: Ctx,
        used: &mut Used,
        diags: &mut Diagnostics,
    ) -> Option<Option<f64>> {
        match number {
            None => Some(None),
            Some(n) => self.eval(n, ctx, used, diags).map(Some),
        }
    }

    fn eval_frozen(
        &self,
        expr: &Expr,
        ctx: Ctx,
        used: &mut Used,
        diags: &mut Diagnostics,
    ) -> Option<f64> {
        let mut failed = false;
        let result = expr::eval(expr, &mut |name, span| {
            let value = match self.admit(name, span, ctx, used, diags) {
                // Every value was fixed by `evaluate_all`.
                Admitted::Value => match self.state.get(name) {
                    Some(State::Done(v)) => *v,
                    _ => None,
                },
                Admitted::UsedOnly | Admitted::No => None,
            };
            if value.is_none() && name != "pi" {
                failed = true;
            }
            value.or(if name == "pi" { None } else { Some(0.0) })
        });
        self.finish_eval(result, failed, diags)
    }

    /// Evaluates a parameter's or basis coordinate's own expression, the
    /// names it uses evaluated on demand.
    fn eval_expr(&mut self, expr: &Expr, ctx: Ctx, diags: &mut Diagnostics) -> Option<f64> {
        let mut failed = false;
        let result = expr::eval(expr, &mut |name, span| {
            let mut used = std::mem::take(&mut self.used);
            let admitted = self.admit(name, span, ctx, &mut used, diags);
            self.used = used;
            let value = match admitted {
                Admitted::Value => self.value_of(name, diags),
                Admitted::UsedOnly | Admitted::No => None,
            };
            if value.is_none() && name != "pi" {
                failed = true;
            }
            value.or(if name == "pi" { None } else { Some(0.0) })
        });
        self.finish_eval(result, failed, diags)
    }

    fn finish_eval(
        &self,
        result: Result<f64, EvalError>,
        failed: bool,
        diags: &mut Diagnostics,
    ) -> Option<f64> {
        if failed {
            return None;
        }
        match result {
            Ok(v) => Some(v),
            Err(EvalError::Unknown { .. }) => None,
            Err(EvalError::NonFinite { span, what }) => {
                diags.push(
                    Diagnostic::new(
                        Code::NonFiniteValue,
                        span,
                        format!("this expression has no finite value: {what}"),
                    )
                    .with_help("check the values of the parameters it uses"),
                );
                None
            }
        }
    }

    /// Whether `name` may give a value where it is used (a wrong use is
    /// reported); a parameter or basis coordinate is marked used either way.
    fn admit(
        &self,
        name: &str,
        span: Span,
        ctx: Ctx,
        used: &mut Used,
        diags: &mut Diagnostics,
    ) -> Admitted {
        match self.sources.get(name) {
            Some((id, Source::Parameter { .. })) => {
                used.0.insert(*id);
                Admitted::Value
            }
            Some((id, Source::Basis { axis, .. })) => {
                used.0.insert(*id);
                let axis = *axis;
                match ctx {
                    Ctx::Coordinate(want) if want == axis => Admitted::Value,
                    Ctx::Coordinate(want) => {
                        diags.push(
                            Diagnostic::new(
                                Code::WrongAxis,
                                span,
                                format!(
                                    "basis coordinate '{name}' is a {} coordinate but is used for {}",
                                    axis.letter(),
                                    want.letter().to_lowercase()
                                ),
                            )
                            .with_help(format!(
                                "use a basis coordinate listed under <coordinate name=\"{}\">",
                                want.letter()
                            )),
                        );
                        Admitted::UsedOnly
                    }
                    Ctx::Any => {
                        diags.push(
                            Diagnostic::new(
                                Code::WrongKind,
                                span,
                                format!("basis coordinate '{name}' is used where no coordinate is expected"),
                            )
                            .with_help("basis coordinates give x, y or z coordinates; define a <parameter> for other values"),
                        );
                        Admitted::UsedOnly
                    }
                }
            }
            None if name == "pi" => Admitted::No,
            None => {
                if let Some(kind) = self
                    .names
                    .kind_of(name)
                    .filter(|&k| k != "parameter" && k != "basis coordinate")
                {
                    diags.push(
                        Diagnostic::new(
                            Code::WrongKind,
                            span,
                            format!("'{name}' is a {kind}, not a number"),
                        )
                        .with_help("expressions may use parameters, basis coordinates and pi"),
                    );
                } else {
                    let candidates: Vec<&str> = self.sources.keys().map(String::as_str).collect();
                    let mut d = Diagnostic::new(
                        Code::UndefinedName,
                        span,
                        format!("undefined name '{name}'"),
                    );
                    d.help = Some(match did_you_mean(name, candidates) {
                        Some(best) => format!("did you mean '{best}'?"),
                        None => format!(
                            "define it: <parameters><parameter name=\"{name}\" value=\"…\"/></parameters>"
                        ),
                    });
                    diags.push(d);
                }
                Admitted::No
            }
        }
    }

    /// The value of a parameter or basis coordinate, evaluated once.
    fn value_of(&mut self, name: &str, diags: &mut Diagnostics) -> Option<f64> {
        match self.state.get(name) {
            Some(State::Done(v)) => return *v,
            Some(State::InProgress) => {
                let start = self.stack.iter().position(|n| n == name).unwrap_or(0);
                let mut cycle: Vec<&str> = self.stack[start..].iter().map(String::as_str).collect();
                cycle.push(name);
                let span = self
                    .sources
                    .get(name)
                    .map(|(_, Source::Parameter { span, .. } | Source::Basis { span, .. })| *span);
                diags.push(
                    Diagnostic::new(
                        Code::ReferenceCycle,
                        span,
                        format!("'{name}' is defined through itself: {}", cycle.join(" → ")),
                    )
                    .with_help("give one of these a value that does not depend on the others"),
                );
                // Mark every member of the cycle failed so it is reported once.
                for n in &self.stack[start..] {
                    self.state.insert(n.clone(), State::Done(None));
                }
                return None;
            }
            None => {}
        }
        let (expr, ctx) = match self.sources.get(name) {
            Some((_, Source::Parameter { expr, .. })) => (expr.clone(), Ctx::Any),
            Some((_, Source::Basis { axis, expr, .. })) => (expr.clone(), Ctx::Coordinate(*axis)),
            None => return None,
        };
        self.state.insert(name.to_string(), State::InProgress);
        self.stack.push(name.to_string());
        let value = expr.and_then(|e| self.eval_expr(&e, ctx, diags));
        self.stack.pop();
        if let Some(State::Done(v)) = self.state.get(name) {
            // A cycle through this name was found and reported while evaluating it.
            return *v;
        }
        self.state.insert(name.to_string(), State::Done(value));
        value
    }

    /// Evaluates every parameter and basis coordinate (so that unused ones are
    /// checked too) and returns the parameters in force, in definition order.
    pub fn evaluate_all(&mut self, diags: &mut Diagnostics) -> Vec<(String, f64)> {
        let mut names: Vec<String> = self.sources.keys().cloned().collect();
        names.sort();
        for name in &names {
            self.value_of(name, diags);
        }
        self.parameter_order
            .clone()
            .into_iter()
            .filter_map(|n| match self.state.get(&n) {
                Some(State::Done(Some(v))) => Some((n, *v)),
                _ => None,
            })
            .collect()
    }

    /// Basis coordinate values per axis, keyed by name.
    pub fn basis_values(&self, axis: Axis) -> BTreeMap<String, f64> {
        self.sources
            .iter()
            .filter_map(|(n, s)| match (s, self.state.get(n)) {
                ((_, Source::Basis { axis: a, .. }), Some(State::Done(Some(v)))) if *a == axis => {
                    Some((n.clone(), *v))
                }
                _ => None,
            })
            .collect()
    }

    /// Parameters that no expression used: not the parameters' own nor any
    /// of `used` (their spans).
    pub fn unused_parameters(&self, used: &Used) -> Vec<(String, Span)> {
        let mut out: Vec<(String, Span)> = self
            .sources
            .iter()
            .filter_map(|(n, (id, s))| match s {
                Source::Parameter { span, .. }
                    if !self.used.0.contains(id) && !used.0.contains(id) =>
                {
                    Some((n.clone(), *span))
                }
                _ => None,
            })
            .collect();
        out.sort_by_key(|(_, s)| *s);
        out
    }
}
