//! The error codes of the wire: one per way a request or an item fails.

use std::fmt;

/// What went wrong with one item or one request.
///
/// `Ok` is 0, so an all-zero [`ItemResult`](crate::ItemResult) (its `Default`) reads as a
/// successful pose update: trust only results the server wrote. The client's
/// `query_batch` overwrites one result per item it sends and leaves the rest
/// of the buffer alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum ErrorCode {
    /// No error.
    Ok = 0,
    /// An object id names no registered object (never registered, removed, or
    /// registered with a server that has since restarted).
    UnknownObject = 1,
    /// A pose or piece offset has a NaN or infinite component or a
    /// translation component beyond 2^998 (about 2.68e300,
    /// [`MAX_TRANSLATION`](crate::MAX_TRANSLATION)), a piece reaches beyond
    /// about 5e300 from its object's origin, or a query's two objects lie
    /// more than about 1e301 apart: gjk's arithmetic could overflow.
    NonFinitePose = 2,
    /// A rotation quaternion is off unit length by more than 1e-6.
    BadQuaternion = 3,
    /// A query option is out of its domain (negative or NaN tolerance, zero
    /// iteration cap, NaN margin).
    InvalidOptions = 4,
    /// A shape has no vertices.
    EmptyVertices = 5,
    /// A shape has more vertices than the server accepts.
    TooManyVertices = 6,
    /// A radius is negative, NaN, infinite, or above 2^999 (about 5e300);
    /// also a cylinder's radius or half-height, or its whole reach
    /// (`hypot(r, h)` plus rounding) above 2^999.
    InvalidRadius = 7,
    /// A batch has more items than the server accepts.
    BatchTooLarge = 8,
    /// A batch has no items.
    EmptyBatch = 9,
    /// A field has a value no client should send (unknown item kind or
    /// operation, inconsistent counts, bad UTF-8 in a name, a registration
    /// token reused for another shape or name).
    Malformed = 10,
    /// The object belongs to another client.
    NotOwner = 11,
    /// The object was loaded from the server's scene file: anyone may move
    /// it (set its pose), nobody may remove it.
    ReadOnly = 12,
    /// A compound has more pieces than [`MAX_PIECES`](crate::MAX_PIECES).
    TooManyPieces = 13,
    /// A compound has no pieces.
    EmptyCompound = 14,
    /// A vertex has a NaN or infinite coordinate, or the shape (vertices
    /// plus rounding radius) reaches beyond 2^999, about 5e300, from its body
    /// origin, where queries could overflow.
    NonFiniteVertex = 15,
    /// No object has this name.
    UnknownName = 16,
    /// Another object already has this name.
    NameTaken = 17,
    /// The server holds as many objects as it accepts.
    TooManyObjects = 18,
    /// The server failed in a way that is its own fault; it keeps serving.
    Internal = 19,
    /// The server's disk has no room to store a registration or removal:
    /// the change was not made. Queries and pose updates are still served;
    /// the same request succeeds once there is room again, without a
    /// server restart.
    StorageFull = 20,
    /// A joint position is outside its joint's limits (and the item did not
    /// ask for clamping, [`item_flags::CLAMP`](crate::item_flags::CLAMP)).
    OutOfLimits = 21,
    /// A robot's URDF is malformed, or its links do not form one tree of
    /// fixed, revolute, continuous and prismatic joints.
    InvalidRobot = 22,
}

impl ErrorCode {
    /// Every code, in wire order.
    pub const ALL: [ErrorCode; 23] = [
        ErrorCode::Ok,
        ErrorCode::UnknownObject,
        ErrorCode::NonFinitePose,
        ErrorCode::BadQuaternion,
        ErrorCode::InvalidOptions,
        ErrorCode::EmptyVertices,
        ErrorCode::TooManyVertices,
        ErrorCode::InvalidRadius,
        ErrorCode::BatchTooLarge,
        ErrorCode::EmptyBatch,
        ErrorCode::Malformed,
        ErrorCode::NotOwner,
        ErrorCode::ReadOnly,
        ErrorCode::TooManyPieces,
        ErrorCode::EmptyCompound,
        ErrorCode::NonFiniteVertex,
        ErrorCode::UnknownName,
        ErrorCode::NameTaken,
        ErrorCode::TooManyObjects,
        ErrorCode::Internal,
        ErrorCode::StorageFull,
        ErrorCode::OutOfLimits,
        ErrorCode::InvalidRobot,
    ];

    /// The code with wire value `raw`, or `None` for a value this version does
    /// not know.
    pub fn from_raw(raw: u32) -> Option<Self> {
        Self::ALL.get(raw as usize).copied()
    }

    /// The wire value.
    pub const fn raw(self) -> u32 {
        self as u32
    }

    /// A short description.
    pub fn describe(self) -> &'static str {
        match self {
            ErrorCode::Ok => "ok",
            ErrorCode::UnknownObject => "unknown object id",
            ErrorCode::NonFinitePose => "pose is not finite, or beyond 2.68e300",
            ErrorCode::BadQuaternion => "rotation quaternion is not of unit length",
            ErrorCode::InvalidOptions => "invalid query options",
            ErrorCode::EmptyVertices => "empty vertex set",
            ErrorCode::TooManyVertices => "too many vertices",
            ErrorCode::InvalidRadius => "radius is not a number from 0 to 5e300",
            ErrorCode::BatchTooLarge => "batch too large",
            ErrorCode::EmptyBatch => "empty batch",
            ErrorCode::Malformed => "malformed request",
            ErrorCode::NotOwner => "object belongs to another client",
            ErrorCode::ReadOnly => "object is read-only",
            ErrorCode::TooManyPieces => "too many compound pieces",
            ErrorCode::EmptyCompound => "compound with no pieces",
            ErrorCode::NonFiniteVertex => "vertex is not finite",
            ErrorCode::UnknownName => "no object has this name",
            ErrorCode::NameTaken => "name already taken",
            ErrorCode::TooManyObjects => "server object limit reached",
            ErrorCode::Internal => "internal server error",
            ErrorCode::StorageFull => "no room on the server's disk to store the change",
            ErrorCode::OutOfLimits => "joint position outside its limits",
            ErrorCode::InvalidRobot => "malformed URDF or unsupported kinematic tree",
        }
    }
}

impl fmt::Display for ErrorCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.describe())
    }
}

impl std::error::Error for ErrorCode {}

impl From<gjk::Error> for ErrorCode {
    /// The wire code of a `gjk` error (a warm start out of range cannot
    /// come from a client: ids are never reused).
    fn from(e: gjk::Error) -> Self {
        match e {
            gjk::Error::EmptyVertices => ErrorCode::EmptyVertices,
            gjk::Error::TooManyVertices(_) => ErrorCode::TooManyVertices,
            gjk::Error::NonFiniteVertex(_) => ErrorCode::NonFiniteVertex,
            gjk::Error::InvalidRadius(_) => ErrorCode::InvalidRadius,
            gjk::Error::EmptyCompound => ErrorCode::EmptyCompound,
            gjk::Error::NonFinitePose => ErrorCode::NonFinitePose,
            gjk::Error::InvalidOption(_) => ErrorCode::InvalidOptions,
            gjk::Error::WarmStartOutOfRange => ErrorCode::Internal,
        }
    }
}
