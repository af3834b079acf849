//! Node merging for binary STL, whose coordinates are `f32`: an
//! open-addressing table of 16-byte entries (three `f32` bit patterns and
//! the node id), half the size of a map keyed by `f64` bits, with a small
//! direct-mapped cache of recent corners in front. Neighbouring triangles
//! share corners, so most repeats are found in the cache, and the table
//! (larger than the processor's caches on big files) is touched about once
//! per distinct node. Nodes are numbered in order of first appearance, as
//! [`super::build::NodeDedup`] numbers them, so the mesh is the same.

use crate::cache_hint::prefetch;

/// An empty slot's id.
const EMPTY: u32 = u32::MAX;

/// Entries of the recent-corner cache (a power of two; 64 kB).
const RECENT: usize = 1 << 12;

pub struct F32Nodes {
    /// (x, y, z bits, id); a power-of-two length, at most three quarters
    /// full (half full made it 128 MB for 2.5 million nodes, a quarter of
    /// the peak of a 5-million-triangle conversion).
    table: Vec<[u32; 4]>,
    recent: Vec<[u32; 4]>,
    len: usize,
}

impl F32Nodes {
    /// A table for about `expected` distinct nodes.
    pub fn with_capacity(expected: usize) -> F32Nodes {
        F32Nodes {
            table: vec![[0, 0, 0, EMPTY]; (expected / 3 * 4 + 16).next_power_of_two()],
            recent: vec![[0, 0, 0, EMPTY]; RECENT],
            len: 0,
        }
    }

    /// The key of a corner: its bits, with −0 as 0.
    fn key(p: [f32; 3]) -> [u32; 3] {
        p.map(|c| if c == 0.0 { 0 } else { c.to_bits() })
    }

    /// Asks for the table slot of `p` a few corners before [`F32Nodes::node`]
    /// looks it up: the table is far larger than the processor's caches, and
    /// waiting for each slot in turn was most of the STL reading (0.73 →
    /// 0.45 s of CPU on 5 million triangles, measured alone).
    #[inline(always)]
    pub fn prefetch(&self, p: [f32; 3]) {
        let slot = Self::hash(Self::key(p)) as usize & (self.table.len() - 1);
        if let Some(entry) = self.table.get(slot) {
            prefetch(entry);
        }
    }

    fn hash(key: [u32; 3]) -> u64 {
        let a = u64::from(key[0]) | u64::from(key[1]) << 32;
        let mix = (a ^ u64::from(key[2]).rotate_left(17)).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        mix ^ (mix >> 29)
    }

    /// The id of the node at `p` (−0 equals 0), appended to `nodes` when new.
    pub fn node(&mut self, nodes: &mut Vec<[f64; 3]>, p: [f32; 3]) -> u32 {
        let key = Self::key(p);
        let h = Self::hash(key);
        // The top bits pick the cache slot, the low bits the table slot.
        let slot = (h >> 52) as usize & (RECENT - 1);
        if let Some(e) = self.recent.get(slot)
            && e[3] != EMPTY
            && e[..3] == key
        {
            return e[3];
        }
        let id = self.find_or_insert(key, h, nodes, p);
        if let Some(e) = self.recent.get_mut(slot) {
            *e = [key[0], key[1], key[2], id];
        }
        id
    }

    fn find_or_insert(
        &mut self,
        key: [u32; 3],
        h: u64,
        nodes: &mut Vec<[f64; 3]>,
        p: [f32; 3],
    ) -> u32 {
        if 4 * (self.len + 1) > 3 * self.table.len() {
            self.grow();
        }
        let mask = self.table.len() - 1;
        let mut i = h as usize & mask;
        loop {
            let Some(e) = self.table.get_mut(i) else {
                // Unreachable: `i` is masked to the table's length.
                return EMPTY;
            };
            if e[3] == EMPTY {
                let id = nodes.len() as u32;
                nodes.push(p.map(f64::from));
                *e = [key[0], key[1], key[2], id];
                self.len += 1;
                return id;
            }
            if e[..3] == key {
                return e[3];
            }
            i = (i + 1) & mask;
        }
    }

    fn grow(&mut self) {
        let size = (2 * self.table.len()).max(16);
        let old = std::mem::replace(&mut self.table, vec![[0, 0, 0, EMPTY]; size]);
        let mask = self.table.len() - 1;
        for e in old.into_iter().filter(|e| e[3] != EMPTY) {
            let mut i = Self::hash([e[0], e[1], e[2]]) as usize & mask;
            while self.table.get(i).is_some_and(|s| s[3] != EMPTY) {
                i = (i + 1) & mask;
            }
            if let Some(s) = self.table.get_mut(i) {
                *s = e;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merges_equal_corners_in_first_seen_order_through_growth() {
        let mut t = F32Nodes::with_capacity(0);
        let mut nodes = Vec::new();
        let mut ids = Vec::new();
        for round in 0..2 {
            for i in 0..10_000u32 {
                let v = i as f32 * 0.25;
                let z = if round == 0 { 0.0 } else { -0.0 };
                ids.push(t.node(&mut nodes, [v, -v, z]));
            }
        }
        assert_eq!(nodes.len(), 10_000);
        assert_eq!(ids[..10_000], ids[10_000..]);
        assert!(
            ids[..10_000]
                .iter()
                .enumerate()
                .all(|(i, &id)| id as usize == i)
        );
        assert_eq!(nodes[3], [0.75, -0.75, 0.0]);
    }
}
