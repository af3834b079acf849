//! Implicit solids in the domain XML (issue 5): `<rfunction>` trees of
//! R-operations over paper 001's primitives and formulas, `<function>`s with
//! named arguments, `<level_surface>` f(u, v, w) = c and `<density_volume>`
//! samples. The driver takes these elements (and the subdomains that use
//! them) out of the tree before the boundary-representation pipeline, and
//! lowers them here into [`ImplicitSubdomain`]s that compile polygonizes.

pub mod density;
pub mod joint;
pub mod mesh;
mod overlap;
mod paths;
pub mod report;
mod settings;
mod tree;

use crate::diag::{Code, Diagnostic, Diagnostics, did_you_mean};
use crate::implicit::ImplicitModel;
use crate::implicit::ir::{Ctx, Node, NodeId};
use crate::implicit::polygonize::{self, Grid, Options, Surface};
use crate::span::{SourceFile, Span};
use crate::syntax::Element;
use std::collections::{BTreeSet, HashMap, HashSet};
use std::path::PathBuf;

/// The elements this module owns.
pub const ELEMENTS: [&str; 4] = ["rfunction", "function", "level_surface", "density_volume"];
/// The elements that define a named solid.
const SOLIDS: [&str; 3] = ["rfunction", "level_surface", "density_volume"];

/// What the driver took out of the element tree.
#[derive(Debug, Default)]
pub struct Extracted<'s> {
    pub defs: Vec<Element<'s>>,
    pub subdomains: Vec<Element<'s>>,
    /// Copies of the `<trim>` elements holding an R-function tree, with the
    /// name of their surface (issue 9); the originals stay in the tree.
    pub trims: Vec<(String, Element<'s>)>,
    /// 2D models: implicit solids a kernel subdomain's `<difference>`
    /// subtracts (issue 6), taken out of its tree; the R-function region
    /// lowering makes their contours holes of that subdomain's face.
    pub carves: Vec<Carve>,
}

/// An implicit solid subtracted from a kernel subdomain of a 2D model.
#[derive(Debug, Clone)]
pub struct Carve {
    pub subdomain: String,
    pub solid: String,
    /// The `ref` value naming the solid.
    pub span: Span,
}

impl Extracted<'_> {
    pub fn is_empty(&self) -> bool {
        self.defs.is_empty() && self.subdomains.is_empty() && self.trims.is_empty()
    }
}

/// The elements of trimmed surfaces (paper 002), which may hold a `<trim>`.
const TRIMMED: [&str; 6] = [
    "patch9",
    "bezier_surface",
    "cone_surface",
    "parametric_surface",
    "sphere_surface",
    "torus_surface",
];

/// Decides, one top-level element at a time, which elements the implicit path
/// takes: the implicit definitions, and every subdomain whose solid tree names
/// one of them (so the driver can build a large file's elements one by one).
pub struct Extractor {
    /// The names of the implicit solids.
    names: HashSet<String>,
    /// Whether the file has any implicit element at all.
    any: bool,
    /// Whether the model is 2D (`dimension="2"`).
    planar: bool,
}

impl Extractor {
    /// Reads the root's `dimension` and the heads of its children (names and
    /// `name=` values).
    pub fn new(root: &Element, children: &[crate::syntax::Head]) -> Extractor {
        Extractor {
            names: children
                .iter()
                .filter(|c| SOLIDS.contains(&c.name))
                .filter_map(|c| c.name_attribute)
                .map(|a| a.trim().to_string())
                .collect(),
            any: children.iter().any(|c| ELEMENTS.contains(&c.name)),
            planar: root
                .attribute("dimension")
                .is_some_and(|a| a.value.trim() == "2"),
        }
    }

    /// Whether [`Extractor::take`] hands `child` back untouched and takes
    /// nothing of it, so its part of the document can be built apart (on
    /// another thread) without the extraction.
    pub fn leaves(&self, child: &Element) -> bool {
        !self.any && !TRIMMED.contains(&child.name)
    }

    /// Moves `child` into `out` when the implicit path owns it, else hands it
    /// back; copies of a trimmed surface's `<trim>` trees go to `out.trims`.
    pub fn take<'s>(&self, child: Element<'s>, out: &mut Extracted<'s>) -> Option<Element<'s>> {
        if TRIMMED.contains(&child.name) {
            let name = child
                .attribute("name")
                .map_or(String::new(), |a| a.value.trim().to_string());
            for t in child.children_named("trim") {
                if !t.children.is_empty() {
                    out.trims.push((name.clone(), t.clone()));
                }
            }
        }
        if !self.any {
            Some(child)
        } else if ELEMENTS.contains(&child.name) {
            out.defs.push(child);
            None
        } else if child.name == "subdomain" && names_any(&child, &self.names) {
            self.carve(child, out)
        } else {
            Some(child)
        }
    }
}

impl Extractor {
    /// In a 2D model, a kernel subdomain `<difference>` whose first operand
    /// is a kernel tree and whose other operands are kernel trees or
    /// `<solid ref>`s of implicit solids stays on the kernel path without the
    /// implicit operands (recorded in `out.carves`); any other subdomain
    /// naming an implicit solid goes to the implicit path.
    fn carve<'s>(&self, mut child: Element<'s>, out: &mut Extracted<'s>) -> Option<Element<'s>> {
        let implicit_ref = |e: &Element| {
            e.name == "solid"
                && e.attribute("ref")
                    .is_some_and(|r| self.names.contains(r.value.trim()))
        };
        let carvable = self.planar
            && child.children.len() == 1
            && child.children[0].name == "difference"
            && child.children[0]
                .children
                .first()
                .is_some_and(|first| !names_any(first, &self.names))
            && child.children[0].children[1..]
                .iter()
                .all(|e| implicit_ref(e) || !names_any(e, &self.names));
        let name = child.attribute("name").map(|a| a.value.trim().to_string());
        let (true, Some(name)) = (carvable, name) else {
            out.subdomains.push(child);
            return None;
        };
        let difference = &mut child.children[0];
        let operands = std::mem::take(&mut difference.children);
        for e in operands {
            match e.attribute("ref").filter(|_| implicit_ref(&e)) {
                Some(r) => out.carves.push(Carve {
                    subdomain: name.clone(),
                    solid: r.value.trim().to_string(),
                    span: r.value_span,
                }),
                None => difference.children.push(e),
            }
        }
        if difference.children.len() == 1 {
            // A difference of one operand is that operand.
            let first = difference.children.remove(0);
            child.children[0] = first;
        }
        Some(child)
    }
}

/// Whether a `<solid ref>` below `e` names one of `names`.
fn names_any(e: &Element, names: &HashSet<String>) -> bool {
    let mut stack = vec![e];
    while let Some(e) = stack.pop() {
        if e.name == "solid"
            && e.attribute("ref")
                .is_some_and(|r| names.contains(r.value.trim()))
        {
            return true;
        }
        stack.extend(e.children.iter());
    }
    false
}

/// What lowering needs from the rest of the front end.
pub struct Env<'a> {
    pub source: &'a SourceFile,
    /// Parameter values in force (after `--set`).
    pub parameters: &'a [(String, f64)],
    /// The folder data files are read from (the XML file's folder).
    pub folder: PathBuf,
    /// Further folders `--allow-path` opened.
    pub allowed: &'a [PathBuf],
    /// Names the rest of the file defines (for duplicate checks).
    pub taken: &'a dyn Fn(&str) -> bool,
}

/// An implicit solid ready to polygonize.
#[derive(Debug, Clone)]
pub enum ImplicitSolid {
    /// f > 0 inside, on the model's Geom grid.
    Function(ImplicitModel),
    /// Samples minus the level (x fastest), one per grid point.
    Samples { grid: Grid, values: Vec<f64> },
}

/// A subdomain whose solid is implicit.
#[derive(Debug, Clone)]
pub struct ImplicitSubdomain {
    pub name: String,
    pub material: Option<String>,
    pub span: Span,
    pub solid: ImplicitSolid,
    /// 2D regions: the largest triangle area (`area=`).
    pub max_area: Option<f64>,
    /// Where `area=` is written (for W150 in a 3D model).
    pub area_span: Option<Span>,
}

impl ImplicitSubdomain {
    /// The box the solid is polygonized in (where it is capped).
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        match &self.solid {
            ImplicitSolid::Function(model) => (model.geom.min, model.geom.max),
            ImplicitSolid::Samples { grid, .. } => (grid.min, grid.max),
        }
    }

    /// The boundary surface: on the solid's own grid, or `cells` per axis for functions.
    pub fn polygonize(&self, cells: Option<usize>) -> Surface {
        match &self.solid {
            ImplicitSolid::Function(model) => model.polygonize(cells.map(|n| [n; 3])),
            ImplicitSolid::Samples { grid, values } => {
                polygonize::polygonize_samples(values.clone(), grid, &Options::default())
            }
        }
    }
}

/// The result of lowering: the subdomains and the parameters the implicit
/// elements use (so they are not reported unused).
#[derive(Debug, Default)]
pub struct Lowered {
    pub subdomains: Vec<ImplicitSubdomain>,
    pub used_parameters: BTreeSet<String>,
    /// The R-function trees of `<trim>`s, by surface name.
    pub trims: Vec<LoweredTrim>,
}

/// A trim's tree F(x, y, z) and its material side.
#[derive(Debug)]
pub struct LoweredTrim {
    pub surface: String,
    pub ctx: Ctx,
    pub root: NodeId,
    pub negative: bool,
}

/// A named solid while lowering.
enum Def {
    Function(ImplicitModel),
    Samples(Grid, Vec<f64>),
    /// Defined, but with errors (already reported).
    Failed,
}

/// Lowers the extracted elements.
pub fn lower(ex: &Extracted, env: &Env, diags: &mut Diagnostics) -> Lowered {
    let mut out = Lowered::default();
    let functions = tree::collect_functions(&ex.defs, diags);
    let mut defs: HashMap<String, Def> = HashMap::new();
    for e in ex.defs.iter().filter(|e| SOLIDS.contains(&e.name)) {
        let Some(name_attr) = e.attribute("name") else {
            continue;
        };
        let name = name_attr.value.trim().to_string();
        if defs.contains_key(&name) || (env.taken)(&name) {
            diags.push(Diagnostic::new(
                Code::DuplicateName,
                name_attr.value_span,
                format!("the name '{name}' is defined twice"),
            ));
            continue;
        }
        let def = match e.name {
            "rfunction" => tree::rfunction(e, env, &functions, &mut out.used_parameters, diags),
            "level_surface" => tree::level_surface(e, env, &mut out.used_parameters, diags),
            _ => density::read(e, env, &mut out.used_parameters, diags)
                .map(|(grid, values)| Def::Samples(grid, values)),
        };
        defs.insert(name, def.unwrap_or(Def::Failed));
    }
    for (surface, e) in &ex.trims {
        if let Some((ctx, root)) =
            tree::trim_tree(e, env, &functions, &mut out.used_parameters, diags)
        {
            out.trims.push(LoweredTrim {
                surface: surface.clone(),
                ctx,
                root,
                negative: e
                    .attribute("material")
                    .is_some_and(|a| a.value.trim() == "negative"),
            });
        }
    }
    for s in &ex.subdomains {
        let Some(name) = s.attribute("name") else {
            continue;
        };
        let Some(root) = s.children.first() else {
            continue;
        };
        let solid = match subdomain_solid(root, &defs, diags) {
            Some(solid) => solid,
            None => continue,
        };
        let max_area = area_limit(s, env, &mut out.used_parameters, diags);
        out.subdomains.push(ImplicitSubdomain {
            name: name.value.trim().to_string(),
            material: s.attribute("material").map(|a| a.value.to_string()),
            span: s.name_span,
            solid,
            max_area,
            area_span: s.attribute("area").map(|a| a.value_span),
        });
    }
    overlap::check(&out.subdomains, diags);
    out
}

/// W150 for each subdomain that gives `area=` in a 3D model, where only 2D
/// regions read it (as for kernel subdomains).
pub fn warn_area_in_3d(subdomains: &[ImplicitSubdomain], diags: &mut Diagnostics) {
    for sub in subdomains {
        let Some(area) = sub.max_area else {
            continue;
        };
        diags.push(
            Diagnostic::new(
                Code::AreaIn3d,
                sub.area_span.unwrap_or(sub.span),
                format!(
                    "subdomain '{}' gives area={} in a 3D model, where it is ignored",
                    sub.name,
                    crate::resolve::fmt(area)
                ),
            )
            .with_help("remove area=, or set dimension=\"2\" on <geometry> for a planar model"),
        );
    }
}

/// A subdomain's `area=` (read by 2D regions): `None` when absent or bad
/// (reported, as for kernel subdomains).
fn area_limit(
    s: &Element,
    env: &Env,
    used: &mut BTreeSet<String>,
    diags: &mut Diagnostics,
) -> Option<f64> {
    let area = settings::constant(s, "area", env, used, diags)??;
    if area > 0.0 {
        return Some(area);
    }
    let name = s.attribute("name").map_or("", |a| a.value.trim());
    let span = s.attribute("area").map_or(s.name_span, |a| a.value_span);
    diags.push(
        Diagnostic::new(
            Code::NonPositiveSize,
            span,
            format!("the area limit of '{name}' is {area}; it must be positive"),
        )
        .with_help("give the area limit a value greater than zero"),
    );
    None
}

/// The solid of one subdomain tree: a density volume alone, or R-operations
/// over functions.
fn subdomain_solid(
    root: &Element,
    defs: &HashMap<String, Def>,
    diags: &mut Diagnostics,
) -> Option<ImplicitSolid> {
    if let Some(r) = root.attribute("ref").filter(|_| root.name == "solid")
        && let Some(Def::Samples(grid, values)) = defs.get(r.value.trim())
    {
        return Some(ImplicitSolid::Samples {
            grid: *grid,
            values: values.clone(),
        });
    }
    let mut ctx = Ctx::new();
    let (root, geom) = combine(root, defs, &mut ctx, diags)?;
    Some(ImplicitSolid::Function(ImplicitModel { geom, ctx, root }))
}

/// A subdomain's boolean tree as R-operations (in the first leaf's system);
/// the grid covers the result (the union of boxes for a union, the first
/// operand's box for a difference) with the finest cells of the operands.
fn combine(
    e: &Element,
    defs: &HashMap<String, Def>,
    ctx: &mut Ctx,
    diags: &mut Diagnostics,
) -> Option<(NodeId, crate::implicit::Geom)> {
    if e.name == "solid" {
        let r = e.attribute("ref")?;
        let name = r.value.trim();
        return match defs.get(name) {
            Some(Def::Function(m)) => Some((import(ctx, &m.ctx, m.root), m.geom.clone())),
            Some(Def::Failed) => None,
            Some(Def::Samples(..)) => {
                diags.push(Diagnostic::new(
                    Code::ImplicitMixedTree,
                    r.value_span,
                    format!("the density volume '{name}' is used inside a boolean; it can only be a subdomain's whole solid"),
                ));
                None
            }
            None => {
                let mut d = Diagnostic::new(
                    Code::ImplicitMixedTree,
                    r.value_span,
                    format!(
                        "'{name}' is not an implicit solid, and this subdomain combines it with implicit ones"
                    ),
                );
                if let Some(s) = did_you_mean(name, defs.keys().map(String::as_str)) {
                    d = d.with_help(format!(
                        "did you mean '{s}'? otherwise write the primitive inside the <rfunction>"
                    ));
                }
                diags.push(d);
                None
            }
        };
    }
    let parts: Vec<Option<(NodeId, crate::implicit::Geom)>> = e
        .children
        .iter()
        .map(|c| combine(c, defs, ctx, diags))
        .collect();
    let parts: Vec<(NodeId, crate::implicit::Geom)> = parts.into_iter().collect::<Option<_>>()?;
    let (first, rest) = parts.split_first()?;
    let sys = first.1.rsystem;
    let mut geom = first.1.clone();
    let mut f = first.0;
    for (g, other) in rest {
        f = match e.name {
            "union" => sys.or(ctx, f, *g),
            "intersection" => sys.and(ctx, f, *g),
            _ => sys.difference(ctx, f, *g),
        };
        for axis in 0..3 {
            if e.name == "union" {
                geom.min[axis] = geom.min[axis].min(other.min[axis]);
                geom.max[axis] = geom.max[axis].max(other.max[axis]);
            }
            geom.cells[axis] = geom.cells[axis].max(other.cells[axis]);
        }
    }
    Some((f, geom))
}

/// Copies the expression `root` of `src` into `dst` (hash-consed again, so
/// shared parts stay shared).
pub fn import(dst: &mut Ctx, src: &Ctx, root: NodeId) -> NodeId {
    let mut map: Vec<NodeId> = Vec::with_capacity(root as usize + 1);
    for node in src.nodes.iter().take(root as usize + 1) {
        let m = |i: NodeId| map[i as usize];
        let id = match *node {
            Node::Const(bits) => dst.constant(f64::from_bits(bits)),
            Node::Var(axis) => dst.var(axis),
            Node::Unary(op, a) => {
                let a = m(a);
                dst.unary(op, a)
            }
            Node::Binary(op, a, b) => {
                let (a, b) = (m(a), m(b));
                dst.binary(op, a, b)
            }
            Node::RAnd(a, b, alpha) => {
                let (a, b) = (m(a), m(b));
                dst.r_and(a, b, f64::from_bits(alpha))
            }
            Node::ROr(a, b, alpha) => {
                let (a, b) = (m(a), m(b));
                dst.r_or(a, b, f64::from_bits(alpha))
            }
        };
        map.push(id);
    }
    map[root as usize]
}
