//! The database and the pose journal as the engine's
//! [`Durability`], and the opening of a persisting server's store.

use std::path::{Path, PathBuf};

use gjkd_proto::WaitMode;
use nalgebra::Isometry3;

use super::database::{Database, StoreError};
use super::journal::{self, Journal};
use crate::engine::durability::{CommitError, Durability};
use crate::engine::records::{Snapshot, StoredObject};
use crate::engine::state::{Limits, State};
use crate::engine::tokens::TokenKey;

/// The database with the pose journal beside it.
#[derive(Debug)]
struct Disk {
    database: Database,
    journal: Journal,
}

impl From<StoreError> for CommitError {
    fn from(e: StoreError) -> Self {
        match e {
            StoreError::Full(_) => CommitError::Full(Box::new(e)),
            _ => CommitError::Failed(Box::new(e)),
        }
    }
}

impl Durability for Disk {
    fn register(
        &mut self,
        object: &StoredObject,
        next_index: u32,
        token: Option<(TokenKey, Option<TokenKey>)>,
    ) -> Result<(), CommitError> {
        Ok(self.database.register(object, next_index, token)?)
    }

    fn remove(&mut self, ids: &[u64], tokens: &[TokenKey]) -> Result<(), CommitError> {
        Ok(self.database.remove(ids, tokens)?)
    }

    fn sync(&mut self, snapshot: &Snapshot) -> Result<(), CommitError> {
        Ok(self.database.sync(snapshot)?)
    }

    fn write_pose(&mut self, slot: u32, id: u64, pose: &Isometry3<f64>) -> std::io::Result<()> {
        self.journal.write(slot, id, pose)
    }

    fn flush_poses(&mut self) -> std::io::Result<()> {
        self.journal.sync()
    }
}

/// Turns persistence on for `state`: from now on every registration and
/// removal is committed to `database` before it is acknowledged, and every
/// pose update goes to the pose journal next to it. Poses the journal holds
/// for the objects already there (restored from the database) replace
/// theirs: they are the latest ones before a crash.
///
/// An object whose journal slot does not hold a whole record of it (the
/// journal damaged or cut short, or its last update torn by a crash) keeps
/// the pose stored with it in the database, the pose of its registration or
/// of the last clean shutdown, which may be older than its last update:
/// such objects are logged at ERROR by id, with a copy of the journal as it
/// was found, and returned.
///
/// # Errors
/// When the journal cannot be opened; persistence stays off then.
pub fn attach(state: &mut State, mut database: Database) -> Result<Vec<u64>, StoreError> {
    let path = journal::path_for(database.path());
    // As found, before opening grows it: kept if it proves damaged.
    let found = std::fs::read(&path).unwrap_or_default();
    let journal = Journal::open(&path).map_err(|source| StoreError::Io {
        what: "cannot open the pose journal",
        path: path.clone(),
        source,
    })?;
    let unverified = state.recover_poses(|slot, id| journal.read(slot, id));
    if !unverified.is_empty() {
        report_unverified_poses(&path, &found, &unverified);
    }
    let tokens = match database.tokens() {
        Ok(entries) => entries,
        // Without its tokens the store still serves; only a retry of a
        // registration from before the restart could store a second
        // object.
        Err(e) => {
            tracing::error!("{e}: registrations from before the restart cannot be retried");
            Vec::new()
        }
    };
    state.set_durability(Box::new(Disk { database, journal }), tokens);
    Ok(unverified)
}

/// The state of a persisting server: the objects stored at `path`
/// (migrated from the old format, or none when the file is new or was
/// damaged and set aside, see [`Database::open`]), with persistence on.
/// A fresh store gets `epoch`.
///
/// # Errors
/// What keeps the server from starting: the store in use by another
/// process, unreadable, or holding more objects than `limits` allow.
pub fn open_state(
    limits: Limits,
    wait: WaitMode,
    path: &Path,
    epoch: u32,
) -> Result<State, String> {
    let (database, opened) = Database::open(path, epoch).map_err(|e| e.to_string())?;
    let mut state = State::restore(limits, wait, &opened.snapshot).map_err(|e| {
        format!(
            "cannot restore {} ({e}); raise the limits or move the file away",
            path.display()
        )
    })?;
    if opened.fresh {
        tracing::info!(file = %path.display(), "new object store");
    } else {
        tracing::info!(file = %path.display(), objects = state.len(), "objects restored");
    }
    attach(&mut state, database).map_err(|e| e.to_string())?;
    Ok(state)
}

/// Logs the objects whose pose the journal at `path` could not verify, after
/// keeping a copy of the journal as it was `found` (it is rewritten next).
fn report_unverified_poses(path: &std::path::Path, found: &[u8], ids: &[u64]) {
    let kept = super::database::aside_name(path, "corrupt");
    let write = |kept: &std::path::Path| {
        use std::io::Write;
        use std::os::unix::fs::OpenOptionsExt;
        std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .mode(0o600)
            .open(kept)?
            .write_all(found)
    };
    let kept = match write(&kept) {
        Ok(()) => kept.display().to_string(),
        Err(e) => format!("(no copy: {e})"),
    };
    let first: Vec<String> = ids.iter().take(32).map(|id| format!("{id:#x}")).collect();
    tracing::error!(
        file = %path.display(),
        kept_as = %kept,
        objects = ids.len(),
        ids = ?first,
        "the pose journal holds no verifiable pose for these objects (damaged, cut short, or an update torn by a crash): they are served at the pose stored with them in the database, as of their registration or the last clean shutdown"
    );
}

/// The default store file of `service`:
/// `${XDG_STATE_HOME:-$HOME/.local/state}/gjkd/<service>.objects`, with `/`
/// in the service name replaced by `_`. `None` when neither variable is set.
pub fn default_path(service: &str) -> Option<PathBuf> {
    let base = std::env::var_os("XDG_STATE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| {
            std::env::var_os("HOME")
                .filter(|v| !v.is_empty())
                .map(|h| PathBuf::from(h).join(".local").join("state"))
        })?;
    let file: String = service
        .chars()
        .map(|c| if c == '/' || c == '\0' { '_' } else { c })
        .collect();
    Some(base.join("gjkd").join(format!("{file}.objects")))
}
