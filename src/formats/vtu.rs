//! VTK XML unstructured grid (`.vtu`), ASCII (the default) or base64 binary.
//! Cells: every face's triangles once (5), edges, 2D fragments' edges and
//! poly_lines as line segments (3), point-set points as vertices (1), volume
//! cells (tetrahedra 10, hexahedra 12, wedges 13, pyramids 14). Cell data
//! (Int32, −1 where it does not apply): `fragment_id`, `subdomain_id`,
//! `other_subdomain_id`, `face_id`, `edge_id`, `polyline_id`, `point_set_id`,
//! and `volume_id` when the mesh has volume cells (one id per volume name).
//! In 3D a triangle's `subdomain_id` / `other_subdomain_id` are its fragment's
//! pair; in 2D a triangle's `subdomain_id` is its region. FieldData arrays
//! name the ids (`Name="inlet"` holding `[id, field index]`); many readers
//! ignore them, so a warning points to the `.frag.xml` for the names.

use super::groups;
use super::{Encoding, MeshWriter, Warning, WriteError, WriteOptions, base64, fmt_num, warning};
use crate::mesh::Mesh;
use std::io::Write;

pub(crate) struct Vtu;

const FIELDS: [&str; 8] = [
    "fragment_id",
    "subdomain_id",
    "other_subdomain_id",
    "face_id",
    "edge_id",
    "polyline_id",
    "point_set_id",
    "volume_id",
];

struct Cell {
    kind: u8,
    nodes: Vec<u32>,
    data: [i32; 8],
}

fn id(i: usize) -> i32 {
    i32::try_from(i).unwrap_or(i32::MAX)
}

impl MeshWriter for Vtu {
    fn name(&self) -> &'static str {
        "vtu"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["vtu"]
    }

    fn keeps_volume_cells(&self) -> bool {
        true
    }

    fn write(
        &self,
        mesh: &Mesh,
        options: &WriteOptions,
        out: &mut dyn Write,
    ) -> Result<Vec<Warning>, WriteError> {
        groups::check(mesh)?;
        let cells = cells(mesh);
        let binary = options.encoding == Some(Encoding::Binary);
        write_grid(mesh, &cells, binary, out)?;
        let mut warnings = Vec::new();
        if !mesh.fragments.is_empty() || !mesh.subdomains.is_empty() {
            warnings.push(warning(
                "vtu",
                "VTU carries fragment and subdomain numbers, not names: write a .frag.xml beside it for the names",
            ));
        }
        Ok(warnings)
    }
}

fn cells(mesh: &Mesh) -> Vec<Cell> {
    let three = mesh.dimension == 3;
    // For every face (3D) or edge (2D): its fragment; for every face (2D): its region.
    let mut face_fragment = vec![None; mesh.faces.len()];
    let mut edge_fragment = vec![None; mesh.edges.len()];
    for (i, fr) in mesh.fragments.iter().enumerate() {
        for &f in &fr.faces {
            face_fragment[f as usize].get_or_insert(i);
        }
        for &e in &fr.edges {
            edge_fragment[e as usize].get_or_insert(i);
        }
    }
    let mut face_region = vec![None; mesh.faces.len()];
    if !three {
        for (i, s) in mesh.subdomains.iter().enumerate() {
            for &(f, _) in &s.faces {
                face_region[f as usize].get_or_insert(i);
            }
        }
    }
    let pair = |fragment: Option<usize>| -> (i32, i32, i32) {
        match fragment.and_then(|i| mesh.fragments.get(i).map(|fr| (i, fr))) {
            Some((i, fr)) => (
                id(i),
                id(fr.subdomain as usize),
                fr.other.map_or(-1, |o| id(o as usize)),
            ),
            None => (-1, -1, -1),
        }
    };

    let mut cells = Vec::new();
    for (f, face) in mesh.faces.iter().enumerate() {
        let (fragment, subdomain, other) = if three {
            pair(face_fragment[f])
        } else {
            (-1, face_region[f].map_or(-1, id), -1)
        };
        let mids = mesh.quadratic.as_ref().and_then(|q| q.faces.get(f));
        for (k, t) in face.triangles.iter().enumerate() {
            // VTK 22, the quadratic triangle: corners, then the mids of 0–1, 1–2, 2–0.
            let (kind, nodes) = match mids.and_then(|m| m.get(k)) {
                Some(m) => (22, [&t[..], &m[..]].concat()),
                None => (5, t.to_vec()),
            };
            cells.push(Cell {
                kind,
                nodes,
                data: [fragment, subdomain, other, id(f), -1, -1, -1, -1],
            });
        }
    }
    for (e, edge) in mesh.edges.iter().enumerate() {
        let (fragment, subdomain, other) = pair(edge_fragment[e]);
        let mids = mesh.quadratic.as_ref().and_then(|q| q.edges.get(e));
        for (k, s) in groups::segments(&edge.nodes).iter().enumerate() {
            let (kind, nodes) = line_cell(s, mids.and_then(|m| m.get(k)));
            cells.push(Cell {
                kind,
                nodes,
                data: [fragment, subdomain, other, -1, id(e), -1, -1, -1],
            });
        }
    }
    for (i, p) in mesh.polylines.iter().enumerate() {
        let mids = mesh.quadratic.as_ref().and_then(|q| q.polylines.get(i));
        for (k, s) in groups::segments(&p.nodes).iter().enumerate() {
            let (kind, nodes) = line_cell(s, mids.and_then(|m| m.get(k)));
            cells.push(Cell {
                kind,
                nodes,
                data: [-1, -1, -1, -1, -1, id(i), -1, -1],
            });
        }
    }
    for (i, p) in mesh.point_sets.iter().enumerate() {
        for &n in &p.nodes {
            cells.push(Cell {
                kind: 1,
                nodes: vec![n],
                data: [-1, -1, -1, -1, -1, -1, id(i), -1],
            });
        }
    }
    let names = volume_names(mesh);
    for v in &mesh.volumes {
        let volume = names.iter().position(|n| *n == v.name).map_or(-1, id);
        let order = v.kind.vtk_order();
        for cell in v.cells() {
            cells.push(Cell {
                kind: v.kind.vtk_type(),
                nodes: order.iter().map(|&i| cell[i]).collect(),
                data: [-1, -1, -1, -1, -1, -1, -1, volume],
            });
        }
    }
    cells
}

/// The distinct names of the mesh's volume cell groups, in order: the
/// values of `volume_id`.
fn volume_names(mesh: &Mesh) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    for v in &mesh.volumes {
        if !names.contains(&v.name.as_str()) {
            names.push(&v.name);
        }
    }
    names
}

/// A segment as VTK line (3) or, with a mid node, quadratic edge (21).
fn line_cell(segment: &[u32; 2], mid: Option<&u32>) -> (u8, Vec<u32>) {
    match mid {
        Some(&m) => (21, vec![segment[0], segment[1], m]),
        None => (3, segment.to_vec()),
    }
}

/// One data array, already in the chosen encoding.
fn data_array(
    out: &mut dyn Write,
    ty: &str,
    name: &str,
    components: usize,
    binary: bool,
    text: Vec<String>,
    bytes: Vec<u8>,
) -> std::io::Result<()> {
    let format = if binary { "binary" } else { "ascii" };
    write!(out, "        <DataArray type=\"{ty}\" Name=\"{name}\"")?;
    if components > 1 {
        write!(out, " NumberOfComponents=\"{components}\"")?;
    }
    writeln!(out, " format=\"{format}\">")?;
    if binary {
        // VTK's inline binary: base64 of a UInt64 byte count, then the bytes.
        let mut block = (bytes.len() as u64).to_le_bytes().to_vec();
        block.extend_from_slice(&bytes);
        writeln!(out, "          {}", base64::encode(&block))?;
    } else {
        for chunk in text.chunks(12) {
            writeln!(out, "          {}", chunk.join(" "))?;
        }
    }
    writeln!(out, "        </DataArray>")
}

/// The names behind the cell data's ids, as FieldData arrays named by the
/// entity and holding `[id, k]`, k the index of its cell-data array in
/// `FIELDS` (meshio reads these as its `field_data`).
fn write_names(mesh: &Mesh, out: &mut dyn Write) -> std::io::Result<()> {
    let lists: [(usize, Vec<&str>); 7] = [
        (0, mesh.fragments.iter().map(|f| f.name.as_str()).collect()),
        (1, mesh.subdomains.iter().map(|s| s.name.as_str()).collect()),
        (3, mesh.faces.iter().map(|f| f.name.as_str()).collect()),
        (4, mesh.edges.iter().map(|e| e.name.as_str()).collect()),
        (5, mesh.polylines.iter().map(|p| p.name.as_str()).collect()),
        (6, mesh.point_sets.iter().map(|p| p.name.as_str()).collect()),
        (7, volume_names(mesh)),
    ];
    if lists.iter().all(|(_, names)| names.is_empty()) {
        return Ok(());
    }
    writeln!(out, "    <FieldData>")?;
    for (k, names) in &lists {
        for (id, name) in names.iter().enumerate() {
            writeln!(
                out,
                "      <DataArray type=\"Int32\" Name=\"{}\" NumberOfTuples=\"2\" format=\"ascii\">{id} {k}</DataArray>",
                escape(name)
            )?;
        }
    }
    writeln!(out, "    </FieldData>")
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn write_grid(
    mesh: &Mesh,
    cells: &[Cell],
    binary: bool,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    writeln!(out, "<?xml version=\"1.0\"?>")?;
    writeln!(
        out,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    )?;
    writeln!(out, "  <UnstructuredGrid>")?;
    write_names(mesh, out)?;
    writeln!(
        out,
        "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        mesh.nodes.len(),
        cells.len()
    )?;

    writeln!(out, "      <Points>")?;
    let coords = mesh.nodes.iter().flatten();
    data_array(
        out,
        "Float64",
        "Points",
        3,
        binary,
        if binary {
            Vec::new()
        } else {
            coords.clone().map(|c| fmt_num(*c)).collect()
        },
        if binary {
            coords.flat_map(|c| c.to_le_bytes()).collect()
        } else {
            Vec::new()
        },
    )?;
    writeln!(out, "      </Points>")?;

    writeln!(out, "      <Cells>")?;
    let connectivity = cells
        .iter()
        .flat_map(|c| c.nodes.iter().map(|&n| i64::from(n)));
    let mut offsets = Vec::with_capacity(cells.len());
    let mut end = 0i64;
    for c in cells {
        end += c.nodes.len() as i64;
        offsets.push(end);
    }
    let ints = |values: Vec<i64>| -> (Vec<String>, Vec<u8>) {
        if binary {
            (
                Vec::new(),
                values.iter().flat_map(|v| v.to_le_bytes()).collect(),
            )
        } else {
            (values.iter().map(i64::to_string).collect(), Vec::new())
        }
    };
    let (t, b) = ints(connectivity.collect());
    data_array(out, "Int64", "connectivity", 1, binary, t, b)?;
    let (t, b) = ints(offsets);
    data_array(out, "Int64", "offsets", 1, binary, t, b)?;
    let types: Vec<u8> = cells.iter().map(|c| c.kind).collect();
    data_array(
        out,
        "UInt8",
        "types",
        1,
        binary,
        if binary {
            Vec::new()
        } else {
            types.iter().map(u8::to_string).collect()
        },
        if binary { types.clone() } else { Vec::new() },
    )?;
    writeln!(out, "      </Cells>")?;

    writeln!(out, "      <CellData Scalars=\"{}\">", FIELDS[0])?;
    // `volume_id` only when there are volume cells: surface meshes' files
    // stay as they were.
    let fields = if mesh.volumes.is_empty() {
        &FIELDS[..7]
    } else {
        &FIELDS[..]
    };
    for (k, field) in fields.iter().enumerate() {
        let values: Vec<i32> = cells.iter().map(|c| c.data[k]).collect();
        data_array(
            out,
            "Int32",
            field,
            1,
            binary,
            if binary {
                Vec::new()
            } else {
                values.iter().map(i32::to_string).collect()
            },
            if binary {
                values.iter().flat_map(|v| v.to_le_bytes()).collect()
            } else {
                Vec::new()
            },
        )?;
    }
    writeln!(out, "      </CellData>")?;
    writeln!(out, "    </Piece>")?;
    writeln!(out, "  </UnstructuredGrid>")?;
    writeln!(out, "</VTKFile>")
}
