//! Gmsh MSH 2.2, ASCII (the default) or binary, for solvers that read only
//! the older format (`--to msh22`). The same model as MSH 4.1 (`msh.rs`):
//! physical names in `$PhysicalNames`, and each element tagged with its
//! physical group and its elementary entity (the `$Entities` section does
//! not exist in 2.2, so entity boundaries are not written). An element in
//! several physical groups is written once per group, as Gmsh does. Nodes
//! are numbered 1..N over the nodes the elements use, in mesh order.

use super::msh::{Model, Sink, model_warnings, write_preamble};
use super::{Encoding, MeshWriter, Warning, WriteError, WriteOptions, groups};
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

fn write_all(
    model: &Model<'_>,
    mesh: &Mesh,
    binary: bool,
    out: &mut dyn Write,
) -> Result<(), WriteError> {
    let mut o = Sink::new(out, binary);
    write_preamble(&mut o, "2.2", model)?;

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
    for (n, p) in mesh.nodes.iter().enumerate() {
        let id = number[n];
        if id == 0 {
            continue;
        }
        o.int(id as i32)?;
        for &c in p {
            o.real(c)?;
        }
        o.end_line()?;
    }
    o.end_section("Nodes")?;

    // One record per element and physical group, entity by entity.
    let blocks: Vec<(usize, &super::msh::Entity<'_>)> = model
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
                    o.int(v)?;
                }
            }
            for element in e.elements.chunks_exact(e.per) {
                id += 1;
                // ASCII also names the type and the tag count on each line.
                let head: &[i32] = if binary {
                    &[id, physical, e.tag]
                } else {
                    &[id, kind, 2, physical, e.tag]
                };
                for &v in head {
                    o.int(v)?;
                }
                for &n in element {
                    o.int(number[n as usize] as i32)?;
                }
                o.end_line()?;
            }
        }
    }
    o.end_section("Elements")?;
    o.flush()?;
    Ok(())
}
