//! What the object store asks of whatever keeps its objects across a crash:
//! registrations and removals committed before they are acknowledged, poses
//! written where a crash of the process cannot lose them. The engine holds
//! no file; the persistence layer ([`crate::persist`]) implements this over
//! its database and pose journal, and a store without it keeps everything
//! in memory only.

use nalgebra::Isometry3;

use super::records::{Snapshot, StoredObject};
use super::tokens::TokenKey;

/// Why a change could not be made durable.
#[derive(Debug, thiserror::Error)]
pub enum CommitError {
    /// The disk has no room for it: the client is told
    /// [`StorageFull`](gjkd_proto::ErrorCode::StorageFull) and may retry
    /// once there is room.
    #[error("{0}")]
    Full(Box<dyn std::error::Error + Send + Sync>),
    /// Anything else.
    #[error("{0}")]
    Failed(Box<dyn std::error::Error + Send + Sync>),
}

/// Where the object store makes its changes durable (see
/// [`ObjectStore::set_durability`](super::objects::ObjectStore::set_durability)).
pub trait Durability: std::fmt::Debug + Send {
    /// Commits a registered object with the id counter after it, and its
    /// registration token (with the token it pushes out), all or nothing.
    ///
    /// # Errors
    /// When it cannot be committed; nothing of it is kept then.
    fn register(
        &mut self,
        object: &StoredObject,
        next_index: u32,
        token: Option<(TokenKey, Option<TokenKey>)>,
    ) -> Result<(), CommitError>;

    /// Commits the removal of objects `ids` and of their registration
    /// `tokens`, all or nothing.
    ///
    /// # Errors
    /// When it cannot be committed; none is removed then.
    fn remove(&mut self, ids: &[u64], tokens: &[TokenKey]) -> Result<(), CommitError>;

    /// Makes what is kept exactly `snapshot`, current poses included.
    ///
    /// # Errors
    /// When it cannot be committed; what is kept is as it was then.
    fn sync(&mut self, snapshot: &Snapshot) -> Result<(), CommitError>;

    /// Records the latest `pose` of object `id`, in its journal `slot`.
    ///
    /// # Errors
    /// The OS error (no room to grow the journal).
    fn write_pose(&mut self, slot: u32, id: u64, pose: &Isometry3<f64>) -> std::io::Result<()>;

    /// Puts the recorded poses on disk (only a machine crash needs it).
    ///
    /// # Errors
    /// The OS error.
    fn flush_poses(&mut self) -> std::io::Result<()>;
}
