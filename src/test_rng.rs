//! A fixed pseudo-random sequence for tests that try many generated cases
//! (xorshift64 with shifts 13, 7, 17): the same cases on every run, so a
//! failure names a case that comes back.

pub struct TestRng(u64);

impl TestRng {
    /// `seed` must not be zero (xorshift stays at zero).
    pub fn new(seed: u64) -> Self {
        TestRng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        let mut s = self.0;
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        self.0 = s;
        s
    }

    /// A number in `0..bound`.
    pub fn below(&mut self, bound: usize) -> usize {
        (self.next_u64() % bound as u64) as usize
    }

    /// A number in `-reach..=reach`.
    pub fn within(&mut self, reach: i64) -> i64 {
        (self.next_u64() % (2 * reach as u64 + 1)) as i64 - reach
    }

    /// `text` after one to `most` edits, each inserting, replacing or
    /// removing one byte at a random place with a byte of `alphabet`;
    /// `None` when the result is not UTF-8.
    pub fn edit(&mut self, text: &str, alphabet: &[u8], most: usize) -> Option<String> {
        let mut bytes = text.as_bytes().to_vec();
        for _ in 0..1 + self.below(most) {
            let at = self.below(bytes.len());
            let byte = alphabet[self.below(alphabet.len())];
            match self.below(3) {
                0 => bytes.insert(at, byte),
                1 => bytes[at] = byte,
                _ => drop(bytes.remove(at)),
            }
        }
        String::from_utf8(bytes).ok()
    }
}
