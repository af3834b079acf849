//! A mesh file's bytes, memory-mapped: the readers parse the page cache in
//! place, where reading into a buffer made the kernel zero a fresh buffer as
//! large as the file and copy the file into it (a third of an MSH → GLB
//! conversion's time).

use memmap2::{Mmap, MmapOptions};
use std::fs::File;
use std::path::Path;

/// The bytes of a file: mapped, or read when mapping is not possible
/// (an empty file, a pipe).
pub enum FileBytes {
    Mapped(Mmap),
    Read(Vec<u8>),
}

impl FileBytes {
    pub fn open(path: &Path) -> std::io::Result<FileBytes> {
        let file = File::open(path)?;
        let meta = file.metadata()?;
        if meta.is_file() && meta.len() > 0 {
            // SAFETY: the map is read-only and private to this process; a
            // file truncated by another program while it is read could raise
            // SIGBUS, as with any program that maps its input (the readers
            // only read, and the map lives no longer than the parse).
            // `populate` faults the pages in at once instead of one fault
            // per few pages while parsing.
            if let Ok(map) = unsafe { MmapOptions::new().populate().map(&file) } {
                return Ok(FileBytes::Mapped(map));
            }
        }
        std::fs::read(path).map(FileBytes::Read)
    }
}

impl std::ops::Deref for FileBytes {
    type Target = [u8];

    fn deref(&self) -> &[u8] {
        match self {
            FileBytes::Mapped(map) => map,
            FileBytes::Read(bytes) => bytes,
        }
    }
}
