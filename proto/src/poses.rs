//! The pose service: the stored poses of a list of objects, read back.

use iceoryx2::prelude::ZeroCopySend;

use crate::{ErrorCode, Pose};

/// One object's stored pose, the answer to one id of a pose request
/// (`[u64]` object ids, answered by a [`PosesReply`] header and one
/// `StoredPose` per id, in order). For a robot's link object it is the
/// link pose the server computed from the robot's last joint positions
/// and base.
#[derive(Clone, Copy, Debug, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.StoredPose")]
pub struct StoredPose {
    /// The object asked about.
    pub id: u64,
    /// [`ErrorCode`] wire value: [`ErrorCode::UnknownObject`] for an id
    /// the server does not hold (the other ids are answered all the same).
    pub error: u32,
    /// Zero.
    pub reserved: u32,
    /// The stored pose, bit for bit as the server holds it (the identity
    /// when `error` is not 0).
    pub pose: Pose,
}

impl StoredPose {
    /// The pose, or the error code.
    pub fn pose(&self) -> Result<Pose, ErrorCode> {
        match ErrorCode::from_raw(self.error) {
            Some(ErrorCode::Ok) => Ok(self.pose),
            Some(code) => Err(code),
            None => Err(ErrorCode::Malformed),
        }
    }
}

/// The header of the pose service's answer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.PosesReply")]
pub struct PosesReply {
    /// [`ErrorCode`] wire value for the request as a whole:
    /// [`ErrorCode::EmptyBatch`] for no id, [`ErrorCode::BatchTooLarge`]
    /// for more than the server's `max_batch`; then no entry is answered.
    pub error: u32,
    /// Entries answered (the number of ids, when `error` is 0).
    pub count: u32,
}
