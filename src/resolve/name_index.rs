//! The resolved objects by name, without a copy of each name per object:
//! on files of many primitives a `String` key per object was a hundred
//! thousand allocations.

use super::ResolvedObject;
use std::hash::BuildHasher;

/// Open addressing over the names' hashes: `slots[h]` is 1 + the last object
/// of a name whose probe sequence (linear, from its hash) stops at `h`, 0 an
/// empty slot. A slot is four bytes (a map of hashes to indices was sixteen,
/// and twice the memory at the front end's peak, when the subdomains look
/// their solids up); a name given twice finds its last object (as a map
/// filled in order would).
///
/// The names a probe compares are the index's own, packed one after another
/// in object order (`text`, object `i`'s ending at `ends[i]`): comparing
/// against the objects' own names read a 160-byte `ResolvedObject` and then
/// the name's heap block, two cache misses per lookup on files of many
/// objects; a lookup of the objects in order now reads the packed names in
/// order.
#[derive(Debug, Clone, Default)]
pub struct NameIndex {
    slots: Vec<u32>,
    text: String,
    ends: Vec<u32>,
    /// (object, 1 + the object before it with the same name), for the
    /// objects whose name an earlier object has, by object: few or none in a
    /// valid file, so no list of one entry per object.
    earlier: Vec<(u32, u32)>,
}

/// How many names ahead the build asks for a slot's cache line.
const PREFETCH_AHEAD: usize = 16;

/// The names' hash of both name tables (`names.rs` folds it to 32 bits).
pub(super) fn hash(name: &str) -> u64 {
    foldhash::fast::FixedState::with_seed(0x6e61_6d65).hash_one(name)
}

impl NameIndex {
    pub fn build(objects: &[ResolvedObject]) -> NameIndex {
        NameIndex::build_with(objects.len(), |i| objects.get(i).map(|o| o.name.as_str()))
    }

    /// The index of `count` objects, object `i` named `name(i)`: built from
    /// the document's names, it serves the resolved objects of the same names.
    pub fn build_with<'n>(count: usize, name: impl Fn(usize) -> Option<&'n str>) -> NameIndex {
        NameIndex::build_within(count, name, u32::MAX as usize)
    }

    /// [`NameIndex::build_with`], the names packed if they take at most
    /// `max_text` bytes in all (the ends are four bytes), compared against
    /// the objects' own otherwise.
    fn build_within<'n>(
        count: usize,
        name: impl Fn(usize) -> Option<&'n str>,
        max_text: usize,
    ) -> NameIndex {
        let names = || (0..count).map(|i| name(i).unwrap_or_default());
        let total: usize = names().map(str::len).sum();
        let mut index = NameIndex::default();
        if total <= max_text.min(u32::MAX as usize) {
            index.text.reserve_exact(total);
            index.ends.reserve_exact(count);
            for n in names() {
                index.text.push_str(n);
                index.ends.push(index.text.len() as u32);
            }
        }
        // At most two thirds full, so probes stay short and end on an empty slot.
        let size = (count + count / 2 + 1).next_power_of_two();
        index.slots = vec![0u32; size];
        // The slots are written in random order: ask for one a few names
        // ahead while this one is probed (its hash kept until then).
        let mask = size - 1;
        let hash_ahead = |i: usize, slots: &[u32]| -> u64 {
            let h = name(i).map_or(0, hash);
            if let Some(slot) = slots.get(h as usize & mask) {
                crate::cache_hint::prefetch(slot);
            }
            h
        };
        let mut ahead = [0u64; PREFETCH_AHEAD];
        for (i, h) in ahead.iter_mut().enumerate() {
            *h = hash_ahead(i, &index.slots);
        }
        for i in 0..count {
            let h = std::mem::replace(
                &mut ahead[i % PREFETCH_AHEAD],
                hash_ahead(i + PREFETCH_AHEAD, &index.slots),
            );
            let slot = index.probe(&name, name(i).unwrap_or_default(), h);
            let Some(s) = index.slots.get_mut(slot) else {
                continue;
            };
            if *s != 0 {
                index.earlier.push((i as u32, *s));
            }
            *s = i as u32 + 1;
        }
        index
    }

    /// Whether object `i` is named `name`: by the packed copy, or by
    /// `name_of(i)` when the names are not packed.
    fn is_named<'n>(
        &self,
        name_of: &impl Fn(usize) -> Option<&'n str>,
        i: usize,
        name: &str,
    ) -> bool {
        if self.ends.is_empty() {
            return name_of(i) == Some(name);
        }
        let start = match i.checked_sub(1) {
            None => Some(0),
            Some(before) => self.ends.get(before).map(|&e| e as usize),
        };
        let end = self.ends.get(i).map(|&e| e as usize);
        match (start, end) {
            (Some(start), Some(end)) => self.text.get(start..end) == Some(name),
            _ => false,
        }
    }

    /// The slot of `name`: the one holding its last object, or the empty slot
    /// where its probe sequence ends.
    fn probe<'n>(
        &self,
        name_of: &impl Fn(usize) -> Option<&'n str>,
        name: &str,
        hash: u64,
    ) -> usize {
        let mask = self.slots.len().wrapping_sub(1);
        let mut at = hash as usize & mask;
        for _ in 0..self.slots.len() {
            match self.slots[at] {
                0 => return at,
                s if self.is_named(name_of, s as usize - 1, name) => return at,
                _ => at = (at + 1) & mask,
            }
        }
        // Not reached: the table is never full.
        self.slots.len()
    }

    /// The index of the last object named `name` in `objects` (the list the
    /// index was built from; its names are read only if the index could not
    /// pack them).
    pub fn get(&self, objects: &[ResolvedObject], name: &str) -> Option<usize> {
        let name_of = |i: usize| objects.get(i).map(|o| o.name.as_str());
        let slot = self.probe(&name_of, name, hash(name));
        match self.slots.get(slot).copied() {
            None | Some(0) => None,
            Some(s) => Some(s as usize - 1),
        }
    }

    /// Every object named `name` (a name given twice has several), in
    /// document order.
    pub fn all(&self, objects: &[ResolvedObject], name: &str) -> Vec<usize> {
        let mut found = Vec::new();
        let mut at = self.get(objects, name);
        while let Some(i) = at {
            found.push(i);
            at = (self.earlier)
                .binary_search_by_key(&(i as u32), |&(object, _)| object)
                .ok()
                .and_then(|k| self.earlier.get(k))
                .map(|&(_, before)| before as usize - 1);
        }
        found.reverse();
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn object(name: &str) -> ResolvedObject {
        ResolvedObject {
            name: name.to_string(),
            span: crate::span::Span::default(),
            geometry: None,
        }
    }

    #[test]
    fn finds_the_last_object_of_a_name() {
        let objects: Vec<ResolvedObject> = ["a", "b", "a", "c", ""].map(object).into();
        let index = NameIndex::build(&objects);
        assert_eq!(index.get(&objects, "a"), Some(2));
        assert_eq!(index.get(&objects, "b"), Some(1));
        assert_eq!(index.get(&objects, "c"), Some(3));
        assert_eq!(index.get(&objects, ""), Some(4));
        assert_eq!(index.get(&objects, "d"), None);
        assert_eq!(index.get(&objects, "ab"), None);
    }

    #[test]
    fn finds_every_object_of_a_name_in_order() {
        let objects: Vec<ResolvedObject> = ["a", "b", "a", "c", "a"].map(object).into();
        let index = NameIndex::build(&objects);
        assert_eq!(index.all(&objects, "a"), [0, 2, 4]);
        assert_eq!(index.all(&objects, "c"), [3]);
        assert!(index.all(&objects, "d").is_empty());
    }

    #[test]
    fn many_names_find_what_a_scan_finds() {
        // Every third name repeats an earlier one; the table is two thirds
        // full at most, so probes collide and wrap around its end.
        let names: Vec<String> = (0..3_000)
            .map(|i| {
                if i % 3 == 2 {
                    format!("n{}", i / 7)
                } else {
                    format!("n{i}")
                }
            })
            .collect();
        let objects: Vec<ResolvedObject> = names.iter().map(|n| object(n)).collect();
        let name_of = |i: usize| objects.get(i).map(|o| o.name.as_str());
        let packed = NameIndex::build(&objects);
        // Names too long in all to pack are compared against the objects'.
        let unpacked = NameIndex::build_within(objects.len(), name_of, 10);
        assert_eq!(packed.text.len(), 13_003);
        assert!(unpacked.text.is_empty() && unpacked.ends.is_empty());
        // 857 objects repeat an earlier name.
        assert_eq!(packed.earlier.len(), 857);
        for index in [&packed, &unpacked] {
            for name in names
                .iter()
                .map(String::as_str)
                .chain(["n3000", "m1", "", "n"])
            {
                let every: Vec<usize> = (0..objects.len()).filter(|&i| names[i] == name).collect();
                assert_eq!(index.get(&objects, name), every.last().copied(), "{name}");
                assert_eq!(index.all(&objects, name), every, "{name}");
            }
            assert_eq!(index.all(&objects, "n0"), [0, 2, 5]);
        }
    }
}
