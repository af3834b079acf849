//! A face's loops in one flat list of oriented edges: one allocation per face
//! instead of one per loop plus one for the list of loops (most faces have a
//! single loop; on files of many primitives the nested vectors were a tenth
//! of the model's memory).

use super::OrientedEdge;

/// Closed chains of oriented edges, stored end to end. `ends` holds the end
/// of each loop in `edges` when there is more than one loop (or a single
/// empty one); otherwise it is empty and `edges` is the one loop (or none,
/// when `edges` is empty too).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Loops {
    edges: Box<[OrientedEdge]>,
    ends: Box<[u32]>,
}

impl Loops {
    /// No loop.
    pub fn new() -> Loops {
        Loops::default()
    }

    pub fn len(&self) -> usize {
        if self.ends.is_empty() {
            usize::from(!self.edges.is_empty())
        } else {
            self.ends.len()
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The extent of loop `i` in `edges`, if there is one.
    fn range(&self, i: usize) -> Option<std::ops::Range<usize>> {
        if self.ends.is_empty() {
            return (i == 0 && !self.edges.is_empty()).then_some(0..self.edges.len());
        }
        let end = *self.ends.get(i)? as usize;
        let start = if i == 0 { 0 } else { self.ends[i - 1] as usize };
        Some(start..end)
    }

    /// Loop `i`, if there is one.
    pub fn get(&self, i: usize) -> Option<&[OrientedEdge]> {
        self.edges.get(self.range(i)?)
    }

    pub fn first(&self) -> Option<&[OrientedEdge]> {
        self.get(0)
    }

    /// The loops in order.
    pub fn iter(&self) -> Iter<'_> {
        Iter {
            loops: self,
            next: 0,
            len: self.len(),
        }
    }

    /// Every edge of every loop, loop after loop.
    pub fn edges(&self) -> &[OrientedEdge] {
        &self.edges
    }

    /// The edges for changing in place (a loop's extent stays).
    pub fn edges_mut(&mut self) -> &mut [OrientedEdge] {
        &mut self.edges
    }

    /// Loop `i` for changing in place.
    pub fn get_mut(&mut self, i: usize) -> Option<&mut [OrientedEdge]> {
        let range = self.range(i)?;
        self.edges.get_mut(range)
    }

    /// The loops as nested vectors (to edit their number or lengths).
    pub fn to_vecs(&self) -> Vec<Vec<OrientedEdge>> {
        self.iter().map(<[OrientedEdge]>::to_vec).collect()
    }

    /// Appends a loop.
    pub fn push(&mut self, lp: Vec<OrientedEdge>) {
        self.extend([lp]);
    }

    /// Appends loops (the list is rebuilt once, whatever their number).
    pub fn extend(&mut self, more: impl IntoIterator<Item = Vec<OrientedEdge>>) {
        let mut loops = self.to_vecs();
        loops.extend(more);
        *self = Loops::from(loops);
    }
}

impl Loops {
    /// One loop of exactly `edges`' length (every primitive face but a
    /// two-rim cone's side): collected straight into the list, with no
    /// builder bookkeeping (lowering makes hundreds of thousands of these).
    pub fn one(edges: impl ExactSizeIterator<Item = OrientedEdge>) -> Loops {
        let edges: Box<[OrientedEdge]> = edges.collect();
        // A single empty loop needs its end (see the struct's comment).
        let ends: Box<[u32]> = if edges.is_empty() {
            Box::new([0])
        } else {
            Box::new([])
        };
        Loops { edges, ends }
    }

    /// The loops of `loops`, `total` edges in all: the edge list is sized
    /// once and no vector is made per loop (lowering builds hundreds of
    /// thousands of faces this way).
    pub fn from_nested<I, J>(loops: I, total: usize) -> Loops
    where
        I: IntoIterator<Item = J>,
        J: IntoIterator<Item = OrientedEdge>,
    {
        let mut builder = Builder::with_capacity(total);
        for lp in loops {
            builder.edges.extend(lp);
            builder.end_loop();
        }
        builder.finish()
    }
}

/// Collects loops end to end; `ends` is allocated only once a second loop
/// comes (most faces have one).
struct Builder {
    edges: Vec<OrientedEdge>,
    ends: Vec<u32>,
    count: usize,
    first_end: u32,
}

impl Builder {
    fn with_capacity(edges: usize) -> Builder {
        Builder {
            edges: Vec::with_capacity(edges),
            ends: Vec::new(),
            count: 0,
            first_end: 0,
        }
    }

    fn end_loop(&mut self) {
        let end = self.edges.len() as u32;
        self.count += 1;
        match self.count {
            1 => self.first_end = end,
            2 => self.ends.extend([self.first_end, end]),
            _ => self.ends.push(end),
        }
    }

    fn finish(mut self) -> Loops {
        // One non-empty loop needs no ends (see the struct's comment); a
        // single empty one does.
        if self.count == 1 && self.edges.is_empty() {
            self.ends.push(0);
        }
        Loops {
            edges: self.edges.into_boxed_slice(),
            ends: self.ends.into_boxed_slice(),
        }
    }
}

impl<L: AsRef<[OrientedEdge]>> FromIterator<L> for Loops {
    fn from_iter<I: IntoIterator<Item = L>>(iter: I) -> Loops {
        let mut builder = Builder::with_capacity(0);
        for lp in iter {
            builder.edges.extend_from_slice(lp.as_ref());
            builder.end_loop();
        }
        builder.finish()
    }
}

impl From<Vec<Vec<OrientedEdge>>> for Loops {
    fn from(loops: Vec<Vec<OrientedEdge>>) -> Loops {
        loops.into_iter().collect()
    }
}

impl std::ops::Index<usize> for Loops {
    type Output = [OrientedEdge];
    fn index(&self, i: usize) -> &[OrientedEdge] {
        match self.get(i) {
            Some(l) => l,
            None => panic!("loop {i} of {} loops", self.len()),
        }
    }
}

impl std::ops::IndexMut<usize> for Loops {
    fn index_mut(&mut self, i: usize) -> &mut [OrientedEdge] {
        let len = self.len();
        match self.get_mut(i) {
            Some(l) => l,
            None => panic!("loop {i} of {len} loops"),
        }
    }
}

#[derive(Debug, Clone)]
pub struct Iter<'a> {
    loops: &'a Loops,
    next: usize,
    len: usize,
}

impl<'a> Iterator for Iter<'a> {
    type Item = &'a [OrientedEdge];
    fn next(&mut self) -> Option<&'a [OrientedEdge]> {
        if self.next >= self.len {
            return None;
        }
        self.next += 1;
        self.loops.get(self.next - 1)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.len - self.next;
        (n, Some(n))
    }
}

impl DoubleEndedIterator for Iter<'_> {
    fn next_back(&mut self) -> Option<Self::Item> {
        if self.next >= self.len {
            return None;
        }
        self.len -= 1;
        self.loops.get(self.len)
    }
}

impl ExactSizeIterator for Iter<'_> {}

impl<'a> IntoIterator for &'a Loops {
    type Item = &'a [OrientedEdge];
    type IntoIter = Iter<'a>;
    fn into_iter(self) -> Iter<'a> {
        self.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ir::EdgeId;

    fn oe(e: u32) -> OrientedEdge {
        OrientedEdge {
            edge: EdgeId(e),
            forward: e.is_multiple_of(2),
        }
    }

    #[test]
    fn loops_keep_their_order_and_extent() {
        let none = Loops::new();
        assert_eq!(
            (none.len(), none.iter().count(), none.first()),
            (0, 0, None)
        );
        let one = Loops::from(vec![vec![oe(0), oe(1), oe(2)]]);
        assert_eq!(one.len(), 1);
        assert_eq!(one[0], [oe(0), oe(1), oe(2)]);
        assert_eq!(one.to_vecs(), vec![vec![oe(0), oe(1), oe(2)]]);
        let mut two = Loops::from(vec![vec![oe(0), oe(1)], vec![oe(5)]]);
        assert_eq!(two.len(), 2);
        assert_eq!(
            two.iter().collect::<Vec<_>>(),
            [&[oe(0), oe(1)][..], &[oe(5)]]
        );
        assert_eq!(two.iter().next_back(), Some(&[oe(5)][..]));
        assert_eq!(two.edges(), [oe(0), oe(1), oe(5)]);
        two[1][0] = oe(7);
        two.push(vec![oe(3)]);
        assert_eq!(
            two.to_vecs(),
            vec![vec![oe(0), oe(1)], vec![oe(7)], vec![oe(3)]]
        );
        // An empty loop is still a loop.
        let empty = Loops::from(vec![Vec::new()]);
        assert_eq!((empty.len(), empty.first()), (1, Some(&[][..])));
        assert_eq!(two.get(3), None);
    }

    #[test]
    fn nested_loops_match_collected_ones() {
        let cases: Vec<Vec<Vec<OrientedEdge>>> = vec![
            vec![],
            vec![vec![]],
            vec![vec![oe(4), oe(1)]],
            vec![vec![oe(0)], vec![oe(3), oe(2)], vec![]],
            vec![vec![], vec![oe(9)]],
        ];
        for case in cases {
            let total = case.iter().map(Vec::len).sum();
            let nested = Loops::from_nested(case.iter().map(|l| l.iter().copied()), total);
            assert_eq!(nested, Loops::from(case.clone()));
            assert_eq!(nested.to_vecs(), case);
        }
    }

    #[test]
    fn one_loop_is_the_nested_single_loop() {
        let mut rng = crate::test_rng::TestRng::new(0x100b);
        for len in (0..40).chain([0, 1, 1000]) {
            let lp: Vec<OrientedEdge> = (0..len).map(|_| oe(rng.below(1 << 20) as u32)).collect();
            let one = Loops::one(lp.iter().copied());
            assert_eq!(one, Loops::from_nested([lp.iter().copied()], len));
            assert_eq!(one, Loops::from(vec![lp.clone()]));
            assert_eq!((one.len(), one.first()), (1, Some(&lp[..])));
        }
    }
}
