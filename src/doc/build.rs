//! Element tree → typed [`Document`]. Parses every numeric attribute as an
//! expression and every reference; reports malformed ones and keeps going.
//! Structure (missing or unknown elements) is the structural check's job: here
//! anything missing simply stays `None`.

use super::grammar::same_name;
use super::model::*;
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::expr::{self, ExprLimits, ParseError};
use crate::span::{SourceFile, Span};
use crate::syntax::{Attribute, Element};

/// Builds the typed document from a structurally checked tree.
pub fn build(source: &SourceFile, root: &Element, diags: &mut Diagnostics) -> Document {
    build_with(source, root, diags, &ExprLimits::default())
}

/// [`build`] with the expression size bounds given (`--max-expression-*`).
pub fn build_with(
    source: &SourceFile,
    root: &Element,
    diags: &mut Diagnostics,
    limits: &ExprLimits,
) -> Document {
    let mut builder = DocumentBuilder::new(source, root, limits);
    for element in &root.children {
        builder.add(element, diags);
    }
    builder.finish()
}

/// Builds the typed document one top-level element at a time, so a caller can
/// drop each element as soon as its part of the document is made.
pub struct DocumentBuilder<'a> {
    source: &'a SourceFile,
    limits: ExprLimits,
    doc: Document,
}

impl<'a> DocumentBuilder<'a> {
    /// Starts a document from the root's attributes; its children (shells are
    /// enough) only size the object and subdomain lists.
    pub fn new(source: &'a SourceFile, root: &Element, limits: &ExprLimits) -> Self {
        let mut doc = Document {
            dimension: match root.attribute("dimension").map(|a| a.value.trim()) {
                Some("2") => 2,
                _ => 3,
            },
            title: root.attribute("name").map(|a| a.value.to_string()),
            ..Document::default()
        };
        // One object or subdomain per top-level element in large files: sized once
        // instead of grown by doubling (each growth copies and touches fresh pages).
        let subdomains = root.children_named("subdomain").count();
        doc.subdomains.reserve(subdomains);
        doc.objects.reserve(root.children.len() - subdomains);
        DocumentBuilder {
            source,
            limits: *limits,
            doc,
        }
    }

    /// Sizes the object and subdomain lists for the top-level elements to come
    /// (when the root given to [`DocumentBuilder::new`] came without children).
    pub fn reserve(&mut self, objects: usize, subdomains: usize) {
        self.doc.objects.reserve(objects);
        self.doc.subdomains.reserve(subdomains);
    }

    /// Adds what one top-level element defines.
    pub fn add(&mut self, element: &Element, diags: &mut Diagnostics) {
        self.part_builder().add(element, &mut self.doc, diags);
    }

    /// What builds [`Parts`] apart from this document (on another thread)
    /// exactly as [`DocumentBuilder::add`] builds them into it.
    pub fn part_builder(&self) -> PartBuilder<'a> {
        PartBuilder {
            source: self.source,
            limits: self.limits,
        }
    }

    /// Moves what `parts` holds to the end of the document's lists, as if its
    /// elements had been added here one by one; `parts` is left empty (with
    /// its lists' room). The strings, boxes and vectors inside stay where the
    /// building thread allocated them: copying them into this thread's heap
    /// (session 18) cost the main thread a fifth of its time and the whole
    /// process more CPU, for no lower peak once the rayon threads' heaps are
    /// collected at the driver's release points (measured in session 19).
    pub fn append(&mut self, parts: &mut Parts) {
        // Destructured whole, so a new list of the document cannot be missed.
        let Document {
            dimension: _,
            title: _,
            parameters,
            basis,
            coordinate_systems,
            objects,
            subdomains,
            boundaries,
        } = &mut parts.0;
        let doc = &mut self.doc;
        doc.parameters.append(parameters);
        doc.basis.append(basis);
        doc.coordinate_systems.append(coordinate_systems);
        doc.objects.append(objects);
        doc.subdomains.append(subdomains);
        doc.boundaries.append(boundaries);
    }

    pub fn finish(self) -> Document {
        self.doc
    }
}

/// The parts of a typed document that some top-level elements define, in
/// their order: built on a rayon thread by [`PartBuilder::add`], added to the
/// document by [`DocumentBuilder::append`].
#[derive(Debug, Default)]
pub struct Parts(Document);

impl Parts {
    /// Empty parts with room for what `elements` define at most (their
    /// parameters and basis coordinates aside): lists grown by doubling
    /// would leave their earlier blocks free on the building thread.
    pub fn for_elements(elements: &[Element]) -> Parts {
        let count = |name: &str| elements.iter().filter(|e| e.name == name).count();
        let [parameters, basis, systems, subdomains, boundaries] = [
            "parameters",
            "basis_coordinate",
            "coordinate_system",
            "subdomain",
            "boundary",
        ]
        .map(count);
        let objects = elements.len() - parameters - basis - systems - subdomains - boundaries;
        Parts(Document {
            coordinate_systems: Vec::with_capacity(systems),
            objects: Vec::with_capacity(objects),
            subdomains: Vec::with_capacity(subdomains),
            boundaries: Vec::with_capacity(boundaries),
            ..Document::default()
        })
    }
}

/// Builds [`Parts`]: [`DocumentBuilder::add`] without the document.
#[derive(Debug, Clone, Copy)]
pub struct PartBuilder<'a> {
    source: &'a SourceFile,
    limits: ExprLimits,
}

impl PartBuilder<'_> {
    /// Adds what one top-level element defines to `parts`.
    pub fn add_part(&self, element: &Element, parts: &mut Parts, diags: &mut Diagnostics) {
        self.add(element, &mut parts.0, diags);
    }

    fn add(&self, element: &Element, doc: &mut Document, diags: &mut Diagnostics) {
        Builder {
            source: self.source,
            diags,
            limits: self.limits,
        }
        .top_level(element, doc);
    }
}

/// Parses one attribute's expression with spans in the source, reporting
/// malformed ones (E120–E124) as every numeric attribute does.
pub fn parse_attribute_expr(
    source: &SourceFile,
    attr: &Attribute,
    diags: &mut Diagnostics,
) -> Option<crate::expr::Expr> {
    Builder {
        source,
        diags,
        limits: ExprLimits::default(),
    }
    .parse_number(attr)
    .expr()
    .map(std::borrow::Cow::into_owned)
}

struct Builder<'a> {
    source: &'a SourceFile,
    diags: &'a mut Diagnostics,
    limits: ExprLimits,
}

impl Builder<'_> {
    fn top_level(&mut self, e: &Element, doc: &mut Document) {
        match e.name {
            "parameters" => {
                for p in e.children_named("parameter") {
                    if let (Some(name), Some(value)) = (self.name(p), self.number(p, "value")) {
                        doc.parameters.push(Parameter { name, value });
                    }
                }
            }
            "basis_coordinate" => {
                for c in e.children_named("coordinate") {
                    let axis = match c.attribute("name").map(|a| a.value.trim()) {
                        Some("X") => Axis::X,
                        Some("Y") => Axis::Y,
                        Some("Z") => Axis::Z,
                        _ => continue,
                    };
                    for v in c.children_named("value") {
                        for attr in &v.attributes {
                            let value = self.parse_number(attr);
                            doc.basis.push(BasisCoordinate {
                                axis,
                                name: Name {
                                    text: attr.name.to_string(),
                                    span: attr.name_span,
                                },
                                value,
                            });
                        }
                    }
                }
            }
            "coordinate_system" => {
                if let Some(name) = self.name(e) {
                    doc.coordinate_systems.push(CoordinateSystem {
                        name,
                        parent: self.reference(e, "cs"),
                        origin: self.point_child(e, "origin"),
                        rotation: self.vector_child(e, "rotation"),
                    });
                }
            }
            "subdomain" => {
                if let Some(name) = self.name(e) {
                    doc.subdomains.push(SubdomainDef {
                        name,
                        material: e.attribute("material").map(|a| a.value.to_string()),
                        faces: self.ref_list(e, "faces").map(Box::new),
                        tree: e.children.first().and_then(|c| self.solid_tree(c)),
                        area: self.number(e, "area").map(Box::new),
                        span: e.name_span,
                    });
                }
            }
            "boundary" => {
                if let Some(name) = self.name(e) {
                    doc.boundaries.push(BoundaryDef {
                        name,
                        faces: self.ref_list(e, "faces"),
                        edges: self.ref_list(e, "edges"),
                        span: e.name_span,
                    });
                }
            }
            _ => {
                if let Some(kind) = self.object_kind(e)
                    && let Some(name) = self.name(e)
                {
                    doc.objects.push(Object {
                        name,
                        cs: self.reference(e, "cs").map(Box::new),
                        kind,
                        span: e.name_span,
                    });
                }
            }
        }
    }

    fn object_kind(&mut self, e: &Element) -> Option<ObjectKind> {
        Some(match e.name {
            "point" => ObjectKind::Point {
                values: e.children_named("value").map(|v| self.vector(v)).collect(),
            },
            "ellipse" => ObjectKind::Ellipse {
                center: self.point_child(e, "center"),
                radius_vertices: self.points_named(e, "radius_vertex"),
            },
            "circle" => ObjectKind::Circle {
                center: self.point_child(e, "center"),
                radius: self.value_child(e, "radius"),
            },
            "triangle" => ObjectKind::Triangle {
                vertices: self.points_named(e, "vertex"),
            },
            "parallelogram" => ObjectKind::Parallelogram {
                base: self.point_child(e, "base_point"),
                vertices: self.points_named(e, "vertex"),
            },
            "polygon" => ObjectKind::Polygon {
                vertices: self.points_named(e, "vertex"),
            },
            "rectangle" => ObjectKind::Rectangle {
                first: self.point_child(e, "first_point"),
                second: self.point_child(e, "second_point"),
            },
            "regular_polygon" => ObjectKind::RegularPolygon {
                center: self.point_child(e, "center"),
                radius: self.value_child(e, "radius"),
                sides: self.number(e, "sides"),
            },
            "poly_line" => ObjectKind::PolyLine {
                crack: e
                    .attribute("crack")
                    .is_some_and(|a| a.value.trim() == "true"),
                segments: e
                    .children_named("line")
                    .map(|l| {
                        (
                            self.point_child(l, "begin_point"),
                            self.point_child(l, "end_point"),
                        )
                    })
                    .collect(),
            },
            "truncated_cone" => ObjectKind::TruncatedCone {
                bottom_center: self.point_child(e, "bottom_center"),
                top_center: self.point_child(e, "top_center"),
                bottom_radius: self.value_child(e, "bottom_radius"),
                top_radius: self.value_child(e, "top_radius"),
            },
            "parallelepiped" => {
                ObjectKind::Parallelepiped(if let Some(base) = self.point_child(e, "base_point") {
                    Some(Box::new(ParallelepipedForm::Edges {
                        base,
                        vertices: self.points_named(e, "vertex"),
                    }))
                } else if e.children_named("point_a").next().is_some() {
                    let points: Vec<PointSpec> = ["point_a", "point_b", "point_c", "point_d"]
                        .iter()
                        .filter_map(|n| self.point_child(e, n))
                        .collect();
                    (points.len() == 4)
                        .then(|| Box::new(ParallelepipedForm::PointEquation { points }))
                } else {
                    match (
                        self.point_child(e, "first_point"),
                        self.point_child(e, "second_point"),
                    ) {
                        (Some(first), Some(second)) => {
                            Some(Box::new(ParallelepipedForm::Corners { first, second }))
                        }
                        _ => None,
                    }
                })
            }
            "sphere" => ObjectKind::Sphere {
                center: self.point_child(e, "center"),
                radius: self.value_child(e, "radius"),
            },
            "ellipsoid" => ObjectKind::Ellipsoid {
                center: self.point_child(e, "center"),
                semi_axes: self.vector_child(e, "semi_axes"),
            },
            "torus" => ObjectKind::Torus {
                center: self.point_child(e, "center"),
                major: self.value_child(e, "major_radius"),
                minor: self.value_child(e, "minor_radius"),
                axis: self.vector_child(e, "axis"),
            },
            "plane" => ObjectKind::Plane {
                base: self.point_child(e, "base_point"),
                normal: self.vector_child(e, "normal"),
            },
            "segment" | "conic_arc" | "desargues_arc" => {
                let (kind, names): (PcCurveKind, &[&str]) = match e.name {
                    "segment" => (PcCurveKind::Segment, &["point_a", "point_b"]),
                    "conic_arc" => (PcCurveKind::Conic, &["point_a", "point_b", "point_c"]),
                    _ => (
                        PcCurveKind::Desargues,
                        &["point_a", "point_b", "point_c", "point_d"],
                    ),
                };
                ObjectKind::PcCurve {
                    kind,
                    points: names.iter().map(|n| self.point_child(e, n)).collect(),
                    discriminant: self.value_child(e, "discriminant"),
                }
            }
            "patch9" if e.children_named("trim").next().is_none() => ObjectKind::Patch9 {
                rows: e
                    .children_named("row")
                    .map(|r| self.points_named(r, "node"))
                    .collect(),
            },
            "patch9" | "bezier_surface" | "cone_surface" | "parametric_surface"
            | "sphere_surface" | "torus_surface" => {
                let carrier = match e.name {
                    "patch9" => CarrierSpec::Patch9 {
                        rows: e
                            .children_named("row")
                            .map(|r| self.points_named(r, "node"))
                            .collect(),
                    },
                    "bezier_surface" => CarrierSpec::Bezier {
                        rows: e
                            .children_named("row")
                            .map(|r| self.points_named(r, "node"))
                            .collect(),
                    },
                    "cone_surface" => CarrierSpec::Cone {
                        bottom_radius: self.number(e, "bottom_radius"),
                        top_radius: self.number(e, "top_radius"),
                        length: self.number(e, "length"),
                        from_angle: self.number(e, "from_angle"),
                        to_angle: self.number(e, "to_angle"),
                    },
                    "sphere_surface" => CarrierSpec::Sphere {
                        radius: self.number(e, "radius"),
                        latitudes: ["from_latitude", "to_latitude"].map(|a| self.number(e, a)),
                        angles: ["from_angle", "to_angle"].map(|a| self.number(e, a)),
                    },
                    "torus_surface" => CarrierSpec::Torus {
                        radii: ["major_radius", "minor_radius"].map(|a| self.number(e, a)),
                        tube: ["from_tube_angle", "to_tube_angle"].map(|a| self.number(e, a)),
                        angles: ["from_angle", "to_angle"].map(|a| self.number(e, a)),
                    },
                    _ => CarrierSpec::Expressions {
                        xyz: ["x", "y", "z"].map(|a| self.number(e, a)),
                        rect: ["u_min", "u_max", "v_min", "v_max"].map(|a| self.number(e, a)),
                    },
                };
                let trim = e.children_named("trim").next().map(|t| TrimSpec {
                    equation: self.number(t, "equation"),
                    tree: !t.children.is_empty(),
                    negative: t
                        .attribute("material")
                        .is_some_and(|a| a.value.trim() == "negative"),
                    span: t.name_span,
                });
                ObjectKind::Trimmed(Box::new(TrimmedSpec { carrier, trim }))
            }
            "transform" => ObjectKind::Transform {
                target: self.reference(e, "ref"),
                steps: self.steps(e),
            },
            "replicate" => ObjectKind::Replicate {
                target: self.reference(e, "ref"),
                count: self.number(e, "count"),
                steps: self.steps(e),
            },
            "surface" => ObjectKind::Surface(e.children.first().and_then(|c| self.surface(c))),
            "line" => ObjectKind::Line(e.children.first().and_then(|c| self.line(c))),
            "vertex" => ObjectKind::Vertex(self.vertex(e)),
            "edge" => ObjectKind::Edge {
                line: self.reference(e, "line"),
                begin: self.reference(e, "begin"),
                end: self.reference(e, "end"),
            },
            "face" => {
                let mut loops = Vec::new();
                let mut loop_spans = Vec::new();
                if let Some((refs, span)) = self.ref_list(e, "edges") {
                    loops.push(refs);
                    loop_spans.push(span);
                }
                for l in e.children_named("loop") {
                    if let Some((refs, span)) = self.ref_list(l, "edges") {
                        loops.push(refs);
                        loop_spans.push(span);
                    }
                }
                ObjectKind::Face {
                    surface: self.reference(e, "surface"),
                    loops,
                    loop_spans,
                }
            }
            _ => return None,
        })
    }

    fn steps(&mut self, e: &Element) -> Vec<Step> {
        let mut steps = Vec::new();
        for c in &e.children {
            match c.name {
                "shift" => steps.push(Step::Shift(self.vector(c))),
                "rotate" => steps.push(Step::Rotate {
                    angles: self.vector(c),
                    center: self.reference(c, "center"),
                }),
                "scale" => steps.push(Step::Scale {
                    factors: self.vector(c),
                    factor: self.number(c, "factor"),
                }),
                _ => {}
            }
        }
        steps
    }

    fn surface(&mut self, c: &Element) -> Option<SurfaceSpec> {
        Some(match c.name {
            "plane" => SurfaceSpec::Plane {
                base: self.point_child(c, "base_point"),
                normal: self.vector_child(c, "normal"),
            },
            "sphere" => SurfaceSpec::Sphere {
                center: self.point_child(c, "center"),
                radius: self.value_child(c, "radius"),
            },
            "cylinder" => SurfaceSpec::Cylinder {
                base: self.point_child(c, "base_point"),
                axis: self.vector_child(c, "axis"),
                radius: self.value_child(c, "radius"),
            },
            "cone" => SurfaceSpec::Cone {
                apex: self.point_child(c, "apex"),
                axis: self.vector_child(c, "axis"),
                half_angle: self.value_child(c, "half_angle"),
            },
            "quadric" => {
                const NAMES: [&str; 10] = ["xx", "yy", "zz", "xy", "yz", "zx", "x", "y", "z", "c"];
                let mut coefficients: [Option<Number>; 10] = Default::default();
                for (slot, name) in coefficients.iter_mut().zip(NAMES) {
                    *slot = self.number(c, name);
                }
                SurfaceSpec::Quadric {
                    coefficients,
                    span: c.name_span,
                }
            }
            "implicit" => SurfaceSpec::Implicit {
                equation: self.number(c, "equation"),
            },
            _ => return None,
        })
    }

    fn line(&mut self, c: &Element) -> Option<LineSpec> {
        Some(match c.name {
            "straight" => LineSpec::Straight,
            "circle_arc" => LineSpec::CircleArc {
                center: self.point_child(c, "center"),
                normal: self.vector_child(c, "normal"),
            },
            "ellipse_arc" => LineSpec::EllipseArc {
                center: self.point_child(c, "center"),
                radius_vertices: self.points_named(c, "radius_vertex"),
            },
            "intersection" => LineSpec::Intersection {
                surfaces: self
                    .ref_list(c, "surfaces")
                    .map(|(r, _)| r)
                    .unwrap_or_default(),
                span: c.name_span,
            },
            _ => return None,
        })
    }

    fn vertex(&mut self, e: &Element) -> Option<VertexSpec> {
        if let Some(i) = e.children_named("intersection").next() {
            let near = self.point_child(i, "near");
            if let Some((surfaces, _)) = self.ref_list(i, "surfaces") {
                return Some(VertexSpec::Surfaces {
                    surfaces,
                    near,
                    span: i.name_span,
                });
            }
            if let Some((lines, _)) = self.ref_list(i, "lines") {
                return Some(VertexSpec::Lines {
                    lines,
                    near,
                    span: i.name_span,
                });
            }
            self.diags.push(
                Diagnostic::new(
                    Code::MissingAttribute,
                    i.name_span,
                    "<intersection> of a vertex needs surfaces=\"a b c\" or lines=\"a b\"",
                )
                .with_help("name three surfaces or two lines whose intersection is the vertex"),
            );
            return None;
        }
        Some(VertexSpec::Coordinates(self.point(e)))
    }

    fn solid_tree(&mut self, e: &Element) -> Option<SolidTree> {
        let operands = |b: &mut Self| -> Vec<SolidTree> {
            e.children.iter().filter_map(|c| b.solid_tree(c)).collect()
        };
        Some(match e.name {
            "solid" => SolidTree::Solid(self.reference(e, "ref")?),
            "union" => SolidTree::Union(operands(self), e.name_span),
            "intersection" => SolidTree::Intersection(operands(self), e.name_span),
            "difference" => SolidTree::Difference(operands(self), e.name_span),
            _ => return None,
        })
    }

    // ---- leaves ----

    fn name(&mut self, e: &Element) -> Option<Name> {
        attribute(e, "name").map(|a| Name {
            text: a.value.trim().to_string(),
            span: a.value_span,
        })
    }

    fn number(&mut self, e: &Element, attr: &str) -> Option<Number> {
        attribute(e, attr).map(|a| self.parse_number(a))
    }

    fn parse_number(&mut self, attr: &Attribute) -> Number {
        // Most numbers of large files are plain literals: their value is made
        // here, without the expression parser's trim, tree and the source
        // comparison below (the same `Number` the parser's path gives).
        if self.limits.max_nodes >= 1
            && let Some(value) = plain_literal(&attr.value)
        {
            return Number::plain(value, attr.value_span);
        }
        // Offsets into the value map onto the source only when the raw text
        // equals the value (no entity references); otherwise point at the whole value.
        let raw = self.source.snippet(attr.value_span);
        let exact = raw == attr.value;
        let base = if exact {
            attr.value_span.start as usize
        } else {
            0
        };
        let fix = |span: Span| if exact { span } else { attr.value_span };
        match expr::parse_with(&attr.value, base, &self.limits) {
            Ok(mut expr) => {
                if !exact {
                    relocate(&mut expr, attr.value_span);
                }
                Number::new(Some(expr), attr.value_span)
            }
            Err(error) => {
                let d = match error {
                    ParseError::Syntax { span, message } => Diagnostic::new(
                        Code::BadExpression,
                        fix(span),
                        format!("{}=\"{}\": {message}", attr.name, attr.value),
                    )
                    .with_help("write a number like 2.5 or an expression like 2*r + 1"),
                    ParseError::UnknownFunction { span, name } => {
                        let names = expr::Function::ALL.iter().map(|(n, _)| *n);
                        let suggestion = crate::diag::did_you_mean(&name, names)
                            .map_or(String::new(), |s| format!("did you mean '{s}'? "));
                        Diagnostic::new(Code::UnknownFunction, fix(span), format!("unknown function '{name}' in {}=\"{}\"", attr.name, attr.value))
                            .with_help(format!("{suggestion}known functions: sqrt sin cos tan asin acos atan exp ln abs min max"))
                    }
                    ParseError::WrongArgumentCount { span, function, given } => Diagnostic::new(
                        Code::WrongArgumentCount,
                        fix(span),
                        format!(
                            "{}() called with {given} argument{} in {}=\"{}\"",
                            function.name(),
                            if given == 1 { "" } else { "s" },
                            attr.name,
                            attr.value
                        ),
                    )
                    .with_help(if function.is_variadic() {
                        format!("{}() takes two or more arguments", function.name())
                    } else {
                        format!("{}() takes exactly one argument", function.name())
                    }),
                    ParseError::TooLarge { span } => Diagnostic::new(
                        Code::ExpressionTooLarge,
                        fix(span),
                        format!(
                            "the expression in {}= exceeds the limit of {} nodes or {} levels of nesting",
                            attr.name, self.limits.max_nodes, self.limits.max_depth
                        ),
                    )
                    .with_help("split it into parameters, or raise the limits with --max-expression-nodes N and --max-expression-depth N"),
                };
                self.diags.push(d);
                Number::new(None, attr.value_span)
            }
        }
    }

    fn reference(&mut self, e: &Element, attr: &str) -> Option<Ref> {
        let a = attribute(e, attr)?;
        Some(parse_ref(a.value.trim(), a.value_span))
    }

    fn ref_list(&mut self, e: &Element, attr: &str) -> Option<(Vec<Ref>, Span)> {
        let a = attribute(e, attr)?;
        let mut refs = Vec::new();
        let base = a.value_span.start as usize;
        let exact = self.source.snippet(a.value_span) == a.value;
        let mut offset = 0;
        for token in a.value.split(|c: char| c.is_whitespace()) {
            if !token.is_empty() {
                let span = if exact {
                    Span::new(base + offset, base + offset + token.len())
                } else {
                    a.value_span
                };
                refs.push(parse_ref(token, span));
            }
            offset += token.len() + 1;
        }
        if refs.is_empty() {
            self.diags.push(
                Diagnostic::new(
                    Code::EmptyModel,
                    a.value_span,
                    format!("{attr}=\"\" on <{}> lists nothing", e.name),
                )
                .with_help(format!("name at least one object in {attr}=\"…\"")),
            );
        }
        Some((refs, a.value_span))
    }

    fn point(&mut self, e: &Element) -> PointSpec {
        self.point_tagged(e, point_tag(e.name))
    }

    /// [`Builder::point`] of an element whose tag is known to be `tag`.
    fn point_tagged(&mut self, e: &Element, tag: std::borrow::Cow<'static, str>) -> PointSpec {
        let [x, y, z, point] = Coordinates::of(e);
        PointSpec {
            x: x.map(|a| self.parse_number(a)),
            y: y.map(|a| self.parse_number(a)),
            z: z.map(|a| self.parse_number(a)),
            point: point.map(|a| Box::new(parse_ref(a.value.trim(), a.value_span))),
            tag,
            span: e.name_span,
        }
    }

    fn vector(&mut self, e: &Element) -> VectorSpec {
        let [x, y, z, _] = Coordinates::of(e);
        VectorSpec {
            x: x.map(|a| self.parse_number(a)),
            y: y.map(|a| self.parse_number(a)),
            z: z.map(|a| self.parse_number(a)),
            span: e.name_span,
        }
    }

    fn point_child(&mut self, e: &Element, name: &'static str) -> Option<PointSpec> {
        child_named(e, name).map(|c| self.point_tagged(c, std::borrow::Cow::Borrowed(name)))
    }

    fn points_named(&mut self, e: &Element, name: &'static str) -> Vec<PointSpec> {
        e.children
            .iter()
            .filter(|c| same_name(c.name, name))
            .map(|c| self.point_tagged(c, std::borrow::Cow::Borrowed(name)))
            .collect()
    }

    fn vector_child(&mut self, e: &Element, name: &str) -> Option<VectorSpec> {
        child_named(e, name).map(|c| self.vector(c))
    }

    fn value_child(&mut self, e: &Element, name: &str) -> Option<Number> {
        child_named(e, name).and_then(|c| self.number(c, "value"))
    }
}

/// [`Element::attribute`] with [`same_name`].
fn attribute<'e, 's>(e: &'e Element<'s>, name: &str) -> Option<&'e Attribute<'s>> {
    e.attributes.iter().find(|a| same_name(a.name, name))
}

/// The first child of `e` named `name`.
fn child_named<'e, 's>(e: &'e Element<'s>, name: &str) -> Option<&'e Element<'s>> {
    e.children.iter().find(|c| same_name(c.name, name))
}

/// The `x`, `y`, `z` and `point` attributes of a point or vector element,
/// found in one pass over its attributes (each the first of its name, as
/// [`Element::attribute`] finds it); the numbers are parsed afterwards in
/// that order, so their findings keep it.
struct Coordinates;

impl Coordinates {
    fn of<'e, 's>(e: &'e Element<'s>) -> [Option<&'e Attribute<'s>>; 4] {
        let mut found = [None; 4];
        for a in &e.attributes {
            // Byte patterns: compared inline, without a `memcmp` per name.
            let slot = match a.name.as_bytes() {
                [b'x'] => 0,
                [b'y'] => 1,
                [b'z'] => 2,
                [b'p', b'o', b'i', b'n', b't'] => 3,
                _ => continue,
            };
            if let Some(place) = found.get_mut(slot) {
                place.get_or_insert(a);
            }
        }
        found
    }
}

/// The value of an attribute that is one unsigned decimal literal without
/// exponent or spaces (`12`, `0.25`, `3.`), when it is exactly what
/// `str::parse::<f64>` gives for it: a mantissa below 2^53 over a power of ten
/// up to 10^22, both exact in an `f64`, so their quotient is correctly rounded
/// (Clinger's fast path; the correctly rounded value is unique). Anything
/// else is `None` and goes to the expression parser.
fn plain_literal(text: &str) -> Option<f64> {
    /// 10^0 … 10^22, each exact in an `f64`.
    const POWERS: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
    ];
    let mut mantissa: u64 = 0;
    let mut digits = 0usize;
    let mut dot: Option<usize> = None;
    for &b in text.as_bytes() {
        match b {
            b'0'..=b'9' => {
                mantissa = mantissa * 10 + u64::from(b - b'0');
                if mantissa >= 1 << 53 {
                    return None;
                }
                digits += 1;
            }
            b'.' if dot.is_none() => dot = Some(digits),
            _ => return None,
        }
    }
    if digits == 0 {
        return None;
    }
    let scale = POWERS.get(dot.map_or(0, |before| digits - before))?;
    // Exact integers up to 2^53: the conversion does not round.
    Some(mantissa as f64 / scale)
}

/// The tag of a point-valued element without allocating for the usual ones.
fn point_tag(name: &str) -> std::borrow::Cow<'static, str> {
    const TAGS: &[&str] = &[
        "center",
        "first_point",
        "second_point",
        "bottom_center",
        "top_center",
        "base_point",
        "vertex",
        "radius_vertex",
        "origin",
        "begin_point",
        "end_point",
        "apex",
        "near",
        "point_a",
        "point_b",
        "point_c",
        "point_d",
    ];
    match TAGS.iter().find(|&&t| same_name(t, name)) {
        Some(t) => std::borrow::Cow::Borrowed(t),
        None => std::borrow::Cow::Owned(name.to_string()),
    }
}

/// `name`, `name[3]` or `name.entity` (the entity part only when the name
/// before the dot is non-empty).
pub fn parse_ref(text: &str, span: Span) -> Ref {
    // Most references are bare names: no dot for an entity, no `]` ending
    // a member index.
    if !text.bytes().any(|b| b == b'.' || b == b']') {
        return Ref::to_name(text, span);
    }
    let mut name_end = text.len();
    let mut entity = None;
    if let Some(dot) = text.rfind('.')
        && dot > 0
        && dot + 1 < text.len()
        && !text[dot + 1..].contains(']')
    {
        entity = Some(dot + 1);
        name_end = dot;
    }
    let name = &text[..name_end];
    let mut index = None;
    if name.ends_with(']')
        && let Some(open) = name.rfind('[')
        && let Ok(i) = name[open + 1..name.len() - 1].trim().parse::<usize>()
    {
        index = Some(i);
        name_end = open;
    }
    Ref::new(text, name_end, index, entity, span)
}

fn relocate(expr: &mut crate::expr::Expr, span: Span) {
    use crate::expr::ExprKind;
    expr.span = span;
    match &mut expr.kind {
        ExprKind::Number(_) | ExprKind::Name(_) => {}
        ExprKind::Neg(inner) => relocate(inner, span),
        ExprKind::Binary(_, a, b) => {
            relocate(a, span);
            relocate(b, span);
        }
        ExprKind::Call(_, args) => args.iter_mut().for_each(|a| relocate(a, span)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::TestRng;

    #[test]
    fn references_parse_members_and_entities() {
        let r = parse_ref("pts[2]", Span::default());
        assert_eq!((r.name(), r.index, r.entity()), ("pts", Some(2), None));
        let r = parse_ref("box.xmin", Span::default());
        assert_eq!((r.name(), r.entity()), ("box", Some("xmin")));
        let r = parse_ref("row[3].top", Span::default());
        assert_eq!(
            (r.name(), r.index, r.entity()),
            ("row", Some(3), Some("top"))
        );
        let r = parse_ref("point 3D", Span::default());
        assert_eq!((r.name(), r.index), ("point 3D", None));
        let r = parse_ref("a.b[2]", Span::default());
        assert_eq!((r.name(), r.index, r.entity()), ("a.b", Some(2), None));
        let r = parse_ref(".x", Span::default());
        assert_eq!((r.name(), r.entity()), (".x", None));
        assert_eq!(
            parse_ref("s", Span::new(4, 5)),
            Ref::to_name("s", Span::new(4, 5))
        );
    }

    /// The split of a reference into owned name and entity strings that
    /// `parse_ref` made before it kept them as ranges of the text.
    fn split_by_copies(text: &str) -> (String, Option<usize>, Option<String>) {
        let mut name = text.to_string();
        let mut index = None;
        let mut entity = None;
        if let Some(dot) = name.rfind('.')
            && dot > 0
            && dot + 1 < name.len()
            && !name[dot + 1..].contains(']')
        {
            entity = Some(name[dot + 1..].to_string());
            name.truncate(dot);
        }
        if name.ends_with(']')
            && let Some(open) = name.rfind('[')
            && let Ok(i) = name[open + 1..name.len() - 1].trim().parse::<usize>()
        {
            index = Some(i);
            name.truncate(open);
        }
        (name, index, entity)
    }

    #[test]
    fn references_split_as_the_copying_split_did() {
        let mut rng = TestRng::new(0x2ef5_17a3);
        const PIECES: &[&str] = &[
            "p", "box", "é", ".", "..", "[", "]", "[2]", "[ 3 ]", "[+4]", "[x]", "3", " ", "_",
            ".xmin", "]x",
        ];
        let mut with_parts = [0; 2];
        for _ in 0..40_000 {
            let mut text = String::new();
            for _ in 0..rng.below(6) {
                text.push_str(PIECES[rng.below(PIECES.len())]);
            }
            let r = parse_ref(&text, Span::new(9, 9 + text.len()));
            let (name, index, entity) = split_by_copies(&text);
            assert_eq!(
                (r.name(), r.index, r.entity()),
                (name.as_str(), index, entity.as_deref()),
                "{text:?}"
            );
            assert_eq!(
                (&*r.text, r.span),
                (text.as_str(), Span::new(9, 9 + text.len()))
            );
            with_parts[0] += usize::from(index.is_some());
            with_parts[1] += usize::from(entity.is_some());
        }
        // Members and entities both come up often, not only plain names.
        assert!(with_parts.iter().all(|&n| n > 2_000), "{with_parts:?}");
    }

    /// The number the expression parser's path makes of `text` at `span`.
    fn parsed(text: &str, span: Span) -> Number {
        let limits = ExprLimits::default();
        Number::new(
            expr::parse_with(text, span.start as usize, &limits).ok(),
            span,
        )
    }

    #[test]
    fn plain_literals_are_the_numbers_the_expression_parser_makes() {
        let span = Span { start: 7, end: 0 };
        let at = |text: &str| Span {
            end: 7 + text.len() as u32,
            ..span
        };
        // Taken here, with the parser's value to the bit.
        for text in [
            "0",
            "12",
            "0.25",
            "3.",
            ".5",
            "007.50",
            "0.1",
            "2.675",
            "123456.789",
            "9007199254740991",
            "0.0000000000000000000001",
            "900719925474099.1",
        ] {
            let value = plain_literal(text).unwrap_or_else(|| panic!("{text:?} is plain"));
            let expected: f64 = text.parse().expect("a literal");
            assert_eq!(value.to_bits(), expected.to_bits(), "{text:?}");
            assert_eq!(
                Number::plain(value, at(text)),
                parsed(text, at(text)),
                "{text:?}"
            );
        }
        // Left to the parser: not one plain literal, or past the exact range.
        for text in [
            "",
            ".",
            "1.2.3",
            "-1",
            "+1",
            " 1",
            "1 ",
            "1e5",
            "r",
            "2*r",
            "1_0",
            "١",
            "9007199254740992",
            "0.00000000000000000000001",
            "99999999999999999999",
            "4503599627370495.5",
        ] {
            assert_eq!(plain_literal(text), None, "{text:?}");
        }
        // Random literals of 1 to 20 digits with and without a dot: every one
        // taken is the parser's number, and most short ones are taken.
        let mut rng = TestRng::new(0x2545_F491_4F6C_DD1D);
        let mut taken = 0;
        for _ in 0..20_000 {
            let digits = 1 + rng.below(20);
            let mut text: String = (0..digits)
                .map(|_| char::from(b'0' + rng.below(10) as u8))
                .collect();
            if rng.below(4) > 0 {
                text.insert(rng.below(digits + 1), '.');
            }
            if let Some(value) = plain_literal(&text) {
                taken += 1;
                let expected: f64 = text.parse().expect("a literal");
                assert_eq!(value.to_bits(), expected.to_bits(), "{text:?}");
                assert_eq!(Number::plain(value, at(&text)), parsed(&text, at(&text)));
            }
        }
        assert!(taken > 12_000, "{taken} of 20,000 taken");
    }

    #[test]
    fn coordinates_are_read_in_their_order_whatever_the_attributes_order() {
        let xml = concat!(
            "<geometry version=\"1\"><sphere name=\"s\">",
            "<center z=\"1+\" point=\"p\" y=\"2\" x=\"*3\"/><radius value=\"1\"/>",
            "</sphere></geometry>"
        );
        let source = SourceFile::new("c.xml", xml);
        let root =
            crate::syntax::parse(&source, &crate::syntax::Limits::default()).expect("parses");
        let mut diags = Diagnostics::default();
        let doc = build(&source, &root, &mut diags);
        let messages: Vec<&str> = diags.items.iter().map(|d| d.message.as_str()).collect();
        assert_eq!(messages.len(), 2, "{messages:?}");
        assert!(messages[0].starts_with("x=\"*3\""), "{messages:?}");
        assert!(messages[1].starts_with("z=\"1+\""), "{messages:?}");
        let Some(Object {
            kind:
                ObjectKind::Sphere {
                    center: Some(center),
                    ..
                },
            ..
        }) = doc.objects.first()
        else {
            panic!("a sphere with a center: {:?}", doc.objects)
        };
        let y = center.y.as_ref().and_then(|n| n.expr()).expect("y parses");
        assert_eq!(y.kind, crate::expr::ExprKind::Number(2.0));
        assert_eq!(center.x.as_ref().map(|n| n.expr()), Some(None));
        assert_eq!(center.point.as_ref().map(|r| r.name()), Some("p"));
        assert_eq!(center.tag, "center");
    }

    #[test]
    fn numbers_give_back_the_expression_they_were_parsed_from() {
        // A plain number spanning its value, one with spaces around it (its
        // token's span is not the value's), a name, an expression, a failure.
        for text in ["2.5", " 2.5 ", "r", "r/2 + 1", "-1"] {
            let span = Span {
                start: 10,
                end: 10 + text.len() as u32,
            };
            let expr = crate::expr::parse(text, 10).expect("parses");
            let number = Number::new(Some(expr.clone()), span);
            assert_eq!(number.expr().as_deref(), Some(&expr), "{text:?}");
            assert_eq!(number.span, span);
        }
        assert_eq!(Number::new(None, Span::default()).expr(), None);
        // Plain numbers are the common case of large files: no tree is kept.
        assert!(std::mem::size_of::<Number>() <= 24);
    }
}
