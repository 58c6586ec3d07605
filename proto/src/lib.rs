//! # gjkd-proto
//!
//! The wire types of gjkd. Every message is a `#[repr(C)]` struct that lives in
//! iceoryx2 shared memory as it is: no serialisation on the hot path. Each type
//! carries an explicit iceoryx2 `type_name` (the default would include the Rust
//! module path, so the same struct seen from another crate would not match),
//! and every service name carries the protocol version.
//!
//! Three services make up one gjkd deployment named `service` (default
//! [`DEFAULT_SERVICE`]):
//!
//! | service name | pattern | request | response |
//! |---|---|---|---|
//! | [`query_service_name`] `{service}/v1/query` | request-response | `[`[`Item`]`]` | [`ReplyHeader`] + `[`[`ItemResult`]`]` |
//! | [`admin_service_name`] `{service}/v1/admin` | request-response | [`AdminRequest`] + `[`[`Vertex`]`]` | [`AdminReply`] |
//! | [`scene_service_name`] `{service}/v1/scene` | request-response | [`SceneRequest`] + `[`[`Item`]`]` | [`SceneReply`] + `[`[`SceneRow`]`]` |
//! | [`wake_service_name`] `{service}/v1/wake` | event | | |
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

use iceoryx2::prelude::ZeroCopySend;
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};

mod scene;

pub use scene::{
    PathMode, SceneKind, SceneReply, SceneRequest, SceneRow, scene_flags, scene_reply_flags,
};

/// Protocol version, part of every service name: a client and a server of
/// different versions never see each other's services, instead of misreading
/// each other's bytes.
pub const PROTOCOL_VERSION: u32 = 1;

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

/// Name of the query service of deployment `service`: `{service}/v1/query`.
pub fn query_service_name(service: &str) -> String {
    format!("{service}/v{PROTOCOL_VERSION}/query")
}

/// Name of the admin service (registration, removal, look-up, statistics).
pub fn admin_service_name(service: &str) -> String {
    format!("{service}/v{PROTOCOL_VERSION}/admin")
}

/// Name of the scene service (whole-scene questions: clearance, pairs
/// within a margin, nearest objects, paths), added within v1: a server older
/// than it has no such service, and a client finds none to open.
pub fn scene_service_name(service: &str) -> String {
    format!("{service}/v{PROTOCOL_VERSION}/scene")
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

/// What went wrong with one item or one request.
///
/// `Ok` is 0, so an all-zero [`ItemResult`] (its `Default`) reads as a
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
    /// A pose or piece offset has a NaN or infinite component, a piece
    /// reaches beyond about 5e300 from its object's origin, or a query's two
    /// objects lie more than about 1e301 apart: gjk's arithmetic could
    /// overflow.
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
    /// A compound has more pieces than [`MAX_PIECES`].
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
    /// ask for clamping, [`item_flags::CLAMP`]).
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
            ErrorCode::NonFinitePose => "pose is not finite, or beyond 1e301",
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

/// How a query ended; the wire values of [`ItemResult::status`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum Status {
    /// The stopping rule held: the distance is exact to the tolerance.
    Converged = 1,
    /// Early exit: the distance is proved greater than the margin.
    Farther = 2,
    /// Early exit: the distance is proved at most the margin.
    Closer = 3,
    /// The iteration cap was reached first; the bounds still hold.
    IterationCap = 4,
    /// Round-off stopped progress before the tolerance was met; the bounds
    /// still hold.
    ToleranceNotMet = 5,
    /// Scene requests only: answered without running GJK, from the pair's
    /// last certified interval widened by how far either object can have
    /// moved since; the interval holds, the distance and points are the last
    /// answer's carried with the objects (see
    /// [`scene_flags::MOTION_BOUNDS`]).
    Bounded = 6,
}

impl Status {
    /// The status with wire value `raw`, if any (0 is "no answer", for items
    /// that failed or were pose updates).
    pub fn from_raw(raw: u32) -> Option<Self> {
        match raw {
            1 => Some(Status::Converged),
            2 => Some(Status::Farther),
            3 => Some(Status::Closer),
            4 => Some(Status::IterationCap),
            5 => Some(Status::ToleranceNotMet),
            6 => Some(Status::Bounded),
            _ => None,
        }
    }

    /// The wire value.
    pub const fn raw(self) -> u32 {
        self as u32
    }
}

/// What an [`Item`] asks for; the wire values of [`Item::kind`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum ItemKind {
    /// Store a new pose for an object (used by every later query that does not
    /// give its own pose).
    SetPose = 1,
    /// Distance between two objects.
    Distance = 2,
    /// Set a robot's joint positions (and optionally its base pose): the
    /// server computes every link's pose by forward kinematics and stores
    /// them. See [`Item::set_joints`] for the layout.
    SetJoints = 3,
    /// Scene requests only: object `a` is a member of the request's group
    /// (when [`SceneRequest::group`] is 0).
    Member = 4,
    /// Scene requests only: the pair `a`, `b` is never reported (an allowed
    /// pair, on top of a robot's own).
    Allow = 5,
    /// Scene requests only: ends one step of a path.
    Step = 6,
}

impl ItemKind {
    /// The kind with wire value `raw`, if any.
    pub fn from_raw(raw: u32) -> Option<Self> {
        match raw {
            1 => Some(ItemKind::SetPose),
            2 => Some(ItemKind::Distance),
            3 => Some(ItemKind::SetJoints),
            4 => Some(ItemKind::Member),
            5 => Some(ItemKind::Allow),
            6 => Some(ItemKind::Step),
            _ => None,
        }
    }
}

/// Bits of [`Item::flags`].
pub mod item_flags {
    /// The item's own `pose_a` replaces the stored pose of object A for this
    /// query only.
    pub const POSE_A: u32 = 1;
    /// The item's own `pose_b` replaces the stored pose of object B for this
    /// query only.
    pub const POSE_B: u32 = 1 << 1;
    /// `margin` is set: stop early once the distance is proved above or below
    /// it.
    pub const MARGIN: u32 = 1 << 2;
    /// Start from the server's cached simplex of this pair (for this client).
    pub const WARM_START: u32 = 1 << 3;
    /// Search support points in f32 ([`Precision::Single`](crate::Precision::Single)). Added within
    /// v1 (the layout is unchanged): a server older than this bit refuses it
    /// as malformed rather than silently answering in f64.
    pub const SINGLE_PRECISION: u32 = 1 << 4;
    /// For [`super::ItemKind::SetJoints`]: clamp positions outside their
    /// limits instead of refusing the item. Added within v1, like
    /// `SINGLE_PRECISION`.
    pub const CLAMP: u32 = 1 << 5;
    /// Scene paths only: a [`super::ItemKind::SetPose`] or
    /// [`super::ItemKind::SetJoints`] item with this bit also ends its path
    /// step, as a [`super::ItemKind::Step`] item after it would. A path's
    /// steps then take one item fewer each, which is what a long path's
    /// round trip is made of. Refused as malformed on any other item and
    /// outside a path. Added within v1, like `SINGLE_PRECISION`.
    pub const END_STEP: u32 = 1 << 6;
    /// Every bit this version knows; others are rejected as malformed.
    pub const ALL: u32 =
        POSE_A | POSE_B | MARGIN | WARM_START | SINGLE_PRECISION | CLAMP | END_STEP;
}

/// Bits of [`ItemResult::flags`].
pub mod result_flags {
    /// The query started from a cached simplex.
    pub const WARM_STARTED: u32 = 1;
    /// gjk's Backup Procedure ran (a sign of a numerically hard case).
    pub const BACKUP_USED: u32 = 1 << 1;
}

/// A rigid pose on the wire: translation and rotation quaternion `[i, j, k, w]`
/// (nalgebra's coordinate order), in f64.
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.Pose")]
pub struct Pose {
    /// Translation.
    pub translation: [f64; 3],
    /// Unit quaternion `[i, j, k, w]`.
    pub rotation: [f64; 4],
}

impl Pose {
    /// The identity pose.
    pub const IDENTITY: Pose = Pose {
        translation: [0.0; 3],
        rotation: [0.0, 0.0, 0.0, 1.0],
    };

    /// The wire form of `iso`, bit for bit.
    pub fn from_isometry(iso: &Isometry3<f64>) -> Self {
        let t = iso.translation.vector;
        let q = iso.rotation.coords;
        Pose {
            translation: [t.x, t.y, t.z],
            rotation: [q.x, q.y, q.z, q.w],
        }
    }

    /// The isometry with exactly these components. The quaternion is taken as
    /// it is, without normalising: check it first (the server does).
    pub fn to_isometry_unchecked(&self) -> Isometry3<f64> {
        let [x, y, z] = self.translation;
        let [i, j, k, w] = self.rotation;
        Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::new_unchecked(Quaternion::new(w, i, j, k)),
        )
    }
}

impl Default for Pose {
    fn default() -> Self {
        Pose::IDENTITY
    }
}

impl From<&Isometry3<f64>> for Pose {
    fn from(iso: &Isometry3<f64>) -> Self {
        Pose::from_isometry(iso)
    }
}

/// Per-query options, the client-side view of [`Item`]'s option fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueryOptions {
    /// Relative tolerance `ε` of the stopping rule, `>= 0` (default
    /// [`DEFAULT_TOLERANCE`]). Larger is faster and looser; the answer's bounds
    /// say by how much.
    pub tolerance: f64,
    /// Iteration cap, at least 1 (default [`DEFAULT_MAX_ITERATIONS`]).
    pub max_iterations: u32,
    /// Early exit: stop as soon as the distance is proved greater than this
    /// margin ([`Status::Farther`]) or at most it ([`Status::Closer`]).
    pub margin: Option<f64>,
    /// Start from the simplex the server kept for this pair after this
    /// client's previous query of it (default on). Changes only the time,
    /// never the answer beyond the tolerance.
    pub warm_start: bool,
    /// Arithmetic of the support search (default [`Precision::Double`]).
    pub precision: Precision,
}

/// Arithmetic of the support search, the step whose cost grows with the
/// number of vertices; the rest of a query is f64 whatever is chosen. The
/// wire form of `gjk::Precision`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Precision {
    /// f64: the distance is exact to the tolerance.
    #[default]
    Double,
    /// f32 for objects of 16 to 1 023 vertices: faster on a few hundred
    /// (about 1.17× at 256 vertices, up to 1.26× at 512), the distance exact
    /// to the tolerance plus about 1e-6 of the two objects' sizes, bounds
    /// still certified. Larger objects use the exact block search either way.
    Single,
}

impl Default for QueryOptions {
    fn default() -> Self {
        QueryOptions {
            tolerance: DEFAULT_TOLERANCE,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            margin: None,
            warm_start: true,
            precision: Precision::Double,
        }
    }
}

impl QueryOptions {
    /// Defaults with warm start off: every query starts cold.
    pub fn cold() -> Self {
        QueryOptions {
            warm_start: false,
            ..Self::default()
        }
    }
}

/// One item of a query request: a pose update or a pair query. A request is a
/// slice of items, answered by a slice of [`ItemResult`]s of the same length,
/// in the same order; items are applied in order, so a pose update affects
/// the queries after it in the same batch.
///
/// Build items with [`Item::set_pose`] and [`Item::distance`].
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.Item")]
pub struct Item {
    /// [`ItemKind`] wire value.
    pub kind: u32,
    /// [`item_flags`] bits.
    pub flags: u32,
    /// Object A (the object whose pose is set, for [`ItemKind::SetPose`]).
    pub a: u64,
    /// Object B (unused for [`ItemKind::SetPose`]).
    pub b: u64,
    /// Pose of A: the new stored pose for [`ItemKind::SetPose`], this query's
    /// pose of A with [`item_flags::POSE_A`].
    pub pose_a: Pose,
    /// This query's pose of B with [`item_flags::POSE_B`].
    pub pose_b: Pose,
    /// Relative tolerance.
    pub tolerance: f64,
    /// Early-exit margin, with [`item_flags::MARGIN`].
    pub margin: f64,
    /// Iteration cap.
    pub max_iterations: u32,
    /// Zero.
    pub reserved: u32,
}

impl Item {
    /// Store `pose` as the pose of object `id`.
    pub fn set_pose(id: ObjectId, pose: &Isometry3<f64>) -> Self {
        Item {
            kind: ItemKind::SetPose as u32,
            flags: 0,
            a: id.raw(),
            b: 0,
            pose_a: Pose::from_isometry(pose),
            pose_b: Pose::IDENTITY,
            tolerance: DEFAULT_TOLERANCE,
            margin: 0.0,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            reserved: 0,
        }
    }

    /// Distance between `a` and `b` at their stored poses.
    pub fn distance(a: ObjectId, b: ObjectId, options: &QueryOptions) -> Self {
        let mut flags = 0;
        if options.warm_start {
            flags |= item_flags::WARM_START;
        }
        if options.margin.is_some() {
            flags |= item_flags::MARGIN;
        }
        if options.precision == Precision::Single {
            flags |= item_flags::SINGLE_PRECISION;
        }
        Item {
            kind: ItemKind::Distance as u32,
            flags,
            a: a.raw(),
            b: b.raw(),
            pose_a: Pose::IDENTITY,
            pose_b: Pose::IDENTITY,
            tolerance: options.tolerance,
            margin: options.margin.unwrap_or(0.0),
            max_iterations: options.max_iterations,
            reserved: 0,
        }
    }

    /// Distance between `a` at `pose_a` and `b` at `pose_b`, leaving the
    /// stored poses alone.
    pub fn distance_at(
        a: ObjectId,
        pose_a: &Isometry3<f64>,
        b: ObjectId,
        pose_b: &Isometry3<f64>,
        options: &QueryOptions,
    ) -> Self {
        Self::distance(a, b, options)
            .with_pose_a(pose_a)
            .with_pose_b(pose_b)
    }

    /// This query with its own pose for A.
    pub fn with_pose_a(mut self, pose: &Isometry3<f64>) -> Self {
        self.flags |= item_flags::POSE_A;
        self.pose_a = Pose::from_isometry(pose);
        self
    }

    /// This query with its own pose for B.
    pub fn with_pose_b(mut self, pose: &Isometry3<f64>) -> Self {
        self.flags |= item_flags::POSE_B;
        self.pose_b = Pose::from_isometry(pose);
        self
    }

    /// Set joint positions `first .. first + positions.len()` of `robot`
    /// (in the robot's joint order: its URDF's moving joints, see
    /// `gjkd_model::kinematics`), and its base pose if `base` is given; the
    /// server then stores every link's pose, computed by forward kinematics.
    /// With `clamp`, positions outside their limits are clamped, otherwise
    /// the item fails with [`ErrorCode::OutOfLimits`] and changes nothing.
    ///
    /// Layout: `a` is the robot, `b` the index of the first joint,
    /// `max_iterations` the number of positions (1 to [`JOINTS_PER_ITEM`]),
    /// carried in `pose_b.translation`, `pose_b.rotation`, `tolerance` and
    /// `margin`, in that order; flag [`item_flags::POSE_A`] sends a base pose
    /// in `pose_a`. A robot with more joints takes several items in one
    /// request (each computes the poses; only the last one's matter).
    ///
    /// # Panics
    /// If `positions` is empty or longer than [`JOINTS_PER_ITEM`].
    pub fn set_joints(
        robot: ObjectId,
        first: u32,
        positions: &[f64],
        base: Option<&Isometry3<f64>>,
        clamp: bool,
    ) -> Self {
        assert!(
            (1..=JOINTS_PER_ITEM).contains(&positions.len()),
            "one item carries 1 to {JOINTS_PER_ITEM} joint positions"
        );
        let mut values = [0.0; JOINTS_PER_ITEM];
        values[..positions.len()].copy_from_slice(positions);
        let [t0, t1, t2, r0, r1, r2, r3, tolerance, margin] = values;
        let mut item = Item {
            kind: ItemKind::SetJoints as u32,
            flags: if clamp { item_flags::CLAMP } else { 0 },
            a: robot.raw(),
            b: u64::from(first),
            pose_a: Pose::IDENTITY,
            pose_b: Pose {
                translation: [t0, t1, t2],
                rotation: [r0, r1, r2, r3],
            },
            tolerance,
            margin,
            max_iterations: positions.len() as u32,
            reserved: 0,
        };
        if let Some(base) = base {
            item.flags |= item_flags::POSE_A;
            item.pose_a = Pose::from_isometry(base);
        }
        item
    }

    /// The joint positions of a [`ItemKind::SetJoints`] item (all
    /// [`JOINTS_PER_ITEM`] slots) and how many are in use, `None` if the
    /// count is out of range.
    pub fn joint_positions(&self) -> Option<([f64; JOINTS_PER_ITEM], usize)> {
        let count = self.max_iterations as usize;
        if !(1..=JOINTS_PER_ITEM).contains(&count) {
            return None;
        }
        let [t0, t1, t2] = self.pose_b.translation;
        let [r0, r1, r2, r3] = self.pose_b.rotation;
        Some((
            [t0, t1, t2, r0, r1, r2, r3, self.tolerance, self.margin],
            count,
        ))
    }

    /// A scene request's group member (see [`ItemKind::Member`]).
    pub fn member(id: ObjectId) -> Self {
        Item {
            kind: ItemKind::Member as u32,
            a: id.raw(),
            ..Item::set_pose(id, &Isometry3::identity())
        }
    }

    /// A scene request's allowed pair (see [`ItemKind::Allow`]).
    pub fn allow(a: ObjectId, b: ObjectId) -> Self {
        Item {
            kind: ItemKind::Allow as u32,
            b: b.raw(),
            ..Item::member(a)
        }
    }

    /// This pose or joint item, also ending its path step (see
    /// [`item_flags::END_STEP`]).
    #[must_use]
    pub fn ending_step(mut self) -> Self {
        self.flags |= item_flags::END_STEP;
        self
    }

    /// The end of a path step in a scene request (see [`ItemKind::Step`]).
    pub fn step() -> Self {
        Item {
            kind: ItemKind::Step as u32,
            a: 0,
            ..Item::member(ObjectId(0))
        }
    }

    /// The kind, if it is one this version knows.
    pub fn item_kind(&self) -> Option<ItemKind> {
        ItemKind::from_raw(self.kind)
    }

    /// Object A.
    pub fn object_a(&self) -> ObjectId {
        ObjectId(self.a)
    }

    /// Object B.
    pub fn object_b(&self) -> ObjectId {
        ObjectId(self.b)
    }

    /// The options encoded in this item.
    pub fn options(&self) -> QueryOptions {
        QueryOptions {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            margin: (self.flags & item_flags::MARGIN != 0).then_some(self.margin),
            warm_start: self.flags & item_flags::WARM_START != 0,
            precision: if self.flags & item_flags::SINGLE_PRECISION != 0 {
                Precision::Single
            } else {
                Precision::Double
            },
        }
    }
}

/// The answer to one [`Item`]. For a pose update only `error` is meaningful.
///
/// Read it with [`ItemResult::answer`].
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.ItemResult")]
pub struct ItemResult {
    /// Distance between the (rounded) shapes, `>= 0`.
    pub distance: f64,
    /// Certified lower bound on the distance.
    pub lower: f64,
    /// Certified upper bound on the distance.
    pub upper: f64,
    /// Lower bound on the penetration depth; 0 when separated.
    pub penetration: f64,
    /// Nearest point on A, world coordinates.
    pub point_a: [f64; 3],
    /// Nearest point on B, world coordinates.
    pub point_b: [f64; 3],
    /// Unit vector from A's nearest point towards B's; zero when the cores
    /// touch or intersect.
    pub normal: [f64; 3],
    /// [`ErrorCode`] wire value.
    pub error: u32,
    /// [`Status`] wire value, 0 when there is no answer.
    pub status: u32,
    /// Subalgorithm iterations (summed over piece pairs for compounds).
    pub iterations: u32,
    /// [`result_flags`] bits.
    pub flags: u32,
    /// Pieces of A and B that realise the distance (0 for convex objects).
    pub pieces: [u32; 2],
}

impl ItemResult {
    /// A result that carries only an error code.
    pub const fn error(code: ErrorCode) -> Self {
        ItemResult {
            distance: 0.0,
            lower: 0.0,
            upper: 0.0,
            penetration: 0.0,
            point_a: [0.0; 3],
            point_b: [0.0; 3],
            normal: [0.0; 3],
            error: code as u32,
            status: 0,
            iterations: 0,
            flags: 0,
            pieces: [0; 2],
        }
    }

    /// The error code; unknown wire values read as [`ErrorCode::Malformed`].
    pub fn error_code(&self) -> ErrorCode {
        ErrorCode::from_raw(self.error).unwrap_or(ErrorCode::Malformed)
    }

    /// The answer of a distance query, or the item's error. A successful pose
    /// update reads as an answer with status `None`.
    pub fn answer(&self) -> Result<Answer, ErrorCode> {
        match self.error_code() {
            ErrorCode::Ok => Ok(Answer {
                distance: self.distance,
                lower: self.lower,
                upper: self.upper,
                penetration: self.penetration,
                point_a: Point3::from(self.point_a),
                point_b: Point3::from(self.point_b),
                normal: Vector3::from(self.normal),
                status: Status::from_raw(self.status),
                iterations: self.iterations,
                pieces: self.pieces,
                warm_started: self.flags & result_flags::WARM_STARTED != 0,
                backup_used: self.flags & result_flags::BACKUP_USED != 0,
            }),
            code => Err(code),
        }
    }
}

impl Default for ItemResult {
    fn default() -> Self {
        ItemResult::error(ErrorCode::Ok)
    }
}

/// A decoded distance answer. Distances are after radii; points are in world
/// coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Answer {
    /// Distance between the (rounded) shapes, `>= 0`.
    pub distance: f64,
    /// Certified lower bound on the distance.
    pub lower: f64,
    /// Certified upper bound on the distance.
    pub upper: f64,
    /// Lower bound on the penetration depth; 0 when separated.
    pub penetration: f64,
    /// Nearest point on A. When the shapes overlap, the deepest point of A
    /// along `normal`.
    pub point_a: Point3<f64>,
    /// Nearest point on B.
    pub point_b: Point3<f64>,
    /// Unit vector from A's nearest point towards B's; zero when the cores
    /// touch or intersect.
    pub normal: Vector3<f64>,
    /// How the query ended; `None` for a pose update.
    pub status: Option<Status>,
    /// Subalgorithm iterations (summed over piece pairs for compounds).
    pub iterations: u32,
    /// Pieces of A and B that realise the distance (0 for convex objects).
    pub pieces: [u32; 2],
    /// The query started from the server's cached simplex.
    pub warm_started: bool,
    /// gjk's Backup Procedure ran.
    pub backup_used: bool,
}

/// Response header of the query service: whole-request errors. When `error`
/// is not [`ErrorCode::Ok`] the result slice is empty.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.ReplyHeader")]
pub struct ReplyHeader {
    /// [`ErrorCode`] wire value: [`ErrorCode::EmptyBatch`],
    /// [`ErrorCode::BatchTooLarge`], or [`ErrorCode::Ok`].
    pub error: u32,
    /// Number of results that follow.
    pub count: u32,
}

/// A vertex on the wire.
#[derive(Clone, Copy, Debug, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.Vertex")]
pub struct Vertex {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

impl From<Point3<f64>> for Vertex {
    fn from(p: Point3<f64>) -> Self {
        Vertex {
            x: p.x,
            y: p.y,
            z: p.z,
        }
    }
}

impl From<Vertex> for Point3<f64> {
    fn from(v: Vertex) -> Self {
        Point3::new(v.x, v.y, v.z)
    }
}

/// Text packed into vertices, 24 bytes each (the admin service's slice
/// carries only vertices), the last one padded with zeros. The inverse is
/// [`unpack_text`].
pub fn pack_text(text: &str) -> Vec<Vertex> {
    text.as_bytes()
        .chunks(24)
        .map(|chunk| {
            let mut bytes = [0u8; 24];
            bytes[..chunk.len()].copy_from_slice(chunk);
            let word = |i: usize| {
                let mut w = [0u8; 8];
                w.copy_from_slice(&bytes[8 * i..8 * i + 8]);
                f64::from_bits(u64::from_le_bytes(w))
            };
            Vertex {
                x: word(0),
                y: word(1),
                z: word(2),
            }
        })
        .collect()
}

/// The first `len` bytes packed in `vertices` by [`pack_text`], if there
/// are that many, the padding is zero and they are UTF-8.
pub fn unpack_text(vertices: &[Vertex], len: u64) -> Option<String> {
    let len = usize::try_from(len).ok()?;
    if vertices.len() != len.div_ceil(24) {
        return None;
    }
    let mut bytes = Vec::with_capacity(vertices.len() * 24);
    for v in vertices {
        for c in [v.x, v.y, v.z] {
            bytes.extend(c.to_bits().to_le_bytes());
        }
    }
    if bytes[len..].iter().any(|&b| b != 0) {
        return None;
    }
    bytes.truncate(len);
    String::from_utf8(bytes).ok()
}

/// Operations of the admin service; the wire values of [`AdminRequest::op`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum AdminOp {
    /// Server information and limits ([`AdminReply::info`]).
    Hello = 1,
    /// Register a convex object (one piece) or a compound (several), with
    /// the vertices in the request's slice payload.
    Register = 2,
    /// Remove object [`AdminRequest::id`].
    Remove = 3,
    /// Look an object up by [`AdminRequest::name`].
    Lookup = 4,
    /// Server statistics ([`AdminReply::stats`]).
    Stats = 5,
    /// Attach a robot's kinematics, named [`AdminRequest::name`], to the
    /// objects already registered as its links (named `<robot>/<link>`; a
    /// link with no such object has no shape and only carries its
    /// children). The slice payload is text packed by [`pack_text`]: the
    /// URDF, optionally followed by a NUL byte and an SRDF whose
    /// `disable_collisions` pairs (with the adjacent links) the server keeps
    /// as the robot's allowed pairs. [`AdminRequest::id`] is the text's
    /// length in bytes. The reply's id is the robot's id, for
    /// [`ItemKind::SetJoints`]; attaching a name again replaces the robot.
    AttachRobot = 6,
}

impl AdminOp {
    /// The operation with wire value `raw`, if any.
    pub fn from_raw(raw: u32) -> Option<Self> {
        match raw {
            1 => Some(AdminOp::Hello),
            2 => Some(AdminOp::Register),
            3 => Some(AdminOp::Remove),
            4 => Some(AdminOp::Lookup),
            5 => Some(AdminOp::Stats),
            6 => Some(AdminOp::AttachRobot),
            _ => None,
        }
    }
}

/// Values of [`AdminRequest::shape`] for [`AdminOp::Lookup`].
pub mod lookup_kind {
    /// Look up an object (the default, 0).
    pub const OBJECT: u32 = 0;
    /// Look up a robot attached with [`AdminOp::AttachRobot`](super::AdminOp::AttachRobot)
    /// or loaded from the scene file: the reply's id is the robot's.
    pub const ROBOT: u32 = 1;
}

/// Values of [`AdminRequest::shape`].
pub mod shape_kind {
    /// One convex piece: `pieces[0]` describes it (its offset is ignored);
    /// a hull or a cylinder ([`piece_kind`](crate::piece_kind)).
    pub const CONVEX: u32 = 1;
    /// A union of `piece_count` convex pieces, each with its offset, each a
    /// hull or a cylinder ([`piece_kind`](crate::piece_kind)).
    pub const COMPOUND: u32 = 2;
}

/// Values of [`PieceDesc::reserved`]: what a piece's vertices describe.
///
/// Added within v1 (the layout is unchanged): a server older than
/// [`CYLINDER`](piece_kind::CYLINDER) refuses any non-zero value as [`ErrorCode::Malformed`], so
/// a cylinder is never misread there as a one-point hull.
pub mod piece_kind {
    /// The convex hull of the piece's vertices grown by its radius (0, the
    /// only kind before cylinders).
    pub const HULL: u32 = 0;
    /// An exact cylinder about the piece's z axis, centred at the piece's
    /// origin: the piece has exactly one vertex, `(r, h, 0)`, the
    /// cylinder's radius `r` and half-height `h` (each finite, `>= 0`, at
    /// most 2^999; a `z` other than 0 is [`Malformed`](crate::ErrorCode::Malformed),
    /// a bad `r` or `h` [`InvalidRadius`](crate::ErrorCode::InvalidRadius)),
    /// and [`PieceDesc::radius`](crate::PieceDesc::radius) rounds its edges.
    pub const CYLINDER: u32 = 1;
}

/// One convex piece of a registration: its offset in the object's body frame,
/// radius, and how many of the slice's vertices are its own (pieces take
/// consecutive runs of the slice, in order).
///
/// A cylinder piece ([`piece_kind::CYLINDER`] in `reserved`) carries its
/// dimensions as its one vertex:
///
/// ```
/// use gjkd_proto::{piece_kind, PieceDesc, Pose, Vertex};
///
/// // Radius 0.05, length 0.4 (half-height 0.2), sharp rims.
/// let desc = PieceDesc {
///     offset: Pose::IDENTITY,
///     radius: 0.0,
///     vertex_count: 1,
///     reserved: piece_kind::CYLINDER,
/// };
/// let dimensions = Vertex { x: 0.05, y: 0.2, z: 0.0 };
/// # let _ = (desc, dimensions);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.PieceDesc")]
pub struct PieceDesc {
    /// Offset of the piece in the object's body frame.
    pub offset: Pose,
    /// Rounding radius, `>= 0`.
    pub radius: f64,
    /// Number of vertices of this piece (1 for a cylinder).
    pub vertex_count: u32,
    /// The piece's kind, a [`piece_kind`] value: 0 (a hull) unless the
    /// piece is a cylinder. The name is the field's from before
    /// cylinders, kept so that code building pieces still compiles.
    pub reserved: u32,
}

/// Request header of the admin service. The slice payload holds the
/// vertices of a registration (empty for other operations).
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.AdminRequest")]
pub struct AdminRequest {
    /// [`AdminOp`] wire value.
    pub op: u32,
    /// [`shape_kind`] value, for [`AdminOp::Register`].
    pub shape: u32,
    /// Object, for [`AdminOp::Remove`].
    ///
    /// For [`AdminOp::Register`], the registration token: 0 for none, or
    /// a value the client draws at random for each registration and sends
    /// again, unchanged with the rest of the request, when it retries that
    /// registration (after a timeout, or a server that died and came back).
    /// A server remembers the tokens of each client's last 64 registrations,
    /// committed with the object, so a retry gets the id of the object that
    /// was stored (also after a crash between the commit and the reply),
    /// never a second object. A token is forgotten with its object; the
    /// same token with another shape or name is [`ErrorCode::Malformed`].
    /// Added within v1 (the layout is unchanged): a server older than this
    /// ignores the token, so a retry there may store a second object.
    pub id: u64,
    /// Number of valid entries of `pieces`.
    pub piece_count: u32,
    /// Bytes of `name` in use.
    pub name_len: u32,
    /// UTF-8 name: optional for [`AdminOp::Register`], required for
    /// [`AdminOp::Lookup`].
    pub name: [u8; MAX_NAME_LEN],
    /// Initial pose of a registered object.
    pub pose: Pose,
    /// Piece table of a registration.
    pub pieces: [PieceDesc; MAX_PIECES],
}

impl Default for AdminRequest {
    /// An empty request with operation 0, which no server accepts: iceoryx2
    /// needs a default header, and a forgotten `op` must not mean anything.
    fn default() -> Self {
        AdminRequest {
            op: 0,
            ..AdminRequest::new(AdminOp::Hello)
        }
    }
}

impl AdminRequest {
    /// A request for `op` with everything else empty.
    pub fn new(op: AdminOp) -> Self {
        AdminRequest {
            op: op as u32,
            shape: 0,
            id: 0,
            piece_count: 0,
            name_len: 0,
            name: [0; MAX_NAME_LEN],
            pose: Pose::IDENTITY,
            pieces: [PieceDesc::default(); MAX_PIECES],
        }
    }

    /// Sets the name; `false` (and no change) if it is longer than
    /// [`MAX_NAME_LEN`] bytes.
    pub fn set_name(&mut self, name: &str) -> bool {
        let bytes = name.as_bytes();
        if bytes.len() > MAX_NAME_LEN {
            return false;
        }
        self.name = [0; MAX_NAME_LEN];
        self.name[..bytes.len()].copy_from_slice(bytes);
        self.name_len = bytes.len() as u32;
        true
    }

    /// The name, or `None` if `name_len` is out of range or the bytes are not
    /// UTF-8.
    pub fn name(&self) -> Option<&str> {
        let len = usize::try_from(self.name_len).ok()?;
        std::str::from_utf8(self.name.get(..len)?).ok()
    }
}

/// Wait strategy of a server; the wire values of [`ServerInfo::wait`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum WaitMode {
    /// Busy-polls: lowest latency, one core always busy.
    Spin = 1,
    /// Sleeps on an event until a client notifies: no busy CPU.
    Block = 2,
    /// Spins for a short while after each request, then sleeps.
    Adaptive = 3,
}

impl WaitMode {
    /// The mode with wire value `raw`, if any.
    pub fn from_raw(raw: u32) -> Option<Self> {
        match raw {
            1 => Some(WaitMode::Spin),
            2 => Some(WaitMode::Block),
            3 => Some(WaitMode::Adaptive),
            _ => None,
        }
    }

    /// Whether clients must notify the wake event after sending.
    pub fn needs_wake(self) -> bool {
        self != WaitMode::Spin
    }
}

/// What a server tells a client at hello (`AdminOp::Hello`; the client
/// crate's `Client::server_info`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.ServerInfo")]
pub struct ServerInfo {
    /// [`PROTOCOL_VERSION`] of the server.
    pub protocol: u32,
    /// [`WaitMode`] wire value.
    pub wait: u32,
    /// Most items in one query request.
    pub max_batch: u32,
    /// Most vertices in one registration.
    pub max_vertices: u32,
    /// Most pieces in one compound.
    pub max_pieces: u32,
    /// Most clients per service.
    pub max_clients: u32,
    /// Most objects the server holds.
    pub max_objects: u64,
    /// Process id of the server.
    pub pid: u64,
}

/// Server statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.ServerStats")]
pub struct ServerStats {
    /// Objects held.
    pub objects: u64,
    /// Query requests answered.
    pub requests: u64,
    /// Items answered (pose updates and queries).
    pub items: u64,
    /// Items that failed.
    pub item_errors: u64,
    /// Warm-start cache entries in use.
    pub cache_entries: u64,
    /// Warm-start cache capacity.
    pub cache_capacity: u64,
    /// Queries that found a cached simplex.
    pub cache_hits: u64,
    /// Warm-start queries that found none.
    pub cache_misses: u64,
    /// Entries evicted to stay within the capacity.
    pub cache_evictions: u64,
    /// Query clients connected, as of the server's last housekeeping
    /// (every few seconds): a client that died drops out once its death
    /// is detected.
    pub clients: u64,
    /// Commits to the object store and writes of the pose journal that
    /// failed. A registration or removal that could not be committed was
    /// refused (with [`ErrorCode::StorageFull`] on a full disk,
    /// [`ErrorCode::Internal`] otherwise) and undone.
    pub persist_errors: u64,
}

/// The admin service's answer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v1.AdminReply")]
pub struct AdminReply {
    /// [`ErrorCode`] wire value.
    pub error: u32,
    /// [`AdminOp`] wire value of the request.
    pub op: u32,
    /// The object registered, removed or found.
    pub id: u64,
    /// Filled for [`AdminOp::Hello`].
    pub info: ServerInfo,
    /// Filled for [`AdminOp::Stats`].
    pub stats: ServerStats,
}

impl AdminReply {
    /// A reply carrying only an error code.
    pub fn error(op: u32, code: ErrorCode) -> Self {
        AdminReply {
            error: code as u32,
            op,
            ..Default::default()
        }
    }

    /// The error code; unknown wire values read as [`ErrorCode::Malformed`].
    pub fn error_code(&self) -> ErrorCode {
        ErrorCode::from_raw(self.error).unwrap_or(ErrorCode::Malformed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_carry_the_version() {
        assert_eq!(query_service_name("gjkd"), "gjkd/v1/query");
        assert_eq!(admin_service_name("x"), "x/v1/admin");
        assert_eq!(wake_service_name("x"), "x/v1/wake");
    }

    #[test]
    fn error_codes_round_trip() {
        for (i, c) in ErrorCode::ALL.iter().enumerate() {
            assert_eq!(c.raw() as usize, i);
            assert_eq!(ErrorCode::from_raw(c.raw()), Some(*c));
        }
        assert_eq!(ErrorCode::from_raw(ErrorCode::ALL.len() as u32), None);
    }

    #[test]
    fn pose_round_trips_bit_for_bit() {
        let iso = Isometry3::new(
            Vector3::new(1.25, -3.5, 1e-300),
            Vector3::new(0.3, -1.2, 2.0),
        );
        let back = Pose::from_isometry(&iso).to_isometry_unchecked();
        assert_eq!(back, iso);
    }

    #[test]
    fn item_encodes_options() {
        let o = QueryOptions {
            tolerance: 1e-9,
            max_iterations: 7,
            margin: Some(0.5),
            warm_start: false,
            precision: Precision::Single,
        };
        let it = Item::distance(ObjectId::from_raw(3), ObjectId::from_raw(4), &o);
        assert_eq!(it.options(), o);
        assert_eq!(it.item_kind(), Some(ItemKind::Distance));
        assert_eq!(it.flags & item_flags::WARM_START, 0);
        assert_eq!(
            it.flags & item_flags::SINGLE_PRECISION,
            item_flags::SINGLE_PRECISION
        );
        let d = Item::distance(
            ObjectId::from_raw(3),
            ObjectId::from_raw(4),
            &QueryOptions::default(),
        );
        assert_eq!(d.flags & item_flags::SINGLE_PRECISION, 0);
        assert_eq!(d.options().precision, Precision::Double);
    }

    #[test]
    fn names_are_bounded_and_checked() {
        let mut r = AdminRequest::new(AdminOp::Lookup);
        assert!(r.set_name("ball"));
        assert_eq!(r.name(), Some("ball"));
        assert!(!r.set_name(&"x".repeat(MAX_NAME_LEN + 1)));
        r.name_len = 1000;
        assert_eq!(r.name(), None);
        r.name_len = 2;
        r.name[0] = 0xff;
        assert_eq!(r.name(), None);
    }

    #[test]
    fn joint_items_carry_their_positions() {
        let q = [0.5, -1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0];
        let robot = ObjectId::from_raw(9);
        let base = Isometry3::translation(1.0, 2.0, 3.0);
        let it = Item::set_joints(robot, 2, &q, Some(&base), true);
        assert_eq!(it.item_kind(), Some(ItemKind::SetJoints));
        assert_eq!(it.joint_positions(), Some((q, 9)));
        assert_eq!((it.a, it.b), (9, 2));
        assert_eq!(it.flags, item_flags::POSE_A | item_flags::CLAMP);
        assert_eq!(it.pose_a, Pose::from_isometry(&base));
        let short = Item::set_joints(robot, 0, &[1.5], None, false);
        assert_eq!(
            short.joint_positions().map(|(v, n)| (v[0], n)),
            Some((1.5, 1))
        );
        assert_eq!(short.flags, 0);
        let mut bad = short;
        bad.max_iterations = 10;
        assert_eq!(bad.joint_positions(), None);
    }

    #[test]
    fn text_round_trips_through_vertices() {
        for text in ["", "a", &"<robot name=\"é\"/>".repeat(5), &"x".repeat(48)] {
            let packed = pack_text(text);
            assert_eq!(packed.len(), text.len().div_ceil(24));
            assert_eq!(
                unpack_text(&packed, text.len() as u64).as_deref(),
                Some(text)
            );
        }
        let packed = pack_text("hello");
        assert_eq!(unpack_text(&packed, 4), None, "non-zero padding");
        assert_eq!(unpack_text(&packed, 30), None, "too few vertices");
    }

    #[test]
    fn wire_sizes_are_stable() {
        assert_eq!(std::mem::size_of::<Pose>(), 56);
        assert_eq!(std::mem::size_of::<Item>(), 160);
        assert_eq!(std::mem::size_of::<ItemResult>(), 128);
        assert_eq!(std::mem::size_of::<Vertex>(), 24);
    }
}
