//! Implicit solids {f ≥ 0} (papers 001 and 004): an expression IR built from
//! R-functions ([`ir`], [`rfs`], [`library`]), paper 001's modelling language
//! ([`lang`], `.rfs` files), a flat evaluation tape over coordinate streams
//! ([`tape`]), interval pruning ([`interval`]) and paper 004's watertight
//! polygonization ([`polygonize`]) into geomc's mesh IR.

pub mod caps;
pub mod cell_table;
pub mod expr_ops;
pub mod field;
pub mod interfaces;
pub mod interval;
pub mod ir;
pub mod joint_optimize;
pub mod lang;
pub mod library;
pub mod optimize;
pub mod polygonize;
pub mod rfs;
pub mod row_blocks;
pub mod rows;
pub mod section;
pub mod signs;
pub mod tape;
pub mod trig;
pub mod vertices;
pub mod weld;
pub mod xml;

use crate::mesh::{Mesh, MeshFace, MeshFragment, MeshSubdomain};
use crate::span::Span;
use ir::{Ctx, NodeId};
use polygonize::{Grid, Options, Surface};
use rfs::RSystem;
use tape::Ssa;

/// What paper 001's `Geom` object holds.
#[derive(Debug, Clone, PartialEq)]
pub struct Geom {
    pub min: [f64; 3],
    pub max: [f64; 3],
    /// Grid cells per axis (nx, ny, nz).
    pub cells: [usize; 3],
    /// The result function's name and where it was set.
    pub name: Option<(String, Span)>,
    pub optiterations: u32,
    pub optiterations_span: Option<Span>,
    pub rsystem: RSystem,
}

impl Default for Geom {
    fn default() -> Geom {
        Geom {
            min: [-1.0; 3],
            max: [1.0; 3],
            cells: [20; 3],
            name: None,
            optiterations: 0,
            optiterations_span: None,
            rsystem: RSystem::Rvachev,
        }
    }
}

impl Geom {
    pub fn grid(&self) -> Grid {
        Grid {
            min: self.min,
            max: self.max,
            cells: self.cells,
        }
    }
}

/// A compiled implicit solid: f positive inside.
#[derive(Debug, Clone)]
pub struct ImplicitModel {
    pub geom: Geom,
    pub ctx: Ctx,
    pub root: NodeId,
}

impl ImplicitModel {
    /// The solid's name: Geom.name, else `r_main`.
    pub fn name(&self) -> &str {
        self.geom.name.as_ref().map_or("r_main", |n| n.0.as_str())
    }

    pub fn ssa(&self) -> Ssa {
        Ssa::from_ctx(&self.ctx, self.root)
    }

    /// Polygonizes the boundary on the Geom grid (or `cells` per axis).
    pub fn polygonize(&self, cells: Option<[usize; 3]>) -> Surface {
        let mut grid = self.geom.grid();
        if let Some(c) = cells {
            grid.cells = c;
        }
        let ssa = self.ssa();
        let mut surface = polygonize::polygonize(&ssa, &grid, &Options::default());
        let iterations = self.geom.optiterations;
        optimize::optimize(&mut surface, &ssa, &grid, iterations);
        surface
    }
}

/// The surface as geomc's mesh IR: one subdomain (the solid) whose boundary
/// is the face `NAME_boundary` (fragment `NAME|exterior`) and, where the
/// solid leaves its box [min, max], the cap `NAME_box_cap` (fragment
/// `NAME|box`).
pub fn surface_to_mesh(surface: &Surface, name: &str, min: [f64; 3], max: [f64; 3]) -> Mesh {
    let mut mesh = Mesh {
        dimension: 3,
        nodes: surface.positions.clone(),
        subdomains: vec![MeshSubdomain {
            name: name.to_string(),
            material: None,
            faces: Vec::new(),
        }],
        ..Mesh::default()
    };
    let (rest, caps) = caps::split_caps(&surface.positions, &surface.triangles, min, max);
    push_boundary(&mut mesh, 0, name, rest, caps);
    mesh
}

/// Adds a subdomain's outer boundary (`NAME_boundary`, `NAME|exterior`) and
/// its box cap when it has one (`NAME_box_cap`, `NAME|box`), both outward,
/// node ids already in `mesh`'s numbering.
pub fn push_boundary(
    mesh: &mut Mesh,
    subdomain: u32,
    name: &str,
    rest: Vec<[u32; 3]>,
    caps: Vec<[u32; 3]>,
) {
    for (triangles, face, fragment) in [
        (rest, format!("{name}_boundary"), format!("{name}|exterior")),
        (caps, format!("{name}_box_cap"), format!("{name}|box")),
    ] {
        if triangles.is_empty() && face.ends_with("_box_cap") {
            continue;
        }
        let index = mesh.faces.len() as u32;
        mesh.faces.push(MeshFace {
            name: face,
            triangles,
            boundary: Vec::new(),
        });
        if let Some(s) = mesh.subdomains.get_mut(subdomain as usize) {
            s.faces.push((index, true));
        }
        mesh.fragments.push(MeshFragment {
            name: fragment,
            subdomain,
            other: None,
            faces: vec![index],
            edges: Vec::new(),
        });
    }
}
