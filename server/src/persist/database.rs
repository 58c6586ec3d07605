//! The object store on disk: a [redb] database holding every registered
//! object, the id epoch and the id counter, so that objects survive a
//! server crash with their exact ids.
//!
//! # Layout
//!
//! Table `objects`: object id (`u64`) to a [`StoredObject`] encoded with
//! postcard. Table `meta`: `format` ([`FORMAT_VERSION`]), `epoch` (upper 32
//! bits of every id) and `next_index` (lower 32 bits of the next id; above
//! every id ever handed out, removed ones included, so ids are never
//! reused). Poses changed after a registration are in the pose journal
//! beside the database ([`crate::persist::journal`]), not here.
//!
//! # Writing
//!
//! A registration or removal is one write transaction, committed with
//! redb's immediate durability before the server acknowledges it: an
//! acknowledged change survives `kill -9` and a power cut alike. Every
//! commit is two-phase, so that a damaged newest commit is reported as
//! damage at the next start instead of being rolled back silently to the
//! one before (see [`Database::open`]). A commit that fails leaves redb
//! refusing every further transaction; the database is then reopened at the
//! next change, so a disk that had no room accepts changes again once it
//! has, without a restart.
//!
//! # Reading
//!
//! At start the file is opened (taking redb's exclusive file lock, which
//! keeps a second server off the same store), every page checksum is
//! verified, and every object is decoded and held to the checks of a
//! registration ([`Snapshot::validate`]). A file that fails any of this is
//! never loaded in part: it is renamed aside to `<file>.corrupt-<unix
//! seconds>` and the server starts with an empty store. A state file of the
//! format before this one (`GJKDOBJS`) is migrated ([`crate::persist::legacy`]).

use std::fs::{File, OpenOptions};
use std::io::Read;
use std::os::unix::fs::{DirBuilderExt, OpenOptionsExt};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};

use redb::{ReadableDatabase, ReadableTable, TableDefinition};
use tracing::{error, info, warn};

pub use super::backends::WriteFaults;
use super::backends::{Backend, Copy};
use crate::engine::records::{Snapshot, StoredObject};
use crate::engine::tokens::TokenKey;
use crate::persist::legacy;

/// Version of this layout, kept in the `meta` table; the `GJKDOBJS` state
/// file was version 1.
pub const FORMAT_VERSION: u64 = 2;

const OBJECTS: TableDefinition<u64, &[u8]> = TableDefinition::new("objects");
const META: TableDefinition<&str, u64> = TableDefinition::new("meta");
/// Registration tokens ([`crate::engine::tokens`]): (owner, token) to object id.
/// Added within format 2: a store without it has no tokens, and a server
/// before it leaves the table alone.
const TOKENS: TableDefinition<(u128, u64), u64> = TableDefinition::new("tokens");
const FORMAT: &str = "format";
const EPOCH: &str = "epoch";
const NEXT_INDEX: &str = "next_index";

/// redb's page cache. The objects live in memory anyway; the cache only
/// serves the writes and the read at start.
const CACHE_BYTES: usize = 16 << 20;

/// Why the store could not be opened, read or written.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// A file operation failed.
    #[error("{what} {path}: {source}")]
    Io {
        /// What was being done.
        what: &'static str,
        /// On which path.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Another process holds the store's lock.
    #[error(
        "{0} is in use by another gjkd server or tool (its lock is held): stop it first, or give another --state-file"
    )]
    InUse(PathBuf),
    /// redb refused an operation.
    #[error("{what} {path}: {reason}")]
    Database {
        /// What was being done.
        what: &'static str,
        /// The database file.
        path: PathBuf,
        /// redb's error.
        reason: String,
    },
    /// The disk has no room for the change.
    #[error("no room on the disk of {0} for the change")]
    Full(PathBuf),
}

fn io(what: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> StoreError {
    let path = path.to_path_buf();
    move |source| StoreError::Io { what, path, source }
}

/// What is wrong with a damaged file (which is set aside, unlike the
/// errors of [`StoreError`], which stop the server).
type Damage = String;

/// The open object store.
#[derive(Debug)]
pub struct Database {
    path: PathBuf,
    /// `None` after a commit failed: redb then refuses every transaction, so
    /// the next change reopens the file first.
    db: Option<redb::Database>,
    /// Test hook shared with the storage backend: while not 0, every write
    /// fails with this OS error.
    fail_with: Arc<AtomicI32>,
}

/// What [`Database::open`] found.
#[derive(Debug)]
pub struct Opened {
    /// The objects and the id counter to start with.
    pub snapshot: Snapshot,
    /// Whether the store was created now (no file, an empty one, or one set
    /// aside): the caller's epoch was used.
    pub fresh: bool,
    /// Files renamed aside because they were damaged, or migrated.
    pub set_aside: Vec<PathBuf>,
}

impl Database {
    /// Opens the store at `path`, creating it (and its directory,
    /// owner-only) if missing, migrating a state file of the old format,
    /// and setting aside a damaged one; a fresh store gets `epoch`.
    ///
    /// The file is checked before anything is written to it: redb repairs
    /// a file left by a crash as it opens it, and would write into a
    /// damaged file too, so the check runs on a copy in memory first (which
    /// costs the file's size in memory for the time of the check).
    ///
    /// # Errors
    /// When the directory or file cannot be created or read at all, when
    /// another process holds the lock ([`StoreError::InUse`]), or when a
    /// damaged file cannot be moved aside: starting without it would risk
    /// overwriting it.
    pub fn open(path: impl Into<PathBuf>, epoch: u32) -> Result<(Self, Opened), StoreError> {
        let path = path.into();
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::DirBuilder::new()
                .recursive(true)
                .mode(0o700)
                .create(dir)
                .map_err(io("cannot create directory", dir))?;
        }
        let mut set_aside = Vec::new();
        let migrated = migrate_if_legacy(&path, &mut set_aside)?;
        let fail_with = Arc::new(AtomicI32::new(0));
        let mut file = open_locked(&path)?;
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes)
            .map_err(io("cannot read", &path))?;
        let stored = match verify(bytes) {
            Ok(stored) => stored,
            Err(reason) => {
                let lost = std::fs::read(&path).ok().and_then(readable_ids);
                let moved_to = set_aside_file(&path, &reason)?;
                let (count, ids) = match &lost {
                    Some(ids) => (
                        ids.len().to_string(),
                        ids.iter().take(32).map(|id| format!("{id:#x}")).collect(),
                    ),
                    None => ("unknown".to_owned(), Vec::new()),
                };
                error!(
                    file = %path.display(),
                    moved_to = %moved_to.display(),
                    lost_objects = %count,
                    lost_ids = ?ids,
                    "the object store is damaged ({reason}): set aside as it was, starting with no objects; the objects it held (as far as it can be read) are lost to this server"
                );
                set_aside.push(moved_to);
                drop(file);
                file = open_locked(&path)?;
                None
            }
        };
        let mut db = Database {
            db: Some(open_redb(&path, file, &fail_with)?),
            path,
            fail_with,
        };
        let (snapshot, fresh) = match (stored, migrated) {
            (_, Some(old)) => {
                db.sync(&old)?;
                (old, false)
            }
            (Some(s), None) => (s, false),
            (None, None) => {
                let s = Snapshot {
                    epoch: epoch.max(1),
                    next_index: 1,
                    objects: Vec::new(),
                };
                db.sync(&s)?;
                (s, true)
            }
        };
        move_leftover_log(&db.path, &mut set_aside);
        Ok((
            db,
            Opened {
                snapshot,
                fresh,
                set_aside,
            },
        ))
    }

    /// The database file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The open database, reopened if a failed commit closed it.
    fn live(&mut self) -> Result<&redb::Database, StoreError> {
        if self.db.is_none() {
            let file = open_locked(&self.path)?;
            self.db = Some(open_redb(&self.path, file, &self.fail_with)?);
            warn!(file = %self.path.display(), "object store reopened after a failed write");
        }
        self.db.as_ref().ok_or_else(|| StoreError::Database {
            what: "cannot open",
            path: self.path.clone(),
            reason: "not open".into(),
        })
    }

    /// Runs `change` in one write transaction and commits it durably.
    fn write(
        &mut self,
        change: impl FnOnce(&redb::WriteTransaction) -> Result<bool, redb::Error>,
    ) -> Result<(), StoreError> {
        let path = self.path.clone();
        let fail = |what: &'static str, e: redb::Error| match &e {
            redb::Error::Io(io) if io.raw_os_error() == Some(libc::ENOSPC) => {
                StoreError::Full(path.clone())
            }
            _ => StoreError::Database {
                what,
                path: path.clone(),
                reason: e.to_string(),
            },
        };
        let db = self.live()?;
        let result = (|| {
            let mut tx = db
                .begin_write()
                .map_err(|e| fail("cannot begin", e.into()))?;
            tx.set_two_phase_commit(true);
            if change(&tx).map_err(|e| fail("cannot write", e))? {
                tx.commit().map_err(|e| fail("cannot commit", e.into()))
            } else {
                tx.abort().map_err(|e| fail("cannot abort", e.into()))
            }
        })();
        if result.is_err() {
            // After a failed write redb refuses every further transaction.
            self.db = None;
        }
        result
    }

    /// Stores a registered object with the id counter after it, and its
    /// registration token (`token`, with the token it pushes out), durably:
    /// all in one transaction, so a retry after a crash finds the object.
    ///
    /// # Errors
    /// When the transaction cannot be committed; nothing of it is stored.
    pub fn register(
        &mut self,
        object: &StoredObject,
        next_index: u32,
        token: Option<(TokenKey, Option<TokenKey>)>,
    ) -> Result<(), StoreError> {
        let bytes = postcard::to_stdvec(object).map_err(|e| StoreError::Database {
            what: "cannot encode an object for",
            path: self.path.clone(),
            reason: e.to_string(),
        })?;
        self.write(|tx| {
            tx.open_table(OBJECTS)?
                .insert(object.id, bytes.as_slice())?;
            tx.open_table(META)?
                .insert(NEXT_INDEX, u64::from(next_index))?;
            if let Some((key, pushed_out)) = token {
                let mut tokens = tx.open_table(TOKENS)?;
                tokens.insert(key, object.id)?;
                if let Some(old) = pushed_out {
                    tokens.remove(old)?;
                }
            }
            Ok(true)
        })
    }

    /// Every registration token stored, with its object's id.
    ///
    /// # Errors
    /// When the table cannot be read.
    pub fn tokens(&mut self) -> Result<Vec<(TokenKey, u64)>, StoreError> {
        let path = self.path.clone();
        let fail = |e: &dyn std::fmt::Display| StoreError::Database {
            what: "cannot read the registration tokens of",
            path: path.clone(),
            reason: e.to_string(),
        };
        let tx = self.live()?.begin_read().map_err(|e| fail(&e))?;
        let table = match tx.open_table(TOKENS) {
            Ok(t) => t,
            Err(redb::TableError::TableDoesNotExist(_)) => return Ok(Vec::new()),
            Err(e) => return Err(fail(&e)),
        };
        let mut out = Vec::new();
        for entry in table.iter().map_err(|e| fail(&e))? {
            let (k, v) = entry.map_err(|e| fail(&e))?;
            out.push((k.value(), v.value()));
        }
        Ok(out)
    }

    /// Removes the objects `ids`, and the registration tokens `tokens` of
    /// theirs, in one durable transaction.
    ///
    /// # Errors
    /// When the transaction cannot be committed; then none is removed.
    pub fn remove(&mut self, ids: &[u64], tokens: &[TokenKey]) -> Result<(), StoreError> {
        self.write(|tx| {
            let mut table = tx.open_table(OBJECTS)?;
            for id in ids {
                table.remove(id)?;
            }
            if !tokens.is_empty() {
                let mut table = tx.open_table(TOKENS)?;
                for key in tokens {
                    table.remove(key)?;
                }
            }
            Ok(true)
        })
    }

    /// Makes the store hold exactly `snapshot` (objects, epoch, counter), in
    /// one durable transaction that writes only what differs; nothing at
    /// all when nothing does.
    ///
    /// # Errors
    /// When the transaction cannot be committed; the store is then as it was.
    pub fn sync(&mut self, snapshot: &Snapshot) -> Result<(), StoreError> {
        let mut encoded = Vec::with_capacity(snapshot.objects.len());
        for o in &snapshot.objects {
            let bytes = postcard::to_stdvec(o).map_err(|e| StoreError::Database {
                what: "cannot encode an object for",
                path: self.path.clone(),
                reason: e.to_string(),
            })?;
            encoded.push((o.id, bytes));
        }
        self.write(|tx| {
            let mut changed = false;
            let mut meta = tx.open_table(META)?;
            for (key, value) in [
                (FORMAT, FORMAT_VERSION),
                (EPOCH, u64::from(snapshot.epoch)),
                (NEXT_INDEX, u64::from(snapshot.next_index)),
            ] {
                if meta.get(key)?.map(|v| v.value()) != Some(value) {
                    meta.insert(key, value)?;
                    changed = true;
                }
            }
            let mut table = tx.open_table(OBJECTS)?;
            let keep: std::collections::HashSet<u64> = encoded.iter().map(|(id, _)| *id).collect();
            let stale: Vec<u64> = table
                .iter()?
                .map(|entry| entry.map(|(k, _)| k.value()))
                .filter(|id| id.as_ref().map_or(true, |id| !keep.contains(id)))
                .collect::<Result<_, _>>()?;
            for id in &stale {
                table.remove(id)?;
                changed = true;
            }
            for (id, bytes) in &encoded {
                if table.get(id)?.map(|v| v.value() != bytes.as_slice()) != Some(false) {
                    table.insert(id, bytes.as_slice())?;
                    changed = true;
                }
            }
            Ok(changed)
        })
    }

    /// Test hook: a handle on this store's writes, which can make them
    /// fail as on a full or failing disk while the store is in use.
    pub fn write_faults(&self) -> WriteFaults {
        WriteFaults(Arc::clone(&self.fail_with))
    }

    /// Test hook: while `full` is set, every write to the file fails with
    /// `ENOSPC`, as on a full disk.
    pub fn simulate_full_disk(&self, full: bool) {
        self.write_faults().simulate_full_disk(full);
    }

    /// Test hook: while `errno` is not 0, every write to the file fails
    /// with that OS error.
    pub fn fail_writes(&self, errno: i32) {
        self.write_faults().fail_writes(errno);
    }
}

/// The file at `path` (created 0600 if missing), locked for this process
/// alone: redb's lock, taken here before the file is read.
fn open_locked(path: &Path) -> Result<File, StoreError> {
    let file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .mode(0o600)
        .open(path)
        .map_err(io("cannot open", path))?;
    match file.try_lock() {
        Ok(()) => Ok(file),
        Err(std::fs::TryLockError::WouldBlock) => Err(StoreError::InUse(path.to_path_buf())),
        Err(std::fs::TryLockError::Error(e)) => Err(io("cannot lock", path)(e)),
    }
}

/// The content of a store file, checked on a copy in memory: every page
/// checksum, every object decoded and validated. `None` for a file with no
/// content yet (new or empty).
fn verify(bytes: Vec<u8>) -> Result<Option<Snapshot>, Damage> {
    // redb repairs a file left by a crash by itself; that is only the
    // rebuilding of its free-page list, unless the newest commit fails its
    // checksum, when it would fall back to the commit before and so lose an
    // acknowledged change without a word. Every commit here is two-phase,
    // so that cannot follow from a crash: it is damage, refused here.
    let rolled_back = Arc::new(AtomicBool::new(false));
    let seen = Arc::clone(&rolled_back);
    let mut builder = redb::Builder::new();
    builder.set_cache_size(CACHE_BYTES);
    builder.set_repair_callback(move |session| {
        if (0.25..0.5).contains(&session.progress()) {
            seen.store(true, Ordering::Release);
            session.abort();
        }
    });
    let copy = Copy(std::sync::RwLock::new(bytes));
    // redb asserts on some malformed files rather than returning an error;
    // on a copy, a panic is just another sign of damage.
    let checked = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let mut db = builder
            .create_with_backend(copy)
            .map_err(|e| e.to_string())?;
        db.check_integrity().map_err(|e| e.to_string())?;
        read_all(&db)
    }));
    match checked {
        _ if rolled_back.load(Ordering::Acquire) => {
            Err("its newest commit fails its checksum".into())
        }
        Ok(result) => result,
        Err(_) => Err("redb cannot read it (it panicked)".into()),
    }
}

/// The ids of the objects a damaged store file still shows, read from a
/// copy in memory as far as redb can read it; `None` when it cannot.
fn readable_ids(bytes: Vec<u8>) -> Option<Vec<u64>> {
    let copy = Copy(std::sync::RwLock::new(bytes));
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let db = redb::Builder::new()
            .set_cache_size(CACHE_BYTES)
            .create_with_backend(copy)
            .ok()?;
        let tx = db.begin_read().ok()?;
        let table = tx.open_table(OBJECTS).ok()?;
        let ids: Vec<u64> = table
            .iter()
            .ok()?
            .map_while(|entry| entry.ok().map(|(k, _)| k.value()))
            .collect();
        Some(ids)
    }))
    .ok()
    .flatten()
}

/// redb on `file` (locked by [`open_locked`], content already verified).
fn open_redb(
    path: &Path,
    file: File,
    fail_with: &Arc<AtomicI32>,
) -> Result<redb::Database, StoreError> {
    let fail = |e: redb::DatabaseError| match e {
        redb::DatabaseError::DatabaseAlreadyOpen => StoreError::InUse(path.to_path_buf()),
        // Reopening after a crash or a failed commit writes (redb's repair).
        redb::DatabaseError::Storage(redb::StorageError::Io(io))
            if io.raw_os_error() == Some(libc::ENOSPC) =>
        {
            StoreError::Full(path.to_path_buf())
        }
        e => StoreError::Database {
            what: "cannot open",
            path: path.to_path_buf(),
            reason: e.to_string(),
        },
    };
    let backend = Backend {
        file: redb::backends::FileBackend::new(file).map_err(fail)?,
        fail_with: Arc::clone(fail_with),
    };
    let mut builder = redb::Builder::new();
    builder.set_cache_size(CACHE_BYTES);
    builder.create_with_backend(backend).map_err(fail)
}

/// Every object and the counter; `None` for a database never written to.
fn read_all(db: &redb::Database) -> Result<Option<Snapshot>, Damage> {
    let damaged = |e: &dyn std::fmt::Display| e.to_string();
    let tx = db.begin_read().map_err(|e| damaged(&e))?;
    let meta = match tx.open_table(META) {
        Ok(t) => t,
        Err(redb::TableError::TableDoesNotExist(_)) => return Ok(None),
        Err(e) => return Err(damaged(&e)),
    };
    let get = |key: &str| -> Result<u64, Damage> {
        meta.get(key)
            .map_err(|e| damaged(&e))?
            .map(|v| v.value())
            .ok_or_else(|| format!("no {key} in the meta table"))
    };
    let format = get(FORMAT)?;
    if format != FORMAT_VERSION {
        return Err(format!(
            "format version {format}, this server reads version {FORMAT_VERSION}"
        ));
    }
    let (epoch, next_index) = (get(EPOCH)?, get(NEXT_INDEX)?);
    let (Ok(epoch), Ok(next_index)) = (u32::try_from(epoch), u32::try_from(next_index)) else {
        return Err(format!(
            "epoch {epoch:#x} or counter {next_index:#x} out of range"
        ));
    };
    let mut objects = Vec::new();
    let table = tx.open_table(OBJECTS).map_err(|e| damaged(&e))?;
    for entry in table.iter().map_err(|e| damaged(&e))? {
        let (key, value) = entry.map_err(|e| damaged(&e))?;
        let object: StoredObject = match postcard::take_from_bytes(value.value()) {
            Ok((o, [])) => o,
            Ok(_) => return Err(format!("bytes after object {:#x}", key.value())),
            Err(e) => {
                return Err(format!("object {:#x} does not decode: {e}", key.value()));
            }
        };
        if object.id != key.value() {
            return Err(format!(
                "object {:#x} stored under key {:#x}",
                object.id,
                key.value()
            ));
        }
        objects.push(object);
    }
    let snapshot = Snapshot {
        epoch,
        next_index,
        objects,
    };
    snapshot.validate()?;
    Ok(Some(snapshot))
}

/// When `path` is a state file of the old format: its objects (with its
/// change log replayed), after the old files have been kept aside; the
/// database is then written from them by the caller. A damaged old state
/// file is set aside like a damaged database (the store starts empty).
fn migrate_if_legacy(
    path: &Path,
    set_aside: &mut Vec<PathBuf>,
) -> Result<Option<Snapshot>, StoreError> {
    let mut head = [0u8; 8];
    match File::open(path).and_then(|mut f| f.read_exact(&mut head)) {
        Ok(()) if legacy::is_legacy(&head) => {}
        _ => return Ok(None),
    }
    // The old server's lock: an old server still running on this file
    // must not see it replaced.
    let _old_lock = take_old_lock(path)?;
    let bytes = std::fs::read(path).map_err(io("cannot read", path))?;
    let log_path = legacy::log_path_for(path);
    let log = match std::fs::read(&log_path) {
        Ok(b) => Some(b),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
        Err(e) => return Err(io("cannot read", &log_path)(e)),
    };
    let mut snapshot = match legacy::decode_snapshot(&bytes) {
        Ok(s) => s,
        Err(reason) => {
            let moved_to = set_aside_file(path, &reason)?;
            error!(
                file = %path.display(),
                moved_to = %moved_to.display(),
                "state file of the old format is damaged ({reason}): set aside, starting with no objects"
            );
            set_aside.push(moved_to);
            if log.is_some() {
                set_aside.push(set_aside_file(&log_path, &"its state file was damaged")?);
            }
            return Ok(None);
        }
    };
    if let Some(log) = &log {
        let replay = legacy::replay_log(&mut snapshot, log);
        if let Some(e) = &replay.error {
            error!(
                file = %log_path.display(),
                kept = replay.applied,
                "old change log is damaged ({e}): the records after the damage are lost"
            );
        } else if replay.torn > 0 {
            warn!(
                file = %log_path.display(),
                bytes = replay.torn,
                "old change log ends in an incomplete record, dropped: an append cut short by a crash (never acknowledged) or a log cut short by damage (then the records after the cut are lost)"
            );
        }
    }
    // Kept under another name before the database takes the path, so that
    // a crash in between finds the old file again and migrates anew.
    let kept = aside_name(path, "migrated-v1");
    std::fs::hard_link(path, &kept).map_err(io("cannot keep the old state file as", &kept))?;
    std::fs::remove_file(path).map_err(io("cannot remove the migrated", path))?;
    info!(
        file = %path.display(),
        objects = snapshot.objects.len(),
        old_file = %kept.display(),
        "state file of the old format migrated into the database; the old file is kept"
    );
    set_aside.push(kept);
    Ok(Some(snapshot))
}

/// An old change log beside the database: its records are in the database
/// (it was replayed by the migration), so it is only moved out of the way.
fn move_leftover_log(path: &Path, set_aside: &mut Vec<PathBuf>) {
    let log = legacy::log_path_for(path);
    if log.exists() {
        let kept = aside_name(&log, "migrated-v1");
        match std::fs::rename(&log, &kept) {
            Ok(()) => set_aside.push(kept),
            Err(e) => {
                warn!(file = %log.display(), "cannot move the migrated change log aside: {e}")
            }
        }
    }
}

fn take_old_lock(path: &Path) -> Result<File, StoreError> {
    let mut lock_path = path.as_os_str().to_owned();
    lock_path.push(".lock");
    let lock_path = PathBuf::from(lock_path);
    let lock = OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(false)
        .mode(0o600)
        .open(&lock_path)
        .map_err(io("cannot open the lock file", &lock_path))?;
    match lock.try_lock() {
        Ok(()) => Ok(lock),
        Err(std::fs::TryLockError::WouldBlock) => Err(StoreError::InUse(path.to_path_buf())),
        Err(std::fs::TryLockError::Error(e)) => Err(io("cannot lock", &lock_path)(e)),
    }
}

/// `<file>.<tag>-<unix seconds>`, with a suffix if that exists already.
pub(crate) fn aside_name(path: &Path, tag: &str) -> PathBuf {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    (0..)
        .map(|n| {
            let mut a = path.as_os_str().to_owned();
            a.push(format!(".{tag}-{secs}"));
            if n > 0 {
                a.push(format!(".{n}"));
            }
            PathBuf::from(a)
        })
        .find(|a| !a.exists())
        .unwrap_or_else(|| path.with_extension(tag))
}

/// Renames a damaged file to `<file>.corrupt-<unix seconds>`, never over an
/// earlier one.
///
/// # Errors
/// When it cannot be moved: starting without it would overwrite it, so the
/// server refuses to start instead.
fn set_aside_file(path: &Path, reason: &dyn std::fmt::Display) -> Result<PathBuf, StoreError> {
    let aside = aside_name(path, "corrupt");
    std::fs::rename(path, &aside).map_err(|e| StoreError::Io {
        what: "cannot set aside the damaged file",
        path: path.to_path_buf(),
        source: std::io::Error::new(e.kind(), format!("{reason}; rename failed: {e}")),
    })?;
    Ok(aside)
}

#[cfg(test)]
mod tests;
