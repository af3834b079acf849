//! The resolved objects by name, without a copy of each name: on files of
//! many primitives a `String` key per object was a hundred thousand
//! allocations, and the lookups compared the same names anyway.

use super::ResolvedObject;
use std::hash::BuildHasher;

/// Open addressing over the names' hashes: `slots[h]` is 1 + the last object
/// of a name whose probe sequence (linear, from its hash) stops at `h`, 0 an
/// empty slot; `previous[i]` is 1 + the object before `i` with the same
/// name, 0 for the first. A slot is four bytes (a map of hashes to indices
/// was sixteen, and twice the memory at the front end's peak, when the
/// subdomains look their solids up); a lookup compares names only in its
/// few probes, and a name given twice finds its last object (as a map
/// filled in order would).
#[derive(Debug, Clone, Default)]
pub struct NameIndex {
    slots: Vec<u32>,
    previous: Vec<u32>,
    /// Some name ends in `]` (such as "row[2]", which member 2 of a group
    /// `row` also meets).
    bracketed: bool,
}

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
        // At most two thirds full, so probes stay short and end on an empty slot.
        let size = (count + count / 2 + 1).next_power_of_two();
        let mut slots = vec![0u32; size];
        let mut previous = Vec::with_capacity(count);
        let mut bracketed = false;
        for i in 0..count {
            let this = name(i).unwrap_or_default();
            bracketed |= this.ends_with(']');
            let slot = probe(&slots, &name, this);
            let before = slots.get(slot).copied().unwrap_or(0);
            previous.push(before);
            if let Some(s) = slots.get_mut(slot) {
                *s = i as u32 + 1;
            }
        }
        NameIndex {
            slots,
            previous,
            bracketed,
        }
    }

    /// Whether some name ends in `]`: without one, no object is literally
    /// named like a group's member ("row[2]").
    pub fn has_bracketed_names(&self) -> bool {
        self.bracketed
    }

    /// The index of the last object named `name` in `objects` (the list the
    /// index was built from).
    pub fn get(&self, objects: &[ResolvedObject], name: &str) -> Option<usize> {
        let name_of = |i: usize| objects.get(i).map(|o| o.name.as_str());
        let slot = probe(&self.slots, &name_of, name);
        match self.slots.get(slot).copied() {
            None | Some(0) => None,
            Some(s) => Some(s as usize - 1),
        }
    }

    /// Every object named `name` (a name given twice has several), from the
    /// last to the first: a walk of the index, no list made per lookup.
    pub fn all_from_last<'a>(
        &'a self,
        objects: &[ResolvedObject],
        name: &str,
    ) -> impl Iterator<Item = usize> + use<'a> {
        self.from_last(self.get(objects, name))
    }

    /// `last` (an object's index, if any) and the objects of its name
    /// before it, from the last to the first.
    pub fn from_last(&self, last: Option<usize>) -> impl Iterator<Item = usize> + '_ {
        std::iter::successors(last, |&i| match self.previous.get(i).copied() {
            None | Some(0) => None,
            Some(s) => Some(s as usize - 1),
        })
    }
}

/// The slot of `name`: the one holding its last object, or the empty slot
/// where its probe sequence ends.
fn probe<'n>(slots: &[u32], name_of: &impl Fn(usize) -> Option<&'n str>, name: &str) -> usize {
    let mask = slots.len().wrapping_sub(1);
    let mut at = hash(name) as usize & mask;
    for _ in 0..slots.len() {
        match slots[at] {
            0 => return at,
            s if name_of(s as usize - 1) == Some(name) => return at,
            _ => at = (at + 1) & mask,
        }
    }
    // Not reached: the table is never full.
    slots.len()
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
        let all = |name| index.all_from_last(&objects, name).collect::<Vec<_>>();
        assert_eq!(all("a"), [4, 2, 0]);
        assert_eq!(all("c"), [3]);
        assert!(all("d").is_empty());
        assert_eq!(index.from_last(Some(2)).collect::<Vec<_>>(), [2, 0]);
        assert_eq!(index.from_last(None).count(), 0);
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
        let index = NameIndex::build(&objects);
        for name in names.iter().map(String::as_str).chain(["n3000", "m1", ""]) {
            let every: Vec<usize> = (0..objects.len()).filter(|&i| names[i] == name).collect();
            assert_eq!(index.get(&objects, name), every.last().copied(), "{name}");
            let from_last: Vec<usize> = index.all_from_last(&objects, name).collect();
            assert_eq!(
                from_last,
                every.iter().rev().copied().collect::<Vec<_>>(),
                "{name}"
            );
        }
        let n0: Vec<usize> = index.all_from_last(&objects, "n0").collect();
        assert_eq!(n0, [5, 2, 0]);
    }
}
