//! Canonical boundary representations of the primitive solids, with the
//! documented entity names users refer to (`box.xmin`, `ball.equator`, …).
//! Built in local indices; the welder merges them into the model.

use crate::geom::solid_carriers::{
    box_corner, box_edge_ends, box_face_center, cone_rim, cone_rims, ellipse, torus_meridian,
    torus_parallel,
};
use crate::geom::{Curve, Frame, Mat3, Point3, SolidShape, Surface, Vec3};
use crate::ir::{Carrier, EntityName, Face, LocalName, Loops, OrientedEdge, SolidId};
use std::sync::Arc;

pub struct BrepVertex {
    pub name: LocalName,
    pub position: Point3,
}

pub struct BrepEdge {
    pub name: LocalName,
    pub curve: Curve,
    pub begin: usize,
    pub end: usize,
}

pub struct BrepFace {
    pub name: LocalName,
    pub surface: Surface,
    /// Its loops, as indices into `Brep::loop_ends` (read through
    /// [`Brep::loops`]).
    loops: std::ops::Range<usize>,
    /// A canonical point inside the face (its centre), for welding and classification.
    pub sample: Point3,
}

/// A primitive's boundary. For 2D regions `faces` holds the single region
/// face (normal along the frame's third column) and `boundary` lists the rim
/// edges with `forward` = region on the left about that normal.
///
/// One `Brep` can be rebuilt for solid after solid ([`Brep::rebuild`]): its
/// vectors keep their capacity and every face's loops share one list, so
/// lowering a solid allocates nothing here (a fresh boundary took 5 to 15
/// small vectors per solid).
#[derive(Default)]
pub struct Brep {
    pub vertices: Vec<BrepVertex>,
    pub edges: Vec<BrepEdge>,
    pub faces: Vec<BrepFace>,
    pub boundary: Vec<(usize, bool)>,
    /// Every face's loops end to end: (local edge index, forward),
    /// counter-clockwise about the outward normal.
    loop_edges: Vec<(usize, bool)>,
    /// The end of each loop in `loop_edges`.
    loop_ends: Vec<usize>,
}

pub fn of(shape: &SolidShape) -> Brep {
    let mut brep = Brep::default();
    brep.rebuild(shape);
    brep
}

/// A lowered entity's carrier: the primitive's own (solid and local index)
/// when the solid is curved, else a copy of the planar curve or surface.
pub(super) fn carrier<T: Clone>(
    by_solid: bool,
    solid: SolidId,
    local: usize,
    own: &T,
) -> Carrier<T> {
    if by_solid {
        Carrier::primitive(solid, local)
    } else {
        Carrier::own(own.clone())
    }
}

impl Brep {
    /// Makes this the boundary of `shape`, reusing the vectors.
    pub fn rebuild(&mut self, shape: &SolidShape) {
        self.vertices.clear();
        self.edges.clear();
        self.faces.clear();
        self.boundary.clear();
        self.loop_edges.clear();
        self.loop_ends.clear();
        match shape {
            SolidShape::Box { frame } => self.parallelepiped(frame),
            SolidShape::Ball { frame } => self.ball(frame),
            SolidShape::Cone { frame, r0, r1 } => self.cone(frame, *r0, *r1),
            SolidShape::Torus {
                frame,
                major,
                minor,
            } => self.torus(frame, *major, *minor),
            SolidShape::Disk { frame } => self.disk(frame),
            SolidShape::Polygon { frame, vertices } => self.polygon(frame, vertices, shape),
        }
    }

    /// The loops of `face` (one of `self.faces`), in order.
    pub fn loops<'b>(
        &'b self,
        face: &BrepFace,
    ) -> impl ExactSizeIterator<Item = &'b [(usize, bool)]> + Clone + 'b {
        face.loops.clone().map(move |i| {
            let start = if i == 0 { 0 } else { self.loop_ends[i - 1] };
            &self.loop_edges[start..self.loop_ends[i]]
        })
    }

    /// Every edge of `face`'s loops, loop after loop.
    fn face_edges(&self, face: &BrepFace) -> &[(usize, bool)] {
        let end_of = |i: usize| if i == 0 { 0 } else { self.loop_ends[i - 1] };
        &self.loop_edges[end_of(face.loops.start)..end_of(face.loops.end)]
    }

    /// The model face of `self.faces[local]`, of solid `solid` named `base`,
    /// its loop items oriented by `orient`. The serial welder and the
    /// isolated runs (`isolated.rs`) both build faces here, so the two paths
    /// give the same model.
    pub(super) fn model_face(
        &self,
        local: usize,
        base: &Arc<Box<str>>,
        (solid, by_solid): (SolidId, bool),
        orient: impl Fn((usize, bool)) -> OrientedEdge,
    ) -> Face {
        let f = &self.faces[local];
        // Every primitive face but a two-rim cone's side has one loop: its
        // edges need no walk through the loop ends.
        let loops = match self.loops(f).len() {
            1 => Loops::one(self.face_edges(f).iter().copied().map(&orient)),
            _ => {
                let total = self.face_edges(f).len();
                Loops::from_nested(self.loops(f).map(|l| l.iter().copied().map(&orient)), total)
            }
        };
        Face {
            name: EntityName::local(base, f.name),
            carrier: carrier(by_solid, solid, local, &f.surface),
            reversed: false,
            loops,
        }
    }

    /// Adds a face whose loops are `loops`.
    fn add_face<L: IntoIterator<Item = (usize, bool)>>(
        &mut self,
        name: LocalName,
        surface: Surface,
        sample: Point3,
        loops: impl IntoIterator<Item = L>,
    ) {
        let first = self.loop_ends.len();
        for lp in loops {
            self.loop_edges.extend(lp);
            self.loop_ends.push(self.loop_edges.len());
        }
        self.faces.push(BrepFace {
            name,
            surface,
            loops: first..self.loop_ends.len(),
            sample,
        });
    }
}

/// The points the welder places for `shape` (its vertices' positions and its
/// faces' samples), without building the boundary: the isolation test boxes
/// them for every solid. Each point is computed as in [`of`], so the box is
/// the same (`anchors_are_the_brep_points` checks it).
pub fn anchors(shape: &SolidShape, mut visit: impl FnMut(Point3)) {
    match shape {
        SolidShape::Box { frame } => {
            for n in 0..8 {
                visit(frame.to_global(&Point3::new(
                    (n & 1) as f64,
                    ((n >> 1) & 1) as f64,
                    ((n >> 2) & 1) as f64,
                )));
            }
            for axis in 0..3 {
                for side in 0..2 {
                    let mut center = Point3::new(0.5, 0.5, 0.5);
                    center[axis] = side as f64;
                    visit(frame.to_global(&center));
                }
            }
        }
        SolidShape::Ball { frame } => {
            visit(frame.to_global(&Point3::new(1.0, 0.0, 0.0)));
            visit(frame.to_global(&Point3::new(0.0, 0.0, 1.0)));
            visit(frame.to_global(&Point3::new(0.0, 0.0, -1.0)));
        }
        SolidShape::Cone { frame, r0, r1 } => {
            // Vertices, then samples, in the order `cone` makes them.
            let rims = [(0.0, *r0), (1.0, *r1)];
            for &(z, r) in rims.iter().filter(|(_, r)| *r > 0.0) {
                visit(frame.to_global(&Point3::new(r, 0.0, z)));
            }
            for &(z, _) in rims.iter().filter(|(_, r)| *r > 0.0) {
                visit(frame.to_global(&Point3::new(0.0, 0.0, z)));
            }
            let mid_r = 0.5 * (r0 + r1);
            visit(frame.to_global(&Point3::new(-mid_r, 0.0, 0.5)));
        }
        SolidShape::Torus {
            frame,
            major,
            minor,
        } => {
            visit(frame.to_global(&Point3::new(major + minor, 0.0, 0.0)));
            visit(frame.to_global(&Point3::new(-(major + minor), 0.0, 0.0)));
        }
        SolidShape::Disk { frame } => {
            visit(frame.to_global(&Point3::new(1.0, 0.0, 0.0)));
            visit(frame.origin);
        }
        SolidShape::Polygon { frame, vertices } => {
            vertices.iter().for_each(|v| visit(frame.to_global(v)));
            visit(shape.interior_point());
        }
    }
}

/// True when the frame mirrors, so loops built counter-clockwise in local
/// coordinates run clockwise in global ones.
fn mirrors(frame: &Frame) -> bool {
    frame.linear.determinant() < 0.0
}

/// Local names are indices into `LOCAL_NAMES` (`ir/name.rs`), checked at
/// compile time: `named` fails the build on a name the table lacks.
const fn named(name: &str) -> LocalName {
    LocalName::named(name)
}

const FACE_NAMES: [[LocalName; 2]; 3] = [
    [named("xmin"), named("xmax")],
    [named("ymin"), named("ymax")],
    [named("zmin"), named("zmax")],
];
/// Edge names by axis the edge runs along, then the sides of the two other
/// axes in ascending axis order ("xmin_ymax" runs along z).
const EDGE_NAMES: [[[LocalName; 2]; 2]; 3] = [
    [
        [named("ymin_zmin"), named("ymin_zmax")],
        [named("ymax_zmin"), named("ymax_zmax")],
    ],
    [
        [named("xmin_zmin"), named("xmin_zmax")],
        [named("xmax_zmin"), named("xmax_zmax")],
    ],
    [
        [named("xmin_ymin"), named("xmin_ymax")],
        [named("xmax_ymin"), named("xmax_ymax")],
    ],
];
const VERTEX_NAMES: [LocalName; 8] = [
    named("v000"),
    named("v100"),
    named("v010"),
    named("v110"),
    named("v001"),
    named("v101"),
    named("v011"),
    named("v111"),
];
/// The round primitives' names (constants, so no lookup at run time).
const BOTTOM: LocalName = named("bottom");
const BOTTOM_RIM: LocalName = named("bottom_rim");
const BOTTOM_SEAM: LocalName = named("bottom_seam");
const EQUATOR: LocalName = named("equator");
const MERIDIAN: LocalName = named("meridian");
const NORTH: LocalName = named("north");
const PARALLEL: LocalName = named("parallel");
const REGION: LocalName = named("region");
const RIM: LocalName = named("rim");
const SEAM: LocalName = named("seam");
const SIDE: LocalName = named("side");
const SOUTH: LocalName = named("south");
const SURFACE: LocalName = named("surface");
const TOP: LocalName = named("top");
const TOP_RIM: LocalName = named("top_rim");
const TOP_SEAM: LocalName = named("top_seam");

/// The builders of each primitive's boundary, into an emptied `Brep`.
impl Brep {
    fn parallelepiped(&mut self, frame: &Frame) {
        let corner = |i: usize, j: usize, k: usize| i + 2 * j + 4 * k;
        self.vertices.extend((0..8).map(|n| BrepVertex {
            name: VERTEX_NAMES[n],
            position: box_corner(frame, n),
        }));
        // Edges along axis `a` at fixed values of the other two axes.
        // Edge (axis, s, t) is edges[4 * axis + 2 * s + t].
        for axis in 0..3 {
            let (p, q) = ((axis + 1) % 3, (axis + 2) % 3);
            let (lo, hi) = (p.min(q), p.max(q));
            for (s, names) in EDGE_NAMES[axis].iter().enumerate() {
                for (t, &name) in names.iter().enumerate() {
                    let mut at = [0usize; 3];
                    at[lo] = s;
                    at[hi] = t;
                    let begin = corner(at[0], at[1], at[2]);
                    at[axis] = 1;
                    let end = corner(at[0], at[1], at[2]);
                    debug_assert_eq!(box_edge_ends(self.edges.len()), (begin, end));
                    let curve = Curve::Segment {
                        a: self.vertices[begin].position,
                        b: self.vertices[end].position,
                    };
                    self.edges.push(BrepEdge {
                        name,
                        curve,
                        begin,
                        end,
                    });
                }
            }
        }
        let flip = mirrors(frame);
        let normals = Normals::of(frame);
        for (axis, names) in FACE_NAMES.iter().enumerate() {
            let (p, q) = ((axis + 1) % 3, (axis + 2) % 3);
            for (side, &face_name) in names.iter().enumerate() {
                // The four edges of the face axis = side, walked p-then-q, which is
                // counter-clockwise about +axis; reversed on the min side.
                let e = |along: usize, fixed_axis: usize, fixed: usize| {
                    // s belongs to the lower of the two fixed axes, t to the higher.
                    let (s, t) = if axis < fixed_axis {
                        (side, fixed)
                    } else {
                        (fixed, side)
                    };
                    4 * along + 2 * s + t
                };
                let mut ring = [
                    (e(p, q, 0), true),
                    (e(q, p, 1), true),
                    (e(p, q, 1), false),
                    (e(q, p, 0), false),
                ];
                if (side == 0) != flip {
                    reverse(&mut ring);
                }
                // `box_face`'s plane, through the centre that is also the sample.
                let center = box_face_center(frame, axis, side);
                let mut local_normal = Vec3::zeros();
                local_normal[axis] = if side == 0 { -1.0 } else { 1.0 };
                let plane = Surface::Plane {
                    origin: center,
                    normal: normals.to_global(&local_normal),
                };
                self.add_face(face_name, plane, center, [ring]);
            }
        }
    }

    fn ball(&mut self, frame: &Frame) {
        let flip = mirrors(frame);
        self.vertices.push(BrepVertex {
            name: SEAM,
            position: frame.to_global(&Point3::new(1.0, 0.0, 0.0)),
        });
        self.edges.push(BrepEdge {
            name: EQUATOR,
            curve: ellipse(frame, Vec3::zeros(), Vec3::x(), Vec3::y()),
            begin: 0,
            end: 0,
        });
        let surface = Surface::Ellipsoid { frame: *frame };
        let north = frame.to_global(&Point3::new(0.0, 0.0, 1.0));
        self.add_face(NORTH, surface.clone(), north, [[(0, !flip)]]);
        let south = frame.to_global(&Point3::new(0.0, 0.0, -1.0));
        self.add_face(SOUTH, surface, south, [[(0, flip)]]);
    }

    fn cone(&mut self, frame: &Frame, r0: f64, r1: f64) {
        let flip = mirrors(frame);
        let normals = Normals::of(frame);
        // The side's loops: one per rim, at most two.
        let mut side_loops = [(0, false); 2];
        let mut rims = 0;
        // The rims that exist, bottom first: their entities take the carriers'
        // local indices in this order.
        let names = |up: f64| {
            if up < 0.0 {
                (BOTTOM_SEAM, BOTTOM_RIM, BOTTOM)
            } else {
                (TOP_SEAM, TOP_RIM, TOP)
            }
        };
        for (z, r, up) in cone_rims(r0, r1) {
            let (vertex, rim, cap) = names(up);
            let v = self.vertices.len();
            self.vertices.push(BrepVertex {
                name: vertex,
                position: frame.to_global(&Point3::new(r, 0.0, z)),
            });
            let e = self.edges.len();
            self.edges.push(BrepEdge {
                name: rim,
                curve: cone_rim(frame, z, r),
                begin: v,
                end: v,
            });
            // The cap's outward normal is ∓axis; the side meets the rim from the other side.
            let cap_forward = (up > 0.0) != flip;
            // `cone_cap`'s plane, through the centre that is also the sample.
            let center = frame.to_global(&Point3::new(0.0, 0.0, z));
            let plane = Surface::Plane {
                origin: center,
                normal: normals.to_global(&Vec3::new(0.0, 0.0, up)),
            };
            self.add_face(cap, plane, center, [[(e, cap_forward)]]);
            side_loops[rims] = (e, !cap_forward);
            rims += 1;
        }
        let mid_r = 0.5 * (r0 + r1);
        let surface = Surface::Cone {
            frame: *frame,
            r0,
            r1,
        };
        let sample = frame.to_global(&Point3::new(-mid_r, 0.0, 0.5));
        let loops = side_loops[..rims].iter().map(|&item| [item]);
        self.add_face(SIDE, surface, sample, loops);
    }

    fn torus(&mut self, frame: &Frame, major: f64, minor: f64) {
        let flip = mirrors(frame);
        let outer = major + minor;
        let mut ring = [(0, true), (1, true), (0, false), (1, false)];
        if flip {
            reverse(&mut ring);
        }
        self.vertices.push(BrepVertex {
            name: SEAM,
            position: frame.to_global(&Point3::new(outer, 0.0, 0.0)),
        });
        self.edges.push(BrepEdge {
            name: PARALLEL,
            curve: torus_parallel(frame, major, minor),
            begin: 0,
            end: 0,
        });
        self.edges.push(BrepEdge {
            name: MERIDIAN,
            curve: torus_meridian(frame, major, minor),
            begin: 0,
            end: 0,
        });
        let surface = Surface::Torus {
            frame: *frame,
            major,
            minor,
        };
        let sample = frame.to_global(&Point3::new(-(major + minor), 0.0, 0.0));
        self.add_face(SURFACE, surface, sample, [ring]);
    }

    fn disk(&mut self, frame: &Frame) {
        let center = frame.origin;
        self.vertices.push(BrepVertex {
            name: SEAM,
            position: frame.to_global(&Point3::new(1.0, 0.0, 0.0)),
        });
        self.edges.push(BrepEdge {
            name: RIM,
            curve: ellipse(frame, Vec3::zeros(), Vec3::x(), Vec3::y()),
            begin: 0,
            end: 0,
        });
        let surface = Surface::Plane {
            origin: center,
            normal: region_normal(frame),
        };
        self.add_face(REGION, surface, center, [[(0, true)]]);
        self.boundary.push((0, true));
    }

    /// A polygon's boundary: vertices v1…vn in the given order, edge ei from vi
    /// to the next vertex, the loop counter-clockwise in local coordinates
    /// (a clockwise vertex list is walked backwards). `shape` is the polygon.
    fn polygon(&mut self, frame: &Frame, local: &[Point3], shape: &SolidShape) {
        let n = local.len();
        self.vertices.extend((0..n).map(|i| BrepVertex {
            name: LocalName::Vertex(i as u32 + 1),
            position: frame.to_global(&local[i]),
        }));
        for i in 0..n {
            let j = (i + 1) % n;
            let curve = Curve::Segment {
                a: self.vertices[i].position,
                b: self.vertices[j].position,
            };
            self.edges.push(BrepEdge {
                name: LocalName::Edge(i as u32 + 1),
                curve,
                begin: i,
                end: j,
            });
        }
        let twice_area: f64 = (0..n)
            .map(|i| {
                let (v, w) = (local[i], local[(i + 1) % n]);
                v.x * w.y - w.x * v.y
            })
            .sum();
        if twice_area >= 0.0 {
            self.boundary.extend((0..n).map(|i| (i, true)));
        } else {
            self.boundary.extend((0..n).rev().map(|i| (i, false)));
        }
        let sample = shape.interior_point();
        let surface = Surface::Plane {
            origin: sample,
            normal: region_normal(frame),
        };
        let ring = std::mem::take(&mut self.boundary);
        self.add_face(REGION, surface, sample, [ring.iter().copied()]);
        self.boundary = ring;
    }
}

/// A loop walked the other way: its edges in reverse order, each reversed.
fn reverse(ring: &mut [(usize, bool)]) {
    ring.reverse();
    for item in ring {
        item.1 = !item.1;
    }
}

/// `Frame::normal_to_global` for the several plane faces of one frame, its
/// inverse computed once instead of per face (the inverses were a sixth of
/// building a box's boundary). The same operations, so the same bits.
struct Normals(Option<Mat3>);

impl Normals {
    fn of(frame: &Frame) -> Normals {
        Normals(frame.linear.try_inverse().map(|inv| inv.transpose()))
    }

    fn to_global(&self, n: &Vec3) -> Vec3 {
        let m = self.0.map_or(*n, |inverse_transpose| inverse_transpose * n);
        let len = m.norm();
        if len > 0.0 { m / len } else { m }
    }
}

fn region_normal(frame: &Frame) -> Vec3 {
    let n = frame.linear.column(0).cross(&frame.linear.column(1));
    if n.norm() > 0.0 {
        n.normalize()
    } else {
        Vec3::z()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Mat3;

    fn frame(linear: Mat3) -> Frame {
        Frame {
            origin: Point3::new(0.3, -1.7, 2.9),
            linear,
        }
    }

    /// The brep's own points: vertex positions, then face samples.
    fn brep_points(shape: &SolidShape) -> Vec<Point3> {
        let brep = of(shape);
        let vertices = brep.vertices.iter().map(|v| v.position);
        vertices
            .chain(brep.faces.iter().map(|f| f.sample))
            .collect()
    }

    /// The 3D primitives' shapes the tests below build their boundaries of:
    /// turned and mirroring frames, cones with and without caps.
    fn solids() -> Vec<SolidShape> {
        let mut shapes = Vec::new();
        for f in frames() {
            shapes.push(SolidShape::Box { frame: f });
            shapes.push(SolidShape::Ball { frame: f });
            for (r0, r1) in [(0.4, 0.2), (0.0, 0.3), (0.5, 0.0), (0.25, 0.25)] {
                shapes.push(SolidShape::Cone { frame: f, r0, r1 });
            }
            shapes.push(SolidShape::Torus {
                frame: f,
                major: 0.5,
                minor: 0.15,
            });
        }
        shapes
    }

    #[test]
    fn carriers_by_local_index_are_the_breps() {
        let mut counts = Vec::new();
        for shape in solids() {
            let brep = of(&shape);
            for (k, face) in brep.faces.iter().enumerate() {
                // Bit for bit: the model makes these instead of keeping them.
                assert_eq!(
                    shape.face_surface(k).as_ref(),
                    Some(&face.surface),
                    "{shape:?} face {k}"
                );
            }
            for (k, edge) in brep.edges.iter().enumerate() {
                assert_eq!(
                    shape.edge_curve(k).as_ref(),
                    Some(&edge.curve),
                    "{shape:?} edge {k}"
                );
            }
            assert_eq!(shape.face_surface(brep.faces.len()), None);
            assert_eq!(shape.edge_curve(brep.edges.len()), None);
            counts.push((brep.faces.len(), brep.edges.len()));
        }
        // Box, ball, four cones (two caps, top only, bottom only, two), torus.
        let expected = [(6, 12), (2, 1), (3, 2), (2, 1), (2, 1), (3, 2), (1, 2)];
        assert_eq!(counts[..7], expected);
        assert_eq!(counts[7..], expected);
    }

    #[test]
    fn regions_keep_their_own_carriers() {
        let disk = SolidShape::Disk {
            frame: frame(Mat3::identity()),
        };
        assert_eq!(of(&disk).faces.len(), 1);
        assert_eq!(disk.face_surface(0), None);
        assert_eq!(disk.edge_curve(0), None);
    }

    /// A turned and a mirroring frame.
    fn frames() -> [Frame; 2] {
        let turned = Mat3::new(0.0, -2.0, 0.1, 1.5, 0.0, 0.0, 0.2, 0.0, 0.7);
        let mirrored = Mat3::from_diagonal(&Vec3::new(-1.0, 0.5, 2.0));
        [frame(turned), frame(mirrored)]
    }

    /// A surface's numbers, bit for bit (`==` takes -0 for +0).
    fn bits(surface: &Surface) -> Vec<u64> {
        match surface {
            Surface::Plane { origin, normal } => (origin.iter().chain(normal.iter()))
                .map(|x| x.to_bits())
                .collect(),
            other => panic!("not a plane: {other:?}"),
        }
    }

    #[test]
    fn plane_faces_are_the_carriers_bit_for_bit() {
        use crate::geom::solid_carriers::{box_face, cone_cap};
        // Regular, mirrored, sheared, flat, singular, tiny and huge frames,
        // and ones with exact zeros (whose normals have signed zeros).
        let mut linears = vec![
            Mat3::identity(),
            Mat3::new(0.0, -2.0, 0.1, 1.5, 0.0, 0.0, 0.2, 0.0, 0.7),
            Mat3::from_diagonal(&Vec3::new(-1.0, 0.5, 2.0)),
            Mat3::from_diagonal(&Vec3::new(1.0, 1.0, 0.0)),
            Mat3::zeros(),
            Mat3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 0.0, 1.0),
            Mat3::identity() * 1e-200,
            Mat3::identity() * 1e200,
            Mat3::new(0.0, 0.0, -3.0, 0.0, 2.0, 0.0, -1.0, 0.0, 0.0),
        ];
        let mut x = 0.37_f64;
        for _ in 0..40 {
            linears.push(Mat3::from_fn(|_, _| {
                x = (x * 3.9 * (1.0 - x)).clamp(1e-9, 1.0 - 1e-9);
                4.0 * x - 2.0
            }));
        }
        let mut planes = 0;
        for linear in linears {
            let f = frame(linear);
            let brep = of(&SolidShape::Box { frame: f });
            for (k, face) in brep.faces.iter().enumerate() {
                let expected = box_face(&f, k / 2, k % 2);
                assert_eq!(bits(&face.surface), bits(&expected), "{linear:?} face {k}");
                assert_eq!(face.sample, box_face_center(&f, k / 2, k % 2));
                planes += 1;
            }
            let cone = of(&SolidShape::Cone {
                frame: f,
                r0: 0.4,
                r1: 0.2,
            });
            for (k, (z, _, up)) in cone_rims(0.4, 0.2).enumerate() {
                let expected = cone_cap(&f, z, up);
                assert_eq!(
                    bits(&cone.faces[k].surface),
                    bits(&expected),
                    "{linear:?} cap {k}"
                );
                planes += 1;
            }
        }
        assert_eq!(planes, 49 * 8);
    }

    #[test]
    fn model_faces_have_the_loops_of_their_brep_faces() {
        let mut shapes = solids();
        shapes.push(SolidShape::Disk {
            frame: frame(Mat3::identity()),
        });
        shapes.push(SolidShape::Polygon {
            frame: frame(Mat3::identity()),
            vertices: vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
            ],
        });
        let base: Arc<Box<str>> = Arc::new("s".into());
        // Edges renumbered and turned, so the orientation is exercised.
        let orient = |(edge, forward): (usize, bool)| OrientedEdge {
            edge: crate::ir::EdgeId(3 * edge as u32 + 1),
            forward: forward == (edge % 2 == 0),
        };
        let mut loop_counts = Vec::new();
        for shape in &shapes {
            let brep = of(shape);
            for (k, f) in brep.faces.iter().enumerate() {
                let face = brep.model_face(k, &base, (SolidId(4), true), orient);
                let nested: Vec<Vec<OrientedEdge>> = (brep.loops(f))
                    .map(|l| l.iter().copied().map(orient).collect())
                    .collect();
                assert_eq!(
                    face.loops,
                    Loops::from(nested.clone()),
                    "{shape:?} face {k}"
                );
                assert_eq!(face.loops.to_vecs(), nested);
                loop_counts.push(face.loops.len());
            }
        }
        // Single loops, and the two-rim cones' sides with two.
        assert_eq!(loop_counts.iter().filter(|&&n| n == 2).count(), 4);
        assert_eq!(
            loop_counts.iter().filter(|&&n| n == 1).count(),
            loop_counts.len() - 4
        );
    }

    #[test]
    fn anchors_are_the_brep_points() {
        let mut shapes = solids();
        for f in frames() {
            shapes.push(SolidShape::Disk { frame: f });
            shapes.push(SolidShape::Polygon {
                frame: f,
                vertices: vec![
                    Point3::new(0.0, 0.0, 0.0),
                    Point3::new(2.0, 0.0, 0.0),
                    Point3::new(2.0, 1.0, 0.0),
                    Point3::new(1.0, 0.4, 0.0),
                    Point3::new(0.0, 1.0, 0.0),
                ],
            });
        }
        for shape in &shapes {
            let mut points = Vec::new();
            anchors(shape, |p| points.push(p));
            let expected = brep_points(shape);
            assert!(expected.len() >= 2, "{shape:?}");
            // Bit for bit, in the same order.
            assert_eq!(points, expected, "{shape:?}");
        }
    }
}
