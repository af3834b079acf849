//! The leaf solids of a subdomain's boolean tree, in first-use order. Most
//! trees have one leaf, kept inline: a vector per subdomain was 100,000 small
//! allocations on files of many primitives, alive at lowering's memory peak.

use crate::ir::SolidId;

#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(super) enum Leaves {
    #[default]
    None,
    One(SolidId),
    Many(Vec<SolidId>),
}

impl Leaves {
    pub(super) fn push(&mut self, id: SolidId) {
        *self = match std::mem::take(self) {
            Leaves::None => Leaves::One(id),
            Leaves::One(first) => Leaves::Many(vec![first, id]),
            Leaves::Many(mut all) => {
                all.push(id);
                Leaves::Many(all)
            }
        };
    }

    /// The index of `id` among the leaves, added at the end if new.
    pub(super) fn index_of(&mut self, id: SolidId) -> usize {
        self.iter().position(|&l| l == id).unwrap_or_else(|| {
            self.push(id);
            self.len() - 1
        })
    }
}

impl std::ops::Deref for Leaves {
    type Target = [SolidId];

    fn deref(&self) -> &[SolidId] {
        match self {
            Leaves::None => &[],
            Leaves::One(id) => std::slice::from_ref(id),
            Leaves::Many(all) => all,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaves_keep_first_use_order_and_index_repeats_once() {
        let mut leaves = Leaves::default();
        assert!(leaves.is_empty());
        assert_eq!(leaves.index_of(SolidId(7)), 0);
        assert_eq!(leaves, Leaves::One(SolidId(7)));
        assert_eq!(leaves.index_of(SolidId(7)), 0);
        assert_eq!(leaves.index_of(SolidId(3)), 1);
        assert_eq!(leaves.index_of(SolidId(9)), 2);
        assert_eq!(leaves.index_of(SolidId(3)), 1);
        assert_eq!(&*leaves, &[SolidId(7), SolidId(3), SolidId(9)]);
    }

    /// Inline leaves make a tree no larger than a vector of them did.
    #[test]
    fn leaves_are_no_larger_than_a_vector() {
        assert!(std::mem::size_of::<Leaves>() <= std::mem::size_of::<Vec<SolidId>>());
    }
}
