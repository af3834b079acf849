//! Subdomains: boolean trees of solids whose boundaries are disjoint, nested
//! or share whole faces. Each face of each leaf solid is classified by
//! evaluating the tree on its two sides; it bounds the subdomain when the
//! sides differ. Crossing boundaries and overlapping subdomains are reported.

use super::Entities;
use super::explicit::{lookup_entities, unknown_entity};
use super::leaves::Leaves;
use super::weld::FaceSamples;
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::doc::{SolidTree, SubdomainDef};
use crate::geom::{Point3, Surface, Vec3, boundary_relation};
use crate::ir::{
    Carrier, Dimension, EdgeId, Face, FaceId, Model, OrientedEdge, OrientedFace, Origin, SolidId,
    SourceMap, Subdomain, SubdomainCells, SubdomainId,
};
use crate::resolve::{Geometry, Resolved};
use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// A boolean tree over leaf solids (indices into `leaves`).
#[derive(Debug, Clone)]
enum Tree {
    Leaf(usize),
    Union(Vec<Tree>),
    Intersection(Vec<Tree>),
    Difference(Vec<Tree>),
}

impl Tree {
    fn eval(&self, inside: &dyn Fn(usize) -> bool) -> bool {
        match self {
            Tree::Leaf(i) => inside(*i),
            Tree::Union(ops) => ops.iter().any(|t| t.eval(inside)),
            Tree::Intersection(ops) => ops.iter().all(|t| t.eval(inside)),
            Tree::Difference(ops) => {
                ops.first().is_some_and(|t| t.eval(inside))
                    && !ops.iter().skip(1).any(|t| t.eval(inside))
            }
        }
    }
}

struct Built {
    tree: Tree,
    leaves: Leaves,
    /// The subdomain element, for messages.
    span: crate::span::Span,
}

/// The subdomains' solid trees, built by [`build_subdomains`] and checked
/// and classified by [`check_subdomains`].
pub(super) struct Trees(Vec<(SubdomainId, Built)>);

/// Lowers the subdomain definitions: a subdomain given by faces gets its
/// shell, one given by a solid tree gets an empty boundary until
/// [`check_subdomains`] classifies its faces. Split in two so the caller can
/// drop the definitions and the resolved objects before the checks.
pub(super) fn build_subdomains(
    defs: Vec<SubdomainDef>,
    resolved: &Resolved,
    model: &mut Model,
    source_map: &mut SourceMap,
    entities: &Entities,
    diags: &mut Diagnostics,
) -> Trees {
    let first = model.subdomains.len();
    let mut made = 0;
    let shared: &Model = model;
    // The solid trees are looked up on the workers (names, each object's
    // solids: hash lookups and cache misses per subdomain), a slot per
    // definition, in order. The slots' vector becomes the trees' (in place),
    // so it costs what the trees' own vector did. Their findings are put
    // back below where the definition's lowering reports them.
    let (mut looked_up, found) = look_up_trees(&defs, resolved, shared, entities);
    source_map
        .subdomains
        .reserve(first + defs.len(), defs.len());
    let mut found = found.into_iter().peekable();
    // Consumed: each definition is dropped once lowered, so none is alive
    // during the overlap check (the memory peak on large files). Collected
    // from the consumed definitions, so the standard library builds the
    // subdomains in the definitions' own allocation (a `Subdomain` is no
    // larger than a `SubdomainDef`, test `subdomains_fit_in_their_definitions`):
    // the two vectors, tens of megabytes on large files, are never allocated
    // side by side at the end of this loop, the lowering's memory peak.
    let subdomains: Vec<Subdomain> = (defs.into_iter().enumerate())
        .filter_map(|(def_index, def)| {
            let model = shared;
            let id = SubdomainId((first + made) as u32);
            while let Some((_, d)) = found.next_if(|(k, _)| *k == def_index) {
                diags.push(d);
            }
            let mut trimmed_faces = Vec::new();
            let cells = match (def.faces.as_deref(), &def.tree) {
                (Some(_), Some(_)) => {
                    diags.push(
                        Diagnostic::new(
                            Code::ConflictingForms,
                            def.span,
                            format!("subdomain '{}' has both faces= and a solid", def.name.text),
                        )
                        .with_help("give either the faces that bound it or a solid tree"),
                    );
                    return None;
                }
                (Some((refs, _)), None) => match explicit_shell(model, entities, refs, diags) {
                    Some((boundary, trimmed)) => {
                        trimmed_faces = trimmed;
                        SubdomainCells::Volume { boundary }
                    }
                    None => return None,
                },
                (None, Some(_)) => {
                    // Empty when the lookup failed (already reported).
                    looked_up[def_index].as_mut()?.0 = id;
                    SubdomainCells::Volume {
                        boundary: Vec::new(),
                    }
                }
                (None, None) => {
                    diags.push(
                        Diagnostic::new(
                            Code::MissingElement,
                            def.span,
                            format!(
                                "subdomain '{}' has neither faces= nor a solid",
                                def.name.text
                            ),
                        )
                        .with_help("add faces=\"…\" or a child such as <solid ref=\"…\"/>"),
                    );
                    return None;
                }
            };
            source_map.subdomains.insert(id, Origin { span: def.span });
            made += 1;
            Some(Subdomain {
                name: def.name.text,
                material: def.material,
                cells,
                solids: Box::default(),
                max_area: resolved.subdomain_areas.get(def_index).copied().flatten(),
                trimmed: trimmed_faces,
            })
        })
        .collect();
    if model.subdomains.is_empty() {
        model.subdomains = subdomains;
    } else {
        model.subdomains.extend(subdomains);
    }
    // In place (`flatten` would collect into a new vector): every filled
    // slot is a tree-form definition that became a subdomain and has its id.
    #[allow(clippy::filter_map_identity)]
    let trees = looked_up.into_iter().filter_map(|slot| slot).collect();
    Trees(trees)
}

/// Definitions per task of [`look_up_trees`].
pub(super) const DEFINITIONS_PER_TASK: usize = 256;

/// The solid trees of the tree-form definitions (neither `faces=` nor a
/// missing form), a slot per definition (`None` also when the lookup failed;
/// the ids are set by the caller), and the lookups' diagnostics by definition
/// index, in the order one definition after another reports them.
#[allow(clippy::type_complexity)]
fn look_up_trees(
    defs: &[SubdomainDef],
    resolved: &Resolved,
    model: &Model,
    entities: &Entities,
) -> (Vec<Option<(SubdomainId, Built)>>, Vec<(usize, Diagnostic)>) {
    let found = std::sync::Mutex::new(Vec::new());
    let looked_up = (defs.par_iter().enumerate())
        .with_min_len(DEFINITIONS_PER_TASK)
        .map(|(k, def)| {
            let (None, Some(tree)) = (&def.faces, &def.tree) else {
                return None;
            };
            let (mut leaves, mut local) = (Leaves::default(), Diagnostics::default());
            let tree = build_tree(tree, resolved, model, entities, &mut leaves, &mut local);
            if !local.items.is_empty() {
                let mut all = found.lock().unwrap_or_else(|e| e.into_inner());
                all.extend(local.items.into_iter().map(|d| (k, d)));
            }
            let built = Built {
                tree: tree?,
                leaves,
                span: def.span,
            };
            Some((SubdomainId(u32::MAX), built))
        })
        .collect();
    let mut found = found.into_inner().unwrap_or_else(|e| e.into_inner());
    // Stable: one definition's findings were added together, in order.
    found.sort_by_key(|(k, _)| *k);
    (looked_up, found)
}

/// Checks the relations of the subdomains' solids (crossing boundaries,
/// overlaps) and classifies each solid tree's faces into its boundary.
pub(super) fn check_subdomains(
    trees: Trees,
    model: &mut Model,
    source_map: &SourceMap,
    face_samples: &FaceSamples,
    overlapping: Option<super::isolation::Overlapping>,
    diags: &mut Diagnostics,
) {
    let Trees(trees) = trees;
    let Some(leaf_pairs) = check_relations(model, source_map, &trees, overlapping, diags) else {
        return;
    };
    // 3D: every tree's faces classified on the workers (reading the model
    // only), in order; 2D regions add faces to the model, one by one below.
    let shared: &Model = model;
    let mut boundaries = match model.dimension {
        Dimension::Three => (trees.par_iter())
            .with_min_len(DEFINITIONS_PER_TASK)
            .map(|(_, built)| classify_faces(shared, built, face_samples))
            .collect(),
        Dimension::Two => Vec::new(),
    }
    .into_iter();
    for (id, built) in &trees {
        let cells = match model.dimension {
            Dimension::Three => SubdomainCells::Volume {
                boundary: boundaries.next().unwrap_or_default(),
            },
            Dimension::Two => {
                let edges = classify_edges(model, built);
                let face = region_face(model, &model.subdomain(*id).name.clone(), &edges);
                SubdomainCells::Region {
                    faces: face.into_iter().collect(),
                }
            }
        };
        let empty = match &cells {
            SubdomainCells::Volume { boundary } => boundary.is_empty(),
            SubdomainCells::Region { faces } => faces.is_empty(),
        };
        if empty {
            let span = built.span;
            diags.push(
                Diagnostic::new(Code::EmptySubdomain, span, format!("subdomain '{}' is empty: its solids leave no volume", model.subdomain(*id).name))
                    .with_help("check the boolean tree: an intersection of disjoint solids, or a difference that removes everything"),
            );
        }
        let subdomain = &mut model.subdomains[id.index()];
        subdomain.cells = cells;
        subdomain.solids = (*built.leaves).into();
    }
    check_overlaps(model, source_map, &trees, face_samples, leaf_pairs, diags);
}

fn build_tree(
    tree: &SolidTree,
    resolved: &Resolved,
    model: &Model,
    entities: &Entities,
    leaves: &mut Leaves,
    diags: &mut Diagnostics,
) -> Option<Tree> {
    let operands =
        |ops: &[SolidTree], leaves: &mut Leaves, diags: &mut Diagnostics| -> Option<Vec<Tree>> {
            let built: Vec<Option<Tree>> = ops
                .iter()
                .map(|t| build_tree(t, resolved, model, entities, leaves, diags))
                .collect();
            built.into_iter().collect()
        };
    Some(match tree {
        SolidTree::Union(ops, _) => Tree::Union(operands(ops, leaves, diags)?),
        SolidTree::Intersection(ops, _) => Tree::Intersection(operands(ops, leaves, diags)?),
        SolidTree::Difference(ops, _) => Tree::Difference(operands(ops, leaves, diags)?),
        SolidTree::Solid(r) => {
            let last = resolved.by_name.get(&resolved.objects, r.name());
            let Some(object) = last.and_then(|i| resolved.objects.get(i)) else {
                let names = resolved
                    .objects
                    .iter()
                    .filter(|o| {
                        matches!(
                            o.geometry,
                            Some(Geometry::Solid(_)) | Some(Geometry::Group(_))
                        )
                    })
                    .map(|o| o.name.as_str());
                let mut d = Diagnostic::new(
                    Code::UndefinedName,
                    r.span,
                    format!("undefined solid '{}'", r.name()),
                );
                d.help = Some(match crate::diag::did_you_mean(r.name(), names) {
                    Some(best) => format!("did you mean '{best}'?"),
                    None => {
                        "name a sphere, parallelepiped, truncated_cone, ellipsoid or torus".into()
                    }
                });
                diags.push(d);
                return None;
            };
            let geometry = object.geometry.as_ref()?;
            let group_members = match geometry {
                Geometry::Group(members) => Some(members.len()),
                _ => None,
            };
            let found = (entities.solids).of(resolved, r.name(), last, r.index, group_members);
            let member_geometry = match (geometry, r.index) {
                (Geometry::Group(members), Some(k)) => members.get(k.wrapping_sub(1)),
                (Geometry::Group(members), None) => members.first(),
                (g, _) => Some(g),
            };
            let Some(first) = found.first() else {
                let d = match (geometry, r.index, member_geometry) {
                    (Geometry::Group(members), Some(k), None) => Diagnostic::new(
                        Code::IndexOutOfRange,
                        r.span,
                        format!(
                            "'{}' has {} members; there is no [{k}]",
                            r.name(),
                            members.len()
                        ),
                    )
                    .with_help(format!("use an index from 1 to {}", members.len())),
                    (_, _, g) => {
                        let kind = g.map_or("object", Geometry::kind);
                        Diagnostic::new(Code::NotASolid, r.span, format!("'{}' is {}, not a bounded solid", r.text, crate::resolve::a(kind)))
                            .with_help("a subdomain's solid is a sphere, ellipsoid, torus, parallelepiped or truncated_cone (in 2D: circle, ellipse, triangle, parallelogram)")
                    }
                };
                diags.push(d);
                return None;
            };
            let planar = model.solids[first.index()].shape.is_planar();
            if planar != (model.dimension == Dimension::Two) {
                let (what, help) = if planar {
                    (
                        "a 2D region",
                        "set dimension=\"2\" on <geometry> for a planar model, or use a 3D solid",
                    )
                } else {
                    (
                        "a 3D solid",
                        "a 2D model's subdomains are circles, ellipses, triangles and parallelograms",
                    )
                };
                diags.push(
                    Diagnostic::new(
                        Code::DimensionMismatch,
                        r.span,
                        format!(
                            "'{}' is {what}, which cannot be a subdomain of a {}D model",
                            r.text,
                            if model.dimension == Dimension::Two {
                                2
                            } else {
                                3
                            }
                        ),
                    )
                    .with_help(help),
                );
                return None;
            }
            match found.len() {
                1 => Tree::Leaf(leaves.index_of(first)),
                _ => Tree::Union(
                    found
                        .iter()
                        .map(|id| Tree::Leaf(leaves.index_of(id)))
                        .collect(),
                ),
            }
        }
    })
}

/// Checks every pair of leaf solids: crossing boundaries, and touching
/// without sharing whole faces, are reported (E408). Returns `None` if any was.
/// `overlapping`: the pairs of all primitive solids whose boxes overlap, when
/// the isolation grid found them (the leaves' pairs are taken from there).
fn check_relations(
    model: &Model,
    source_map: &SourceMap,
    trees: &[(SubdomainId, Built)],
    overlapping: Option<super::isolation::Overlapping>,
    diags: &mut Diagnostics,
) -> Option<LeafPairs> {
    let mut leaves: Vec<SolidId> = trees
        .iter()
        .flat_map(|(_, b)| b.leaves.iter().copied())
        .collect();
    leaves.sort_unstable();
    leaves.dedup();
    // The isolation grid is made only when every box is finite and in order.
    let boxes_finite = matches!(&overlapping, Some(all) if all.solids == model.solids.len());
    let pairs = match overlapping {
        // The solids are the shapes the pairs were found for, in order.
        Some(all) if all.solids == model.solids.len() => {
            leaf_pairs(&leaves, &all.pairs, all.solids)
        }
        _ => {
            let boxes: Vec<crate::geom::Aabb> = leaves
                .iter()
                .map(|id| model.solids[id.index()].shape.bbox())
                .collect();
            candidate_pairs(&boxes, model.tolerance)
        }
    };
    // On the workers; the findings are reported in pair order.
    let found = std::sync::Mutex::new(Vec::new());
    (pairs.par_iter().enumerate()).for_each(|(k, &(i, j))| {
        if let Some(d) = check_pair(model, source_map, leaves[i], leaves[j]) {
            let mut all = found.lock().unwrap_or_else(|e| e.into_inner());
            all.push((k, d));
        }
    });
    let mut found = found.into_inner().unwrap_or_else(|e| e.into_inner());
    found.sort_unstable_by_key(|(k, _)| *k);
    let ok = found.is_empty();
    diags.items.extend(found.into_iter().map(|(_, d)| d));
    ok.then_some(LeafPairs {
        leaves,
        pairs,
        boxes_finite,
    })
}

/// The pairs among `leaves` (sorted solid ids) of the pairs of all `solids`
/// solids, as indices into `leaves`: sorted, since the indices grow with the ids.
fn leaf_pairs(leaves: &[SolidId], all: &[(u32, u32)], solids: usize) -> Vec<(usize, usize)> {
    const NONE: u32 = u32::MAX;
    let mut leaf_of = vec![NONE; solids];
    for (k, id) in leaves.iter().enumerate() {
        leaf_of[id.index()] = k as u32;
    }
    all.iter()
        .filter_map(|&(a, b)| {
            let (i, j) = (leaf_of[a as usize], leaf_of[b as usize]);
            (i != NONE && j != NONE).then_some((i as usize, j as usize))
        })
        .collect()
}

/// The candidate pairs of leaf solids (indices into `leaves`, sorted by id)
/// that `check_relations` found. When every subdomain is one solid of its
/// own, the overlap check's boxes are these same boxes, so it relabels these
/// pairs instead of sorting the grid cells of the same boxes a second time.
struct LeafPairs {
    leaves: Vec<SolidId>,
    pairs: Vec<(usize, usize)>,
    /// Every solid's `bbox()` is finite (the pairs came from the isolation
    /// grid, which is made only then): a one-leaf tree's box is its leaf's.
    boxes_finite: bool,
}

impl LeafPairs {
    /// The pairs over `members` (in member order) when each member is a tree
    /// of exactly one leaf solid, every leaf belongs to one member, and the
    /// member's box (the union of its leaves' boxes, [`tree_box`]) is its
    /// leaf's box; `None` otherwise.
    fn relabelled(
        &self,
        model: &Model,
        members: &[(SubdomainId, Member)],
    ) -> Option<Vec<(usize, usize)>> {
        if members.len() != self.leaves.len() {
            return None;
        }
        // Members are distinct leaves when there are as many as leaves, since
        // `leaves` is the set of all the trees' leaves.
        // Each member's leaf (its index in `leaves`), on the workers.
        let leaf_of = |(_, member): &(SubdomainId, Member)| {
            let Member::Tree(built) = member else {
                return None;
            };
            let [leaf] = &*built.leaves else {
                return None;
            };
            // Equal unless a coordinate is NaN (the union with the empty box
            // does not keep NaN): then the general pass decides. Finite boxes
            // need no look.
            if !self.boxes_finite
                && tree_box(model, built) != model.solids[leaf.index()].shape.bbox()
            {
                return None;
            }
            self.leaves.binary_search(leaf).ok()
        };
        let leaf_of: Vec<usize> = (members.par_iter())
            .with_min_len(DEFINITIONS_PER_TASK)
            .map(leaf_of)
            .collect::<Option<_>>()?;
        let mut member_of = vec![0usize; self.leaves.len()];
        for (m, leaf) in leaf_of.into_iter().enumerate() {
            member_of[leaf] = m;
        }
        let mut pairs: Vec<(usize, usize)> = (self.pairs.iter())
            .map(|&(i, j)| {
                let (a, b) = (member_of[i], member_of[j]);
                (a.min(b), a.max(b))
            })
            .collect();
        pairs.sort_unstable();
        Some(pairs)
    }
}

/// Pairs of boxes that may overlap, found with a uniform grid whose cell is
/// twice the median box size (a typical box then covers 1 to 8 cells, 3.4 on
/// average, instead of 8 with cells of its own size: fewer entries to sort,
/// and the pairs do not depend on the cell); boxes spanning many cells are
/// compared with all.
pub(super) fn candidate_pairs(boxes: &[crate::geom::Aabb], tol: f64) -> Vec<(usize, usize)> {
    let mut sizes: Vec<f64> = (boxes.par_iter())
        .with_min_len(BOXES_PER_TASK)
        .map(|b| (b.max - b.min).max())
        .collect();
    let middle = sizes.len() / 2;
    let median =
        (middle < sizes.len()).then(|| *sizes.select_nth_unstable_by(middle, f64::total_cmp).1);
    let cell = (2.0 * median.unwrap_or(0.5))
        .max(tol * 1e3)
        .max(f64::MIN_POSITIVE);
    // The grid is shifted by an irrational part of a cell: files often place
    // solids on a lattice of round numbers, and a lattice whose boxes are
    // centred on cell borders put every box in 8 cells (the pairs do not
    // depend on the grid, only the number of entries to sort does).
    let key = |v: f64| super::floor_index::floor_index(v / cell + GRID_SHIFT);
    // A sorted list of (cell, box) instead of a map of cells: boxes sharing a
    // cell are adjacent after sorting, and nothing is allocated per cell.
    // The cell range (lowest, highest) of a placeable box and how many cells
    // it covers; computed twice (count, then fill) rather than stored, since on
    // large models a stored range per box was megabytes at the peak.
    let range = |b: &crate::geom::Aabb| -> Option<([i64; 3], [i64; 3], i128)> {
        let finite = [b.min, b.max]
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite()));
        if b.is_empty() || !finite {
            // Nothing, or nothing placeable: it cannot overlap anything.
            return None;
        }
        let lo = [key(b.min.x - tol), key(b.min.y - tol), key(b.min.z - tol)];
        let hi = [key(b.max.x + tol), key(b.max.y + tol), key(b.max.z + tol)];
        let count = (0..3)
            .map(|k| (i128::from(hi[k]) - i128::from(lo[k]) + 1).max(0))
            .fold(1i128, |acc, n| acc.saturating_mul(n));
        Some((lo, hi, count))
    };
    // Sized exactly: on large models the list has millions of entries. The
    // boxes of more than 64 cells are counted too, so the pass finding them
    // runs only when there are some (on large models, seldom).
    let (total, big_count): (usize, usize) = (boxes.par_iter())
        .with_min_len(BOXES_PER_TASK)
        .filter_map(range)
        .map(|r| if r.2 <= 64 { (r.2 as usize, 0) } else { (0, 1) })
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    // A cell is kept as a 64-bit hash of its coordinates (16 bytes an entry
    // instead of 32): cells that collide only add candidates, which the box
    // test below discards, and the pairs are sorted at the end. Filled on the
    // workers, in box order (the order does not matter: the list is sorted).
    let mut cells: Vec<(u64, u32)> = Vec::with_capacity(total);
    let placed = (boxes.par_iter().enumerate())
        .with_min_len(BOXES_PER_TASK)
        .filter_map(|(i, b)| {
            range(b)
                .filter(|r| r.2 <= 64)
                .map(|(lo, hi, _)| (i, lo, hi))
        })
        .flat_map_iter(|(i, lo, hi)| {
            (lo[0]..=hi[0]).flat_map(move |x| {
                (lo[1]..=hi[1]).flat_map(move |y| {
                    (lo[2]..=hi[2]).map(move |z| (cell_hash([x, y, z]), i as u32))
                })
            })
        });
    cells.par_extend(placed);
    let big: Vec<usize> = if big_count == 0 {
        Vec::new()
    } else {
        (boxes.par_iter().enumerate())
            .with_min_len(BOXES_PER_TASK)
            .filter(|(_, b)| range(b).is_some_and(|r| r.2 > 64))
            .map(|(i, _)| i)
            .collect()
    };
    // In parallel: entries equal under the order are identical, so the sorted
    // list does not depend on the threads.
    cells.par_sort_unstable();
    let mut pairs = Vec::new();
    for run in cells.chunk_by(|a, b| a.0 == b.0) {
        for (k, &(_, i)) in run.iter().enumerate() {
            for &(_, j) in &run[k + 1..] {
                let (i, j) = (i as usize, j as usize);
                // Two cells of one box may share a hash.
                if i != j && boxes[i].overlaps(&boxes[j], tol) {
                    pairs.push((i.min(j), i.max(j)));
                }
            }
        }
    }
    for &i in &big {
        for j in 0..boxes.len() {
            if i != j && boxes[i].overlaps(&boxes[j], tol) {
                pairs.push((i.min(j), i.max(j)));
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// Boxes per task of [`candidate_pairs`]' parallel passes.
const BOXES_PER_TASK: usize = 4096;

/// Where the candidate grid's cell borders lie, in cells (1/φ², far from
/// simple fractions).
const GRID_SHIFT: f64 = 0.381_966_011_250_105_1;

/// A well-mixed 64-bit hash of a grid cell (fixed, so runs are reproducible).
pub(super) fn cell_hash(cell: [i64; 3]) -> u64 {
    use std::hash::BuildHasher;
    foldhash::quality::FixedState::with_seed(0x5eed).hash_one(cell)
}

/// What is wrong with a pair of leaf solids (E408), if anything.
fn check_pair(model: &Model, source_map: &SourceMap, a: SolidId, b: SolidId) -> Option<Diagnostic> {
    let sa = &model.solids[a.index()];
    let sb = &model.solids[b.index()];
    if !sa.shape.bbox().overlaps(&sb.shape.bbox(), model.tolerance) {
        return None;
    }
    let relation = boundary_relation(&sa.shape, &sb.shape, model.tolerance * 10.0);
    let span = source_map.solid(b).or(source_map.solid(a));
    if let Some(p) = relation
        .a_in_b
        .crossing_near
        .or(relation.b_in_a.crossing_near)
    {
        return Some(
            Diagnostic::new(
                Code::BoundariesIntersect,
                span,
                format!("the boundaries of '{}' and '{}' cross near {}", sa.name, sb.name, crate::resolve::fmt_point(&p)),
            )
            .with_help("move the solids apart, nest one inside the other, or make touching faces coincide exactly"),
        );
    }
    if relation.a_in_b.crosses() || relation.b_in_a.crosses() {
        return Some(
            Diagnostic::new(Code::BoundariesIntersect, span, format!("the boundaries of '{}' and '{}' cross", sa.name, sb.name))
                .with_help("move the solids apart, nest one inside the other, or make touching faces coincide exactly"),
        );
    }
    let touching = relation.a_in_b.on > 0 || relation.b_in_a.on > 0;
    let shares_face = match model.dimension {
        Dimension::Three => sa
            .faces
            .iter()
            .any(|f| sb.faces.iter().any(|g| g.face == f.face)),
        Dimension::Two => sa
            .boundary_edges
            .iter()
            .any(|e| sb.boundary_edges.iter().any(|g| g.edge == e.edge)),
    };
    if touching && !shares_face {
        return Some(
            Diagnostic::new(
                Code::BoundariesIntersect,
                span,
                format!(
                    "'{}' and '{}' touch without sharing a whole face",
                    sa.name, sb.name
                ),
            )
            .with_help(
                "make the touching faces coincide exactly (same corners), or move the solids apart",
            ),
        );
    }
    None
}

/// The faces of the subdomain's boundary, with `outward` set.
fn classify_faces(model: &Model, built: &Built, samples: &FaceSamples) -> Vec<OrientedFace> {
    if let (Tree::Leaf(0), [leaf]) = (&built.tree, &*built.leaves) {
        return single_solid_faces(&model.solids[leaf.index()].faces, samples);
    }
    let mut result: BTreeMap<FaceId, bool> = BTreeMap::new();
    // Each leaf's faces sorted once: a linear search per face and leaf was
    // quadratic in a solid's face count.
    let sides: Vec<Vec<(FaceId, bool)>> = built
        .leaves
        .iter()
        .map(|leaf| {
            let faces = &model.solids[leaf.index()].faces;
            sorted_sides(faces.iter().map(|g| (g.face, g.outward)))
        })
        .collect();
    let sides = &sides;
    for &leaf in built.leaves.iter() {
        for of in &model.solids[leaf.index()].faces {
            if result.contains_key(&of.face) {
                continue;
            }
            let Some(sample) = samples.get(&of.face) else {
                continue;
            };
            // Membership of each leaf on the face's two sides: the side the face
            // normal points away from ("behind") and the side it points to.
            let side = |behind: bool| {
                move |i: usize| -> bool {
                    match first_side(&sides[i], of.face) {
                        Some(outward) => outward == behind,
                        None => model.solids[built.leaves[i].index()].shape.value(sample) > 0.0,
                    }
                }
            };
            let behind = built.tree.eval(&side(true));
            let front = built.tree.eval(&side(false));
            if behind != front {
                result.insert(of.face, behind);
            }
        }
    }
    result
        .into_iter()
        .map(|(face, outward)| OrientedFace { face, outward })
        .collect()
}

/// [`classify_faces`] for a tree of one solid (every subdomain of a file of
/// separate primitives), without the general evaluation: each face with a
/// sample has its own solid behind (outward) or in front of it (inward), so
/// the sides always differ and the first listing of a face gives its flag.
fn single_solid_faces(faces: &[OrientedFace], samples: &FaceSamples) -> Vec<OrientedFace> {
    let mut out: Vec<OrientedFace> = faces
        .iter()
        .filter(|of| samples.get(&of.face).is_some())
        .copied()
        .collect();
    // Stable: a repeated face keeps its first flag, as the general path does.
    out.sort_by_key(|of| of.face);
    out.dedup_by_key(|of| of.face);
    out
}

/// (key, flag) pairs sorted by key; a stable sort keeps a repeated key's
/// first flag first, as a linear search would find it.
fn sorted_sides<K: Ord + Copy>(pairs: impl Iterator<Item = (K, bool)>) -> Vec<(K, bool)> {
    let mut v: Vec<(K, bool)> = pairs.collect();
    v.sort_by_key(|p| p.0);
    v
}

/// The flag of the first pair with this key in a [`sorted_sides`] list.
fn first_side<K: Ord + Copy>(sorted: &[(K, bool)], key: K) -> Option<bool> {
    let at = sorted.partition_point(|p| p.0 < key);
    sorted.get(at).filter(|p| p.0 == key).map(|p| p.1)
}

/// The boundary edges of a 2D subdomain, `forward` with the region on the left.
fn classify_edges(model: &Model, built: &Built) -> Vec<OrientedEdge> {
    let mut result: BTreeMap<EdgeId, bool> = BTreeMap::new();
    // Each leaf's edges sorted once: a linear search per edge and leaf was
    // quadratic in a polygon's vertex count.
    let sides: Vec<Vec<(EdgeId, bool)>> = built
        .leaves
        .iter()
        .map(|leaf| {
            let edges = &model.solids[leaf.index()].boundary_edges;
            sorted_sides(edges.iter().map(|g| (g.edge, g.forward)))
        })
        .collect();
    let sides = &sides;
    for &leaf in built.leaves.iter() {
        for oe in &model.solids[leaf.index()].boundary_edges {
            if result.contains_key(&oe.edge) {
                continue;
            }
            let sample = model.edge_curve(oe.edge).point(0.5);
            // "left" = the side on the left of the edge's own direction.
            let side = |left: bool| {
                move |i: usize| -> bool {
                    match first_side(&sides[i], oe.edge) {
                        Some(forward) => forward == left,
                        None => model.solids[built.leaves[i].index()].shape.value(&sample) > 0.0,
                    }
                }
            };
            let left = built.tree.eval(&side(true));
            let right = built.tree.eval(&side(false));
            if left != right {
                result.insert(oe.edge, left);
            }
        }
    }
    result
        .into_iter()
        .map(|(edge, forward)| OrientedEdge { edge, forward })
        .collect()
}

/// One planar face per 2D subdomain, its loops chained from the boundary edges.
fn region_face(model: &mut Model, name: &str, edges: &[OrientedEdge]) -> Option<FaceId> {
    if edges.is_empty() {
        return None;
    }
    let start_of = |m: &Model, e: &OrientedEdge| {
        let edge = m.edge(e.edge);
        if e.forward { edge.begin } else { edge.end }
    };
    let end_of = |m: &Model, e: &OrientedEdge| {
        let edge = m.edge(e.edge);
        if e.forward { edge.end } else { edge.begin }
    };
    let mut remaining: Vec<OrientedEdge> = edges.to_vec();
    let mut loops = Vec::new();
    while let Some(first) = remaining.first().copied() {
        remaining.remove(0);
        let mut l = vec![first];
        let start = start_of(model, &first);
        let mut at = end_of(model, &first);
        while at != start {
            let Some(k) = remaining.iter().position(|e| start_of(model, e) == at) else {
                break;
            };
            let next = remaining.remove(k);
            at = end_of(model, &next);
            l.push(next);
        }
        loops.push(l);
    }
    let origin = model.vertex(model.edge(edges[0].edge).begin).position;
    let id = FaceId(model.faces.len() as u32);
    model.faces.push(Face {
        name: name.into(),
        carrier: Carrier::own(Surface::Plane {
            origin,
            normal: Vec3::z(),
        }),
        reversed: false,
        loops: loops.into(),
    });
    Some(id)
}

/// Reports pairs of subdomains that share volume: a point just inside one
/// How a subdomain answers "is this point inside?": its boolean tree of
/// solids, or the winding number of its explicit faces.
enum Member<'a> {
    Tree(&'a Built),
    /// A shell of explicit faces, with its interior probes (boxed: there is
    /// a member per subdomain, and most are trees).
    Shell(Box<(super::winding::ShellTriangles, Vec<Point3>)>),
}

/// Reports pairs of subdomains that share volume: a point just inside one
/// subdomain, next to one of its boundary faces, lies inside the other.
fn check_overlaps(
    model: &Model,
    source_map: &SourceMap,
    trees: &[(SubdomainId, Built)],
    samples: &FaceSamples,
    leaf_pairs: LeafPairs,
    diags: &mut Diagnostics,
) {
    let step = model.tolerance * 1000.0;
    let mut from_tree = vec![false; model.subdomains.len()];
    for (t, _) in trees {
        from_tree[t.index()] = true;
    }
    let is_shell = |k: usize, s: &crate::ir::Subdomain| {
        !from_tree[k] && matches!(s.cells, SubdomainCells::Volume { .. })
    };
    let shells = (model.subdomains.iter().enumerate())
        .filter(|(k, s)| is_shell(*k, s))
        .count();
    // Sized once, and a member's box kept apart (what `candidate_pairs`
    // reads). A solid tree's probes are made only when it is
    // in a candidate pair: on large models most subdomains are in none, and a
    // probe vector per subdomain was megabytes at the memory peak.
    let mut members: Vec<(SubdomainId, Member)> = Vec::with_capacity(trees.len() + shells);
    // The shells' boxes; the trees' are made only if the pairs cannot be
    // relabelled from the leaves' (on files of one solid per subdomain they
    // can, and every solid's box was made again here).
    let mut shell_boxes: Vec<crate::geom::Aabb> = Vec::with_capacity(shells);
    members.extend(trees.iter().map(|(id, built)| (*id, Member::Tree(built))));
    for (k, subdomain) in model.subdomains.iter().enumerate() {
        let id = SubdomainId(k as u32);
        if !is_shell(k, subdomain) {
            continue;
        }
        let SubdomainCells::Volume { boundary } = &subdomain.cells else {
            continue;
        };
        let shell = super::winding::ShellTriangles::of(model, boundary);
        let mut bbox = crate::geom::Aabb::empty();
        let mut face_points = FaceSamples::default();
        for of in boundary {
            for e in model.face(of.face).loops.iter().flatten() {
                let edge = model.edge(e.edge);
                bbox.include(&model.vertex(edge.begin).position);
                let curve = edge.curve(&model.solids);
                curve.samples(8).iter().for_each(|p| bbox.include(p));
            }
            if let Some(p) = super::winding::face_sample(model, of.face) {
                face_points.insert(of.face, p);
            }
        }
        let probes = interior_probes(model, id, &face_points, step);
        members.push((id, Member::Shell(Box::new((shell, probes)))));
        shell_boxes.push(bbox);
    }
    let inside = |member: &Member, p: &Point3| match member {
        Member::Tree(built) => built
            .tree
            .eval(&|i| model.solids[built.leaves[i].index()].shape.value(p) > 0.0),
        Member::Shell(shell) => shell.0.contains(p),
    };
    // Tree probes made so far, by member index (same points as made eagerly).
    let mut tree_probes: HashMap<usize, Vec<Point3>> = HashMap::new();
    // The same pairs as `candidate_pairs` over these boxes would give.
    let pairs = leaf_pairs.relabelled(model, &members).unwrap_or_else(|| {
        // Members in order: the trees, then the shells.
        let mut boxes: Vec<crate::geom::Aabb> = Vec::with_capacity(members.len());
        let tree_boxes = (trees.par_iter())
            .with_min_len(DEFINITIONS_PER_TASK)
            .map(|(_, built)| tree_box(model, built));
        boxes.par_extend(tree_boxes);
        boxes.extend(shell_boxes);
        candidate_pairs(&boxes, model.tolerance)
    });
    drop(leaf_pairs);
    for (i, j) in pairs {
        for k in [i, j] {
            if let (id, Member::Tree(_)) = &members[k] {
                (tree_probes.entry(k))
                    .or_insert_with(|| interior_probes(model, *id, samples, step));
            }
        }
        let probes_of = |k: usize| -> &[Point3] {
            match &members[k] {
                (_, Member::Shell(shell)) => &shell.1,
                (_, Member::Tree(_)) => tree_probes.get(&k).map_or(&[], Vec::as_slice),
            }
        };
        let (probes_a, probes_b) = (probes_of(i), probes_of(j));
        let ((a, member_a), (b, member_b)) = (&members[i], &members[j]);
        let overlap = probes_a
            .iter()
            .any(|p| inside(member_b, p) && inside(member_a, p))
            || probes_b
                .iter()
                .any(|p| inside(member_a, p) && inside(member_b, p));
        if overlap {
            let (sa, sb) = (model.subdomain(*a), model.subdomain(*b));
            diags.push(
                Diagnostic::new(
                    Code::SubdomainsOverlap,
                    source_map.subdomain(*a.max(b)),
                    format!("subdomains '{}' and '{}' overlap", sa.name, sb.name),
                )
                .with_help(format!(
                    "carve one out of the other, e.g. <difference><solid ref=\"outer solid\"/><solid ref=\"inner solid\"/></difference> for the outer of '{}' and '{}'",
                    sa.name, sb.name
                )),
            );
        }
    }
}

/// The box of a solid tree: the union of its leaves' boxes, in leaf order.
fn tree_box(model: &Model, built: &Built) -> crate::geom::Aabb {
    (built.leaves.iter()).fold(crate::geom::Aabb::empty(), |acc, l| {
        acc.union(&model.solids[l.index()].shape.bbox())
    })
}

/// Points just inside a subdomain, next to each of its boundary faces (edges in 2D).
fn interior_probes(
    model: &Model,
    id: SubdomainId,
    samples: &FaceSamples,
    step: f64,
) -> Vec<Point3> {
    match &model.subdomain(id).cells {
        SubdomainCells::Volume { boundary } => boundary
            .iter()
            .filter_map(|of| {
                let p = samples.get(&of.face)?;
                let face = model.face(of.face);
                let n = face.surface(&model.solids).gradient(p);
                if n.norm() == 0.0 {
                    return None;
                }
                // Step against the outward normal, into the subdomain.
                let sign = if of.outward != face.reversed {
                    -1.0
                } else {
                    1.0
                };
                Some(p + n.normalize() * (sign * step))
            })
            .collect(),
        SubdomainCells::Region { faces } => faces
            .iter()
            .flat_map(|f| model.face(*f).loops.iter().flatten())
            .map(|e| {
                let curve = model.edge_curve(e.edge);
                let left = Vec3::z().cross(&curve.tangent(0.5));
                curve.point(0.5) + left * (if e.forward { step } else { -step })
            })
            .collect(),
    }
}

/// A subdomain given by its faces: the faces' outward flags are made
/// consistent across shared edges, then all flipped if the enclosed volume is negative.
fn explicit_shell(
    model: &Model,
    entities: &Entities,
    refs: &[crate::doc::Ref],
    diags: &mut Diagnostics,
) -> Option<(Vec<OrientedFace>, Vec<usize>)> {
    let mut faces: Vec<FaceId> = Vec::new();
    // Trimmed surfaces are faces too, found by their element's name.
    let mut trimmed: Vec<usize> = Vec::new();
    let mut seen: BTreeSet<FaceId> = BTreeSet::new();
    let mut ok = true;
    for r in refs {
        match lookup_entities(&entities.faces, &r.text) {
            Some(ids) => {
                for id in ids {
                    if !seen.insert(id) {
                        // A shell uses each face once; a repeat is a slip, not a second sheet.
                        diags.push(
                            Diagnostic::new(
                                Code::RepeatedFace,
                                r.span,
                                format!("face '{}' is already in this subdomain's faces= list; the repeat is ignored", r.text),
                            )
                            .with_help("remove the repeated name"),
                        );
                    } else {
                        faces.push(id);
                    }
                }
            }
            None => match model.trimmed.iter().position(|s| *s.name == *r.text) {
                Some(k) if trimmed.contains(&k) => diags.push(
                    Diagnostic::new(
                        Code::RepeatedFace,
                        r.span,
                        format!("face '{}' is already in this subdomain's faces= list; the repeat is ignored", r.text),
                    )
                    .with_help("remove the repeated name"),
                ),
                Some(k) => trimmed.push(k),
                None => {
                    unknown_entity(r, "face", entities, diags);
                    ok = false;
                }
            },
        }
    }
    if !ok {
        return None;
    }
    Some((orient_shell(model, &faces), trimmed))
}

/// Propagates outward flags across shared edges (an edge is run in opposite
/// directions by its two faces in a consistently oriented shell), then fixes
/// the overall sign by the signed volume.
pub(super) fn orient_shell(model: &Model, faces: &[FaceId]) -> Vec<OrientedFace> {
    let mut uses: HashMap<EdgeId, Vec<(usize, bool)>> = HashMap::new();
    for (k, &f) in faces.iter().enumerate() {
        for e in model.face(f).loops.iter().flatten() {
            uses.entry(e.edge).or_default().push((k, e.forward));
        }
    }
    let mut outward: Vec<Option<bool>> = vec![None; faces.len()];
    for start in 0..faces.len() {
        if outward[start].is_some() {
            continue;
        }
        outward[start] = Some(true);
        let mut stack = vec![start];
        let mut component = vec![start];
        while let Some(k) = stack.pop() {
            let flag = outward[k].unwrap_or(true);
            for e in model.face(faces[k]).loops.iter().flatten() {
                for &(other, forward) in uses.get(&e.edge).map(Vec::as_slice).unwrap_or(&[]) {
                    if other == k || outward[other].is_some() {
                        continue;
                    }
                    // Effective directions must be opposite: flag·d = −flag'·d'.
                    let same_direction = forward == e.forward;
                    outward[other] = Some(if same_direction { !flag } else { flag });
                    stack.push(other);
                    component.push(other);
                }
            }
        }
        let volume: f64 = component
            .iter()
            .map(|&k| {
                let sign = if outward[k] == Some(true) { 1.0 } else { -1.0 };
                sign * face_volume(model, faces[k])
            })
            .sum();
        if volume < 0.0 {
            for &k in &component {
                outward[k] = outward[k].map(|o| !o);
            }
        }
    }
    faces
        .iter()
        .zip(outward)
        .map(|(&face, o)| OrientedFace {
            face,
            outward: o.unwrap_or(true),
        })
        .collect()
}

/// The signed volume contribution ∫ p·n dA / 3 of a face, with its loops
/// fanned from a point on the surface (n along the loop orientation).
fn face_volume(model: &Model, face_id: FaceId) -> f64 {
    let face = model.face(face_id);
    let surface = face.surface(&model.solids);
    if let crate::geom::Surface::Parametric(s) = &*surface {
        // Its loops run counter-clockwise about R_u × R_v.
        let share = crate::trimmed::volume_share(s);
        return if face.reversed { -share } else { share };
    }
    let mut total = 0.0;
    for l in &face.loops {
        let mut points = Vec::new();
        for e in l {
            let mut s = model.edge_curve(e.edge).samples(16);
            if !e.forward {
                s.reverse();
            }
            s.pop();
            points.extend(s);
        }
        if points.len() < 2 {
            continue;
        }
        let centroid =
            Point3::from(points.iter().map(|p| p.coords).sum::<Vec3>() / points.len() as f64);
        let apex = surface.project(&centroid).unwrap_or(centroid);
        for i in 0..points.len() {
            let a = points[i];
            let b = points[(i + 1) % points.len()];
            total += apex.coords.dot(&a.coords.cross(&b.coords)) / 6.0;
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{Frame, Mat3, SolidShape};
    use crate::ir::Solid;

    #[test]
    fn a_one_solid_tree_classifies_as_the_general_evaluation() {
        let mut model = Model::empty(Dimension::Three);
        let of = |face: u32, outward: bool| OrientedFace {
            face: FaceId(face),
            outward,
        };
        // Face 3 is listed twice with different flags (the first wins), face 5
        // has no sample (skipped), the list is not in id order.
        let faces = vec![
            of(3, true),
            of(1, false),
            of(5, true),
            of(3, false),
            of(0, true),
        ];
        model.solids.push(Solid {
            name: std::sync::Arc::new("s".into()),
            shape: SolidShape::Box {
                frame: Frame {
                    origin: Point3::origin(),
                    linear: Mat3::identity(),
                },
            },
            faces: faces.into_boxed_slice(),
            boundary_edges: Box::default(),
            edges: Box::default(),
            vertices: Box::default(),
        });
        let mut samples = FaceSamples::default();
        for f in [0, 1, 3] {
            samples.insert(FaceId(f), Point3::new(f as f64, 0.0, 0.0));
        }
        let built = |tree| Built {
            tree,
            leaves: Leaves::One(SolidId(0)),
            span: crate::span::Span::default(),
        };
        let fast = classify_faces(&model, &built(Tree::Leaf(0)), &samples);
        let general = classify_faces(&model, &built(Tree::Union(vec![Tree::Leaf(0)])), &samples);
        assert_eq!(fast, vec![of(0, true), of(1, false), of(3, true)]);
        assert_eq!(fast, general);
    }

    /// On files of one solid per subdomain the overlap check's pairs are the
    /// isolation grid's, relabelled without making the trees' boxes: they
    /// are the pairs `candidate_pairs` finds over the trees' boxes, for
    /// members in any order, and with finite boxes the relabelling never
    /// needs to look at a box.
    #[test]
    fn relabelled_pairs_are_the_pairs_of_the_trees_boxes() {
        use crate::test_rng::TestRng;
        let mut rng = TestRng::new(0x1abe_11ed);
        let mut found = 0;
        for case in 0..60 {
            let mut model = Model::empty(Dimension::Three);
            let n = 50 + rng.below(150);
            let shapes: Vec<SolidShape> = (0..n)
                .map(|_| {
                    let mut shape = super::super::tolerance::tests::random_shape(&mut rng, false);
                    // Crowded: about one solid in three overlaps another's box.
                    if let SolidShape::Ball { frame } | SolidShape::Box { frame } = &mut shape {
                        frame.origin /= 200.0;
                    }
                    shape
                })
                .collect();
            for (k, shape) in shapes.iter().enumerate() {
                model.solids.push(Solid {
                    name: std::sync::Arc::new(format!("s{k}").into()),
                    shape: shape.clone(),
                    faces: Box::default(),
                    boundary_edges: Box::default(),
                    edges: Box::default(),
                    vertices: Box::default(),
                });
            }
            model.tolerance = 1e-3;
            let refs: Vec<&SolidShape> = shapes.iter().collect();
            let boxes = super::super::isolation::shape_boxes(&refs);
            let overlapping = super::super::isolation::pairs(&refs, boxes, model.tolerance)
                .overlapping
                .expect("finite boxes");
            // The members: one tree per solid, in a random order.
            let mut order: Vec<usize> = (0..n).collect();
            for k in (1..n).rev() {
                order.swap(k, rng.below(k + 1));
            }
            let built: Vec<Built> = (order.iter())
                .map(|&k| Built {
                    tree: Tree::Leaf(0),
                    leaves: Leaves::One(SolidId(k as u32)),
                    span: crate::span::Span::default(),
                })
                .collect();
            let members: Vec<(SubdomainId, Member)> = (built.iter().enumerate())
                .map(|(m, b)| (SubdomainId(m as u32), Member::Tree(b)))
                .collect();
            let leaves: Vec<SolidId> = (0..n as u32).map(SolidId).collect();
            let tree_boxes: Vec<crate::geom::Aabb> =
                built.iter().map(|b| tree_box(&model, b)).collect();
            let expected = candidate_pairs(&tree_boxes, model.tolerance);
            for boxes_finite in [true, false] {
                let leaf_pairs = LeafPairs {
                    pairs: leaf_pairs(&leaves, &overlapping.pairs, n),
                    leaves: leaves.clone(),
                    boxes_finite,
                };
                let relabelled = leaf_pairs.relabelled(&model, &members);
                assert_eq!(relabelled.as_ref(), Some(&expected), "case {case}");
            }
            found += expected.len();
        }
        assert!(found > 500, "{found} pairs");
    }

    /// The grid finds every pair of boxes within the tolerance and no other,
    /// with and without boxes of more than 64 cells (compared with all).
    #[test]
    fn candidate_pairs_are_the_overlapping_pairs() {
        use crate::geom::Aabb;
        use crate::test_rng::TestRng;
        let mut rng = TestRng::new(0xb0c5);
        let mut bigs = 0;
        for case in 0..200 {
            let n = 1 + rng.below(120);
            let boxes: Vec<Aabb> = (0..n)
                .map(|_| {
                    let at = Point3::new(
                        rng.within(100) as f64,
                        rng.within(100) as f64,
                        rng.within(10) as f64,
                    );
                    // Mostly small; in odd cases now and then one spanning the field.
                    let size = if case % 2 == 1 && rng.below(40) == 0 {
                        150.0
                    } else {
                        1.0 + rng.below(20) as f64 / 4.0
                    };
                    let mut b = Aabb::empty();
                    b.include(&at);
                    b.include(&(at + Vec3::new(size, size, 1.0)));
                    b
                })
                .collect();
            let tol = 0.25;
            let mut all = Vec::new();
            for i in 0..n {
                for j in i + 1..n {
                    if boxes[i].overlaps(&boxes[j], tol) {
                        all.push((i, j));
                    }
                }
            }
            assert_eq!(candidate_pairs(&boxes, tol), all, "case {case}");
            bigs += boxes.iter().filter(|b| b.max.x - b.min.x > 100.0).count();
        }
        assert!(bigs > 20, "{bigs} big boxes");
    }

    /// `build_subdomains` collects the subdomains from the consumed
    /// definitions so they reuse the definitions' allocation; the standard
    /// library does that only when a subdomain fits in a definition with the
    /// same alignment. Otherwise it grows a second vector beside the first:
    /// with a 56-byte `Ref` (136-byte definitions) and `Vec` leaf solids
    /// (144-byte subdomains), validate's peak on the 100k file rose from 166
    /// to 195 MB.
    #[test]
    fn subdomains_fit_in_their_definitions() {
        use std::mem::{align_of, size_of};
        assert!(
            size_of::<crate::ir::Subdomain>() <= size_of::<SubdomainDef>(),
            "Subdomain {} bytes, SubdomainDef {} bytes",
            size_of::<crate::ir::Subdomain>(),
            size_of::<SubdomainDef>()
        );
        assert_eq!(
            align_of::<crate::ir::Subdomain>(),
            align_of::<SubdomainDef>()
        );
    }
}
