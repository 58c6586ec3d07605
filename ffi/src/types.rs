//! The plain C structs and enums of the API, and their conversions to the
//! Rust client's types.

#![allow(non_camel_case_types)]

use gjkd_proto::{Pose, Precision};
use nalgebra::Isometry3;
use rust_client::{ErrorCode, ItemResult, QueryOptions, ServerInfo, ServerStats};

use crate::status::Failure;

/// Identifier of a registered object (never 0 for a real object).
pub type gjkd_id = u64;

/// A rigid pose: translation, then rotation quaternion `[qx, qy, qz, qw]`.
/// Laid out as 7 consecutive doubles `[x, y, z, qx, qy, qz, qw]`, so an
/// array of `double[7]` rows can be passed as an array of poses. The
/// quaternion must be of unit length within 1e-6.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct gjkd_pose {
    /// Translation `[x, y, z]`.
    pub translation: [f64; 3],
    /// Unit quaternion `[qx, qy, qz, qw]` (identity: `{0, 0, 0, 1}`).
    pub rotation: [f64; 4],
}

impl gjkd_pose {
    /// The wire pose, bit for bit.
    pub fn wire(&self) -> Pose {
        Pose {
            translation: self.translation,
            rotation: self.rotation,
        }
    }

    /// The isometry with exactly these components (check them first).
    pub fn isometry(&self) -> Isometry3<f64> {
        self.wire().to_isometry_unchecked()
    }

    /// Checks what the server checks ([`Pose::checked`]): finite, each
    /// translation component within `GJKD_MAX_TRANSLATION`, a unit
    /// quaternion within the server's tolerance. On failure, the server's
    /// code and why in words.
    pub fn check(&self) -> Result<(), (ErrorCode, &'static str)> {
        match self.wire().checked() {
            Ok(_) => Ok(()),
            Err(ErrorCode::BadQuaternion) => Err((
                ErrorCode::BadQuaternion,
                "has a rotation quaternion that is not of unit length (within 1e-6)",
            )),
            Err(code) => Err((
                code,
                "has a NaN or infinite component, or a translation beyond GJKD_MAX_TRANSLATION",
            )),
        }
    }
}

/// Shape kinds of `gjkd_shape::kind`.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum gjkd_shape_kind {
    /// A ball of `radius` about the body origin.
    GJKD_SHAPE_SPHERE = 1,
    /// The segment from `a` to `b` grown by `radius`.
    GJKD_SHAPE_CAPSULE = 2,
    /// A box of half extents `a`, centred on the body origin, grown by
    /// `radius` (every point within `radius` of the box: each half extent
    /// grows by `radius`, edges and corners become round; 0 for a sharp
    /// box).
    GJKD_SHAPE_BOX = 3,
    /// The convex hull of `vertex_count` points at `vertices` grown by
    /// `radius`.
    GJKD_SHAPE_POLYTOPE = 4,
    /// An exact cylinder about the body z axis, centred on the body origin:
    /// the disk of radius `a[0]` swept from `z = -a[1]` to `z = +a[1]`,
    /// grown by `radius` (radius and half-height each grow by it, the rims
    /// become round; 0 for sharp rims). Never approximated by a polytope.
    GJKD_SHAPE_CYLINDER = 5,
}

/// A convex shape, in its body frame. Fields a kind does not use are
/// ignored.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct gjkd_shape {
    /// A `gjkd_shape_kind` value.
    pub kind: u32,
    /// Rounding radius, finite and `>= 0`: the shape is grown by it (every
    /// point within `radius` of it), so each of its sizes grows by it (the
    /// ball's radius for a sphere).
    pub radius: f64,
    /// Capsule: one end. Box: the half extents, each `>= 0`. Cylinder:
    /// `{radius, half_height, 0}`, each `>= 0`.
    pub a: [f64; 3],
    /// Capsule: the other end.
    pub b: [f64; 3],
    /// Polytope: `3 * vertex_count` doubles, `x, y, z` per vertex. Read
    /// during the call only. May be NULL when `vertex_count` is 0 (which
    /// the server refuses with `GJKD_CODE_EMPTY_VERTICES`).
    pub vertices: *const f64,
    /// Polytope: number of vertices.
    pub vertex_count: usize,
}

/// A convex piece of a compound, placed in the compound's body frame.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct gjkd_piece {
    /// Pose of the piece in the compound's body frame.
    pub offset: gjkd_pose,
    /// The piece's shape.
    pub shape: gjkd_shape,
}

/// Arithmetic of the support search (`gjkd_query_options::precision`).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum gjkd_precision {
    /// f64: the distance is exact to the tolerance (the default).
    GJKD_PRECISION_DOUBLE = 0,
    /// f32 support search for objects of 16 to 1 023 vertices: faster, the
    /// distance exact to the tolerance plus about 1e-6 of the objects'
    /// sizes, bounds still certified.
    GJKD_PRECISION_SINGLE = 1,
}

/// Options of a query. Start from `gjkd_query_options_default()`; passing
/// NULL where options are asked for means the defaults.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct gjkd_query_options {
    /// Relative tolerance of the stopping rule, finite and `>= 0` (default
    /// `GJKD_DEFAULT_TOLERANCE`, 100 × machine epsilon).
    pub tolerance: f64,
    /// Early-exit margin, used when `use_margin` is true: stop once the
    /// distance is proved greater than it (`GJKD_QUERY_FARTHER`) or at most
    /// it (`GJKD_QUERY_CLOSER`). Finite. A query may still end
    /// `GJKD_QUERY_CONVERGED` (the exact distance found before a bound
    /// crossed the margin, as for objects that touch or are near the
    /// margin): compare `distance` with the margin then.
    pub margin: f64,
    /// Iteration cap, at least 1 (default `GJKD_DEFAULT_MAX_ITERATIONS`).
    pub max_iterations: u32,
    /// A `gjkd_precision` value (default `GJKD_PRECISION_DOUBLE`).
    pub precision: u32,
    /// Whether `margin` is used (default false).
    pub use_margin: bool,
    /// Start from the simplex the server kept for this pair after this
    /// handle's previous query of it (default true). Changes the time only.
    pub warm_start: bool,
    /// Also answer the signed distance with its certified interval
    /// (`gjkd_answer::signed_distance`; default false): the penetration
    /// depth, negated, for overlapping pairs. Costs nothing for a pair
    /// proved apart.
    pub signed_distance: bool,
}

impl Default for gjkd_query_options {
    fn default() -> Self {
        gjkd_query_options {
            tolerance: gjkd_proto::DEFAULT_TOLERANCE,
            margin: 0.0,
            max_iterations: gjkd_proto::DEFAULT_MAX_ITERATIONS,
            precision: gjkd_precision::GJKD_PRECISION_DOUBLE as u32,
            use_margin: false,
            warm_start: true,
            signed_distance: false,
        }
    }
}

impl gjkd_query_options {
    /// The client's options, after the checks the server would make (so
    /// that a bad option is refused by name, before anything is sent).
    pub fn checked(&self) -> Result<QueryOptions, Failure> {
        if !(self.tolerance.is_finite() && self.tolerance >= 0.0) {
            return Err(Failure::invalid_code(
                ErrorCode::InvalidOptions,
                "tolerance must be finite and >= 0",
            ));
        }
        if self.max_iterations == 0 {
            return Err(Failure::invalid_code(
                ErrorCode::InvalidOptions,
                "max_iterations must be at least 1",
            ));
        }
        if self.use_margin && !self.margin.is_finite() {
            return Err(Failure::invalid_code(
                ErrorCode::InvalidOptions,
                "margin must be finite",
            ));
        }
        let precision = match self.precision {
            0 => Precision::Double,
            1 => Precision::Single,
            p => {
                return Err(Failure::invalid_code(
                    ErrorCode::InvalidOptions,
                    format!("precision {p} is not a gjkd_precision"),
                ));
            }
        };
        Ok(QueryOptions {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            margin: self.use_margin.then_some(self.margin),
            warm_start: self.warm_start,
            precision,
            signed_distance: self.signed_distance,
        })
    }
}

/// How a query ended (`gjkd_answer::status`, `gjkd_results::status`).
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum gjkd_query_status {
    /// No answer: the item failed (see its error code).
    GJKD_QUERY_NONE = 0,
    /// The stopping rule held: the distance is exact to the tolerance.
    GJKD_QUERY_CONVERGED = 1,
    /// Early exit: the distance is proved greater than the margin (never
    /// reported without a margin; with one, `GJKD_QUERY_CONVERGED` may
    /// come instead, see `gjkd_query_options::margin`).
    GJKD_QUERY_FARTHER = 2,
    /// Early exit: the distance is proved at most the margin.
    GJKD_QUERY_CLOSER = 3,
    /// The iteration cap was reached first; the bounds still hold.
    GJKD_QUERY_ITERATION_CAP = 4,
    /// Round-off stopped progress before the tolerance was met; the bounds
    /// still hold.
    GJKD_QUERY_TOLERANCE_NOT_MET = 5,
    /// Scene queries only: answered from the pair's last certified interval
    /// widened by how far the objects moved since, without running GJK;
    /// the bounds hold, the distance and points are the last answer's
    /// carried with the objects.
    GJKD_QUERY_BOUNDED = 6,
}

/// The server's error codes: per item in `gjkd_results::error`, and for a
/// call that returned `GJKD_ERR_REJECTED` from `gjkd_last_error_code()`.
/// `docs/errors.md` has the full table.
#[repr(u32)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum gjkd_error_code {
    /// No error.
    GJKD_CODE_OK = 0,
    /// No object has this id (never registered, removed, or from a server
    /// run that has ended without persistence).
    GJKD_CODE_UNKNOWN_OBJECT = 1,
    /// A pose or piece offset is not finite, or lies beyond about 1e301.
    GJKD_CODE_NON_FINITE_POSE = 2,
    /// A rotation quaternion is off unit length by more than 1e-6.
    GJKD_CODE_BAD_QUATERNION = 3,
    /// A query option is out of its domain.
    GJKD_CODE_INVALID_OPTIONS = 4,
    /// A shape has no vertices.
    GJKD_CODE_EMPTY_VERTICES = 5,
    /// A shape has more vertices than the server accepts.
    GJKD_CODE_TOO_MANY_VERTICES = 6,
    /// A radius is negative, NaN or infinite.
    GJKD_CODE_INVALID_RADIUS = 7,
    /// A request has more items than the server accepts. Pair batches
    /// (`gjkd_set_poses()`, `gjkd_distances()`, `gjkd_query_pairs()`) and
    /// paths longer than one request (`gjkd_path()`, `gjkd_path_joints()`)
    /// are split by this library; what cannot be split does see it:
    /// `gjkd_clearance()`, `gjkd_within()` and `gjkd_nearest()` with more
    /// members and allowed pairs than the server's `max_batch`
    /// (`gjkd_server_info()`), and a path whose members and allowed pairs
    /// plus one step's poses (or joint items) exceed it.
    GJKD_CODE_BATCH_TOO_LARGE = 8,
    /// A batch has no items.
    GJKD_CODE_EMPTY_BATCH = 9,
    /// A request no client should send.
    GJKD_CODE_MALFORMED = 10,
    /// The object belongs to another client.
    GJKD_CODE_NOT_OWNER = 11,
    /// The object comes from the server's scene file: anyone may move it,
    /// nobody may remove it.
    GJKD_CODE_READ_ONLY = 12,
    /// A compound has more than `GJKD_MAX_PIECES` pieces.
    GJKD_CODE_TOO_MANY_PIECES = 13,
    /// A compound has no pieces.
    GJKD_CODE_EMPTY_COMPOUND = 14,
    /// A vertex is not finite, or the shape reaches beyond about 5e300.
    GJKD_CODE_NON_FINITE_VERTEX = 15,
    /// No object has this name.
    GJKD_CODE_UNKNOWN_NAME = 16,
    /// Another object already has this name.
    GJKD_CODE_NAME_TAKEN = 17,
    /// The server holds as many objects as it accepts.
    GJKD_CODE_TOO_MANY_OBJECTS = 18,
    /// The server failed in a way that is its own fault; it keeps serving.
    GJKD_CODE_INTERNAL = 19,
    /// The server's disk has no room to store a registration or removal:
    /// the change was not made; the same call succeeds once there is room.
    GJKD_CODE_STORAGE_FULL = 20,
    /// A joint position is outside its joint's limits.
    GJKD_CODE_OUT_OF_LIMITS = 21,
    /// A robot's URDF is malformed, or its links do not form one tree of
    /// supported joints.
    GJKD_CODE_INVALID_ROBOT = 22,
}

/// The answer to one pair query. Distances are after radii; points are in
/// world coordinates.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct gjkd_answer {
    /// Distance between the (rounded) shapes, `>= 0`.
    pub distance: f64,
    /// Certified lower bound on the distance.
    pub lower: f64,
    /// Certified upper bound on the distance.
    pub upper: f64,
    /// Lower bound on the penetration depth; 0 when separated.
    pub penetration: f64,
    /// Nearest point on A.
    pub point_a: [f64; 3],
    /// Nearest point on B.
    pub point_b: [f64; 3],
    /// Unit vector from A's nearest point towards B's; zero when the cores
    /// touch or intersect.
    pub normal: [f64; 3],
    /// A `gjkd_query_status` value.
    pub status: u32,
    /// Subalgorithm iterations (summed over piece pairs for compounds).
    pub iterations: u32,
    /// Pieces of A and B that realise the distance (0 for convex objects).
    pub pieces: [u32; 2],
    /// The query started from the pair's last simplex.
    pub warm_started: bool,
    /// gjk's Backup Procedure ran (a numerically hard case).
    pub backup_used: bool,
    /// Whether the signed-distance fields hold an answer (the query asked
    /// with `gjkd_query_options::signed_distance`).
    pub has_signed_distance: bool,
    /// The signed distance: the distance apart, minus the penetration
    /// depth (the shortest separating translation) overlapping. `point_a`,
    /// `point_b` and `normal` are then its witnesses and direction
    /// (`point_b - point_a = signed_distance * normal`).
    pub signed_distance: f64,
    /// Certified lower bound on the signed distance.
    pub signed_lower: f64,
    /// Certified upper bound on the signed distance.
    pub signed_upper: f64,
}

impl From<&ItemResult> for gjkd_answer {
    fn from(r: &ItemResult) -> Self {
        gjkd_answer {
            distance: r.distance,
            lower: r.lower,
            upper: r.upper,
            penetration: r.penetration,
            point_a: r.point_a,
            point_b: r.point_b,
            normal: r.normal,
            status: r.status,
            iterations: r.iterations,
            pieces: r.pieces,
            warm_started: r.flags & gjkd_proto::result_flags::WARM_STARTED != 0,
            backup_used: r.flags & gjkd_proto::result_flags::BACKUP_USED != 0,
            has_signed_distance: r.flags & gjkd_proto::result_flags::SIGNED_DISTANCE != 0,
            signed_distance: r.signed_distance,
            signed_lower: r.signed_lower,
            signed_upper: r.signed_upper,
        }
    }
}

/// Caller-owned output arrays of `gjkd_distances()`, one row per pair. Each
/// pointer is either NULL (that field is not wanted) or points to room for
/// `count` rows of the stated width; `distance` and `error` are required.
/// Row `i` of a failed pair has its code in `error[i]` and zeros elsewhere.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct gjkd_results {
    /// `count` distances. Required.
    pub distance: *mut f64,
    /// `count` certified lower bounds.
    pub lower: *mut f64,
    /// `count` certified upper bounds.
    pub upper: *mut f64,
    /// `count` lower bounds on the penetration depth.
    pub penetration: *mut f64,
    /// `3 * count` doubles: nearest points on A.
    pub point_a: *mut f64,
    /// `3 * count` doubles: nearest points on B.
    pub point_b: *mut f64,
    /// `3 * count` doubles: unit normals from A towards B.
    pub normal: *mut f64,
    /// `count` `gjkd_query_status` values.
    pub status: *mut u32,
    /// `count` iteration counts.
    pub iterations: *mut u32,
    /// `2 * count` piece indices (A, B).
    pub pieces: *mut u32,
    /// `count` `gjkd_error_code` values, 0 where the pair was answered.
    /// Required.
    pub error: *mut u32,
    /// `count` flags: the query started warm.
    pub warm_started: *mut bool,
}

/// What the server said about itself at the last (re)connection.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct gjkd_info {
    /// The server's protocol version (`GJKD_PROTOCOL_VERSION`).
    pub protocol: u32,
    /// Wait strategy: 1 spin, 2 block, 3 adaptive.
    pub wait: u32,
    /// Most items in one request (larger batches are split).
    pub max_batch: u32,
    /// Most vertices in one registration.
    pub max_vertices: u32,
    /// Most pieces in one compound.
    pub max_pieces: u32,
    /// Most client processes per service.
    pub max_clients: u32,
    /// Most objects the server holds.
    pub max_objects: u64,
    /// Process id of the server.
    pub pid: u64,
}

impl From<ServerInfo> for gjkd_info {
    fn from(i: ServerInfo) -> Self {
        gjkd_info {
            protocol: i.protocol,
            wait: i.wait,
            max_batch: i.max_batch,
            max_vertices: i.max_vertices,
            max_pieces: i.max_pieces,
            max_clients: i.max_clients,
            max_objects: i.max_objects,
            pid: i.pid,
        }
    }
}

/// The server's counters.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct gjkd_server_stats {
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
    /// Query clients connected, as of the server's last housekeeping.
    pub clients: u64,
    /// Writes of the server's state that failed.
    pub persist_errors: u64,
}

impl From<ServerStats> for gjkd_server_stats {
    fn from(s: ServerStats) -> Self {
        gjkd_server_stats {
            objects: s.objects,
            requests: s.requests,
            items: s.items,
            item_errors: s.item_errors,
            cache_entries: s.cache_entries,
            cache_capacity: s.cache_capacity,
            cache_hits: s.cache_hits,
            cache_misses: s.cache_misses,
            cache_evictions: s.cache_evictions,
            clients: s.clients,
            persist_errors: s.persist_errors,
        }
    }
}

/// How a handle's registrations treat names and the handle's end; set with
/// `gjkd_set_registration_options()`. Both off by default.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct gjkd_registration_options {
    /// A registration whose name is taken gives the id of the object
    /// already under that name (its shape not compared, its pose not
    /// changed; a mesh's `out_info` then zeroed), and a robot registration
    /// whose name is taken gives that robot (attached again to its link
    /// objects if a restarted server kept them but not the robot): what a
    /// restarted node needs to get its objects back instead of
    /// `GJKD_CODE_NAME_TAKEN`.
    pub reuse_names: bool,
    /// Objects and robots registered from now on are removed when the
    /// handle is closed (`gjkd_close()`, the C++ destructor). A process
    /// that dies without closing leaves them, unless the server runs with
    /// `--remove-departed`.
    pub remove_on_close: bool,
}
