//! Incidence matrices of the topology graph (paper 000): M_VE, M_EF, M_FD,
//! signed where orientation matters, and the derived V–F and E–D.

use super::Model;

/// A sparse matrix of small signed entries, rows × cols, entries sorted by
/// (row, col). Entry values: −1 / +1 for the two orientations, 2 for an entity
/// incident both ways (a closed edge's single vertex, a seam edge used twice
/// by one face), 1 in the unsigned derived matrices.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Incidence {
    pub rows: usize,
    pub cols: usize,
    pub entries: Vec<(u32, u32, i8)>,
}

#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct IncidenceMatrices {
    /// Vertex i bounds edge j: −1 begin, +1 end, 2 both (closed edge).
    pub ve: Incidence,
    /// Edge i bounds face j: +1 used forward in the face's loops, −1 backward, 2 both.
    pub ef: Incidence,
    /// Face i bounds subdomain j: +1 normal outward, −1 inward (3D); in 2D, +1
    /// when face i is part of region subdomain j.
    pub fd: Incidence,
    /// Derived, unsigned: vertex i lies on face j.
    pub vf: Incidence,
    /// Derived, unsigned: edge i lies on the boundary of (3D) or in (2D) subdomain j.
    pub ed: Incidence,
}

impl IncidenceMatrices {
    pub fn of(model: &Model) -> IncidenceMatrices {
        let _ = model;
        todo!("topology")
    }
}
