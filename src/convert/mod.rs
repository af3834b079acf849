//! `geomc convert`'s mesh operations between reading and writing: keep only
//! some groups, scale, rotate, translate, weld nearby nodes, and orient
//! triangles consistently. Each works on the mesh IR in place and reports
//! what it did; [`inspect`] summarises a mesh file for `geomc inspect`.

pub mod boundary;
pub mod inspect;
mod orient;
mod weld;

use crate::diag::{Code, Diagnostic, did_you_mean};
use crate::mesh::Mesh;

pub use orient::orient;
pub use weld::weld;

/// What the command line asks for, applied in this order: groups, scale,
/// rotate, translate, weld, normals.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ConvertOptions {
    /// Names of the groups to keep; empty keeps all.
    pub groups: Vec<String>,
    pub scale: Option<[f64; 3]>,
    /// Degrees about x, then y, then z.
    pub rotate: Option<[f64; 3]>,
    pub translate: Option<[f64; 3]>,
    /// Merge nodes closer than this.
    pub weld: Option<f64>,
    /// Orient triangles consistently (outward on closed surfaces).
    pub normals: bool,
}

/// What the operations did, for the command line to tell.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Applied {
    pub notes: Vec<String>,
}

/// Applies the options to a mesh. Errors: `--group` names no group.
pub fn apply(mesh: &mut Mesh, options: &ConvertOptions) -> Result<Applied, Vec<Diagnostic>> {
    let mut applied = Applied::default();
    if !options.groups.is_empty() {
        keep_groups(mesh, &options.groups)?;
    }
    let mut matrix = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if let Some(s) = options.scale {
        matrix = mul(
            &[[s[0], 0.0, 0.0], [0.0, s[1], 0.0], [0.0, 0.0, s[2]]],
            &matrix,
        );
    }
    if let Some(r) = options.rotate {
        let [x, y, z] = r.map(f64::to_radians);
        let rx = [
            [1.0, 0.0, 0.0],
            [0.0, x.cos(), -x.sin()],
            [0.0, x.sin(), x.cos()],
        ];
        let ry = [
            [y.cos(), 0.0, y.sin()],
            [0.0, 1.0, 0.0],
            [-y.sin(), 0.0, y.cos()],
        ];
        let rz = [
            [z.cos(), -z.sin(), 0.0],
            [z.sin(), z.cos(), 0.0],
            [0.0, 0.0, 1.0],
        ];
        matrix = mul(&rz, &mul(&ry, &mul(&rx, &matrix)));
    }
    let t = options.translate.unwrap_or([0.0; 3]);
    if options.scale.is_some() || options.rotate.is_some() || options.translate.is_some() {
        for p in &mut mesh.nodes {
            let q = *p;
            for (i, row) in matrix.iter().enumerate() {
                p[i] = row[0] * q[0] + row[1] * q[1] + row[2] * q[2] + t[i];
            }
        }
        if det(&matrix) < 0.0 {
            // A mirror turns the surface inside out: reverse the triangles so
            // outward normals stay outward.
            for f in &mut mesh.faces {
                for tri in &mut f.triangles {
                    tri.swap(1, 2);
                }
            }
            crate::mesh::volume::permute(&mut mesh.volumes, crate::mesh::CellKind::mirror_order);
            applied
                .notes
                .push("the transform mirrors: triangles reversed to keep their orientation".into());
        }
    }
    if let Some(eps) = options.weld {
        let w = weld(mesh, eps);
        applied.notes.push(format!(
            "--weld {eps}: {} nodes merged into others, {} collapsed triangles removed",
            w.merged, w.removed_triangles
        ));
        if w.removed_cells > 0 {
            applied.notes.push(format!(
                "--weld {eps}: {} volume cells with merged corners removed",
                w.removed_cells
            ));
        }
    }
    if options.normals {
        let o = orient(mesh);
        applied.notes.push(format!(
            "--normals: {} of {} triangles reversed ({} connected surfaces, {} closed)",
            o.flipped, o.triangles, o.components, o.closed
        ));
    }
    Ok(applied)
}

/// Keeps the faces, poly_lines, point sets and volume groups whose names are listed, and
/// the fragments and subdomains over kept faces; unused nodes are removed.
fn keep_groups(mesh: &mut Mesh, names: &[String]) -> Result<(), Vec<Diagnostic>> {
    let known: Vec<&str> = mesh
        .faces
        .iter()
        .map(|f| f.name.as_str())
        .chain(mesh.polylines.iter().map(|p| p.name.as_str()))
        .chain(mesh.point_sets.iter().map(|p| p.name.as_str()))
        .chain(mesh.fragments.iter().map(|f| f.name.as_str()))
        .chain(mesh.volumes.iter().map(|v| v.name.as_str()))
        .collect();
    let errors: Vec<Diagnostic> = names
        .iter()
        .filter(|n| !known.contains(&n.as_str()))
        .map(|n| {
            let mut d = Diagnostic::new(
                Code::UnknownGroup,
                None,
                format!("--group {n}: the mesh has no group `{n}`"),
            );
            if let Some(s) = did_you_mean(n, known.iter().copied()) {
                d = d.with_help(format!("did you mean `{s}`?"));
            }
            d
        })
        .collect();
    if !errors.is_empty() {
        return Err(errors);
    }
    let keep = |name: &str| names.iter().any(|n| n == name);
    // A fragment named on the command line keeps its faces.
    let mut keep_face: Vec<bool> = mesh.faces.iter().map(|f| keep(&f.name)).collect();
    for fr in &mesh.fragments {
        if keep(&fr.name) {
            for &f in &fr.faces {
                keep_face[f as usize] = true;
            }
        }
    }
    let mut new_index = vec![u32::MAX; mesh.faces.len()];
    let mut faces = Vec::new();
    for (i, f) in std::mem::take(&mut mesh.faces).into_iter().enumerate() {
        if keep_face[i] {
            new_index[i] = faces.len() as u32;
            faces.push(f);
        }
    }
    mesh.faces = faces;
    let remap = |f: u32| Some(new_index[f as usize]).filter(|&n| n != u32::MAX);
    for fr in &mut mesh.fragments {
        fr.faces = fr.faces.iter().filter_map(|&f| remap(f)).collect();
    }
    mesh.fragments.retain(|fr| !fr.faces.is_empty());
    for s in &mut mesh.subdomains {
        s.faces = s
            .faces
            .iter()
            .filter_map(|&(f, o)| remap(f).map(|n| (n, o)))
            .collect();
    }
    mesh.polylines.retain(|p| keep(&p.name));
    mesh.point_sets.retain(|p| keep(&p.name));
    mesh.volumes.retain(|v| keep(&v.name));
    mesh.vertices.clear();
    mesh.edges.clear();
    for f in &mut mesh.faces {
        f.boundary.clear();
    }
    compact_nodes(mesh);
    Ok(())
}

/// Drops nodes nothing uses and renumbers the rest in order.
pub fn compact_nodes(mesh: &mut Mesh) {
    let mut used = vec![false; mesh.nodes.len()];
    let mut mark = |n: u32| used[n as usize] = true;
    mesh.faces
        .iter()
        .flat_map(|f| f.triangles.iter().flatten())
        .for_each(|&n| mark(n));
    mesh.edges
        .iter()
        .flat_map(|e| &e.nodes)
        .for_each(|&n| mark(n));
    mesh.polylines
        .iter()
        .chain(&mesh.point_sets)
        .flat_map(|p| &p.nodes)
        .for_each(|&n| mark(n));
    mesh.vertices.iter().for_each(|v| mark(v.node));
    mesh.volumes
        .iter()
        .flat_map(|v| &v.nodes)
        .for_each(|&n| mark(n));
    if used.iter().all(|&u| u) {
        return;
    }
    let mut map = vec![u32::MAX; mesh.nodes.len()];
    let mut nodes = Vec::new();
    for (i, p) in mesh.nodes.iter().enumerate() {
        if used[i] {
            map[i] = nodes.len() as u32;
            nodes.push(*p);
        }
    }
    mesh.nodes = nodes;
    renumber(mesh, &map);
}

/// Replaces every node index `n` by `map[n]`.
pub(crate) fn renumber(mesh: &mut Mesh, map: &[u32]) {
    let m = |n: &mut u32| *n = map[*n as usize];
    mesh.faces
        .iter_mut()
        .flat_map(|f| f.triangles.iter_mut().flatten())
        .for_each(m);
    mesh.edges
        .iter_mut()
        .flat_map(|e| e.nodes.iter_mut())
        .for_each(m);
    mesh.polylines
        .iter_mut()
        .chain(mesh.point_sets.iter_mut())
        .flat_map(|p| p.nodes.iter_mut())
        .for_each(m);
    mesh.vertices.iter_mut().for_each(|v| m(&mut v.node));
    mesh.volumes
        .iter_mut()
        .flat_map(|v| v.nodes.iter_mut())
        .for_each(m);
}

type M3 = [[f64; 3]; 3];

fn mul(a: &M3, b: &M3) -> M3 {
    let mut out = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    out
}

fn det(m: &M3) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}
