//! One error per operation, as iceoryx2 has (`LoanError`, `SendError`,
//! ...): each holds the faults its operation can meet, the server's
//! refusals as variants of their own, and the connection faults every
//! call shares as one variant, [`ConnectError`]. Each converts into
//! [`ClientError`], the umbrella, so `?` into one type keeps working, and
//! each variant's `code()` is the code [`ClientError::code`] gives the
//! same fault: Python and C read the faults through [`ClientError`], with
//! the same codes (`docs/errors.md` has the table per operation).

use gjkd_proto::ShapeError;

use crate::refusals::refusals;
#[cfg(doc)]
use crate::{Client, ErrorCode, MAX_NAME_LEN, MAX_PIECES, ServerInfo};
use crate::{ClientError, ConnectError};

/// What the client says when a name does not fit [`MAX_NAME_LEN`].
pub(crate) const NAME_TOO_LONG: &str = "name longer than MAX_NAME_LEN";

/// What the client says when an item asks for a gradient the call has no
/// room for ([`QueryError::NoRoomForGradient`]).
pub(crate) const NO_GRADIENT_BUFFER: &str = "an item asks for a gradient (item_flags::GRADIENT) \
     the call has no room for: use query_batch_gradients with a buffer as long as the items \
     that ask";

/// Why a registration ([`Client::register`], [`Client::register_named`],
/// the `register_*` shorthands, `Client::register_mesh`) failed. Nothing
/// is stored then, except after a connection fault (see
/// [`Client::register`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RegisterError {
    /// The geometry cannot be sent (a negative half extent, a compound
    /// inside a compound, more than [`MAX_PIECES`] pieces, more vertices
    /// than a `u32` counts), found before anything is sent.
    #[error("the shape cannot be sent: {0}")]
    InvalidShape(ShapeError),
    /// The name is longer than [`MAX_NAME_LEN`] bytes, found before
    /// anything is sent.
    #[error("the name is longer than MAX_NAME_LEN bytes")]
    NameTooLong,
    /// A mesh cannot be made a shape (`Client::register_mesh_file`,
    /// `Client::register_mesh`, with the `robots` feature): its file is
    /// missing or no mesh, its scale is bad, or its decomposition found no
    /// pieces. The server never sees meshes, so no code names this.
    #[error("the mesh cannot be used: {0}")]
    InvalidMesh(String),
    /// A convex piece has no vertices.
    #[error("a convex piece has no vertices")]
    EmptyVertices,
    /// The shape has more vertices than the server's `--max-vertices`.
    #[error("the shape has more vertices than the server accepts")]
    TooManyVertices,
    /// A radius, a cylinder's half-height or rounding is negative, NaN,
    /// infinite or above 2^999 (about 5e300), or a cylinder reaches beyond
    /// that.
    #[error("a radius, half-height or rounding is not a number from 0 to 5e300")]
    InvalidRadius,
    /// A vertex is NaN or infinite, or the shape (vertices plus radius)
    /// reaches beyond 2^999 from its body origin.
    #[error("a vertex is not finite, or the shape reaches beyond 5e300 from its origin")]
    NonFiniteVertex,
    /// The compound has no pieces.
    #[error("the compound has no pieces")]
    EmptyCompound,
    /// The compound has more pieces than the server accepts.
    #[error("the compound has more pieces than the server accepts")]
    TooManyPieces,
    /// The initial pose or a piece's offset is not finite, or reaches
    /// beyond the server's limit.
    #[error("the pose or a piece's offset is not finite, or reaches beyond 2.68e300")]
    NonFinitePose,
    /// A rotation of the initial pose or of a piece's offset is off unit
    /// length by more than 1e-6.
    #[error("a rotation of the pose or a piece's offset is not of unit length")]
    BadQuaternion,
    /// Another object (the scene file's included) already has this name.
    #[error("another object already has this name")]
    NameTaken,
    /// The server holds as many objects as its `--max-objects`.
    #[error("the server holds as many objects as it accepts")]
    TooManyObjects,
    /// The server's disk has no room to store the object: the same call
    /// succeeds once there is room.
    #[error("the server's disk has no room to store the object")]
    StorageFull,
    /// The server found the registration malformed: its token was used
    /// before for another shape or name (a client bug).
    #[error("the server found the registration malformed")]
    Malformed,
    /// The server failed in a way that is its own fault (the store could
    /// not commit the object); it keeps serving.
    #[error("the server failed to store the object")]
    Internal,
    /// No server could be reached, or not in time: see [`ConnectError`].
    #[error(transparent)]
    Connection(#[from] ConnectError),
}

refusals! {
    RegisterError {
        EmptyVertices, TooManyVertices, InvalidRadius, NonFiniteVertex, EmptyCompound,
        TooManyPieces, NonFinitePose, BadQuaternion, NameTaken, TooManyObjects, StorageFull,
        Malformed, Internal,
    }
    others {
        RegisterError::InvalidShape(e) => ClientError::InvalidArgument(e.describe()),
        RegisterError::NameTooLong => ClientError::InvalidArgument(NAME_TOO_LONG),
        RegisterError::InvalidMesh(m) => ClientError::InvalidMesh(m),
        RegisterError::Connection(e) => e.into(),
    }
}

/// Why [`Client::remove`] failed; the object stays.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RemoveError {
    /// No object has this id (never registered, removed already, or
    /// registered with a server since restarted without persistence).
    #[error("no object has this id")]
    UnknownObject,
    /// The object belongs to another client.
    #[error("the object belongs to another client")]
    NotOwner,
    /// The object was loaded from the server's scene file: nobody may
    /// remove it.
    #[error("the object belongs to the server's scene file and cannot be removed")]
    ReadOnly,
    /// The server's disk has no room to store the removal: the same call
    /// succeeds once there is room.
    #[error("the server's disk has no room to store the removal")]
    StorageFull,
    /// The server failed in a way that is its own fault; it keeps serving.
    #[error("the server failed to store the removal")]
    Internal,
    /// No server could be reached, or not in time: see [`ConnectError`].
    #[error(transparent)]
    Connection(#[from] ConnectError),
}

refusals! {
    RemoveError { UnknownObject, NotOwner, ReadOnly, StorageFull, Internal }
    others { RemoveError::Connection(e) => e.into() }
}

/// Why a look-up by name ([`Client::lookup`], [`Client::robot_id`])
/// failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LookupError {
    /// The name is longer than [`MAX_NAME_LEN`] bytes, found before
    /// anything is sent.
    #[error("the name is longer than MAX_NAME_LEN bytes")]
    NameTooLong,
    /// Nothing of the kind asked for has this name.
    #[error("nothing has this name")]
    UnknownName,
    /// The server failed in a way that is its own fault; it keeps serving.
    #[error("the server failed to look the name up")]
    Internal,
    /// No server could be reached, or not in time: see [`ConnectError`].
    #[error(transparent)]
    Connection(#[from] ConnectError),
}

refusals! {
    LookupError { UnknownName, Internal }
    others {
        LookupError::NameTooLong => ClientError::InvalidArgument(NAME_TOO_LONG),
        LookupError::Connection(e) => e.into(),
    }
}

/// Why [`Client::set_pose`] failed; the stored pose stays as it was.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PoseError {
    /// No object has this id.
    #[error("no object has this id")]
    UnknownObject,
    /// The pose has a NaN or infinite component, or a translation beyond
    /// the server's limit (about 2.68e300).
    #[error("the pose is not finite, or reaches beyond 2.68e300")]
    NonFinitePose,
    /// The rotation quaternion is off unit length by more than 1e-6.
    #[error("the pose's rotation is not of unit length")]
    BadQuaternion,
    /// The server failed in a way that is its own fault; it keeps serving.
    #[error("the server failed to store the pose")]
    Internal,
    /// No server could be reached, or not in time: see [`ConnectError`].
    #[error(transparent)]
    Connection(#[from] ConnectError),
}

refusals! {
    PoseError { UnknownObject, NonFinitePose, BadQuaternion, Internal }
    others { PoseError::Connection(e) => e.into() }
}

/// Why a pair query ([`Client::distance`], [`Client::distance_at`],
/// [`Client::distance_gradient`]) or a batch ([`Client::query_batch`] and
/// its variants) failed. A batch fails only as a whole: its items' own
/// faults are in their results.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum QueryError {
    /// The result buffer of [`Client::query_batch`] is shorter than the
    /// batch, found before anything is sent.
    #[error("result buffer holds {got} results but the batch has {needed} items")]
    ResultBufferTooSmall {
        /// Items in the batch.
        needed: usize,
        /// Length of the buffer.
        got: usize,
    },
    /// An object of the pair is not registered.
    #[error("no object has this id")]
    UnknownObject,
    /// A pose given with the query is not finite, or the two objects lie
    /// too far apart for gjk's arithmetic.
    #[error("a pose is not finite, or the objects lie beyond 1e301 apart")]
    NonFinitePose,
    /// A rotation given with the query is off unit length by more than
    /// 1e-6.
    #[error("a pose's rotation is not of unit length")]
    BadQuaternion,
    /// A query option is out of its domain (a negative or NaN tolerance,
    /// a zero iteration cap, a NaN margin), or a gradient asked of a robot
    /// with more coordinates than a gradient holds.
    #[error("a query option is out of its domain")]
    InvalidOptions,
    /// The batch has no items.
    #[error("the batch has no items")]
    EmptyBatch,
    /// The batch has more items than the server's
    /// [`ServerInfo::max_batch`].
    #[error("the batch has more items than the server accepts")]
    BatchTooLarge,
    /// The server failed in a way that is its own fault; it keeps serving.
    #[error("the server failed to answer the query")]
    Internal,
    /// An item asks for a gradient ([`Item::with_gradient`](crate::Item::with_gradient))
    /// that the call has no room for: a call without a gradient buffer
    /// ([`Client::query_batch`]), or a buffer shorter than the items that
    /// ask ([`Client::query_batch_gradients`]); found before anything is
    /// sent.
    #[error("an item asks for a gradient the call has no room for")]
    NoRoomForGradient,
    /// No server could be reached, or not in time: see [`ConnectError`].
    #[error(transparent)]
    Connection(#[from] ConnectError),
}

refusals! {
    QueryError {
        UnknownObject, NonFinitePose, BadQuaternion, InvalidOptions, EmptyBatch,
        BatchTooLarge, Internal,
    }
    others {
        QueryError::ResultBufferTooSmall { needed, got } => {
            ClientError::ResultBufferTooSmall { needed, got }
        },
        QueryError::NoRoomForGradient => ClientError::InvalidArgument(NO_GRADIENT_BUFFER),
        QueryError::Connection(e) => e.into(),
    }
}

/// Why [`Client::poses`] failed as a whole (an unknown id fails alone, in
/// its entry).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PoseReadError {
    /// More ids than the server takes in one request: the client splits
    /// by the limit it was told, so this is a server restarted since with
    /// a smaller `--max-batch` (the next call knows the new one).
    #[error("more ids than the server accepts in one request")]
    BatchTooLarge,
    /// The server failed in a way that is its own fault; it keeps serving.
    #[error("the server failed to read the poses")]
    Internal,
    /// No server could be reached, or not in time: see [`ConnectError`].
    #[error(transparent)]
    Connection(#[from] ConnectError),
}

refusals! {
    PoseReadError { BatchTooLarge, Internal }
    others { PoseReadError::Connection(e) => e.into() }
}

/// Why [`Client::stats`] failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StatsError {
    /// The server failed in a way that is its own fault; it keeps serving.
    #[error("the server failed to count")]
    Internal,
    /// No server could be reached, or not in time: see [`ConnectError`].
    #[error(transparent)]
    Connection(#[from] ConnectError),
}

refusals! {
    StatsError { Internal }
    others { StatsError::Connection(e) => e.into() }
}

/// Why a scene question ([`SceneQuery::into_rows`](crate::SceneQuery::into_rows),
/// `into_pairs`, `into_contacts`, `run`, [`Client::scene_with`],
/// `Client::edge_contact`) failed as a whole; nothing changes then (a
/// pair's own fault is in its row).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// A path's poses or joint positions do not make whole steps (or it
    /// moves nothing), found before anything is sent.
    #[error("a path's poses or positions do not make whole steps")]
    PartialSteps,
    /// An edge's ends are not one position per joint of the robot
    /// (`Client::edge_contact`), found before anything is sent.
    #[error("an edge's ends need one position per joint")]
    EdgeEnds,
    /// The group, a member, an object of an allowed pair or a moving
    /// object (or robot) is not registered.
    #[error("an object of the question is not registered")]
    UnknownObject,
    /// A tolerance, iteration cap, margin, cut-off, accepted accuracy,
    /// bracket or `k` is out of its domain.
    #[error("an option of the question is out of its domain")]
    InvalidOptions,
    /// The question cannot be asked so: [`Client::nearest`] of more than
    /// one object, `until_hit` or `continuous` of another question than
    /// [`Client::within`], a continuous path of fewer than two steps or
    /// along which nothing moves, signed distances on a continuous path.
    #[error("the question cannot be asked so")]
    Malformed,
    /// More poses, members, allowed pairs and steps together than the
    /// server's [`ServerInfo::max_batch`] in one step of a path, which no
    /// split helps.
    #[error("the question has more items than the server accepts")]
    BatchTooLarge,
    /// A pose given with the question is not finite.
    #[error("a pose or joint position is not finite")]
    NonFinitePose,
    /// A rotation given with the question is off unit length by more than
    /// 1e-6.
    #[error("a pose's rotation is not of unit length")]
    BadQuaternion,
    /// A joint position is outside its limits (and clamping was not
    /// asked).
    #[error("a joint position is outside its limits")]
    OutOfLimits,
    /// The server failed in a way that is its own fault; it keeps serving.
    #[error("the server failed to answer the question")]
    Internal,
    /// No server could be reached, or not in time: see [`ConnectError`].
    #[error(transparent)]
    Connection(#[from] ConnectError),
}

refusals! {
    SceneError {
        UnknownObject, InvalidOptions, Malformed, BatchTooLarge, NonFinitePose, BadQuaternion,
        OutOfLimits, Internal,
    }
    others {
        SceneError::PartialSteps => ClientError::InvalidArgument(
            "a path's poses or positions do not make whole steps",
        ),
        SceneError::EdgeEnds => {
            ClientError::InvalidArgument("an edge's ends need one position per joint")
        },
        SceneError::Connection(e) => e.into(),
    }
}

/// Why a robot call failed: `Client::register_robot` (and `_text`,
/// `_or_get`), `Client::attach_robot`, `Client::open_robot`,
/// `Client::set_joints` (and `_with`, `_by_name`), with the `robots`
/// feature, and [`Client::remove_robot`], without. Nothing moves or is
/// kept then (a registration's link objects are removed again).
///
/// The faults found before sending ([`RobotError::InvalidRobot`],
/// [`RobotError::UnknownJoint`]) come only from calls of the `robots`
/// feature; they carry text, not the model's types, so the enum is the
/// same with and without it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RobotError {
    /// The robot's URDF or SRDF, or a mesh it names, cannot be read
    /// (missing, malformed, a `package://` URL found in no folder, a
    /// collision element of a bad size), found before anything is sent;
    /// code [`ErrorCode::InvalidRobot`], as the server's refusal of the
    /// same fault. The message names the file, link or joint.
    #[error("the robot cannot be read: {0}")]
    InvalidRobot(String),
    /// Joint positions named a joint the robot does not move (no such
    /// joint, or a fixed or mimic one), found before anything is sent;
    /// code [`ErrorCode::UnknownName`], as a name look-up's.
    #[error("the robot has no moving joint named `{0}`")]
    UnknownJoint(String),
    /// Not one position per moving joint of the robot, found before
    /// anything is sent.
    #[error("not one position per moving joint of the robot")]
    WrongJointCount,
    /// The robot's name, or a link object's (`<name>/<link>`), is longer
    /// than [`MAX_NAME_LEN`] bytes, found before anything is sent.
    #[error("the name is longer than MAX_NAME_LEN bytes")]
    NameTooLong,
    /// The URDF and SRDF text is longer than 4 GiB.
    #[error("the robot's text is longer than 4 GiB")]
    TextTooLong,
    /// A link object could not be registered (its name taken by another
    /// object, the server full, a shape it refuses): the registration's
    /// error, and the links registered before it are removed again.
    #[error("a link object cannot be registered: {0}")]
    Link(RegisterError),
    /// The server cannot use the robot: its URDF or SRDF is malformed, or
    /// its links do not form one tree of fixed, revolute, continuous and
    /// prismatic joints.
    #[error("the server refuses the robot's URDF or SRDF")]
    RobotRefused,
    /// No robot has this name (never attached, removed, or a server
    /// restarted since, which keeps the link objects but not the robot).
    #[error("no robot has this name")]
    UnknownRobot,
    /// The robot, or one of its link objects, belongs to another client.
    #[error("the robot belongs to another client")]
    NotOwner,
    /// The robot was loaded from the server's scene file: nobody may
    /// remove it.
    #[error("the robot belongs to the server's scene file and cannot be removed")]
    ReadOnly,
    /// The robot, or one of its link objects, is gone from the server.
    #[error("the robot or one of its links is not registered")]
    UnknownObject,
    /// A joint position is outside its limits (and clamping was not
    /// asked).
    #[error("a joint position is outside its limits")]
    OutOfLimits,
    /// A joint position or the base pose is NaN or infinite.
    #[error("a joint position or the base pose is not finite")]
    NonFinitePose,
    /// The base pose's rotation is off unit length by more than 1e-6.
    #[error("the base pose's rotation is not of unit length")]
    BadQuaternion,
    /// The server found the request malformed (a joint range outside the
    /// robot's: positions for another robot of the same name).
    #[error("the server found the request malformed")]
    Malformed,
    /// The server's disk has no room to store the robot's removal.
    #[error("the server's disk has no room to store the change")]
    StorageFull,
    /// The server failed in a way that is its own fault; it keeps serving.
    #[error("the server failed to handle the robot")]
    Internal,
    /// No server could be reached, or not in time: see [`ConnectError`].
    #[error(transparent)]
    Connection(#[from] ConnectError),
}

refusals! {
    RobotError {
        RobotRefused = InvalidRobot, UnknownRobot = UnknownName, NotOwner, ReadOnly,
        UnknownObject, OutOfLimits, NonFinitePose, BadQuaternion, Malformed, StorageFull,
        Internal,
    }
    others {
        RobotError::InvalidRobot(m) => ClientError::InvalidRobot(m),
        RobotError::UnknownJoint(j) => ClientError::UnknownJoint(j),
        RobotError::WrongJointCount => {
            ClientError::InvalidArgument("one position per moving joint of the robot")
        },
        RobotError::NameTooLong => ClientError::InvalidArgument(NAME_TOO_LONG),
        RobotError::TextTooLong => ClientError::InvalidArgument("robot text longer than 4 GiB"),
        RobotError::Link(e) => e.into(),
        RobotError::Connection(e) => e.into(),
    }
}

impl From<RegisterError> for RobotError {
    /// A link's registration failure: a connection fault stays one.
    fn from(e: RegisterError) -> Self {
        match e {
            RegisterError::Connection(c) => RobotError::Connection(c),
            other => RobotError::Link(other),
        }
    }
}

impl From<LookupError> for RobotError {
    /// A robot or link look-up's failure: an unknown name is an unknown
    /// robot.
    fn from(e: LookupError) -> Self {
        match e {
            LookupError::NameTooLong => RobotError::NameTooLong,
            LookupError::UnknownName => RobotError::UnknownRobot,
            LookupError::Internal => RobotError::Internal,
            LookupError::Connection(c) => RobotError::Connection(c),
        }
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use gjkd_proto::ErrorCode as C;

    use super::*;
    use crate::refusals::{Operation, op_error};

    /// Each of `cases` has the code written beside it, and the umbrella
    /// error of the same fault has the same: what Python and C report.
    macro_rules! codes {
        ($($e:expr => $code:expr),* $(,)?) => {$(
            let e = $e;
            assert_eq!(e.code(), $code, "{e:?}");
            assert_eq!(ClientError::from(e.clone()).code(), $code, "{e:?} as ClientError");
        )*};
    }

    /// Every code the operation `E` is refused with comes back as the
    /// variant of that code, with that code, and reads as the same
    /// refusal in the umbrella; every other code is a protocol fault.
    /// Returns how many codes are the operation's.
    fn refusals_round_trip<E>() -> usize
    where
        E: Operation + Clone + std::fmt::Debug + PartialEq + Into<ClientError>,
    {
        let mut own = 0;
        for code in C::ALL {
            let e: E = op_error(ClientError::Rejected(code));
            match E::refused(code) {
                Some(variant) => {
                    own += 1;
                    assert_eq!(e, variant);
                    assert_eq!(e.clone().into(), ClientError::Rejected(code), "{e:?}");
                }
                None => assert!(
                    matches!(e.clone().into(), ClientError::Protocol(m) if m.contains(&code.to_string())),
                    "{code:?} gave {e:?}"
                ),
            }
        }
        // The connection faults pass through unchanged, both ways.
        for fault in [
            ClientError::ServerGone("s".into()),
            ClientError::Timeout(Duration::from_millis(3)),
            ClientError::Protocol("p".into()),
            ClientError::Ipc("i".into()),
            ClientError::TooManyClients("s".into()),
        ] {
            let e: E = op_error(fault.clone());
            assert_eq!(e.into(), fault);
        }
        own
    }

    #[test]
    fn every_code_of_an_operation_is_its_own_variant_and_no_other() {
        // The counts are the server's refusals per operation
        // (docs/errors.md's sections).
        assert_eq!(refusals_round_trip::<RegisterError>(), 13);
        assert_eq!(refusals_round_trip::<RemoveError>(), 5);
        assert_eq!(refusals_round_trip::<LookupError>(), 2);
        assert_eq!(refusals_round_trip::<PoseError>(), 4);
        assert_eq!(refusals_round_trip::<QueryError>(), 7);
        assert_eq!(refusals_round_trip::<PoseReadError>(), 2);
        assert_eq!(refusals_round_trip::<StatsError>(), 1);
        assert_eq!(refusals_round_trip::<SceneError>(), 8);
        assert_eq!(refusals_round_trip::<RobotError>(), 11);
        // `Ok` is no refusal of any operation.
        assert_eq!(RegisterError::refused(C::Ok), None);
    }

    #[test]
    fn every_variant_has_the_code_of_the_same_fault_in_client_error() {
        let gone = || ConnectError::ServerGone("gjkd".into());
        codes! {
            RegisterError::InvalidShape(ShapeError::HalfExtentIsNegative) => None,
            RegisterError::NameTooLong => None,
            RegisterError::InvalidMesh("m".into()) => None,
            RegisterError::EmptyVertices => Some(C::EmptyVertices),
            RegisterError::TooManyVertices => Some(C::TooManyVertices),
            RegisterError::InvalidRadius => Some(C::InvalidRadius),
            RegisterError::NonFiniteVertex => Some(C::NonFiniteVertex),
            RegisterError::EmptyCompound => Some(C::EmptyCompound),
            RegisterError::TooManyPieces => Some(C::TooManyPieces),
            RegisterError::NonFinitePose => Some(C::NonFinitePose),
            RegisterError::BadQuaternion => Some(C::BadQuaternion),
            RegisterError::NameTaken => Some(C::NameTaken),
            RegisterError::TooManyObjects => Some(C::TooManyObjects),
            RegisterError::StorageFull => Some(C::StorageFull),
            RegisterError::Malformed => Some(C::Malformed),
            RegisterError::Internal => Some(C::Internal),
            RegisterError::Connection(gone()) => None,
            RemoveError::UnknownObject => Some(C::UnknownObject),
            RemoveError::NotOwner => Some(C::NotOwner),
            RemoveError::ReadOnly => Some(C::ReadOnly),
            RemoveError::StorageFull => Some(C::StorageFull),
            RemoveError::Internal => Some(C::Internal),
            RemoveError::Connection(gone()) => None,
            LookupError::NameTooLong => None,
            LookupError::UnknownName => Some(C::UnknownName),
            LookupError::Internal => Some(C::Internal),
            LookupError::Connection(gone()) => None,
            PoseError::UnknownObject => Some(C::UnknownObject),
            PoseError::NonFinitePose => Some(C::NonFinitePose),
            PoseError::BadQuaternion => Some(C::BadQuaternion),
            PoseError::Internal => Some(C::Internal),
            PoseError::Connection(gone()) => None,
            QueryError::ResultBufferTooSmall { needed: 2, got: 1 } => None,
            QueryError::UnknownObject => Some(C::UnknownObject),
            QueryError::NonFinitePose => Some(C::NonFinitePose),
            QueryError::BadQuaternion => Some(C::BadQuaternion),
            QueryError::InvalidOptions => Some(C::InvalidOptions),
            QueryError::EmptyBatch => Some(C::EmptyBatch),
            QueryError::BatchTooLarge => Some(C::BatchTooLarge),
            QueryError::Internal => Some(C::Internal),
            QueryError::NoRoomForGradient => None,
            QueryError::Connection(gone()) => None,
            PoseReadError::BatchTooLarge => Some(C::BatchTooLarge),
            PoseReadError::Internal => Some(C::Internal),
            PoseReadError::Connection(gone()) => None,
            StatsError::Internal => Some(C::Internal),
            StatsError::Connection(gone()) => None,
            SceneError::PartialSteps => None,
            SceneError::EdgeEnds => None,
            SceneError::UnknownObject => Some(C::UnknownObject),
            SceneError::InvalidOptions => Some(C::InvalidOptions),
            SceneError::Malformed => Some(C::Malformed),
            SceneError::BatchTooLarge => Some(C::BatchTooLarge),
            SceneError::NonFinitePose => Some(C::NonFinitePose),
            SceneError::BadQuaternion => Some(C::BadQuaternion),
            SceneError::OutOfLimits => Some(C::OutOfLimits),
            SceneError::Internal => Some(C::Internal),
            SceneError::Connection(gone()) => None,
            RobotError::InvalidRobot("r".into()) => Some(C::InvalidRobot),
            RobotError::UnknownJoint("j".into()) => Some(C::UnknownName),
            RobotError::WrongJointCount => None,
            RobotError::NameTooLong => None,
            RobotError::TextTooLong => None,
            RobotError::Link(RegisterError::NameTaken) => Some(C::NameTaken),
            RobotError::Link(RegisterError::InvalidMesh("m".into())) => None,
            RobotError::RobotRefused => Some(C::InvalidRobot),
            RobotError::UnknownRobot => Some(C::UnknownName),
            RobotError::NotOwner => Some(C::NotOwner),
            RobotError::ReadOnly => Some(C::ReadOnly),
            RobotError::UnknownObject => Some(C::UnknownObject),
            RobotError::OutOfLimits => Some(C::OutOfLimits),
            RobotError::NonFinitePose => Some(C::NonFinitePose),
            RobotError::BadQuaternion => Some(C::BadQuaternion),
            RobotError::Malformed => Some(C::Malformed),
            RobotError::StorageFull => Some(C::StorageFull),
            RobotError::Internal => Some(C::Internal),
            RobotError::Connection(gone()) => None,
        }
    }

    #[test]
    fn faults_found_before_sending_read_as_before_in_the_umbrella() {
        // Python's and C's messages and classes come from these.
        assert_eq!(
            ClientError::from(RegisterError::InvalidShape(ShapeError::CompoundIsNested)),
            ClientError::InvalidArgument("a compound cannot be a piece of a compound")
        );
        assert_eq!(
            ClientError::from(LookupError::NameTooLong),
            ClientError::InvalidArgument("name longer than MAX_NAME_LEN")
        );
        assert_eq!(
            ClientError::from(RobotError::UnknownJoint("j".into())),
            ClientError::UnknownJoint("j".into())
        );
        assert_eq!(
            ClientError::from(QueryError::ResultBufferTooSmall { needed: 3, got: 2 }),
            ClientError::ResultBufferTooSmall { needed: 3, got: 2 }
        );
        assert_eq!(
            ClientError::from(QueryError::NoRoomForGradient),
            ClientError::InvalidArgument(NO_GRADIENT_BUFFER)
        );
        // A connection fault reads the same in every error.
        let e = QueryError::Connection(ConnectError::Timeout(Duration::from_secs(1)));
        assert_eq!(
            e.to_string(),
            ConnectError::Timeout(Duration::from_secs(1)).to_string()
        );
        // A link's connection fault is the robot call's own.
        assert_eq!(
            RobotError::from(RegisterError::Connection(ConnectError::ServerGone(
                "s".into()
            ))),
            RobotError::Connection(ConnectError::ServerGone("s".into()))
        );
        assert_eq!(
            RobotError::from(LookupError::UnknownName),
            RobotError::UnknownRobot
        );
    }
}
