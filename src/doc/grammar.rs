//! The structure of geomc's XML format, as data: which elements exist where,
//! their attributes and their children. The structural checker walks it, and a
//! test compares it with `schema/geomc.xsd` so the two cannot drift apart.

/// What an attribute holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AttrKind {
    /// A number or an expression over parameters and basis coordinates.
    Expr,
    /// The name this element defines.
    Name,
    /// One reference to a named object (`ref`, `point`, `cs`, `surface`, …).
    Ref,
    /// Whitespace-separated references.
    RefList,
    /// Free text (a description, a material name).
    Text,
    /// One of a fixed set of words.
    Enum(&'static [&'static str]),
}

#[derive(Debug, Clone, Copy)]
pub struct Attr {
    pub name: &'static str,
    pub required: bool,
    pub kind: AttrKind,
}

/// A child element as it may occur in its parent.
#[derive(Debug, Clone, Copy)]
pub struct Child {
    pub rule: &'static Rule,
    pub min: u32,
    /// `None` = unbounded.
    pub max: Option<u32>,
}

/// How an element's children are arranged (the XSD particle it maps to).
#[derive(Debug, Clone, Copy)]
pub enum Content {
    /// No children.
    Empty,
    /// `xs:all`: each child at most once, in any order.
    All(&'static [Child]),
    /// `xs:sequence`: children in this order, each within its counts.
    Sequence(&'static [Child]),
    /// `xs:choice minOccurs=min maxOccurs=max` over single elements: any of
    /// them, in any order, `min..=max` children in all.
    Choice {
        options: &'static [&'static Rule],
        min: u32,
        max: Option<u32>,
    },
    /// `xs:choice` between sequences: exactly one form, each form a sequence.
    Forms(&'static [&'static [Child]]),
}

/// One element declaration in one context.
#[derive(Debug)]
pub struct Rule {
    pub name: &'static str,
    pub attrs: &'static [Attr],
    /// Any further attribute (`xs:anyAttribute`), as basis coordinate values have.
    pub any_attrs: bool,
    pub content: Content,
}

/// Whether two names are equal, comparing the length, the address (the
/// structure check compares the grammar's own strings) and the first byte
/// before calling `memcmp`: most names compared are different ones, and
/// `memcmp` was 3% of the front end's instructions.
#[inline]
pub(crate) fn same_name(a: &str, b: &str) -> bool {
    a.len() == b.len()
        && (std::ptr::eq(a.as_ptr(), b.as_ptr())
            || (a.as_bytes().first() == b.as_bytes().first() && (a.len() < 2 || a == b)))
}

impl Rule {
    pub fn attr(&self, name: &str) -> Option<&'static Attr> {
        self.attrs.iter().find(|a| same_name(a.name, name))
    }

    /// Every child rule this element may contain, in declaration order.
    pub fn child_rules(&self) -> Vec<&'static Rule> {
        match self.content {
            Content::Empty => Vec::new(),
            Content::All(children) | Content::Sequence(children) => {
                children.iter().map(|c| c.rule).collect()
            }
            Content::Choice { options, .. } => options.to_vec(),
            Content::Forms(forms) => {
                let mut out: Vec<&'static Rule> = Vec::new();
                for child in forms.iter().flat_map(|f| f.iter()) {
                    if !out.iter().any(|r| r.name == child.rule.name) {
                        out.push(child.rule);
                    }
                }
                out
            }
        }
    }

    /// The rule of a child named `name`: the first in [`Rule::child_rules`]'
    /// order, found without making that list (called for every element).
    pub fn child_rule(&self, name: &str) -> Option<&'static Rule> {
        match self.content {
            Content::Empty => None,
            Content::All(children) | Content::Sequence(children) => children
                .iter()
                .map(|c| c.rule)
                .find(|r| same_name(r.name, name)),
            // The root's forty options: looked up twice per top-level element.
            Content::Choice { .. } if std::ptr::eq(self, &GEOMETRY) => top_level_index().find(name),
            Content::Choice { options, .. } => {
                options.iter().copied().find(|r| same_name(r.name, name))
            }
            Content::Forms(forms) => forms
                .iter()
                .flat_map(|f| f.iter())
                .map(|c| c.rule)
                .find(|r| same_name(r.name, name)),
        }
    }
}

/// The options of [`GEOMETRY`] by name: open addressing over a hash of a
/// name's length and three of its bytes, each slot the option's index + 1
/// (0: empty). A name's first option wins, as a search in order finds it.
struct OptionIndex {
    options: &'static [&'static Rule],
    slots: [u8; OptionIndex::SLOTS],
}

impl OptionIndex {
    const SLOTS: usize = 256;

    fn new(options: &'static [&'static Rule]) -> OptionIndex {
        let mut index = OptionIndex {
            options,
            slots: [0; OptionIndex::SLOTS],
        };
        for (i, rule) in options.iter().enumerate().take(OptionIndex::SLOTS / 2) {
            if index.find(rule.name).is_some() {
                continue;
            }
            let mut slot = OptionIndex::hash(rule.name);
            while index.slots[slot] != 0 {
                slot = (slot + 1) % OptionIndex::SLOTS;
            }
            index.slots[slot] = (i + 1) as u8;
        }
        index
    }

    fn hash(name: &str) -> usize {
        let bytes = name.as_bytes();
        let byte = |i: usize| u64::from(bytes.get(i).copied().unwrap_or(0));
        let last = bytes.len().saturating_sub(1);
        let key = bytes.len() as u64 | byte(0) << 8 | byte(last) << 16 | byte(last / 2) << 24;
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 56) as usize
    }

    fn find(&self, name: &str) -> Option<&'static Rule> {
        let mut slot = OptionIndex::hash(name);
        loop {
            let option = usize::from(*self.slots.get(slot)?);
            let rule = *self.options.get(option.checked_sub(1)?)?;
            if same_name(rule.name, name) {
                return Some(rule);
            }
            slot = (slot + 1) % OptionIndex::SLOTS;
        }
    }
}

fn top_level_index() -> &'static OptionIndex {
    static INDEX: std::sync::OnceLock<OptionIndex> = std::sync::OnceLock::new();
    INDEX.get_or_init(|| match GEOMETRY.content {
        Content::Choice { options, .. } => OptionIndex::new(options),
        _ => OptionIndex::new(&[]),
    })
}

const fn req(name: &'static str, kind: AttrKind) -> Attr {
    Attr {
        name,
        required: true,
        kind,
    }
}
const fn opt(name: &'static str, kind: AttrKind) -> Attr {
    Attr {
        name,
        required: false,
        kind,
    }
}
const fn one(rule: &'static Rule) -> Child {
    Child {
        rule,
        min: 1,
        max: Some(1),
    }
}
const fn maybe(rule: &'static Rule) -> Child {
    Child {
        rule,
        min: 0,
        max: Some(1),
    }
}
const fn exactly(rule: &'static Rule, n: u32) -> Child {
    Child {
        rule,
        min: n,
        max: Some(n),
    }
}
const fn many(rule: &'static Rule, min: u32) -> Child {
    Child {
        rule,
        min,
        max: None,
    }
}
const fn leaf(name: &'static str, attrs: &'static [Attr]) -> Rule {
    Rule {
        name,
        attrs,
        any_attrs: false,
        content: Content::Empty,
    }
}

use AttrKind::{Expr, Name, Ref, RefList, Text};

// ---- shared leaf shapes ----

/// A point given by coordinates (any of x, y, z) or by reference to a named point.
const POINT_ATTRS: &[Attr] = &[
    opt("x", Expr),
    opt("y", Expr),
    opt("z", Expr),
    opt("point", Ref),
];
/// A vector (normal, axis, rotation angles, semi-axes): missing components are 0.
const VECTOR_ATTRS: &[Attr] = &[opt("x", Expr), opt("y", Expr), opt("z", Expr)];
const VALUE_ATTRS: &[Attr] = &[req("value", Expr)];
const NAMED: &[Attr] = &[req("name", Name), opt("cs", Ref)];

pub static CENTER: Rule = leaf("center", POINT_ATTRS);
pub static BASE_POINT: Rule = leaf("base_point", POINT_ATTRS);
pub static VERTEX_POINT: Rule = leaf("vertex", POINT_ATTRS);
pub static FIRST_POINT: Rule = leaf("first_point", POINT_ATTRS);
pub static SECOND_POINT: Rule = leaf("second_point", POINT_ATTRS);
pub static BOTTOM_CENTER: Rule = leaf("bottom_center", POINT_ATTRS);
pub static TOP_CENTER: Rule = leaf("top_center", POINT_ATTRS);
pub static BEGIN_POINT: Rule = leaf("begin_point", POINT_ATTRS);
pub static END_POINT: Rule = leaf("end_point", POINT_ATTRS);
pub static RADIUS_VERTEX: Rule = leaf("radius_vertex", POINT_ATTRS);
pub static ORIGIN: Rule = leaf("origin", POINT_ATTRS);
pub static APEX: Rule = leaf("apex", POINT_ATTRS);
pub static NEAR: Rule = leaf("near", POINT_ATTRS);
pub static POINT_A: Rule = leaf("point_a", POINT_ATTRS);
pub static POINT_B: Rule = leaf("point_b", POINT_ATTRS);
pub static POINT_C: Rule = leaf("point_c", POINT_ATTRS);
pub static POINT_D: Rule = leaf("point_d", POINT_ATTRS);

pub static NORMAL: Rule = leaf("normal", VECTOR_ATTRS);
pub static AXIS: Rule = leaf("axis", VECTOR_ATTRS);
pub static ROTATION: Rule = leaf("rotation", VECTOR_ATTRS);
pub static SEMI_AXES: Rule = leaf("semi_axes", VECTOR_ATTRS);

pub static RADIUS: Rule = leaf("radius", VALUE_ATTRS);
pub static BOTTOM_RADIUS: Rule = leaf("bottom_radius", VALUE_ATTRS);
pub static TOP_RADIUS: Rule = leaf("top_radius", VALUE_ATTRS);
pub static MAJOR_RADIUS: Rule = leaf("major_radius", VALUE_ATTRS);
pub static MINOR_RADIUS: Rule = leaf("minor_radius", VALUE_ATTRS);
pub static HALF_ANGLE: Rule = leaf("half_angle", VALUE_ATTRS);

// ---- parameters and basis coordinates ----

pub static PARAMETER: Rule = leaf(
    "parameter",
    &[
        req("name", Name),
        req("value", Expr),
        opt("description", Text),
    ],
);
pub static PARAMETERS: Rule = Rule {
    name: "parameters",
    attrs: &[],
    any_attrs: false,
    content: Content::Choice {
        options: &[&PARAMETER],
        min: 0,
        max: None,
    },
};
/// `<value x1='1' x2='10'/>`: every attribute defines a basis coordinate.
pub static BASIS_VALUE: Rule = Rule {
    name: "value",
    attrs: &[],
    any_attrs: true,
    content: Content::Empty,
};
pub static COORDINATE: Rule = Rule {
    name: "coordinate",
    attrs: &[req("name", AttrKind::Enum(&["X", "Y", "Z"]))],
    any_attrs: false,
    content: Content::Sequence(&[many(&BASIS_VALUE, 1)]),
};
pub static BASIS_COORDINATE: Rule = Rule {
    name: "basis_coordinate",
    attrs: &[],
    any_attrs: false,
    content: Content::Choice {
        options: &[&COORDINATE],
        min: 1,
        max: None,
    },
};
pub static COORDINATE_SYSTEM: Rule = Rule {
    name: "coordinate_system",
    attrs: NAMED,
    any_attrs: false,
    content: Content::All(&[maybe(&ORIGIN), maybe(&ROTATION)]),
};

// ---- paper 000's primitives and the rest of its kernel ----

pub static POINT_VALUE: Rule = leaf("value", VECTOR_ATTRS);
pub static POINT: Rule = Rule {
    name: "point",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Sequence(&[many(&POINT_VALUE, 1)]),
};
pub static ELLIPSE: Rule = Rule {
    name: "ellipse",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Sequence(&[one(&CENTER), exactly(&RADIUS_VERTEX, 2)]),
};
pub static CIRCLE: Rule = Rule {
    name: "circle",
    attrs: NAMED,
    any_attrs: false,
    content: Content::All(&[one(&CENTER), one(&RADIUS)]),
};
pub static TRIANGLE: Rule = Rule {
    name: "triangle",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Sequence(&[exactly(&VERTEX_POINT, 3)]),
};
pub static PARALLELOGRAM: Rule = Rule {
    name: "parallelogram",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Sequence(&[one(&BASE_POINT), exactly(&VERTEX_POINT, 2)]),
};
pub static POLYGON: Rule = Rule {
    name: "polygon",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Sequence(&[many(&VERTEX_POINT, 3)]),
};
pub static RECTANGLE: Rule = Rule {
    name: "rectangle",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Sequence(&[one(&FIRST_POINT), one(&SECOND_POINT)]),
};
pub static REGULAR_POLYGON: Rule = Rule {
    name: "regular_polygon",
    attrs: &[req("name", Name), opt("cs", Ref), req("sides", Expr)],
    any_attrs: false,
    content: Content::All(&[one(&CENTER), one(&RADIUS)]),
};
pub static POLY_LINE_SEGMENT: Rule = Rule {
    name: "line",
    attrs: &[],
    any_attrs: false,
    content: Content::Sequence(&[one(&BEGIN_POINT), one(&END_POINT)]),
};
pub static POLY_LINE: Rule = Rule {
    name: "poly_line",
    attrs: &[
        req("name", Name),
        opt("cs", Ref),
        opt("crack", AttrKind::Enum(&["true", "false"])),
    ],
    any_attrs: false,
    content: Content::Sequence(&[many(&POLY_LINE_SEGMENT, 1)]),
};
pub static TRUNCATED_CONE: Rule = Rule {
    name: "truncated_cone",
    attrs: NAMED,
    any_attrs: false,
    content: Content::All(&[
        one(&BOTTOM_RADIUS),
        maybe(&TOP_RADIUS),
        one(&BOTTOM_CENTER),
        one(&TOP_CENTER),
    ]),
};
pub static PARALLELEPIPED: Rule = Rule {
    name: "parallelepiped",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Forms(&[
        &[one(&BASE_POINT), exactly(&VERTEX_POINT, 3)],
        &[one(&FIRST_POINT), one(&SECOND_POINT)],
        // Paper 003's point equation M = Au + Bv + Cw + D(1 − u − v − w).
        &[one(&POINT_A), one(&POINT_B), one(&POINT_C), one(&POINT_D)],
    ]),
};
pub static SPHERE: Rule = Rule {
    name: "sphere",
    attrs: NAMED,
    any_attrs: false,
    content: Content::All(&[one(&CENTER), one(&RADIUS)]),
};
pub static ELLIPSOID: Rule = Rule {
    name: "ellipsoid",
    attrs: NAMED,
    any_attrs: false,
    content: Content::All(&[one(&CENTER), one(&SEMI_AXES)]),
};
pub static TORUS: Rule = Rule {
    name: "torus",
    attrs: NAMED,
    any_attrs: false,
    content: Content::All(&[
        one(&CENTER),
        one(&MAJOR_RADIUS),
        one(&MINOR_RADIUS),
        maybe(&AXIS),
    ]),
};
pub static PLANE: Rule = Rule {
    name: "plane",
    attrs: NAMED,
    any_attrs: false,
    content: Content::All(&[one(&BASE_POINT), one(&NORMAL)]),
};

// ---- point calculus (paper 003) ----

/// The straight segment M = A·ū + B·u.
pub static SEGMENT: Rule = Rule {
    name: "segment",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Sequence(&[one(&POINT_A), one(&POINT_B)]),
};
/// The conic arc's "engineering discriminant" k = CK/CT, 0 < k < 1.
pub static DISCRIMINANT: Rule = leaf("discriminant", VALUE_ATTRS);
/// The arc from A to B whose end tangents meet at C, shaped by k.
pub static CONIC_ARC: Rule = Rule {
    name: "conic_arc",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Sequence(&[
        one(&POINT_A),
        one(&POINT_B),
        one(&POINT_C),
        one(&DISCRIMINANT),
    ]),
};
/// The cubic arc of the Desargues configuration, from A to D.
pub static DESARGUES_ARC: Rule = Rule {
    name: "desargues_arc",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Sequence(&[one(&POINT_A), one(&POINT_B), one(&POINT_C), one(&POINT_D)]),
};
pub static PATCH_NODE: Rule = leaf("node", POINT_ATTRS);
pub static PATCH_ROW: Rule = Rule {
    name: "row",
    attrs: &[],
    any_attrs: false,
    content: Content::Sequence(&[exactly(&PATCH_NODE, 3)]),
};
/// The 9-point parabolic patch: rows A, B, C of three points each; with a
/// `<trim>` it is a trimmed parametric surface (paper 002).
pub static PATCH9: Rule = Rule {
    name: "patch9",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Sequence(&[exactly(&PATCH_ROW, 3), maybe(&TRIM)]),
};

// ---- trimmed parametric surfaces (paper 002) ----

/// Where the surface keeps material: F(x, y, z) ≥ 0 (`positive`, the
/// default) or ≤ 0 (`negative`), F in global coordinates, given by
/// `equation=` or by one R-function tree (as in `<rfunction>`).
pub static TRIM: Rule = Rule {
    name: "trim",
    attrs: &[
        opt("equation", Expr),
        opt("material", AttrKind::Enum(&["positive", "negative"])),
    ],
    any_attrs: false,
    content: Content::Choice {
        options: &R_TREE,
        min: 0,
        max: Some(1),
    },
};
pub static BEZIER_NODE: Rule = leaf("node", POINT_ATTRS);
pub static BEZIER_ROW: Rule = Rule {
    name: "row",
    attrs: &[],
    any_attrs: false,
    content: Content::Sequence(&[many(&BEZIER_NODE, 2)]),
};
/// A tensor-product Bezier surface: rows along u, nodes along v.
pub static BEZIER_SURFACE: Rule = Rule {
    name: "bezier_surface",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Sequence(&[many(&BEZIER_ROW, 2), maybe(&TRIM)]),
};
/// Paper 002's truncated cone about the local y axis (angles in degrees).
pub static CONE_SURFACE: Rule = Rule {
    name: "cone_surface",
    attrs: &[
        req("name", Name),
        opt("cs", Ref),
        req("bottom_radius", Expr),
        req("top_radius", Expr),
        req("length", Expr),
        opt("from_angle", Expr),
        opt("to_angle", Expr),
    ],
    any_attrs: false,
    content: Content::Sequence(&[maybe(&TRIM)]),
};
/// x(u, v), y(u, v), z(u, v) over [u_min, u_max] × [v_min, v_max].
pub static PARAMETRIC_SURFACE: Rule = Rule {
    name: "parametric_surface",
    attrs: &[
        req("name", Name),
        opt("cs", Ref),
        req("x", Expr),
        req("y", Expr),
        req("z", Expr),
        req("u_min", Expr),
        req("u_max", Expr),
        req("v_min", Expr),
        req("v_max", Expr),
    ],
    any_attrs: false,
    content: Content::Sequence(&[maybe(&TRIM)]),
};

/// A sphere patch about the local origin: latitude u from the local xz
/// plane towards +y, longitude v about the local y axis (degrees). A
/// latitude of ±90° is a pole (meshed as one vertex).
pub static SPHERE_SURFACE: Rule = Rule {
    name: "sphere_surface",
    attrs: &[
        req("name", Name),
        opt("cs", Ref),
        req("radius", Expr),
        req("from_latitude", Expr),
        req("to_latitude", Expr),
        opt("from_angle", Expr),
        opt("to_angle", Expr),
    ],
    any_attrs: false,
    content: Content::Sequence(&[maybe(&TRIM)]),
};
/// A torus patch about the local y axis: tube angle u, angle v about the
/// axis (degrees); less than a full turn of the tube.
pub static TORUS_SURFACE: Rule = Rule {
    name: "torus_surface",
    attrs: &[
        req("name", Name),
        opt("cs", Ref),
        req("major_radius", Expr),
        req("minor_radius", Expr),
        req("from_tube_angle", Expr),
        req("to_tube_angle", Expr),
        opt("from_angle", Expr),
        opt("to_angle", Expr),
    ],
    any_attrs: false,
    content: Content::Sequence(&[maybe(&TRIM)]),
};

// ---- transforms and replication ----

pub static SHIFT: Rule = leaf("shift", VECTOR_ATTRS);
/// Rotation angles in degrees about the x, y, z axes through `center` (default the origin).
pub static ROTATE: Rule = leaf(
    "rotate",
    &[
        opt("x", Expr),
        opt("y", Expr),
        opt("z", Expr),
        opt("center", Ref),
    ],
);
pub static SCALE: Rule = leaf(
    "scale",
    &[
        opt("x", Expr),
        opt("y", Expr),
        opt("z", Expr),
        opt("factor", Expr),
    ],
);
const STEPS: &[&Rule] = &[&SHIFT, &ROTATE, &SCALE];
pub static TRANSFORM: Rule = Rule {
    name: "transform",
    attrs: &[req("name", Name), req("ref", Ref)],
    any_attrs: false,
    content: Content::Choice {
        options: STEPS,
        min: 1,
        max: None,
    },
};
pub static REPLICATE: Rule = Rule {
    name: "replicate",
    attrs: &[req("name", Name), req("ref", Ref), req("count", Expr)],
    any_attrs: false,
    content: Content::Choice {
        options: STEPS,
        min: 1,
        max: None,
    },
};

// ---- explicit topology ----

pub static SURFACE_PLANE: Rule = Rule {
    name: "plane",
    attrs: &[],
    any_attrs: false,
    content: Content::All(&[one(&BASE_POINT), one(&NORMAL)]),
};
pub static SURFACE_SPHERE: Rule = Rule {
    name: "sphere",
    attrs: &[],
    any_attrs: false,
    content: Content::All(&[one(&CENTER), one(&RADIUS)]),
};
pub static SURFACE_CYLINDER: Rule = Rule {
    name: "cylinder",
    attrs: &[],
    any_attrs: false,
    content: Content::All(&[one(&BASE_POINT), one(&AXIS), one(&RADIUS)]),
};
pub static SURFACE_CONE: Rule = Rule {
    name: "cone",
    attrs: &[],
    any_attrs: false,
    content: Content::All(&[one(&APEX), one(&AXIS), one(&HALF_ANGLE)]),
};
/// xx·x² + yy·y² + zz·z² + xy·xy + yz·yz + zx·zx + x·x + y·y + z·z + c = 0.
pub static SURFACE_QUADRIC: Rule = leaf(
    "quadric",
    &[
        opt("xx", Expr),
        opt("yy", Expr),
        opt("zz", Expr),
        opt("xy", Expr),
        opt("yz", Expr),
        opt("zx", Expr),
        opt("x", Expr),
        opt("y", Expr),
        opt("z", Expr),
        opt("c", Expr),
    ],
);
/// S(x, y, z) = 0 for an expression in the free variables x, y, z.
pub static SURFACE_IMPLICIT: Rule = leaf("implicit", &[req("equation", Expr)]);
pub static SURFACE: Rule = Rule {
    name: "surface",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Forms(&[
        &[one(&SURFACE_PLANE)],
        &[one(&SURFACE_SPHERE)],
        &[one(&SURFACE_CYLINDER)],
        &[one(&SURFACE_CONE)],
        &[one(&SURFACE_QUADRIC)],
        &[one(&SURFACE_IMPLICIT)],
    ]),
};

/// The straight segment between an edge's two vertices.
pub static LINE_STRAIGHT: Rule = leaf("straight", &[]);
/// A circular arc about `center`, counter-clockwise about `normal` (default +z).
pub static LINE_CIRCLE_ARC: Rule = Rule {
    name: "circle_arc",
    attrs: &[],
    any_attrs: false,
    content: Content::All(&[one(&CENTER), maybe(&NORMAL)]),
};
/// An elliptic arc: centre and the ends of the two semi-axes, as `ellipse`.
pub static LINE_ELLIPSE_ARC: Rule = Rule {
    name: "ellipse_arc",
    attrs: &[],
    any_attrs: false,
    content: Content::Sequence(&[one(&CENTER), exactly(&RADIUS_VERTEX, 2)]),
};
/// The intersection curve of two surfaces.
pub static LINE_INTERSECTION: Rule = leaf("intersection", &[req("surfaces", RefList)]);
pub static LINE: Rule = Rule {
    name: "line",
    attrs: NAMED,
    any_attrs: false,
    content: Content::Forms(&[
        &[one(&LINE_STRAIGHT)],
        &[one(&LINE_CIRCLE_ARC)],
        &[one(&LINE_ELLIPSE_ARC)],
        &[one(&LINE_INTERSECTION)],
    ]),
};

/// A vertex as the intersection of three surfaces or two lines, found by
/// Newton's method from the `near` hint.
pub static VERTEX_INTERSECTION: Rule = Rule {
    name: "intersection",
    attrs: &[opt("surfaces", RefList), opt("lines", RefList)],
    any_attrs: false,
    content: Content::Sequence(&[one(&NEAR)]),
};
pub static VERTEX: Rule = Rule {
    name: "vertex",
    attrs: &[
        req("name", Name),
        opt("cs", Ref),
        opt("x", Expr),
        opt("y", Expr),
        opt("z", Expr),
        opt("point", Ref),
    ],
    any_attrs: false,
    content: Content::Sequence(&[maybe(&VERTEX_INTERSECTION)]),
};
pub static EDGE: Rule = leaf(
    "edge",
    &[
        req("name", Name),
        opt("line", Ref),
        req("begin", Ref),
        req("end", Ref),
    ],
);
pub static LOOP: Rule = leaf("loop", &[req("edges", RefList)]);
pub static FACE: Rule = Rule {
    name: "face",
    attrs: &[
        req("name", Name),
        req("surface", Ref),
        opt("edges", RefList),
    ],
    any_attrs: false,
    content: Content::Sequence(&[many(&LOOP, 0)]),
};

// ---- subdomains and boundaries ----

pub static SOLID: Rule = leaf("solid", &[req("ref", Ref)]);
static SOLID_TREE: [&Rule; 4] = [&SOLID, &UNION, &INTERSECTION, &DIFFERENCE];
pub static UNION: Rule = Rule {
    name: "union",
    attrs: &[],
    any_attrs: false,
    content: Content::Choice {
        options: &SOLID_TREE,
        min: 2,
        max: None,
    },
};
pub static INTERSECTION: Rule = Rule {
    name: "intersection",
    attrs: &[],
    any_attrs: false,
    content: Content::Choice {
        options: &SOLID_TREE,
        min: 2,
        max: None,
    },
};
/// The first operand minus all the others.
pub static DIFFERENCE: Rule = Rule {
    name: "difference",
    attrs: &[],
    any_attrs: false,
    content: Content::Choice {
        options: &SOLID_TREE,
        min: 2,
        max: None,
    },
};
pub static SUBDOMAIN: Rule = Rule {
    name: "subdomain",
    attrs: &[
        req("name", Name),
        opt("faces", RefList),
        opt("material", Text),
        opt("area", Expr),
    ],
    any_attrs: false,
    content: Content::Choice {
        options: &SOLID_TREE,
        min: 0,
        max: Some(1),
    },
};
pub static BOUNDARY: Rule = leaf(
    "boundary",
    &[
        req("name", Name),
        opt("faces", RefList),
        opt("edges", RefList),
    ],
);

// ---- implicit solids (issue 5): <rfunction>, <function>, <level_surface>, <density_volume> ----

/// Paper 001's Geom fields as attributes: bounding box, cells per axis, optimisation.
macro_rules! geom_attrs {
    ($($extra:expr),* $(,)?) => {
        &[
            $($extra,)*
            opt("x_min", Expr),
            opt("x_max", Expr),
            opt("y_min", Expr),
            opt("y_max", Expr),
            opt("z_min", Expr),
            opt("z_max", Expr),
            opt("nx", Expr),
            opt("ny", Expr),
            opt("nz", Expr),
            opt("optiterations", Expr),
        ]
    };
}

pub static F_HALF_PLANE: Rule = leaf(
    "half_plane",
    &[
        req("x1", Expr),
        req("y1", Expr),
        req("x2", Expr),
        req("y2", Expr),
    ],
);
pub static F_HALF_SPACE: Rule = leaf(
    "half_space",
    &[
        req("xp", Expr),
        req("yp", Expr),
        req("zp", Expr),
        req("nx", Expr),
        req("ny", Expr),
        req("nz", Expr),
    ],
);
pub static F_ELLIPSE: Rule = leaf(
    "ellipse",
    &[
        req("x0", Expr),
        req("y0", Expr),
        req("a", Expr),
        req("b", Expr),
    ],
);
pub static F_DISK: Rule = leaf("disk", &[req("r", Expr), req("x0", Expr), req("y0", Expr)]);
pub static F_ELLIPSOID: Rule = leaf(
    "ellipsoid",
    &[
        req("x0", Expr),
        req("y0", Expr),
        req("z0", Expr),
        req("a", Expr),
        req("b", Expr),
        req("c", Expr),
    ],
);
pub static F_BALL: Rule = leaf(
    "ball",
    &[
        req("r", Expr),
        req("x0", Expr),
        req("y0", Expr),
        req("z0", Expr),
    ],
);
pub static F_REGULAR_POLYGON: Rule = leaf(
    "regular_polygon",
    &[
        req("r", Expr),
        req("x0", Expr),
        req("y0", Expr),
        req("n", Expr),
    ],
);
pub static F_PARALLELOGRAM: Rule = leaf(
    "parallelogram",
    &[
        req("x0", Expr),
        req("y0", Expr),
        req("a", Expr),
        req("h", Expr),
        req("alpha", Expr),
    ],
);
pub static F_RECTANGLE: Rule = leaf(
    "rectangle",
    &[
        req("x0", Expr),
        req("y0", Expr),
        req("w", Expr),
        req("h", Expr),
    ],
);
pub static F_PARALLELEPIPED: Rule = leaf(
    "parallelepiped",
    &[
        req("x0", Expr),
        req("y0", Expr),
        req("z0", Expr),
        req("a", Expr),
        req("h", Expr),
        req("d", Expr),
        req("alpha", Expr),
        req("beta", Expr),
    ],
);
pub static F_BOX: Rule = leaf(
    "box",
    &[
        req("x0", Expr),
        req("y0", Expr),
        req("z0", Expr),
        req("w", Expr),
        req("h", Expr),
        req("d", Expr),
    ],
);
pub static F_ROUNDED_RECTANGLE: Rule = leaf(
    "rounded_rectangle",
    &[
        req("x0", Expr),
        req("y0", Expr),
        req("w", Expr),
        req("h", Expr),
        req("r", Expr),
    ],
);
pub static F_SECTOR: Rule = leaf(
    "sector",
    &[
        req("x0", Expr),
        req("y0", Expr),
        req("r", Expr),
        req("angle1", Expr),
        req("angle2", Expr),
    ],
);
pub static F_VERTEX: Rule = leaf("vertex", &[req("x", Expr), req("y", Expr)]);
/// Vertices clockwise, as paper 001's (9).
pub static F_CONVEX_POLYGON: Rule = Rule {
    name: "convex_polygon",
    attrs: &[],
    any_attrs: false,
    content: Content::Sequence(&[many(&F_VERTEX, 3)]),
};
pub static F_FORMULA: Rule = leaf("formula", &[req("value", Expr)]);
/// A call of a <function>: every other attribute is a named argument.
pub static F_CALL: Rule = Rule {
    name: "call",
    attrs: &[req("function", Ref)],
    any_attrs: true,
    content: Content::Empty,
};
/// Paper 001's language inside the XML: a program in an attribute or a file.
pub static F_RFS: Rule = leaf("rfs", &[opt("file", Text), opt("program", Text)]);
const fn r_operation(name: &'static str, min: u32, max: Option<u32>) -> Rule {
    Rule {
        name,
        attrs: &[],
        any_attrs: false,
        content: Content::Choice {
            options: &R_TREE,
            min,
            max,
        },
    }
}
pub static F_UNION: Rule = r_operation("union", 1, None);
pub static F_INTERSECTION: Rule = r_operation("intersection", 1, None);
/// The first operand minus all the others.
pub static F_DIFFERENCE: Rule = r_operation("difference", 2, None);
pub static F_NOT: Rule = r_operation("not", 1, Some(1));
/// The operands of an R-function tree.
pub static R_TREE: [&Rule; 21] = [
    &F_UNION,
    &F_INTERSECTION,
    &F_DIFFERENCE,
    &F_NOT,
    &F_FORMULA,
    &F_CALL,
    &F_RFS,
    &F_CONVEX_POLYGON,
    &F_HALF_PLANE,
    &F_HALF_SPACE,
    &F_ELLIPSE,
    &F_DISK,
    &F_ELLIPSOID,
    &F_BALL,
    &F_REGULAR_POLYGON,
    &F_PARALLELOGRAM,
    &F_RECTANGLE,
    &F_PARALLELEPIPED,
    &F_BOX,
    &F_ROUNDED_RECTANGLE,
    &F_SECTOR,
];
pub static RFUNCTION: Rule = Rule {
    name: "rfunction",
    attrs: geom_attrs![
        req("name", Name),
        opt("dimension", AttrKind::Enum(&["3"])),
        opt("rsystem", AttrKind::Enum(&["rvachev", "minmax", "alpha"])),
        opt("alpha", Expr),
    ],
    any_attrs: false,
    content: Content::Choice {
        options: &R_TREE,
        min: 1,
        max: Some(1),
    },
};
pub static FUNCTION: Rule = Rule {
    name: "function",
    attrs: &[req("name", Name), req("args", Text)],
    any_attrs: false,
    content: Content::Choice {
        options: &R_TREE,
        min: 1,
        max: Some(1),
    },
};
pub static LEVEL_SURFACE: Rule = leaf(
    "level_surface",
    geom_attrs![
        req("name", Name),
        req("expression", Expr),
        opt("level", Expr),
        opt("variables", Text),
    ],
);
pub static DENSITY_VOLUME: Rule = leaf(
    "density_volume",
    &[
        req("name", Name),
        req("file", Text),
        req("level", Expr),
        opt("type", AttrKind::Enum(&["u8", "u16", "i16", "f32"])),
        opt("endian", AttrKind::Enum(&["little", "big"])),
        opt("dims", Text),
        opt("spacing", Text),
        opt("origin", Text),
    ],
);

// ---- the root ----

pub static GEOMETRY: Rule = Rule {
    name: "geometry",
    attrs: &[
        req("version", AttrKind::Enum(&["1"])),
        opt("dimension", AttrKind::Enum(&["2", "3"])),
        opt("name", Text),
    ],
    any_attrs: false,
    content: Content::Choice {
        options: &[
            &PARAMETERS,
            &BASIS_COORDINATE,
            &COORDINATE_SYSTEM,
            &POINT,
            &ELLIPSE,
            &CIRCLE,
            &TRIANGLE,
            &PARALLELOGRAM,
            &POLYGON,
            &RECTANGLE,
            &REGULAR_POLYGON,
            &POLY_LINE,
            &TRUNCATED_CONE,
            &PARALLELEPIPED,
            &SPHERE,
            &ELLIPSOID,
            &TORUS,
            &PLANE,
            &SEGMENT,
            &CONIC_ARC,
            &DESARGUES_ARC,
            &PATCH9,
            &BEZIER_SURFACE,
            &CONE_SURFACE,
            &PARAMETRIC_SURFACE,
            &SPHERE_SURFACE,
            &TORUS_SURFACE,
            &TRANSFORM,
            &REPLICATE,
            &SURFACE,
            &LINE,
            &VERTEX,
            &EDGE,
            &FACE,
            &SUBDOMAIN,
            &BOUNDARY,
            &RFUNCTION,
            &FUNCTION,
            &LEVEL_SURFACE,
            &DENSITY_VOLUME,
        ],
        min: 0,
        max: None,
    },
};

#[cfg(test)]
mod index_tests {
    use super::*;

    #[test]
    fn the_top_level_index_finds_what_a_search_in_order_finds() {
        let Content::Choice { options, .. } = GEOMETRY.content else {
            panic!("the root is a choice")
        };
        let in_order = |name: &str| options.iter().copied().find(|r| r.name == name);
        let mut names: Vec<String> = options.iter().map(|r| r.name.to_string()).collect();
        assert_eq!(names.len(), 40);
        // Near misses of every option: cut, lengthened, recased, one byte changed.
        for option in options {
            let name = option.name;
            names.push(name[..name.len() - 1].to_string());
            names.push(format!("{name}s"));
            names.push(name.to_uppercase());
            names.push(format!("x{}", &name[1..]));
            names.push(format!("{}x", &name[..name.len() - 1]));
        }
        names.extend(["", "a", "geometry", "center", "value"].map(String::from));
        let mut found = 0;
        for name in &names {
            let indexed = GEOMETRY.child_rule(name);
            assert_eq!(indexed.map(|r| r.name), in_order(name).map(|r| r.name));
            assert!(
                indexed
                    .zip(in_order(name))
                    .is_none_or(|(a, b)| std::ptr::eq(a, b)),
                "{name}"
            );
            found += usize::from(indexed.is_some());
        }
        assert!(found >= 40, "{found}");
    }

    #[test]
    fn names_are_the_same_exactly_when_equal() {
        let names = [
            "", "x", "y", "xy", "yx", "point", "points", "pOint", "center", "centre",
        ];
        for a in names {
            for b in names {
                assert_eq!(same_name(a, b), a == b, "{a:?} {b:?}");
            }
        }
    }
}
