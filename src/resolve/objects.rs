//! The object resolver: looks up references (with cycle detection through
//! transforms), evaluates points and vectors in their coordinate systems, and
//! hands each primitive to [`super::shapes`].

use super::ResolvedObject;
use super::geometry::{Geometry, Link};
use super::names::NameTable;
use super::values::{Ctx, Used, Values};
use crate::diag::{Code, Diagnostic, Diagnostics, did_you_mean};
use crate::doc::{Axis, CoordinateSystem, Document, Number, Object, PointSpec, Ref, VectorSpec};
use crate::geom::{Frame, Point3, Vec3};
use foldhash::{HashMap, HashMapExt};

#[derive(Debug, Clone, Copy, PartialEq)]
enum FrameState {
    InProgress,
    Done(Option<Frame>),
}

/// Where an object's resolution is; its geometry is in its
/// [`ResolvedObject`] as soon as it has one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Unresolved,
    InProgress,
    Done,
    /// Resolved on a worker by a resolver of its own (see `resolve_alone`);
    /// its findings are reported when the serial pass first asks for it.
    Alone,
}

/// The resolver's view of the other objects.
enum Objects {
    /// Every object's state: the serial resolver, which resolves a referenced
    /// object on demand (with cycle detection).
    All {
        state: Vec<State>,
        /// What [`Resolver::resolve_all`] gives back, filled in place (a
        /// second list of a hundred thousand geometries, copied from the
        /// states, was fresh memory the main thread faulted in). The names
        /// are left empty: the caller moves the document's in.
        resolved: Vec<ResolvedObject>,
        /// The findings of objects resolved alone, by object index (sorted),
        /// until the serial pass reaches them.
        pending: Vec<(usize, Diagnostics)>,
    },
    /// A worker's resolver of objects that need no other object: set when
    /// one did (its result is then dropped and the serial pass resolves it).
    Alone { needed_another: bool },
}

/// Coordinate-system frames: filled by the serial resolver, read by the
/// workers' once every system is resolved.
enum Frames<'a> {
    Own(HashMap<String, FrameState>),
    Shared(&'a HashMap<String, FrameState>),
}

impl Frames<'_> {
    fn get(&self, name: &str) -> Option<&FrameState> {
        match self {
            Frames::Own(frames) => frames.get(name),
            Frames::Shared(frames) => frames.get(name),
        }
    }
}

pub(super) struct Resolver<'a> {
    pub doc: &'a Document,
    pub names: &'a NameTable<'a>,
    /// Parameter and basis values, fixed before any object is resolved.
    pub values: &'a Values<'a>,
    /// The parameters and basis coordinates this resolver's numbers used.
    pub used: Used,
    /// This resolver's findings, in the order it made them.
    pub diags: Diagnostics,
    tables: &'a Tables<'a>,
    frames: Frames<'a>,
    objects: Objects,
}

/// What a task of the parallel pass gives back: the findings of its objects
/// by index, the names they used, and how many it resolved.
type AloneTask = (Vec<(usize, Diagnostics)>, Used, usize);

/// Objects per task of the parallel pass (each a few microseconds).
const ALONE_CHUNK: usize = 512;

/// The resolver's table of coordinate systems (the first of a repeated
/// name); the objects are looked up in the name table.
pub(super) struct Tables<'a> {
    systems: HashMap<String, &'a CoordinateSystem>,
}

impl<'a> Tables<'a> {
    pub fn build(doc: &'a Document) -> Tables<'a> {
        let mut systems = HashMap::new();
        for cs in &doc.coordinate_systems {
            systems.entry(cs.name.text.clone()).or_insert(cs);
        }
        Tables { systems }
    }
}

impl<'a> Resolver<'a> {
    pub fn new(
        doc: &'a Document,
        names: &'a NameTable<'a>,
        tables: &'a Tables<'a>,
        values: &'a Values<'a>,
    ) -> Self {
        Resolver {
            doc,
            names,
            values,
            used: Used::default(),
            diags: Diagnostics::default(),
            tables,
            frames: Frames::Own(HashMap::new()),
            objects: Objects::All {
                state: vec![State::Unresolved; doc.objects.len()],
                resolved: (doc.objects.iter())
                    .map(|object| ResolvedObject {
                        name: String::new(),
                        span: object.span,
                        geometry: None,
                    })
                    .collect(),
                pending: Vec::new(),
            },
        }
    }

    /// The first object named `name`.
    pub fn by_name_index(&self, name: &str) -> Option<usize> {
        self.names.first_object(name)
    }

    /// The names this resolver used and its findings.
    pub fn finish(self) -> (Used, Diagnostics) {
        (self.used, self.diags)
    }

    /// Resolves every object, as [`Resolver::resolve_serially`] does, with
    /// the objects that need no other object (most of a large file's
    /// primitives) resolved first on the rayon threads; also says how many
    /// were.
    pub fn resolve_all(&mut self) -> (Vec<ResolvedObject>, usize) {
        self.resolve_systems();
        let alone = if self.doc.objects.len() >= 2 * ALONE_CHUNK {
            self.resolve_alone()
        } else {
            0
        };
        (self.resolve_objects(), alone)
    }

    /// Every object resolved on this thread only (the reference the
    /// parallel pass is tested against).
    #[cfg(test)]
    pub fn resolve_serially(&mut self) -> Vec<ResolvedObject> {
        self.resolve_systems();
        self.resolve_objects()
    }

    /// Coordinate systems first, so unused ones are checked too (an origin
    /// given as a named point resolves that object).
    fn resolve_systems(&mut self) {
        let systems: Vec<&CoordinateSystem> = self.doc.coordinate_systems.iter().collect();
        for cs in systems {
            let reference = crate::doc::Ref::to_name(&cs.name.text, cs.name.span);
            self.frame_of(&reference);
        }
    }

    /// Resolves each object not resolved yet on a worker, with a resolver of
    /// its own that shares the frozen values, frames and tables: an object
    /// that needs another object's geometry is left to the serial pass. The
    /// results wait in the states (allocated here, on the calling thread),
    /// their findings in `pending`, until the serial pass reaches them, so
    /// the findings come in the serial order whatever the threads did.
    fn resolve_alone(&mut self) -> usize {
        use rayon::prelude::*;
        let Resolver {
            doc,
            names,
            values,
            used,
            tables,
            frames,
            objects,
            ..
        } = self;
        let Objects::All {
            state,
            resolved,
            pending,
        } = objects
        else {
            return 0;
        };
        let frames = match frames {
            Frames::Own(frames) => &*frames,
            Frames::Shared(frames) => *frames,
        };
        let (doc, names, values, tables) = (*doc, *names, *values, *tables);
        let done: Vec<AloneTask> = (state.par_chunks_mut(ALONE_CHUNK))
            .zip(resolved.par_chunks_mut(ALONE_CHUNK))
            .enumerate()
            .map(|(chunk, (slots, results))| {
                let mut alone = Resolver {
                    doc,
                    names,
                    values,
                    used: Used::default(),
                    diags: Diagnostics::default(),
                    tables,
                    frames: Frames::Shared(frames),
                    objects: Objects::Alone {
                        needed_another: false,
                    },
                };
                let mut found = Vec::new();
                let mut count = 0;
                for (k, (slot, result)) in slots.iter_mut().zip(results).enumerate() {
                    if *slot != State::Unresolved {
                        continue;
                    }
                    let i = chunk * ALONE_CHUNK + k;
                    alone.objects = Objects::Alone {
                        needed_another: false,
                    };
                    let geometry = alone.resolve_object(&doc.objects[i]);
                    let diags = std::mem::take(&mut alone.diags);
                    if let Objects::Alone {
                        needed_another: true,
                    } = alone.objects
                    {
                        // The names it used before are used again by the
                        // serial pass, on the same path: a merge adds none
                        // that the serial resolver would not.
                        continue;
                    }
                    if !diags.items.is_empty() {
                        found.push((i, diags));
                    }
                    *slot = State::Alone;
                    result.geometry = geometry;
                    count += 1;
                }
                (found, alone.used, count)
            })
            .collect();
        let mut total = 0;
        for (found, task_used, count) in done {
            pending.extend(found);
            used.merge(task_used);
            total += count;
        }
        total
    }

    /// Every object resolved once, in document order (a reference may
    /// resolve a later one first); then the resolved objects are moved out
    /// of the resolver (nothing reads them after this: the subdomains' area
    /// limits are plain numbers). Their names are empty.
    fn resolve_objects(&mut self) -> Vec<ResolvedObject> {
        for i in 0..self.doc.objects.len() {
            self.resolve_once(i);
        }
        let Objects::All {
            state, resolved, ..
        } = &mut self.objects
        else {
            return Vec::new();
        };
        *state = Vec::new();
        std::mem::take(resolved)
    }

    /// The geometry of object `i`, resolved once.
    pub fn geometry(&mut self, i: usize) -> Option<Geometry> {
        self.resolve_once(i);
        match &self.objects {
            Objects::All {
                state, resolved, ..
            } => match (state.get(i), resolved.get(i)) {
                (Some(State::Done), Some(object)) => object.geometry.clone(),
                _ => None,
            },
            Objects::Alone { .. } => None,
        }
    }

    /// Resolves object `i` unless it was: its geometry (or `None` after an
    /// error) is then in `state[i]`. A worker's resolver only notes that its
    /// object needs another.
    fn resolve_once(&mut self, i: usize) {
        let state = match &mut self.objects {
            Objects::All { state, pending, .. } => match state.get_mut(i) {
                // Out of range only after `resolve_all` moved the geometries out.
                None | Some(State::Done) => return,
                Some(slot @ State::Alone) => {
                    *slot = State::Done;
                    if let Ok(k) = pending.binary_search_by_key(&i, |(j, _)| *j) {
                        self.diags.extend(std::mem::take(&mut pending[k].1));
                    }
                    return;
                }
                Some(State::InProgress) => {
                    let object = &self.doc.objects[i];
                    self.diags.push(
                        Diagnostic::new(
                            Code::ReferenceCycle,
                            object.name.span,
                            format!(
                                "{} '{}' is defined through itself",
                                object.kind.element(),
                                object.name.text
                            ),
                        )
                        .with_help(
                            "a transform or reference chain leads back to this object; break the chain",
                        ),
                    );
                    // Its geometry stays `None`.
                    state[i] = State::Done;
                    return;
                }
                Some(State::Unresolved) => state,
            },
            Objects::Alone { needed_another } => {
                *needed_another = true;
                return;
            }
        };
        state[i] = State::InProgress;
        let object: &'a Object = &self.doc.objects[i];
        let geometry = self.resolve_object(object);
        let Objects::All {
            state, resolved, ..
        } = &mut self.objects
        else {
            return;
        };
        if state[i] == State::Done {
            // A cycle through it was reported: it stays unresolved.
            return;
        }
        state[i] = State::Done;
        if let Some(object) = resolved.get_mut(i) {
            object.geometry = geometry;
        }
    }

    fn resolve_object(&mut self, object: &'a Object) -> Option<Geometry> {
        let frame = match &object.cs {
            Some(cs) => self.frame_of(cs)?,
            None => Frame::identity(),
        };
        super::shapes::resolve_kind(self, object, &frame)
    }

    /// The frame of a coordinate system, through its parents (cycles reported).
    pub fn frame_of(&mut self, reference: &Ref) -> Option<Frame> {
        let name = reference.name();
        let Some(cs) = self.tables.systems.get(name).copied() else {
            let d = match self.names.kind_of(name) {
                Some(kind) => Diagnostic::new(
                    Code::WrongKind,
                    reference.span,
                    format!("cs=\"{name}\" names a {kind}, not a coordinate system"),
                )
                .with_help("name a <coordinate_system>"),
                None => {
                    let mut d = Diagnostic::new(
                        Code::UndefinedName,
                        reference.span,
                        format!("undefined coordinate system '{name}'"),
                    );
                    d.help = Some(
                        match did_you_mean(name, self.tables.systems.keys().map(String::as_str)) {
                            Some(best) => format!("did you mean '{best}'?"),
                            None => format!("define it with <coordinate_system name=\"{name}\">"),
                        },
                    );
                    d
                }
            };
            self.diags.push(d);
            return None;
        };
        let in_progress = match self.frames.get(name) {
            Some(FrameState::Done(frame)) => return *frame,
            Some(FrameState::InProgress) => true,
            None => false,
        };
        let Frames::Own(frames) = &mut self.frames else {
            // Every system was resolved before the workers started.
            self.needs_another();
            return None;
        };
        if in_progress {
            frames.insert(name.to_string(), FrameState::Done(None));
            self.diags.push(
                Diagnostic::new(
                    Code::ReferenceCycle,
                    cs.name.span,
                    format!("coordinate system '{name}' lies inside itself through its cs= chain"),
                )
                .with_help("remove cs= from one of the systems in the chain"),
            );
            return None;
        }
        frames.insert(name.to_string(), FrameState::InProgress);
        let parent = match &cs.parent {
            Some(p) => self.frame_of(p),
            None => Some(Frame::identity()),
        };
        if let Some(FrameState::Done(None)) = self.frames.get(name) {
            return None;
        }
        let frame = parent.and_then(|parent| {
            // The origin is given in the parent's coordinates (or as a named point).
            let origin = match &cs.origin {
                Some(o) => self.point(o, &parent, false)?,
                None => parent.origin,
            };
            let angles = match &cs.rotation {
                Some(r) => self.numbers3(r)?,
                None => Vec3::zeros(),
            };
            let rotation = Frame::rotation_degrees(angles);
            Some(Frame {
                origin,
                linear: parent.linear * rotation.linear,
            })
        });
        if let Frames::Own(frames) = &mut self.frames {
            frames.insert(name.to_string(), FrameState::Done(frame));
        }
        frame
    }

    /// Notes, on a worker's resolver, that its object needs another object
    /// or system (the serial pass resolves it instead).
    fn needs_another(&mut self) {
        if let Objects::Alone { needed_another } = &mut self.objects {
            *needed_another = true;
        }
    }

    // ---- numbers, points, vectors ----

    pub fn number(&mut self, n: &Number) -> Option<f64> {
        self.values
            .eval(n, Ctx::Any, &mut self.used, &mut self.diags)
    }

    /// A point in global coordinates. `need3` asks for a warning when a 3D
    /// model's single point leaves coordinates out.
    pub fn point(&mut self, spec: &PointSpec, frame: &Frame, need3: bool) -> Option<Point3> {
        if let Some(reference) = &spec.point {
            if spec.x.is_some() || spec.y.is_some() || spec.z.is_some() {
                self.diags.push(
                    Diagnostic::new(
                        Code::ConflictingForms,
                        spec.span,
                        format!(
                            "<{}> gives both coordinates and point=\"{}\"",
                            self.tag(spec),
                            reference.text
                        ),
                    )
                    .with_help("give either x/y/z or point=, not both"),
                );
                return None;
            }
            return self.point_reference(reference, need3);
        }
        if spec.x.is_none() && spec.y.is_none() && spec.z.is_none() {
            self.diags.push(
                Diagnostic::new(
                    Code::MissingAttribute,
                    spec.span,
                    format!("<{}> gives no coordinates", self.tag(spec)),
                )
                .with_help("add x=, y= and z= (or point=\"name\")"),
            );
            return None;
        }
        let local = vector3(
            self.values,
            &mut self.used,
            spec.x.as_ref(),
            spec.y.as_ref(),
            spec.z.as_ref(),
            true,
            &mut self.diags,
        )?;
        let missing_z = spec.z.is_none() && self.doc.dimension == 3;
        if need3 && (spec.x.is_none() || spec.y.is_none() || missing_z) {
            let missing: Vec<&str> = [
                ("x", spec.x.is_none()),
                ("y", spec.y.is_none()),
                ("z", missing_z),
            ]
            .iter()
            .filter(|(_, m)| *m)
            .map(|(n, _)| *n)
            .collect();
            self.diags.push(
                Diagnostic::new(
                    Code::PointValueShape,
                    spec.span,
                    format!(
                        "<{}> gives no {}; taken as 0",
                        self.tag(spec),
                        missing.join(", ")
                    ),
                )
                .with_help("give all three coordinates of a 3D point"),
            );
        }
        Some(frame.to_global(&Point3::from(local)))
    }

    fn tag(&self, spec: &PointSpec) -> String {
        spec.tag.to_string()
    }

    /// A point given by reference: a point set (member), or a vertex.
    fn point_reference(&mut self, reference: &Ref, need3: bool) -> Option<Point3> {
        let i = self.lookup(reference, &["point", "vertex"])?;
        match self.geometry(i)? {
            Geometry::Points { points, partial } => match (reference.index, points.len()) {
                (None, 1) | (Some(1..), _) if reference.index.unwrap_or(1) <= points.len() => {
                    let k = reference.index.unwrap_or(1) - 1;
                    if need3 && partial.get(k).copied().unwrap_or(false) {
                        self.diags.push(
                            Diagnostic::new(
                                Code::PointValueShape,
                                reference.span,
                                format!("'{}' gives fewer than three coordinates (a line or plane in paper 000's sense); the missing ones are taken as 0", reference.text),
                            )
                            .with_help("give the point all three coordinates where a single point is needed"),
                        );
                    }
                    points.get(k).copied()
                }
                (None, n) => {
                    self.diags.push(
                        Diagnostic::new(
                            Code::IndexOutOfRange,
                            reference.span,
                            format!(
                                "point '{}' holds {n} points; say which one",
                                reference.name()
                            ),
                        )
                        .with_help(format!(
                            "write {}[1] … {}[{n}]",
                            reference.name(),
                            reference.name()
                        )),
                    );
                    None
                }
                (Some(k), n) => {
                    self.diags.push(
                        Diagnostic::new(
                            Code::IndexOutOfRange,
                            reference.span,
                            format!(
                                "point '{}' has no member {k}: it holds {n} point{}",
                                reference.name(),
                                if n == 1 { "" } else { "s" }
                            ),
                        )
                        .with_help(format!("use an index from 1 to {n}")),
                    );
                    None
                }
            },
            Geometry::Vertex(p) => Some(p),
            _ => None,
        }
    }

    pub fn vector(&mut self, spec: &VectorSpec, frame: &Frame) -> Option<Vec3> {
        let v = vector3(
            self.values,
            &mut self.used,
            spec.x.as_ref(),
            spec.y.as_ref(),
            spec.z.as_ref(),
            true,
            &mut self.diags,
        )?;
        Some(frame.linear * v)
    }

    /// A vector of plain numbers (angles, scale factors): basis coordinates not allowed.
    pub fn numbers3(&mut self, spec: &VectorSpec) -> Option<Vec3> {
        vector3(
            self.values,
            &mut self.used,
            spec.x.as_ref(),
            spec.y.as_ref(),
            spec.z.as_ref(),
            false,
            &mut self.diags,
        )
    }

    // ---- references ----

    /// Finds the object a reference names, checking that its element is one of
    /// `kinds` (element names as in the format; "*" accepts any object).
    pub fn lookup(&mut self, reference: &Ref, kinds: &[&str]) -> Option<usize> {
        let Some(i) = self.names.first_object(reference.name()) else {
            let d = match self.names.kind_of(reference.name()) {
                Some(kind) => Diagnostic::new(
                    Code::WrongKind,
                    reference.span,
                    format!(
                        "'{}' is {}, but {} is expected here",
                        reference.name(),
                        a(kind),
                        describe_kinds(kinds)
                    ),
                )
                .with_help(format!("name {}", describe_kinds(kinds))),
                None => {
                    let mut d = Diagnostic::new(
                        Code::UndefinedName,
                        reference.span,
                        format!("undefined name '{}'", reference.name()),
                    );
                    let candidates = self
                        .doc
                        .objects
                        .iter()
                        .filter(|o| kinds.contains(&"*") || kinds.contains(&o.kind.element()))
                        .map(|o| o.name.text.as_str());
                    d.help = Some(match did_you_mean(reference.name(), candidates) {
                        Some(best) => format!("did you mean '{best}'?"),
                        None => {
                            format!(
                                "define {} named '{}'",
                                describe_kinds(kinds),
                                reference.name()
                            )
                        }
                    });
                    d
                }
            };
            self.diags.push(d);
            return None;
        };
        let element = self.doc.objects[i].kind.element();
        let transformed = matches!(element, "transform" | "replicate");
        if !kinds.contains(&"*") && !kinds.contains(&element) && !transformed {
            self.diags.push(
                Diagnostic::new(
                    Code::WrongKind,
                    reference.span,
                    format!(
                        "'{}' is {}, but {} is expected here",
                        reference.name(),
                        a(element),
                        describe_kinds(kinds)
                    ),
                )
                .with_help(format!("name {}", describe_kinds(kinds))),
            );
            return None;
        }
        Some(i)
    }

    /// Resolves a reference to geometry, picking a replicate's member when indexed.
    pub fn linked_geometry(
        &mut self,
        reference: &Ref,
        kinds: &[&str],
    ) -> Option<(usize, Geometry)> {
        let i = self.lookup(reference, kinds)?;
        let g = self.geometry(i)?;
        match (g, reference.index) {
            (Geometry::Group(members), Some(k)) => match members.get(k.wrapping_sub(1)) {
                Some(m) => Some((i, m.clone())),
                None => {
                    self.diags.push(
                        Diagnostic::new(
                            Code::IndexOutOfRange,
                            reference.span,
                            format!(
                                "'{}' has {} members; there is no [{k}]",
                                reference.name(),
                                members.len()
                            ),
                        )
                        .with_help(format!("use an index from 1 to {}", members.len())),
                    );
                    None
                }
            },
            (Geometry::Group(members), None) => Some((i, Geometry::Group(members))),
            (g, None) => Some((i, g)),
            (g, Some(k)) => {
                if let Geometry::Points { points, partial } = &g
                    && k >= 1
                    && k <= points.len()
                {
                    return Some((
                        i,
                        Geometry::Points {
                            points: vec![points[k - 1]],
                            partial: vec![partial[k - 1]],
                        },
                    ));
                }
                self.diags.push(
                    Diagnostic::new(
                        Code::IndexOutOfRange,
                        reference.span,
                        format!(
                            "'{}' is a single {}; it has no member [{k}]",
                            reference.name(),
                            g.kind()
                        ),
                    )
                    .with_help(format!("write '{}' without an index", reference.name())),
                );
                None
            }
        }
    }

    pub fn link(&mut self, reference: &Ref, kinds: &[&str]) -> Option<Link> {
        let i = self.lookup(reference, kinds)?;
        Some(Link {
            object: i,
            span: reference.span,
        })
    }
}

/// "a sphere", "an edge".
pub fn a(kind: &str) -> String {
    let article = if kind.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    };
    format!("{article} {kind}")
}

/// "a point or a vertex"; "*" is any object.
fn describe_kinds(kinds: &[&str]) -> String {
    if kinds.contains(&"*") {
        return "a named object (a solid, point, surface, …)".to_string();
    }
    kinds.iter().map(|k| a(k)).collect::<Vec<_>>().join(" or ")
}

/// Evaluates three optional components (missing = 0). As coordinates, each
/// may use basis coordinates of its own axis.
fn vector3(
    values: &Values,
    used: &mut Used,
    x: Option<&Number>,
    y: Option<&Number>,
    z: Option<&Number>,
    coordinates: bool,
    diags: &mut Diagnostics,
) -> Option<Vec3> {
    let mut out = Vec3::zeros();
    let mut ok = true;
    for (slot, (n, axis)) in [(x, Axis::X), (y, Axis::Y), (z, Axis::Z)]
        .into_iter()
        .enumerate()
    {
        if let Some(n) = n {
            let ctx = if coordinates {
                Ctx::Coordinate(axis)
            } else {
                Ctx::Any
            };
            match values.eval(n, ctx, used, diags) {
                Some(v) => out[slot] = v,
                None => ok = false,
            }
        }
    }
    ok.then_some(out)
}
