//! Trimmed surfaces as faces of 3D subdomains (issue 9). A subdomain's
//! `faces=` may name trimmed surfaces; their chains exist only on the mesh,
//! so here, after they are appended: the outward flags are the topology
//! IR's (`lower/trimmed_topology.rs`, as for any face list), checked on the
//! mesh, where each one's outward side is taken from a neighbour across a
//! shared mesh edge (a consistently oriented shell runs a shared edge both
//! ways), starting from the model faces' own flags — or, with no model
//! face, from the first trimmed face and then all flipped if the enclosed
//! volume is negative. The shell must close (every mesh edge used by two of
//! its triangles), and each trimmed face joins the fragment between its
//! subdomains (`A|exterior`, `A|B`) as model faces do. Triangles stay
//! counter-clockwise about R_u × R_v, the IR face's normal.

use super::MeshError;
use crate::ir::Model;
use crate::mesh::{Mesh, MeshFragment};
use std::collections::{BTreeMap, HashSet};

/// `first` is the mesh face index of `model.trimmed[0]` (they are appended
/// in model order).
pub(super) fn join(
    model: &Model,
    full: &Model,
    mesh: &mut Mesh,
    first: usize,
) -> Result<(), MeshError> {
    // Which subdomains each trimmed face bounds, for the fragments.
    let mut sides: BTreeMap<usize, Vec<u32>> = BTreeMap::new();
    for (k, sub) in model.subdomains.iter().enumerate() {
        if sub.trimmed.is_empty() {
            continue;
        }
        let trimmed: Vec<u32> = sub.trimmed.iter().map(|&t| (first + t) as u32).collect();
        let known = mesh.subdomains[k].faces.clone();
        let found = orient(mesh, &known, &trimmed, &sub.name)?;
        check_closed(model, mesh, &known, &trimmed, &sub.name, first)?;
        // The IR's flags (`lower/trimmed_topology.rs`) are the faces' own;
        // the mesh, oriented across its shared edges, must agree.
        let flags = match ir_flags(full, k) {
            Some(ir) if ir != found => {
                return Err(MeshError::Internal {
                    entity: format!("subdomain `{}`", sub.name),
                    message: format!(
                        "the outward sides of its trimmed faces are {ir:?} in the model but {found:?} on the mesh"
                    ),
                });
            }
            Some(ir) => ir,
            None => found,
        };
        for (&f, outward) in trimmed.iter().zip(flags) {
            mesh.subdomains[k].faces.push((f, outward));
            sides.entry(f as usize).or_default().push(k as u32);
        }
    }
    for (f, subs) in sides {
        let (k, other) = match subs.as_slice() {
            [k] => (*k, None),
            [k, k2] => (*k, Some(*k2)),
            _ => {
                return Err(MeshError::Face {
                    face: mesh.faces[f].name.clone(),
                    reason: format!(
                        "it bounds {} subdomains; a face separates at most two",
                        subs.len()
                    ),
                });
            }
        };
        let name = match other {
            None => format!("{}|exterior", model.subdomains[k as usize].name),
            Some(k2) => format!(
                "{}|{}",
                model.subdomains[k as usize].name, model.subdomains[k2 as usize].name
            ),
        };
        match mesh
            .fragments
            .iter_mut()
            .find(|g| g.subdomain == k && g.other == other && g.name == name)
        {
            Some(g) => g.faces.push(f as u32),
            None => mesh.fragments.push(MeshFragment {
                name,
                subdomain: k,
                other,
                faces: vec![f as u32],
                edges: Vec::new(),
            }),
        }
    }
    Ok(())
}

/// The directed edges of a face's triangles, reversed when `outward` is false.
fn directed(mesh: &Mesh, face: u32, outward: bool) -> HashSet<(u32, u32)> {
    mesh.faces[face as usize]
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .map(|(a, b)| if outward { (a, b) } else { (b, a) })
        .collect()
}

/// Outward flags of `trimmed`, consistent with `known` across shared edges.
fn orient(
    mesh: &Mesh,
    known: &[(u32, bool)],
    trimmed: &[u32],
    subdomain: &str,
) -> Result<Vec<bool>, MeshError> {
    let mut oriented: HashSet<(u32, u32)> = HashSet::new();
    for &(f, outward) in known {
        oriented.extend(directed(mesh, f, outward));
    }
    let mut flags: Vec<Option<bool>> = vec![None; trimmed.len()];
    let seeded = known.is_empty();
    if seeded {
        flags[0] = Some(true);
        oriented.extend(directed(mesh, trimmed[0], true));
    }
    loop {
        let mut progress = false;
        for (k, &f) in trimmed.iter().enumerate() {
            if flags[k].is_some() {
                continue;
            }
            let own = directed(mesh, f, true);
            // A shared edge runs the other way in the oriented neighbour.
            let agree = own.iter().any(|&(a, b)| oriented.contains(&(b, a)));
            let disagree = own.iter().any(|&(a, b)| oriented.contains(&(a, b)));
            if agree || disagree {
                let outward = agree;
                flags[k] = Some(outward);
                oriented.extend(directed(mesh, f, outward));
                progress = true;
            }
        }
        if !progress {
            break;
        }
    }
    let mut out = Vec::with_capacity(trimmed.len());
    for (k, flag) in flags.into_iter().enumerate() {
        match flag {
            Some(o) => out.push(o),
            None => {
                return Err(MeshError::Face {
                    face: mesh.faces[trimmed[k] as usize].name.clone(),
                    reason: format!(
                        "it shares no boundary nodes with the other faces of subdomain `{subdomain}`; make its trim curve run along a neighbour's boundary (within the tolerance)"
                    ),
                });
            }
        }
    }
    if seeded && signed_volume(mesh, trimmed, &out) < 0.0 {
        out.iter_mut().for_each(|o| *o = !*o);
    }
    Ok(out)
}

/// Six times the volume enclosed by the faces with their flags.
fn signed_volume(mesh: &Mesh, faces: &[u32], outward: &[bool]) -> f64 {
    let p = |i: u32| nalgebra::Vector3::from(mesh.nodes[i as usize]);
    faces
        .iter()
        .zip(outward)
        .map(|(&f, &o)| {
            let sum: f64 = mesh.faces[f as usize]
                .triangles
                .iter()
                .map(|t| p(t[0]).dot(&p(t[1]).cross(&p(t[2]))))
                .sum();
            if o { sum } else { -sum }
        })
        .sum()
}

/// Every mesh edge of the shell used by exactly two of its triangles.
fn check_closed(
    model: &Model,
    mesh: &Mesh,
    known: &[(u32, bool)],
    trimmed: &[u32],
    subdomain: &str,
    first: usize,
) -> Result<(), MeshError> {
    let mut uses: BTreeMap<(u32, u32), (usize, u32)> = BTreeMap::new();
    let faces = known.iter().map(|&(f, _)| f).chain(trimmed.iter().copied());
    for f in faces {
        for t in &mesh.faces[f as usize].triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let e = uses.entry((a.min(b), a.max(b))).or_insert((0, f));
                e.0 += 1;
            }
        }
    }
    if let Some((&(a, b), &(n, f))) = uses.iter().find(|(_, u)| u.0 != 2) {
        let name = mesh.faces[f as usize].name.clone();
        let trimmed_face = (f as usize) >= first && (f as usize) < first + model.trimmed.len();
        let hint = if trimmed_face {
            "a trim chain that should meet another face does not coincide with its boundary within twice the tolerance"
        } else {
            "a face's boundary is not met by a trimmed surface's trim chain or side"
        };
        return Err(MeshError::Face {
            face: name,
            reason: format!(
                "the boundary of subdomain `{subdomain}` is not closed: the mesh edge between nodes {a} and {b} is used by {n} triangle{}; {hint}",
                if n == 1 { "" } else { "s" }
            ),
        });
    }
    Ok(())
}

/// The topology IR's outward flags of subdomain `k`'s trimmed faces, in
/// `Subdomain::trimmed` order (`None` without the trimmed topology).
fn ir_flags(full: &Model, k: usize) -> Option<Vec<bool>> {
    let [_, _, f0] = full.trimmed_start?;
    let sub = full.subdomains.get(k)?;
    let crate::ir::SubdomainCells::Volume { boundary } = &sub.cells else {
        return None;
    };
    sub.trimmed
        .iter()
        .map(|&t| {
            boundary
                .iter()
                .find(|of| of.face.index() == f0 + t)
                .map(|of| of.outward)
        })
        .collect()
}
