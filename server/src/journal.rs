//! The pose journal: the latest stored pose of every object, in a
//! memory-mapped file next to the state file (`<state file>.poses`).
//!
//! Pose updates are the hot path (one per object per control cycle), far too
//! frequent for an fsynced rewrite of the state file each. A store into a
//! shared file mapping costs a few nanoseconds and lands in the kernel's page
//! cache, which outlives the process: after `kill -9` (or a panic, or an
//! abort) the restarted server finds every pose that was acknowledged. Only
//! a crash of the whole machine can lose poses written since the last
//! `msync` (done at housekeeping, every few seconds while poses change); the
//! objects themselves are on disk regardless (the fsynced change log and state
//! file, see `crate::persist`).
//!
//! # Layout (version 1)
//!
//! A 16-byte header (`b"GJKDPOSE"`, version `u32` LE, 4 zero bytes), then
//! one 72-byte slot per object: the object id, the seven pose components
//! (`[x, y, z, i, j, k, w]`) and a check word, all `u64` little-endian. The
//! check word is a hash of the other eight, so a slot torn by a kill in the
//! middle of its update reads as invalid and the state file's pose is used
//! instead. A slot whose id is not the object's (a slot reused after a
//! removal) is ignored too.

use std::fs::{File, OpenOptions};
use std::os::unix::fs::OpenOptionsExt;
use std::os::unix::io::AsRawFd;
use std::path::{Path, PathBuf};

use nalgebra::Isometry3;

/// First bytes of a journal.
pub const MAGIC: [u8; 8] = *b"GJKDPOSE";
/// Journal layout version.
pub const VERSION: u32 = 1;
const HEADER: usize = 16;
/// Bytes per slot.
pub const SLOT: usize = 72;
const INITIAL_SLOTS: usize = 1024;

/// The journal path of a state file: `<state file>.poses`.
pub fn path_for(state_file: &Path) -> PathBuf {
    let mut p = state_file.as_os_str().to_owned();
    p.push(".poses");
    PathBuf::from(p)
}

fn words(id: u64, pose: &Isometry3<f64>) -> [u64; 9] {
    let t = pose.translation.vector;
    let q = pose.rotation.coords;
    let mut w = [
        id,
        t.x.to_bits(),
        t.y.to_bits(),
        t.z.to_bits(),
        q.x.to_bits(),
        q.y.to_bits(),
        q.z.to_bits(),
        q.w.to_bits(),
        0,
    ];
    w[8] = check(&w[..8]);
    w
}

/// A 64-bit mix of the slot's words; never 0 for a written slot, so that a
/// zeroed (never written) slot is invalid.
fn check(w: &[u64]) -> u64 {
    let mut h: u64 = 0x6A09_E667_F3BC_C908;
    for &x in w {
        h = (h ^ x).wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(29);
    }
    h | 1
}

/// An open, mapped journal.
#[derive(Debug)]
pub struct Journal {
    file: File,
    path: PathBuf,
    map: *mut u8,
    len: usize,
    dirty: bool,
}

// SAFETY: the mapping is owned by this value alone (no aliasing handles
// exist), like a Vec's buffer; moving it to another thread is fine.
unsafe impl Send for Journal {}

impl Journal {
    /// Opens (creating owner-only, 0600) the journal at `path`, keeping its
    /// content. A file that is not a journal of this version is started
    /// afresh: its poses are only a refinement of the state file's.
    ///
    /// # Errors
    /// When the file cannot be opened, sized or mapped.
    pub fn open(path: &Path) -> std::io::Result<Self> {
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .mode(0o600)
            .open(path)?;
        let current = file.metadata()?.len() as usize;
        let valid_header = current >= HEADER && {
            let mut head = [0u8; HEADER];
            std::os::unix::fs::FileExt::read_exact_at(&file, &mut head, 0)?;
            head[..8] == MAGIC && head[8..12] == VERSION.to_le_bytes()
        };
        if !valid_header {
            file.set_len(0)?;
        }
        let slots = current.saturating_sub(HEADER) / SLOT;
        let mut j = Journal {
            file,
            path: path.to_path_buf(),
            map: std::ptr::null_mut(),
            len: 0,
            dirty: false,
        };
        j.remap(slots.max(INITIAL_SLOTS))?;
        if !valid_header {
            let mut head = [0u8; HEADER];
            head[..8].copy_from_slice(&MAGIC);
            head[8..12].copy_from_slice(&VERSION.to_le_bytes());
            // SAFETY: the mapping is at least HEADER bytes long.
            unsafe { std::ptr::copy_nonoverlapping(head.as_ptr(), j.map, HEADER) };
        }
        Ok(j)
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn slots(&self) -> usize {
        (self.len - HEADER) / SLOT
    }

    fn remap(&mut self, slots: usize) -> std::io::Result<()> {
        let len = HEADER + slots * SLOT;
        if (self.file.metadata()?.len() as usize) < len {
            self.file.set_len(len as u64)?;
        }
        self.unmap();
        // SAFETY: a fresh shared mapping of `len` bytes of a file that is at
        // least that long; checked for failure below.
        let map = unsafe {
            libc::mmap(
                std::ptr::null_mut(),
                len,
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_SHARED,
                self.file.as_raw_fd(),
                0,
            )
        };
        if map == libc::MAP_FAILED {
            return Err(std::io::Error::last_os_error());
        }
        self.map = map.cast();
        self.len = len;
        Ok(())
    }

    fn unmap(&mut self) {
        if !self.map.is_null() {
            // SAFETY: `map` and `len` are those of our own live mapping.
            unsafe { libc::munmap(self.map.cast(), self.len) };
            self.map = std::ptr::null_mut();
            self.len = 0;
        }
    }

    /// Records `pose` as the pose of object `id` in `slot`, growing the file
    /// if needed.
    ///
    /// # Errors
    /// When the file cannot grow (the pose is then only in memory).
    pub fn write(&mut self, slot: u32, id: u64, pose: &Isometry3<f64>) -> std::io::Result<()> {
        let slot = slot as usize;
        if slot >= self.slots() {
            self.remap((self.slots() * 2).max(slot + 1))?;
        }
        let w = words(id, pose);
        let mut bytes = [0u8; SLOT];
        for (chunk, x) in bytes.chunks_exact_mut(8).zip(w) {
            chunk.copy_from_slice(&x.to_le_bytes());
        }
        // SAFETY: slot < slots(), so the SLOT bytes at this offset are inside
        // our mapping, which nothing else in this process aliases.
        unsafe {
            std::ptr::copy_nonoverlapping(bytes.as_ptr(), self.map.add(HEADER + slot * SLOT), SLOT);
        }
        self.dirty = true;
        Ok(())
    }

    /// Asks the kernel to write the mapping to disk if anything changed
    /// since the last call (which only matters for a machine crash).
    ///
    /// # Errors
    /// The `msync` error.
    pub fn sync(&mut self) -> std::io::Result<()> {
        if !self.dirty {
            return Ok(());
        }
        // SAFETY: our own live mapping.
        if unsafe { libc::msync(self.map.cast(), self.len, libc::MS_SYNC) } != 0 {
            return Err(std::io::Error::last_os_error());
        }
        self.dirty = false;
        Ok(())
    }

    /// The pose recorded for `id` in `slot`, if that slot holds a complete
    /// record of that object with a finite unit-quaternion pose.
    pub fn read(&self, slot: u32, id: u64) -> Option<Isometry3<f64>> {
        let slot = slot as usize;
        if slot >= self.slots() {
            return None;
        }
        let mut bytes = [0u8; SLOT];
        // SAFETY: inside our mapping, as in `write`.
        unsafe {
            std::ptr::copy_nonoverlapping(
                self.map.add(HEADER + slot * SLOT),
                bytes.as_mut_ptr(),
                SLOT,
            );
        }
        let mut w = [0u64; 9];
        for (x, chunk) in w.iter_mut().zip(bytes.chunks_exact(8)) {
            let mut b = [0u8; 8];
            b.copy_from_slice(chunk);
            *x = u64::from_le_bytes(b);
        }
        if w[0] != id || w[8] != check(&w[..8]) {
            return None;
        }
        let f = |i: usize| f64::from_bits(w[i]);
        let pose = crate::persist::StoredPose {
            translation: [f(1), f(2), f(3)],
            rotation: [f(4), f(5), f(6), f(7)],
        };
        pose.to_isometry()
    }
}

impl Drop for Journal {
    fn drop(&mut self) {
        let _ = self.sync();
        self.unmap();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn poses_survive_reopening_and_torn_or_foreign_slots_are_ignored() {
        let dir = std::env::temp_dir().join(format!("gjkd-journal-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("x.poses");
        let p = Isometry3::new(Vector3::new(1.0, 2.0, -3.0), Vector3::new(0.3, 0.2, 0.1));
        {
            let mut j = Journal::open(&path).expect("open");
            j.write(0, 11, &p).expect("write");
            // Past the initial size: the file grows.
            j.write(5000, 12, &p).expect("write");
            j.write(3, 13, &Isometry3::identity()).expect("write");
            // Dropped without sync on purpose: the page cache keeps it.
        }
        let j = Journal::open(&path).expect("reopen");
        assert_eq!(j.read(0, 11), Some(p), "bit for bit");
        assert_eq!(j.read(5000, 12), Some(p));
        assert_eq!(j.read(0, 12), None, "another object's slot");
        assert_eq!(j.read(1, 0), None, "never written");
        assert_eq!(j.read(1 << 30, 11), None, "out of range");
        // Tear slot 3: a byte of the pose changes without its check word.
        let mut bytes = std::fs::read(&path).expect("read");
        bytes[HEADER + 3 * SLOT + 20] ^= 0x40;
        drop(j);
        std::fs::write(&path, &bytes).expect("tear");
        let mut j = Journal::open(&path).expect("reopen");
        assert_eq!(j.read(3, 13), None, "torn slot");
        assert_eq!(j.read(0, 11), Some(p));
        j.sync().expect("sync");
        // A file that is not a journal starts afresh.
        drop(j);
        std::fs::write(&path, b"garbage").expect("spoil");
        let j = Journal::open(&path).expect("reopen");
        assert_eq!(j.read(0, 11), None);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
