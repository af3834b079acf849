//! Incidence matrices of the topology graph (paper 000): M_VE, M_EF, M_FD,
//! signed where orientation matters, and the derived V–F and E–D.

use super::{Dimension, FaceId, Model, SubdomainCells};
use std::collections::{BTreeMap, BTreeSet};

/// A sparse matrix of small signed entries, rows × cols, entries sorted by
/// (row, col). Entry values: −1 / +1 for the two orientations, 2 for an entity
/// incident both ways (a closed edge's single vertex, a seam edge used twice
/// by one face), 1 in the unsigned derived matrices.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Incidence {
    pub rows: usize,
    pub cols: usize,
    /// Whether the entries carry an orientation; decides whether a 1 renders
    /// as `+` (signed) or `1` (plain membership).
    pub signed: bool,
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

/// Collects the directions an entity is used in, so that one used both ways
/// becomes a single entry 2 instead of two contradicting ones.
#[derive(Default)]
struct Signs(BTreeMap<(u32, u32), (bool, bool)>);

impl Signs {
    fn add(&mut self, row: u32, col: u32, positive: bool) {
        let slot = self.0.entry((row, col)).or_default();
        if positive {
            slot.0 = true;
        } else {
            slot.1 = true;
        }
    }

    fn into_incidence(self, rows: usize, cols: usize) -> Incidence {
        let entries = self
            .0
            .into_iter()
            .map(|((r, c), (pos, neg))| {
                let value = match (pos, neg) {
                    (true, true) => 2,
                    (true, false) => 1,
                    _ => -1,
                };
                (r, c, value)
            })
            .collect();
        Incidence {
            rows,
            cols,
            signed: true,
            entries,
        }
    }
}

fn unsigned(set: BTreeSet<(u32, u32)>, rows: usize, cols: usize) -> Incidence {
    Incidence {
        rows,
        cols,
        signed: false,
        entries: set.into_iter().map(|(r, c)| (r, c, 1)).collect(),
    }
}

impl IncidenceMatrices {
    /// Builds all five matrices. Ids out of range (a malformed model) are
    /// skipped, never indexed.
    pub fn of(model: &Model) -> IncidenceMatrices {
        let (nv, ne, nf, nd) = (
            model.vertices.len(),
            model.edges.len(),
            model.faces.len(),
            model.subdomains.len(),
        );

        let mut ve = Signs::default();
        for (j, edge) in model.edges.iter().enumerate() {
            let j = j as u32;
            if edge.begin.index() < nv {
                ve.add(edge.begin.0, j, false);
            }
            if edge.end.index() < nv {
                ve.add(edge.end.0, j, true);
            }
        }

        let mut ef = Signs::default();
        let mut vf = BTreeSet::new();
        for (j, face) in model.faces.iter().enumerate() {
            let j = j as u32;
            for used in face.loops.iter().flatten() {
                let Some(edge) = model.edges.get(used.edge.index()) else {
                    continue;
                };
                ef.add(used.edge.0, j, used.forward);
                for v in [edge.begin, edge.end] {
                    if v.index() < nv {
                        vf.insert((v.0, j));
                    }
                }
            }
        }

        let mut fd = Signs::default();
        let mut ed = BTreeSet::new();
        for (j, subdomain) in model.subdomains.iter().enumerate() {
            let j = j as u32;
            let faces: Vec<FaceId> = match &subdomain.cells {
                SubdomainCells::Volume { boundary } => {
                    for of in boundary.iter().filter(|of| of.face.index() < nf) {
                        fd.add(of.face.0, j, of.outward);
                    }
                    boundary.iter().map(|of| of.face).collect()
                }
                SubdomainCells::Region { faces } => {
                    for f in faces.iter().filter(|f| f.index() < nf) {
                        fd.add(f.0, j, true);
                    }
                    faces.clone()
                }
            };
            for face in faces.iter().filter_map(|f| model.faces.get(f.index())) {
                for used in face.loops.iter().flatten() {
                    if used.edge.index() < ne {
                        ed.insert((used.edge.0, j));
                    }
                }
            }
        }
        let mut fd = fd.into_incidence(nf, nd);
        // 2D membership is not an orientation.
        fd.signed = model.dimension == Dimension::Three;

        IncidenceMatrices {
            ve: ve.into_incidence(nv, ne),
            ef: ef.into_incidence(ne, nf),
            fd,
            vf: unsigned(vf, nv, nf),
            ed: unsigned(ed, ne, nd),
        }
    }
}

impl Incidence {
    /// The value at (row, col), 0 when absent.
    pub fn get(&self, row: u32, col: u32) -> i8 {
        self.entries
            .binary_search_by_key(&(row, col), |&(r, c, _)| (r, c))
            .map_or(0, |i| self.entries[i].2)
    }

    /// A dense text table for `geomc inspect --matrices` and snapshots: one
    /// line per row, headed by the column names; cells `+` / `-` (signed), `±`
    /// (both ways), `1` (unsigned), `.` (absent). Trailing spaces are trimmed
    /// so the output is stable under editors; missing names become `#index`.
    ///
    /// A matrix of more than `TABLE_COLUMNS` columns lists each row's entries
    /// instead (`row: -col +col`): as a table, a polygon of 10,000 edges
    /// printed 1.2 GB.
    pub fn render(&self, row_names: &[String], col_names: &[String]) -> String {
        if self.cols > TABLE_COLUMNS {
            return self.render_rows(row_names, col_names);
        }
        fn width(s: &str) -> usize {
            s.chars().count()
        }
        fn pad(out: &mut String, s: &str, w: usize) {
            out.push_str(s);
            out.extend(std::iter::repeat_n(' ', w.saturating_sub(width(s))));
        }

        let rows: Vec<String> = (0..self.rows).map(|i| name(row_names, i)).collect();
        let cols: Vec<String> = (0..self.cols).map(|j| name(col_names, j)).collect();
        let row_w = rows.iter().map(|s| width(s)).max().unwrap_or(0);
        let col_w: Vec<usize> = cols.iter().map(|s| width(s).max(1)).collect();

        // Entries are sorted by (row, col): walk them with a cursor instead of
        // allocating rows × cols cells.
        let mut next = self.entries.iter().peekable();
        let mut out = String::new();
        let mut line = String::new();
        pad(&mut line, "", row_w);
        for (col, w) in cols.iter().zip(&col_w) {
            line.push_str("  ");
            pad(&mut line, col, *w);
        }
        out.push_str(line.trim_end());
        out.push('\n');
        for (i, row) in rows.iter().enumerate() {
            line.clear();
            pad(&mut line, row, row_w);
            for (j, w) in col_w.iter().enumerate() {
                while next
                    .next_if(|&&(r, c, _)| (r as usize, c as usize) < (i, j))
                    .is_some()
                {}
                let value = next
                    .next_if(|&&(r, c, _)| (r as usize, c as usize) == (i, j))
                    .map_or(0, |&(_, _, v)| v);
                let cell = self.cell(value);
                line.push_str("  ");
                pad(&mut line, cell, *w);
            }
            out.push_str(line.trim_end());
            out.push('\n');
        }
        out
    }

    /// One line per row: its name, then its entries in column order, each
    /// the column's name after the cell's sign (`+`, `-`, `±`; none when
    /// unsigned).
    fn render_rows(&self, row_names: &[String], col_names: &[String]) -> String {
        let mut out = format!(
            "{} × {}, {} entries, by row:\n",
            self.rows,
            self.cols,
            self.entries.len()
        );
        let mut next = self.entries.iter().peekable();
        for i in 0..self.rows {
            out.push_str(&name(row_names, i));
            out.push(':');
            while next.next_if(|&&(r, _, _)| (r as usize) < i).is_some() {}
            while let Some(&(_, c, v)) = next.next_if(|&&(r, _, _)| r as usize == i) {
                out.push(' ');
                out.push_str(match self.cell(v) {
                    "1" => "",
                    sign => sign,
                });
                out.push_str(&name(col_names, c as usize));
            }
            out.push('\n');
        }
        out
    }

    /// How an entry value prints in a table.
    fn cell(&self, value: i8) -> &'static str {
        match value {
            0 => ".",
            1 if self.signed => "+",
            1 => "1",
            -1 => "-",
            2 => "±",
            _ => "?",
        }
    }
}

/// Columns up to which a matrix prints as a table.
const TABLE_COLUMNS: usize = 64;

/// The name of row or column `i`, or `#i` when it has none.
fn name(names: &[String], i: usize) -> String {
    names.get(i).cloned().unwrap_or_else(|| format!("#{i}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ir::Dimension;
    use crate::valid::fixtures::{Builder, cube, torus};

    fn names<T, N: ToString + ?Sized>(items: &[T], name: impl Fn(&T) -> &N) -> Vec<String> {
        items.iter().map(|x| name(x).to_string()).collect()
    }

    #[test]
    fn cube_matrices() {
        let b = cube();
        let m = IncidenceMatrices::of(&b.model);
        assert_eq!((m.ve.rows, m.ve.cols), (8, 12));
        assert_eq!((m.ef.rows, m.ef.cols), (12, 6));
        assert_eq!((m.fd.rows, m.fd.cols), (6, 1));

        assert_eq!(m.ve.entries.len(), 24);
        for edge in 0..12 {
            let mut column: Vec<i8> =
                m.ve.entries
                    .iter()
                    .filter(|e| e.1 == edge)
                    .map(|e| e.2)
                    .collect();
            column.sort_unstable();
            assert_eq!(column, [-1, 1], "edge {edge}");
        }

        assert_eq!(m.ef.entries.len(), 24);
        for edge in 0..12 {
            let mut row: Vec<i8> =
                m.ef.entries
                    .iter()
                    .filter(|e| e.0 == edge)
                    .map(|e| e.2)
                    .collect();
            row.sort_unstable();
            assert_eq!(row, [-1, 1], "edge {edge}");
        }

        assert_eq!(m.fd.entries, (0..6).map(|f| (f, 0, 1)).collect::<Vec<_>>());
        assert_eq!(m.vf.entries.len(), 24);
        assert_eq!(m.ed.entries, (0..12).map(|e| (e, 0, 1)).collect::<Vec<_>>());
        for mat in [&m.ve, &m.ef, &m.fd, &m.vf, &m.ed] {
            assert!(
                mat.entries
                    .windows(2)
                    .all(|w| (w[0].0, w[0].1) < (w[1].0, w[1].1))
            );
        }
        assert!(m.ve.signed && m.fd.signed && !m.vf.signed && !m.ed.signed);
    }

    #[test]
    fn shared_face_is_outward_for_one_cube_and_inward_for_the_other() {
        let mut b = Builder::new(Dimension::Three);
        b.unit_box("A", [0.0; 3]);
        b.unit_box("B", [1.0, 0.0, 0.0]);
        let m = IncidenceMatrices::of(&b.model);
        let shared = b
            .model
            .faces
            .iter()
            .position(|f| f.name == "A.right")
            .unwrap_or(99) as u32;
        assert_eq!(m.fd.get(shared, 0), 1);
        assert_eq!(m.fd.get(shared, 1), -1);
        assert_eq!(m.fd.entries.len(), 12);
        // Twelve edges a cube; the four of the shared face lie on both.
        assert_eq!(m.ed.entries.iter().filter(|e| e.1 == 1).count(), 12);
        assert_eq!(m.ed.entries.len(), 24);
        let on_both = (0..b.model.edges.len() as u32)
            .filter(|&e| m.ed.get(e, 0) == 1 && m.ed.get(e, 1) == 1)
            .count();
        assert_eq!(on_both, 4);
    }

    #[test]
    fn torus_seam_entries_are_two() {
        let b = torus(false);
        let m = IncidenceMatrices::of(&b.model);
        assert_eq!(m.ef.entries, [(0, 0, 2), (1, 0, 2)]);
        assert_eq!(m.ve.entries, [(0, 0, 2), (0, 1, 2)]);
        let edges = names(&b.model.edges, |e| &e.name);
        let faces = names(&b.model.faces, |f| &f.name);
        assert_eq!(m.ef.render(&edges, &faces), "   skin\nm  ±\np  ±\n");
    }

    #[test]
    fn render_triangle() {
        let mut b = Builder::new(Dimension::Two);
        let face = b
            .polygon("T", &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]])
            .face;
        b.push_subdomain("D", crate::ir::SubdomainCells::Region { faces: vec![face] });
        let m = IncidenceMatrices::of(&b.model);
        let vertices = names(&b.model.vertices, |v| &v.name);
        let edges = names(&b.model.edges, |e| &e.name);
        let faces = names(&b.model.faces, |f| &f.name);
        let subdomains = names(&b.model.subdomains, |s| &s.name);
        assert_eq!(
            m.ve.render(&vertices, &edges),
            "    e0  e1  e2\n\
             v0  -   .   +\n\
             v1  +   -   .\n\
             v2  .   +   -\n"
        );
        assert_eq!(m.ef.render(&edges, &faces), "    T\ne0  +\ne1  +\ne2  +\n");
        // 2D membership is unsigned; missing names fall back to the index.
        assert_eq!(m.fd.render(&faces, &[]), "   #0\nT  1\n");
        assert_eq!(
            m.ed.render(&edges, &subdomains),
            "    D\ne0  1\ne1  1\ne2  1\n"
        );
        let empty = IncidenceMatrices::of(&crate::ir::Model::empty(Dimension::Two));
        assert_eq!(empty.ve.render(&[], &[]), "\n");
    }

    #[test]
    fn a_matrix_wider_than_a_table_lists_each_rows_entries() {
        let n = TABLE_COLUMNS + 1;
        let corners: Vec<[f64; 3]> = (0..n)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / n as f64;
                [t.cos(), t.sin(), 0.0]
            })
            .collect();
        let mut b = Builder::new(Dimension::Two);
        let face = b.polygon("P", &corners).face;
        b.push_subdomain("D", crate::ir::SubdomainCells::Region { faces: vec![face] });
        let m = IncidenceMatrices::of(&b.model);
        let vertices = names(&b.model.vertices, |v| &v.name);
        let edges = names(&b.model.edges, |e| &e.name);
        let faces = names(&b.model.faces, |f| &f.name);
        let text = m.ve.render(&vertices, &edges);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), n + 1);
        assert_eq!(lines[0], format!("{n} × {n}, {} entries, by row:", 2 * n));
        assert_eq!(lines[1], format!("v0: -e0 +e{}", n - 1));
        assert_eq!(lines[2], "v1: +e0 -e1");
        // Unsigned entries print the column alone; a narrow matrix stays a table.
        let vf = m.vf.render(&vertices, &faces);
        assert!(vf.starts_with("     P\nv0   1\n"), "{vf}");
        let transposed = Incidence {
            rows: 1,
            cols: n,
            signed: false,
            entries: (0..n as u32).step_by(2).map(|c| (0, c, 1)).collect(),
        };
        let text = transposed.render(&faces, &edges);
        assert_eq!(
            text.lines().nth(1),
            Some(&*format!(
                "P: {}",
                (0..n)
                    .step_by(2)
                    .map(|c| format!("e{c}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            ))
        );
    }
}
