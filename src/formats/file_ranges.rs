//! Byte ranges of an output file made and written apart from the bytes
//! written in order: each range's bytes can be made from any offset in it
//! (a converted copy of some values), so a range is cut into pieces at
//! fixed file offsets, each made in a page-aligned buffer and written at
//! its offset, by the in-order writer's thread in step with its own writes
//! or by a thread that is free ([`Pieces`]).
//! A writer leaves these ranges out of what it writes in order
//! ([`FileOutput::skip_to`](super::atomic::FileOutput::skip_to)).

use super::atomic::Parts;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Bytes of a piece: pieces start at multiples of this in the file (the
/// first of a range excepted), and a thread with nothing else to do takes
/// the next one.
const PIECE: usize = 1 << 18;

/// Memory pages: a piece's bytes sit at their file offset's place in a page.
const PAGE: usize = 4096;

/// Makes the bytes of a range from an offset in it.
pub(crate) type Fill<'a> = Box<dyn Fn(usize, &mut [u8]) + Sync + 'a>;

/// A range of the file: its offset, length, and how its bytes are made.
pub(crate) struct Range<'a> {
    pub offset: u64,
    pub len: usize,
    pub fill: Fill<'a>,
}

/// The pieces of some ranges, taken in file order by whichever thread
/// asks: the writer of the in-order bytes takes them a few at a time
/// between its own writes ([`Pieces::write_until`]), so they reach the
/// file (and the disk, through the background syncs) while the rest is
/// still being made, and a thread that is free takes the rest
/// ([`Pieces::write_rest`]). Each piece is taken once.
pub(crate) struct Pieces<'r, 'a> {
    list: Vec<(&'r Range<'a>, usize, usize)>,
    /// The first piece no thread has taken yet.
    next: AtomicUsize,
}

impl<'r, 'a> Pieces<'r, 'a> {
    pub(crate) fn of(ranges: &'r [Range<'a>]) -> Pieces<'r, 'a> {
        Pieces {
            list: ranges.iter().flat_map(pieces_of).collect(),
            next: AtomicUsize::new(0),
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.list.len()
    }

    /// Makes and writes pieces until `upto` of them are taken (by any
    /// thread); `buffer` is the caller's ([`piece_buffer`]).
    pub(crate) fn write_until(
        &self,
        parts: &Parts,
        upto: usize,
        buffer: &mut [u8],
    ) -> std::io::Result<()> {
        let upto = upto.min(self.list.len());
        while let Ok(i) = self
            .next
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |i| {
                (i < upto).then_some(i + 1)
            })
        {
            if let Some(&(range, from, len)) = self.list.get(i) {
                write_piece(parts, range, from, len, buffer)?;
            }
        }
        Ok(())
    }

    /// Makes and writes every piece not taken yet.
    pub(crate) fn write_rest(&self, parts: &Parts) -> std::io::Result<()> {
        if self.next.load(Ordering::Relaxed) >= self.list.len() {
            return Ok(());
        }
        self.write_until(parts, self.list.len(), &mut piece_buffer())
    }
}

/// A buffer for [`Pieces::write_until`]: a piece and the page it may start
/// inside.
pub(crate) fn piece_buffer() -> Vec<u8> {
    vec![0u8; PIECE + PAGE]
}

/// Makes one piece in `buffer`, at its file offset's place in a page, and
/// writes it at that offset.
fn write_piece(
    parts: &Parts,
    range: &Range<'_>,
    from: usize,
    len: usize,
    buffer: &mut [u8],
) -> std::io::Result<()> {
    let offset = range.offset + from as u64;
    let start = buffer.as_ptr().align_offset(PAGE).min(PAGE) + (offset % PAGE as u64) as usize;
    let Some(bytes) = buffer.get_mut(start..start + len) else {
        return Err(std::io::Error::other("a piece larger than its buffer"));
    };
    (range.fill)(from, bytes);
    parts.write_at(offset, bytes)
}

/// A range's pieces as (range, offset in it, length), cut where the file
/// offset is a multiple of [`PIECE`].
fn pieces_of<'r, 'a>(range: &'r Range<'a>) -> Vec<(&'r Range<'a>, usize, usize)> {
    let mut pieces = Vec::new();
    let mut from = 0;
    while from < range.len {
        let offset = range.offset + from as u64;
        let room = PIECE - (offset % PIECE as u64) as usize;
        let len = room.min(range.len - from);
        pieces.push((range, from, len));
        from += len;
    }
    pieces
}

/// Fills `out` with the bytes of `values` converted to `N` bytes each,
/// from byte `from` of that stream on (a piece may start and end inside a
/// value).
pub(crate) fn fill_converted<T: Copy, const N: usize>(
    values: &[T],
    bytes: impl Fn(T) -> [u8; N],
    from: usize,
    out: &mut [u8],
) {
    let value = |i: usize| values.get(i).map_or([0; N], |&v| bytes(v));
    let mut i = from / N;
    let mut out = out;
    let skip = from % N;
    if skip != 0 {
        let first = value(i);
        let n = (N - skip).min(out.len());
        let (head, rest) = out.split_at_mut(n);
        head.copy_from_slice(&first[skip..skip + n]);
        out = rest;
        i += 1;
    }
    let whole = out.len() / N;
    let (body, tail) = out.split_at_mut(whole * N);
    let run = values.get(i..i + whole).unwrap_or_default();
    for (slot, &v) in body.chunks_exact_mut(N).zip(run) {
        slot.copy_from_slice(&bytes(v));
    }
    if !tail.is_empty() {
        let last = value(i + whole);
        tail.copy_from_slice(&last[..tail.len()]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every cut of a converted stream, at every offset and length, is the
    /// matching slice of the whole conversion.
    #[test]
    fn a_piece_of_a_converted_stream_is_that_slice_of_it() {
        let values: Vec<[f32; 3]> = (0..9)
            .map(|i| [i as f32, -(i as f32) * 0.5, 1e-3 * i as f32])
            .collect();
        let to_bytes = |v: [f32; 3]| {
            let mut b = [0u8; 12];
            for (slot, c) in b.chunks_exact_mut(4).zip(v) {
                slot.copy_from_slice(&c.to_le_bytes());
            }
            b
        };
        let whole: Vec<u8> = values.iter().flat_map(|&v| to_bytes(v)).collect();
        for from in 0..whole.len() {
            for len in 0..=whole.len() - from {
                let mut out = vec![0xAA; len];
                fill_converted(&values, to_bytes, from, &mut out);
                assert_eq!(out, whole[from..from + len], "from {from}, {len} bytes");
            }
        }
    }

    /// Pieces taken a few at a time by one thread, and the rest by another
    /// at the same time, give every range's bytes at their offsets, each
    /// piece taken once.
    #[test]
    fn pieces_taken_in_steps_and_the_rest_fill_every_range() {
        let values: Vec<u32> = (0..(3 * PIECE / 4 + 777) as u32)
            .map(|i| i.wrapping_mul(2_654_435_761))
            .collect();
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let (a, b) = values.split_at(100_001);
        let ranges = [
            Range {
                offset: 0,
                len: 4 * a.len(),
                fill: Box::new(|from, out| fill_converted(a, u32::to_le_bytes, from, out)),
            },
            Range {
                offset: 4 * a.len() as u64,
                len: 4 * b.len(),
                fill: Box::new(|from, out| fill_converted(b, u32::to_le_bytes, from, out)),
            },
        ];
        let dir = tempfile::tempdir().expect("temporary folder");
        let path = dir.path().join("pieces.bin");
        super::super::write_atomic_file(&path, |out| {
            let parts = out.parts().expect("positioned writes");
            let pieces = Pieces::of(&ranges);
            assert_eq!(pieces.len(), 5);
            let mut buffer = piece_buffer();
            pieces.write_until(&parts, 2, &mut buffer)?;
            assert_eq!(pieces.next.load(Ordering::Relaxed), 2);
            pieces.write_until(&parts, 1, &mut buffer)?;
            assert_eq!(pieces.next.load(Ordering::Relaxed), 2);
            std::thread::scope(|s| {
                let rest = s.spawn(|| pieces.write_rest(&parts));
                pieces.write_until(&parts, 4, &mut buffer)?;
                rest.join().expect("the other thread")
            })?;
            assert_eq!(pieces.next.load(Ordering::Relaxed), 5);
            Ok(())
        })
        .expect("written");
        assert_eq!(std::fs::read(&path).expect("read back"), bytes);
    }

    #[test]
    fn pieces_end_at_multiples_of_the_piece_size_in_the_file() {
        let range = Range {
            offset: PIECE as u64 - 10,
            len: 2 * PIECE + 30,
            fill: Box::new(|_, _| {}),
        };
        let cuts: Vec<(usize, usize)> = pieces_of(&range).iter().map(|p| (p.1, p.2)).collect();
        assert_eq!(
            cuts,
            vec![
                (0, 10),
                (10, PIECE),
                (10 + PIECE, PIECE),
                (10 + 2 * PIECE, 20)
            ]
        );
    }
}
