//! A file writer for large outputs that bypasses the page cache: whole
//! blocks go to the disk with `O_DIRECT` from aligned buffers, written by a
//! thread of their own while the next block is filled; the last partial
//! block goes through the page cache. `write_atomic` syncs the file anyway,
//! so the data had to reach the disk before it returned; through the page
//! cache the kernel first copied it there (a sixth to a fifth of an
//! MSH → GLB conversion's CPU time in `perf`) and wrote it back only at the
//! sync. Outputs smaller than one block never use `O_DIRECT`, and a file
//! system that refuses it is written through the page cache as before.

use std::fs::File;
use std::io::{self, Write};
use std::os::fd::AsRawFd;
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, sync_channel};
use std::thread::JoinHandle;

/// Bytes per direct write.
const BLOCK: usize = 4 << 20;
/// The alignment `O_DIRECT` asks of the buffer, the file offset and the
/// length (the largest logical block size in use).
const ALIGN: usize = 4096;
/// Blocks in use at once: one filled while the other is written.
const BLOCKS: usize = 2;

/// A buffer of `BLOCK` aligned bytes at `start`, `filled` of them used.
struct Block {
    bytes: Vec<u8>,
    start: usize,
    filled: usize,
}

impl Block {
    fn new() -> Block {
        // Zeroed by the allocator without a pass: the first touch of each
        // page is the copy into it.
        let bytes = vec![0; BLOCK + ALIGN];
        let start = bytes.as_ptr().align_offset(ALIGN).min(ALIGN);
        Block {
            bytes,
            start,
            filled: 0,
        }
    }

    fn used(&self) -> &[u8] {
        self.bytes
            .get(self.start..self.start + self.filled)
            .unwrap_or_default()
    }
}

/// The file, with `O_DIRECT` set while whole blocks are written.
struct Disk {
    file: File,
    direct: bool,
    /// `O_DIRECT` was refused: the page cache from then on.
    refused: bool,
}

impl Disk {
    /// Sets or clears `O_DIRECT`.
    fn set_direct(&mut self, on: bool) {
        if on == self.direct || (on && self.refused) {
            return;
        }
        let fd = self.file.as_raw_fd();
        // SAFETY: `fcntl` on a file descriptor this writer owns; F_GETFL and
        // F_SETFL only read and change its status flags.
        let ok = unsafe {
            let flags = libc::fcntl(fd, libc::F_GETFL);
            let flags = if on {
                flags | libc::O_DIRECT
            } else {
                flags & !libc::O_DIRECT
            };
            flags >= 0 && libc::fcntl(fd, libc::F_SETFL, flags) == 0
        };
        if ok {
            self.direct = on;
        } else if on {
            self.refused = true;
        }
    }

    /// Writes a whole block: directly when the file system allows it.
    fn write_block(&mut self, block: &Block) -> io::Result<()> {
        self.set_direct(true);
        let mut rest = block.used();
        while !rest.is_empty() {
            match self.file.write(rest) {
                Ok(0) => return Err(io::ErrorKind::WriteZero.into()),
                Ok(n) => rest = rest.get(n..).unwrap_or_default(),
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                // A file system (or a short write's unaligned rest) that
                // `O_DIRECT` does not suit: the page cache from here on.
                Err(e) if self.direct && e.raw_os_error() == Some(libc::EINVAL) => {
                    self.set_direct(false);
                    self.refused = true;
                }
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }
}

/// Where full blocks go.
enum Io {
    /// Not started: no block was full yet.
    Idle(Disk),
    /// A thread writes the blocks sent to it and sends them back for reuse.
    Thread {
        to_io: SyncSender<Block>,
        from_io: Receiver<Block>,
        handle: JoinHandle<io::Result<Disk>>,
        blocks: usize,
    },
    /// Written in place (no thread could be started).
    Inline(Disk),
    Failed,
}

pub(crate) struct DirectWriter {
    block: Option<Block>,
    io: Io,
}

impl DirectWriter {
    pub(crate) fn new(file: File) -> DirectWriter {
        DirectWriter {
            block: None,
            io: Io::Idle(Disk {
                file,
                direct: false,
                refused: false,
            }),
        }
    }

    /// Waits for the blocks in flight, writes what is left through the page
    /// cache and returns the file.
    pub(crate) fn finish(mut self) -> io::Result<File> {
        let mut disk = match std::mem::replace(&mut self.io, Io::Failed) {
            Io::Idle(disk) | Io::Inline(disk) => disk,
            Io::Thread { to_io, handle, .. } => {
                drop(to_io);
                join(handle)?
            }
            Io::Failed => return Err(io::Error::other("an earlier write failed")),
        };
        disk.set_direct(false);
        if let Some(block) = &self.block {
            disk.file.write_all(block.used())?;
        }
        Ok(disk.file)
    }

    /// Sends the full block away and takes an empty one.
    fn hand_over(&mut self) -> io::Result<()> {
        let Some(full) = self.block.take() else {
            return Ok(());
        };
        if let Io::Idle(_) = self.io {
            let Io::Idle(disk) = std::mem::replace(&mut self.io, Io::Failed) else {
                return Ok(());
            };
            self.io = start_thread(disk);
        }
        match &mut self.io {
            Io::Inline(disk) => {
                let result = disk.write_block(&full);
                self.block = Some(Block { filled: 0, ..full });
                result
            }
            Io::Thread {
                to_io,
                from_io,
                blocks,
                ..
            } => {
                let sent = to_io.send(full).is_ok();
                let empty = match from_io.try_recv() {
                    Ok(b) => Some(b),
                    Err(TryRecvError::Empty) if *blocks < BLOCKS => {
                        *blocks += 1;
                        Some(Block::new())
                    }
                    Err(_) if sent => from_io.recv().ok(),
                    Err(_) => None,
                };
                match empty {
                    Some(b) => {
                        self.block = Some(Block { filled: 0, ..b });
                        Ok(())
                    }
                    // The thread stopped: its error says why.
                    None => self.fail(),
                }
            }
            Io::Idle(_) | Io::Failed => Err(io::Error::other("an earlier write failed")),
        }
    }

    /// The writing thread's error, once it stopped.
    fn fail(&mut self) -> io::Result<()> {
        match std::mem::replace(&mut self.io, Io::Failed) {
            Io::Thread { to_io, handle, .. } => {
                drop(to_io);
                join(handle).and(Err(io::Error::other("the writing thread stopped")))
            }
            _ => Err(io::Error::other("an earlier write failed")),
        }
    }
}

/// The thread that writes full blocks; in place when none can be started.
fn start_thread(disk: Disk) -> Io {
    let (to_io, blocks_in) = sync_channel::<Block>(1);
    let (blocks_out, from_io) = sync_channel::<Block>(BLOCKS);
    let disk = std::sync::Arc::new(std::sync::Mutex::new(Some(disk)));
    let shared = disk.clone();
    let spawned = std::thread::Builder::new()
        .name("geomc-write".into())
        .spawn(move || {
            let taken = shared.lock().ok().and_then(|mut d| d.take());
            let Some(mut disk) = taken else {
                return Err(io::Error::other("the file was not handed over"));
            };
            for block in blocks_in {
                disk.write_block(&block)?;
                // The writer may be done and gone: then the block is dropped.
                let _ = blocks_out.send(block);
            }
            Ok(disk)
        });
    match spawned {
        Ok(handle) => Io::Thread {
            to_io,
            from_io,
            handle,
            blocks: 1,
        },
        Err(_) => match disk.lock().ok().and_then(|mut d| d.take()) {
            Some(disk) => Io::Inline(disk),
            None => Io::Failed,
        },
    }
}

fn join(handle: JoinHandle<io::Result<Disk>>) -> io::Result<Disk> {
    handle
        .join()
        .unwrap_or_else(|_| Err(io::Error::other("the writing thread panicked")))
}

impl Write for DirectWriter {
    fn write(&mut self, data: &[u8]) -> io::Result<usize> {
        let block = self.block.get_or_insert_with(Block::new);
        let (start, filled) = (block.start, block.filled);
        let room = block
            .bytes
            .get_mut(start + filled..start + BLOCK)
            .unwrap_or_default();
        let n = room.len().min(data.len());
        if let (Some(to), Some(from)) = (room.get_mut(..n), data.get(..n)) {
            to.copy_from_slice(from);
        }
        block.filled += n;
        if block.filled == BLOCK {
            self.hand_over()?;
        }
        Ok(n)
    }

    /// Nothing: a partial block is written by [`DirectWriter::finish`] (a
    /// direct write needs whole blocks).
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whole blocks (directly, or through the page cache where the file
    /// system refuses `O_DIRECT`) and the tail reach the file in order.
    #[test]
    fn writes_every_byte_in_order_across_blocks() {
        let dir = tempfile::tempdir().expect("temporary folder");
        for len in [0usize, 10, BLOCK, 2 * BLOCK + 12_345, 5 * BLOCK + 1] {
            let data: Vec<u8> = (0..len).map(|i| (i * 7 + i / 4099) as u8).collect();
            let path = dir.path().join(format!("out{len}"));
            let mut w = DirectWriter::new(File::create(&path).expect("create"));
            // Uneven pieces, as the writers give them.
            for piece in data.chunks(300_007) {
                w.write_all(piece).expect("write");
            }
            w.finish().expect("finish").sync_all().expect("sync");
            assert!(
                std::fs::read(&path).expect("read back") == data,
                "{len} bytes"
            );
        }
    }
}
