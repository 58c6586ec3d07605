//! Stored poses and distance queries: one pair, or a batch written into
//! the caller's arrays.

use gjkd_proto::item_flags;
use rust_client::{ErrorCode, Item, ItemResult, ObjectId};

use crate::args::{checked_pose, out, required, slice, slice_mut};
use crate::handle::{gjkd_client, with_client};
use crate::status::{Failure, gjkd_status, guard};
use crate::types::{gjkd_answer, gjkd_id, gjkd_pose, gjkd_query_options, gjkd_results};

/// Stores a new pose for object `id`, used by every later query (of any
/// client) that does not give its own.
///
/// The pose is checked as the server checks it, when it is set: a pose
/// stored is one every later query accepts.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `pose`),
/// `GJKD_ERR_BUSY`, `GJKD_ERR_INVALID_ARGUMENT` (nothing is sent)
/// with last error code `GJKD_CODE_NON_FINITE_POSE` (a NaN or infinite
/// component, a translation component beyond `GJKD_MAX_TRANSLATION`) or
/// `GJKD_CODE_BAD_QUATERNION` (a quaternion off unit length by more than
/// 1e-6), `GJKD_ERR_REJECTED` with `GJKD_CODE_UNKNOWN_OBJECT`;
/// `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT`.
///
/// # Safety
/// `client` is NULL or a live handle; `pose` NULL or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_set_pose(
    client: *mut gjkd_client,
    id: gjkd_id,
    pose: *const gjkd_pose,
) -> gjkd_status {
    // SAFETY: forwarded.
    unsafe { set_poses("gjkd_set_pose", client, &id, pose, 1) }
}

/// Stores `count` poses in one round trip: `poses[i]` becomes the pose of
/// `ids[i]`, in order. Every pose is checked first; a bad one fails the
/// call with nothing sent. An unknown id fails the call with
/// `GJKD_ERR_REJECTED` (`GJKD_CODE_UNKNOWN_OBJECT`, the message names the
/// first such row) after the other rows were stored. A count of 0 does
/// nothing (the arrays may then be NULL). Batches larger than the server
/// takes are split.
///
/// Errors: as `gjkd_set_pose()`, plus `GJKD_ERR_NULL_POINTER` for `ids` or
/// `poses`.
///
/// # Safety
/// `client` is NULL or a live handle; `ids` and `poses` NULL or pointing to
/// `count` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_set_poses(
    client: *mut gjkd_client,
    ids: *const gjkd_id,
    poses: *const gjkd_pose,
    count: usize,
) -> gjkd_status {
    // SAFETY: forwarded.
    unsafe { set_poses("gjkd_set_poses", client, ids, poses, count) }
}

/// The body of `gjkd_set_pose` and `gjkd_set_poses`.
///
/// # Safety
/// As `gjkd_set_poses()`.
unsafe fn set_poses(
    function: &str,
    client: *mut gjkd_client,
    ids: *const gjkd_id,
    poses: *const gjkd_pose,
    count: usize,
) -> gjkd_status {
    guard(function, || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let single = function == "gjkd_set_pose";
                let ids = slice(ids, count, "ids")?;
                let poses = slice(poses, count, if single { "pose" } else { "poses" })?;
                for (i, p) in poses.iter().enumerate() {
                    let what = if single {
                        "pose".into()
                    } else {
                        format!("poses[{i}]")
                    };
                    checked_pose(p, &what)?;
                }
                let template = Item::set_pose(ObjectId::from_raw(0), &Default::default());
                let item = |i: usize| Item {
                    a: ids[i],
                    pose_a: poses[i].wire(),
                    ..template
                };
                let mut failed: Option<(usize, ErrorCode)> = None;
                c.run(count, item, |start, results| {
                    if failed.is_none()
                        && let Some(k) = results.iter().position(|r| r.error != 0)
                    {
                        failed = Some((start + k, results[k].error_code()));
                    }
                })?;
                match failed {
                    None => Ok(()),
                    Some((_, code)) if single => Err(Failure::rejected(code, "")),
                    Some((i, code)) => Err(Failure::rejected(code, &format!("ids[{i}]: "))),
                }
            })
        }
    })
}

/// The query item of pair `(a, b)` with `options`, and each pose given.
fn pair_item(
    template: &Item,
    a: u64,
    b: u64,
    pose_a: Option<&gjkd_pose>,
    pose_b: Option<&gjkd_pose>,
) -> Item {
    let mut item = *template;
    item.a = a;
    item.b = b;
    if let Some(p) = pose_a {
        item.flags |= item_flags::POSE_A;
        item.pose_a = p.wire();
    }
    if let Some(p) = pose_b {
        item.flags |= item_flags::POSE_B;
        item.pair_mut().pose_b = p.wire();
    }
    item
}

/// The query template of `options` (NULL: the defaults).
///
/// # Safety
/// `options` is NULL or readable.
pub(crate) unsafe fn template(options: *const gjkd_query_options) -> Result<Item, Failure> {
    // SAFETY: the caller's promise.
    let options = unsafe { options.as_ref() }.copied().unwrap_or_default();
    let options = options.checked()?;
    Ok(Item::distance(
        ObjectId::from_raw(0),
        ObjectId::from_raw(0),
        &options,
    ))
}

/// The distance between objects `a` and `b`, into `*out_answer`: at their
/// stored poses, or at `pose_a` / `pose_b` when not NULL (for this query
/// only: the stored poses are neither used nor changed). `options` NULL
/// means `gjkd_query_options_default()`.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `out_answer`),
/// `GJKD_ERR_BUSY`, `GJKD_ERR_INVALID_ARGUMENT` (bad options, last
/// error code `GJKD_CODE_INVALID_OPTIONS`; a pose given here that
/// `gjkd_set_pose()` would refuse, with the same code:
/// `GJKD_CODE_NON_FINITE_POSE` or `GJKD_CODE_BAD_QUATERNION`; nothing is
/// sent), `GJKD_ERR_REJECTED` with `GJKD_CODE_UNKNOWN_OBJECT`;
/// `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT`. On failure `*out_answer` is
/// zeroed.
///
/// # Safety
/// `client` is NULL or a live handle; the poses and options NULL or
/// readable; `out_answer` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_distance(
    client: *mut gjkd_client,
    a: gjkd_id,
    b: gjkd_id,
    pose_a: *const gjkd_pose,
    pose_b: *const gjkd_pose,
    options: *const gjkd_query_options,
    out_answer: *mut gjkd_answer,
) -> gjkd_status {
    guard("gjkd_distance", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let slot = out(out_answer, "out_answer")?;
                *slot = gjkd_answer::default();
                // Checked here as `gjkd_set_pose()` checks a pose, so that
                // a bad pose fails alike whichever call it is given to.
                if let Some(p) = pose_a.as_ref() {
                    checked_pose(p, "pose_a")?;
                }
                if let Some(p) = pose_b.as_ref() {
                    checked_pose(p, "pose_b")?;
                }
                let item = pair_item(&template(options)?, a, b, pose_a.as_ref(), pose_b.as_ref());
                let mut result = [ItemResult::default()];
                c.client.query_batch(&[item], &mut result)?;
                match result[0].error_code() {
                    ErrorCode::Ok => {
                        *slot = gjkd_answer::from(&result[0]);
                        Ok(())
                    }
                    code => Err(Failure::rejected(code, "")),
                }
            })
        }
    })
}

/// The caller's output arrays, as slices.
struct Outputs<'a> {
    distance: &'a mut [f64],
    error: &'a mut [u32],
    lower: Option<&'a mut [f64]>,
    upper: Option<&'a mut [f64]>,
    penetration: Option<&'a mut [f64]>,
    point_a: Option<&'a mut [[f64; 3]]>,
    point_b: Option<&'a mut [[f64; 3]]>,
    normal: Option<&'a mut [[f64; 3]]>,
    status: Option<&'a mut [u32]>,
    iterations: Option<&'a mut [u32]>,
    pieces: Option<&'a mut [[u32; 2]]>,
    warm_started: Option<&'a mut [bool]>,
}

impl<'a> Outputs<'a> {
    /// The arrays of `r` for `n` rows.
    ///
    /// # Safety
    /// Each non-NULL pointer of `r` has room for its rows.
    unsafe fn new(r: &gjkd_results, n: usize) -> Result<Self, Failure> {
        // SAFETY: the caller's promise, field by field.
        unsafe {
            Ok(Outputs {
                distance: slice_mut(r.distance, n, "out.distance")?
                    .ok_or_else(|| Failure::null("out.distance"))?,
                error: slice_mut(r.error, n, "out.error")?
                    .ok_or_else(|| Failure::null("out.error"))?,
                lower: slice_mut(r.lower, n, "out.lower")?,
                upper: slice_mut(r.upper, n, "out.upper")?,
                penetration: slice_mut(r.penetration, n, "out.penetration")?,
                point_a: slice_mut(r.point_a.cast(), n, "out.point_a")?,
                point_b: slice_mut(r.point_b.cast(), n, "out.point_b")?,
                normal: slice_mut(r.normal.cast(), n, "out.normal")?,
                status: slice_mut(r.status, n, "out.status")?,
                iterations: slice_mut(r.iterations, n, "out.iterations")?,
                pieces: slice_mut(r.pieces.cast(), n, "out.pieces")?,
                warm_started: slice_mut(r.warm_started, n, "out.warm_started")?,
            })
        }
    }

    /// Writes `results` into rows `start..`.
    fn write(&mut self, start: usize, results: &[ItemResult]) {
        /// `dst[i] = value` when the caller asked for that field.
        #[inline(always)]
        fn put<T>(dst: &mut Option<&mut [T]>, i: usize, value: T) {
            if let Some(d) = dst {
                d[i] = value;
            }
        }
        // One pass over the results, each row written whole while it is
        // in cache, rather than a pass per field.
        for (i, r) in (start..).zip(results) {
            self.distance[i] = r.distance;
            self.error[i] = r.error;
            put(&mut self.lower, i, r.lower);
            put(&mut self.upper, i, r.upper);
            put(&mut self.penetration, i, r.penetration);
            put(&mut self.point_a, i, r.point_a);
            put(&mut self.point_b, i, r.point_b);
            put(&mut self.normal, i, r.normal);
            put(&mut self.status, i, r.status);
            put(&mut self.iterations, i, r.iterations);
            put(&mut self.pieces, i, r.pieces);
            let warm = r.flags & gjkd_proto::result_flags::WARM_STARTED != 0;
            put(&mut self.warm_started, i, warm);
        }
    }
}

/// The distances of `count` pairs in one call, into the caller's arrays.
///
/// - `pairs`: `2 * count` ids, `a0, b0, a1, b1, ...`.
/// - `poses_a`, `poses_b`: NULL (the stored poses) or `count` poses each,
///   for these queries only.
/// - `options`: the same for every pair; NULL means the defaults.
/// - `out`: the arrays to fill (see `gjkd_results`); row `i` answers pair
///   `i`. A pair that fails (an unknown id, a bad pose given here) has its
///   `gjkd_error_code` in `out->error[i]`, zeros elsewhere, and the other
///   pairs are answered: the call still returns `GJKD_OK`.
///
/// Batches larger than the server takes are split. The pairs go straight
/// into shared memory and the answers straight into `out`: nothing is
/// allocated per pair. A count of 0 does nothing (`pairs`, `out` and every
/// array may then be NULL).
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, and with a non-zero count
/// `pairs`, `out`, `out->distance`, `out->error`), `GJKD_ERR_BUSY`,
/// `GJKD_ERR_INVALID_ARGUMENT` (bad options, a count larger than any
/// array); `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT` (rows of the chunks
/// answered before are written, the others left as they were).
///
/// # Safety
/// `client` is NULL or a live handle; every other non-NULL pointer points
/// to the number of elements its parameter says.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_distances(
    client: *mut gjkd_client,
    pairs: *const gjkd_id,
    count: usize,
    poses_a: *const gjkd_pose,
    poses_b: *const gjkd_pose,
    options: *const gjkd_query_options,
    out: *const gjkd_results,
) -> gjkd_status {
    // SAFETY: forwarded.
    unsafe {
        distances_with(
            "gjkd_distances",
            client,
            (pairs, count),
            (poses_a, poses_b),
            options,
            out,
            |template| Ok((template, ())),
            |_, _, _| {},
        )
    }
}

/// `gjkd_distances()`'s body, shared with the calls that ask more of each
/// pair: `prepare` may add to the query template and check the caller's
/// further arrays (its state `S`) once the common arguments are checked,
/// and `more` sees every chunk of results after `out` is written.
///
/// # Safety
/// As `gjkd_distances()`.
#[allow(clippy::too_many_arguments)]
pub(crate) unsafe fn distances_with<S>(
    call: &'static str,
    client: *mut gjkd_client,
    (pairs, count): (*const gjkd_id, usize),
    (poses_a, poses_b): (*const gjkd_pose, *const gjkd_pose),
    options: *const gjkd_query_options,
    out: *const gjkd_results,
    prepare: impl FnOnce(Item) -> Result<(Item, S), Failure>,
    mut more: impl FnMut(&mut S, usize, &[ItemResult]),
) -> gjkd_status {
    guard(call, || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let template = template(options)?;
                // As `gjkd_query_pairs`: nothing to answer, nothing read,
                // so `out` too may be NULL.
                if count == 0 {
                    return Ok(());
                }
                let results = required(out, "out")?;
                let pairs = slice(pairs.cast::<[gjkd_id; 2]>(), count, "pairs")?;
                let poses_a = optional(poses_a, count, "poses_a")?;
                let poses_b = optional(poses_b, count, "poses_b")?;
                let mut outputs = Outputs::new(results, count)?;
                let (template, mut state) = prepare(template)?;
                let item = |i: usize| {
                    let [a, b] = pairs[i];
                    pair_item(
                        &template,
                        a,
                        b,
                        poses_a.map(|p| &p[i]),
                        poses_b.map(|p| &p[i]),
                    )
                };
                c.run(count, item, |start, results| {
                    outputs.write(start, results);
                    more(&mut state, start, results);
                })
            })
        }
    })
}

/// `count` poses, or `None` for NULL.
///
/// # Safety
/// A non-NULL `ptr` points to `count` poses.
unsafe fn optional<'a>(
    ptr: *const gjkd_pose,
    count: usize,
    what: &str,
) -> Result<Option<&'a [gjkd_pose]>, Failure> {
    if ptr.is_null() {
        Ok(None)
    } else {
        // SAFETY: the caller's promise.
        unsafe { slice(ptr, count, what) }.map(Some)
    }
}
