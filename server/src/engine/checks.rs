//! What every shape and pose a client or a stored record gives is held to
//! before the engine keeps it, and the wire forms of gjk's verdicts. Below
//! both the request decoding ([`super::handlers`]) and the stored records
//! ([`super::records`]), which build shapes by the same rules.

use gjkd_proto::{ErrorCode, Pose};
use nalgebra::Isometry3;

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

/// The wire code of a gjk error (the protocol's own mapping).
pub fn map_gjk_error(e: gjk::Error) -> ErrorCode {
    ErrorCode::from(e)
}

/// The isometry of a wire pose, checked as the protocol says
/// ([`Pose::checked`]).
///
/// # Errors
/// [`ErrorCode::NonFinitePose`], [`ErrorCode::BadQuaternion`].
pub fn check_pose(p: &Pose) -> Result<Isometry3<f64>, ErrorCode> {
    p.checked()
}

/// The protocol's shape checks, which stored records are held to as
/// registrations are.
pub use gjkd_proto::{UNIT_TOLERANCE, cylinder, hull as convex};
