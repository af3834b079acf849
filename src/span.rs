//! Byte spans into one source text, and the line index that turns them into
//! 1-based line:column positions (columns counted in characters, as roxmltree does).

use std::ops::Range;
use std::sync::OnceLock;

/// A half-open byte range `start..end` in a source text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Span {
    pub start: u32,
    pub end: u32,
}

impl Span {
    pub fn new(start: usize, end: usize) -> Span {
        Span {
            start: clamp_u32(start),
            end: clamp_u32(end.max(start)),
        }
    }

    pub fn from_range(range: Range<usize>) -> Span {
        Span::new(range.start, range.end)
    }

    /// A sub-span `offset..offset+len` relative to this span's start.
    pub fn sub(self, offset: usize, len: usize) -> Span {
        let start = self.start as usize + offset;
        Span::new(start, (start + len).min(self.end as usize).max(start))
    }

    pub fn range(self) -> Range<usize> {
        self.start as usize..self.end as usize
    }

    pub fn len(self) -> usize {
        (self.end - self.start) as usize
    }

    pub fn is_empty(self) -> bool {
        self.end == self.start
    }
}

fn clamp_u32(value: usize) -> u32 {
    u32::try_from(value).unwrap_or(u32::MAX)
}

/// A 1-based line and column; the column counts characters, not bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct LineCol {
    pub line: u32,
    pub column: u32,
}

/// Start offsets of every line of a text, built once so that positions are
/// looked up by binary search instead of rescanning the text.
#[derive(Debug, Clone)]
pub struct LineIndex {
    line_starts: Vec<u32>,
}

impl LineIndex {
    pub fn new(text: &str) -> LineIndex {
        let mut line_starts = vec![0];
        // memchr's vectorised search: a byte-by-byte filter was about 2% of
        // the front end's instructions on a large file, all before reading.
        line_starts.extend(memchr::memchr_iter(b'\n', text.as_bytes()).map(|i| clamp_u32(i + 1)));
        LineIndex { line_starts }
    }

    /// The line:column of a byte offset in `text` (the text this index was built from).
    pub fn line_col(&self, text: &str, offset: usize) -> LineCol {
        let offset = floor_char_boundary(text, offset.min(text.len()));
        let line_idx = match self.line_starts.binary_search(&clamp_u32(offset)) {
            Ok(i) => i,
            Err(i) => i.saturating_sub(1),
        };
        let line_start = self.line_starts.get(line_idx).copied().unwrap_or(0) as usize;
        let column = text
            .get(line_start..offset)
            .map_or(0, |prefix| prefix.chars().count());
        LineCol {
            line: clamp_u32(line_idx + 1),
            column: clamp_u32(column + 1),
        }
    }

    /// The text of a 1-based line, without its line terminator.
    pub fn line_text<'t>(&self, text: &'t str, line: u32) -> &'t str {
        let idx = (line as usize).saturating_sub(1);
        let start = self.line_starts.get(idx).copied().unwrap_or(0) as usize;
        let end = self
            .line_starts
            .get(idx + 1)
            .map_or(text.len(), |&s| s as usize);
        text.get(start..end)
            .unwrap_or("")
            .trim_end_matches(['\n', '\r'])
    }

    /// The byte offset of a 1-based line:column, if it lies in the text.
    pub fn offset_of(&self, text: &str, pos: LineCol) -> Option<usize> {
        let start = *self.line_starts.get((pos.line as usize).checked_sub(1)?)? as usize;
        let line = text.get(start..)?;
        let skip = (pos.column as usize).saturating_sub(1);
        match line.char_indices().nth(skip) {
            Some((i, _)) => Some(start + i),
            None => Some(text.len()),
        }
    }
}

fn floor_char_boundary(text: &str, mut offset: usize) -> usize {
    while offset > 0 && !text.is_char_boundary(offset) {
        offset -= 1;
    }
    offset
}

/// One input text with its name (a path as the user gave it) and line index.
#[derive(Debug, Clone)]
pub struct SourceFile {
    pub name: String,
    pub text: String,
    /// Built on first use: only diagnostics read it, and building it was a
    /// serial pass over the whole text (with a vector of every line start)
    /// before a large file's reading could start, for nothing when the file
    /// has no findings.
    lines: OnceLock<LineIndex>,
}

impl SourceFile {
    pub fn new(name: impl Into<String>, text: impl Into<String>) -> SourceFile {
        SourceFile {
            name: name.into(),
            text: text.into(),
            lines: OnceLock::new(),
        }
    }

    /// The line index of [`SourceFile::text`].
    pub fn lines(&self) -> &LineIndex {
        self.lines.get_or_init(|| LineIndex::new(&self.text))
    }

    pub fn line_col(&self, offset: usize) -> LineCol {
        self.lines().line_col(&self.text, offset)
    }

    pub fn snippet(&self, span: Span) -> &str {
        self.text.get(span.range()).unwrap_or("")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_count_characters() {
        let src = SourceFile::new("t", "ab\nдx y\n");
        assert_eq!(src.line_col(0), LineCol { line: 1, column: 1 });
        assert_eq!(src.line_col(3), LineCol { line: 2, column: 1 });
        // 'x' follows a two-byte character.
        assert_eq!(src.line_col(5), LineCol { line: 2, column: 2 });
        assert_eq!(src.lines().line_text(&src.text, 2), "дx y");
        assert_eq!(
            src.lines()
                .offset_of(&src.text, LineCol { line: 2, column: 3 }),
            Some(6)
        );
    }

    /// The index built on first use (by any of the threads asking at once)
    /// places every offset as one built from the text directly.
    #[test]
    fn the_index_built_on_first_use_is_the_texts() {
        let mut rng = crate::test_rng::TestRng::new(0x2f6b_9d1c_43a7_e805);
        for _ in 0..200 {
            let text: String = (0..rng.below(120))
                .map(|_| ['a', ' ', '\n', '\r', 'д', '<'][rng.below(6)])
                .collect();
            let src = SourceFile::new("t", text.as_str());
            let direct = LineIndex::new(&text);
            let copy = src.clone();
            let asked: Vec<Vec<LineCol>> = std::thread::scope(|scope| {
                let threads: Vec<_> = (0..3)
                    .map(|_| scope.spawn(|| (0..=text.len()).map(|o| src.line_col(o)).collect()))
                    .collect();
                threads
                    .into_iter()
                    .map(|t| t.join().expect("no panic"))
                    .collect()
            });
            let expected: Vec<LineCol> = (0..=text.len())
                .map(|o| direct.line_col(&text, o))
                .collect();
            assert!(asked.iter().all(|a| *a == expected), "{text:?}");
            // A copy made before the index was built builds its own.
            assert_eq!(
                copy.line_col(text.len()),
                direct.line_col(&text, text.len())
            );
            let last = expected.last().map_or(1, |p| p.line);
            assert_eq!(
                src.lines().line_text(&text, last),
                direct.line_text(&text, last)
            );
        }
        let src = SourceFile::new("t", "a\nb\n\nc");
        assert_eq!(src.line_col(5), LineCol { line: 4, column: 1 });
    }
}
