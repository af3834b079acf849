//! Resolution: parameters and expressions evaluated, names looked up,
//! coordinate systems and transforms applied — every object of the document
//! in global coordinates, ready to be lowered into the model IR.

mod geometry;
mod name_index;
mod names;
#[cfg(test)]
mod names_tests;
mod objects;
#[cfg(test)]
mod parallel_tests;
mod point_calculus;
mod polygons;
mod shapes;
mod trimmed;
mod values;

pub use geometry::{Geometry, LineCarrier, Link};
pub use name_index::NameIndex;
pub use names::{NameTable, is_plain_name};
pub use objects::a;
pub use shapes::{fmt, fmt_point, perpendicular_pair};
pub use values::{Ctx, Values};

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::doc::Document;
use crate::expr::Expr;
use crate::span::{SourceFile, Span};

/// One object of the document after resolution.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedObject {
    pub name: String,
    /// The element's name in its start tag.
    pub span: Span,
    /// `None` when the object could not be resolved (already reported).
    pub geometry: Option<Geometry>,
}

#[derive(Debug, Clone)]
pub struct Resolved {
    pub dimension: u8,
    /// In document order: `objects[i]` resolves `doc.objects[i]`.
    pub objects: Vec<ResolvedObject>,
    /// Objects by name (the last of a repeated name).
    pub by_name: NameIndex,
    /// Parameter values in force, in definition order.
    pub parameters: Vec<(String, f64)>,
    /// `subdomain_areas[i]`: the `area=` limit of `doc.subdomains[i]`, when
    /// given, positive and in a 2D model.
    pub subdomain_areas: Vec<Option<f64>>,
}

impl Resolved {
    pub fn object(&self, name: &str) -> Option<&ResolvedObject> {
        self.by_name
            .get(&self.objects, name)
            .and_then(|i| self.objects.get(i))
    }
}

/// A `--set NAME=VALUE` override, parsed.
#[derive(Debug, Clone)]
pub struct Override {
    pub name: String,
    pub value: Expr,
}

/// Parses `NAME=VALUE` from the command line.
pub fn parse_override(text: &str) -> Result<Override, Diagnostic> {
    let Some((name, value)) = text.split_once('=') else {
        return Err(Diagnostic::new(
            Code::BadOverride,
            None,
            format!("--set {text}: expected NAME=VALUE"),
        )
        .with_help("write for example --set r=0.8"));
    };
    let name = name.trim();
    if !is_plain_name(name) {
        return Err(Diagnostic::new(
            Code::BadOverride,
            None,
            format!("--set {text}: '{name}' is not a parameter name"),
        )
        .with_help("write for example --set r=0.8"));
    }
    match crate::expr::parse(value, 0) {
        Ok(expr) => Ok(Override {
            name: name.to_string(),
            value: expr,
        }),
        Err(_) => Err(Diagnostic::new(
            Code::BadOverride,
            None,
            format!("--set {text}: '{value}' is not a number or an expression"),
        )
        .with_help("write for example --set r=0.8 or --set r=2*h")),
    }
}

/// Resolves a typed document. Overrides naming no parameter are reported with E204.
///
/// Takes the document's objects (`doc.objects` is left empty): nothing
/// after resolution reads them, and their names move into the resolved
/// objects instead of being copied (a hundred thousand strings on large
/// files).
pub fn resolve(
    source: &SourceFile,
    doc: &mut Document,
    overrides: &[Override],
    diags: &mut Diagnostics,
) -> Resolved {
    let resolved = resolve_in(source, doc, overrides, diags, Pass::Parallel).0;
    let objects = std::mem::take(&mut doc.objects);
    named(resolved, objects.into_iter().map(|object| object.name.text))
}

/// Gives the resolved objects their names (in document order) and indexes
/// them by name.
fn named(mut resolved: Resolved, names: impl Iterator<Item = String>) -> Resolved {
    for (object, name) in resolved.objects.iter_mut().zip(names) {
        object.name = name;
    }
    resolved
}

/// How the objects are resolved: the serial pass alone is what the parallel
/// one is tested against.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Pass {
    Parallel,
    #[cfg(test)]
    Serial,
}

/// [`resolve`] without the objects' names (left empty), and how many
/// objects were resolved alone on the workers.
fn resolve_in(
    source: &SourceFile,
    doc: &Document,
    overrides: &[Override],
    diags: &mut Diagnostics,
    pass: Pass,
) -> (Resolved, usize) {
    // The index by name needs only the names: a worker builds it from the
    // document's while this thread resolves (it serves the resolved objects,
    // which take the same names).
    let mut by_name = NameIndex::default();
    let (resolved, alone) = rayon::in_place_scope(|scope| {
        scope.spawn(|_| {
            let names = |i: usize| doc.objects.get(i).map(|o| o.name.text.as_str());
            by_name = NameIndex::build_with(doc.objects.len(), names);
        });
        resolve_objects(source, doc, overrides, diags, pass)
    });
    (
        Resolved {
            by_name,
            ..resolved
        },
        alone,
    )
}

fn resolve_objects(
    source: &SourceFile,
    doc: &Document,
    overrides: &[Override],
    diags: &mut Diagnostics,
    pass: Pass,
) -> (Resolved, usize) {
    let names = NameTable::build(source, doc, diags);
    let tables = objects::Tables::build(doc);
    let pairs: Vec<(String, Expr)> = overrides
        .iter()
        .map(|o| (o.name.clone(), o.value.clone()))
        .collect();
    let mut values = Values::new(doc, &pairs, &names);
    for o in overrides {
        if !values.is_parameter(&o.name) {
            let candidates = values.parameter_names();
            let mut d = Diagnostic::new(
                Code::UnknownParameterOverride,
                None,
                format!(
                    "--set {}: the file defines no parameter '{}'",
                    o.name, o.name
                ),
            );
            d.help = Some(
                match crate::diag::did_you_mean(&o.name, candidates.iter().copied()) {
                    Some(best) => format!("did you mean --set {best}=…?"),
                    None if candidates.is_empty() => "the file defines no parameters".to_string(),
                    None => format!("parameters: {}", candidates.join(", ")),
                },
            );
            diags.push(d);
        }
    }
    let parameters = values.evaluate_all(diags);
    check_basis_order(doc, &values, diags);
    // From here on the values are fixed: the resolvers share them.
    let mut resolver = objects::Resolver::new(doc, &names, &tables, &values);
    let (objects, alone) = match pass {
        Pass::Parallel => resolver.resolve_all(),
        #[cfg(test)]
        Pass::Serial => (resolver.resolve_serially(), 0),
    };
    let subdomain_areas = doc
        .subdomains
        .iter()
        .map(|def| shapes::subdomain_area(&mut resolver, def, doc.dimension))
        .collect();
    let (used, found) = resolver.finish();
    diags.extend(found);
    for (name, span) in values.unused_parameters(&used) {
        diags.push(
            Diagnostic::new(
                Code::UnusedParameter,
                span,
                format!("parameter '{name}' is never used"),
            )
            .with_help("remove it, or use it in an attribute"),
        );
    }
    let resolved = Resolved {
        dimension: doc.dimension,
        objects,
        by_name: NameIndex::default(),
        parameters,
        subdomain_areas,
    };
    (resolved, alone)
}

/// Paper 000 supposes basis coordinates ascend with their index (x1 < x2 < …).
fn check_basis_order(doc: &Document, values: &Values, diags: &mut Diagnostics) {
    use crate::doc::Axis;
    for axis in [Axis::X, Axis::Y, Axis::Z] {
        let known = values.basis_values(axis);
        let mut indexed: Vec<(u64, &str, f64, Span)> = doc
            .basis
            .iter()
            .filter(|b| b.axis == axis)
            .filter_map(|b| {
                let digits: String = b
                    .name
                    .text
                    .chars()
                    .rev()
                    .take_while(char::is_ascii_digit)
                    .collect();
                let index: u64 = digits.chars().rev().collect::<String>().parse().ok()?;
                Some((
                    index,
                    b.name.text.as_str(),
                    *known.get(&b.name.text)?,
                    b.name.span,
                ))
            })
            .collect();
        indexed.sort_by_key(|&(i, _, _, _)| i);
        for pair in indexed.windows(2) {
            let (_, prev_name, prev, _) = pair[0];
            let (_, name, value, span) = pair[1];
            if value <= prev {
                diags.push(
                    Diagnostic::new(
                        Code::NotAscending,
                        span,
                        format!(
                            "basis coordinate {name} = {value} is not greater than {prev_name} = {prev}; the values are used as given"
                        ),
                    )
                    .with_help(format!("{} coordinates are expected to ascend with their index", axis.letter())),
                );
            }
        }
    }
}
