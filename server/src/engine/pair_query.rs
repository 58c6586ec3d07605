//! One pair query in the engine's terms: the step the query service and
//! the group queries ([`super::group_queries`]) share.

use gjk::Shape;
use gjkd_proto::{ErrorCode, ItemResult, result_flags};
use nalgebra::Isometry3;

use super::checks::{map_gjk_error, status_code};

/// One pair query, as the query service and the scene service run it:
/// `warm` (the pair's cached simplex, if any) starts it, and the answer
/// comes back in its wire form with the simplex to cache for the next.
/// A cached simplex that does not fit the shapes (cannot happen: ids are
/// never reused) is dropped and the query runs cold.
///
/// # Errors
/// The wire code of gjk's error.
pub(crate) fn run_pair(
    workspace: &mut gjk::Workspace,
    a: (&Shape, &Isometry3<f64>),
    b: (&Shape, &Isometry3<f64>),
    options: &gjk::Options,
    warm: Option<&gjk::WarmStart>,
) -> Result<(ItemResult, gjk::WarmStart), ErrorCode> {
    let mut result = ItemResult::default();
    let next = run_pair_into(workspace, a, b, options, warm, &mut result)?;
    Ok((result, next))
}

/// As [`run_pair`], the answer written into `out` (untouched on an error):
/// the query service's path, where a result moved by value costs a
/// `memcpy` a pair, written in place none.
///
/// # Errors
/// As [`run_pair`].
pub(crate) fn run_pair_into(
    workspace: &mut gjk::Workspace,
    (a, pose_a): (&Shape, &Isometry3<f64>),
    (b, pose_b): (&Shape, &Isometry3<f64>),
    options: &gjk::Options,
    warm: Option<&gjk::WarmStart>,
    out: &mut ItemResult,
) -> Result<gjk::WarmStart, ErrorCode> {
    let mut query = |warm: Option<&gjk::WarmStart>| {
        gjk::distance_in(workspace, a, pose_a, b, pose_b, options, warm)
    };
    let answer = match query(warm) {
        Ok(answer) => answer,
        Err(gjk::Error::WarmStartOutOfRange) => query(None).map_err(map_gjk_error)?,
        Err(e) => return Err(map_gjk_error(e)),
    };
    let mut flags = 0;
    if warm.is_some() {
        flags |= result_flags::WARM_STARTED;
    }
    if answer.backup_used {
        flags |= result_flags::BACKUP_USED;
    }
    *out = ItemResult {
        distance: answer.distance,
        lower: answer.lower,
        upper: answer.upper,
        penetration: answer.penetration,
        point_a: answer.point_a.coords.into(),
        point_b: answer.point_b.coords.into(),
        normal: answer.normal.into(),
        error: ErrorCode::Ok as u32,
        status: status_code(answer.status),
        iterations: answer.iterations,
        flags,
        pieces: answer.pieces,
        signed_distance: 0.0,
        signed_lower: 0.0,
        signed_upper: 0.0,
    };
    Ok(answer.warm_start)
}
