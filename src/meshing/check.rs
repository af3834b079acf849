//! Checks and measures of a [`Mesh`]: `sanity_check` verifies the invariants
//! every writer relies on (spade's habit of checking after each change in
//! tests), `quality` reports angles, aspect ratios, volumes and areas.

use crate::mesh::Mesh;
use std::collections::BTreeMap;

/// Mesh quality figures. Angles are in degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct Quality {
    /// The smallest triangle angle over all faces (180 when there are none).
    pub min_angle: f64,
    /// Triangles per 5° bin of their smallest angle: [0, 5), [5, 10), … [55, 60].
    pub min_angle_histogram: [usize; 12],
    /// The largest longest-edge / (2√3 · inradius) ratio: 1 for equilateral triangles.
    pub max_aspect_ratio: f64,
    /// The smallest angle per face, in face order (180 for faces without triangles).
    pub face_min_angles: Vec<f64>,
    pub subdomains: Vec<SubdomainMeasure>,
}

/// What a subdomain's triangles enclose.
#[derive(Debug, Clone, PartialEq)]
pub struct SubdomainMeasure {
    pub name: String,
    /// 3D: the enclosed volume by the divergence theorem (outward faces
    /// positive). 2D: 0.
    pub volume: f64,
    /// 3D: the boundary surface area. 2D: the region's area.
    pub area: f64,
}

/// Verifies indices, non-degenerate triangles, closed and consistently
/// oriented subdomain boundaries (3D) or regions (2D), and conformity: every
/// face's triangles meet its edges' polylines exactly (no T-junctions).
pub fn sanity_check(mesh: &Mesh) -> Result<(), String> {
    let n = mesh.nodes.len();
    if let Some(i) = mesh
        .nodes
        .iter()
        .position(|p| !p.iter().all(|x| x.is_finite()))
    {
        return Err(format!("node {i} is not finite"));
    }
    let node_ok = |i: u32| (i as usize) < n;
    for v in &mesh.vertices {
        if !node_ok(v.node) {
            return Err(format!(
                "vertex {} has node {} out of range",
                v.name, v.node
            ));
        }
    }
    for e in &mesh.edges {
        if e.nodes.len() < 2 || !e.nodes.iter().all(|&i| node_ok(i)) {
            return Err(format!("edge {} has bad nodes", e.name));
        }
    }
    for line in mesh.point_sets.iter().chain(&mesh.polylines) {
        if !line.nodes.iter().all(|&i| node_ok(i)) {
            return Err(format!("{} has nodes out of range", line.name));
        }
    }
    for face in &mesh.faces {
        for t in &face.triangles {
            if !t.iter().all(|&i| node_ok(i)) {
                return Err(format!("face {} has a node out of range", face.name));
            }
            if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
                return Err(format!(
                    "face {} has a degenerate triangle {t:?}",
                    face.name
                ));
            }
            let [a, b, c] = t.map(|i| nalgebra::Vector3::from(mesh.nodes[i as usize]));
            if no_area_width(&a, &b, &c).is_some() {
                return Err(format!(
                    "face {} has a triangle of no area {t:?}",
                    face.name
                ));
            }
        }
        check_conformity(mesh, face)?;
    }
    for fragment in &mesh.fragments {
        let bad_face = fragment
            .faces
            .iter()
            .any(|&f| f as usize >= mesh.faces.len());
        let bad_edge = fragment
            .edges
            .iter()
            .any(|&e| e as usize >= mesh.edges.len());
        if bad_face || bad_edge || fragment.subdomain as usize >= mesh.subdomains.len() {
            return Err(format!(
                "fragment {} refers to a missing entity",
                fragment.name
            ));
        }
    }
    for sub in &mesh.subdomains {
        let mut directed: BTreeMap<(u32, u32), usize> = BTreeMap::new();
        for &(f, outward) in &sub.faces {
            let face = mesh
                .faces
                .get(f as usize)
                .ok_or_else(|| format!("subdomain {} has face {f} out of range", sub.name))?;
            for t in &face.triangles {
                let t = if outward { *t } else { [t[0], t[2], t[1]] };
                for k in 0..3 {
                    *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
                }
            }
        }
        for (&(a, b), &count) in &directed {
            let back = directed.get(&(b, a)).copied().unwrap_or(0);
            if count > 1 {
                return Err(format!(
                    "subdomain {}: edge {a}→{b} is used {count} times in one direction",
                    sub.name
                ));
            }
            if mesh.dimension == 3 && back != 1 {
                return Err(format!(
                    "subdomain {}: edge {a}–{b} is not shared by exactly two triangles (open or non-manifold)",
                    sub.name
                ));
            }
        }
    }
    Ok(())
}

/// Each segment of the face's edges must be used by its triangles as many
/// times as the edge occurs in its loops (twice for a torus seam), and every
/// other triangle edge exactly twice.
fn check_conformity(mesh: &Mesh, face: &crate::mesh::MeshFace) -> Result<(), String> {
    if face.triangles.is_empty() {
        return Ok(());
    }
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut used: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for t in &face.triangles {
        for k in 0..3 {
            *used.entry(key(t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    let mut expected: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for &(e, _) in &face.boundary {
        let edge = mesh
            .edges
            .get(e as usize)
            .ok_or_else(|| format!("face {} has edge {e} out of range", face.name))?;
        for w in edge.nodes.windows(2) {
            *expected.entry(key(w[0], w[1])).or_default() += 1;
        }
    }
    for (segment, &count) in &used {
        let want = expected.get(segment).copied().unwrap_or(2);
        if count != want {
            return Err(format!(
                "face {}: segment {segment:?} is used by {count} triangles, expected {want} (not conforming)",
                face.name
            ));
        }
    }
    if let Some(missing) = expected.keys().find(|s| !used.contains_key(s)) {
        return Err(format!(
            "face {}: boundary segment {missing:?} is not used by any triangle",
            face.name
        ));
    }
    Ok(())
}

pub fn quality(mesh: &Mesh) -> Quality {
    let point = |i: u32| {
        mesh.nodes
            .get(i as usize)
            .map_or(nalgebra::Vector3::zeros(), |p| nalgebra::Vector3::from(*p))
    };
    let mut q = Quality {
        min_angle: 180.0,
        min_angle_histogram: [0; 12],
        max_aspect_ratio: 0.0,
        face_min_angles: Vec::with_capacity(mesh.faces.len()),
        subdomains: Vec::new(),
    };
    for face in &mesh.faces {
        let mut face_min: f64 = 180.0;
        for t in &face.triangles {
            let [a, b, c] = t.map(point);
            let (ab, bc, ca) = ((b - a).norm(), (c - b).norm(), (a - c).norm());
            let angle =
                |u: nalgebra::Vector3<f64>, v: nalgebra::Vector3<f64>| u.angle(&v).to_degrees();
            let smallest = angle(b - a, c - a)
                .min(angle(a - b, c - b))
                .min(angle(a - c, b - c));
            face_min = face_min.min(smallest);
            let bin = ((smallest / 5.0).floor().max(0.0) as usize).min(11);
            q.min_angle_histogram[bin] += 1;
            let area = 0.5 * (b - a).cross(&(c - a)).norm();
            let inradius = 2.0 * area / (ab + bc + ca);
            let aspect = ab.max(bc).max(ca) / (2.0 * 3f64.sqrt() * inradius);
            q.max_aspect_ratio = q.max_aspect_ratio.max(if aspect.is_nan() {
                f64::INFINITY
            } else {
                aspect
            });
        }
        q.min_angle = q.min_angle.min(face_min);
        q.face_min_angles.push(face_min);
    }
    for sub in &mesh.subdomains {
        let (mut volume, mut area) = (0.0, 0.0);
        for &(f, outward) in &sub.faces {
            let Some(face) = mesh.faces.get(f as usize) else {
                continue;
            };
            let sign = if outward { 1.0 } else { -1.0 };
            for t in &face.triangles {
                let [a, b, c] = t.map(point);
                area += 0.5 * (b - a).cross(&(c - a)).norm();
                if mesh.dimension == 3 {
                    volume += sign * a.dot(&b.cross(&c)) / 6.0;
                }
            }
        }
        q.subdomains.push(SubdomainMeasure {
            name: sub.name.clone(),
            volume,
            area,
        });
    }
    q
}

/// The width (twice the area over the longest side) of a triangle whose
/// area is below 1e-14 of its longest side squared, or `None` for a triangle
/// with area.
pub(crate) fn no_area_width(
    a: &nalgebra::Vector3<f64>,
    b: &nalgebra::Vector3<f64>,
    c: &nalgebra::Vector3<f64>,
) -> Option<f64> {
    // Compared squared (no square root for the triangles that pass: this
    // runs over every triangle of a mesh).
    let longest2 = (b - a)
        .norm_squared()
        .max((c - b).norm_squared())
        .max((a - c).norm_squared());
    let twice2 = (b - a).cross(&(c - a)).norm_squared();
    (twice2 <= 1e-28 * longest2 * longest2)
        .then(|| twice2.sqrt() / longest2.sqrt().max(f64::MIN_POSITIVE))
}
