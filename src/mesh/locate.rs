//! Point location (paper 000's point classification): which subdomain of a
//! mesh holds a point, or none (the exterior).
//!
//! 3D: a ray from the point along +x crosses each subdomain's closed boundary
//! an odd number of times exactly when the point is inside it. 2D: the point
//! lies in one triangle of its region. Triangles are binned by their
//! projection onto the plane across the ray (y, z in 3D; x, y in 2D), so a
//! query looks only at the triangles of one grid cell.
//!
//! Points on a shared triangle edge or vertex are decided by one symbolic
//! perturbation of the point (a little along the first projected axis, far
//! less along the second), applied the same way to every triangle: the ray
//! crosses a closed surface through an edge exactly once, never twice or not
//! at all. The mesh stands in for the exact surfaces, so points closer to a
//! curved boundary than the chordal tolerance may fall on either side.

use super::Mesh;

/// A triangle projected onto the binning plane, with what a query needs.
#[derive(Debug, Clone, Copy)]
struct Projected {
    corners: [[f64; 2]; 3],
    /// The coordinate along the ray at each corner (3D only).
    depth: [f64; 3],
    subdomain: u32,
}

/// A mesh prepared for many point queries.
#[derive(Debug)]
pub struct Locator {
    /// 3: parity along a ray; 2: containment in a region's triangle.
    dimension: u8,
    subdomains: usize,
    triangles: Vec<Projected>,
    lo: [f64; 2],
    cell: [f64; 2],
    cells: [usize; 2],
    /// Triangles of cell k: `members[starts[k]..starts[k + 1]]`.
    starts: Vec<usize>,
    members: Vec<u32>,
}

/// The two plane axes of the projection, and the ray axis (3D).
fn axes(dimension: u8) -> ([usize; 2], usize) {
    if dimension == 3 {
        ([1, 2], 0)
    } else {
        ([0, 1], 2)
    }
}

impl Locator {
    /// Prepares `mesh` (whose indices must be in range, as meshing and the
    /// readers give them).
    pub fn new(mesh: &Mesh) -> Locator {
        let dimension = if mesh.dimension == 3 { 3 } else { 2 };
        let ([u, v], w) = axes(dimension);
        let mut triangles = Vec::new();
        for (s, subdomain) in mesh.subdomains.iter().enumerate() {
            for &(face, _) in &subdomain.faces {
                let Some(face) = mesh.faces.get(face as usize) else {
                    continue;
                };
                for t in &face.triangles {
                    let Some(p) = t
                        .iter()
                        .map(|&n| mesh.nodes.get(n as usize))
                        .collect::<Option<Vec<_>>>()
                    else {
                        continue;
                    };
                    let corners = [[p[0][u], p[0][v]], [p[1][u], p[1][v]], [p[2][u], p[2][v]]];
                    // A triangle seen edge-on is never crossed by the perturbed ray.
                    if area2(corners) == 0.0 {
                        continue;
                    }
                    triangles.push(Projected {
                        corners,
                        depth: [p[0][w], p[1][w], p[2][w]],
                        subdomain: s as u32,
                    });
                }
            }
        }
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for t in &triangles {
            for c in t.corners {
                for k in 0..2 {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
            }
        }
        // About two triangles per cell.
        let side = ((triangles.len() as f64 / 2.0).sqrt().ceil() as usize).clamp(1, 4096);
        let cells = [side, side];
        let cell = [0, 1].map(|k| ((hi[k] - lo[k]) / side as f64).max(f64::MIN_POSITIVE));
        let mut locator = Locator {
            dimension,
            subdomains: mesh.subdomains.len(),
            triangles,
            lo,
            cell,
            cells,
            starts: Vec::new(),
            members: Vec::new(),
        };
        locator.bin();
        locator
    }

    /// Fills the cell lists (counting first, so one allocation each).
    fn bin(&mut self) {
        let n = self.cells[0] * self.cells[1];
        let mut counts = vec![0usize; n + 1];
        for t in &self.triangles {
            self.for_cells(t, |k| counts[k + 1] += 1);
        }
        for k in 0..n {
            counts[k + 1] += counts[k];
        }
        let mut fill = counts.clone();
        let mut members = vec![0u32; counts[n]];
        for (i, t) in self.triangles.iter().enumerate() {
            self.for_cells(t, |k| {
                members[fill[k]] = i as u32;
                fill[k] += 1;
            });
        }
        self.starts = counts;
        self.members = members;
    }

    fn for_cells(&self, t: &Projected, mut f: impl FnMut(usize)) {
        let range = |k: usize| {
            let (a, b) = t
                .corners
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| {
                    (a.min(c[k]), b.max(c[k]))
                });
            (self.index(k, a), self.index(k, b))
        };
        let (u0, u1) = range(0);
        let (v0, v1) = range(1);
        for j in v0..=v1 {
            for i in u0..=u1 {
                f(j * self.cells[0] + i);
            }
        }
    }

    /// The grid column (k = 0) or row (k = 1) of a coordinate, clamped.
    fn index(&self, k: usize, x: f64) -> usize {
        let i = ((x - self.lo[k]) / self.cell[k]).floor();
        if i.is_nan() || i < 0.0 {
            0
        } else {
            (i as usize).min(self.cells[k] - 1)
        }
    }

    /// The index of the subdomain holding `p`, `None` outside all of them.
    pub fn locate(&self, p: [f64; 3]) -> Option<u32> {
        let ([u, v], w) = axes(self.dimension);
        let q = [p[u], p[v]];
        if self.triangles.is_empty() || !q.iter().all(|c| c.is_finite()) {
            return None;
        }
        if (0..2)
            .any(|k| q[k] < self.lo[k] || q[k] > self.lo[k] + self.cell[k] * self.cells[k] as f64)
        {
            return None;
        }
        let k = self.index(1, q[1]) * self.cells[0] + self.index(0, q[0]);
        let mut parity = vec![false; self.subdomains];
        for &i in &self.members[self.starts[k]..self.starts[k + 1]] {
            let t = &self.triangles[i as usize];
            let Some(weights) = inside(t.corners, q) else {
                continue;
            };
            if self.dimension == 2 {
                return Some(t.subdomain);
            }
            let depth: f64 = (0..3).map(|c| weights[c] * t.depth[c]).sum();
            if depth >= p[w] {
                let slot = &mut parity[t.subdomain as usize];
                *slot = !*slot;
            }
        }
        parity.iter().position(|&odd| odd).map(|s| s as u32)
    }
}

/// Twice the signed area of a plane triangle.
fn area2([a, b, c]: [[f64; 2]; 3]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Whether the perturbed `p` lies left of the directed edge a → b. The edge
/// is evaluated in one canonical direction, so the two triangles sharing it
/// see the same value with opposite meaning.
fn left_of(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> bool {
    if b < a {
        return !left_of(b, a, p);
    }
    let s = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    if s != 0.0 {
        return s > 0.0;
    }
    // p + ε e₀ + ε² e₁: the ε term is −(b₁ − a₁), then the ε² term b₀ − a₀.
    if b[1] != a[1] {
        b[1] < a[1]
    } else {
        b[0] > a[0]
    }
}

/// The barycentric weights of `p` when the perturbed point is inside.
fn inside(t: [[f64; 2]; 3], p: [f64; 2]) -> Option<[f64; 3]> {
    let sides = [
        left_of(t[0], t[1], p),
        left_of(t[1], t[2], p),
        left_of(t[2], t[0], p),
    ];
    if sides[0] != sides[1] || sides[1] != sides[2] {
        return None;
    }
    let total = area2(t);
    let w = [
        area2([p, t[1], t[2]]) / total,
        area2([t[0], p, t[2]]) / total,
        area2([t[0], t[1], p]) / total,
    ];
    Some(w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{MeshFace, MeshSubdomain};

    fn face_of(triangles: Vec<[u32; 3]>) -> MeshFace {
        MeshFace {
            name: String::new(),
            triangles,
            boundary: Vec::new(),
        }
    }

    fn subdomain_of(name: &str, faces: Vec<u32>) -> MeshSubdomain {
        MeshSubdomain {
            name: name.into(),
            material: None,
            faces: faces.into_iter().map(|f| (f, true)).collect(),
        }
    }

    /// Two unit cubes side by side ([0,1]³ and [1,2]×[0,1]²), each face split
    /// into two triangles along a diagonal, the shared face used by both.
    fn two_cubes() -> Mesh {
        let mut nodes = Vec::new();
        for x in 0..3 {
            for y in 0..2 {
                for z in 0..2 {
                    nodes.push([x as f64, y as f64, z as f64]);
                }
            }
        }
        let id = |x: u32, y: u32, z: u32| x * 4 + y * 2 + z;
        let quad = |a, b, c, d| vec![[a, b, c], [a, c, d]];
        let mut faces = Vec::new();
        let mut face = |triangles: Vec<[u32; 3]>| {
            faces.push(face_of(triangles));
            faces.len() as u32 - 1
        };
        let mut cube = |x0: u32, shared: Option<u32>| {
            let x1 = x0 + 1;
            let mut list = vec![
                face(quad(id(x0, 0, 0), id(x1, 0, 0), id(x1, 0, 1), id(x0, 0, 1))),
                face(quad(id(x0, 1, 0), id(x0, 1, 1), id(x1, 1, 1), id(x1, 1, 0))),
                face(quad(id(x0, 0, 0), id(x0, 1, 0), id(x1, 1, 0), id(x1, 0, 0))),
                face(quad(id(x0, 0, 1), id(x1, 0, 1), id(x1, 1, 1), id(x0, 1, 1))),
                face(quad(id(x1, 0, 0), id(x1, 1, 0), id(x1, 1, 1), id(x1, 0, 1))),
            ];
            list.push(match shared {
                Some(f) => f,
                None => face(quad(id(x0, 0, 0), id(x0, 0, 1), id(x0, 1, 1), id(x0, 1, 0))),
            });
            list
        };
        let left = cube(0, None);
        let right = cube(1, Some(left[4]));
        let subdomain = |name: &str, list: Vec<u32>| subdomain_of(name, list);
        Mesh {
            dimension: 3,
            nodes,
            subdomains: vec![subdomain("a", left), subdomain("b", right)],
            faces,
            ..Mesh::default()
        }
    }

    #[test]
    fn points_inside_each_cube_and_outside() {
        let locator = Locator::new(&two_cubes());
        assert_eq!(locator.locate([0.5, 0.5, 0.5]), Some(0));
        assert_eq!(locator.locate([1.5, 0.25, 0.75]), Some(1));
        assert_eq!(locator.locate([-0.5, 0.5, 0.5]), None);
        assert_eq!(locator.locate([2.5, 0.5, 0.5]), None);
        assert_eq!(locator.locate([0.5, 1.5, 0.5]), None);
        assert_eq!(locator.locate([0.5, 0.5, f64::NAN]), None);
    }

    #[test]
    fn rays_through_shared_edges_and_vertices_count_once() {
        let locator = Locator::new(&two_cubes());
        // y = z: the ray runs through the faces' diagonals; y = 0.5, z = 0:
        // along the bottom faces' plane; (y, z) = (0, 0): along cube edges.
        // (The perturbation moves such points towards +y, +z: into the cubes.)
        for (y, z) in [
            (0.5, 0.5),
            (0.25, 0.25),
            (0.75, 0.75),
            (0.5, 0.0),
            (0.0, 0.0),
        ] {
            assert_eq!(locator.locate([0.5, y, z]), Some(0), "y {y} z {z} in a");
            assert_eq!(locator.locate([1.5, y, z]), Some(1), "y {y} z {z} in b");
            assert_eq!(locator.locate([-1.0, y, z]), None, "y {y} z {z} outside");
        }
        // On the top edge the perturbed point is above the cubes.
        assert_eq!(locator.locate([0.5, 1.0, 1.0]), None);
    }

    #[test]
    fn a_plane_mesh_locates_by_triangle() {
        let mesh = Mesh {
            dimension: 2,
            nodes: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
                [2.0, 0.0, 0.0],
                [2.0, 1.0, 0.0],
            ],
            faces: vec![
                face_of(vec![[0, 1, 2], [0, 2, 3]]),
                face_of(vec![[1, 4, 5], [1, 5, 2]]),
            ],
            subdomains: vec![
                subdomain_of("left", vec![0]),
                subdomain_of("right", vec![1]),
            ],
            ..Mesh::default()
        };
        let locator = Locator::new(&mesh);
        assert_eq!(locator.locate([0.25, 0.5, 0.0]), Some(0));
        assert_eq!(locator.locate([0.5, 0.5, 0.0]), Some(0), "on the diagonal");
        assert_eq!(locator.locate([1.75, 0.5, 0.0]), Some(1));
        assert_eq!(locator.locate([2.5, 0.5, 0.0]), None);
        // On the shared edge x = 1: exactly one side takes it.
        assert!(locator.locate([1.0, 0.5, 0.0]).is_some());
    }
}
