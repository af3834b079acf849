//! Implicit subdomains into geomc's mesh IR: each subdomain's closed surface
//! is one face (`NAME_boundary`) and its fragment against the exterior
//! (`NAME|exterior`), plus the cap where it leaves its box (`NAME_box_cap`,
//! `NAME|box`); `--section` adds the contour lines of a plane cut as
//! line elements (`NAME_section_K`). Touching function subdomains share
//! their interface faces (`joint`).

use super::ImplicitSubdomain;
use super::joint;
use crate::implicit::caps::split_caps;
use crate::implicit::{push_boundary, section};
use crate::mesh::{Mesh, MeshPolyline, MeshSubdomain};
use rayon::prelude::*;

/// A plane x, y or z = value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    pub axis: usize,
    pub value: f64,
}

impl Plane {
    /// `AXIS=VALUE`, as `--section` takes it.
    pub fn parse(text: &str) -> Option<Plane> {
        let (axis, value) = text.split_once('=')?;
        let axis = ["x", "y", "z"]
            .iter()
            .position(|a| a.eq_ignore_ascii_case(axis.trim()))?;
        let value: f64 = value.trim().parse().ok().filter(|v: &f64| v.is_finite())?;
        Some(Plane { axis, value })
    }
}

/// What was added: triangles per subdomain and the subdomains the section
/// plane missed.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct Appended {
    pub triangles: Vec<usize>,
    pub missed_by_section: Vec<String>,
}

/// Polygonizes every subdomain (in parallel, results in input order) and
/// appends it to `mesh`. Function subdomains that touch one another are
/// meshed together (`interfaces`): the surface between two of them is one
/// face `A|B` shared by both, with the fragment `A|B`.
pub fn append(
    mesh: &mut Mesh,
    subdomains: &[ImplicitSubdomain],
    cells: Option<usize>,
    section: Option<Plane>,
) -> Appended {
    let joint = joint::mesh_touching(subdomains, cells);
    let surfaces: Vec<_> = subdomains
        .par_iter()
        .enumerate()
        .map(|(i, s)| {
            if joint.as_ref().is_some_and(|j| j.members.contains(&i)) {
                Default::default()
            } else {
                s.polygonize(cells)
            }
        })
        .collect();
    let mut out = Appended::default();
    mesh.dimension = 3;
    let first = mesh.subdomains.len() as u32;
    for sub in subdomains {
        mesh.subdomains.push(MeshSubdomain {
            name: sub.name.clone(),
            material: sub.material.clone(),
            faces: Vec::new(),
        });
    }
    let joint_counts = joint
        .as_ref()
        .map(|j| joint::add(mesh, j, subdomains, first))
        .unwrap_or_default();
    for (i, (sub, surface)) in subdomains.iter().zip(&surfaces).enumerate() {
        let index = first + i as u32;
        if let Some(j) = joint.as_ref().filter(|j| j.members.contains(&i)) {
            out.triangles.push(joint_counts[i]);
            if let Some(plane) = section {
                let (positions, triangles) = j.boundary_of(i);
                if !add_section(mesh, &positions, &triangles, &sub.name, plane) {
                    out.missed_by_section.push(sub.name.clone());
                }
            }
            continue;
        }
        let base = mesh.nodes.len() as u32;
        mesh.nodes.extend_from_slice(&surface.positions);
        let (min, max) = sub.bounds();
        let (rest, caps) = split_caps(&surface.positions, &surface.triangles, min, max);
        let shift = |t: Vec<[u32; 3]>| t.into_iter().map(|t| t.map(|i| i + base)).collect();
        push_boundary(mesh, index, &sub.name, shift(rest), shift(caps));
        out.triangles.push(surface.triangles.len());
        if let Some(plane) = section
            && !add_section(
                mesh,
                &surface.positions,
                &surface.triangles,
                &sub.name,
                plane,
            )
        {
            out.missed_by_section.push(sub.name.clone());
        }
    }
    out
}

/// Adds the contour lines of `plane` on a surface as polylines `NAME_section_K`
/// (closed loops end on their first node); false when the plane misses it.
pub fn add_section(
    mesh: &mut Mesh,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    name: &str,
    plane: Plane,
) -> bool {
    let lines = section::contours(positions, triangles, plane.axis, plane.value);
    let any = !lines.is_empty();
    for (k, line) in lines.into_iter().enumerate() {
        let first = mesh.nodes.len() as u32;
        let closed = line.len() > 2 && line.first() == line.last();
        let n = if closed { line.len() - 1 } else { line.len() };
        mesh.nodes.extend_from_slice(&line[..n]);
        let mut nodes: Vec<u32> = (first..first + n as u32).collect();
        if closed {
            nodes.push(first);
        }
        mesh.polylines.push(MeshPolyline {
            name: format!("{name}_section_{}", k + 1),
            nodes,
        });
    }
    any
}
