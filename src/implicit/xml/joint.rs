//! Function subdomains that touch (a pin in a hole carved out of a block)
//! are meshed together by `implicit::interfaces` on one grid over the union
//! of their boxes, so the surface between two of them is meshed once: one
//! face `A_B_interface` listed by both subdomains (outward for A, the
//! earlier one) and the fragment `A|B`; the rest of each boundary is the
//! face `NAME_boundary` with the fragment `NAME|exterior`, as for a lone
//! subdomain, and where a member reaches the joint grid's box, the surface
//! closing it next to the box is `NAME_box_cap` with `NAME|box`.

use super::{ImplicitSolid, ImplicitSubdomain};
use crate::implicit::interfaces::{self, Interfaces};
use crate::implicit::joint_optimize::optimize_joint;
use crate::implicit::polygonize::Grid;
use crate::implicit::push_boundary;
use crate::mesh::{Mesh, MeshFace, MeshFragment};

/// The touching subdomains and their labelled surfaces (label m + 1 is
/// `members[m]`).
#[derive(Debug, Clone)]
pub struct Joint {
    pub members: Vec<usize>,
    pub grid: Grid,
    pub interfaces: Interfaces,
}

impl Joint {
    fn label(&self, subdomain: usize) -> Option<u32> {
        let m = self.members.iter().position(|&s| s == subdomain)?;
        Some(m as u32 + 1)
    }

    /// The closed boundary of one member, oriented outward (for sections).
    pub fn boundary_of(&self, subdomain: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let Some(l) = self.label(subdomain) else {
            return Default::default();
        };
        let mut triangles = Vec::new();
        for p in &self.interfaces.patches {
            if p.pair.0 == l {
                triangles.extend_from_slice(&p.triangles);
            } else if p.pair.1 == l {
                triangles.extend(p.triangles.iter().map(|t| [t[0], t[2], t[1]]));
            }
        }
        (self.interfaces.positions.clone(), triangles)
    }
}

/// Meshes the function subdomains together when at least two of them
/// touch; `None` when none do (each is then meshed on its own).
pub fn mesh_touching(subdomains: &[ImplicitSubdomain], cells: Option<usize>) -> Option<Joint> {
    let models: Vec<(usize, &crate::implicit::ImplicitModel)> = subdomains
        .iter()
        .enumerate()
        .filter_map(|(i, s)| match &s.solid {
            ImplicitSolid::Function(m) => Some((i, m)),
            ImplicitSolid::Samples { .. } => None,
        })
        .collect();
    if models.len() < 2 {
        return None;
    }
    // Only worth the joint grid when some two boxes meet.
    let meet = |a: &crate::implicit::Geom, b: &crate::implicit::Geom| {
        (0..3).all(|k| a.min[k] <= b.max[k] && b.min[k] <= a.max[k])
    };
    let any_meet = models
        .iter()
        .enumerate()
        .any(|(x, a)| models[x + 1..].iter().any(|b| meet(&a.1.geom, &b.1.geom)));
    if !any_meet {
        return None;
    }
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    let mut spacing = [f64::INFINITY; 3];
    for (_, m) in &models {
        let g = &m.geom;
        for k in 0..3 {
            min[k] = min[k].min(g.min[k]);
            max[k] = max[k].max(g.max[k]);
            let n = cells.unwrap_or(g.cells[k]).max(1);
            spacing[k] = spacing[k].min((g.max[k] - g.min[k]) / n as f64);
        }
    }
    let grid = Grid {
        min,
        max,
        cells: std::array::from_fn(|k| {
            let n = ((max[k] - min[k]) / spacing[k] - 1e-9).ceil();
            if n.is_finite() && n >= 1.0 {
                n as usize
            } else {
                1
            }
        }),
    };
    let solids: Vec<interfaces::Solid> = models
        .iter()
        .map(|(_, m)| interfaces::Solid {
            ssa: m.ssa(),
            min: m.geom.min,
            max: m.geom.max,
        })
        .collect();
    let mut interfaces = interfaces::polygonize_labels(&solids, &grid);
    if !interfaces.touching() {
        return None;
    }
    // The members' optimisation rounds (the most any of them asks for).
    let iterations = models.iter().map(|(_, m)| m.geom.optiterations).max();
    let spacing = spacing.iter().copied().fold(f64::INFINITY, f64::min);
    optimize_joint(
        &mut interfaces,
        &solids,
        |a, b| interfaces::deciding_solid(a, b, solids.len()),
        spacing,
        iterations.unwrap_or(0),
    );
    Some(Joint {
        members: models.iter().map(|(i, _)| *i).collect(),
        grid,
        interfaces,
    })
}

/// Adds a box cap face `NAME_box_cap` with its fragment `NAME|box`.
fn push_cap(mesh: &mut Mesh, subdomain: u32, name: &str, triangles: Vec<[u32; 3]>) {
    let face = mesh.faces.len() as u32;
    mesh.faces.push(MeshFace {
        name: format!("{name}_box_cap"),
        triangles,
        boundary: Vec::new(),
    });
    if let Some(s) = mesh.subdomains.get_mut(subdomain as usize) {
        s.faces.push((face, true));
    }
    mesh.fragments.push(MeshFragment {
        name: format!("{name}|box"),
        subdomain,
        other: None,
        faces: vec![face],
        edges: Vec::new(),
    });
}

/// Adds the joint surfaces to `mesh` (whose subdomains `first..` are
/// `subdomains`); returns the triangles on each subdomain's boundary.
pub fn add(
    mesh: &mut Mesh,
    joint: &Joint,
    subdomains: &[ImplicitSubdomain],
    first: u32,
) -> Vec<usize> {
    let mut counts = vec![0; subdomains.len()];
    let base = mesh.nodes.len() as u32;
    mesh.nodes.extend_from_slice(&joint.interfaces.positions);
    for patch in &joint.interfaces.patches {
        let (a, b) = patch.pair;
        let face = mesh.faces.len() as u32;
        let shifted = patch.triangles.iter().map(|t| t.map(|v| v + base));
        let Some(&sb) = joint.members.get(b as usize - 1) else {
            continue;
        };
        if a == 0 {
            // Normals point into b: reversed, they point out of it.
            let name = &subdomains[sb].name;
            let reversed = shifted.map(|t| [t[0], t[2], t[1]]).collect();
            if patch.cap {
                push_cap(mesh, first + sb as u32, name, reversed);
            } else {
                push_boundary(mesh, first + sb as u32, name, reversed, Vec::new());
            }
            counts[sb] += patch.triangles.len();
            continue;
        }
        let sa = joint.members[a as usize - 1];
        let (na, nb) = (&subdomains[sa].name, &subdomains[sb].name);
        mesh.faces.push(MeshFace {
            name: format!("{na}_{nb}_interface"),
            triangles: shifted.collect(),
            boundary: Vec::new(),
        });
        mesh.subdomains[first as usize + sa]
            .faces
            .push((face, true));
        mesh.subdomains[first as usize + sb]
            .faces
            .push((face, false));
        mesh.fragments.push(MeshFragment {
            name: format!("{na}|{nb}"),
            subdomain: first + sa as u32,
            other: Some(first + sb as u32),
            faces: vec![face],
            edges: Vec::new(),
        });
        counts[sa] += patch.triangles.len();
        counts[sb] += patch.triangles.len();
    }
    counts
}
