//! Validation of the model IR. The topology checks ([`shell`]) work on the
//! graph alone: edges and face loops first, then the closed shells bounding
//! 3D subdomains, then how entities are used, so that the report reads from
//! the smallest entity up. Every check reports and goes on; none panics on a
//! malformed model.

pub mod shell;

use crate::diag::Diagnostics;
use crate::ir::{Model, SourceMap};

/// Runs the topology checks in a fixed order: [`shell::check_faces`] (E400,
/// E401), [`shell::check_subdomain_shells`] (E402–E405),
/// [`shell::check_face_usage`] (E406, W004). The diagnostics are in that
/// order; callers sort them by position with [`Diagnostics::sort`].
pub fn check_topology(model: &Model, source_map: &SourceMap) -> Diagnostics {
    // The three checks only read the model, so they run side by side; their
    // findings are joined in the fixed order, whatever the threads.
    let check = |f: fn(&Model, &SourceMap, &mut Diagnostics)| {
        let mut diags = Diagnostics::default();
        f(model, source_map, &mut diags);
        diags
    };
    let ((mut diags, shells), usage) = rayon::join(
        || {
            rayon::join(
                || check(shell::check_faces),
                || check(shell::check_subdomain_shells),
            )
        },
        || check(shell::check_face_usage),
    );
    diags.extend(shells);
    diags.extend(usage);
    diags
}

/// Hand-built models for the tests of `ir` and `valid`: welded polyhedra
/// made of segments and planar faces, each entity with a span.
#[cfg(test)]
pub(crate) mod fixtures {
    use crate::geom::{Curve, Frame, Point3, Surface, Vec3};
    use crate::ir::{
        Dimension, Edge, EdgeId, Face, FaceId, Model, OrientedEdge, OrientedFace, Origin,
        SourceMap, Subdomain, SubdomainCells, SubdomainId, Vertex, VertexId,
    };
    use crate::span::Span;

    pub(crate) struct Builder {
        pub model: Model,
        pub map: SourceMap,
        /// The vertex cycle of every face, to weld faces given twice.
        cycles: Vec<Vec<VertexId>>,
        next_span: usize,
    }

    impl Builder {
        pub fn new(dimension: Dimension) -> Builder {
            Builder {
                model: Model::empty(dimension),
                map: SourceMap::default(),
                cycles: Vec::new(),
                next_span: 0,
            }
        }

        fn origin(&mut self) -> Origin {
            let span = Span::new(self.next_span, self.next_span + 4);
            self.next_span += 10;
            Origin { span }
        }

        /// The vertex at `p`, made on first use.
        pub fn vertex(&mut self, p: [f64; 3]) -> VertexId {
            let position = Point3::new(p[0], p[1], p[2]);
            if let Some(i) = self
                .model
                .vertices
                .iter()
                .position(|v| v.position == position)
            {
                return VertexId(i as u32);
            }
            let id = VertexId(self.model.vertices.len() as u32);
            self.model.vertices.push(Vertex {
                name: format!("v{}", id.0).into(),
                position,
            });
            let origin = self.origin();
            self.map.vertices.insert(id, origin);
            id
        }

        /// The segment a → b, reusing an existing edge between them.
        pub fn segment(&mut self, a: VertexId, b: VertexId) -> OrientedEdge {
            for (i, e) in self.model.edges.iter().enumerate() {
                if (e.begin, e.end) == (a, b) || (e.begin, e.end) == (b, a) {
                    return OrientedEdge {
                        edge: EdgeId(i as u32),
                        forward: e.begin == a,
                    };
                }
            }
            let edge = self.push_edge(
                Curve::Segment {
                    a: self.model.vertex(a).position,
                    b: self.model.vertex(b).position,
                },
                a,
                b,
            );
            OrientedEdge {
                edge,
                forward: true,
            }
        }

        pub fn push_edge(&mut self, curve: Curve, begin: VertexId, end: VertexId) -> EdgeId {
            let id = EdgeId(self.model.edges.len() as u32);
            self.model.edges.push(Edge {
                name: format!("e{}", id.0).into(),
                carrier: crate::ir::Carrier::own(curve),
                begin,
                end,
            });
            let origin = self.origin();
            self.map.edges.insert(id, origin);
            id
        }

        pub fn push_face(
            &mut self,
            name: &str,
            surface: Surface,
            loops: Vec<Vec<OrientedEdge>>,
        ) -> FaceId {
            let id = FaceId(self.model.faces.len() as u32);
            self.model.faces.push(Face {
                name: name.into(),
                carrier: crate::ir::Carrier::own(surface),
                reversed: false,
                loops: loops.into(),
            });
            self.cycles.push(Vec::new());
            let origin = self.origin();
            self.map.faces.insert(id, origin);
            id
        }

        /// A planar face through `pts` (counter-clockwise about its normal),
        /// or the existing face on the same vertices, outward when the
        /// existing loop runs the same way.
        pub fn polygon(&mut self, name: &str, pts: &[[f64; 3]]) -> OrientedFace {
            let cycle: Vec<VertexId> = pts.iter().map(|&p| self.vertex(p)).collect();
            for (i, known) in self.cycles.iter().enumerate() {
                if let Some(same) = same_cycle(known, &cycle) {
                    return OrientedFace {
                        face: FaceId(i as u32),
                        outward: same,
                    };
                }
            }
            let n = cycle.len();
            let lp: Vec<OrientedEdge> = (0..n)
                .map(|i| self.segment(cycle[i], cycle[(i + 1) % n]))
                .collect();
            let p: Vec<Point3> = pts.iter().map(|p| Point3::new(p[0], p[1], p[2])).collect();
            let normal = (p[1] - p[0]).cross(&(p[2] - p[1])).normalize();
            let face = self.push_face(
                name,
                Surface::Plane {
                    origin: p[0],
                    normal,
                },
                vec![lp],
            );
            self.cycles[face.index()] = cycle;
            OrientedFace {
                face,
                outward: true,
            }
        }

        pub fn push_subdomain(&mut self, name: &str, cells: SubdomainCells) -> SubdomainId {
            let id = SubdomainId(self.model.subdomains.len() as u32);
            self.model.subdomains.push(Subdomain {
                name: name.to_string(),
                material: None,
                cells,
                ..Default::default()
            });
            let origin = self.origin();
            self.map.subdomains.insert(id, origin);
            id
        }

        /// The six faces of the unit cube at `m`, outward normals, named
        /// "<prefix>.bottom" etc.
        pub fn unit_box_faces(&mut self, prefix: &str, m: [f64; 3]) -> Vec<OrientedFace> {
            let p = |i: f64, j: f64, k: f64| [m[0] + i, m[1] + j, m[2] + k];
            let sides: [(&str, [[f64; 3]; 4]); 6] = [
                (
                    "bottom",
                    [p(0., 0., 0.), p(0., 1., 0.), p(1., 1., 0.), p(1., 0., 0.)],
                ),
                (
                    "top",
                    [p(0., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(0., 1., 1.)],
                ),
                (
                    "front",
                    [p(0., 0., 0.), p(1., 0., 0.), p(1., 0., 1.), p(0., 0., 1.)],
                ),
                (
                    "back",
                    [p(0., 1., 0.), p(0., 1., 1.), p(1., 1., 1.), p(1., 1., 0.)],
                ),
                (
                    "left",
                    [p(0., 0., 0.), p(0., 0., 1.), p(0., 1., 1.), p(0., 1., 0.)],
                ),
                (
                    "right",
                    [p(1., 0., 0.), p(1., 1., 0.), p(1., 1., 1.), p(1., 0., 1.)],
                ),
            ];
            sides
                .iter()
                .map(|(side, pts)| self.polygon(&format!("{prefix}.{side}"), pts))
                .collect()
        }

        /// A unit cube subdomain at `m`.
        pub fn unit_box(&mut self, name: &str, m: [f64; 3]) -> SubdomainId {
            let boundary = self.unit_box_faces(name, m);
            self.push_subdomain(name, SubdomainCells::Volume { boundary })
        }

        /// A unit square region at (x, y) in the plane z = 0.
        pub fn unit_square(&mut self, name: &str, x: f64, y: f64) -> SubdomainId {
            let pts = [
                [x, y, 0.],
                [x + 1., y, 0.],
                [x + 1., y + 1., 0.],
                [x, y + 1., 0.],
            ];
            let face = self.polygon(name, &pts).face;
            self.push_subdomain(name, SubdomainCells::Region { faces: vec![face] })
        }
    }

    /// Some(true) when `b` is `a` rotated, Some(false) when reversed and rotated.
    fn same_cycle(a: &[VertexId], b: &[VertexId]) -> Option<bool> {
        let n = a.len();
        if n == 0 || n != b.len() {
            return None;
        }
        let rotated = |b: &[VertexId]| (0..n).any(|r| (0..n).all(|i| a[i] == b[(i + r) % n]));
        let reversed: Vec<VertexId> = b.iter().rev().copied().collect();
        if rotated(b) {
            Some(true)
        } else if rotated(&reversed) {
            Some(false)
        } else {
            None
        }
    }

    /// One unit cube subdomain "box".
    pub fn cube() -> Builder {
        let mut b = Builder::new(Dimension::Three);
        b.unit_box("box", [0.0; 3]);
        b
    }

    fn circle(center: [f64; 3], major: [f64; 3], minor: [f64; 3]) -> Curve {
        Curve::Ellipse {
            center: Point3::new(center[0], center[1], center[2]),
            major: Vec3::new(major[0], major[1], major[2]),
            minor: Vec3::new(minor[0], minor[1], minor[2]),
            t0: 0.0,
            t1: std::f64::consts::TAU,
        }
    }

    /// A torus (major radius 2, minor 1) as one face on one vertex and two
    /// closed edges, the meridian `m` and the parallel `p`, with the loop
    /// m p m⁻¹ p⁻¹, or m p m p⁻¹ (a Klein bottle) when `klein`.
    pub fn torus(klein: bool) -> Builder {
        let mut b = Builder::new(Dimension::Three);
        let v = b.vertex([3.0, 0.0, 0.0]);
        let m = b.push_edge(circle([2., 0., 0.], [1., 0., 0.], [0., 0., 1.]), v, v);
        let p = b.push_edge(circle([0., 0., 0.], [3., 0., 0.], [0., 3., 0.]), v, v);
        b.model.edges[m.index()].name = "m".into();
        b.model.edges[p.index()].name = "p".into();
        let oe = |edge, forward| OrientedEdge { edge, forward };
        let lp = vec![oe(m, true), oe(p, true), oe(m, klein), oe(p, false)];
        let surface = Surface::Torus {
            frame: Frame::identity(),
            major: 2.0,
            minor: 1.0,
        };
        let face = b.push_face("skin", surface, vec![lp]);
        let boundary = vec![OrientedFace {
            face,
            outward: true,
        }];
        b.push_subdomain("ring", SubdomainCells::Volume { boundary });
        b
    }

    /// The unit sphere as two hemispheres on one closed equator edge.
    pub fn sphere() -> Builder {
        let mut b = Builder::new(Dimension::Three);
        let v = b.vertex([1.0, 0.0, 0.0]);
        let eq = b.push_edge(circle([0., 0., 0.], [1., 0., 0.], [0., 1., 0.]), v, v);
        let surface = Surface::Ellipsoid {
            frame: Frame::identity(),
        };
        let loop_of = |forward| vec![vec![OrientedEdge { edge: eq, forward }]];
        let north = b.push_face("north", surface.clone(), loop_of(true));
        let south = b.push_face("south", surface, loop_of(false));
        let boundary = vec![
            OrientedFace {
                face: north,
                outward: true,
            },
            OrientedFace {
                face: south,
                outward: true,
            },
        ];
        b.push_subdomain("ball", SubdomainCells::Volume { boundary });
        b
    }
}
