//! The boundary surface of a volume mesh, for surface formats given volume
//! cells only (an MSH or VTU of tetrahedra): the cell faces used by exactly
//! one cell, oriented out of their cell, one mesh face per volume group.
//! Faces shared by two cells (also across groups) are inside and left out.

use crate::mesh::volume::cell_volume;
use crate::mesh::{CellKind, Mesh, MeshFace};

/// What [`extract`] added.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Boundary {
    pub triangles: usize,
    pub groups: usize,
}

/// Each cell face's corners, outward for a cell of positive volume (Gmsh's
/// corner order); quadrilaterals are split along their first diagonal.
pub(crate) fn faces(kind: CellKind) -> &'static [&'static [usize]] {
    match kind {
        CellKind::Tetrahedron => &[&[0, 2, 1], &[0, 1, 3], &[1, 2, 3], &[0, 3, 2]],
        CellKind::Hexahedron => &[
            &[0, 3, 2, 1],
            &[4, 5, 6, 7],
            &[0, 1, 5, 4],
            &[1, 2, 6, 5],
            &[2, 3, 7, 6],
            &[3, 0, 4, 7],
        ],
        CellKind::Wedge => &[
            &[0, 2, 1],
            &[3, 4, 5],
            &[0, 1, 4, 3],
            &[1, 2, 5, 4],
            &[2, 0, 3, 5],
        ],
        CellKind::Pyramid => &[
            &[0, 3, 2, 1],
            &[0, 1, 4],
            &[1, 2, 4],
            &[2, 3, 4],
            &[3, 0, 4],
        ],
    }
}

/// A face's corners sorted (a triangle's fourth slot `u32::MAX`): the same
/// key for the face seen from either of its cells.
pub(crate) fn key(corners: &[u32]) -> [u32; 4] {
    let mut k = [u32::MAX; 4];
    k[..corners.len()].copy_from_slice(corners);
    k.sort_unstable();
    k
}

/// The values of the keys that stand once in `sorted` (sorted by key): the
/// faces used by one cell only.
pub(crate) fn used_once<T>(sorted: &[([u32; 4], T)]) -> Vec<&T> {
    sorted
        .chunk_by(|a, b| a.0 == b.0)
        .filter_map(|run| match run {
            [(_, only)] => Some(only),
            _ => None,
        })
        .collect()
}

/// Adds the boundary of the volume cells as mesh faces named after their
/// volume groups (in first-appearance order). The mesh must have passed the
/// writers' check (indices in range). Deterministic: no hashing, faces in
/// cell order.
pub fn extract(mesh: &mut Mesh) -> Boundary {
    // Every cell face once, with its running number, sorted by corners.
    let mut keyed: Vec<([u32; 4], u32)> = Vec::new();
    for v in &mesh.volumes {
        for cell in v.cells() {
            for f in faces(v.kind) {
                let corners: Vec<u32> = f.iter().map(|&i| cell[i]).collect();
                keyed.push((key(&corners), keyed.len() as u32));
            }
        }
    }
    keyed.sort_unstable();
    let mut boundary = vec![false; keyed.len()];
    for &id in used_once(&keyed) {
        boundary[id as usize] = true;
    }
    drop(keyed);

    let mut names: Vec<String> = Vec::new();
    let mut groups: Vec<Vec<[u32; 3]>> = Vec::new();
    let mut id = 0usize;
    for v in &mesh.volumes {
        let g = match names.iter().position(|n| *n == v.name) {
            Some(g) => g,
            None => {
                names.push(v.name.clone());
                groups.push(Vec::new());
                names.len() - 1
            }
        };
        for cell in v.cells() {
            // A cell with its corners in mirrored order has inward faces.
            let flip = cell_volume(v.kind, &mesh.nodes, cell) < 0.0;
            for f in faces(v.kind) {
                if boundary[id] {
                    let c: Vec<u32> = f.iter().map(|&i| cell[i]).collect();
                    for k in 1..c.len() - 1 {
                        let t = [c[0], c[k], c[k + 1]];
                        groups[g].push(if flip { [t[0], t[2], t[1]] } else { t });
                    }
                }
                id += 1;
            }
        }
    }
    let mut added = Boundary::default();
    for (name, triangles) in names.into_iter().zip(groups) {
        if triangles.is_empty() {
            continue;
        }
        added.triangles += triangles.len();
        added.groups += 1;
        mesh.faces.push(MeshFace {
            name,
            triangles,
            boundary: Vec::new(),
        });
    }
    added
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::volume::MeshVolume;

    fn cube() -> Vec<[f64; 3]> {
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ]
    }

    /// The enclosed volume by the divergence theorem: positive when every
    /// triangle faces outward.
    fn enclosed(mesh: &Mesh) -> f64 {
        let p = |n: u32| mesh.nodes[n as usize];
        mesh.faces
            .iter()
            .flat_map(|f| &f.triangles)
            .map(|&[a, b, c]| {
                let (a, b, c) = (p(a), p(b), p(c));
                (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                    + a[2] * (b[0] * c[1] - b[1] * c[0]))
                    / 6.0
            })
            .sum()
    }

    #[test]
    fn every_cell_kind_alone_gives_its_closed_outward_surface() {
        for (kind, cell, triangles, volume) in [
            (CellKind::Tetrahedron, vec![0, 1, 3, 4], 4, 1.0 / 6.0),
            (CellKind::Hexahedron, vec![0, 1, 2, 3, 4, 5, 6, 7], 12, 1.0),
            (CellKind::Wedge, vec![0, 1, 3, 4, 5, 7], 8, 0.5),
            (CellKind::Pyramid, vec![0, 1, 2, 3, 6], 6, 1.0 / 3.0),
        ] {
            let mut mesh = Mesh {
                dimension: 3,
                nodes: cube(),
                volumes: vec![MeshVolume {
                    name: "v".into(),
                    kind,
                    nodes: cell,
                }],
                ..Mesh::default()
            };
            let b = extract(&mut mesh);
            assert_eq!(
                b,
                Boundary {
                    triangles,
                    groups: 1
                },
                "{kind:?}"
            );
            assert!(
                (enclosed(&mesh) - volume).abs() < 1e-12,
                "{kind:?}: {}",
                enclosed(&mesh)
            );
        }
    }

    #[test]
    fn shared_faces_are_inside_and_groups_keep_their_names() {
        // The cube as five tetrahedra (one of them mirrored), in two groups.
        let tets: [[u32; 4]; 5] = [
            [0, 1, 3, 4],
            [1, 2, 3, 6],
            [1, 6, 4, 5],
            [3, 4, 6, 7],
            [1, 3, 6, 4],
        ];
        let mut left: Vec<u32> = tets[..2].iter().flatten().copied().collect();
        let mut right: Vec<u32> = tets[2..].iter().flatten().copied().collect();
        left.swap(0, 1); // mirrored: [1, 0, 3, 4]
        right.swap(0, 1);
        let mut mesh = Mesh {
            dimension: 3,
            nodes: cube(),
            volumes: vec![
                MeshVolume {
                    name: "left".into(),
                    kind: CellKind::Tetrahedron,
                    nodes: left,
                },
                MeshVolume {
                    name: "right".into(),
                    kind: CellKind::Tetrahedron,
                    nodes: right,
                },
            ],
            ..Mesh::default()
        };
        let b = extract(&mut mesh);
        // Six square sides, two triangles each; the middle tetrahedron has no
        // face on the boundary.
        assert_eq!(
            b,
            Boundary {
                triangles: 12,
                groups: 2
            }
        );
        let names: Vec<&str> = mesh.faces.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(names, ["left", "right"]);
        assert_eq!(mesh.faces[0].triangles.len(), 6);
        assert_eq!(mesh.faces[1].triangles.len(), 6);
        assert!((enclosed(&mesh) - 1.0).abs() < 1e-12, "{}", enclosed(&mesh));
    }
}
