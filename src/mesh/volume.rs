//! Volume cells read from solver formats (MSH, VTU): tetrahedra, hexahedra,
//! wedges and pyramids, one block per named group and kind. geomc makes no
//! volume meshes itself; `convert` carries them between the formats that
//! hold them (MSH 4.1, VTU) and says what it drops for the others.
//!
//! Corner order is Gmsh's. VTK uses the same order for all four kinds but
//! orients the wedge the other way round (its base triangle faces away from
//! the top): [`CellKind::vtk_order`] converts.

/// The linear volume cell kinds (higher-order cells are read as their corners).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum CellKind {
    Tetrahedron,
    Hexahedron,
    Wedge,
    Pyramid,
}

impl CellKind {
    pub const ALL: [CellKind; 4] = [
        CellKind::Tetrahedron,
        CellKind::Hexahedron,
        CellKind::Wedge,
        CellKind::Pyramid,
    ];

    /// Corner nodes per cell.
    pub fn corners(self) -> usize {
        match self {
            CellKind::Tetrahedron => 4,
            CellKind::Hexahedron => 8,
            CellKind::Wedge => 6,
            CellKind::Pyramid => 5,
        }
    }

    /// Gmsh's element type number of the linear cell.
    pub fn gmsh_type(self) -> i32 {
        match self {
            CellKind::Tetrahedron => 4,
            CellKind::Hexahedron => 5,
            CellKind::Wedge => 6,
            CellKind::Pyramid => 7,
        }
    }

    /// VTK's cell type number of the linear cell.
    pub fn vtk_type(self) -> u8 {
        match self {
            CellKind::Tetrahedron => 10,
            CellKind::Hexahedron => 12,
            CellKind::Wedge => 13,
            CellKind::Pyramid => 14,
        }
    }

    /// The plural used in messages ("tetrahedra").
    pub fn plural(self) -> &'static str {
        match self {
            CellKind::Tetrahedron => "tetrahedra",
            CellKind::Hexahedron => "hexahedra",
            CellKind::Wedge => "wedges",
            CellKind::Pyramid => "pyramids",
        }
    }

    pub fn singular(self) -> &'static str {
        match self {
            CellKind::Tetrahedron => "tetrahedron",
            CellKind::Hexahedron => "hexahedron",
            CellKind::Wedge => "wedge",
            CellKind::Pyramid => "pyramid",
        }
    }

    /// Gmsh corner `i` is VTK corner `vtk_order()[i]` (and back: the
    /// permutation is its own inverse).
    pub fn vtk_order(self) -> &'static [usize] {
        match self {
            CellKind::Wedge => &[0, 2, 1, 3, 5, 4],
            CellKind::Tetrahedron => &[0, 1, 2, 3],
            CellKind::Hexahedron => &[0, 1, 2, 3, 4, 5, 6, 7],
            CellKind::Pyramid => &[0, 1, 2, 3, 4],
        }
    }

    /// The corner order of the mirrored cell (what a transform with a
    /// negative determinant needs to keep the cell's volume positive).
    pub fn mirror_order(self) -> &'static [usize] {
        match self {
            CellKind::Tetrahedron => &[0, 2, 1, 3],
            CellKind::Hexahedron => &[0, 3, 2, 1, 4, 7, 6, 5],
            CellKind::Wedge => &[0, 2, 1, 3, 5, 4],
            CellKind::Pyramid => &[0, 3, 2, 1, 4],
        }
    }
}

/// The cells of one kind in one named group (a Gmsh physical volume, a VTU
/// cell-data value).
#[derive(Debug, Clone, PartialEq)]
pub struct MeshVolume {
    pub name: String,
    pub kind: CellKind,
    /// `kind.corners()` node indices per cell, one cell after the other.
    pub nodes: Vec<u32>,
}

impl MeshVolume {
    pub fn count(&self) -> usize {
        self.nodes.len() / self.kind.corners()
    }

    /// Each cell's corners.
    pub fn cells(&self) -> std::slice::ChunksExact<'_, u32> {
        self.nodes.chunks_exact(self.kind.corners())
    }
}

/// Cell counts per kind over all volumes, for messages: "120 tetrahedra, 8 wedges".
pub fn describe(volumes: &[MeshVolume]) -> String {
    let mut counts = [0usize; 4];
    for v in volumes {
        counts[v.kind as usize] += v.count();
    }
    CellKind::ALL
        .iter()
        .zip(counts)
        .filter(|(_, n)| *n > 0)
        .map(|(k, n)| format!("{n} {}", if n == 1 { k.singular() } else { k.plural() }))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Reorders every cell's corners by `order(kind)`.
pub fn permute(volumes: &mut [MeshVolume], order: impl Fn(CellKind) -> &'static [usize]) {
    for v in volumes {
        let per = v.kind.corners();
        let order = order(v.kind);
        let mut tmp = [0u32; 8];
        for cell in v.nodes.chunks_exact_mut(per) {
            tmp[..per].copy_from_slice(cell);
            for (slot, &from) in cell.iter_mut().zip(order) {
                *slot = tmp[from];
            }
        }
    }
}

/// The signed volume of a cell (positive when its corners are in Gmsh's
/// order), by splitting it into tetrahedra.
pub fn cell_volume(kind: CellKind, nodes: &[[f64; 3]], cell: &[u32]) -> f64 {
    let p = |i: usize| nodes[cell[i] as usize];
    let tet = |a: usize, b: usize, c: usize, d: usize| {
        let (a, b, c, d) = (p(a), p(b), p(c), p(d));
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
        (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
            + u[2] * (v[0] * w[1] - v[1] * w[0]))
            / 6.0
    };
    match kind {
        CellKind::Tetrahedron => tet(0, 1, 2, 3),
        CellKind::Pyramid => tet(0, 1, 2, 4) + tet(0, 2, 3, 4),
        CellKind::Wedge => tet(0, 1, 2, 3) + tet(1, 2, 3, 4) + tet(2, 3, 4, 5),
        CellKind::Hexahedron => {
            tet(0, 1, 3, 4) + tet(1, 2, 3, 6) + tet(1, 3, 4, 6) + tet(1, 4, 5, 6) + tet(3, 4, 6, 7)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_cells_have_their_volumes() {
        let cube = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 1.0],
        ];
        let v = |k, c: &[u32]| cell_volume(k, &cube, c);
        assert!((v(CellKind::Tetrahedron, &[0, 1, 3, 4]) - 1.0 / 6.0).abs() < 1e-15);
        assert!((v(CellKind::Hexahedron, &[0, 1, 2, 3, 4, 5, 6, 7]) - 1.0).abs() < 1e-15);
        assert!((v(CellKind::Wedge, &[0, 1, 3, 4, 5, 7]) - 0.5).abs() < 1e-15);
        assert!((v(CellKind::Pyramid, &[0, 1, 2, 3, 6]) - 1.0 / 3.0).abs() < 1e-15);
        // Mirrored corner orders flip the sign.
        for (k, c) in [
            (CellKind::Tetrahedron, vec![0, 1, 3, 4]),
            (CellKind::Hexahedron, vec![0, 1, 2, 3, 4, 5, 6, 7]),
            (CellKind::Wedge, vec![0, 1, 3, 4, 5, 7]),
            (CellKind::Pyramid, vec![0, 1, 2, 3, 6]),
        ] {
            let m: Vec<u32> = k.mirror_order().iter().map(|&i| c[i]).collect();
            assert!((v(k, &m) + v(k, &c)).abs() < 1e-15, "{k:?}");
        }
    }
}
