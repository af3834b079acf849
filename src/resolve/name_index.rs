//! The resolved objects by name, without a copy of each name: on files of
//! many primitives a `String` key per object was a hundred thousand
//! allocations, and the lookups compared the same names anyway.

use super::ResolvedObject;
use foldhash::HashMap;
use std::hash::BuildHasher;

/// No object: the end of a chain.
const NONE: u32 = u32::MAX;

/// A hash of each name → the last object with that hash; `previous[i]`
/// links object `i` to the one before it with the same hash. A lookup walks
/// the chain and compares the names, so a name given twice finds its last
/// object (as a map filled in order would).
#[derive(Debug, Clone, Default)]
pub struct NameIndex {
    last: HashMap<u64, u32>,
    previous: Vec<u32>,
}

fn hash(name: &str) -> u64 {
    foldhash::fast::FixedState::with_seed(0x6e61_6d65).hash_one(name)
}

impl NameIndex {
    pub fn build(objects: &[ResolvedObject]) -> NameIndex {
        let mut last = HashMap::default();
        last.reserve(objects.len());
        let previous = (objects.iter().enumerate())
            .map(|(i, o)| last.insert(hash(&o.name), i as u32).unwrap_or(NONE))
            .collect();
        NameIndex { last, previous }
    }

    /// The index of the last object named `name` in `objects` (the list the
    /// index was built from).
    pub fn get(&self, objects: &[ResolvedObject], name: &str) -> Option<usize> {
        let mut at = self.last.get(&hash(name)).copied().unwrap_or(NONE);
        while at != NONE {
            let i = at as usize;
            if objects.get(i)?.name == name {
                return Some(i);
            }
            at = self.previous.get(i).copied().unwrap_or(NONE);
        }
        None
    }

    /// Every object named `name` (a name given twice has several), in
    /// document order.
    pub fn all(&self, objects: &[ResolvedObject], name: &str) -> Vec<usize> {
        let mut found = Vec::new();
        let mut at = self.last.get(&hash(name)).copied().unwrap_or(NONE);
        while let Some(object) = objects.get(at as usize) {
            if object.name == name {
                found.push(at as usize);
            }
            at = self.previous.get(at as usize).copied().unwrap_or(NONE);
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
}
