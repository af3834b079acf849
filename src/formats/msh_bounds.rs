//! The bounding surfaces of volume entities made from volume cells (a mesh
//! read from a solver format, not compiled from a model): a surface entity
//! (mesh face) bounds a volume group when its triangles lie on the group's
//! boundary, the cell faces used by one cell of the group. The sign says
//! whether the face's triangles point out of the group (+) or into it (−),
//! as for a subdomain's faces. Gmsh reads these as the volume's boundary
//! (`gmsh.model.getBoundary`), which it needs to mesh the volume again.

use crate::convert::boundary::{faces as cell_faces, key as face_key, used_once};
use crate::mesh::Mesh;
use crate::mesh::volume::cell_volume;

/// A triangle's corners sorted: the same key from either side.
fn key(t: [u32; 3]) -> [u32; 3] {
    let mut k = t;
    k.sort_unstable();
    k
}

/// Whether `t` runs the same way round as `outward`.
fn same_turn(t: [u32; 3], outward: [u32; 3]) -> bool {
    (0..3).any(|r| [t[r], t[(r + 1) % 3], t[(r + 2) % 3]] == outward)
}

/// For each volume group name (first-appearance order), the signed surface
/// tags (mesh face index + 1) of the faces on its boundary, in face order.
/// Deterministic: sorted keys and face order, no hashing.
pub(crate) fn volume_bounding(mesh: &Mesh) -> Vec<(String, Vec<i32>)> {
    let mut names: Vec<&str> = Vec::new();
    for v in &mesh.volumes {
        if !names.contains(&v.name.as_str()) {
            names.push(&v.name);
        }
    }
    if mesh.faces.is_empty() {
        return names
            .into_iter()
            .map(|n| (n.to_string(), Vec::new()))
            .collect();
    }
    names
        .into_iter()
        .map(|name| (name.to_string(), bounding_of(mesh, name)))
        .collect()
}

fn bounding_of(mesh: &Mesh, name: &str) -> Vec<i32> {
    // Every cell face of the group as outward triangles (a quadrilateral by
    // both of its diagonals, since a reader may have split it either way),
    // keyed by its sorted corners; the face's own key tells shared faces.
    let mut faces: Vec<([u32; 4], Vec<[u32; 3]>)> = Vec::new();
    for v in mesh.volumes.iter().filter(|v| v.name == name) {
        for cell in v.cells() {
            let flip = cell_volume(v.kind, &mesh.nodes, cell) < 0.0;
            for f in cell_faces(v.kind) {
                let c: Vec<u32> = f.iter().map(|&i| cell[i]).collect();
                let tris: Vec<[u32; 3]> = match c[..] {
                    [a, b, d] => vec![[a, b, d]],
                    [a, b, d, e] => vec![[a, b, d], [a, d, e], [a, b, e], [b, d, e]],
                    _ => Vec::new(),
                };
                let tris = tris
                    .into_iter()
                    .map(|[a, b, d]| if flip { [a, d, b] } else { [a, b, d] })
                    .collect();
                faces.push((face_key(&c), tris));
            }
        }
    }
    faces.sort_unstable_by_key(|f| f.0);
    let mut boundary: Vec<([u32; 3], [u32; 3])> = used_once(&faces)
        .into_iter()
        .flatten()
        .map(|&t| (key(t), t))
        .collect();
    drop(faces);
    boundary.sort_unstable();
    let mut out = Vec::new();
    for (index, face) in mesh.faces.iter().enumerate() {
        let (mut outward, mut inward) = (0usize, 0usize);
        for &t in &face.triangles {
            let k = key(t);
            let at = boundary.partition_point(|(b, _)| *b < k);
            if let Some(&(b, turn)) = boundary.get(at)
                && b == k
            {
                if same_turn(t, turn) {
                    outward += 1;
                } else {
                    inward += 1;
                }
            }
        }
        if outward + inward > 0 {
            let tag = index as i32 + 1;
            out.push(if outward >= inward { tag } else { -tag });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{CellKind, MeshFace, MeshVolume};

    #[test]
    fn two_tetrahedra_groups_share_their_interface_with_opposite_signs() {
        // Two tetrahedra on the triangle 0 1 2: `low` below it, `high` above.
        let nodes = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, -1.0],
            [0.0, 0.0, 1.0],
        ];
        let face = |name: &str, triangles: Vec<[u32; 3]>| MeshFace {
            name: name.into(),
            triangles,
            boundary: Vec::new(),
        };
        let mesh = Mesh {
            dimension: 3,
            nodes,
            faces: vec![
                // Pointing up (+z): out of `low`, into `high`.
                face("interface", vec![[0, 1, 2]]),
                face("bottom", vec![[0, 1, 3]]),
                face("top", vec![[0, 4, 1]]),
                face("elsewhere", vec![[1, 2, 3], [0, 2, 4]]),
            ],
            volumes: vec![
                MeshVolume {
                    name: "low".into(),
                    kind: CellKind::Tetrahedron,
                    nodes: vec![0, 1, 2, 3],
                },
                MeshVolume {
                    name: "high".into(),
                    kind: CellKind::Tetrahedron,
                    nodes: vec![0, 2, 1, 4],
                },
            ],
            ..Mesh::default()
        };
        let b = volume_bounding(&mesh);
        // Each group's faces: the interface, its own side, and `elsewhere`,
        // which has a triangle on each.
        assert_eq!(b[0].0, "low");
        assert_eq!(b[1].0, "high");
        assert_eq!(
            b[0].1.iter().map(|t| t.abs()).collect::<Vec<_>>(),
            [1, 2, 4]
        );
        assert_eq!(
            b[1].1.iter().map(|t| t.abs()).collect::<Vec<_>>(),
            [1, 3, 4]
        );
        assert_eq!(b[0].1[0], 1, "the interface points out of `low`");
        assert_eq!(b[1].1[0], -1, "and into `high`");
    }
}
