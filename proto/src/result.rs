//! The answer to an item: its wire form, its decoded form, and the
//! header of a query reply.

use iceoryx2::prelude::ZeroCopySend;
use nalgebra::{Point3, Vector3};

use crate::{ErrorCode, Gradient};

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
    /// [`scene_flags::MOTION_BOUNDS`](crate::scene_flags::MOTION_BOUNDS)).
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

/// Bits of [`ItemResult::flags`].
pub mod result_flags {
    /// The query started from a cached simplex.
    pub const WARM_STARTED: u32 = 1;
    /// gjk's Backup Procedure ran (a sign of a numerically hard case).
    pub const BACKUP_USED: u32 = 1 << 1;
    /// The signed-distance fields hold an answer (the item asked for it
    /// with [`item_flags::SIGNED_DISTANCE`](crate::item_flags::SIGNED_DISTANCE)).
    pub const SIGNED_DISTANCE: u32 = 1 << 2;
}

/// The answer to one [`Item`](crate::Item). For a pose update only `error` is meaningful.
///
/// Read it with [`ItemResult::answer`].
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.ItemResult")]
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
    /// The signed distance when [`result_flags::SIGNED_DISTANCE`] is set
    /// (else 0): the distance apart, minus the penetration depth
    /// overlapping. `point_a`, `point_b` and `normal` are then its
    /// witnesses and direction (`point_b - point_a = signed_distance ·
    /// normal`; `pieces` the deepest piece pair), the same as the
    /// distance's when apart.
    pub signed_distance: f64,
    /// Certified lower bound on the signed distance (when flagged).
    pub signed_lower: f64,
    /// Certified upper bound on the signed distance (when flagged).
    pub signed_upper: f64,
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
            signed_distance: 0.0,
            signed_lower: 0.0,
            signed_upper: 0.0,
        }
    }

    /// The error code; unknown wire values read as [`ErrorCode::Malformed`].
    pub fn error_code(&self) -> ErrorCode {
        ErrorCode::from_raw(self.error).unwrap_or(ErrorCode::Malformed)
    }

    /// The answer of a distance query, or the item's error. A successful pose
    /// update reads as an answer with status `None`. The gradient travels
    /// apart ([`GradientRow`](crate::GradientRow)): the answer's is `None`;
    /// [`ItemResult::answer_with`] joins one in.
    pub fn answer(&self) -> Result<Answer, ErrorCode> {
        self.answer_with(None)
    }

    /// As [`ItemResult::answer`], with `gradient` (the item's, from the
    /// reply's gradient section) as [`Answer::gradient`] when it is
    /// present.
    pub fn answer_with(&self, gradient: Option<&Gradient>) -> Result<Answer, ErrorCode> {
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
                signed: (self.flags & result_flags::SIGNED_DISTANCE != 0).then_some(
                    SignedDistance {
                        value: self.signed_distance,
                        lower: self.signed_lower,
                        upper: self.signed_upper,
                    },
                ),
                gradient: gradient.filter(|g| g.is_present()).copied(),
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
    /// The signed distance with its certified interval, when the query
    /// asked for it ([`QueryOptions::signed_distance`](crate::QueryOptions::signed_distance));
    /// `point_a`, `point_b` and `normal` are then its witnesses and
    /// direction, also when the shapes overlap.
    pub signed: Option<SignedDistance>,
    /// The distance's gradient, when asked (see [`Gradient`]) and joined
    /// in by [`ItemResult::answer_with`] (the client's
    /// `distance_gradient` does).
    pub gradient: Option<Gradient>,
}

/// A signed distance with its certified interval: the distance apart,
/// minus the penetration depth (the shortest translation that separates
/// the shapes) overlapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SignedDistance {
    /// The signed distance.
    pub value: f64,
    /// Certified lower bound.
    pub lower: f64,
    /// Certified upper bound.
    pub upper: f64,
}

/// Response header of the query service: whole-request errors, and how
/// the reply's slice of [`ReplyEntry`](crate::ReplyEntry)s divides. When `error` is not
/// [`ErrorCode::Ok`] the slice is empty.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.ReplyHeader")]
pub struct ReplyHeader {
    /// [`ErrorCode`] wire value: [`ErrorCode::EmptyBatch`],
    /// [`ErrorCode::BatchTooLarge`], or [`ErrorCode::Ok`].
    pub error: u32,
    /// Number of results that follow: the slice's first `count` entries,
    /// one per item.
    pub count: u32,
    /// Number of gradients after the results: one per item flagged
    /// [`item_flags::GRADIENT`](crate::item_flags::GRADIENT), in item
    /// order.
    pub gradients: u32,
    /// Zero.
    pub reserved: u32,
}
