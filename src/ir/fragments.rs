//! Boundary fragments Γ_{k,k'} derived from M_FD: faces (edges, in 2D)
//! between two subdomains are interface fragments, faces of one subdomain only
//! belong to its outer boundary Γ_{k,0}.

use super::{Dimension, EdgeId, FaceId, Model, SubdomainCells, SubdomainId};
use std::collections::BTreeMap;

/// The other side of a fragment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub enum Side {
    Exterior,
    Subdomain(SubdomainId),
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Fragment {
    /// The user's <boundary> name when one names these faces, else
    /// "A|B" from the subdomain names ("A|exterior" for the outer boundary).
    pub name: String,
    /// The lower-numbered subdomain of the pair (k < k'), or the only one for
    /// an outer fragment.
    pub subdomain: SubdomainId,
    /// The exterior, or the higher-numbered subdomain k'.
    pub other: Side,
    /// Faces of the fragment (3D), sorted.
    pub faces: Vec<FaceId>,
    /// Edges of the fragment (2D), sorted.
    pub edges: Vec<EdgeId>,
}

/// Fragments grouped by (subdomain pair, boundary name), ordered by subdomain,
/// then other side, then name: deterministic for the same model.
///
/// A face (edge) bounding more than two subdomains belongs to no fragment: it
/// is an error the validator reports (E406). When several <boundary> elements
/// name one face, the first in model order gives the name.
pub fn derive_fragments(model: &Model) -> Vec<Fragment> {
    let sides = match model.dimension {
        Dimension::Three => face_sides(model),
        Dimension::Two => edge_sides(model),
    };

    // Which user boundary names each face (edge): the first one wins.
    let mut names: BTreeMap<u32, &str> = BTreeMap::new();
    for boundary in &model.boundaries {
        let ids: Vec<u32> = match model.dimension {
            Dimension::Three => boundary.faces.iter().map(|f| f.0).collect(),
            Dimension::Two => boundary.edges.iter().map(|e| e.0).collect(),
        };
        for id in ids {
            names.entry(id).or_insert(boundary.name.as_str());
        }
    }

    let subdomain_name = |id: SubdomainId| {
        model
            .subdomains
            .get(id.index())
            .map_or_else(|| format!("#{}", id.0), |s| s.name.clone())
    };

    // Grouped first by the user's name, or none for the default name: a
    // name string per face (edge) was most of this on a 10,000-edge polygon.
    let mut by_pair: BTreeMap<(SubdomainId, Side, Option<&str>), Vec<u32>> = BTreeMap::new();
    for (id, sides) in (0u32..).zip(&sides) {
        let (k, other) = match sides.pair() {
            Some(&[k]) => (k, Side::Exterior),
            Some(&[k, k2]) => (k, Side::Subdomain(k2)),
            _ => continue,
        };
        let name = names.get(&id).copied();
        by_pair.entry((k, other, name)).or_default().push(id);
    }
    let mut groups: BTreeMap<(SubdomainId, Side, String), Vec<u32>> = BTreeMap::new();
    for ((k, other, name), ids) in by_pair {
        let name = match name {
            Some(name) => name.to_string(),
            None => match other {
                Side::Exterior => format!("{}|exterior", subdomain_name(k)),
                Side::Subdomain(k2) => format!("{}|{}", subdomain_name(k), subdomain_name(k2)),
            },
        };
        // A user name equal to a default one is one group, as before.
        let group = groups.entry((k, other, name)).or_default();
        let merged = !group.is_empty();
        group.extend(ids);
        if merged {
            group.sort_unstable();
        }
    }

    groups
        .into_iter()
        .map(|((subdomain, other, name), ids)| {
            // Ascending: BTreeMap iteration, or sorted when merged.
            let (faces, edges) = match model.dimension {
                Dimension::Three => (ids.into_iter().map(FaceId).collect(), Vec::new()),
                Dimension::Two => (Vec::new(), ids.into_iter().map(EdgeId).collect()),
            };
            Fragment {
                name,
                subdomain,
                other,
                faces,
                edges,
            }
        })
        .collect()
}

/// The subdomains on the sides of one face (edge): the first two, in
/// ascending order, and how many there are. Fixed size, kept in a table
/// indexed by face (edge): a map with a list per edge was a third of this
/// function on a 10,000-edge polygon.
#[derive(Clone, Copy)]
struct Sides {
    first: [SubdomainId; 2],
    count: usize,
}

impl Sides {
    const NONE: Sides = Sides {
        first: [SubdomainId(0); 2],
        count: 0,
    };

    /// Adds subdomain k: subdomains come in ascending order, so a repeat is
    /// the last one added.
    fn push(&mut self, k: SubdomainId) {
        if self.count > 0 && self.first[(self.count - 1).min(1)] == k {
            return;
        }
        if let Some(slot) = self.first.get_mut(self.count) {
            *slot = k;
        }
        self.count += 1;
    }

    /// The lone subdomain or the pair; `None` for no side or more than two.
    fn pair(&self) -> Option<&[SubdomainId]> {
        self.first.get(..self.count)
    }
}

/// For every face (by index), the subdomains whose Volume boundary lists it.
fn face_sides(model: &Model) -> Vec<Sides> {
    let mut sides = vec![Sides::NONE; model.faces.len()];
    for (k, subdomain) in model.subdomains.iter().enumerate() {
        if let SubdomainCells::Volume { boundary } = &subdomain.cells {
            for of in boundary {
                if let Some(slot) = sides.get_mut(of.face.index()) {
                    slot.push(SubdomainId(k as u32));
                }
            }
        }
    }
    sides
}

/// For every edge (by index), the region subdomains it bounds. An edge lies
/// on region k's boundary when exactly one face of k uses it; one shared by
/// two faces of k is inside k and bounds nothing.
fn edge_sides(model: &Model) -> Vec<Sides> {
    let mut sides = vec![Sides::NONE; model.edges.len()];
    // Per edge: the faces of the current subdomain using it, and the last
    // face that counted it (a face using an edge twice counts once).
    let mut uses = vec![0usize; model.edges.len()];
    let mut counted_by = vec![usize::MAX; model.edges.len()];
    let mut touched: Vec<usize> = Vec::new();
    for (k, subdomain) in model.subdomains.iter().enumerate() {
        let SubdomainCells::Region { faces } = &subdomain.cells else {
            continue;
        };
        let mut distinct: Vec<usize> = faces.iter().map(|f| f.index()).collect();
        distinct.sort_unstable();
        distinct.dedup();
        for f in distinct {
            let Some(face) = model.faces.get(f) else {
                continue;
            };
            for oe in face.loops.iter().flatten() {
                let e = oe.edge.index();
                if e < model.edges.len() && counted_by[e] != f {
                    counted_by[e] = f;
                    if uses[e] == 0 {
                        touched.push(e);
                    }
                    uses[e] += 1;
                }
            }
        }
        // In edge order, as the sides of each edge come in subdomain order.
        touched.sort_unstable();
        for &e in &touched {
            if uses[e] == 1 {
                sides[e].push(SubdomainId(k as u32));
            }
            uses[e] = 0;
            counted_by[e] = usize::MAX;
        }
        touched.clear();
    }
    sides
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ir::Boundary;
    use crate::valid::fixtures::{Builder, cube};

    fn face_named(model: &Model, name: &str) -> FaceId {
        FaceId(
            model
                .faces
                .iter()
                .position(|f| f.name == name)
                .unwrap_or(99) as u32,
        )
    }

    fn summary(fragments: &[Fragment]) -> Vec<(String, u32, Side, usize, usize)> {
        fragments
            .iter()
            .map(|f| {
                (
                    f.name.clone(),
                    f.subdomain.0,
                    f.other,
                    f.faces.len(),
                    f.edges.len(),
                )
            })
            .collect()
    }

    #[test]
    fn one_cube_has_one_outer_fragment() {
        let b = cube();
        let fragments = derive_fragments(&b.model);
        assert_eq!(
            summary(&fragments),
            [("box|exterior".into(), 0, Side::Exterior, 6, 0)]
        );
        assert_eq!(fragments[0].faces, (0..6).map(FaceId).collect::<Vec<_>>());
    }

    fn two_cubes() -> Builder {
        let mut b = Builder::new(Dimension::Three);
        b.unit_box("A", [0.0; 3]);
        b.unit_box("B", [1.0, 0.0, 0.0]);
        b
    }

    #[test]
    fn two_cubes_share_an_interface() {
        let b = two_cubes();
        let fragments = derive_fragments(&b.model);
        let b_side = Side::Subdomain(SubdomainId(1));
        assert_eq!(
            summary(&fragments),
            [
                ("A|exterior".into(), 0, Side::Exterior, 5, 0),
                ("A|B".into(), 0, b_side, 1, 0),
                ("B|exterior".into(), 1, Side::Exterior, 5, 0),
            ]
        );
        assert_eq!(fragments[1].faces, [face_named(&b.model, "A.right")]);
    }

    #[test]
    fn named_boundary_splits_the_outer_fragment() {
        let mut b = two_cubes();
        let inlet = face_named(&b.model, "A.left");
        // A stray face in no subdomain makes no fragment, even when named.
        let stray = b
            .polygon("stray", &[[5., 5., 5.], [6., 5., 5.], [6., 6., 5.]])
            .face;
        b.model.boundaries.push(Boundary {
            name: "inlet".into(),
            faces: vec![inlet, stray],
            edges: Vec::new(),
        });
        b.model.boundaries.push(Boundary {
            name: "later".into(),
            faces: vec![inlet],
            edges: Vec::new(),
        });
        let fragments = derive_fragments(&b.model);
        let b_side = Side::Subdomain(SubdomainId(1));
        assert_eq!(
            summary(&fragments),
            [
                ("A|exterior".into(), 0, Side::Exterior, 4, 0),
                ("inlet".into(), 0, Side::Exterior, 1, 0),
                ("A|B".into(), 0, b_side, 1, 0),
                ("B|exterior".into(), 1, Side::Exterior, 5, 0),
            ]
        );
        assert_eq!(fragments[1].faces, [inlet]);
    }

    #[test]
    fn two_squares_share_one_edge() {
        let mut b = Builder::new(Dimension::Two);
        b.unit_square("A", 0.0, 0.0);
        b.unit_square("B", 1.0, 0.0);
        let fragments = derive_fragments(&b.model);
        let b_side = Side::Subdomain(SubdomainId(1));
        assert_eq!(
            summary(&fragments),
            [
                ("A|exterior".into(), 0, Side::Exterior, 0, 3),
                ("A|B".into(), 0, b_side, 0, 1),
                ("B|exterior".into(), 1, Side::Exterior, 0, 3),
            ]
        );
        // The shared edge runs (1,0) → (1,1): the second edge of A's loop.
        assert_eq!(fragments[1].edges, [b.model.faces[0].loops[0][1].edge]);
    }

    #[test]
    fn edge_inside_one_region_bounds_nothing() {
        let mut b = Builder::new(Dimension::Two);
        let left = b.polygon(
            "l",
            &[[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
        );
        let right = b.polygon(
            "r",
            &[[1., 0., 0.], [2., 0., 0.], [2., 1., 0.], [1., 1., 0.]],
        );
        let faces = vec![left.face, right.face];
        b.push_subdomain("A", crate::ir::SubdomainCells::Region { faces });
        b.model.boundaries.push(Boundary {
            name: "wall".into(),
            faces: Vec::new(),
            edges: vec![EdgeId(0)],
        });
        let fragments = derive_fragments(&b.model);
        assert_eq!(
            summary(&fragments),
            [
                ("A|exterior".into(), 0, Side::Exterior, 0, 5),
                ("wall".into(), 0, Side::Exterior, 0, 1),
            ]
        );
    }
}
