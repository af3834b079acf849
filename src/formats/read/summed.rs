//! A vector extended by fixed-size records decoded in parallel pieces, each
//! piece also summed up (bounds, first-use order, block ranges) while its
//! values are still in the processor's cache: the reader's facts came from
//! a second pass over the 48 MB of nodes and triangles of a 2-million-
//! triangle MSH file after they were read.

use rayon::prelude::*;
use std::mem::MaybeUninit;

/// Appends `decode` of each `size`-byte record of `bytes` (a shorter tail
/// is ignored) to `values`, in pieces of `piece` records made in parallel,
/// and gives `sum` of each piece's decoded values, in order.
pub(crate) fn extend_summed<T, S>(
    values: &mut Vec<T>,
    bytes: &[u8],
    size: usize,
    piece: usize,
    decode: impl Fn(&[u8]) -> T + Sync,
    sum: impl Fn(&[T]) -> S + Sync,
) -> Vec<S>
where
    T: Send + Sync,
    S: Send,
{
    let (size, piece) = (size.max(1), piece.max(1));
    let n = bytes.len() / size;
    let records = bytes.get(..n * size).unwrap_or_default();
    values.reserve(n);
    let base = values.len();
    let Some(slots) = values.spare_capacity_mut().get_mut(..n) else {
        return Vec::new();
    };
    let sums = slots
        .par_chunks_mut(piece)
        .zip(records.par_chunks(size * piece))
        .map(|(slots, records)| sum(fill(slots, records, size, &decode)))
        .collect();
    // SAFETY: the `n` slots past `base` were each written by `fill` (the
    // pieces of slots and of records pair up one to one: `n` records of
    // `size` bytes in pieces of `piece`, `n` slots in pieces of `piece`).
    unsafe { values.set_len(base + n) };
    sums
}

/// Writes `decode` of each record into its slot; the slots as values.
fn fill<'s, T>(
    slots: &'s mut [MaybeUninit<T>],
    records: &[u8],
    size: usize,
    decode: &impl Fn(&[u8]) -> T,
) -> &'s [T] {
    let written = slots.len().min(records.len() / size);
    for (slot, record) in slots.iter_mut().zip(records.chunks_exact(size)) {
        slot.write(decode(record));
    }
    let filled = slots.get(..written).unwrap_or_default();
    // SAFETY: the first `written` slots were written just above, and
    // `MaybeUninit<T>` has `T`'s layout.
    unsafe { std::slice::from_raw_parts(filled.as_ptr().cast::<T>(), filled.len()) }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records decoded after values already there, in pieces that do not
    /// divide the count: the values in order, one sum per piece over that
    /// piece's values, and a trailing partial record ignored.
    #[test]
    fn records_are_appended_in_order_with_one_sum_per_piece() {
        let mut bytes: Vec<u8> = (0..10_001u32).flat_map(|i| i.to_le_bytes()).collect();
        bytes.extend([7, 7]);
        let mut values = vec![u32::MAX];
        let sums = extend_summed(
            &mut values,
            &bytes,
            4,
            1_000,
            |r| u32::from_le_bytes([r[0], r[1], r[2], r[3]]) * 2,
            |piece| {
                (
                    piece.len(),
                    piece.iter().map(|&v| u64::from(v)).sum::<u64>(),
                )
            },
        );
        assert_eq!(values.len(), 10_002);
        assert_eq!(values[0], u32::MAX);
        assert!(values[1..].iter().zip(0u32..).all(|(&v, i)| v == 2 * i));
        assert_eq!(sums.len(), 11);
        assert_eq!(sums[0], (1_000, 999_000));
        assert_eq!(sums[10], (1, 20_000));
        let total: u64 = sums.iter().map(|s| s.1).sum();
        assert_eq!(total, 10_000 * 10_001);
        let none = extend_summed(&mut values, &[1, 2, 3], 4, 8, |_| 0, |p| p.len());
        assert!(none.is_empty());
        assert_eq!(values.len(), 10_002);
    }
}
