//! The pose journal: the latest stored pose of every object, in a
//! memory-mapped file next to the object store (`<store file>.poses`).
//!
//! Pose updates are the hot path (one per object per control cycle), far too
//! frequent for a committed transaction each. A store into a
//! shared file mapping costs a few nanoseconds and lands in the kernel's page
//! cache, which outlives the process: after `kill -9` (or a panic, or an
//! abort) the restarted server finds every pose that was acknowledged. Only
//! a crash of the whole machine can lose poses written since the last
//! `msync` (done at housekeeping, every few seconds while poses change); the
//! objects themselves are on disk regardless (the database, committed before
//! each acknowledgement, see `crate::persist::database`).
//!
//! # Layout (version 1)
//!
//! A 16-byte header (`b"GJKDPOSE"`, version `u32` LE, 4 zero bytes), then
//! one 72-byte slot per object: the object id, the seven pose components
//! (`[x, y, z, i, j, k, w]`) and a check word, all `u64` little-endian. The
//! check word is a hash of the other eight, so a slot torn by a kill in the
//! middle of its update reads as invalid and the pose stored with the object
//! is used instead. A slot whose id is not the object's (a slot reused after a
//! removal) is ignored too.

use std::fs::{File, OpenOptions};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};

use memmap2::MmapMut;
use nalgebra::Isometry3;

/// First bytes of a journal.
pub const MAGIC: [u8; 8] = *b"GJKDPOSE";
/// Journal layout version.
pub const VERSION: u32 = 1;
const HEADER: usize = 16;
/// Bytes per slot.
pub const SLOT: usize = 72;
const INITIAL_SLOTS: usize = 1024;

/// The journal path of a store file: `<store file>.poses`.
pub fn path_for(store_file: &Path) -> PathBuf {
    let mut p = store_file.as_os_str().to_owned();
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
    map: MmapMut,
    dirty: bool,
}

impl Journal {
    /// Opens (creating owner-only, 0600) the journal at `path`, keeping its
    /// content. A file that is not a journal of this version is copied
    /// aside (`<file>.corrupt-<unix seconds>`) and started afresh: its poses
    /// are only a refinement of the stored ones.
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
            if current > 0 {
                // Kept as found before it is started afresh; the objects it
                // held poses for are reported by the store.
                let kept = crate::persist::database::aside_name(path, "corrupt");
                std::fs::copy(path, &kept)?;
                tracing::error!(
                    file = %path.display(),
                    kept_as = %kept.display(),
                    "the pose journal is not a journal of this version: kept aside, started afresh"
                );
            }
            file.set_len(0)?;
        }
        let slots = current.saturating_sub(HEADER) / SLOT;
        let map = map(&file, slots.max(INITIAL_SLOTS))?;
        let mut j = Journal {
            file,
            path: path.to_path_buf(),
            map,
            dirty: false,
        };
        if !valid_header {
            j.map[..8].copy_from_slice(&MAGIC);
            j.map[8..12].copy_from_slice(&VERSION.to_le_bytes());
        }
        Ok(j)
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn slots(&self) -> usize {
        (self.map.len() - HEADER) / SLOT
    }

    /// Records `pose` as the pose of object `id` in `slot`, growing the file
    /// if needed.
    ///
    /// # Errors
    /// When the file cannot grow (the pose is then only in memory).
    pub fn write(&mut self, slot: u32, id: u64, pose: &Isometry3<f64>) -> std::io::Result<()> {
        let slot = slot as usize;
        if slot >= self.slots() {
            // The old mapping stays valid until the new one is in place, so
            // a failure to grow leaves the journal as it was.
            self.map = map(&self.file, (self.slots() * 2).max(slot + 1))?;
        }
        let start = HEADER + slot * SLOT;
        let out = &mut self.map[start..start + SLOT];
        for (chunk, x) in out.chunks_exact_mut(8).zip(words(id, pose)) {
            chunk.copy_from_slice(&x.to_le_bytes());
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
        self.map.flush()?;
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
        let start = HEADER + slot * SLOT;
        let mut w = [0u64; 9];
        for (x, chunk) in w
            .iter_mut()
            .zip(self.map[start..start + SLOT].chunks_exact(8))
        {
            *x = u64::from_le_bytes(chunk.try_into().unwrap_or_default());
        }
        if w[0] != id || w[8] != check(&w[..8]) {
            return None;
        }
        let f = |i: usize| f64::from_bits(w[i]);
        let pose = crate::engine::records::StoredPose {
            translation: [f(1), f(2), f(3)],
            rotation: [f(4), f(5), f(6), f(7)],
        };
        pose.to_isometry()
    }
}

/// A shared writable mapping of the first `slots` slots of `file`, grown to
/// hold them if shorter.
fn map(file: &File, slots: usize) -> std::io::Result<MmapMut> {
    let len = HEADER + slots * SLOT;
    if (file.metadata()?.len() as usize) < len {
        allocate(file, len)?;
    }
    // SAFETY: the file is ours (0600, under the store's lock, which keeps a
    // second server away) and never truncated while mapped, so the mapping
    // cannot lose its pages under us; every access goes through the slice
    // bounds of `MmapMut`.
    unsafe { memmap2::MmapOptions::new().len(len).map_mut(file) }
}

/// Grows `file` to `len` bytes with its disk blocks allocated: a store into
/// a mapped page that has no block yet would kill the process (`SIGBUS`) on
/// a full disk, where this fails with `ENOSPC` instead.
fn allocate(file: &File, len: usize) -> std::io::Result<()> {
    use std::os::unix::io::AsRawFd;
    let len = libc::off_t::try_from(len).map_err(std::io::Error::other)?;
    // SAFETY: posix_fallocate(3) on a descriptor we own.
    match unsafe { libc::posix_fallocate(file.as_raw_fd(), 0, len) } {
        0 => Ok(()),
        // A file system without fallocate: grow it sparse.
        libc::EOPNOTSUPP | libc::EINVAL => file.set_len(len as u64),
        errno => Err(std::io::Error::from_raw_os_error(errno)),
    }
}

impl Drop for Journal {
    fn drop(&mut self) {
        let _ = self.sync();
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
        // A file that is not a journal starts afresh, kept aside first.
        drop(j);
        std::fs::write(&path, b"garbage").expect("spoil");
        let j = Journal::open(&path).expect("reopen");
        assert_eq!(j.read(0, 11), None);
        let kept: Vec<_> = std::fs::read_dir(&dir)
            .expect("list")
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(".corrupt-"))
            .collect();
        assert_eq!(kept.len(), 1);
        assert_eq!(std::fs::read(kept[0].path()).expect("kept"), b"garbage");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
