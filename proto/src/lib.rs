//! # gjkd-proto
//!
//! The wire types of gjkd. Every message is a `#[repr(C)]` struct that lives in
//! iceoryx2 shared memory as it is: no serialisation on the hot path. Each type
//! carries an explicit iceoryx2 `type_name` (the default would include the Rust
//! module path, so the same struct seen from another crate would not match),
//! and every service name carries the protocol version.
//!
//! Five services make up one gjkd deployment named `service` (default
//! [`DEFAULT_SERVICE`]):
//!
//! | service name | pattern | request | response |
//! |---|---|---|---|
//! | [`query_service_name`] `{service}/v4/query` | request-response | `[`[`Item`]`]` | [`ReplyHeader`] + `[`[`ReplyEntry`]`]` (results, then gradients) |
//! | [`admin_service_name`] `{service}/v4/admin` | request-response | [`AdminRequest`] + `[`[`AdminChunk`]`]` | [`AdminReply`] |
//! | [`scene_service_name`] `{service}/v4/scene` | request-response | [`SceneRequest`] + `[`[`Item`]`]` | [`SceneReply`] + `[`[`SceneRow`]`]` |
//! | [`poses_service_name`] `{service}/v4/poses` | request-response | `[u64]` (object ids) | [`PosesReply`] + `[`[`StoredPose`]`]` |
//! | [`wake_service_name`] `{service}/v4/wake` | event | | |
//!
//! Integers that encode a choice ([`Item::kind`], [`ItemResult::error`], ...)
//! are plain `u32` on the wire, never Rust enums: any bit pattern a client
//! writes must be a valid value of the type, so that the server can read
//! arbitrary bytes without undefined behaviour. The typed views
//! ([`ErrorCode`], [`Status`], [`ItemKind`], ...) are decoded from them.
//!
//! Most programs should use the `gjkd-client` crate rather than these types
//! directly; the batch API of the client takes [`Item`] and fills
//! [`ItemResult`], so their builders and accessors are documented here.
//!
//! ```
//! use gjkd_proto::{Item, ObjectId, QueryOptions};
//! use nalgebra::Isometry3;
//!
//! let a = ObjectId::from_raw(0x1_0000_0001);
//! let b = ObjectId::from_raw(0x1_0000_0002);
//! let items = [
//!     Item::set_pose(a, &Isometry3::translation(1.0, 0.0, 0.0)),
//!     Item::distance(a, b, &QueryOptions::default()),
//! ];
//! assert_eq!(items[1].object_a(), a);
//! ```

#![warn(missing_docs)]

use std::fmt;

mod admin;
mod admin_payload;
mod error;
mod geometry;
mod gradient;
mod item;
mod item_body;
mod pose;
mod poses;
mod reply_entry;
mod result;
mod scene;
mod shape;

pub use admin::{
    AdminOp, AdminReply, AdminRequest, ServerInfo, ServerStats, WaitMode, lookup_kind,
};
pub use admin_payload::{AdminChunk, TEXT_CHUNK_LEN};
pub use error::ErrorCode;
pub use geometry::{
    Geometry, Piece, ShapeError, cuboid_corners, cylinder, decode_piece, decode_shape, hull,
};
pub use gradient::{GRADIENT_COLUMNS, Gradient, gradient_flags};
pub use item::{Item, ItemKind, Precision, QueryOptions, item_flags};
pub use item_body::{ItemBody, JointsBody, PairBody};
pub use pose::{MAX_TRANSLATION, Pose, UNIT_TOLERANCE};
pub use poses::{PosesReply, StoredPose};
pub use reply_entry::{GradientRow, ReplyEntry};
pub use result::{Answer, ItemResult, ReplyHeader, SignedDistance, Status, result_flags};
pub use scene::{
    DEFAULT_BRACKET, PathMode, SceneKind, SceneReply, SceneRequest, SceneRow, scene_flags,
    scene_reply_flags,
};
pub use shape::{PieceDesc, Vertex, piece_kind, shape_kind};

/// Protocol version, part of every service name: a client and a server of
/// different versions never see each other's services, instead of misreading
/// each other's bytes (a client that finds only another version's services
/// reports a version mismatch). Version 2 named every field for what it
/// holds: registration tokens, removed objects, lookup kinds and cylinder
/// dimensions have fields of their own. Version 3 types the rest: an
/// item's body is a pair view or a joints view ([`ItemBody`]), robot text
/// travels as bytes ([`AdminChunk`]), results carry the signed distance
/// and the gradient, scene requests the continuous mode and its bracket,
/// and stored poses are read back on a service of their own. Version 4
/// takes the gradient out of every result: a query reply's gradients
/// travel after its results, only for the items that ask
/// ([`ReplyEntry`], [`GradientRow`]), and a scene row's beside its result
/// ([`SceneRow::gradient`]).
pub const PROTOCOL_VERSION: u32 = 4;

/// Service name used when none is given: `"gjkd"`.
pub const DEFAULT_SERVICE: &str = "gjkd";

/// Default relative tolerance of a query: 100 × machine epsilon (about
/// 2.2e-14), as in the paper and the `gjk` crate.
pub const DEFAULT_TOLERANCE: f64 = 100.0 * f64::EPSILON;

/// Default iteration cap of a query: 128, as in the `gjk` crate.
pub const DEFAULT_MAX_ITERATIONS: u32 = 128;

/// Most pieces a compound may have: the piece table travels in the fixed-size
/// header of a registration (`AdminRequest`, in `gjkd-proto`).
pub const MAX_PIECES: usize = 64;

/// Most joint positions one [`ItemKind::SetJoints`] item carries.
pub const JOINTS_PER_ITEM: usize = 9;

/// Longest object name in bytes (UTF-8).
pub const MAX_NAME_LEN: usize = 64;

/// Name of the query service of deployment `service`: `{service}/v4/query`.
pub fn query_service_name(service: &str) -> String {
    format!("{service}/v{PROTOCOL_VERSION}/query")
}

/// Name of the admin service (registration, removal, look-up, statistics).
pub fn admin_service_name(service: &str) -> String {
    format!("{service}/v{PROTOCOL_VERSION}/admin")
}

/// Name of the scene service (whole-scene questions: clearance, pairs
/// within a margin, nearest objects, paths).
pub fn scene_service_name(service: &str) -> String {
    format!("{service}/v{PROTOCOL_VERSION}/scene")
}

/// Name of the pose service (stored poses read back, a batch of ids at a
/// time).
pub fn poses_service_name(service: &str) -> String {
    format!("{service}/v{PROTOCOL_VERSION}/poses")
}

/// Name of the event service a client notifies after sending, so that a
/// server in `block` or `adaptive` mode wakes up.
pub fn wake_service_name(service: &str) -> String {
    format!("{service}/v{PROTOCOL_VERSION}/wake")
}

/// Identifier of a registered object. Ids are never reused by a server, and
/// carry a per-server-start epoch in their upper 32 bits, so an id from a
/// previous server run is reported as unknown instead of naming some other
/// object.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ObjectId(u64);

impl ObjectId {
    /// The id with the given wire value.
    pub const fn from_raw(raw: u64) -> Self {
        ObjectId(raw)
    }

    /// The wire value.
    pub const fn raw(self) -> u64 {
        self.0
    }
}

impl fmt::Display for ObjectId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:#x}", self.0)
    }
}

#[cfg(test)]
mod tests;
