//! The side table from IR entities back to the XML that defined them, so the
//! validator can point at the source without the IR carrying spans.

use super::{EdgeId, FaceId, SolidId, SubdomainId, VertexId};
use crate::span::Span;

/// Where an entity came from: the span of the defining element's name (or the
/// whole element) in the source file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Origin {
    pub span: Span,
}

/// A typed id that indexes a dense vector.
pub trait DenseId: Copy {
    fn index(self) -> usize;
    fn from_index(index: usize) -> Self;
}

macro_rules! dense_id {
    ($($name:ident),*) => {$(
        impl DenseId for $name {
            fn index(self) -> usize { self.0 as usize }
            fn from_index(index: usize) -> Self { $name(index as u32) }
        }
    )*};
}
dense_id!(VertexId, EdgeId, FaceId, SubdomainId, SolidId);

/// A map from dense ids to values, stored as a vector indexed by id: ids are
/// allocated in order, so this costs a slot per entity and no hashing (a
/// hash map per entity kind dominated lowering time and memory on large files).
///
/// A slot holds the index of its value in a list of distinct values: every
/// entity of one primitive solid has the same origin, so runs of equal values
/// are stored once (4 bytes an entity instead of an `Option<V>`).
#[derive(Debug, Clone)]
pub struct IdMap<K, V> {
    slots: Vec<u32>,
    values: Vec<V>,
    len: usize,
    _key: std::marker::PhantomData<K>,
}

/// An id without a value.
const EMPTY: u32 = u32::MAX;

impl<K, V> Default for IdMap<K, V> {
    fn default() -> Self {
        IdMap {
            slots: Vec::new(),
            values: Vec::new(),
            len: 0,
            _key: std::marker::PhantomData,
        }
    }
}

impl<K: DenseId, V: Copy + PartialEq> IdMap<K, V> {
    /// Makes room for ids below `ids` and `values` more distinct values, so
    /// a table filled to a known size is allocated once, at that size
    /// (growth by doubling left up to half of it unused, and copied it).
    pub fn reserve(&mut self, ids: usize, values: usize) {
        self.slots
            .reserve_exact(ids.saturating_sub(self.slots.len()));
        self.values.reserve_exact(values);
    }

    /// Sets the value of `id`, returning the previous one.
    pub fn insert(&mut self, id: K, value: V) -> Option<V> {
        let i = id.index();
        if self.slots.len() <= i {
            self.slots.resize(i + 1, EMPTY);
        }
        let old = self.get(&id).copied();
        if self.values.last() != Some(&value) {
            self.values.push(value);
        }
        self.slots[i] = (self.values.len() - 1) as u32;
        if old.is_none() {
            self.len += 1;
        }
        old
    }

    /// Sets the value of ids `first..first + n`: the same as inserting each
    /// in order, in one step when they are past every id set so far.
    pub fn insert_range(&mut self, first: usize, n: usize, value: V) {
        if n == 0 {
            return;
        }
        if self.slots.len() > first {
            for i in first..first + n {
                self.insert(K::from_index(i), value);
            }
            return;
        }
        self.slots.resize(first, EMPTY);
        if self.values.last() != Some(&value) {
            self.values.push(value);
        }
        let slot = (self.values.len() - 1) as u32;
        self.slots.resize(first + n, slot);
        self.len += n;
    }

    pub fn get(&self, id: &K) -> Option<&V> {
        match self.slots.get(id.index()) {
            Some(&slot) if slot != EMPTY => self.values.get(slot as usize),
            _ => None,
        }
    }

    pub fn contains_key(&self, id: &K) -> bool {
        self.get(id).is_some()
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The entries in id order.
    pub fn iter(&self) -> impl Iterator<Item = (K, &V)> + '_ {
        self.slots
            .iter()
            .enumerate()
            .filter(|&(_, &slot)| slot != EMPTY)
            .map(|(i, &slot)| (K::from_index(i), &self.values[slot as usize]))
    }

    /// The table with every id renamed by `map`; ids it drops are removed.
    pub fn remap(&self, map: impl Fn(K) -> Option<K>) -> IdMap<K, V> {
        let mut out = IdMap::default();
        for (k, &v) in self.iter() {
            if let Some(k) = map(k) {
                out.insert(k, v);
            }
        }
        out
    }
}

#[derive(Debug, Clone, Default)]
pub struct SourceMap {
    pub vertices: IdMap<VertexId, Origin>,
    pub edges: IdMap<EdgeId, Origin>,
    pub faces: IdMap<FaceId, Origin>,
    pub subdomains: IdMap<SubdomainId, Origin>,
    pub solids: IdMap<SolidId, Origin>,
    /// The element of each trimmed surface (`Model::trimmed` order).
    pub trimmed: Vec<Span>,
}

impl SourceMap {
    pub fn vertex(&self, id: VertexId) -> Option<Span> {
        self.vertices.get(&id).map(|o| o.span)
    }
    pub fn edge(&self, id: EdgeId) -> Option<Span> {
        self.edges.get(&id).map(|o| o.span)
    }
    pub fn face(&self, id: FaceId) -> Option<Span> {
        self.faces.get(&id).map(|o| o.span)
    }
    pub fn subdomain(&self, id: SubdomainId) -> Option<Span> {
        self.subdomains.get(&id).map(|o| o.span)
    }
    pub fn solid(&self, id: SolidId) -> Option<Span> {
        self.solids.get(&id).map(|o| o.span)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn origin(k: usize) -> Origin {
        Origin {
            span: Span::new(k, k + 1),
        }
    }

    /// `insert_range` against one `insert` per id, fresh ids and not.
    #[test]
    fn a_range_is_the_inserts_of_its_ids_in_order() {
        let steps = [
            (0, 3, 1),
            (3, 0, 2),
            (3, 2, 2),
            (7, 1, 3),
            (8, 4, 3),
            (2, 3, 4),
        ];
        let (mut ranged, mut one_by_one) = (IdMap::default(), IdMap::default());
        for (first, n, value) in steps {
            ranged.insert_range(first, n, origin(value));
            for id in first..first + n {
                one_by_one.insert(VertexId(id as u32), origin(value));
            }
        }
        let list = |m: &IdMap<VertexId, Origin>| m.iter().map(|(k, v)| (k, *v)).collect::<Vec<_>>();
        assert_eq!(list(&ranged), list(&one_by_one));
        assert_eq!((ranged.len(), ranged.values.len()), (10, 4));
        assert_eq!(ranged.values, one_by_one.values);
        assert_eq!(ranged.slots, one_by_one.slots);
        assert_eq!(ranged.get(&VertexId(5)), None);
        assert_eq!(ranged.get(&VertexId(3)), Some(&origin(4)));
    }
}
