//! `.frag.xml`: geomc's description of a mesh file's structure. Loading one
//! reads the mesh file it names (relative to its folder) and puts the
//! structure back on that mesh: face names, subdomains (from M_FD) and
//! fragments with their subdomain pairs. Faces are matched by name, or by
//! the `face N` a `.vtu`'s `face_id` gives, and must have the triangle
//! counts the description says.

use super::build::FastMap;
use super::{Loaded, ReadFormat, ReadLimits, check_named_file, load_mesh_limited};
use crate::diag::{Code, Diagnostic};
use crate::formats::frag::{FragDocument, read_frag_xml};
use crate::mesh::{MeshFragment, MeshSubdomain};
use crate::span::Span;
use std::path::Path;

pub fn load(path: &Path, bytes: &[u8], limits: &ReadLimits) -> Result<Loaded, Vec<Diagnostic>> {
    let text = String::from_utf8_lossy(bytes);
    let name = path.display().to_string();
    let doc = read_frag_xml(&name, &text).map_err(|e| {
        // The reader renders its own position; keep it in the message.
        vec![Diagnostic::new(
            Code::MeshSyntax,
            None,
            format!("{}: {}", e.location, e.message),
        )]
    })?;
    let Some(file) = doc.mesh_file.clone() else {
        return Err(vec![Diagnostic::new(
            Code::FragMeshMismatch,
            Some(Span::new(0, 1)),
            "the .frag.xml names no mesh file (<mesh file=\"…\"/>), so there are no coordinates to read",
        )]);
    };
    if file.contains("..") || Path::new(&file).is_absolute() {
        return Err(vec![Diagnostic::new(
            Code::FragMeshMismatch,
            None,
            format!("the mesh file `{file}` is outside the .frag.xml's folder"),
        )]);
    }
    let mesh_path = path.parent().unwrap_or(Path::new("")).join(&file);
    let format = ReadFormat::from_path(&mesh_path);
    if format == Some(ReadFormat::FragXml) {
        return Err(vec![Diagnostic::new(
            Code::FragMeshMismatch,
            None,
            format!("the mesh file `{file}` is itself a .frag.xml"),
        )]);
    }
    check_named_file(&mesh_path, "the mesh file", limits.max_file_size).map_err(|d| vec![d])?;
    let mut loaded = load_mesh_limited(&mesh_path, format, limits)?;
    if let Err(by_face) = apply(&mut loaded, &doc, &file) {
        // Formats that group by fragment (MSH, STL solids) match fragment-wise.
        if !apply_by_fragment(&mut loaded, &doc) {
            return Err(vec![by_face]);
        }
    }
    Ok(loaded)
}

fn apply(loaded: &mut Loaded, doc: &FragDocument, file: &str) -> Result<(), Diagnostic> {
    let mesh = &mut loaded.mesh;
    let by_name: FastMap<String, usize> = mesh
        .faces
        .iter()
        .enumerate()
        .map(|(i, f)| (f.name.clone(), i))
        .collect();
    // Frag face i → mesh face.
    let mut map: Vec<Option<u32>> = Vec::with_capacity(doc.faces.len());
    for (i, face) in doc.faces.iter().enumerate() {
        let found = by_name
            .get(&face.name)
            .or_else(|| by_name.get(&format!("face {i}")))
            .copied();
        let count = |m: usize| mesh.faces.get(m).map_or(0, |f| f.triangles.len());
        match found {
            Some(m) if count(m) == face.triangles => {
                map.push(Some(m as u32));
            }
            None if face.triangles == 0 => map.push(None),
            other => {
                let has = other.map_or(0, count);
                return Err(Diagnostic::new(
                    Code::FragMeshMismatch,
                    None,
                    format!(
                        "face `{}` has {} triangles in the .frag.xml but {has} in `{file}`: the two files do not belong together",
                        face.name, face.triangles
                    ),
                )
                .with_help("write the mesh and its .frag.xml in one `geomc compile` or `geomc convert` run"));
            }
        }
    }
    for (face, m) in doc.faces.iter().zip(&map) {
        if let Some(f) = m.and_then(|m| mesh.faces.get_mut(m as usize)) {
            f.name = face.name.clone();
        }
    }
    mesh.dimension = doc.dimension;
    mesh.subdomains = doc
        .subdomains
        .iter()
        .map(|s| MeshSubdomain {
            name: s.name.clone(),
            material: s.material.clone(),
            faces: Vec::new(),
        })
        .collect();
    for &(face, sub, sign) in &doc.m_fd.entries {
        let (Some(Some(m)), Some(s)) = (
            map.get(face as usize),
            mesh.subdomains.get_mut(sub as usize),
        ) else {
            continue;
        };
        s.faces.push((*m, sign >= 0));
    }
    mesh.fragments = doc
        .fragments
        .iter()
        .map(|fr| MeshFragment {
            name: fr.name.clone(),
            subdomain: fr.subdomain,
            other: fr.other,
            faces: fr
                .faces
                .iter()
                .filter_map(|&f| map.get(f as usize).copied().flatten())
                .collect(),
            edges: Vec::new(),
        })
        .filter(|fr| {
            let n = doc.subdomains.len();
            (fr.subdomain as usize) < n && fr.other.is_none_or(|o| (o as usize) < n)
        })
        .collect();
    Ok(())
}

/// Matches each fragment of a 3D description to the mesh face of its name
/// with its triangle count; the faces become the fragments' faces.
fn apply_by_fragment(loaded: &mut Loaded, doc: &FragDocument) -> bool {
    let mesh = &mut loaded.mesh;
    if doc.dimension != 3 {
        return false;
    }
    let by_name: FastMap<&str, usize> = mesh
        .faces
        .iter()
        .enumerate()
        .map(|(i, f)| (f.name.as_str(), i))
        .collect();
    let mut faces = Vec::new();
    for fr in &doc.fragments {
        match by_name.get(fr.name.as_str()) {
            Some(&m) if mesh.faces.get(m).map(|f| f.triangles.len()) == Some(fr.elements) => {
                faces.push(Some(m as u32))
            }
            None if fr.elements == 0 => faces.push(None),
            _ => return false,
        }
    }
    let n_sub = doc.subdomains.len();
    if doc
        .fragments
        .iter()
        .any(|fr| fr.subdomain as usize >= n_sub || fr.other.is_some_and(|o| o as usize >= n_sub))
    {
        return false;
    }
    mesh.subdomains = doc
        .subdomains
        .iter()
        .map(|s| MeshSubdomain {
            name: s.name.clone(),
            material: s.material.clone(),
            faces: Vec::new(),
        })
        .collect();
    mesh.fragments.clear();
    for (fr, face) in doc.fragments.iter().zip(faces) {
        let Some(face) = face else { continue };
        // Both indices were checked against the subdomain count above.
        if let Some(s) = mesh.subdomains.get_mut(fr.subdomain as usize) {
            s.faces.push((face, true));
        }
        if let Some(s) = fr.other.and_then(|o| mesh.subdomains.get_mut(o as usize)) {
            s.faces.push((face, false));
        }
        mesh.fragments.push(MeshFragment {
            name: fr.name.clone(),
            subdomain: fr.subdomain,
            other: fr.other,
            faces: vec![face],
            edges: Vec::new(),
        });
    }
    true
}
