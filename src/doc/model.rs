//! The typed document: one struct per element kind, names still unresolved,
//! every value with the span it came from. Built by [`super::build`]; parts the
//! structural check already reported as missing are `None`.

use crate::expr::Expr;
use crate::span::Span;

/// A name as written, with the span of the attribute value.
#[derive(Debug, Clone, PartialEq)]
pub struct Name {
    pub text: String,
    pub span: Span,
}

/// A reference to a named object: `name`, `name[3]` (1-based member), or, in
/// face and edge lists, `name.entity`.
///
/// The name and the entity are parts of the text as written, kept as byte
/// ranges of it: one allocation per reference (there is one per solid of a
/// subdomain, and one per point given by name).
#[derive(Debug, Clone, PartialEq)]
pub struct Ref {
    /// The reference as written.
    pub text: Box<str>,
    /// The name is `text[..name_end]`.
    name_end: usize,
    /// The entity is `text[entity_start..]`; 0 when there is none (an
    /// entity never starts the text).
    entity_start: usize,
    pub index: Option<usize>,
    pub span: Span,
}

impl Ref {
    /// The reference `text` whose name is `text[..name_end]`, member `index`
    /// and entity `text[entity_start..]` (`None` or 0: no entity). Both
    /// offsets must be character boundaries of `text`.
    pub fn new(
        text: &str,
        name_end: usize,
        index: Option<usize>,
        entity_start: Option<usize>,
        span: Span,
    ) -> Ref {
        Ref {
            text: text.into(),
            name_end,
            entity_start: entity_start.unwrap_or(0),
            index,
            span,
        }
    }

    /// A reference to `name` itself, without member or entity.
    pub fn to_name(name: &str, span: Span) -> Ref {
        Ref::new(name, name.len(), None, None, span)
    }

    /// The name referred to: the text before any `[index]` and `.entity`.
    pub fn name(&self) -> &str {
        self.text.get(..self.name_end).unwrap_or_default()
    }

    /// The entity after the last dot (`box.xmin`), if any.
    pub fn entity(&self) -> Option<&str> {
        match self.entity_start {
            0 => None,
            start => self.text.get(start..),
        }
    }
}

/// A numeric attribute: the parsed expression, or none if it did not parse
/// (already reported). Read it with [`Number::expr`].
#[derive(Debug, Clone, PartialEq)]
pub struct Number {
    parsed: Parsed,
    pub span: Span,
}

/// A plain number spanning the whole value (most numbers of large files) is
/// kept as its value, any other expression as a boxed tree: an `Expr` inline
/// made every coordinate 48 bytes, and the typed document holds one per
/// number of the file until resolution is done.
#[derive(Debug, Clone, PartialEq)]
enum Parsed {
    Plain(f64),
    Expr(Box<Expr>),
    Invalid,
}

impl Number {
    /// `expr`: the parsed value (`None`: it did not parse); `span`: the value's.
    pub fn new(expr: Option<Expr>, span: Span) -> Number {
        let parsed = match expr {
            None => Parsed::Invalid,
            Some(Expr {
                kind: crate::expr::ExprKind::Number(value),
                span: at,
            }) if at == span => Parsed::Plain(value),
            Some(expr) => Parsed::Expr(Box::new(expr)),
        };
        Number { parsed, span }
    }

    /// A plain number spanning its whole value: what [`Number::new`] makes of
    /// a number literal whose span is `span`.
    pub fn plain(value: f64, span: Span) -> Number {
        Number {
            parsed: Parsed::Plain(value),
            span,
        }
    }

    /// The parsed expression, or `None` if it did not parse.
    pub fn expr(&self) -> Option<std::borrow::Cow<'_, Expr>> {
        match &self.parsed {
            Parsed::Plain(value) => Some(std::borrow::Cow::Owned(Expr::number(*value, self.span))),
            Parsed::Expr(expr) => Some(std::borrow::Cow::Borrowed(expr)),
            Parsed::Invalid => None,
        }
    }
}

/// A point-valued child element (`center`, `vertex`, …): coordinates, or a
/// reference to a named point.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSpec {
    pub x: Option<Number>,
    pub y: Option<Number>,
    pub z: Option<Number>,
    /// Boxed: most points give coordinates, and a point is stored per corner.
    pub point: Option<Box<Ref>>,
    /// The element's tag, for messages (borrowed for the grammar's point elements).
    pub tag: std::borrow::Cow<'static, str>,
    /// The element's name in its start tag.
    pub span: Span,
}

/// A vector-valued child element (`normal`, `axis`, `rotation`, `semi_axes`, shift …).
#[derive(Debug, Clone, PartialEq)]
pub struct VectorSpec {
    pub x: Option<Number>,
    pub y: Option<Number>,
    pub z: Option<Number>,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    pub name: Name,
    pub value: Number,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
    pub fn letter(self) -> &'static str {
        match self {
            Axis::X => "X",
            Axis::Y => "Y",
            Axis::Z => "Z",
        }
    }
}

/// One basis coordinate: an attribute of `<coordinate name="X"><value x1=…/>`.
#[derive(Debug, Clone, PartialEq)]
pub struct BasisCoordinate {
    pub axis: Axis,
    pub name: Name,
    pub value: Number,
}

#[derive(Debug, Clone, PartialEq)]
pub struct CoordinateSystem {
    pub name: Name,
    pub parent: Option<Ref>,
    pub origin: Option<PointSpec>,
    pub rotation: Option<VectorSpec>,
}

// Both forms are a few points; the enum is boxed where it is stored.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum ParallelepipedForm {
    /// Base point and the ends of the three edges from it.
    Edges {
        base: PointSpec,
        vertices: Vec<PointSpec>,
    },
    /// Two opposite corners of an axis-aligned box.
    Corners { first: PointSpec, second: PointSpec },
    /// Paper 003's M = Au + Bv + Cw + D(1 − u − v − w): `points` are A, B, C, D.
    PointEquation { points: Vec<PointSpec> },
}

/// Which of paper 003's curves an element defines.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PcCurveKind {
    /// `segment`: A, B.
    Segment,
    /// `conic_arc`: A, B, C and the discriminant.
    Conic,
    /// `desargues_arc`: A, B, C, D.
    Desargues,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    Shift(VectorSpec),
    Rotate {
        angles: VectorSpec,
        center: Option<Ref>,
    },
    Scale {
        factors: VectorSpec,
        factor: Option<Number>,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub enum SurfaceSpec {
    Plane {
        base: Option<PointSpec>,
        normal: Option<VectorSpec>,
    },
    Sphere {
        center: Option<PointSpec>,
        radius: Option<Number>,
    },
    Cylinder {
        base: Option<PointSpec>,
        axis: Option<VectorSpec>,
        radius: Option<Number>,
    },
    Cone {
        apex: Option<PointSpec>,
        axis: Option<VectorSpec>,
        half_angle: Option<Number>,
    },
    /// Coefficients xx yy zz xy yz zx x y z c (absent = 0).
    Quadric {
        coefficients: [Option<Number>; 10],
        span: Span,
    },
    Implicit {
        equation: Option<Number>,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub enum LineSpec {
    Straight,
    CircleArc {
        center: Option<PointSpec>,
        normal: Option<VectorSpec>,
    },
    EllipseArc {
        center: Option<PointSpec>,
        radius_vertices: Vec<PointSpec>,
    },
    Intersection {
        surfaces: Vec<Ref>,
        span: Span,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub enum VertexSpec {
    Coordinates(PointSpec),
    Surfaces {
        surfaces: Vec<Ref>,
        near: Option<PointSpec>,
        span: Span,
    },
    Lines {
        lines: Vec<Ref>,
        near: Option<PointSpec>,
        span: Span,
    },
}

/// What a named object is.
#[derive(Debug, Clone, PartialEq)]
pub enum ObjectKind {
    Point {
        values: Vec<VectorSpec>,
    },
    Ellipse {
        center: Option<PointSpec>,
        radius_vertices: Vec<PointSpec>,
    },
    Circle {
        center: Option<PointSpec>,
        radius: Option<Number>,
    },
    Triangle {
        vertices: Vec<PointSpec>,
    },
    Parallelogram {
        base: Option<PointSpec>,
        vertices: Vec<PointSpec>,
    },
    /// A simple polygon, vertices in document order (either orientation).
    Polygon {
        vertices: Vec<PointSpec>,
    },
    /// An axis-aligned rectangle (in its coordinate system) by opposite corners.
    Rectangle {
        first: Option<PointSpec>,
        second: Option<PointSpec>,
    },
    RegularPolygon {
        center: Option<PointSpec>,
        radius: Option<Number>,
        sides: Option<Number>,
    },
    PolyLine {
        segments: Vec<(Option<PointSpec>, Option<PointSpec>)>,
        /// `crack="true"`: a 2D mesh is opened along it.
        crack: bool,
    },
    TruncatedCone {
        bottom_center: Option<PointSpec>,
        top_center: Option<PointSpec>,
        bottom_radius: Option<Number>,
        top_radius: Option<Number>,
    },
    Parallelepiped(Option<Box<ParallelepipedForm>>),
    Sphere {
        center: Option<PointSpec>,
        radius: Option<Number>,
    },
    Ellipsoid {
        center: Option<PointSpec>,
        semi_axes: Option<VectorSpec>,
    },
    Torus {
        center: Option<PointSpec>,
        major: Option<Number>,
        minor: Option<Number>,
        axis: Option<VectorSpec>,
    },
    Plane {
        base: Option<PointSpec>,
        normal: Option<VectorSpec>,
    },
    Transform {
        target: Option<Ref>,
        steps: Vec<Step>,
    },
    Replicate {
        target: Option<Ref>,
        count: Option<Number>,
        steps: Vec<Step>,
    },
    Surface(Option<SurfaceSpec>),
    Line(Option<LineSpec>),
    Vertex(Option<VertexSpec>),
    Edge {
        line: Option<Ref>,
        begin: Option<Ref>,
        end: Option<Ref>,
    },
    /// Paper 003's curves; `points` holds A, B, … in order (missing ones
    /// already reported by the structural check).
    PcCurve {
        kind: PcCurveKind,
        points: Vec<Option<PointSpec>>,
        discriminant: Option<Number>,
    },
    /// Paper 003's 9-point patch: three rows of three points.
    Patch9 {
        rows: Vec<Vec<PointSpec>>,
    },
    /// A parametric surface of paper 002, meshed as a face of its own.
    Trimmed(Box<TrimmedSpec>),
    /// Loops of edge references; the first is the outer loop.
    Face {
        surface: Option<Ref>,
        loops: Vec<Vec<Ref>>,
        loop_spans: Vec<Span>,
    },
}

impl ObjectKind {
    /// The element name that defines this kind, for messages.
    pub fn element(&self) -> &'static str {
        match self {
            ObjectKind::Point { .. } => "point",
            ObjectKind::Ellipse { .. } => "ellipse",
            ObjectKind::Circle { .. } => "circle",
            ObjectKind::Triangle { .. } => "triangle",
            ObjectKind::Parallelogram { .. } => "parallelogram",
            ObjectKind::Polygon { .. } => "polygon",
            ObjectKind::Rectangle { .. } => "rectangle",
            ObjectKind::RegularPolygon { .. } => "regular_polygon",
            ObjectKind::PolyLine { .. } => "poly_line",
            ObjectKind::TruncatedCone { .. } => "truncated_cone",
            ObjectKind::Parallelepiped(_) => "parallelepiped",
            ObjectKind::Sphere { .. } => "sphere",
            ObjectKind::Ellipsoid { .. } => "ellipsoid",
            ObjectKind::Torus { .. } => "torus",
            ObjectKind::Plane { .. } => "plane",
            ObjectKind::Transform { .. } => "transform",
            ObjectKind::Replicate { .. } => "replicate",
            ObjectKind::Surface(_) => "surface",
            ObjectKind::Line(_) => "line",
            ObjectKind::Vertex(_) => "vertex",
            ObjectKind::Edge { .. } => "edge",
            ObjectKind::Face { .. } => "face",
            ObjectKind::PcCurve { kind, .. } => match kind {
                PcCurveKind::Segment => "segment",
                PcCurveKind::Conic => "conic_arc",
                PcCurveKind::Desargues => "desargues_arc",
            },
            ObjectKind::Patch9 { .. } => "patch9",
            ObjectKind::Trimmed(spec) => match spec.carrier {
                CarrierSpec::Bezier { .. } => "bezier_surface",
                CarrierSpec::Cone { .. } => "cone_surface",
                CarrierSpec::Sphere { .. } => "sphere_surface",
                CarrierSpec::Torus { .. } => "torus_surface",
                CarrierSpec::Expressions { .. } => "parametric_surface",
                CarrierSpec::Patch9 { .. } => "patch9",
            },
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    pub name: Name,
    /// Boxed: most objects have none.
    pub cs: Option<Box<Ref>>,
    pub kind: ObjectKind,
    /// The element's name in its start tag.
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub enum SolidTree {
    Solid(Ref),
    Union(Vec<SolidTree>, Span),
    Intersection(Vec<SolidTree>, Span),
    /// The first operand minus the others.
    Difference(Vec<SolidTree>, Span),
}

#[derive(Debug, Clone, PartialEq)]
pub struct SubdomainDef {
    pub name: Name,
    pub material: Option<String>,
    /// Boxed, as `area`: most subdomains are a solid tree, and a definition
    /// is kept per subdomain until lowering.
    pub faces: Option<Box<(Vec<Ref>, Span)>>,
    pub tree: Option<SolidTree>,
    /// 2D: the largest triangle area allowed in its mesh.
    pub area: Option<Box<Number>>,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryDef {
    pub name: Name,
    pub faces: Option<(Vec<Ref>, Span)>,
    pub edges: Option<(Vec<Ref>, Span)>,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Document {
    /// 2 or 3 (the default).
    pub dimension: u8,
    pub title: Option<String>,
    pub parameters: Vec<Parameter>,
    pub basis: Vec<BasisCoordinate>,
    pub coordinate_systems: Vec<CoordinateSystem>,
    pub objects: Vec<Object>,
    pub subdomains: Vec<SubdomainDef>,
    pub boundaries: Vec<BoundaryDef>,
}

/// The carrier of a trimmed surface as written.
#[derive(Debug, Clone, PartialEq)]
pub enum CarrierSpec {
    /// Rows of control points (rows along u, nodes along v).
    Bezier { rows: Vec<Vec<PointSpec>> },
    Cone {
        bottom_radius: Option<Number>,
        top_radius: Option<Number>,
        length: Option<Number>,
        from_angle: Option<Number>,
        to_angle: Option<Number>,
    },
    /// Radius; latitudes and angles (from, to), degrees.
    Sphere {
        radius: Option<Number>,
        latitudes: [Option<Number>; 2],
        angles: [Option<Number>; 2],
    },
    /// Major and minor radii; tube angles and angles (from, to), degrees.
    Torus {
        radii: [Option<Number>; 2],
        tube: [Option<Number>; 2],
        angles: [Option<Number>; 2],
    },
    /// x, y, z, then u_min, u_max, v_min, v_max.
    Expressions {
        xyz: [Option<Number>; 3],
        rect: [Option<Number>; 4],
    },
    /// Paper 003's 9-point patch with a `<trim>`: rows A, B, C (v = 0, ½, 1)
    /// of three points (u = 0, ½, 1).
    Patch9 { rows: Vec<Vec<PointSpec>> },
}

/// `<trim equation="F" material="positive|negative"/>`.
#[derive(Debug, Clone, PartialEq)]
pub struct TrimSpec {
    pub equation: Option<Number>,
    /// An R-function tree is the trim (lowered with the implicit solids).
    pub tree: bool,
    pub negative: bool,
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq)]
pub struct TrimmedSpec {
    pub carrier: CarrierSpec,
    pub trim: Option<TrimSpec>,
}
