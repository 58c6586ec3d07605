//! Batches as arrays of rows: a `gjkd_pair_query` row per pair in, a
//! `gjkd_result` row per pair out, laid out as the server writes its
//! answers, so that each row is copied once each way between the caller's
//! memory and shared memory.

use std::mem::offset_of;

use gjkd_proto::item_flags;
use rust_client::ItemResult;

use crate::args::{slice, slice_mut};
use crate::handle::{gjkd_client, with_client};
use crate::status::{Failure, gjkd_status, guard};
use crate::types::{gjkd_id, gjkd_pose, gjkd_query_options};

/// `gjkd_pair_query::poses` bit: this row's `pose_a` replaces the stored
/// pose of `a`, for this query only.
pub const GJKD_POSE_A: u32 = 1;
const _: () = assert!(GJKD_POSE_A == item_flags::POSE_A);

/// `gjkd_pair_query::poses` bit: this row's `pose_b` replaces the stored
/// pose of `b`, for this query only.
pub const GJKD_POSE_B: u32 = 2;
const _: () = assert!(GJKD_POSE_B == item_flags::POSE_B);

/// `gjkd_result::flags` bit: the query started from the pair's last
/// simplex.
pub const GJKD_RESULT_WARM_STARTED: u32 = 1;
const _: () = assert!(GJKD_RESULT_WARM_STARTED == gjkd_proto::result_flags::WARM_STARTED);

/// `gjkd_result::flags` bit: gjk's Backup Procedure ran (a numerically
/// hard case).
pub const GJKD_RESULT_BACKUP_USED: u32 = 2;
const _: () = assert!(GJKD_RESULT_BACKUP_USED == gjkd_proto::result_flags::BACKUP_USED);

/// One pair of a `gjkd_query_pairs()` batch. Zero it (or start from
/// `gjkd_pair_query_of()`), then set the ids and, for a pose given for this
/// query only, the pose and its bit in `poses`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct gjkd_pair_query {
    /// Object A.
    pub a: gjkd_id,
    /// Object B.
    pub b: gjkd_id,
    /// The pose of A for this query, used when `poses` has `GJKD_POSE_A`.
    pub pose_a: gjkd_pose,
    /// The pose of B for this query, used when `poses` has `GJKD_POSE_B`.
    pub pose_b: gjkd_pose,
    /// `GJKD_POSE_A | GJKD_POSE_B` bits; 0: both at their stored poses
    /// (which are neither used nor changed for a pose given here).
    pub poses: u32,
    /// Zero.
    pub reserved: u32,
}

/// The answer row of one pair of a `gjkd_query_pairs()` batch, laid out
/// as the server writes it (so a batch's answers are copied into the
/// caller's array in one piece). Distances are after radii; points in world
/// coordinates. A pair that failed has its code in `error` and zeros
/// elsewhere.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct gjkd_result {
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
    /// A `gjkd_error_code` value, `GJKD_CODE_OK` (0) when answered.
    pub error: u32,
    /// A `gjkd_query_status` value.
    pub status: u32,
    /// Subalgorithm iterations (summed over piece pairs for compounds).
    pub iterations: u32,
    /// `GJKD_RESULT_WARM_STARTED | GJKD_RESULT_BACKUP_USED` bits.
    pub flags: u32,
    /// Pieces of A and B that realise the distance (0 for convex objects).
    pub pieces: [u32; 2],
}

// `gjkd_result` is `ItemResult` under a C name: same size, alignment and
// offsets, so a slice of one is read as a slice of the other.
const _: () = {
    assert!(size_of::<gjkd_result>() == size_of::<ItemResult>());
    assert!(align_of::<gjkd_result>() == align_of::<ItemResult>());
    assert!(offset_of!(gjkd_result, distance) == offset_of!(ItemResult, distance));
    assert!(offset_of!(gjkd_result, lower) == offset_of!(ItemResult, lower));
    assert!(offset_of!(gjkd_result, upper) == offset_of!(ItemResult, upper));
    assert!(offset_of!(gjkd_result, penetration) == offset_of!(ItemResult, penetration));
    assert!(offset_of!(gjkd_result, point_a) == offset_of!(ItemResult, point_a));
    assert!(offset_of!(gjkd_result, point_b) == offset_of!(ItemResult, point_b));
    assert!(offset_of!(gjkd_result, normal) == offset_of!(ItemResult, normal));
    assert!(offset_of!(gjkd_result, error) == offset_of!(ItemResult, error));
    assert!(offset_of!(gjkd_result, status) == offset_of!(ItemResult, status));
    assert!(offset_of!(gjkd_result, iterations) == offset_of!(ItemResult, iterations));
    assert!(offset_of!(gjkd_result, flags) == offset_of!(ItemResult, flags));
    assert!(offset_of!(gjkd_result, pieces) == offset_of!(ItemResult, pieces));
};

/// Copies `results` into `out`, which has room for them: one copy of the
/// whole rows.
fn copy_results(results: &[ItemResult], out: &mut [gjkd_result]) {
    // SAFETY: same layout (asserted above), every bit pattern of the
    // fields valid in both; `out` holds at least `results.len()` rows, and
    // caller memory never overlaps shared memory.
    unsafe {
        std::ptr::copy_nonoverlapping(
            results.as_ptr().cast::<gjkd_result>(),
            out.as_mut_ptr(),
            results.len(),
        );
    }
}

/// A row asking the distance of `a` and `b` at their stored poses.
#[unsafe(no_mangle)]
pub extern "C" fn gjkd_pair_query_of(a: gjkd_id, b: gjkd_id) -> gjkd_pair_query {
    let identity = gjkd_pose {
        translation: [0.0; 3],
        rotation: [0.0, 0.0, 0.0, 1.0],
    };
    gjkd_pair_query {
        a,
        b,
        pose_a: identity,
        pose_b: identity,
        poses: 0,
        reserved: 0,
    }
}

/// The distances of `count` pairs in one call: `queries[i]` in, its answer
/// into `out[i]`. The fastest batch of this API: each row is copied once
/// into the request's shared memory, and the answers once, whole, from the
/// response's into `out`. `options` (NULL: the defaults) is the same for
/// every pair.
///
/// A pair that fails (an unknown id, a bad pose given in its row) has its
/// `gjkd_error_code` in `out[i].error`, zeros elsewhere, and the other
/// pairs are answered: the call still returns `GJKD_OK`. Batches larger
/// than the server takes are split. A count of 0 does nothing (`queries`
/// and `out` may then be NULL).
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `queries`, `out`),
/// `GJKD_ERR_WRONG_THREAD`, `GJKD_ERR_INVALID_ARGUMENT` (bad options, a
/// count larger than any array, a row whose `poses` has bits other than
/// `GJKD_POSE_A | GJKD_POSE_B` or whose `reserved` is not 0: nothing is
/// sent); `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT` (rows of the chunks
/// answered before are written, the others left as they were).
///
/// # Safety
/// `client` is NULL or a live handle; `queries` NULL or `count` readable
/// rows; `out` NULL or `count` writable rows; `options` NULL or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_query_pairs(
    client: *mut gjkd_client,
    queries: *const gjkd_pair_query,
    count: usize,
    options: *const gjkd_query_options,
    out: *mut gjkd_result,
) -> gjkd_status {
    guard("gjkd_query_pairs", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let template = crate::query::template(options)?;
                if count == 0 {
                    return Ok(());
                }
                let queries = slice(queries, count, "queries")?;
                let out = slice_mut(out, count, "out")?.ok_or_else(|| Failure::null("out"))?;
                check_rows(queries)?;
                let item = |i: usize| {
                    let q = &queries[i];
                    let mut item = template;
                    item.a = q.a;
                    item.b = q.b;
                    item.flags |= q.poses;
                    item.pose_a = q.pose_a.wire();
                    item.pose_b = q.pose_b.wire();
                    item
                };
                c.run(count, item, |start, results| {
                    copy_results(results, &mut out[start..start + results.len()]);
                })
            })
        }
    })
}

/// Refuses the first row with bits the API does not define, by index.
fn check_rows(queries: &[gjkd_pair_query]) -> Result<(), Failure> {
    const KNOWN: u32 = GJKD_POSE_A | GJKD_POSE_B;
    // One branch-free pass first: rows are almost always right.
    let stray = queries
        .iter()
        .fold(0, |acc, q| acc | (q.poses & !KNOWN) | q.reserved);
    if stray == 0 {
        return Ok(());
    }
    let i = queries
        .iter()
        .position(|q| q.poses & !KNOWN != 0 || q.reserved != 0)
        .unwrap_or_default();
    let q = &queries[i];
    Err(Failure::invalid(if q.poses & !KNOWN != 0 {
        format!(
            "queries[{i}]: poses {:#x} has bits other than GJKD_POSE_A | GJKD_POSE_B",
            q.poses
        )
    } else {
        format!("queries[{i}]: reserved {} is not 0", q.reserved)
    }))
}
