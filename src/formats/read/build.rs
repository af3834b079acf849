//! What every reader fills: nodes and named groups of triangles, line
//! segments and points, then [`Builder::finish`] turns them into the mesh IR
//! (one face per triangle group, poly_lines for line groups, point sets for
//! point groups) and runs the surface checks.

use super::Loaded;
use super::clean;
use crate::diag::{Code, Diagnostic};
use crate::formats::MeshFacts;
use crate::formats::groups::Bounds;
use crate::formats::mesh_facts::FaceFacts;
use crate::mesh::{
    CellKind, Mesh, MeshFace, MeshFragment, MeshPolyline, MeshSubdomain, MeshVolume,
};
use std::collections::HashMap;

/// Elements of one named group.
#[derive(Debug, Clone, Default)]
pub struct Group {
    pub name: String,
    pub triangles: Vec<[u32; 3]>,
    pub lines: Vec<[u32; 2]>,
    pub points: Vec<u32>,
    /// Volume cells by kind (index: `CellKind as usize`), corners flat.
    pub volumes: [Vec<u32>; 4],
}

impl Group {
    /// Adds one volume cell; `corners` has `kind.corners()` nodes (the
    /// readers check the count where they read it).
    pub fn add_cell(&mut self, kind: CellKind, corners: &[u32]) {
        if let (Some(list), Some(c)) = (
            self.volumes.get_mut(kind as usize),
            corners.get(..kind.corners()),
        ) {
            list.extend_from_slice(c);
        }
    }
}

/// A fragment recovered from a file that carries one (geomc's own glTF
/// extras): group name, subdomain name, other subdomain name (`None`: exterior).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FragmentInfo {
    pub group: String,
    pub subdomain: String,
    pub other: Option<String>,
}

#[derive(Debug, Default)]
pub struct Builder {
    pub nodes: Vec<[f64; 3]>,
    pub groups: Vec<Group>,
    index: HashMap<String, usize>,
    pub warnings: Vec<Diagnostic>,
    /// Subdomains by name, with their material, when the file names them.
    pub subdomains: Vec<(String, Option<String>)>,
    pub fragments: Vec<FragmentInfo>,
    /// What the reader summed up while reading, for [`Builder::finish_with`].
    pub(crate) known: Known,
}

/// Facts a reader found while it decoded the nodes and triangles
/// (`read::summed`), so that [`Builder::finish_with`] need not scan them
/// again. Used only where the counts still match: readers only append.
#[derive(Debug, Default)]
pub(crate) struct Known {
    /// The bounds of the first `.0` nodes, every coordinate of which is
    /// finite (`None`: not known).
    pub(crate) nodes: Option<(usize, Option<Bounds>)>,
    /// Per group index, the facts of its triangles.
    pub(crate) faces: HashMap<usize, FaceFacts>,
}

impl Known {
    /// `count` more nodes after the first `before`, with these bounds: kept
    /// when the nodes before were all known (or there were none).
    pub(crate) fn add_nodes(&mut self, before: usize, count: usize, bounds: Option<Bounds>) {
        let so_far = match self.nodes {
            Some((known, b)) if known == before => Some(b),
            None if before == 0 => Some(None),
            _ => None,
        };
        self.nodes = so_far.map(|b| {
            (
                before + count,
                crate::formats::mesh_facts::merge_bounds(b, bounds),
            )
        });
    }
}

impl Builder {
    pub fn new() -> Builder {
        Builder::default()
    }

    /// The index of the group named `name`, created empty when new.
    pub fn group(&mut self, name: &str) -> usize {
        if let Some(&i) = self.index.get(name) {
            return i;
        }
        self.groups.push(Group {
            name: name.to_string(),
            ..Group::default()
        });
        self.index.insert(name.to_string(), self.groups.len() - 1);
        self.groups.len() - 1
    }

    pub fn warn(&mut self, code: Code, message: impl Into<String>) {
        self.warnings.push(Diagnostic::new(code, None, message));
    }

    /// The mesh and its checks. Indices are the readers' to check; this
    /// checks them again so that no reader bug can reach a writer.
    pub fn finish(self) -> Result<Loaded, Vec<Diagnostic>> {
        let mut loaded = self.finish_unchecked()?;
        loaded.check();
        Ok(loaded)
    }

    /// [`Builder::finish`] without the surface checks ([`Loaded::check`]
    /// runs them later, e.g. while `convert` writes).
    pub fn finish_unchecked(self) -> Result<Loaded, Vec<Diagnostic>> {
        self.finish_with(false).map(|(loaded, _)| loaded)
    }

    /// [`Builder::finish_unchecked`]; with `facts`, also what its passes
    /// over the nodes and triangles found ([`MeshFacts`]), for the passes
    /// after it (without, those passes look for the largest index and the
    /// first coordinate that is not finite only).
    pub fn finish_with(
        mut self,
        facts: bool,
    ) -> Result<(Loaded, Option<MeshFacts>), Vec<Diagnostic>> {
        let n = self.nodes.len();
        let mut found = std::mem::take(&mut self.known);
        // One per group with triangles: the faces' facts, in face order.
        let faces: Vec<FaceFacts> = if facts {
            self.groups
                .iter()
                .enumerate()
                .filter(|(_, g)| !g.triangles.is_empty())
                .map(|(i, g)| {
                    found
                        .faces
                        .remove(&i)
                        .filter(|f| f.counts(&g.triangles))
                        .unwrap_or_else(|| FaceFacts::of(&g.triangles))
                })
                .collect()
        } else {
            Vec::new()
        };
        let mut known = faces.iter();
        for g in &self.groups {
            let largest = match (g.triangles.is_empty(), facts) {
                (false, true) => known.next().map_or(u32::MAX, FaceFacts::largest),
                _ => crate::formats::groups::largest_index(&g.triangles),
            };
            let bad = (!g.triangles.is_empty() && largest as usize >= n)
                || g.lines.iter().flatten().any(|&v| v as usize >= n)
                || g.points.iter().any(|&v| v as usize >= n)
                || g.volumes.iter().flatten().any(|&v| v as usize >= n);
            if bad {
                return Err(vec![Diagnostic::new(
                    Code::MeshIndexOutOfRange,
                    None,
                    format!("group `{}` refers to a node beyond the {n} nodes", g.name),
                )]);
            }
        }
        let non_finite = |i: usize| {
            vec![Diagnostic::new(
                Code::MeshNonFinite,
                None,
                format!("node {} has a coordinate that is not finite", i + 1),
            )]
        };
        let facts = if facts {
            match found.nodes {
                Some((count, bounds)) if count == n => Some(MeshFacts::of_finite(n, bounds, faces)),
                _ => Some(MeshFacts::of(&self.nodes, faces).map_err(non_finite)?),
            }
        } else {
            if let Some(i) = crate::formats::groups::first_non_finite(&self.nodes) {
                return Err(non_finite(i));
            }
            None
        };
        let mut mesh = Mesh {
            dimension: 3,
            nodes: self.nodes,
            ..Mesh::default()
        };
        let mut face_of_group = HashMap::new();
        for g in &mut self.groups {
            for (kind, nodes) in CellKind::ALL.into_iter().zip(&mut g.volumes) {
                if !nodes.is_empty() {
                    mesh.volumes.push(MeshVolume {
                        name: g.name.clone(),
                        kind,
                        nodes: std::mem::take(nodes),
                    });
                }
            }
        }
        for g in self.groups {
            if !g.triangles.is_empty() {
                face_of_group.insert(g.name.clone(), mesh.faces.len() as u32);
                mesh.faces.push(MeshFace {
                    name: g.name.clone(),
                    triangles: g.triangles,
                    boundary: Vec::new(),
                });
            }
            for chain in chains(&g.lines) {
                mesh.polylines.push(MeshPolyline {
                    name: g.name.clone(),
                    nodes: chain,
                });
            }
            if !g.points.is_empty() {
                mesh.point_sets.push(MeshPolyline {
                    name: g.name,
                    nodes: g.points,
                });
            }
        }
        attach_fragments(&mut mesh, &self.subdomains, &self.fragments, &face_of_group);
        let loaded = Loaded {
            mesh,
            warnings: self.warnings,
            report: clean::CleanReport::default(),
            binary: None,
        };
        Ok((loaded, facts))
    }
}

/// Subdomains and fragments named by the file: each fragment's face is
/// outward for its subdomain and inward for the other one.
fn attach_fragments(
    mesh: &mut Mesh,
    subdomains: &[(String, Option<String>)],
    fragments: &[FragmentInfo],
    face_of_group: &HashMap<String, u32>,
) {
    if subdomains.is_empty() {
        return;
    }
    let index: HashMap<&str, u32> = subdomains
        .iter()
        .enumerate()
        .map(|(i, (name, _))| (name.as_str(), i as u32))
        .collect();
    mesh.subdomains = subdomains
        .iter()
        .map(|(name, material)| MeshSubdomain {
            name: name.clone(),
            material: material.clone(),
            faces: Vec::new(),
        })
        .collect();
    for fr in fragments {
        let (Some(&face), Some(&sub)) = (
            face_of_group.get(&fr.group),
            index.get(fr.subdomain.as_str()),
        ) else {
            continue;
        };
        let other = fr.other.as_deref().and_then(|o| index.get(o).copied());
        // The index maps names to positions in `mesh.subdomains`.
        if let Some(s) = mesh.subdomains.get_mut(sub as usize) {
            s.faces.push((face, true));
        }
        if let Some(s) = other.and_then(|o| mesh.subdomains.get_mut(o as usize)) {
            s.faces.push((face, false));
        }
        mesh.fragments.push(MeshFragment {
            name: fr.group.clone(),
            subdomain: sub,
            other,
            faces: vec![face],
            edges: Vec::new(),
        });
    }
}

/// Line segments as polylines: consecutive segments that share a node make
/// one run (the way the writers emit them).
pub fn chains(segments: &[[u32; 2]]) -> Vec<Vec<u32>> {
    let mut out: Vec<Vec<u32>> = Vec::new();
    for &[a, b] in segments {
        match out.last_mut() {
            Some(run) if run.last() == Some(&a) => run.push(b),
            _ => out.push(vec![a, b]),
        }
    }
    out
}

/// foldhash with a fixed seed: the node maps hash millions of keys, where
/// SipHash's protection against chosen keys is not needed (input files only
/// choose coordinates, and a slow map is the worst they can cause). A plain
/// multiply-rotate hash was tried: coordinates read as f32 leave 29 low bits
/// zero, and its bucket tags collided so often that key compares took half
/// of an STL conversion.
pub type FastMap<K, V> = HashMap<K, V, foldhash::fast::FixedState>;

/// Merges nodes with bit-identical coordinates (−0 equals 0), for formats
/// that repeat a vertex per triangle (STL).
///
/// A small direct-mapped cache of recent vertices sits in front of the map:
/// neighbouring triangles share corners, so most repeats are found there,
/// and the map (far larger than the processor's caches on big files) is
/// touched about once per distinct node. Same nodes, same order.
pub struct NodeDedup {
    map: FastMap<[u64; 3], u32>,
    recent: Vec<([u64; 3], u32)>,
}

/// Entries of [`NodeDedup`]'s cache (a power of two; 128 kB).
const RECENT: usize = 1 << 12;

impl Default for NodeDedup {
    fn default() -> NodeDedup {
        NodeDedup::with_capacity(0)
    }
}

impl NodeDedup {
    pub fn with_capacity(n: usize) -> NodeDedup {
        let mut map = FastMap::default();
        map.reserve(n);
        NodeDedup {
            map,
            recent: vec![([0; 3], u32::MAX); RECENT],
        }
    }

    pub fn node(&mut self, nodes: &mut Vec<[f64; 3]>, p: [f64; 3]) -> u32 {
        let key = p.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
        // The high bits of a multiply mix all of the key's bits.
        let mix = (key[0] ^ key[1].rotate_left(21) ^ key[2].rotate_left(42))
            .wrapping_mul(0x9e37_79b9_7f4a_7c15);
        let slot = (mix >> 52) as usize & (RECENT - 1);
        if let Some(&(cached, id)) = self.recent.get(slot)
            && id != u32::MAX
            && cached == key
        {
            return id;
        }
        let id = *self.map.entry(key).or_insert_with(|| {
            nodes.push(p);
            (nodes.len() - 1) as u32
        });
        if let Some(entry) = self.recent.get_mut(slot) {
            *entry = (key, id);
        }
        id
    }
}
