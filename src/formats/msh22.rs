//! Gmsh MSH 2.2, ASCII (the default) or binary, for solvers that read only
//! the older format (`--to msh22`). The same model as MSH 4.1 (`msh.rs`):
//! physical names in `$PhysicalNames`, and each element tagged with its
//! physical group and its elementary entity (the `$Entities` section does
//! not exist in 2.2, so entity boundaries are not written). An element in
//! several physical groups is written once per group, as Gmsh does. Nodes
//! are numbered 1..N over the nodes the elements use, in mesh order.

use super::msh::{Model, model_warnings};
use super::{Encoding, MeshWriter, Warning, WriteError, WriteOptions, groups, push_num};
use crate::mesh::Mesh;
use std::io::Write;

pub(crate) struct Msh22;

impl MeshWriter for Msh22 {
    fn name(&self) -> &'static str {
        "msh22"
    }

    /// None: `.msh` files are MSH 4.1 unless `--to msh22` says otherwise.
    fn extensions(&self) -> &'static [&'static str] {
        &[]
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
        let model = Model::of(mesh);
        let binary = options.encoding == Some(Encoding::Binary);
        write_all(&model, mesh, binary, out)?;
        Ok(model_warnings(&model))
    }
}

/// Bytes gathered before each write to `out`.
const CHUNK: usize = 1 << 16;

struct Out<'a> {
    out: &'a mut dyn Write,
    buf: Vec<u8>,
}

impl Out<'_> {
    fn put(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.buf.extend_from_slice(bytes);
        if self.buf.len() >= CHUNK {
            self.flush()?;
        }
        Ok(())
    }

    fn text(&mut self, s: &str) -> std::io::Result<()> {
        self.put(s.as_bytes())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.write_all(&self.buf)?;
        self.buf.clear();
        Ok(())
    }
}

fn write_all(
    model: &Model,
    mesh: &Mesh,
    binary: bool,
    out: &mut dyn Write,
) -> Result<(), WriteError> {
    let mut o = Out {
        out,
        buf: Vec::with_capacity(CHUNK + 1024),
    };
    o.text("$MeshFormat\n")?;
    if binary {
        o.text("2.2 1 8\n")?;
        // The integer 1 tells readers the byte order.
        o.put(&1i32.to_le_bytes())?;
        o.text("\n")?;
    } else {
        o.text("2.2 0 8\n")?;
    }
    o.text("$EndMeshFormat\n")?;
    if !model.physical_names.is_empty() {
        o.text("$PhysicalNames\n")?;
        o.text(&format!("{}\n", model.physical_names.len()))?;
        for (dim, tag, name) in &model.physical_names {
            o.text(&format!("{dim} {tag} \"{name}\"\n"))?;
        }
        o.text("$EndPhysicalNames\n")?;
    }

    // Node numbers: 1.. over the written nodes, in mesh order.
    let mut number = vec![0u32; mesh.nodes.len()];
    let mut written = 0u32;
    for (n, owner) in model.owner.iter().enumerate() {
        if owner.is_some() {
            written += 1;
            number[n] = written;
        }
    }
    o.text(&format!("$Nodes\n{written}\n"))?;
    let mut line = String::new();
    for (n, p) in mesh.nodes.iter().enumerate() {
        let id = number[n];
        if id == 0 {
            continue;
        }
        if binary {
            o.put(&(id as i32).to_le_bytes())?;
            for c in p {
                o.put(&c.to_le_bytes())?;
            }
        } else {
            line.clear();
            line.push_str(&id.to_string());
            for &c in p {
                line.push(' ');
                push_num(&mut line, c);
            }
            line.push('\n');
            o.text(&line)?;
        }
    }
    if binary {
        o.text("\n")?;
    }
    o.text("$EndNodes\n")?;

    // One record per element and physical group, entity by entity.
    let blocks: Vec<(usize, &super::msh::Entity)> = model
        .entities
        .iter()
        .enumerate()
        .flat_map(|(dim, list)| list.iter().map(move |e| (dim, e)))
        .filter(|(_, e)| !e.elements.is_empty())
        .collect();
    let total: usize = blocks
        .iter()
        .map(|(_, e)| e.count() * e.physicals.len())
        .sum();
    o.text(&format!("$Elements\n{total}\n"))?;
    let mut id = 0i32;
    for (dim, e) in blocks {
        let kind = e.element_type(dim);
        for &physical in &e.physicals {
            if binary {
                // A block header: type, how many follow, two tags each.
                for v in [kind, e.count() as i32, 2] {
                    o.put(&v.to_le_bytes())?;
                }
            }
            for element in e.elements.chunks_exact(e.per) {
                id += 1;
                if binary {
                    for v in [id, physical, e.tag] {
                        o.put(&v.to_le_bytes())?;
                    }
                    for &n in element {
                        o.put(&(number[n as usize] as i32).to_le_bytes())?;
                    }
                } else {
                    line.clear();
                    line.push_str(&format!("{id} {kind} 2 {physical} {}", e.tag));
                    for &n in element {
                        line.push(' ');
                        line.push_str(&number[n as usize].to_string());
                    }
                    line.push('\n');
                    o.text(&line)?;
                }
            }
        }
    }
    if binary {
        o.text("\n")?;
    }
    o.text("$EndElements\n")?;
    o.flush()?;
    Ok(())
}
