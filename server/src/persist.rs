//! Persistence of registered objects: the state file that lets objects
//! survive a server crash with their exact ids.
//!
//! # Format (version 1)
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
//! # Writing
//!
//! Every write replaces the whole file atomically: the snapshot goes to a
//! temporary file in the same directory, which is fsynced, renamed over the
//! state file, and then the directory is fsynced so the rename itself is
//! durable. A reader (the next server start) sees either the old file or the
//! new one, never a mix. The server writes before it acknowledges a
//! registration or a removal, so an acknowledged change survives `kill -9`
//! and a power cut alike.
//!
//! # Reading
//!
//! A file that fails any check (magic, version, length, checksum, postcard
//! decoding, or the geometry and id checks of [`Snapshot::validate`]) is
//! never loaded in part: [`load_or_quarantine`] renames it aside to
//! `<file>.corrupt-<unix seconds>` and the server starts empty.

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::os::unix::fs::{DirBuilderExt, OpenOptionsExt};
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
    /// store's epoch and lies below the counter, that ids and names are
    /// unique, and that every shape and pose passes the registration checks.
    ///
    /// # Errors
    /// A description of the first problem.
    pub fn validate(&self) -> Result<(), String> {
        if self.epoch == 0 {
            return Err("epoch 0".into());
        }
        let mut ids = std::collections::HashSet::new();
        let mut names = std::collections::HashSet::new();
        let mut slots = std::collections::HashSet::new();
        for o in &self.objects {
            // Slots are reused after removals, so they stay below the peak
            // number of objects; one past MAX_SLOTS could only come from a
            // buggy writer, and would size the journal absurdly.
            if o.slot >= MAX_SLOTS || !slots.insert(o.slot) {
                return Err(format!("bad or repeated journal slot {}", o.slot));
            }
            let (epoch, index) = ((o.id >> 32) as u32, o.id as u32);
            if epoch != self.epoch || index == 0 || index >= self.next_index {
                return Err(format!("id {:#x} outside this store", o.id));
            }
            if !ids.insert(o.id) {
                return Err(format!("id {:#x} twice", o.id));
            }
            if let Some(name) = &o.name
                && (name.is_empty()
                    || name.len() > gjkd_proto::MAX_NAME_LEN
                    || !names.insert(name.as_str()))
            {
                return Err(format!("bad or repeated name {name:?}"));
            }
            o.pose
                .to_isometry()
                .ok_or_else(|| format!("bad pose of {:#x}", o.id))?;
            o.shape
                .to_shape()
                .map_err(|e| format!("object {:#x}: {e}", o.id))?;
        }
        Ok(())
    }
}

/// Where and how the server keeps its state file.
#[derive(Debug)]
pub struct Store {
    path: PathBuf,
    tmp: PathBuf,
    /// `<file>.lock`, held (`flock`) for the store's life: two servers on
    /// one state file would overwrite each other's objects. The kernel
    /// drops the lock when the process dies, `kill -9` included.
    _lock: File,
}

/// Why a state file could not be written or read.
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
    /// The snapshot could not be encoded.
    #[error("cannot encode the state: {0}")]
    Encode(String),
}

fn io(what: &'static str, path: &Path) -> impl FnOnce(std::io::Error) -> StoreError {
    let path = path.to_path_buf();
    move |source| StoreError::Io { what, path, source }
}

/// What [`load_or_quarantine`] found.
#[derive(Debug)]
pub enum Loaded {
    /// No state file: a first start.
    Missing,
    /// A valid file.
    Snapshot(Snapshot),
    /// A file that failed a check; it was renamed to `moved_to`.
    Corrupt {
        /// Why it was refused.
        reason: FormatError,
        /// Where it now is.
        moved_to: PathBuf,
    },
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
            path,
            tmp: tmp.into(),
            _lock: lock,
        })
    }

    /// The state file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Replaces the state file with `snapshot`: write a temporary file,
    /// fsync it, rename it over the state file, fsync the directory.
    ///
    /// # Errors
    /// The first step that fails; the old file is then still intact.
    pub fn write(&self, snapshot: &Snapshot) -> Result<(), StoreError> {
        let bytes = snapshot.encode().map_err(StoreError::Encode)?;
        self.write_bytes(&bytes)
    }

    /// [`Store::write`] of ready-made file bytes.
    ///
    /// # Errors
    /// As [`Store::write`].
    pub fn write_bytes(&self, bytes: &[u8]) -> Result<(), StoreError> {
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
            std::fs::rename(&self.tmp, &self.path).map_err(io("cannot rename to", &self.path))?;
            sync_dir(&self.path)
        })();
        if result.is_err() {
            let _ = std::fs::remove_file(&self.tmp);
        }
        result
    }

    /// Reads the state file. A missing file is [`Loaded::Missing`]; one that
    /// fails any check is renamed aside and reported as [`Loaded::Corrupt`].
    ///
    /// # Errors
    /// When the file exists but cannot be read at all (permissions, I/O):
    /// the server must not start empty and then overwrite it.
    pub fn load_or_quarantine(&self) -> Result<Loaded, StoreError> {
        load_or_quarantine(&self.path)
    }
}

/// See [`Store::load_or_quarantine`].
///
/// # Errors
/// As [`Store::load_or_quarantine`].
pub fn load_or_quarantine(path: &Path) -> Result<Loaded, StoreError> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Loaded::Missing),
        Err(e) => return Err(io("cannot read", path)(e)),
    };
    match Snapshot::decode(&bytes) {
        Ok(s) => Ok(Loaded::Snapshot(s)),
        Err(reason) => {
            let secs = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_secs())
                .unwrap_or(0);
            // Never over an earlier corrupt file of the same second.
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
            // If it cannot be moved, starting empty would overwrite it at
            // the first registration: refuse to start instead.
            std::fs::rename(path, &aside).map_err(|e| StoreError::Io {
                what: "cannot set aside the corrupt state file",
                path: path.to_path_buf(),
                source: std::io::Error::new(e.kind(), format!("{reason}; rename failed: {e}")),
            })?;
            Ok(Loaded::Corrupt {
                reason,
                moved_to: aside,
            })
        }
    }
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
        let store = Store::open(&path).expect("dir");
        assert!(!dir.join("sub").join("x.objects.tmp-999999").exists());
        assert!(matches!(store.load_or_quarantine(), Ok(Loaded::Missing)));
        store.write(&sample()).expect("write");
        let mode = std::fs::metadata(&path).expect("file").permissions().mode();
        assert_eq!(mode & 0o777, 0o600);
        let dmode = std::fs::metadata(path.parent().expect("dir"))
            .expect("dir")
            .permissions()
            .mode();
        assert_eq!(dmode & 0o777, 0o700);
        match store.load_or_quarantine().expect("read") {
            Loaded::Snapshot(s) => assert_eq!(s, sample()),
            other => panic!("{other:?}"),
        }
        // No temporary file is left behind: the state file and the lock.
        let mut names: Vec<_> = std::fs::read_dir(path.parent().expect("dir"))
            .expect("list")
            .map(|e| e.expect("entry").file_name())
            .collect();
        names.sort();
        assert_eq!(names, ["x.objects", "x.objects.lock"], "{names:?}");
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
            } => {
                assert!(aside.to_string_lossy().contains(".corrupt-"));
                assert_eq!(std::fs::read(&aside).expect("kept"), bytes);
            }
            other => panic!("{other:?}"),
        }
        assert!(!path.exists(), "the corrupt file was moved, not left");
        assert!(matches!(store.load_or_quarantine(), Ok(Loaded::Missing)));
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
