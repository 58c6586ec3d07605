//! The admin service: registration, removal, look-up, statistics, robots.

use iceoryx2::prelude::ZeroCopySend;

use crate::{ErrorCode, MAX_NAME_LEN, MAX_PIECES, PieceDesc, Pose};

/// Operations of the admin service; the wire values of [`AdminRequest::op`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum AdminOp {
    /// Server information and limits ([`AdminReply::info`]).
    Hello = 1,
    /// Register a convex object (one piece) or a compound (several), with
    /// the vertices in the request's slice payload.
    Register = 2,
    /// Remove object [`AdminRequest::object`].
    Remove = 3,
    /// Look an object up by [`AdminRequest::name`].
    Lookup = 4,
    /// Server statistics ([`AdminReply::stats`]).
    Stats = 5,
    /// Attach a robot's kinematics, named [`AdminRequest::name`], to the
    /// objects already registered as its links (named `<robot>/<link>`; a
    /// link with no such object has no shape and only carries its
    /// children). The slice payload is text in [`AdminChunk`](crate::AdminChunk)s
    /// ([`AdminChunk::pack_text`](crate::AdminChunk::pack_text)): the
    /// URDF, optionally followed by a NUL byte and an SRDF whose
    /// `disable_collisions` pairs (with the adjacent links) the server keeps
    /// as the robot's allowed pairs. [`AdminRequest::text_len`] is the
    /// text's length in bytes. The reply's id is the robot's id, for
    /// [`ItemKind::SetJoints`](crate::ItemKind::SetJoints); attaching a name again replaces the robot.
    AttachRobot = 6,
    /// Remove the robot named [`AdminRequest::name`] as a whole: its
    /// kinematics and every link object, in one commit (all or nothing).
    /// The reply's id is the robot's id. Refused with
    /// [`ErrorCode::UnknownName`] (no robot of that name),
    /// [`ErrorCode::ReadOnly`] (a robot of the scene file) and
    /// [`ErrorCode::NotOwner`] (another client's robot, or a link object
    /// another client registered).
    RemoveRobot = 7,
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
            7 => Some(AdminOp::RemoveRobot),
            _ => None,
        }
    }
}

/// Values of [`AdminRequest::lookup`].
pub mod lookup_kind {
    /// Look up an object (the default, 0).
    pub const OBJECT: u32 = 0;
    /// Look up a robot attached with [`AdminOp::AttachRobot`](super::AdminOp::AttachRobot)
    /// or loaded from the scene file: the reply's id is the robot's.
    pub const ROBOT: u32 = 1;
}

/// Request header of the admin service. The slice payload
/// ([`AdminChunk`](crate::AdminChunk)s) holds the vertices of a
/// registration, or the text of a robot ([`AdminOp::AttachRobot`]), and is
/// empty for other operations.
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.AdminRequest")]
pub struct AdminRequest {
    /// [`AdminOp`] wire value.
    pub op: u32,
    /// [`shape_kind`](crate::shape_kind) value, for [`AdminOp::Register`].
    pub shape: u32,
    /// [`lookup_kind`] value, for [`AdminOp::Lookup`].
    pub lookup: u32,
    /// Number of valid entries of `pieces`, for [`AdminOp::Register`].
    pub piece_count: u32,
    /// Bytes of `name` in use.
    pub name_len: u32,
    /// Bytes of robot text in the slice payload, for
    /// [`AdminOp::AttachRobot`].
    pub text_len: u32,
    /// The object to remove, for [`AdminOp::Remove`].
    pub object: u64,
    /// The registration token, for [`AdminOp::Register`]: 0 for none, or
    /// a value the client draws at random for each registration and sends
    /// again, unchanged with the rest of the request, when it retries that
    /// registration (after a timeout, or a server that died and came back).
    /// A server remembers the tokens of each client's last 64 registrations,
    /// committed with the object, so a retry gets the id of the object that
    /// was stored (also after a crash between the commit and the reply),
    /// never a second object. A token is forgotten with its object; the
    /// same token with another shape or name is [`ErrorCode::Malformed`].
    pub token: u64,
    /// UTF-8 name: optional for [`AdminOp::Register`], required for
    /// [`AdminOp::Lookup`], [`AdminOp::AttachRobot`] and
    /// [`AdminOp::RemoveRobot`].
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
            lookup: lookup_kind::OBJECT,
            piece_count: 0,
            name_len: 0,
            text_len: 0,
            object: 0,
            token: 0,
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
#[type_name("gjkd.v4.ServerInfo")]
pub struct ServerInfo {
    /// [`PROTOCOL_VERSION`](crate::PROTOCOL_VERSION) of the server.
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
    /// Most rows in one scene answer ([`SceneRequest::max_rows`](crate::SceneRequest::max_rows)
    /// above it is cut to it).
    pub max_rows: u64,
    /// Most objects the server holds.
    pub max_objects: u64,
    /// Process id of the server.
    pub pid: u64,
}

/// Server statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.ServerStats")]
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
#[type_name("gjkd.v4.AdminReply")]
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
