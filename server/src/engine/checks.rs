//! What every shape and pose a client or a stored record gives is held to
//! before the engine keeps it, and the wire forms of gjk's verdicts. Below
//! both the request decoding ([`super::handlers`]) and the stored records
//! ([`super::records`]), which build shapes by the same rules.

use gjk::Convex;
use gjkd_proto::{ErrorCode, Pose, Vertex};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};

/// The wire value of a gjk status.
pub fn status_code(s: gjk::Status) -> u32 {
    use gjkd_proto::Status as W;
    match s {
        gjk::Status::Converged => W::Converged as u32,
        gjk::Status::Farther => W::Farther as u32,
        gjk::Status::Closer => W::Closer as u32,
        gjk::Status::IterationCap => W::IterationCap as u32,
        gjk::Status::ToleranceNotMet => W::ToleranceNotMet as u32,
    }
}

/// The wire code of a gjk error.
pub fn map_gjk_error(e: gjk::Error) -> ErrorCode {
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

/// Quaternions whose squared norm is this close to 1 are taken as they are:
/// that is what nalgebra's own normalisation yields, and re-normalising them
/// would change the last bits of every answer relative to an in-process call.
const UNIT_ROUNDING: f64 = 8.0 * f64::EPSILON;

/// How far off unit length a quaternion may be and still be accepted (after
/// normalising).
pub const UNIT_TOLERANCE: f64 = 1e-6;

/// The isometry of a wire pose: finite, and a rotation quaternion within
/// [`UNIT_TOLERANCE`] of unit length (normalised unless it already is, to
/// round-off).
///
/// # Errors
/// [`ErrorCode::NonFinitePose`], [`ErrorCode::BadQuaternion`].
pub fn check_pose(p: &Pose) -> Result<Isometry3<f64>, ErrorCode> {
    if !p
        .translation
        .iter()
        .chain(&p.rotation)
        .all(|c| c.is_finite())
    {
        return Err(ErrorCode::NonFinitePose);
    }
    let [i, j, k, w] = p.rotation;
    let q = Quaternion::new(w, i, j, k);
    let n2 = q.norm_squared();
    let rotation = if (n2 - 1.0).abs() <= UNIT_ROUNDING {
        UnitQuaternion::new_unchecked(q)
    } else if (n2.sqrt() - 1.0).abs() <= UNIT_TOLERANCE {
        UnitQuaternion::new_normalize(q)
    } else {
        return Err(ErrorCode::BadQuaternion);
    };
    let [x, y, z] = p.translation;
    Ok(Isometry3::from_parts(Translation3::new(x, y, z), rotation))
}

/// The farthest a shape may reach from its body origin, 2^999 (gjk's own
/// limit, about 5e300), so that no query's arithmetic can overflow.
const MAX_REACH: f64 = 5.357543035931337e300;

/// An exact cylinder of `radius` and `half_height` rounded by `rounding`:
/// each a number from 0 to 2^999, and the whole within 2^999 of its
/// origin, else [`ErrorCode::InvalidRadius`] (gjk would call a bad
/// dimension a bad vertex, which a cylinder sent none of).
pub fn cylinder(radius: f64, half_height: f64, rounding: f64) -> Result<Convex, ErrorCode> {
    let dimensions = [radius, half_height, rounding];
    if !dimensions.iter().all(|x| (0.0..=MAX_REACH).contains(x)) {
        return Err(ErrorCode::InvalidRadius);
    }
    if radius.hypot(half_height) + rounding > MAX_REACH {
        return Err(ErrorCode::InvalidRadius);
    }
    Convex::cylinder(radius, half_height, rounding).map_err(map_gjk_error)
}

/// A hull of `vertices` rounded by `radius`.
///
/// # Errors
/// [`ErrorCode::EmptyVertices`], [`ErrorCode::InvalidRadius`] and the
/// codes of gjk's own checks.
pub fn convex(vertices: &[Vertex], radius: f64) -> Result<Convex, ErrorCode> {
    if vertices.is_empty() {
        return Err(ErrorCode::EmptyVertices);
    }
    if !(radius.is_finite() && radius >= 0.0) {
        return Err(ErrorCode::InvalidRadius);
    }
    let points: Vec<Point3<f64>> = vertices.iter().map(|&v| v.into()).collect();
    Convex::new(points, radius).map_err(map_gjk_error)
}
