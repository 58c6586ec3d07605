//! The storage under the database: redb's file backend with a hook that
//! makes writes fail (as on a full or failing disk) for the tests, and a
//! copy in memory that a file is checked on before anything writes to it.

use std::sync::Arc;
use std::sync::atomic::{AtomicI32, Ordering};

use redb::StorageBackend;

/// Test hook: makes the writes of one store fail (see
/// `Database::write_faults`).
#[derive(Clone, Debug)]
pub struct WriteFaults(pub(super) Arc<AtomicI32>);

impl WriteFaults {
    /// While `full` is set, every write to the file fails with `ENOSPC`,
    /// as on a full disk.
    pub fn simulate_full_disk(&self, full: bool) {
        self.fail_writes(if full { libc::ENOSPC } else { 0 });
    }

    /// While `errno` is not 0, every write to the file fails with that OS
    /// error.
    pub fn fail_writes(&self, errno: i32) {
        self.0.store(errno, Ordering::Release);
    }
}

/// redb's file backend, with writes that fail with the OS error of the
/// shared test hook while it is set (see `Database::fail_writes`).
#[derive(Debug)]
pub(super) struct Backend {
    pub(super) file: redb::backends::FileBackend,
    pub(super) fail_with: Arc<AtomicI32>,
}

impl Backend {
    fn check(&self) -> std::io::Result<()> {
        match self.fail_with.load(Ordering::Acquire) {
            0 => Ok(()),
            errno => Err(std::io::Error::from_raw_os_error(errno)),
        }
    }
}

impl StorageBackend for Backend {
    fn len(&self) -> std::io::Result<u64> {
        self.file.len()
    }
    fn read(&self, offset: u64, out: &mut [u8]) -> std::io::Result<()> {
        self.file.read(offset, out)
    }
    fn set_len(&self, len: u64) -> std::io::Result<()> {
        self.check()?;
        self.file.set_len(len)
    }
    fn sync_data(&self) -> std::io::Result<()> {
        self.check()?;
        self.file.sync_data()
    }
    fn write(&self, offset: u64, data: &[u8]) -> std::io::Result<()> {
        self.check()?;
        self.file.write(offset, data)
    }
    fn close(&self) -> std::io::Result<()> {
        self.file.close()
    }
}

/// A copy of the file in memory, for checking it without writing to it.
#[derive(Debug)]
pub(super) struct Copy(pub(super) std::sync::RwLock<Vec<u8>>);

impl Copy {
    fn bytes(&self) -> std::sync::RwLockReadGuard<'_, Vec<u8>> {
        self.0
            .read()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
    fn bytes_mut(&self) -> std::sync::RwLockWriteGuard<'_, Vec<u8>> {
        self.0
            .write()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

impl StorageBackend for Copy {
    fn len(&self) -> std::io::Result<u64> {
        Ok(self.bytes().len() as u64)
    }
    fn read(&self, offset: u64, out: &mut [u8]) -> std::io::Result<()> {
        let bytes = self.bytes();
        let start = usize::try_from(offset).map_err(std::io::Error::other)?;
        let src = bytes
            .get(start..start + out.len())
            .ok_or(std::io::ErrorKind::UnexpectedEof)?;
        out.copy_from_slice(src);
        Ok(())
    }
    fn set_len(&self, len: u64) -> std::io::Result<()> {
        let len = usize::try_from(len).map_err(std::io::Error::other)?;
        self.bytes_mut().resize(len, 0);
        Ok(())
    }
    fn sync_data(&self) -> std::io::Result<()> {
        Ok(())
    }
    fn write(&self, offset: u64, data: &[u8]) -> std::io::Result<()> {
        let start = usize::try_from(offset).map_err(std::io::Error::other)?;
        let mut bytes = self.bytes_mut();
        if bytes.len() < start + data.len() {
            bytes.resize(start + data.len(), 0);
        }
        bytes[start..start + data.len()].copy_from_slice(data);
        Ok(())
    }
}
