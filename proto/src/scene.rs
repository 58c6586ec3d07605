//! The scene service: whole-scene questions in one request.
//!
//! A [`SceneRequest`] header asks one question ([`SceneKind`]) about a group
//! of objects (a robot's links, one object, or a set listed in the request);
//! the request's slice of [`Item`](crate::Item)s carries, in order, the pose
//! and joint updates to apply first ([`ItemKind::SetPose`](crate::ItemKind::SetPose),
//! [`ItemKind::SetJoints`](crate::ItemKind::SetJoints)), the group's members
//! ([`ItemKind::Member`](crate::ItemKind::Member)), pairs never to report
//! ([`ItemKind::Allow`](crate::ItemKind::Allow)) and, for a path, the ends of
//! its steps ([`ItemKind::Step`](crate::ItemKind::Step), or a pose item
//! flagged [`item_flags::END_STEP`](crate::item_flags::END_STEP)). The answer is a
//! [`SceneReply`] header and a slice of [`SceneRow`]s, at most
//! [`SceneRequest::max_rows`] of them.
//!
//! Every row carries a certified interval: a pair whose distance could be at
//! most the asked margin is never left out, and a truncated answer says so
//! ([`scene_reply_flags::TRUNCATED`]) rather than dropping rows silently.

use iceoryx2::prelude::ZeroCopySend;

use crate::{DEFAULT_MAX_ITERATIONS, DEFAULT_TOLERANCE, ErrorCode, Gradient, ItemResult};

/// The question of a [`SceneRequest`]; the wire values of
/// [`SceneRequest::kind`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum SceneKind {
    /// For each member of the group, the nearest object outside the group
    /// (one row per member; `b` is 0 when no object qualifies, for example
    /// none within the cut-off [`scene_flags::CUTOFF`]).
    Clearance = 1,
    /// Every pair, group against the rest (or all against all with
    /// [`scene_flags::ALL_PAIRS`]), whose distance is at most
    /// [`SceneRequest::margin`]. A row answered from motion bounds
    /// ([`Status::Bounded`](crate::Status::Bounded), an interval no wider
    /// than the accepted accuracy) is reported when its interval reaches
    /// below the margin, so such a pair may lie beyond the margin by at most
    /// its interval's width.
    Within = 2,
    /// The [`SceneRequest::k`] objects nearest to the group's only member,
    /// nearest first.
    Nearest = 3,
}

impl SceneKind {
    /// The kind with wire value `raw`, if any.
    pub fn from_raw(raw: u32) -> Option<Self> {
        match raw {
            1 => Some(SceneKind::Clearance),
            2 => Some(SceneKind::Within),
            3 => Some(SceneKind::Nearest),
            _ => None,
        }
    }
}

/// Whether a request is a path, and what it reports per step; the wire
/// values of [`SceneRequest::path`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum PathMode {
    /// Not a path: pose and joint items change the stored poses, then the
    /// question is asked once.
    Single = 0,
    /// A path: the items up to each [`ItemKind::Step`](crate::ItemKind::Step)
    /// (or each pose item flagged [`END_STEP`](crate::item_flags::END_STEP))
    /// are one step's poses (a candidate motion: the stored poses are the
    /// same after the request as before), and the question is answered at
    /// every step.
    EveryStep = 1,
    /// A path that stops at its first step with a pair within the margin
    /// ([`SceneKind::Within`] only), reporting that step's pairs and its
    /// index in [`SceneReply::first_hit`].
    FirstHit = 2,
    /// A continuous path ([`SceneKind::Within`] only): the poses after each
    /// step are waypoints, and the motion between two consecutive
    /// waypoints is one segment, `s` running from 0 (the first waypoint)
    /// to 1 (the next). Along a segment, joint positions move linearly in
    /// `s`; a rigid object's translation moves linearly and its rotation
    /// along the shortest arc at a constant rate (slerp), or, with
    /// [`scene_flags::LINEAR_QUATERNION`], its quaternion's components
    /// linearly, renormalised (the configuration variables of the GJK
    /// paper's Section 8). Every pose of the segment is asked, not samples
    /// of it: a segment with no row is certified clear (no pair of the
    /// question within the margin at any `s`); a segment with a row has
    /// its first contact in the row's bracket
    /// [[`SceneRow::s_lo`], [`SceneRow::s_hi`]], at most
    /// [`SceneRequest::bracket`] wide: every pose before `s_lo` is
    /// certified clear, and the row is the pair's answer at `s_hi`, within
    /// the margin (its upper bound at most the margin, but for a contact
    /// too grazing for the pair query's accuracy to decide: its interval
    /// then reaches below the margin). The row's `step` is the segment's
    /// index (segment `k` runs from waypoint `k` to `k + 1`);
    /// [`SceneReply::first_hit`] is the first segment with a contact,
    /// [`SceneReply::steps`] the segments answered. Pairs neither of
    /// whose objects the path moves are not asked. A path with fewer than
    /// two waypoints, a segment along which nothing moves, or an object
    /// both posed and moved as a robot's link is malformed.
    Continuous = 3,
}

impl PathMode {
    /// The mode with wire value `raw`, if any.
    pub fn from_raw(raw: u32) -> Option<Self> {
        match raw {
            0 => Some(PathMode::Single),
            1 => Some(PathMode::EveryStep),
            2 => Some(PathMode::FirstHit),
            3 => Some(PathMode::Continuous),
            _ => None,
        }
    }
}

/// Bits of [`SceneRequest::flags`].
pub mod scene_flags {
    /// Start each pair from the server's cached simplex (for this client)
    /// and update the cache.
    pub const WARM_START: u32 = 1;
    /// Answer a pair from its cached certified interval, widened by how far
    /// either object can have moved since, when that decides the question or
    /// is within the accepted accuracy; such rows have status
    /// [`Status::Bounded`](crate::Status::Bounded).
    pub const MOTION_BOUNDS: u32 = 1 << 1;
    /// [`SceneKind::Within`](super::SceneKind::Within): every pair of the
    /// scene, not only group against the rest.
    pub const ALL_PAIRS: u32 = 1 << 2;
    /// Search support points in f32, as
    /// [`Precision::Single`](crate::Precision::Single).
    pub const SINGLE_PRECISION: u32 = 1 << 3;
    /// [`SceneKind::Clearance`](super::SceneKind::Clearance) and
    /// [`SceneKind::Nearest`](super::SceneKind::Nearest): ignore objects
    /// farther than [`SceneRequest::margin`](super::SceneRequest::margin)
    /// (they may still be reported when found on the way, but are never
    /// searched for).
    pub const CUTOFF: u32 = 1 << 4;
    /// Clamp joint positions outside their limits instead of refusing the
    /// request, as [`item_flags::CLAMP`](crate::item_flags::CLAMP).
    pub const CLAMP: u32 = 1 << 5;
    /// Exact distances on every reported row: no row is answered from
    /// motion bounds ([`Status::Bounded`](crate::Status::Bounded)) or
    /// left at a margin's early exit ([`Status::Closer`](crate::Status::Closer));
    /// each runs GJK to the tolerance. Motion bounds and early exits still
    /// rule out pairs that are not reported.
    pub const EXACT: u32 = 1 << 6;
    /// [`SceneKind::Within`](super::SceneKind::Within) and
    /// [`SceneKind::Clearance`](super::SceneKind::Clearance): the group's
    /// members meet each other too, but the allowed pairs (for a robot: its
    /// self-collisions, without the SRDF's disabled pairs and adjacent
    /// links); a clearance row's nearest object may then be another member.
    /// Refused with nearest.
    pub const SELF_PAIRS: u32 = 1 << 10;
    /// Every row also carries its distance's gradient with respect to the
    /// coordinates that move its `a` object (see
    /// [`Gradient`](crate::Gradient)), at the row's step, in
    /// [`SceneRow::gradient`](super::SceneRow::gradient).
    pub const GRADIENTS: u32 = 1 << 7;
    /// With [`GRADIENTS`], rows of robot links: the base pose's twist too.
    pub const GRADIENT_BASE: u32 = 1 << 8;
    /// [`PathMode::Continuous`](super::PathMode::Continuous): rigid objects
    /// turn with their quaternion's components linear in `s`, renormalised
    /// (the paper's configuration variables), not along the shortest arc;
    /// the quaternions are taken with the signs given. Malformed in any
    /// other mode.
    pub const LINEAR_QUATERNION: u32 = 1 << 9;
    /// Every reported row also carries its pair's signed distance with its
    /// certified interval ([`ItemResult::signed_distance`](crate::ItemResult::signed_distance),
    /// `signed_lower`, `signed_upper`, flagged
    /// [`result_flags::SIGNED_DISTANCE`](crate::result_flags::SIGNED_DISTANCE)),
    /// at the row's step: a pair apart carries its distance (the same
    /// value and interval, also for a row answered from motion bounds or
    /// at a margin's early exit), a pair that may overlap minus its
    /// penetration depth, with the depth's witnesses, normal and pieces.
    /// It changes which rows are reported in no way: the questions compare
    /// the distance, which is 0 for every overlapping pair, so
    /// [`SceneKind::Within`](super::SceneKind::Within) with any margin
    /// reports every overlapping pair however deep, and
    /// [`SceneKind::Nearest`](super::SceneKind::Nearest) and
    /// [`SceneKind::Clearance`](super::SceneKind::Clearance) rank
    /// overlapping objects as equally near (distance 0), not by depth.
    /// Refused (malformed) with
    /// [`PathMode::Continuous`](super::PathMode::Continuous), whose rows
    /// answer poses between the waypoints.
    pub const SIGNED_DISTANCE: u32 = 1 << 11;
    /// Every bit this version knows; others are refused as malformed.
    pub const ALL: u32 = WARM_START
        | MOTION_BOUNDS
        | ALL_PAIRS
        | SINGLE_PRECISION
        | CUTOFF
        | CLAMP
        | EXACT
        | SELF_PAIRS
        | GRADIENTS
        | GRADIENT_BASE
        | LINEAR_QUATERNION
        | SIGNED_DISTANCE;
}

/// Bits of [`SceneReply::flags`].
pub mod scene_reply_flags {
    /// More rows qualified than [`SceneRequest::max_rows`](super::SceneRequest::max_rows):
    /// the rows sent are a prefix, [`SceneReply::total`](super::SceneReply::total)
    /// counts them all.
    pub const TRUNCATED: u32 = 1;
}

/// Request header of the scene service.
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.SceneRequest")]
pub struct SceneRequest {
    /// [`SceneKind`] wire value.
    pub kind: u32,
    /// [`PathMode`] wire value.
    pub path: u32,
    /// The group: a robot id (its links, with the robot's allowed pairs), an
    /// object id (a group of one), or 0 for the members listed by
    /// [`ItemKind::Member`](crate::ItemKind::Member) items.
    pub group: u64,
    /// [`SceneKind::Within`]'s margin; the cut-off of
    /// [`scene_flags::CUTOFF`].
    pub margin: f64,
    /// Relative tolerance of every pair query.
    pub tolerance: f64,
    /// An absolute accuracy the caller accepts: a pair whose widened
    /// interval is at most this wide is answered without running GJK
    /// (with [`scene_flags::MOTION_BOUNDS`]). 0 for none.
    pub accept_absolute: f64,
    /// A relative accuracy the caller accepts: as `accept_absolute`, for an
    /// interval at most this times its upper end wide. 0 for none.
    pub accept_relative: f64,
    /// Iteration cap of every pair query.
    pub max_iterations: u32,
    /// [`SceneKind::Nearest`]: how many objects.
    pub k: u32,
    /// Most rows the reply may carry (at most the server's
    /// [`ServerInfo::max_rows`](crate::ServerInfo::max_rows)).
    pub max_rows: u32,
    /// [`scene_flags`] bits.
    pub flags: u32,
    /// [`PathMode::Continuous`]: the widest bracket `[s_lo, s_hi]` of a
    /// segment's first contact, in `s` (a finite number `> 0`; default
    /// [`DEFAULT_BRACKET`]).
    pub bracket: f64,
}

/// [`SceneRequest::bracket`]'s default: contacts located to a millionth
/// of their segment.
pub const DEFAULT_BRACKET: f64 = 1e-6;

impl Default for SceneRequest {
    /// A request with kind 0, which no server accepts: iceoryx2 needs a
    /// default header, and a forgotten `kind` must not mean anything.
    fn default() -> Self {
        SceneRequest {
            kind: 0,
            ..SceneRequest::new(SceneKind::Clearance, 0)
        }
    }
}

impl SceneRequest {
    /// A question about `group` with the default tolerance and iteration
    /// cap, warm starts and motion bounds on, no margin, no path, and room
    /// for no rows (set [`SceneRequest::max_rows`]).
    pub fn new(kind: SceneKind, group: u64) -> Self {
        SceneRequest {
            kind: kind as u32,
            path: PathMode::Single as u32,
            group,
            margin: 0.0,
            tolerance: DEFAULT_TOLERANCE,
            accept_absolute: 0.0,
            accept_relative: 0.0,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            k: 0,
            max_rows: 0,
            flags: scene_flags::WARM_START | scene_flags::MOTION_BOUNDS,
            bracket: DEFAULT_BRACKET,
        }
    }

    /// The question, if it is one this version knows.
    pub fn scene_kind(&self) -> Option<SceneKind> {
        SceneKind::from_raw(self.kind)
    }

    /// The path mode, if it is one this version knows.
    pub fn path_mode(&self) -> Option<PathMode> {
        PathMode::from_raw(self.path)
    }
}

/// One row of a scene answer: a pair and its distance answer.
#[derive(Clone, Copy, Debug, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.SceneRow")]
pub struct SceneRow {
    /// The group's object (the object asked about, for
    /// [`SceneKind::Nearest`]).
    pub a: u64,
    /// The other object; 0 when none qualifies.
    pub b: u64,
    /// The path step (0 when not a path).
    pub step: u32,
    /// Zero.
    pub reserved: u32,
    /// The pair's answer, as a pair query's, with `point_a` on `a`.
    /// `lower` and `upper` always bound the true distance; `distance` and
    /// the points are exact (to the tolerance) for
    /// [`Status::Converged`](crate::Status::Converged), and an estimate
    /// inside the interval for [`Status::Closer`](crate::Status::Closer)
    /// (a margin's early exit) and [`Status::Bounded`](crate::Status::Bounded)
    /// (motion bounds); [`scene_flags::EXACT`] asks for exact rows only.
    /// With [`scene_flags::SIGNED_DISTANCE`], its signed-distance fields
    /// hold the pair's signed distance.
    pub result: ItemResult,
    /// The pair's gradient with [`scene_flags::GRADIENTS`] (see
    /// [`Gradient`]); [`Gradient::NONE`] otherwise.
    pub gradient: Gradient,
    /// [`PathMode::Continuous`]: every pose of the segment before this `s`
    /// is certified clear (0 otherwise).
    pub s_lo: f64,
    /// [`PathMode::Continuous`]: the `s` of the pose `result` answers, the
    /// end of the first contact's bracket (0 otherwise).
    pub s_hi: f64,
}

/// Response header of the scene service.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.SceneReply")]
pub struct SceneReply {
    /// [`ErrorCode`] wire value for the whole request; when it is not
    /// [`ErrorCode::Ok`] the row slice is empty and nothing changed.
    pub error: u32,
    /// [`scene_reply_flags`] bits.
    pub flags: u32,
    /// Rows that qualified, also those beyond `max_rows`.
    pub total: u64,
    /// Steps answered (1 when not a path).
    pub steps: u32,
    /// [`PathMode::FirstHit`]: the first step with a pair within the margin;
    /// [`PathMode::Continuous`]: the first segment with a contact;
    /// `u32::MAX` when none.
    pub first_hit: u32,
    /// Pair queries that ran GJK.
    pub gjk_runs: u64,
    /// Pairs answered from motion bounds alone.
    pub bounded: u64,
    /// Pairs the broadphase could not rule out.
    pub candidates: u64,
}

impl SceneReply {
    /// A reply carrying only an error code.
    pub fn error(code: ErrorCode) -> Self {
        SceneReply {
            error: code as u32,
            first_hit: u32::MAX,
            ..Default::default()
        }
    }

    /// The error code; unknown wire values read as [`ErrorCode::Malformed`].
    pub fn error_code(&self) -> ErrorCode {
        ErrorCode::from_raw(self.error).unwrap_or(ErrorCode::Malformed)
    }
}
