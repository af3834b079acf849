//! The polygonizer's cell topology as a lookup table (issue 5).
//!
//! Why: a crossed cell's cycles depend only on its eight corner signs and,
//! on each face with four crossings, on the asymptotic decider's answer.
//! Working them out per cell (`polygonize::cell_links`, face by face) cost
//! more than everything else in contouring a sampled grid; here they are
//! worked out once for every (sign case, decider answers) pair by that same
//! function, so the table gives exactly its cycles. Per cell only the
//! decider products of the case's ambiguous faces are left to compute.

use super::polygonize::{FACE_MASK, FACES, cycles_of, links, saddle_corners};
use std::sync::OnceLock;

/// One cell's cycles, with the fan starts `triangulate` may use.
#[derive(Debug, Clone, Copy, Default)]
pub struct CaseCycles {
    /// The cycles' cell edges, one after the other.
    pub edges: [u8; 12],
    /// Cycle c is `edges[ends[c]..ends[c + 1]]` (at most 4 cycles: each has
    /// at least 3 of the 12 edges).
    pub ends: [u8; 5],
    pub count: u8,
    /// Bit s of `valid[c]`: a fan from the cycle's s-th vertex joins no two
    /// crossings on one cell face.
    pub valid: [u16; 4],
}

impl CaseCycles {
    /// Cycle c's edges and valid fan starts.
    #[inline]
    pub fn cycle(&self, c: usize) -> (&[u8], u16) {
        (
            &self.edges[self.ends[c] as usize..self.ends[c + 1] as usize],
            self.valid[c],
        )
    }
}

/// One sign case: its ambiguous faces and where its entries start.
#[derive(Debug, Clone, Copy, Default)]
struct Case {
    /// Corners of each face with four crossings, starting at an inside one.
    saddles: [[u8; 4]; 6],
    count: u8,
    /// Entry of decider answers 0 in `CellTable::entries`.
    first: u16,
}

/// Cycles for every sign case and decider answer.
pub struct CellTable {
    cases: [Case; 256],
    entries: Vec<CaseCycles>,
}

impl CellTable {
    /// The table, built on first use.
    pub fn get() -> &'static CellTable {
        static TABLE: OnceLock<CellTable> = OnceLock::new();
        TABLE.get_or_init(CellTable::build)
    }

    fn build() -> CellTable {
        let mut cases = [Case::default(); 256];
        let mut entries = Vec::new();
        for (sign_case, case) in cases.iter_mut().enumerate() {
            let inside: [bool; 8] = std::array::from_fn(|c| sign_case >> c & 1 == 1);
            let mut faces = Vec::new();
            for (f, q) in FACES.iter().enumerate() {
                let ins = q.map(|c| inside[c as usize]);
                if (0..4).all(|s| ins[s] != ins[(s + 1) % 4]) {
                    case.saddles[faces.len()] = saddle_corners(*q, ins[0]);
                    faces.push(f);
                }
            }
            case.count = faces.len() as u8;
            case.first = entries.len() as u16;
            for answers in 0..1u32 << faces.len() {
                let next = links(inside, |f, _| {
                    let b = faces.iter().position(|&g| g == f).unwrap_or(0);
                    answers >> b & 1 == 1
                });
                entries.push(case_cycles(&next));
            }
        }
        CellTable { cases, entries }
    }

    /// The cycles of a cell with corner values `v` (corner c at offset
    /// (c & 1, c >> 1 & 1, c >> 2 & 1)); the same as
    /// `polygonize::cell_cycles(v)`.
    #[inline]
    pub fn lookup(&self, v: &[f64; 8]) -> &CaseCycles {
        let mut sign_case = 0usize;
        for (c, &x) in v.iter().enumerate() {
            sign_case |= usize::from(x > 0.0) << c;
        }
        self.lookup_case(sign_case, |c| v[c as usize])
    }

    /// [`CellTable::lookup`] from the sign case (bit c set: corner c is
    /// inside), reading corner values (`value(c)`) only for the decider on
    /// ambiguous faces: most crossed cells need none, and the contouring
    /// knows the signs from its packed bits without loading the samples.
    #[inline]
    pub fn lookup_case(&self, sign_case: usize, value: impl Fn(u8) -> f64) -> &CaseCycles {
        let case = &self.cases[sign_case];
        let mut answers = 0usize;
        for (b, p) in case.saddles[..case.count as usize].iter().enumerate() {
            // The asymptotic decider, as in `polygonize::cell_links`.
            answers |= usize::from(value(p[0]) * value(p[2]) > value(p[1]) * value(p[3])) << b;
        }
        &self.entries[case.first as usize + answers]
    }
}

fn case_cycles(next: &[u8; 12]) -> CaseCycles {
    let cycles = cycles_of(next);
    let mut out = CaseCycles::default();
    let mut len = 0usize;
    for (c, cycle) in cycles.iter().enumerate() {
        let n = cycle.len();
        out.edges[len..len + n].copy_from_slice(cycle);
        len += n;
        out.ends[c + 1] = len as u8;
        out.count += 1;
        for s in 0..n {
            let valid = (2..n.saturating_sub(1)).all(|d| {
                FACE_MASK[cycle[s] as usize] & FACE_MASK[cycle[(s + d) % n] as usize] == 0
            });
            out.valid[c] |= u16::from(valid) << s;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::implicit::polygonize::cell_cycles;

    #[test]
    fn the_table_gives_the_cycles_of_cell_cycles() {
        // Random corner values, many with ambiguous faces (and exact ties).
        let table = CellTable::get();
        let mut state = 2463534242u32;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            (state % 7) as f64 - 3.0 + (state >> 8) as f64 * 1e-9
        };
        let mut ambiguous = 0;
        for _ in 0..200_000 {
            let v: [f64; 8] = std::array::from_fn(|_| next());
            let want: Vec<Vec<u8>> = cell_cycles(&v).iter().map(<[u8]>::to_vec).collect();
            let got = table.lookup(&v);
            let got_cycles: Vec<Vec<u8>> = (0..got.count as usize)
                .map(|c| got.cycle(c).0.to_vec())
                .collect();
            assert_eq!(got_cycles, want, "{v:?}");
            ambiguous += usize::from(want.len() > 1);
        }
        assert!(ambiguous > 1000);
        // 256 cases; the checkerboard cases have six ambiguous faces.
        assert_eq!(table.cases[0b1001_0110].count, 6);
        assert_eq!(table.cases[0].count, 0);
        assert!(table.entries.len() > 256 && table.entries.len() < 4096);
    }
}
