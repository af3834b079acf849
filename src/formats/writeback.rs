//! An output file whose pages are sent to the disk while it is still being
//! written: the final `fsync` of the atomic write (see `atomic.rs`) then waits
//! for the last few megabytes only, instead of for the whole file after the
//! last byte (tens of milliseconds for a 70 MB GLB, a fifth of a conversion).

use std::fs::File;
use std::io::{self, Write};

/// Bytes written between two write-back starts.
const STEP: u64 = 8 << 20;

/// A file that starts writing back each `STEP` bytes as they are written.
pub struct Writeback {
    file: File,
    written: u64,
    started: u64,
}

impl Writeback {
    pub fn new(file: File) -> Writeback {
        Writeback {
            file,
            written: 0,
            started: 0,
        }
    }

    pub fn into_file(self) -> File {
        self.file
    }
}

impl Write for Writeback {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.file.write(buf)?;
        self.written += n as u64;
        if self.written - self.started >= STEP {
            start_writeback(&self.file, self.started, self.written - self.started);
            self.started = self.written;
        }
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file.flush()
    }
}

/// Asks the kernel to start writing a range of the file to disk, without
/// waiting for it. Only a hint: the `fsync` at the end is what makes the file
/// durable, so a failure here is ignored.
#[cfg(target_os = "linux")]
fn start_writeback(file: &File, offset: u64, len: u64) {
    use std::os::fd::AsRawFd;
    let (Ok(offset), Ok(len)) = (i64::try_from(offset), i64::try_from(len)) else {
        return;
    };
    // SAFETY: a plain system call on a file descriptor this process owns
    // (borrowed from `file` for the call); it reads no memory of ours.
    unsafe {
        libc::sync_file_range(file.as_raw_fd(), offset, len, libc::SYNC_FILE_RANGE_WRITE);
    }
}

#[cfg(not(target_os = "linux"))]
fn start_writeback(_file: &File, _offset: u64, _len: u64) {}
