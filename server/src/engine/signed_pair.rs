//! The signed distance of a pair query that asks for it
//! ([`item_flags::SIGNED_DISTANCE`](gjkd_proto::item_flags::SIGNED_DISTANCE)):
//! written into the answer the distance query already made. A pair that
//! answer proves apart needs nothing more (its signed distance is its
//! distance, interval and all); only a pair that may overlap is expanded.

use gjk::Shape;
use gjkd_proto::{ErrorCode, ItemResult, result_flags};
use nalgebra::Isometry3;

use super::checks::map_gjk_error;

/// Fills `result`'s signed-distance fields (and, for a pair that may
/// overlap, its witnesses, normal and pieces with the depth's) for the
/// pair `a`, `b` that `result` answers, with the distance `options` it was
/// asked with. Returns gjk's signed distance when it was computed (the
/// pair may overlap), for the gradient to read its direction from.
///
/// # Errors
/// The wire code of gjk's error (none for inputs the distance query
/// accepted).
pub(crate) fn add_signed_distance(
    result: &mut ItemResult,
    (a, pose_a): (&Shape, &Isometry3<f64>),
    (b, pose_b): (&Shape, &Isometry3<f64>),
    options: &gjk::Options,
) -> Result<Option<gjk::SignedDistance>, ErrorCode> {
    result.flags |= result_flags::SIGNED_DISTANCE;
    if result.lower > 0.0 {
        result.signed_distance = result.distance;
        result.signed_lower = result.lower;
        result.signed_upper = result.upper;
        return Ok(None);
    }
    let depth = gjk::DepthOptions {
        distance: *options,
        ..gjk::DepthOptions::default()
    };
    let sd = gjk::signed_distance(a, pose_a, b, pose_b, &depth).map_err(map_gjk_error)?;
    result.signed_distance = sd.value;
    result.signed_lower = sd.lower;
    result.signed_upper = sd.upper;
    result.point_a = sd.point_a.coords.into();
    result.point_b = sd.point_b.coords.into();
    result.normal = sd.normal.into();
    result.pieces = sd.pieces;
    Ok(Some(sd))
}
