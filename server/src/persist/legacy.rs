//! The store format of gjkd before the database (`GJKDOBJS` state file and
//! its `.log` change log), read once to migrate it into the database
//! ([`crate::persist::database`]). Only reading is kept; nothing writes this format.
//!
//! The state file is a 24-byte header (magic `GJKDOBJS`, version `u32` LE,
//! payload length `u64` LE, CRC-32 of the payload `u32` LE) and a postcard
//! [`Snapshot`]. The change log is a 16-byte header (magic `GJKDCLOG`,
//! version `u32` LE, the snapshot's epoch `u32` LE) and records: payload
//! length `u32` LE, payload CRC-32, CRC-32 of those 8 bytes, then a postcard
//! [`Change`].

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::engine::records::{Snapshot, StoredObject, check_object, check_unique};

/// First bytes of a state file of the old format.
pub const MAGIC: [u8; 8] = *b"GJKDOBJS";
const VERSION: u32 = 1;
const HEADER_LEN: usize = 24;
const LOG_MAGIC: [u8; 8] = *b"GJKDCLOG";
const LOG_HEADER_LEN: usize = 16;
const RECORD_HEADER_LEN: usize = 12;

/// One record of the old change log.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Change {
    /// An object was registered.
    Register(StoredObject),
    /// The object with this id was removed.
    Remove(u64),
}

/// The change log beside an old state file: `<state file>.log`.
pub fn log_path_for(state_file: &Path) -> PathBuf {
    let mut p = state_file.as_os_str().to_owned();
    p.push(".log");
    PathBuf::from(p)
}

/// Whether `bytes` start like an old state file.
pub fn is_legacy(bytes: &[u8]) -> bool {
    bytes.starts_with(&MAGIC)
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    let mut b = [0u8; 4];
    b.copy_from_slice(&bytes[at..at + 4]);
    u32::from_le_bytes(b)
}

/// Decodes and validates an old state file; all or nothing.
///
/// # Errors
/// What is wrong with it.
pub fn decode_snapshot(bytes: &[u8]) -> Result<Snapshot, String> {
    if bytes.len() < HEADER_LEN || !is_legacy(bytes) {
        return Err("not a gjkd state file of the old format".into());
    }
    let version = u32_at(bytes, 8);
    if version != VERSION {
        return Err(format!("old format version {version}, expected {VERSION}"));
    }
    let mut len = [0u8; 8];
    len.copy_from_slice(&bytes[12..20]);
    let payload = &bytes[HEADER_LEN..];
    if u64::from_le_bytes(len) != payload.len() as u64 {
        return Err("truncated or extended".into());
    }
    if crc32fast::hash(payload) != u32_at(bytes, 20) {
        return Err("checksum mismatch".into());
    }
    let snapshot: Snapshot = match postcard::take_from_bytes(payload) {
        Ok((s, [])) => s,
        Ok(_) => return Err("bytes after the snapshot".into()),
        Err(e) => return Err(format!("does not decode: {e}")),
    };
    snapshot.validate()?;
    Ok(snapshot)
}

/// What replaying an old change log did.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Replay {
    /// Records that changed the snapshot.
    pub applied: u64,
    /// Bytes at the end that did not form a whole record: an append that a
    /// crash cut short (never acknowledged), or a log cut short by damage,
    /// which cannot be told apart.
    pub torn: u64,
    /// Damage before the end of the log (or a wrong header): the records
    /// after it are lost.
    pub error: Option<String>,
}

/// Applies the old change log `log` to `snapshot`, as the old server did at
/// start: records up to the first that is damaged, each held to the checks
/// of a registration. A damaged last record is an append cut short by a
/// crash (never acknowledged); damage with data after it is reported in
/// [`Replay::error`], and the records before it are kept. Records already
/// in the snapshot (a compaction interrupted before the log was emptied)
/// change nothing. If the result breaks a rule of the store (a name or slot
/// twice), `snapshot` is left as it was and that is the error.
pub fn replay_log(snapshot: &mut Snapshot, log: &[u8]) -> Replay {
    let mut replay = Replay::default();
    if log.len() < LOG_HEADER_LEN || log.iter().all(|&b| b == 0) {
        replay.torn = log.len() as u64;
        return replay;
    }
    if log[..8] != LOG_MAGIC || u32_at(log, 8) != VERSION || u32_at(log, 12) != snapshot.epoch {
        replay.error = Some("bad header (magic, version or epoch)".into());
        return replay;
    }
    let mut objects: BTreeMap<u64, StoredObject> =
        snapshot.objects.iter().map(|o| (o.id, o.clone())).collect();
    let mut next_index = snapshot.next_index;
    let mut pos = LOG_HEADER_LEN;
    while pos < log.len() {
        let change = match next_record(log, pos) {
            Record::Whole(change, end) => {
                pos = end;
                change
            }
            Record::Torn => {
                replay.torn = (log.len() - pos) as u64;
                break;
            }
            Record::Bad(reason) => {
                replay.error = Some(format!("record at byte {pos}: {reason}"));
                break;
            }
        };
        if let Err(e) = apply(snapshot.epoch, &mut objects, &mut next_index, change) {
            replay.error = Some(format!("record before byte {pos}: {e}"));
            break;
        }
        replay.applied += 1;
    }
    if let Err(e) = check_unique(objects.values()) {
        replay.applied = 0;
        replay.error = Some(format!("the replayed objects clash: {e}"));
        return replay;
    }
    snapshot.objects = objects.into_values().collect();
    snapshot.next_index = next_index;
    replay
}

enum Record {
    /// A record and where the next one starts.
    Whole(Change, usize),
    /// The rest of the log is a record cut short.
    Torn,
    /// A record that is damaged with data after it, or impossible.
    Bad(String),
}

fn next_record(log: &[u8], pos: usize) -> Record {
    let rest = &log[pos..];
    if rest.len() < RECORD_HEADER_LEN {
        return Record::Torn;
    }
    if crc32fast::hash(&rest[..8]) != u32_at(rest, 8) {
        // Without a trustworthy length, only a zero-filled tail is surely
        // an append cut short.
        return if rest.iter().all(|&b| b == 0) {
            Record::Torn
        } else {
            Record::Bad("record header checksum mismatch".into())
        };
    }
    let len = u32_at(rest, 0) as usize;
    let end = RECORD_HEADER_LEN + len;
    if end > rest.len() {
        return Record::Torn;
    }
    let payload = &rest[RECORD_HEADER_LEN..end];
    if crc32fast::hash(payload) != u32_at(rest, 4) {
        return if end == rest.len() {
            Record::Torn
        } else {
            Record::Bad("payload checksum mismatch".into())
        };
    }
    match postcard::take_from_bytes::<Change>(payload) {
        Ok((change, [])) => Record::Whole(change, pos + end),
        Ok(_) => Record::Bad("bytes after the change".into()),
        Err(e) => Record::Bad(format!("does not decode: {e}")),
    }
}

fn apply(
    epoch: u32,
    objects: &mut BTreeMap<u64, StoredObject>,
    next_index: &mut u32,
    change: Change,
) -> Result<(), String> {
    match change {
        Change::Register(o) => {
            check_object(epoch, &o)?;
            *next_index = (*next_index).max(o.id as u32 + 1);
            match objects.get(&o.id) {
                // Already folded into the snapshot, whose pose is newer.
                Some(old)
                    if old.owner == o.owner
                        && old.name == o.name
                        && old.slot == o.slot
                        && old.shape == o.shape => {}
                Some(_) => return Err(format!("id {:#x} registered twice", o.id)),
                None => {
                    objects.insert(o.id, o);
                }
            }
        }
        Change::Remove(id) => {
            if (id >> 32) as u32 != epoch {
                return Err(format!("removal of id {id:#x} of another store"));
            }
            objects.remove(&id);
        }
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The bytes of an old state file holding `snapshot`.
    pub(crate) fn encode_snapshot(snapshot: &Snapshot) -> Vec<u8> {
        let payload = postcard::to_stdvec(snapshot).expect("encodes");
        let mut out = MAGIC.to_vec();
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
        out.extend_from_slice(&payload);
        out
    }

    /// The bytes of an old change log of `changes` for a snapshot of
    /// `epoch`, and where each record starts.
    pub(crate) fn encode_log(epoch: u32, changes: &[Change]) -> (Vec<u8>, Vec<usize>) {
        let mut out = LOG_MAGIC.to_vec();
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&epoch.to_le_bytes());
        let mut starts = Vec::new();
        for c in changes {
            starts.push(out.len());
            let payload = postcard::to_stdvec(c).expect("encodes");
            let head_start = out.len();
            out.extend_from_slice(&(payload.len() as u32).to_le_bytes());
            out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
            let head_crc = crc32fast::hash(&out[head_start..]);
            out.extend_from_slice(&head_crc.to_le_bytes());
            out.extend_from_slice(&payload);
        }
        (out, starts)
    }
}
