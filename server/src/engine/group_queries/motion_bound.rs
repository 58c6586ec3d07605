//! Certified motion bounds: a pair's last certified interval, widened by
//! how far any point of either object can have moved since.
//!
//! A point `p` of a body moving from pose `T0` to `T1` moves by
//! `|T1 p - T0 p| <= |T1 c - T0 c| + |(R1 - R0)(p - c)|
//! <= |T1 c - T0 c| + 2 sin(theta / 2) R`, with `c` the body-frame centroid,
//! `R` the extent about it (radius included) and `theta` the angle of the
//! relative rotation `R1 R0^-1`. The distance between two sets moves by
//! at most the sum of their points' largest moves, so the interval widened
//! by `dA + dB` holds the distance at the new poses.

use gjkd_proto::{ErrorCode, ItemResult, Status};

use super::entry::{Entry, ROUND_OFF, displacement};
use crate::engine::warm_cache::PairBound;

/// A cached interval at the current poses.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Widened {
    /// Certified lower bound, at least 0.
    pub lower: f64,
    /// Certified upper bound.
    pub upper: f64,
}

/// The largest distance any point of `a` or `b` can have moved from the
/// poses of `bound` to their index poses, rounded up (the sum of both).
pub(crate) fn moved_since(bound: &PairBound, a: &Entry, b: &Entry) -> f64 {
    displacement(a, &bound.pose_a) + displacement(b, &bound.pose_b)
}

/// An upper bound on how far any point of an object moved between two
/// steps of a path, from its [`Entry::travel`] `then` and `now`, after
/// `moves` moves in all: the difference, plus the round-off of two sums of
/// at most `moves` non-negative terms each.
#[inline]
pub(crate) fn travelled(now: f64, then: f64, moves: u32) -> f64 {
    (now - then) * (1.0 + ROUND_OFF) + (2.0 * f64::from(moves) + 4.0) * f64::EPSILON * now
}

/// `bound` widened by `d`, an upper bound on how far any point of either
/// object moved since.
pub(crate) fn widen_by(bound: &PairBound, d: f64) -> Widened {
    let lower = (bound.lower - d) * (1.0 - ROUND_OFF);
    // Objects that overlapped by at least `penetration` and moved by less
    // still overlap: the distance is 0.
    let upper = if bound.penetration * (1.0 - ROUND_OFF) > d * (1.0 + ROUND_OFF) {
        0.0
    } else {
        (bound.upper + d) * (1.0 + ROUND_OFF)
    };
    Widened {
        // A NaN (never expected) reads as no information.
        lower: if lower > 0.0 { lower } else { 0.0 },
        upper: if upper.is_nan() { f64::INFINITY } else { upper },
    }
}

/// Whether an interval is as narrow as the caller accepts.
#[inline]
pub(crate) fn accepted(w: &Widened, absolute: f64, relative: f64) -> bool {
    let width = w.upper - w.lower;
    (absolute > 0.0 && width <= absolute) || (relative > 0.0 && width <= relative * w.upper)
}

/// The answer of a pair from its motion bound: the interval `w`, the
/// cached distance clamped into it, the cached points carried with their
/// objects.
pub(crate) fn bounded_result(bound: &PairBound, w: &Widened, a: &Entry, b: &Entry) -> ItemResult {
    let point_a = a.pose * bound.point_a;
    let point_b = b.pose * bound.point_b;
    let normal = a.pose.rotation * bound.normal;
    ItemResult {
        distance: bound.distance.clamp(w.lower, w.upper.max(w.lower)),
        lower: w.lower,
        upper: w.upper,
        penetration: 0.0,
        point_a: point_a.coords.into(),
        point_b: point_b.coords.into(),
        normal: normal.into(),
        error: ErrorCode::Ok as u32,
        status: Status::Bounded as u32,
        iterations: 0,
        flags: 0,
        pieces: bound.pieces,
        signed_distance: 0.0,
        signed_lower: 0.0,
        signed_upper: 0.0,
    }
}

/// `bound` carried to the index poses of `a` and `b`, which it holds at
/// widened by `d` ([`moved_since`]) to `w`: the interval `w`, the
/// penetration left, the same points and normal in the bodies' frames.
pub(crate) fn carried(bound: &PairBound, d: f64, w: &Widened, a: &Entry, b: &Entry) -> PairBound {
    let left = (bound.penetration * (1.0 - ROUND_OFF) - d * (1.0 + ROUND_OFF)) * (1.0 - ROUND_OFF);
    PairBound {
        lower: w.lower,
        upper: w.upper,
        distance: bound.distance.clamp(w.lower, w.upper.max(w.lower)),
        penetration: if left > 0.0 { left } else { 0.0 },
        pose_a: a.pose,
        pose_b: b.pose,
        ..*bound
    }
}

/// What to keep of an answer found by GJK at the poses of `a` and `b`.
pub(crate) fn bound_of(result: &ItemResult, a: &Entry, b: &Entry) -> PairBound {
    let pa: nalgebra::Point3<f64> = result.point_a.into();
    let pb: nalgebra::Point3<f64> = result.point_b.into();
    let n: nalgebra::Vector3<f64> = result.normal.into();
    PairBound {
        lower: result.lower,
        upper: result.upper,
        distance: result.distance,
        penetration: if result.penetration > 0.0 {
            result.penetration
        } else {
            0.0
        },
        pose_a: a.pose,
        pose_b: b.pose,
        point_a: a.pose.inverse_transform_point(&pa),
        point_b: b.pose.inverse_transform_point(&pb),
        normal: a.pose.rotation.inverse_transform_vector(&n),
        pieces: result.pieces,
    }
}
