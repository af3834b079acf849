//! Atomic file output: write to a temporary file in the destination's folder,
//! flush and fsync it, then rename it over the destination. A reader sees the
//! old file or the whole new one, never a half-written one, and an error
//! removes the temporary file so nothing partial is left behind.

use super::WriteError;
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
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
    // Large writes: the writers' pieces reach the kernel in few system calls.
    let mut out = BufWriter::with_capacity(1 << 20, file);
    let value = fill(&mut out)?;
    let file = out.into_inner().map_err(|e| e.into_error())?;
    file.sync_all()?;
    Ok(value)
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
