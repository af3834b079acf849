//! Atomic file output: write to a temporary file in the destination's folder,
//! flush and fsync it, then rename it over the destination. A reader sees the
//! old file or the whole new one, never a half-written one, and an error
//! removes the temporary file so nothing partial is left behind.

use super::WriteError;
use std::fs::{File, OpenOptions};
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::Sender;

/// Distinguishes temporary files of one process writing several outputs at once.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Calls `fill` with a buffered writer to a temporary file beside `path`, then
/// moves the finished file to `path`.
pub fn write_atomic<T>(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> Result<T, WriteError>,
) -> Result<T, WriteError> {
    write_atomic_file(path, |out| fill(out))
}

/// [`write_atomic`] with the output file itself, so that a writer may also
/// have parts of it written at their offsets by other threads
/// ([`FileOutput::parts`]).
pub fn write_atomic_file<T>(
    path: &Path,
    fill: impl FnOnce(&mut FileOutput) -> Result<T, WriteError>,
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
    fill: impl FnOnce(&mut FileOutput) -> Result<T, WriteError>,
) -> Result<T, WriteError> {
    let mut out = FileOutput::new(file);
    let value = fill(&mut out)?;
    out.flush()?;
    let FileOutput { file, syncer, .. } = out;
    file.sync_all()?;
    if let Some(syncer) = syncer {
        // A write-back error the background sync saw is not seen again by
        // the final one (they share the open file): it is reported here.
        syncer.finish()?;
    }
    Ok(value)
}

/// Bytes of [`FileOutput`]'s buffer.
const BUFFER: usize = 1 << 20;

/// Memory pages and file blocks: the buffer's bytes sit at the same offset
/// within a page as they will in the file.
const PAGE: usize = 4096;

/// Bytes written between two syncs on the background thread.
const SYNC_STEP: u64 = 8 << 20;

/// A buffered writer to a new file whose writes are whole buffers from a
/// page-aligned buffer at offsets that are multiples of the buffer's size
/// (the first after [`FileOutput::skip_to`] and the last one excepted): the
/// kernel's copy into the page cache was up to three times slower for some
/// offsets of the file against the memory (a 24 MB write at file offset
/// 1,500 took 55 ms of CPU, at 0 or 2,000 20 ms). Past [`SYNC_STEP`] bytes
/// a thread syncs the file's data every [`SYNC_STEP`] bytes while the
/// writer goes on, so the final sync of a large output waits for its tail
/// only (the whole 48 MB of a GLB took 27–41 ms to sync at the end).
pub struct FileOutput {
    file: File,
    buffer: Vec<u8>,
    /// Where the page-aligned part of `buffer` starts.
    start: usize,
    len: usize,
    /// The file offset of the buffer's first byte.
    at: u64,
    /// Bytes written before the syncer started.
    unsynced: u64,
    syncer: Option<Syncer>,
}

impl FileOutput {
    fn new(file: File) -> FileOutput {
        let buffer = vec![0u8; BUFFER + PAGE];
        let start = buffer.as_ptr().align_offset(PAGE).min(PAGE);
        FileOutput {
            file,
            buffer,
            start,
            len: 0,
            at: 0,
            unsynced: 0,
            syncer: None,
        }
    }

    /// Where the buffer's bytes start: at the file offset's place in a page.
    fn first(&self) -> usize {
        self.start + (self.at % PAGE as u64) as usize
    }

    /// Bytes the buffer takes before it is written: up to the next multiple
    /// of [`BUFFER`] in the file.
    fn room(&self) -> usize {
        BUFFER - (self.at % BUFFER as u64) as usize
    }

    fn write_buffer(&mut self) -> std::io::Result<()> {
        let first = self.first();
        let Some(bytes) = self.buffer.get(first..first + self.len) else {
            return Ok(());
        };
        (&self.file).write_all(bytes)?;
        let written = self.len as u64;
        self.at += written;
        self.len = 0;
        self.wrote(written);
        Ok(())
    }

    /// Counts written bytes; starts the syncer once they pass [`SYNC_STEP`].
    fn wrote(&mut self, bytes: u64) {
        if self.syncer.is_none() {
            self.unsynced += bytes;
            if self.unsynced < SYNC_STEP {
                return;
            }
            self.start_syncer();
            return;
        }
        if let Some(s) = &self.syncer {
            s.trigger.wrote(bytes);
        }
    }

    fn start_syncer(&mut self) {
        self.syncer = Syncer::start(&self.file);
        if let Some(s) = &self.syncer {
            s.trigger.wrote(std::mem::take(&mut self.unsynced));
        }
    }

    /// Writes what is buffered and goes on at file offset `offset` (at or
    /// past the end of what was written): the bytes between are left to
    /// [`FileOutput::parts`].
    pub fn skip_to(&mut self, offset: u64) -> std::io::Result<()> {
        self.write_buffer()?;
        if offset != self.at {
            (&self.file).seek(SeekFrom::Start(offset))?;
            self.at = offset;
        }
        Ok(())
    }

    /// Writes `values` converted to `N` bytes each, converted straight into
    /// the buffer (no block of their own copied in afterwards).
    pub(crate) fn write_converted<T: Copy, const N: usize>(
        &mut self,
        values: &[T],
        bytes: impl Fn(T) -> [u8; N],
    ) -> std::io::Result<()> {
        let total = N * values.len();
        let mut from = 0;
        while from < total {
            let room = self.room();
            let n = (room - self.len).min(total - from);
            let at = self.first() + self.len;
            if let Some(slot) = self.buffer.get_mut(at..at + n) {
                super::file_ranges::fill_converted(values, &bytes, from, slot);
            }
            self.len += n;
            from += n;
            if self.len == room {
                self.write_buffer()?;
            }
        }
        Ok(())
    }

    /// The file offset the next byte written goes to.
    pub fn position(&self) -> u64 {
        self.at + self.len as u64
    }

    /// A handle with which any thread writes bytes at given offsets of the
    /// file (the syncer counts them too); `None` where the platform has no
    /// positioned writes or the file cannot be shared. Drop it before the
    /// output is finished.
    pub fn parts(&mut self) -> Option<Parts> {
        if !cfg!(any(unix, windows)) {
            return None;
        }
        if self.syncer.is_none() {
            self.start_syncer();
        }
        Some(Parts {
            file: self.file.try_clone().ok()?,
            trigger: self.syncer.as_ref().map(|s| s.trigger.clone()),
        })
    }
}

impl Write for FileOutput {
    fn write(&mut self, data: &[u8]) -> std::io::Result<usize> {
        let room = self.room();
        let n = data.len().min(room - self.len);
        let at = self.first() + self.len;
        if let (Some(slot), Some(part)) = (self.buffer.get_mut(at..at + n), data.get(..n)) {
            slot.copy_from_slice(part);
        }
        self.len += n;
        if self.len == room {
            self.write_buffer()?;
        }
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.write_buffer()?;
        (&self.file).flush()
    }
}

/// Writes bytes at offsets of a [`FileOutput`]'s file, from any thread.
pub struct Parts {
    file: File,
    trigger: Option<SyncTrigger>,
}

impl Parts {
    /// Writes `bytes` at file offset `offset`.
    pub fn write_at(&self, offset: u64, bytes: &[u8]) -> std::io::Result<()> {
        write_all_at(&self.file, offset, bytes)?;
        if let Some(t) = &self.trigger {
            t.wrote(bytes.len() as u64);
        }
        Ok(())
    }
}

#[cfg(unix)]
fn write_all_at(file: &File, offset: u64, bytes: &[u8]) -> std::io::Result<()> {
    std::os::unix::fs::FileExt::write_all_at(file, bytes, offset)
}

#[cfg(windows)]
fn write_all_at(file: &File, mut offset: u64, mut bytes: &[u8]) -> std::io::Result<()> {
    while !bytes.is_empty() {
        let n = std::os::windows::fs::FileExt::seek_write(file, bytes, offset)?;
        if n == 0 {
            return Err(std::io::ErrorKind::WriteZero.into());
        }
        bytes = bytes.get(n..).unwrap_or_default();
        offset += n as u64;
    }
    Ok(())
}

#[cfg(not(any(unix, windows)))]
fn write_all_at(_: &File, _: u64, _: &[u8]) -> std::io::Result<()> {
    Err(std::io::ErrorKind::Unsupported.into())
}

/// Counts the bytes written by a file's writers and asks the syncer for a
/// sync each time the count passes a multiple of [`SYNC_STEP`].
#[derive(Clone)]
struct SyncTrigger {
    written: Arc<AtomicU64>,
    requests: Sender<()>,
}

impl SyncTrigger {
    fn wrote(&self, bytes: u64) {
        let before = self.written.fetch_add(bytes, Ordering::Relaxed);
        if (before + bytes) / SYNC_STEP != before / SYNC_STEP {
            let _ = self.requests.send(());
        }
    }
}

/// The background thread that syncs a file's data on request.
struct Syncer {
    trigger: SyncTrigger,
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
        Some(Syncer {
            trigger: SyncTrigger {
                written: Arc::new(AtomicU64::new(0)),
                requests,
            },
            thread,
        })
    }

    /// Stops the thread (once every [`Parts`] is dropped too); its first
    /// error, if any.
    fn finish(self) -> std::io::Result<()> {
        drop(self.trigger);
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

    /// Bytes skipped by the buffered writer and written through `parts`
    /// from another thread, before, between and after buffered writes at
    /// odd offsets, give the file back byte for byte.
    #[test]
    fn skipped_ranges_written_by_offset_fill_the_gaps() {
        let dir = tempfile::tempdir().expect("temporary folder");
        let path = dir.path().join("parts.bin");
        let data: Vec<u8> = (0..(2 * SYNC_STEP as usize + 5_000))
            .map(|i| (i * 13 + i / 5003) as u8)
            .collect();
        // Written in order / left to the parts: [0, a) [a, b) [b, c) [c, d) [d, end).
        let (a, b, c, d) = (
            1_500,
            3 * BUFFER + 77,
            3 * BUFFER + 4_096,
            SYNC_STEP as usize + 9,
        );
        write_atomic_file(&path, |out| {
            let parts = out.parts().expect("positioned writes");
            std::thread::scope(|s| {
                s.spawn(|| {
                    for (from, to) in [(a, b), (c, d)] {
                        for piece in (from..to).step_by(300_001) {
                            let end = (piece + 300_001).min(to);
                            parts
                                .write_at(piece as u64, &data[piece..end])
                                .expect("part");
                        }
                    }
                });
            });
            drop(parts);
            out.write_all(&data[..a])?;
            assert_eq!(out.position(), a as u64);
            out.skip_to(b as u64)?;
            for piece in data[b..c].chunks(999) {
                out.write_all(piece)?;
            }
            out.skip_to(d as u64)?;
            for piece in data[d..].chunks(777_777) {
                out.write_all(piece)?;
            }
            Ok(())
        })
        .expect("written");
        assert_eq!(std::fs::read(&path).expect("read back"), data);
    }

    /// Values converted straight into the buffer, across several buffers
    /// and from an offset that is not a value's or a page's, give the bytes
    /// of their conversion.
    #[test]
    fn values_converted_into_the_buffer_are_their_bytes() {
        let dir = tempfile::tempdir().expect("temporary folder");
        let path = dir.path().join("converted.bin");
        let values: Vec<f32> = (0..700_000).map(|i| i as f32 * 0.37 - 5.0).collect();
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        write_atomic_file(&path, |out| {
            out.write_all(b"abc")?;
            out.write_converted(&values[..1_000], f32::to_le_bytes)?;
            out.write_converted(&values[1_000..], f32::to_le_bytes)?;
            out.write_all(b"z")?;
            Ok(())
        })
        .expect("written");
        let read = std::fs::read(&path).expect("read back");
        assert_eq!(read.len(), 4 + bytes.len());
        assert_eq!(&read[..3], b"abc");
        assert_eq!(read[3..3 + bytes.len()], bytes[..]);
        assert_eq!(read.last(), Some(&b'z'));
    }
}
