//! The next slots of a vector, written from several threads at once: the
//! lowering of isolated solids knows each solid's entity ids before it makes
//! the entities, so every task writes its own consecutive part of the model's
//! vectors in place (no per-task vector appended and copied afterwards).

use std::mem::MaybeUninit;
use std::sync::atomic::{AtomicUsize, Ordering};

/// `len` slots past the end of `vec`, split into parts that are filled in
/// any order and then committed together.
pub(super) struct Tail<'v, T> {
    vec: &'v mut Vec<T>,
    len: usize,
    /// How many values the dropped parts wrote.
    written: AtomicUsize,
    /// Whether [`Tail::parts`] was called: a second split would hand out
    /// the same slots again, and its counts could then add up to `len`
    /// with slots left unwritten.
    split: bool,
}

/// Consecutive slots of a [`Tail`], filled front to back by [`Part::push`].
pub(super) struct Part<'t, T> {
    slots: &'t mut [MaybeUninit<T>],
    filled: usize,
    written: &'t AtomicUsize,
}

impl<'v, T> Tail<'v, T> {
    pub fn new(vec: &'v mut Vec<T>, len: usize) -> Tail<'v, T> {
        vec.reserve(len);
        Tail {
            vec,
            len,
            written: AtomicUsize::new(0),
            split: false,
        }
    }

    /// The slots split into consecutive parts of the given lengths (which
    /// add up to at most the tail's).
    ///
    /// # Panics
    /// When called a second time, or when the lengths add up to more.
    pub fn parts(&mut self, lens: impl IntoIterator<Item = usize>) -> Vec<Part<'_, T>> {
        assert!(!self.split, "a tail is split into parts once");
        self.split = true;
        let written = &self.written;
        let mut rest = &mut self.vec.spare_capacity_mut()[..self.len];
        lens.into_iter()
            .map(|n| {
                let (slots, tail) = std::mem::take(&mut rest).split_at_mut(n);
                rest = tail;
                Part {
                    slots,
                    filled: 0,
                    written,
                }
            })
            .collect()
    }

    /// Appends the written slots to the vector.
    ///
    /// # Panics
    /// When the parts did not fill every slot (the values written are then
    /// leaked, never read).
    pub fn commit(mut self) {
        let written = *self.written.get_mut();
        assert_eq!(written, self.len, "every reserved slot is written");
        let len = self.vec.len() + self.len;
        // SAFETY: the capacity was reserved in `new`. The one split (`parts`
        // refuses a second) hands out disjoint parts whose lengths add up to
        // at most `self.len`; each part writes its slots front to back and
        // counts them when dropped, and cannot write past its end (`push`
        // indexes its slice), so the counts add up to `self.len` only when
        // every part was full and the parts cover the tail, that is, when
        // every slot in `len - self.len..len` holds a value.
        unsafe { self.vec.set_len(len) };
    }
}

impl<T> Part<'_, T> {
    /// Writes the next slot.
    ///
    /// # Panics
    /// When the part is full.
    pub fn push(&mut self, value: T) {
        self.slots[self.filled].write(value);
        self.filled += 1;
    }
}

impl<T> Drop for Part<'_, T> {
    fn drop(&mut self) {
        self.written.fetch_add(self.filled, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn parts_filled_in_parallel_append_in_order() {
        let mut v = vec![String::from("a")];
        let mut tail = Tail::new(&mut v, 6);
        let parts = tail.parts([2, 0, 3, 1]);
        let starts = [0, 2, 2, 5];
        parts
            .into_par_iter()
            .zip(starts)
            .for_each(|(mut part, start)| {
                for k in 0..part.slots.len() {
                    part.push(format!("s{}", start + k));
                }
            });
        tail.commit();
        assert_eq!(v, ["a", "s0", "s1", "s2", "s3", "s4", "s5"]);
    }

    #[test]
    #[should_panic(expected = "every reserved slot is written")]
    fn a_part_left_short_is_never_committed() {
        let mut v: Vec<String> = Vec::new();
        let mut tail = Tail::new(&mut v, 2);
        let mut parts = tail.parts([2]);
        parts[0].push("only one".into());
        drop(parts);
        tail.commit();
    }

    #[test]
    #[should_panic(expected = "a tail is split into parts once")]
    fn a_tail_is_split_once() {
        let mut v: Vec<u32> = Vec::new();
        let mut tail = Tail::new(&mut v, 2);
        let mut first = tail.parts([1]);
        first[0].push(1);
        drop(first);
        // The same slot again: its count would make the two slots look full.
        let mut again = tail.parts([1]);
        again[0].push(2);
    }

    #[test]
    #[should_panic]
    fn a_part_takes_no_more_than_its_slots() {
        let mut v: Vec<u32> = Vec::new();
        let mut tail = Tail::new(&mut v, 1);
        let mut parts = tail.parts([1]);
        parts[0].push(1);
        parts[0].push(2);
    }
}
