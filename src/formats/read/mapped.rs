//! A mesh file's bytes, memory-mapped: the readers parse the page cache in
//! place, where reading into a buffer made the kernel zero a fresh buffer as
//! large as the file and copy the file into it (a third of an MSH → GLB
//! conversion's time).

use memmap2::{Mmap, MmapOptions};
use std::fs::File;
use std::path::Path;

/// Bytes of the map faulted in by one job of [`map`].
#[cfg(target_os = "linux")]
const POPULATE_PIECE: usize = 8 << 20;

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
        if meta.is_file()
            && meta.len() > 0
            && let Ok(map) = map(&file)
        {
            return Ok(FileBytes::Mapped(map));
        }
        std::fs::read(path).map(FileBytes::Read)
    }
}

/// The file mapped with its pages faulted in at once, instead of one fault
/// per few pages while parsing. On Linux the pages are faulted in by
/// parallel jobs of [`POPULATE_PIECE`] bytes (`MADV_POPULATE_READ`): the
/// single-threaded `MAP_POPULATE` of a 96 MB MSH file was about a tenth of
/// an MSH → GLB conversion's wall time, with the other core idle.
fn map(file: &File) -> std::io::Result<Mmap> {
    // SAFETY: the map is read-only and private to this process; a file
    // truncated by another program while it is read could raise SIGBUS, as
    // with any program that maps its input (the readers only read, and the
    // map lives no longer than the parse).
    #[cfg(target_os = "linux")]
    {
        use rayon::prelude::*;
        let map = unsafe { MmapOptions::new().map(file) }?;
        let len = map.len();
        let populated = (0..len.div_ceil(POPULATE_PIECE))
            .into_par_iter()
            .map(|i| {
                let offset = i * POPULATE_PIECE;
                map.advise_range(
                    memmap2::Advice::PopulateRead,
                    offset,
                    POPULATE_PIECE.min(len - offset),
                )
            })
            .all(|r| r.is_ok());
        if !populated {
            // A kernel before 5.14: the pages fault in while parsing.
            let _ = map.advise(memmap2::Advice::WillNeed);
        }
        Ok(map)
    }
    #[cfg(not(target_os = "linux"))]
    unsafe {
        MmapOptions::new().populate().map(file)
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
