//! Atomic file output: write to a temporary file in the destination's folder,
//! flush and fsync it, then rename it over the destination. A reader sees the
//! old file or the whole new one, never a half-written one, and an error
//! removes the temporary file so nothing partial is left behind.

use super::WriteError;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Distinguishes temporary files of one process writing several outputs at once.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Calls `fill` with a buffered writer to a temporary file beside `path`, then
/// moves the finished file to `path`.
pub fn write_atomic<T>(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> Result<T, WriteError>,
) -> Result<T, WriteError> {
    let (tmp_path, file) = create_temporary(path)?;
    match fill_and_sync(file, fill) {
        Ok(value) => match std::fs::rename(&tmp_path, path) {
            Ok(()) => {
                sync_folder(path);
                Ok(value)
            }
            Err(e) => {
                let _ = std::fs::remove_file(&tmp_path);
                Err(e.into())
            }
        },
        Err(e) => {
            let _ = std::fs::remove_file(&tmp_path);
            Err(e)
        }
    }
}

fn fill_and_sync<T>(
    file: File,
    fill: impl FnOnce(&mut dyn Write) -> Result<T, WriteError>,
) -> Result<T, WriteError> {
    let mut out = PageWriter::new(file);
    let value = fill(&mut out)?;
    out.flush()?;
    let PageWriter { file, syncer, .. } = out;
    file.sync_all()?;
    if let Some(syncer) = syncer {
        // A write-back error the background sync saw is not seen again by
        // the final one (they share the open file): it is reported here.
        syncer.finish()?;
    }
    Ok(value)
}

/// Bytes of [`PageWriter`]'s buffer.
const BUFFER: usize = 1 << 20;

/// Bytes written between two syncs on the background thread.
const SYNC_STEP: u64 = 8 << 20;

/// A buffered writer whose writes to the file are whole buffers from a
/// page-aligned buffer at offsets that are multiples of the buffer's size
/// (the last one excepted): the kernel's copy into the page cache was up to
/// three times slower for some offsets of the file against the memory
/// (a 24 MB write at file offset 1,500 took 55 ms of CPU, at 0 or 2,000
/// 20 ms). Past [`SYNC_STEP`] bytes a thread syncs the file's data every
/// [`SYNC_STEP`] bytes while the writer goes on, so the final sync of a
/// large output waits for its tail only (the whole 48 MB of a GLB took
/// 27–41 ms to sync at the end).
struct PageWriter {
    file: File,
    buffer: Vec<u8>,
    /// Where the page-aligned part of `buffer` starts.
    start: usize,
    len: usize,
    unsynced: u64,
    syncer: Option<Syncer>,
}

impl PageWriter {
    fn new(file: File) -> PageWriter {
        let buffer = vec![0u8; BUFFER + 4096];
        let start = buffer.as_ptr().align_offset(4096).min(4096);
        PageWriter {
            file,
            buffer,
            start,
            len: 0,
            unsynced: 0,
            syncer: None,
        }
    }

    fn write_buffer(&mut self) -> std::io::Result<()> {
        let Some(bytes) = self.buffer.get(self.start..self.start + self.len) else {
            return Ok(());
        };
        (&self.file).write_all(bytes)?;
        self.unsynced += self.len as u64;
        self.len = 0;
        if self.unsynced >= SYNC_STEP {
            self.unsynced = 0;
            if self.syncer.is_none() {
                self.syncer = Syncer::start(&self.file);
            }
            if let Some(s) = &self.syncer {
                s.request();
            }
        }
        Ok(())
    }
}

impl Write for PageWriter {
    fn write(&mut self, data: &[u8]) -> std::io::Result<usize> {
        let free = BUFFER - self.len;
        let n = data.len().min(free);
        let at = self.start + self.len;
        if let (Some(slot), Some(part)) = (self.buffer.get_mut(at..at + n), data.get(..n)) {
            slot.copy_from_slice(part);
        }
        self.len += n;
        if self.len == BUFFER {
            self.write_buffer()?;
        }
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.write_buffer()?;
        (&self.file).flush()
    }
}

/// The background thread that syncs a file's data on request.
struct Syncer {
    requests: std::sync::mpsc::Sender<()>,
    thread: std::thread::JoinHandle<std::io::Result<()>>,
}

impl Syncer {
    /// `None` when the file cannot be shared with a thread (then only the
    /// final sync runs).
    fn start(file: &File) -> Option<Syncer> {
        let file = file.try_clone().ok()?;
        let (requests, received) = std::sync::mpsc::channel::<()>();
        let thread = std::thread::Builder::new()
            .name("geomc-sync".into())
            .spawn(move || {
                while received.recv().is_ok() {
                    // Requests that came while syncing are covered by one more sync.
                    while received.try_recv().is_ok() {}
                    file.sync_data()?;
                }
                Ok(())
            })
            .ok()?;
        Some(Syncer { requests, thread })
    }

    fn request(&self) {
        let _ = self.requests.send(());
    }

    /// Stops the thread; its first error, if any.
    fn finish(self) -> std::io::Result<()> {
        drop(self.requests);
        self.thread
            .join()
            .unwrap_or_else(|_| Err(std::io::Error::other("the sync thread panicked")))
    }
}

/// A new file `.NAME.PID.N.tmp` in the same folder: the same file system, so
/// the final rename is atomic. `create_new` never reuses a stale file.
fn create_temporary(path: &Path) -> Result<(PathBuf, File), WriteError> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .ok_or_else(|| WriteError::Unsupported(format!("not a file path: {}", path.display())))?;
    let folder = path.parent().unwrap_or(Path::new(""));
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = folder.join(format!(".{name}.{}.{n}.tmp", std::process::id()));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(file) => return Ok((tmp, file)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e.into()),
        }
    }
}

/// Makes the rename itself durable where the platform allows opening a folder;
/// best effort, since the data is already safe in the file.
fn sync_folder(path: &Path) {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if let Ok(dir) = File::open(folder) {
        let _ = dir.sync_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Writes of odd sizes across many buffers and past several background
    /// syncs give the file back byte for byte.
    #[test]
    fn large_output_in_odd_pieces_is_written_whole() {
        let dir = tempfile::tempdir().expect("temporary folder");
        let path = dir.path().join("big.bin");
        let data: Vec<u8> = (0..(3 * SYNC_STEP as usize + 12_345))
            .map(|i| (i * 7 + i / 4099) as u8)
            .collect();
        write_atomic(&path, |out| {
            for piece in data.chunks(777_777) {
                out.write_all(piece)?;
            }
            Ok(())
        })
        .expect("written");
        assert_eq!(std::fs::read(&path).expect("read back"), data);
    }
}
