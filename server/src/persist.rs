//! Persistence of registered objects: the state file and its change log,
//! which let objects survive a server crash with their exact ids.
//!
//! # Format
//!
//! ## State file (version 1)
//!
//! | bytes | content |
//! |---|---|
//! | 0..8 | magic `b"GJKDOBJS"` |
//! | 8..12 | format version, `u32` little-endian ([`FORMAT_VERSION`]) |
//! | 12..20 | payload length in bytes, `u64` little-endian |
//! | 20..24 | CRC-32 (IEEE) of the payload, `u32` little-endian |
//! | 24.. | payload: a [`Snapshot`] encoded with postcard |
//!
//! The file must be exactly header plus payload long: a truncated or extended
//! file is refused before the checksum is even looked at.
//!
//! ## Change log `<state file>.log` (version 1)
//!
//! A 16-byte header — magic `b"GJKDCLOG"`, version `u32` LE
//! ([`LOG_VERSION`]), the snapshot's id epoch `u32` LE — then records, each:
//!
//! | bytes | content |
//! |---|---|
//! | 0..4 | payload length `n`, `u32` LE, 1..=[`MAX_RECORD`] |
//! | 4..8 | CRC-32 of the payload, `u32` LE |
//! | 8..12 | CRC-32 of bytes 0..8, `u32` LE |
//! | 12..12+n | payload: a [`Change`] encoded with postcard |
//!
//! The header checksum lets a damaged length be told from a record cut
//! short: without it, a bit flip in the length of a middle record would
//! look like a torn tail and silently drop the records after it.
//!
//! # Writing
//!
//! A registration or removal is appended to the log as one record, and the
//! log fsynced (`fdatasync`), before the server acknowledges it: an
//! acknowledged change survives `kill -9` and a power cut alike. That costs
//! the same whatever the number of objects.
//!
//! Compaction folds the log into the state file: once the log is longer
//! than the snapshot or 64 KiB ([`COMPACT_MIN`]), whichever is larger, the
//! next change is written as a whole snapshot instead of a record, which
//! keeps the total bytes written linear in the number of changes. A snapshot
//! replaces the whole file atomically: written to a temporary file in the
//! same directory, fsynced, renamed over the state file, directory fsynced.
//! Then the log is recreated empty (header only), fsynced, and the directory
//! fsynced (the log may be new). The server also writes a snapshot at start
//! and at clean shutdown (when the log holds changes).
//!
//! A crash between the rename and the log's truncation leaves a log whose
//! changes the snapshot already holds; replay is idempotent
//! ([`replay_log`]), so that is harmless. If an append fails, the change is
//! undone and the log is closed; the next change is written as a snapshot,
//! which starts a fresh log.
//!
//! # Reading
//!
//! A state file that fails any check (magic, version, length, checksum,
//! postcard decoding, or the geometry and id checks of
//! [`Snapshot::validate`]) is never loaded in part:
//! [`Store::load_or_quarantine`] renames it aside to
//! `<file>.corrupt-<unix seconds>` and the server starts empty (a log with
//! records beside it is set aside too: it means nothing without its base).
//!
//! The log is then replayed onto the snapshot, each registered object held
//! to the snapshot's checks. A last record cut short or failing its checksum
//! (an append interrupted by a crash, never acknowledged), or a zero-filled
//! tail, is dropped and cut off the file. Any other damage — a bad record
//! with more data after it, a record with valid checksums but impossible
//! content, a wrong header — sets the whole log aside as
//! `<file>.log.corrupt-<unix seconds>`. What is kept then: for a bad record,
//! the snapshot plus every record before it (the store as it was just
//! before the damage), first written into the state file; for a bad header,
//! or records that clash together (a name or slot twice), the snapshot
//! alone.
//!
//! Damage confined to the last record's payload cannot be told from a torn
//! append, and is dropped as one (reported as a torn tail).

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::os::unix::fs::{DirBuilderExt, FileExt, OpenOptionsExt};
use std::os::unix::io::AsRawFd;
use std::path::{Path, PathBuf};

use gjk::{Compound, Convex, Shape};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};
use serde::{Deserialize, Serialize};

/// First bytes of every state file.
pub const MAGIC: [u8; 8] = *b"GJKDOBJS";

/// Version of the file layout and of [`Snapshot`]'s encoding. A file of any
/// other version is refused (and set aside), never guessed at.
pub const FORMAT_VERSION: u32 = 1;

/// Bytes before the payload.
pub const HEADER_LEN: usize = 24;

/// Largest payload accepted on read: far above what the server's limits
/// allow, small enough that a corrupt length cannot make the reader allocate
/// the machine away (the whole file is read first anyway, so this only
/// guards against absurd files).
pub const MAX_PAYLOAD: u64 = 1 << 36;

/// Journal slots above this are refused on load (a journal of 4 Mi slots
/// is 288 MiB; the default object limit is 1 Mi).
pub const MAX_SLOTS: u32 = 1 << 22;

/// A pose as stored: translation and quaternion `[i, j, k, w]`, exactly the
/// bits of the in-memory isometry.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredPose {
    /// Translation.
    pub translation: [f64; 3],
    /// Unit quaternion `[i, j, k, w]`.
    pub rotation: [f64; 4],
}

impl StoredPose {
    /// The stored form of `iso`, bit for bit.
    pub fn from_isometry(iso: &Isometry3<f64>) -> Self {
        let t = iso.translation.vector;
        let q = iso.rotation.coords;
        StoredPose {
            translation: [t.x, t.y, t.z],
            rotation: [q.x, q.y, q.z, q.w],
        }
    }

    /// The isometry with exactly these bits, if finite and of unit length to
    /// round-off (what the server stored was checked on the way in, so
    /// anything else is corruption).
    pub fn to_isometry(&self) -> Option<Isometry3<f64>> {
        if !self
            .translation
            .iter()
            .chain(&self.rotation)
            .all(|c| c.is_finite())
        {
            return None;
        }
        let [i, j, k, w] = self.rotation;
        let q = Quaternion::new(w, i, j, k);
        if (q.norm() - 1.0).abs() > 1e-9 {
            return None;
        }
        let [x, y, z] = self.translation;
        Some(Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::new_unchecked(q),
        ))
    }
}

/// A convex piece as stored: the vertices as registered (their order is
/// kept, so answers after a reload equal the ones before bit for bit) and the
/// radius.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredConvex {
    /// Rounding radius.
    pub radius: f64,
    /// Vertices in the body frame, in registration order.
    pub vertices: Vec<[f64; 3]>,
}

/// A shape as stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum StoredShape {
    /// One convex piece.
    Convex(StoredConvex),
    /// Pieces with their offsets, in registration order.
    Compound(Vec<(StoredPose, StoredConvex)>),
}

impl StoredShape {
    /// The stored form of `shape`.
    pub fn from_shape(shape: &Shape) -> Self {
        fn convex(c: &Convex) -> StoredConvex {
            StoredConvex {
                radius: c.radius(),
                vertices: c.vertices().iter().map(|p| [p.x, p.y, p.z]).collect(),
            }
        }
        match shape {
            Shape::Convex(c) => StoredShape::Convex(convex(c)),
            Shape::Compound(c) => StoredShape::Compound(
                c.pieces()
                    .iter()
                    .map(|(o, p)| (StoredPose::from_isometry(o), convex(p)))
                    .collect(),
            ),
        }
    }

    /// Rebuilds the shape with the same checks as a registration.
    ///
    /// # Errors
    /// A description of what is wrong.
    pub fn to_shape(&self) -> Result<Shape, String> {
        fn convex(c: &StoredConvex) -> Result<Convex, String> {
            let points: Vec<Point3<f64>> = c.vertices.iter().map(|&v| v.into()).collect();
            Convex::new(points, c.radius).map_err(|e| e.to_string())
        }
        match self {
            StoredShape::Convex(c) => Ok(convex(c)?.into()),
            StoredShape::Compound(pieces) => {
                if pieces.len() > gjkd_proto::MAX_PIECES {
                    return Err(format!("compound of {} pieces", pieces.len()));
                }
                let pieces = pieces
                    .iter()
                    .map(|(o, c)| {
                        let offset = o.to_isometry().ok_or("bad piece offset")?;
                        Ok((offset, convex(c)?))
                    })
                    .collect::<Result<Vec<_>, String>>()?;
                Ok(Compound::new(pieces).map_err(|e| e.to_string())?.into())
            }
        }
    }
}

/// Who owns a stored object; mirrors [`crate::state::Owner`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum StoredOwner {
    /// Loaded from the scene file.
    Scene,
    /// Registered by the client whose iceoryx2 node has this id.
    Client(u128),
}

/// One object as stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredObject {
    /// Its id, kept across restarts.
    pub id: u64,
    /// Its owner.
    pub owner: StoredOwner,
    /// Its name, if any.
    pub name: Option<String>,
    /// Its stored pose at the time of the write.
    pub pose: StoredPose,
    /// Its geometry.
    pub shape: StoredShape,
    /// Its slot in the pose journal ([`crate::journal`]).
    pub slot: u32,
}

/// Everything the state file holds: the id counter and the objects.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Upper 32 bits of every id of this store.
    pub epoch: u32,
    /// Lower 32 bits of the next id to hand out: above every id ever handed
    /// out, removed ones included, so ids are never reused across restarts.
    pub next_index: u32,
    /// The objects, in id order.
    pub objects: Vec<StoredObject>,
}

/// Why a state file was refused.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum FormatError {
    /// Shorter than the header.
    #[error("file of {0} bytes is shorter than the {HEADER_LEN}-byte header")]
    Short(usize),
    /// The first bytes are not [`MAGIC`].
    #[error("not a gjkd state file (bad magic)")]
    Magic,
    /// Written by a different format version.
    #[error("format version {0}, this server reads version {FORMAT_VERSION}")]
    Version(u32),
    /// The payload length in the header disagrees with the file.
    #[error("header says {expected} payload bytes, file has {actual}")]
    Length {
        /// From the header.
        expected: u64,
        /// In the file.
        actual: u64,
    },
    /// The checksum does not match the payload.
    #[error("checksum mismatch: header {expected:#010x}, payload {actual:#010x}")]
    Checksum {
        /// From the header.
        expected: u32,
        /// Of the payload.
        actual: u32,
    },
    /// The payload does not decode.
    #[error("payload does not decode: {0}")]
    Decode(String),
    /// The payload decodes to something the server would never have written.
    #[error("invalid content: {0}")]
    Invalid(String),
}

impl Snapshot {
    /// The file bytes of this snapshot: header and postcard payload.
    ///
    /// # Errors
    /// When postcard cannot encode it (it always can for these types; the
    /// error is passed on rather than unwrapped).
    pub fn encode(&self) -> Result<Vec<u8>, String> {
        let payload = postcard::to_stdvec(self).map_err(|e| e.to_string())?;
        let mut out = Vec::with_capacity(HEADER_LEN + payload.len());
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
        out.extend_from_slice(&payload);
        Ok(out)
    }

    /// Decodes and validates file bytes; all or nothing.
    ///
    /// # Errors
    /// The first check that fails.
    pub fn decode(bytes: &[u8]) -> Result<Self, FormatError> {
        if bytes.len() < HEADER_LEN {
            return Err(FormatError::Short(bytes.len()));
        }
        if bytes[..8] != MAGIC {
            return Err(FormatError::Magic);
        }
        let word = |r: std::ops::Range<usize>| {
            let mut b = [0u8; 8];
            b[..r.len()].copy_from_slice(&bytes[r]);
            u64::from_le_bytes(b)
        };
        let version = word(8..12) as u32;
        if version != FORMAT_VERSION {
            return Err(FormatError::Version(version));
        }
        let expected = word(12..20);
        let payload = &bytes[HEADER_LEN..];
        if expected != payload.len() as u64 || expected > MAX_PAYLOAD {
            return Err(FormatError::Length {
                expected,
                actual: payload.len() as u64,
            });
        }
        let crc = word(20..24) as u32;
        let actual = crc32fast::hash(payload);
        if crc != actual {
            return Err(FormatError::Checksum {
                expected: crc,
                actual,
            });
        }
        let (snapshot, rest): (Snapshot, &[u8]) =
            postcard::take_from_bytes(payload).map_err(|e| FormatError::Decode(e.to_string()))?;
        if !rest.is_empty() {
            return Err(FormatError::Decode(format!(
                "{} bytes after the snapshot",
                rest.len()
            )));
        }
        snapshot.validate().map_err(FormatError::Invalid)?;
        Ok(snapshot)
    }

    /// Checks what the checksum cannot: that every id belongs to this
    /// store's epoch and lies below the counter, that ids, names and journal
    /// slots are unique, and that every shape and pose passes the
    /// registration checks.
    ///
    /// # Errors
    /// A description of the first problem.
    pub fn validate(&self) -> Result<(), String> {
        if self.epoch == 0 {
            return Err("epoch 0".into());
        }
        for o in &self.objects {
            check_object(self.epoch, o)?;
            if o.id as u32 >= self.next_index {
                return Err(format!("id {:#x} outside this store", o.id));
            }
        }
        check_unique(self.objects.iter())
    }
}

/// The checks of one object that need no other object: its id is of
/// `epoch` and could have been handed out, its slot, name, pose and geometry
/// are what a registration accepts. Shared by the snapshot and the change
/// log, so an object is held to the same rules whichever file it came from.
fn check_object(epoch: u32, o: &StoredObject) -> Result<(), String> {
    // Slots are reused after removals, so they stay below the peak number
    // of objects; one past MAX_SLOTS could only come from a buggy writer,
    // and would size the journal absurdly.
    if o.slot >= MAX_SLOTS {
        return Err(format!("bad journal slot {}", o.slot));
    }
    // Index u32::MAX is never handed out: the counter stops below it.
    let (id_epoch, index) = ((o.id >> 32) as u32, o.id as u32);
    if id_epoch != epoch || index == 0 || index == u32::MAX {
        return Err(format!("id {:#x} outside this store", o.id));
    }
    if let Some(name) = &o.name
        && (name.is_empty() || name.len() > gjkd_proto::MAX_NAME_LEN)
    {
        return Err(format!("bad name {name:?}"));
    }
    o.pose
        .to_isometry()
        .ok_or_else(|| format!("bad pose of {:#x}", o.id))?;
    o.shape
        .to_shape()
        .map_err(|e| format!("object {:#x}: {e}", o.id))?;
    Ok(())
}

/// Ids, names and journal slots are each unique among `objects`.
fn check_unique<'a>(objects: impl Iterator<Item = &'a StoredObject>) -> Result<(), String> {
    let mut ids = std::collections::HashSet::new();
    let mut names = std::collections::HashSet::new();
    let mut slots = std::collections::HashSet::new();
    for o in objects {
        if !ids.insert(o.id) {
            return Err(format!("id {:#x} twice", o.id));
        }
        if !slots.insert(o.slot) {
            return Err(format!("repeated journal slot {}", o.slot));
        }
        if let Some(name) = &o.name
            && !names.insert(name.as_str())
        {
            return Err(format!("repeated name {name:?}"));
        }
    }
    Ok(())
}

/// First bytes of every change log.
pub const LOG_MAGIC: [u8; 8] = *b"GJKDCLOG";

/// Version of the change log's layout and of [`Change`]'s encoding; a log of
/// any other version is refused (and set aside).
pub const LOG_VERSION: u32 = 1;

/// Bytes of the change log's header: magic, version, epoch.
pub const LOG_HEADER_LEN: usize = 16;

/// Bytes before each record's payload: its length, its CRC-32 and the
/// CRC-32 of those two.
pub const RECORD_HEADER_LEN: usize = 12;

/// Largest record payload written or read. A registration is bounded by the
/// server's vertex limit, far below this; a larger length in a record whose
/// header checksum holds can only come from a buggy writer.
pub const MAX_RECORD: u32 = 1 << 30;

/// The change log is folded into a new snapshot once it is longer than the
/// snapshot or than this, whichever is larger: rewriting the snapshot then
/// costs at most as much as the appends since the last one did, so the total
/// write volume stays linear in the number of changes, and a small store is
/// not rewritten every few changes.
pub const COMPACT_MIN: u64 = 64 * 1024;

/// The change log of a state file: `<state file>.log`.
pub fn log_path_for(state_file: &Path) -> PathBuf {
    let mut p = state_file.as_os_str().to_owned();
    p.push(".log");
    PathBuf::from(p)
}

/// One change since the snapshot, as a record of the change log.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Change {
    /// An object was registered (its pose as of the registration; later
    /// poses are in the pose journal).
    Register(StoredObject),
    /// The object with this id was removed.
    Remove(u64),
}

impl Change {
    /// The framed record: payload length (`u32` LE), payload CRC-32 (`u32`
    /// LE), CRC-32 of those 8 bytes (`u32` LE), postcard payload.
    ///
    /// # Errors
    /// When postcard cannot encode it, or it exceeds [`MAX_RECORD`].
    pub fn encode_record(&self) -> Result<Vec<u8>, String> {
        let payload = postcard::to_stdvec(self).map_err(|e| e.to_string())?;
        let len = u32::try_from(payload.len())
            .ok()
            .filter(|&l| l <= MAX_RECORD)
            .ok_or_else(|| format!("record of {} bytes", payload.len()))?;
        let mut out = Vec::with_capacity(RECORD_HEADER_LEN + payload.len());
        out.extend_from_slice(&len.to_le_bytes());
        out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
        let head_crc = crc32fast::hash(&out[..8]);
        out.extend_from_slice(&head_crc.to_le_bytes());
        out.extend_from_slice(&payload);
        Ok(out)
    }
}

/// The header of a change log applying to a snapshot of `epoch`.
pub fn log_header(epoch: u32) -> [u8; LOG_HEADER_LEN] {
    let mut h = [0u8; LOG_HEADER_LEN];
    h[..8].copy_from_slice(&LOG_MAGIC);
    h[8..12].copy_from_slice(&LOG_VERSION.to_le_bytes());
    h[12..16].copy_from_slice(&epoch.to_le_bytes());
    h
}

/// Why a change log was set aside.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum LogError {
    /// Bad magic, another version, or the log of another store's epoch.
    #[error("bad header: {0}")]
    Header(String),
    /// A record failed its checksum and more data follows it: not a torn
    /// append (that can only be the last record) but damage.
    #[error("record at byte {offset}: {reason}, with more data after it")]
    Corrupt {
        /// Where the record starts.
        offset: u64,
        /// What failed.
        reason: String,
    },
    /// A record whose checksums hold but whose content the server would
    /// never have written.
    #[error("record at byte {offset} is invalid: {reason}")]
    Invalid {
        /// Where the record starts.
        offset: u64,
        /// What is wrong.
        reason: String,
    },
    /// Every record is valid alone but together they break a rule of the
    /// store (a name or journal slot twice).
    #[error("the replayed objects are inconsistent: {0}")]
    Inconsistent(String),
    /// A log with records but no state file to apply them to (the state
    /// file was deleted by hand).
    #[error("there is no state file to apply it to")]
    Orphan,
    /// The state file it applies to was corrupt and has been set aside.
    #[error("its state file was corrupt")]
    StateCorrupt,
}

/// What loading the change log did.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Replay {
    /// Records that changed the snapshot.
    pub applied: u64,
    /// Records the snapshot already had (left by a compaction interrupted
    /// between its snapshot and its log truncation).
    pub skipped: u64,
    /// Bytes of header and good records: where a torn tail is cut off; 0
    /// when there is no usable log.
    pub good_len: u64,
    /// Bytes of a torn last record (an append a crash interrupted, never
    /// acknowledged) that were cut off.
    pub torn: u64,
    /// Why the log was set aside, if it was.
    pub error: Option<LogError>,
    /// Where the set-aside log now is.
    pub moved_to: Option<PathBuf>,
}

/// Applies the change log `log` to `snapshot` (both as read from disk);
/// pure, so that every damage can be tested without files.
///
/// Replay is idempotent: a registration of an id the snapshot holds with
/// the same owner, name, slot and geometry is skipped (the pose may differ:
/// the snapshot's is newer), a removal of a missing id is skipped. So a log
/// whose records are already in the snapshot (a compaction interrupted
/// after writing the snapshot) replays to exactly the snapshot: every id is
/// registered once and removed at most once, after its registration, so
/// each record's net effect is already there. The id counter ends above
/// every id the log names, removed ones included.
///
/// A torn last record is dropped ([`Replay::torn`]). On a bad record
/// followed by more data ([`LogError::Corrupt`]) or a record with valid
/// checksums but invalid content ([`LogError::Invalid`]), the records before
/// it are applied and the rest is not: that is the store as it was at some
/// moment, every change acknowledged before the damage included. On
/// [`LogError::Header`] and [`LogError::Inconsistent`] `snapshot` is left
/// as it was.
pub fn replay_log(snapshot: &mut Snapshot, log: &[u8]) -> Replay {
    let mut replay = Replay::default();
    // A crash while a compaction created the log leaves it shorter than its
    // header, or (on file systems that extend before writing) zero-filled:
    // no record was ever appended to such a log.
    if log.len() < LOG_HEADER_LEN || log.iter().all(|&b| b == 0) {
        replay.torn = log.len() as u64;
        return replay;
    }
    if log[..LOG_HEADER_LEN] != log_header(snapshot.epoch) {
        let reason = if log[..8] != LOG_MAGIC {
            "not a gjkd change log (bad magic)".to_owned()
        } else if log[8..12] != LOG_VERSION.to_le_bytes() {
            format!(
                "version {}, this server reads version {LOG_VERSION}",
                u32::from_le_bytes(log[8..12].try_into().unwrap_or_default())
            )
        } else {
            format!(
                "epoch {:#x}, the state file's is {:#x}",
                u32::from_le_bytes(log[12..16].try_into().unwrap_or_default()),
                snapshot.epoch
            )
        };
        replay.error = Some(LogError::Header(reason));
        return replay;
    }
    // The changes go into an overlay, not the snapshot, so that nothing is
    // changed if the result turns out inconsistent.
    let base: std::collections::HashMap<u64, usize> = snapshot
        .objects
        .iter()
        .enumerate()
        .map(|(i, o)| (o.id, i))
        .collect();
    let mut added: std::collections::HashMap<u64, StoredObject> = Default::default();
    let mut removed: std::collections::HashSet<u64> = Default::default();
    let mut next_index = snapshot.next_index;
    let mut pos = LOG_HEADER_LEN;
    let word = |at: usize| u32::from_le_bytes(log[at..at + 4].try_into().unwrap_or_default());
    while pos < log.len() {
        let offset = pos as u64;
        let rest = &log[pos..];
        let torn = |replay: &mut Replay| {
            replay.torn = rest.len() as u64;
        };
        if rest.len() < RECORD_HEADER_LEN {
            torn(&mut replay);
            break;
        }
        let (len, crc) = (word(pos), word(pos + 4));
        if crc32fast::hash(&rest[..8]) != word(pos + 8) {
            // Without a trustworthy length the extent of this record is
            // unknown, so it cannot be told to be the last one; only a
            // zero-filled tail is surely an interrupted append.
            if rest.iter().all(|&b| b == 0) {
                torn(&mut replay);
            } else {
                replay.error = Some(LogError::Corrupt {
                    offset,
                    reason: "record header checksum mismatch".into(),
                });
            }
            break;
        }
        if len == 0 || len > MAX_RECORD {
            replay.error = Some(LogError::Invalid {
                offset,
                reason: format!("record length {len}"),
            });
            break;
        }
        let end = pos + RECORD_HEADER_LEN + len as usize;
        if end > log.len() {
            torn(&mut replay);
            break;
        }
        let payload = &log[pos + RECORD_HEADER_LEN..end];
        if crc32fast::hash(payload) != crc {
            if end == log.len() {
                torn(&mut replay);
            } else {
                replay.error = Some(LogError::Corrupt {
                    offset,
                    reason: "payload checksum mismatch".into(),
                });
            }
            break;
        }
        let invalid = |reason: String| Some(LogError::Invalid { offset, reason });
        let change = match postcard::take_from_bytes::<Change>(payload) {
            Ok((c, [])) => c,
            Ok((_, rest)) => {
                replay.error = invalid(format!("{} bytes after the change", rest.len()));
                break;
            }
            Err(e) => {
                replay.error = invalid(format!("does not decode: {e}"));
                break;
            }
        };
        let present = |id: u64| {
            added
                .get(&id)
                .or_else(|| {
                    base.get(&id)
                        .filter(|_| !removed.contains(&id))
                        .map(|&i| &snapshot.objects[i])
                })
                .cloned()
        };
        match change {
            Change::Register(o) => {
                if let Err(e) = check_object(snapshot.epoch, &o) {
                    replay.error = invalid(e);
                    break;
                }
                next_index = next_index.max(o.id as u32 + 1);
                match present(o.id) {
                    Some(old)
                        if old.owner == o.owner
                            && old.name == o.name
                            && old.slot == o.slot
                            && old.shape == o.shape =>
                    {
                        replay.skipped += 1;
                    }
                    Some(_) => {
                        replay.error = invalid(format!("id {:#x} registered twice", o.id));
                        break;
                    }
                    None => {
                        added.insert(o.id, o);
                        replay.applied += 1;
                    }
                }
            }
            Change::Remove(id) => {
                if (id >> 32) as u32 != snapshot.epoch {
                    replay.error = invalid(format!("removal of id {id:#x} of another store"));
                    break;
                }
                if added.remove(&id).is_some() || (base.contains_key(&id) && removed.insert(id)) {
                    replay.applied += 1;
                } else {
                    replay.skipped += 1;
                }
            }
        }
        pos = end;
    }
    replay.good_len = pos as u64;
    // Each object was checked alone; what replay can still break is
    // uniqueness (ids are unique by construction of the overlay).
    let merged = snapshot
        .objects
        .iter()
        .filter(|o| !removed.contains(&o.id))
        .chain(added.values());
    if let Err(e) = check_unique(merged) {
        replay.applied = 0;
        replay.skipped = 0;
        replay.error = Some(LogError::Inconsistent(e));
        return replay;
    }
    snapshot.objects.retain(|o| !removed.contains(&o.id));
    snapshot.objects.extend(added.into_values());
    snapshot.objects.sort_unstable_by_key(|o| o.id);
    snapshot.next_index = next_index;
    replay
}

/// Where and how the server keeps its state file and change log.
#[derive(Debug)]
pub struct Store {
    path: PathBuf,
    tmp: PathBuf,
    log_path: PathBuf,
    /// The change log, open for appends; `None` before the first snapshot
    /// write of this store, and after an append failed (the file's content
    /// is then uncertain): the next change is written as a full snapshot,
    /// which starts a fresh log.
    log: Option<File>,
    /// Bytes of the log that hold its header and whole records: where the
    /// next record goes.
    log_len: u64,
    /// Size of the state file as last written or read, which sets when the
    /// log is compacted.
    snapshot_len: u64,
    /// `<file>.lock`, held (`flock`) for the store's life: two servers on
    /// one state file would overwrite each other's objects. The kernel
    /// drops the lock when the process dies, `kill -9` included. It covers
    /// the change log too.
    _lock: File,
    /// Test hook: the next log resets fail (see [`Store::fail_log_resets`]).
    #[cfg(test)]
    resets_fail: bool,
}

/// Why a state file or change log could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// An I/O operation failed.
    #[error("{what} {path}: {source}")]
    Io {
        /// What was being done.
        what: &'static str,
        /// On which path.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The snapshot or change could not be encoded.
    #[error("cannot encode the state: {0}")]
    Encode(String),
    /// An append was asked for with no change log open (see
    /// [`Store::can_append`]).
    #[error("no change log open: write a snapshot first")]
    NoLog,
}

fn io(what: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> StoreError {
    let path = path.to_path_buf();
    move |source| StoreError::Io { what, path, source }
}

/// What [`Store::load_or_quarantine`] found.
#[derive(Debug)]
pub enum Loaded {
    /// No state file: a first start.
    Missing {
        /// What became of a change log found without its state file.
        log: Replay,
    },
    /// A valid state file, with the valid part of its change log applied.
    Snapshot {
        /// The objects.
        snapshot: Snapshot,
        /// What the change log held.
        log: Replay,
    },
    /// A file that failed a check; it was renamed to `moved_to`.
    Corrupt {
        /// Why it was refused.
        reason: FormatError,
        /// Where it now is.
        moved_to: PathBuf,
        /// What became of its change log.
        log: Replay,
    },
}

impl Loaded {
    /// The same answer with `log` as what became of the change log.
    fn with_log(self, log: Replay) -> Self {
        match self {
            Loaded::Missing { .. } => Loaded::Missing { log },
            Loaded::Snapshot { snapshot, .. } => Loaded::Snapshot { snapshot, log },
            Loaded::Corrupt {
                reason, moved_to, ..
            } => Loaded::Corrupt {
                reason,
                moved_to,
                log,
            },
        }
    }
}

impl Store {
    /// A store at `path`. Creates the parent directory (owner-only, 0700)
    /// if missing (an existing directory's mode is left alone), and takes
    /// the lock that keeps a second server off the same file.
    ///
    /// # Errors
    /// When the directory cannot be created, or another process holds the
    /// lock (another server uses this state file).
    pub fn open(path: impl Into<PathBuf>) -> Result<Self, StoreError> {
        let path = path.into();
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::DirBuilder::new()
                .recursive(true)
                .mode(0o700)
                .create(dir)
                .map_err(io("cannot create directory", dir))?;
        }
        let mut lock_path = path.clone().into_os_string();
        lock_path.push(".lock");
        let lock_path = PathBuf::from(lock_path);
        let lock = OpenOptions::new()
            .write(true)
            .create(true)
            .truncate(false)
            .mode(0o600)
            .open(&lock_path)
            .map_err(io("cannot open the lock file", &lock_path))?;
        // SAFETY: flock(2) on a descriptor we own.
        if unsafe { libc::flock(lock.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
            let e = std::io::Error::last_os_error();
            return Err(StoreError::Io {
                what: "state file in use by another gjkd server (lock held)",
                path: lock_path,
                source: e,
            });
        }
        remove_stale_temporaries(&path);
        let mut tmp = path.clone().into_os_string();
        tmp.push(format!(".tmp-{}", std::process::id()));
        Ok(Store {
            log_path: log_path_for(&path),
            path,
            tmp: tmp.into(),
            log: None,
            log_len: 0,
            snapshot_len: 0,
            _lock: lock,
            #[cfg(test)]
            resets_fail: false,
        })
    }

    /// The state file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The change log, `<state file>.log`.
    pub fn log_path(&self) -> &Path {
        &self.log_path
    }

    /// Bytes in the change log (header and records); 0 when none is open.
    pub fn log_len(&self) -> u64 {
        self.log_len
    }

    /// Whether the change log holds records not yet in the state file.
    pub fn has_changes(&self) -> bool {
        self.log_len > LOG_HEADER_LEN as u64
    }

    /// Whether [`Store::append`] can be used: a log is open.
    pub fn can_append(&self) -> bool {
        self.log.is_some()
    }

    /// Whether the next change should be written as a full snapshot
    /// ([`Store::write`]) instead of appended: there is no log to append to,
    /// or it has grown past the larger of the snapshot and [`COMPACT_MIN`].
    pub fn wants_compaction(&self) -> bool {
        self.log.is_none() || self.log_len > self.snapshot_len.max(COMPACT_MIN)
    }

    /// Compaction: replaces the state file with `snapshot` (write a
    /// temporary file, fsync it, rename it over the state file, fsync the
    /// directory), then empties the change log, whose changes the snapshot
    /// now holds.
    ///
    /// Once the rename is durable the change is, so a failure to empty the
    /// log is not an error of the write: the old log is removed instead
    /// (its records would replay onto this snapshot as no-ops, see
    /// [`replay_log`], but for registrations of objects the snapshot has
    /// since dropped, which they would bring back), the failure is logged,
    /// and the next change is written as a snapshot again.
    ///
    /// # Errors
    /// A step up to the rename that fails; the old file and log are then
    /// intact.
    pub fn write(&mut self, snapshot: &Snapshot) -> Result<(), StoreError> {
        let bytes = snapshot.encode().map_err(StoreError::Encode)?;
        self.write_snapshot_file(&bytes)?;
        self.snapshot_len = bytes.len() as u64;
        if let Err(e) = self.reset_log(snapshot.epoch) {
            // The old log's records would replay onto this snapshot at the
            // next start, and a registration there of an object that this
            // snapshot no longer holds (removed since) would bring it back.
            // With no log there is nothing to replay.
            match std::fs::remove_file(&self.log_path) {
                Ok(()) => tracing::error!(
                    "{e}; the old change log is removed, the next change is written as a full snapshot"
                ),
                Err(r) if r.kind() == std::io::ErrorKind::NotFound => {
                    tracing::error!("{e}; the next change is written as a full snapshot")
                }
                Err(r) => tracing::error!(
                    "{e}; the old change log cannot be removed either ({r}): a restart before the next change may replay it"
                ),
            }
        }
        Ok(())
    }

    /// Writes the state file alone, atomically.
    fn write_snapshot_file(&self, bytes: &[u8]) -> Result<(), StoreError> {
        let result = (|| {
            let mut f = OpenOptions::new()
                .write(true)
                .create(true)
                .truncate(true)
                .mode(0o600)
                .open(&self.tmp)
                .map_err(io("cannot create", &self.tmp))?;
            f.write_all(bytes).map_err(io("cannot write", &self.tmp))?;
            f.sync_all().map_err(io("cannot fsync", &self.tmp))?;
            drop(f);
            std::fs::rename(&self.tmp, &self.path).map_err(io("cannot rename to", &self.path))
        })();
        if result.is_err() {
            let _ = std::fs::remove_file(&self.tmp);
            return result;
        }
        // The new file is in place: reporting a failure now would have the
        // caller undo in memory a change that the file already holds. A
        // machine crash before the directory entry is durable can only
        // bring back the previous file and log, a state as consistent.
        if let Err(e) = sync_dir(&self.path) {
            tracing::error!(
                "{e}; the state file is written, its directory entry maybe not yet durable"
            );
        }
        Ok(())
    }

    /// Starts an empty change log (just the header) for a snapshot of
    /// `epoch`, durable with its directory entry.
    fn reset_log(&mut self, epoch: u32) -> Result<(), StoreError> {
        // Reopened by path, never reused: after a failed append the old
        // descriptor's state is unknown.
        self.log = None;
        self.log_len = 0;
        let path = &self.log_path;
        #[cfg(test)]
        if self.resets_fail {
            return Err(io("cannot create the change log", path)(
                std::io::Error::other("test hook"),
            ));
        }
        let f = OpenOptions::new()
            .write(true)
            .create(true)
            .truncate(true)
            .mode(0o600)
            .open(path)
            .map_err(io("cannot create the change log", path))?;
        f.write_all_at(&log_header(epoch), 0)
            .map_err(io("cannot write", path))?;
        f.sync_all().map_err(io("cannot fsync", path))?;
        // The file may be new: its directory entry must be durable too, or
        // a power cut could lose the log with the records later appended.
        sync_dir(path)?;
        self.log = Some(f);
        self.log_len = LOG_HEADER_LEN as u64;
        Ok(())
    }

    /// Appends `change` to the change log and fsyncs it: once this returns
    /// the change survives `kill -9` and a power cut.
    ///
    /// # Errors
    /// [`StoreError::NoLog`] when no log is open, or the failed write or
    /// fsync. The record is then cut off again if possible, and the log is
    /// closed either way (after a failed fsync the kernel may have dropped
    /// the pages, so the file is no longer trusted): the next change must be
    /// written with [`Store::write`]. A record that stays behind was not
    /// acknowledged, like a change in flight at a crash.
    pub fn append(&mut self, change: &Change) -> Result<(), StoreError> {
        let record = change.encode_record().map_err(StoreError::Encode)?;
        let log = self.log.as_ref().ok_or(StoreError::NoLog)?;
        // One positioned write per record: a kill can cut it short (at a
        // page boundary) but never interleave it with another.
        let written = log
            .write_all_at(&record, self.log_len)
            .map_err(io("cannot append to", &self.log_path))
            .and_then(|()| log.sync_data().map_err(io("cannot fsync", &self.log_path)));
        if let Err(e) = written {
            let _ = log.set_len(self.log_len);
            self.log = None;
            return Err(e);
        }
        self.log_len += record.len() as u64;
        Ok(())
    }

    /// Reads the state file and then its change log.
    ///
    /// A missing state file is [`Loaded::Missing`]; one that fails any check
    /// is renamed aside and reported as [`Loaded::Corrupt`]. A change log
    /// with records but no valid state file to apply them to is set aside
    /// too (`<log>.corrupt-<unix seconds>`): its records mean nothing
    /// without their base.
    ///
    /// Otherwise the log is replayed ([`replay_log`]). A torn last record is
    /// cut off the file. A damaged log is set aside whole, after the records
    /// before the damage have been written into the state file (in that
    /// order, so a crash in between replays them again as no-ops).
    ///
    /// # Errors
    /// When a file exists but cannot be read at all (permissions, I/O), or
    /// a bad file cannot be moved aside: the server must not start without
    /// them and then overwrite them.
    pub fn load_or_quarantine(&mut self) -> Result<Loaded, StoreError> {
        let (loaded, snapshot_len) = load_snapshot(&self.path)?;
        let log_bytes = match std::fs::read(&self.log_path) {
            Ok(b) => Some(b),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => return Err(io("cannot read", &self.log_path)(e)),
        };
        let mut snapshot = match loaded {
            Loaded::Snapshot { snapshot, .. } => snapshot,
            other => {
                let mut replay = Replay::default();
                // A log no longer than its header holds no change: the next
                // snapshot write truncates it.
                if log_bytes.is_some_and(|b| b.len() > LOG_HEADER_LEN) {
                    let error = match other {
                        Loaded::Missing { .. } => LogError::Orphan,
                        _ => LogError::StateCorrupt,
                    };
                    replay.moved_to = Some(set_aside(&self.log_path, &error)?);
                    replay.error = Some(error);
                }
                return Ok(other.with_log(replay));
            }
        };
        self.snapshot_len = snapshot_len;
        let Some(bytes) = log_bytes else {
            return Ok(Loaded::Snapshot {
                snapshot,
                log: Replay::default(),
            });
        };
        let mut replay = replay_log(&mut snapshot, &bytes);
        if let Some(error) = &replay.error {
            if replay.applied > 0 {
                let bytes = snapshot.encode().map_err(StoreError::Encode)?;
                self.write_snapshot_file(&bytes)?;
                self.snapshot_len = bytes.len() as u64;
            }
            replay.moved_to = Some(set_aside(&self.log_path, error)?);
        } else if replay.good_len > 0 {
            let f = OpenOptions::new()
                .write(true)
                .open(&self.log_path)
                .map_err(io("cannot open", &self.log_path))?;
            if replay.torn > 0 {
                // Cut before anything is appended after it, which would turn
                // the torn record into a corrupt one in mid-log.
                f.set_len(replay.good_len)
                    .and_then(|()| f.sync_all())
                    .map_err(io("cannot truncate", &self.log_path))?;
            }
            self.log = Some(f);
            self.log_len = replay.good_len;
        }
        Ok(Loaded::Snapshot {
            snapshot,
            log: replay,
        })
    }

    /// Test hook: every further reset of the change log (after a snapshot
    /// write) fails, leaving the old log's content where it is.
    #[cfg(test)]
    pub(crate) fn fail_log_resets(&mut self) {
        self.resets_fail = true;
    }

    /// Test hook: makes every further write to the open change log fail as
    /// on a full disk (its descriptor now refers to `/dev/full`), to
    /// exercise the failure path with a real OS error.
    #[cfg(test)]
    pub(crate) fn fill_disk_under_log(&self) {
        let full = OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full");
        let log = self.log.as_ref().expect("a log is open");
        // SAFETY: dup2(2) onto a descriptor this store owns; both stay open.
        assert!(unsafe { libc::dup2(full.as_raw_fd(), log.as_raw_fd()) } >= 0);
    }
}

/// Reads the state file alone (see [`Store::load_or_quarantine`]), with the
/// length of what it read. The `log` fields of the answer are empty.
fn load_snapshot(path: &Path) -> Result<(Loaded, u64), StoreError> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Ok((
                Loaded::Missing {
                    log: Replay::default(),
                },
                0,
            ));
        }
        Err(e) => return Err(io("cannot read", path)(e)),
    };
    let len = bytes.len() as u64;
    match Snapshot::decode(&bytes) {
        Ok(snapshot) => Ok((
            Loaded::Snapshot {
                snapshot,
                log: Replay::default(),
            },
            len,
        )),
        Err(reason) => {
            let moved_to = set_aside(path, &reason)?;
            Ok((
                Loaded::Corrupt {
                    reason,
                    moved_to,
                    log: Replay::default(),
                },
                len,
            ))
        }
    }
}

/// Renames a file that failed its checks to `<file>.corrupt-<unix
/// seconds>`, never over an earlier one. (Not fsynced: if a crash undoes the
/// rename, the next start finds the same file and sets it aside again.)
///
/// # Errors
/// When it cannot be moved: starting without it would overwrite it at the
/// first registration, so the server refuses to start instead.
fn set_aside(path: &Path, reason: &dyn std::fmt::Display) -> Result<PathBuf, StoreError> {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    let aside = (0..)
        .map(|n| {
            let mut a = path.as_os_str().to_owned();
            a.push(format!(".corrupt-{secs}"));
            if n > 0 {
                a.push(format!(".{n}"));
            }
            PathBuf::from(a)
        })
        .find(|a| !a.exists())
        .unwrap_or_else(|| path.with_extension("corrupt"));
    std::fs::rename(path, &aside).map_err(|e| StoreError::Io {
        what: "cannot set aside the corrupt file",
        path: path.to_path_buf(),
        source: std::io::Error::new(e.kind(), format!("{reason}; rename failed: {e}")),
    })?;
    Ok(aside)
}

/// Removes `<file>.tmp-*` left by a server killed in the middle of a
/// write (the state file itself is intact: the rename never happened).
/// Only called with the lock held, so no live server is writing them.
fn remove_stale_temporaries(path: &Path) {
    let (Some(dir), Some(name)) = (path.parent(), path.file_name()) else {
        return;
    };
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let mut prefix = name.to_owned();
    prefix.push(".tmp-");
    let prefix = prefix.to_string_lossy().into_owned();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        if e.file_name().to_string_lossy().starts_with(&prefix) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

fn sync_dir(file: &Path) -> Result<(), StoreError> {
    let dir = match file.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    File::open(dir)
        .and_then(|d| d.sync_all())
        .map_err(io("cannot fsync directory", dir))
}

/// The default state file of `service`:
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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn sample() -> Snapshot {
        let pose = StoredPose::from_isometry(&Isometry3::new(
            Vector3::new(1.0, -2.0, 3.5),
            Vector3::new(0.1, 0.2, -0.3),
        ));
        let cube = StoredShape::from_shape(
            &Convex::cuboid(Vector3::new(1.0, 2.0, 3.0), 0.25)
                .expect("box")
                .into(),
        );
        let dumbbell = StoredShape::Compound(vec![
            (
                StoredPose::from_isometry(&Isometry3::translation(-1.0, 0.0, 0.0)),
                StoredConvex {
                    radius: 0.3,
                    vertices: vec![[0.0; 3]],
                },
            ),
            (
                pose,
                StoredConvex {
                    radius: 0.0,
                    vertices: vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1e-300, 0.0, 1e150]],
                },
            ),
        ]);
        let epoch = 0xABCD_0123u32;
        let id = |i: u64| (u64::from(epoch) << 32) | i;
        Snapshot {
            epoch,
            next_index: 9,
            objects: vec![
                StoredObject {
                    id: id(1),
                    owner: StoredOwner::Client(u128::MAX - 5),
                    name: Some("cube".into()),
                    pose,
                    shape: cube,
                    slot: 0,
                },
                StoredObject {
                    id: id(7),
                    owner: StoredOwner::Scene,
                    name: None,
                    pose: StoredPose::from_isometry(&Isometry3::identity()),
                    shape: dumbbell,
                    slot: 3,
                },
            ],
        }
    }

    #[test]
    fn round_trips_bit_for_bit() {
        let s = sample();
        let bytes = s.encode().expect("encodes");
        assert_eq!(&bytes[..8], b"GJKDOBJS");
        assert_eq!(Snapshot::decode(&bytes), Ok(s.clone()));
        let shape = s.objects[0].shape.to_shape().expect("valid");
        assert_eq!(StoredShape::from_shape(&shape), s.objects[0].shape);
    }

    #[test]
    fn every_truncation_is_refused() {
        let bytes = sample().encode().expect("encodes");
        for len in 0..bytes.len() {
            let err = Snapshot::decode(&bytes[..len]).expect_err("truncated");
            if len < HEADER_LEN {
                assert_eq!(err, FormatError::Short(len));
            } else {
                assert!(matches!(err, FormatError::Length { .. }), "{len}: {err}");
            }
        }
        eprintln!("{} truncations refused", bytes.len());
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(matches!(
            Snapshot::decode(&longer),
            Err(FormatError::Length { .. })
        ));
    }

    #[test]
    fn every_bit_flip_is_refused() {
        let bytes = sample().encode().expect("encodes");
        for i in 0..bytes.len() {
            for bit in 0..8 {
                let mut b = bytes.clone();
                b[i] ^= 1 << bit;
                assert!(
                    Snapshot::decode(&b).is_err(),
                    "flip of bit {bit} of byte {i}"
                );
            }
        }
        eprintln!("{} single-bit flips refused", bytes.len() * 8);
    }

    #[test]
    fn other_versions_are_refused() {
        let mut bytes = sample().encode().expect("encodes");
        bytes[8..12].copy_from_slice(&2u32.to_le_bytes());
        assert_eq!(Snapshot::decode(&bytes), Err(FormatError::Version(2)));
        bytes[8..12].copy_from_slice(&0u32.to_le_bytes());
        assert_eq!(Snapshot::decode(&bytes), Err(FormatError::Version(0)));
    }

    /// A payload with a valid checksum but impossible content (what a buggy
    /// writer or a hand-edited file would give) is refused as a whole.
    #[test]
    fn consistent_but_invalid_content_is_refused() {
        type Spoil = Box<dyn Fn(&mut Snapshot)>;
        let cases: Vec<Spoil> = vec![
            Box::new(|s| s.next_index = 7),
            Box::new(|s| s.objects[1].id = s.objects[0].id),
            Box::new(|s| s.objects[0].id ^= 1 << 40),
            Box::new(|s| s.objects[1].name = Some("cube".into())),
            Box::new(|s| s.objects[0].pose.rotation[3] = 2.0),
            Box::new(|s| s.objects[0].pose.translation[0] = f64::NAN),
            Box::new(|s| {
                if let StoredShape::Convex(c) = &mut s.objects[0].shape {
                    c.vertices.clear();
                }
            }),
            Box::new(|s| {
                if let StoredShape::Convex(c) = &mut s.objects[0].shape {
                    c.radius = -1.0;
                }
            }),
            Box::new(|s| s.objects[1].shape = StoredShape::Compound(vec![])),
            Box::new(|s| s.epoch = 0),
            Box::new(|s| s.objects[1].slot = 0),
            Box::new(|s| s.objects[1].slot = 1 << 30),
        ];
        for (i, spoil) in cases.iter().enumerate() {
            let mut s = sample();
            spoil(&mut s);
            let bytes = s.encode().expect("encodes");
            assert!(
                matches!(Snapshot::decode(&bytes), Err(FormatError::Invalid(_))),
                "case {i}"
            );
        }
    }

    #[test]
    fn writes_atomically_owner_only_and_sets_corrupt_files_aside() {
        use std::os::unix::fs::PermissionsExt;
        let dir = std::env::temp_dir().join(format!(
            "gjkd-persist-{}-{:?}",
            std::process::id(),
            std::thread::current().id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        let path = dir.join("sub").join("x.objects");
        // What a writer killed before its rename leaves behind.
        std::fs::DirBuilder::new()
            .recursive(true)
            .mode(0o700)
            .create(path.parent().expect("dir"))
            .expect("dir");
        std::fs::write(dir.join("sub").join("x.objects.tmp-999999"), b"half").expect("tmp");
        let mut store = Store::open(&path).expect("dir");
        assert!(!dir.join("sub").join("x.objects.tmp-999999").exists());
        assert!(matches!(
            store.load_or_quarantine(),
            Ok(Loaded::Missing { .. })
        ));
        store.write(&sample()).expect("write");
        let mode = std::fs::metadata(&path).expect("file").permissions().mode();
        assert_eq!(mode & 0o777, 0o600);
        let dmode = std::fs::metadata(path.parent().expect("dir"))
            .expect("dir")
            .permissions()
            .mode();
        assert_eq!(dmode & 0o777, 0o700);
        match store.load_or_quarantine().expect("read") {
            Loaded::Snapshot { snapshot, log } => {
                assert_eq!(snapshot, sample());
                assert_eq!(log.good_len, LOG_HEADER_LEN as u64, "an empty log");
            }
            other => panic!("{other:?}"),
        }
        // No temporary file is left behind: the state file, its (empty)
        // change log and the lock.
        let mut names: Vec<_> = std::fs::read_dir(path.parent().expect("dir"))
            .expect("list")
            .map(|e| e.expect("entry").file_name())
            .collect();
        names.sort();
        assert_eq!(
            names,
            ["x.objects", "x.objects.lock", "x.objects.log"],
            "{names:?}"
        );
        // A second store on the same file is refused while this one lives
        // (flock locks are per open file description, so this holds within
        // one process too).
        assert!(Store::open(&path).is_err());

        let mut bytes = std::fs::read(&path).expect("read");
        bytes.truncate(bytes.len() - 3);
        std::fs::write(&path, &bytes).expect("spoil");
        match store.load_or_quarantine().expect("read") {
            Loaded::Corrupt {
                reason: FormatError::Length { .. },
                moved_to: aside,
                log,
            } => {
                assert_eq!(log.error, None, "a log without records stays");
                assert!(aside.to_string_lossy().contains(".corrupt-"));
                assert_eq!(std::fs::read(&aside).expect("kept"), bytes);
            }
            other => panic!("{other:?}"),
        }
        assert!(!path.exists(), "the corrupt file was moved, not left");
        assert!(matches!(
            store.load_or_quarantine(),
            Ok(Loaded::Missing { .. })
        ));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A scratch directory of the test's own.
    fn scratch(tag: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("gjkd-log-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("dir");
        dir
    }

    fn sid(index: u32) -> u64 {
        (u64::from(sample().epoch) << 32) | u64::from(index)
    }

    /// A box of the sample's store.
    fn object(index: u32, slot: u32, name: Option<&str>) -> StoredObject {
        StoredObject {
            id: sid(index),
            owner: StoredOwner::Client(42),
            name: name.map(Into::into),
            pose: StoredPose::from_isometry(&Isometry3::translation(f64::from(index), 0.0, 0.0)),
            shape: StoredShape::from_shape(
                &Convex::cuboid(Vector3::new(0.5, 0.4, 0.3), 0.0)
                    .expect("box")
                    .into(),
            ),
            slot,
        }
    }

    /// Changes to the sample (ids 1 and 7, counter 9): a registration, the
    /// removal of a snapshot object, a registration reusing its slot and
    /// name, one registered and removed within the log, and one reusing
    /// that one's slot and name.
    fn changes() -> Vec<Change> {
        vec![
            Change::Register(object(9, 1, Some("a"))),
            Change::Remove(sid(1)),
            Change::Register(object(10, 0, Some("cube"))),
            Change::Register(object(11, 2, Some("b"))),
            Change::Remove(sid(11)),
            Change::Register(object(12, 2, Some("b"))),
        ]
    }

    /// The sample after `changes`, by the obvious model (not replay_log).
    fn reference(changes: &[Change]) -> Snapshot {
        let mut s = sample();
        for c in changes {
            match c {
                Change::Register(o) => {
                    s.next_index = s.next_index.max(o.id as u32 + 1);
                    s.objects.push(o.clone());
                }
                Change::Remove(id) => s.objects.retain(|o| o.id != *id),
            }
        }
        s.objects.sort_by_key(|o| o.id);
        s
    }

    /// A log of `changes` on the sample, and where each record starts.
    fn log_of(changes: &[Change]) -> (Vec<u8>, Vec<usize>) {
        let mut bytes = log_header(sample().epoch).to_vec();
        let mut starts = Vec::new();
        for c in changes {
            starts.push(bytes.len());
            bytes.extend(c.encode_record().expect("encodes"));
        }
        (bytes, starts)
    }

    fn load(path: &Path) -> (Store, Snapshot, Replay) {
        let mut store = Store::open(path).expect("store");
        match store.load_or_quarantine().expect("load") {
            Loaded::Snapshot { snapshot, log } => (store, snapshot, log),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn snapshot_and_log_round_trip() {
        let dir = scratch("round-trip");
        let path = dir.join("x.objects");
        let mut store = Store::open(&path).expect("store");
        assert!(!store.can_append(), "no log before the first snapshot");
        assert!(matches!(
            store.append(&changes()[0]),
            Err(StoreError::NoLog)
        ));
        store.write(&sample()).expect("write");
        assert_eq!(store.log_len(), LOG_HEADER_LEN as u64);
        for c in changes() {
            let before = store.log_len();
            store.append(&c).expect("append");
            assert_eq!(
                store.log_len(),
                before + c.encode_record().expect("encodes").len() as u64
            );
        }
        let (log_bytes, _) = log_of(&changes());
        assert_eq!(std::fs::read(store.log_path()).expect("log"), log_bytes);
        drop(store);
        let (mut store, snapshot, log) = load(&path);
        assert_eq!(snapshot, reference(&changes()));
        assert_eq!(snapshot.next_index, 13);
        assert_eq!(
            (log.applied, log.skipped, log.torn, log.error),
            (6, 0, 0, None)
        );
        // Appends after a load go after the last record.
        let more = Change::Register(object(13, 5, None));
        store.append(&more).expect("append");
        drop(store);
        let (_, snapshot, log) = load(&path);
        let mut all = changes();
        all.push(more);
        assert_eq!(snapshot, reference(&all));
        assert_eq!(log.applied, 7);
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A crash in the middle of an append leaves any prefix of the last
    /// record: each loads the records before it and nothing else, and is
    /// cut off the file so that later appends follow good records.
    #[test]
    fn every_cut_of_the_last_record_loads_exactly_the_records_before_it() {
        let dir = scratch("cuts");
        let path = dir.join("x.objects");
        Store::open(&path)
            .expect("store")
            .write(&sample())
            .expect("write");
        let all = changes();
        let (bytes, starts) = log_of(&all);
        let last = *starts.last().expect("records");
        let want = reference(&all[..all.len() - 1]);
        for cut in last..bytes.len() {
            std::fs::write(log_path_for(&path), &bytes[..cut]).expect("cut");
            let (store, snapshot, log) = load(&path);
            assert_eq!(snapshot, want, "cut at {cut}");
            assert_eq!(log.applied, all.len() as u64 - 1, "cut at {cut}");
            assert_eq!(log.torn, (cut - last) as u64, "cut at {cut}");
            assert_eq!(log.error, None, "cut at {cut}");
            let len = std::fs::metadata(store.log_path()).expect("log").len();
            assert_eq!(len, last as u64, "cut at {cut}: torn bytes removed");
            assert!(store.can_append());
        }
        eprintln!("{} cuts of the last record", bytes.len() - last);
        // A log cut inside its own header (a compaction killed while it
        // created the log) holds no record.
        for cut in 0..LOG_HEADER_LEN {
            let mut s = sample();
            let log = replay_log(&mut s, &bytes[..cut]);
            assert_eq!((s.clone(), log.error, log.good_len), (sample(), None, 0));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Any single-bit flip in a record followed by others is corruption,
    /// never taken for a torn tail; the records before it are kept, made
    /// durable in the state file, and the log is set aside as it was.
    #[test]
    fn a_bit_flip_in_a_middle_record_is_detected() {
        let all = changes();
        let (bytes, starts) = log_of(&all);
        let want = reference(&all[..2]);
        for i in starts[2]..starts[3] {
            for bit in 0..8 {
                let mut b = bytes.clone();
                b[i] ^= 1 << bit;
                let mut s = sample();
                let log = replay_log(&mut s, &b);
                assert_eq!(
                    log.error,
                    Some(LogError::Corrupt {
                        offset: starts[2] as u64,
                        reason: if i < starts[2] + RECORD_HEADER_LEN {
                            "record header checksum mismatch".into()
                        } else {
                            "payload checksum mismatch".into()
                        }
                    }),
                    "flip of bit {bit} of byte {i}"
                );
                assert_eq!(s, want, "flip of bit {bit} of byte {i}");
            }
        }
        eprintln!("{} flips in a middle record", (starts[3] - starts[2]) * 8);

        let dir = scratch("flip");
        let path = dir.join("x.objects");
        Store::open(&path)
            .expect("store")
            .write(&sample())
            .expect("write");
        let mut b = bytes.clone();
        b[starts[2] + 20] ^= 4;
        std::fs::write(log_path_for(&path), &b).expect("spoil");
        let (store, snapshot, log) = load(&path);
        assert_eq!(snapshot, want);
        assert!(matches!(log.error, Some(LogError::Corrupt { .. })));
        let aside = log.moved_to.expect("set aside");
        assert!(aside.to_string_lossy().contains(".log.corrupt-"));
        assert_eq!(std::fs::read(&aside).expect("kept"), b, "kept as it was");
        assert!(!store.log_path().exists());
        assert!(!store.can_append() && store.wants_compaction());
        let on_disk = Snapshot::decode(&std::fs::read(&path).expect("state")).expect("valid");
        assert_eq!(on_disk, want, "the kept records are in the state file");
        drop(store);
        let (_, again, log) = load(&path);
        assert_eq!((again, log), (want, Replay::default()));

        // Damage confined to the last record cannot be told from a torn
        // append: it is cut off (and reported as torn).
        let mut s = sample();
        let mut b = bytes.clone();
        let n = b.len();
        b[n - 3] ^= 1;
        let log = replay_log(&mut s, &b);
        assert_eq!(log.error, None);
        assert_eq!(log.torn, (n - starts[5]) as u64);
        assert_eq!(s, reference(&all[..5]));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A compaction killed after its snapshot is durable but before the log
    /// is emptied: the old log replays onto the new snapshot as no-ops,
    /// giving the same objects (with the snapshot's newer poses) and the
    /// same id counter. Replaying object 11 (registered and removed within
    /// the log) clashes for a moment with object 12 of the snapshot, which
    /// has its slot and name: that must not be taken for corruption.
    #[test]
    fn a_compaction_cut_short_before_the_log_is_emptied_changes_nothing() {
        let dir = scratch("compaction-crash");
        let path = dir.join("x.objects");
        let mut store = Store::open(&path).expect("store");
        store.write(&sample()).expect("write");
        for c in changes() {
            store.append(&c).expect("append");
        }
        let old_log = std::fs::read(store.log_path()).expect("log");
        drop(store);
        let (mut store, mut compacted, _) = load(&path);
        // A pose changed since the registration: the snapshot has the new one.
        compacted.objects[2].pose.translation = [5.0, 6.0, 7.0];
        store.write(&compacted).expect("compaction");
        assert_eq!(store.log_len(), LOG_HEADER_LEN as u64, "log emptied");
        std::fs::write(store.log_path(), &old_log).expect("as if never emptied");
        drop(store);
        let (_, snapshot, log) = load(&path);
        assert_eq!(snapshot, compacted);
        assert_eq!(snapshot.next_index, compacted.next_index);
        assert_eq!(log.error, None);
        // Only the object registered and removed within the log comes and
        // goes again; every other record is skipped.
        assert_eq!((log.applied, log.skipped), (2, 4));
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// An id the log names keeps the counter above it even when its object
    /// is gone again, so it is never handed out twice.
    #[test]
    fn replay_keeps_the_counter_above_every_id_named() {
        let mut s = sample();
        s.next_index = 2; // an older counter than object 7 needs...
        s.objects.truncate(1); // ...so drop object 7 to keep it valid
        let log = log_of(&[
            Change::Register(object(20, 5, Some("t"))),
            Change::Remove(sid(20)),
        ])
        .0;
        let r = replay_log(&mut s, &log);
        assert_eq!((r.applied, r.error), (2, None));
        assert_eq!(s.next_index, 21, "id 20 is never handed out again");
        assert_eq!(s.objects.len(), 1);
    }

    /// What the checksums cannot catch: records the server would never
    /// write are refused with the snapshot's own checks, and records valid
    /// alone but clashing together leave the snapshot untouched.
    #[test]
    fn invalid_or_inconsistent_records_are_refused() {
        let mut bad_shape = object(9, 1, None);
        if let StoredShape::Convex(c) = &mut bad_shape.shape {
            c.vertices.clear();
        }
        let mut bad_pose = object(9, 1, None);
        bad_pose.pose.rotation = [0.0; 4];
        let mut other_epoch = object(9, 1, None);
        other_epoch.id ^= 1 << 40;
        let mut changed = sample().objects[0].clone();
        changed.slot = 6;
        let cases: Vec<Vec<Change>> = vec![
            vec![Change::Register(bad_shape)],
            vec![Change::Register(bad_pose)],
            vec![Change::Register(other_epoch)],
            vec![Change::Register(object(9, MAX_SLOTS, None))],
            vec![Change::Register(object(u32::MAX, 1, None))],
            vec![Change::Register(object(9, 1, Some("")))],
            vec![Change::Register(changed)],
            vec![Change::Remove(sid(7) ^ (1 << 40))],
        ];
        for (i, case) in cases.iter().enumerate() {
            let mut records = vec![Change::Register(object(8, 2, None))];
            records.extend(case.iter().cloned());
            let (bytes, starts) = log_of(&records);
            let mut s = sample();
            let r = replay_log(&mut s, &bytes);
            assert!(
                matches!(r.error, Some(LogError::Invalid { offset, .. }) if offset == starts[1] as u64),
                "case {i}: {:?}",
                r.error
            );
            assert_eq!(
                s,
                reference(&records[..1]),
                "case {i}: the good record is kept"
            );
        }
        // Checksummed garbage.
        let mut bytes = log_header(sample().epoch).to_vec();
        let payload = [0xFFu8; 5];
        bytes.extend(5u32.to_le_bytes());
        bytes.extend(crc32fast::hash(&payload).to_le_bytes());
        let head = crc32fast::hash(&bytes[LOG_HEADER_LEN..]);
        bytes.extend(head.to_le_bytes());
        bytes.extend(payload);
        let r = replay_log(&mut sample(), &bytes);
        assert!(matches!(r.error, Some(LogError::Invalid { .. })), "{r:?}");
        // Two objects named alike, or in one slot.
        for clash in [object(9, 1, Some("cube")), object(9, 3, None)] {
            let mut s = sample();
            let r = replay_log(&mut s, &log_of(&[Change::Register(clash)]).0);
            assert!(matches!(r.error, Some(LogError::Inconsistent(_))), "{r:?}");
            assert_eq!((s, r.applied), (sample(), 0), "nothing taken");
        }
        // Another store's log.
        let mut bytes = log_of(&changes()).0;
        bytes[12] ^= 1;
        let mut s = sample();
        let r = replay_log(&mut s, &bytes);
        assert!(matches!(r.error, Some(LogError::Header(_))), "{r:?}");
        assert_eq!(s, sample());
    }

    /// A log whose state file is missing or corrupt cannot be applied: it is
    /// set aside, not replayed onto an empty store and not deleted.
    #[test]
    fn a_log_without_its_state_file_is_set_aside() {
        let dir = scratch("orphan");
        let path = dir.join("x.objects");
        let (bytes, _) = log_of(&changes());
        for spoil_state in [true, false] {
            let mut store = Store::open(&path).expect("store");
            store.write(&sample()).expect("write");
            std::fs::write(store.log_path(), &bytes).expect("log");
            if spoil_state {
                std::fs::write(&path, b"GJKDOBJS").expect("spoil");
            } else {
                std::fs::remove_file(&path).expect("rm");
            }
            let log = match store.load_or_quarantine().expect("load") {
                Loaded::Corrupt { log, .. } if spoil_state => {
                    assert_eq!(log.error, Some(LogError::StateCorrupt));
                    log
                }
                Loaded::Missing { log } if !spoil_state => {
                    assert_eq!(log.error, Some(LogError::Orphan));
                    log
                }
                other => panic!("{other:?}"),
            };
            let aside = log.moved_to.expect("set aside");
            assert_eq!(std::fs::read(aside).expect("kept"), bytes);
            assert!(!store.log_path().exists());
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn default_path_follows_xdg() {
        // Only the shape of the path: the environment belongs to the test
        // harness and is not changed here.
        if let Some(p) = default_path("a/b") {
            assert!(p.ends_with("gjkd/a_b.objects"), "{}", p.display());
        }
    }
}
