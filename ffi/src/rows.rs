//! Batches as arrays of rows: a `gjkd_pair_query` row per pair in, laid
//! out as the server reads its requests, and a `gjkd_result` row per pair
//! out, laid out as it writes its answers, so that a batch is copied in one
//! piece each way between the caller's memory and shared memory, as the
//! Rust client's `query_batch` does. Gradients, asked row by row
//! (`GJKD_PAIR_GRADIENT`), come apart, into a `gjkd_gradient` array of
//! the caller's (`gjkd_query_pairs_gradients()`): a row that asks none
//! carries none, in the reply too.

use std::mem::offset_of;

use gjkd_proto::{Gradient, ItemKind, Pose, ReplyEntry, item_flags};
use rust_client::{Item, ItemResult};

use crate::args::{slice, slice_mut};
use crate::gradient::gjkd_gradient;
use crate::handle::{gjkd_client, with_client};
use crate::status::{Failure, gjkd_status, guard};
use crate::types::{gjkd_id, gjkd_pose, gjkd_precision, gjkd_query_options};

/// `gjkd_pair_query::flags` bit: this row's `pose_a` replaces the stored
/// pose of `a`, for this query only.
pub const GJKD_POSE_A: u32 = 1;
const _: () = assert!(GJKD_POSE_A == item_flags::POSE_A);

/// `gjkd_pair_query::flags` bit: this row's `pose_b` replaces the stored
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

/// `gjkd_result::flags` bit: the signed-distance fields hold an answer.
pub const GJKD_RESULT_SIGNED_DISTANCE: u32 = 4;
const _: () = assert!(GJKD_RESULT_SIGNED_DISTANCE == gjkd_proto::result_flags::SIGNED_DISTANCE);

/// `flags` bits a row of `gjkd_query_pairs()` may carry: the two pose bits
/// and the bits `gjkd_pair_query_of()` sets from the options.
const ROW_FLAGS: u32 = item_flags::POSE_A
    | item_flags::POSE_B
    | item_flags::MARGIN
    | item_flags::WARM_START
    | item_flags::SINGLE_PRECISION
    | item_flags::SIGNED_DISTANCE;

/// `flags` bits a row of `gjkd_query_pairs_gradients()` may carry: those
/// of `gjkd_query_pairs()` and the gradient's.
const GRADIENT_ROW_FLAGS: u32 = ROW_FLAGS | item_flags::GRADIENT | item_flags::GRADIENT_BASE;

/// One pair of a `gjkd_query_pairs()` batch, laid out as the request the
/// server reads (so a batch of rows is copied into it in one piece). Make
/// it with `gjkd_pair_query_of()`, which sets `kind` and the options'
/// fields; then, for a pose given for this query only, set the pose and OR
/// its bit into `flags` (`row.flags |= GJKD_POSE_B`). Keep the rows from
/// call to call and rewrite only the poses that move.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct gjkd_pair_query {
    /// What the row asks: set by `gjkd_pair_query_of()`, not to be changed.
    pub kind: u32,
    /// `GJKD_POSE_A` and `GJKD_POSE_B`, ORed into the bits
    /// `gjkd_pair_query_of()` set from the options (keep those).
    pub flags: u32,
    /// Object A.
    pub a: gjkd_id,
    /// Object B.
    pub b: gjkd_id,
    /// The pose of A for this query, used when `flags` has `GJKD_POSE_A`
    /// (the stored pose is then neither used nor changed).
    pub pose_a: gjkd_pose,
    /// The pose of B for this query, used when `flags` has `GJKD_POSE_B`.
    pub pose_b: gjkd_pose,
    /// The options' tolerance.
    pub tolerance: f64,
    /// The options' margin.
    pub margin: f64,
    /// The options' iteration cap.
    pub max_iterations: u32,
    /// Zero.
    pub reserved: u32,
}

// `gjkd_pair_query` is the wire's `Item` under a C name.
const _: () = {
    assert!(size_of::<gjkd_pair_query>() == size_of::<Item>());
    assert!(align_of::<gjkd_pair_query>() == align_of::<Item>());
    assert!(offset_of!(gjkd_pair_query, kind) == offset_of!(Item, kind));
    assert!(offset_of!(gjkd_pair_query, flags) == offset_of!(Item, flags));
    assert!(offset_of!(gjkd_pair_query, a) == offset_of!(Item, a));
    assert!(offset_of!(gjkd_pair_query, b) == offset_of!(Item, b));
    assert!(offset_of!(gjkd_pair_query, pose_a) == offset_of!(Item, pose_a));
    assert!(offset_of!(gjkd_pair_query, pose_b) == offset_of!(Item, body.pair.pose_b));
    assert!(offset_of!(gjkd_pair_query, tolerance) == offset_of!(Item, body.pair.tolerance));
    assert!(offset_of!(gjkd_pair_query, margin) == offset_of!(Item, body.pair.margin));
    assert!(
        offset_of!(gjkd_pair_query, max_iterations) == offset_of!(Item, body.pair.max_iterations)
    );
    assert!(offset_of!(gjkd_pair_query, reserved) == offset_of!(Item, body.pair.reserved));
    assert!(size_of::<gjkd_pose>() == size_of::<Pose>());
    assert!(align_of::<gjkd_pose>() == align_of::<Pose>());
    assert!(offset_of!(gjkd_pose, translation) == offset_of!(Pose, translation));
    assert!(offset_of!(gjkd_pose, rotation) == offset_of!(Pose, rotation));
};

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
    /// The signed distance when `flags` has `GJKD_RESULT_SIGNED_DISTANCE`
    /// (the query asked with `gjkd_query_options::signed_distance`), else
    /// 0: the distance apart, minus the penetration depth overlapping.
    /// `point_a`, `point_b` and `normal` are then its witnesses and
    /// direction.
    pub signed_distance: f64,
    /// Certified lower bound on the signed distance (when flagged).
    pub signed_lower: f64,
    /// Certified upper bound on the signed distance (when flagged).
    pub signed_upper: f64,
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
    assert!(offset_of!(gjkd_result, signed_distance) == offset_of!(ItemResult, signed_distance));
    assert!(offset_of!(gjkd_result, signed_lower) == offset_of!(ItemResult, signed_lower));
    assert!(offset_of!(gjkd_result, signed_upper) == offset_of!(ItemResult, signed_upper));
};

/// A row asking the distance of `a` and `b` at their stored poses, with
/// `options` (NULL: the defaults). Options out of their domain (see
/// `gjkd_query_options`) make the row fail alone, with
/// `GJKD_CODE_INVALID_OPTIONS` in its result.
///
/// # Safety
/// `options` is NULL or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_pair_query_of(
    a: gjkd_id,
    b: gjkd_id,
    options: *const gjkd_query_options,
) -> gjkd_pair_query {
    // SAFETY: the caller's promise.
    let o = unsafe { options.as_ref() }.copied().unwrap_or_default();
    let mut flags = 0;
    if o.warm_start {
        flags |= item_flags::WARM_START;
    }
    if o.use_margin {
        flags |= item_flags::MARGIN;
    }
    if o.precision == gjkd_precision::GJKD_PRECISION_SINGLE as u32 {
        flags |= item_flags::SINGLE_PRECISION;
    }
    if o.signed_distance {
        flags |= item_flags::SIGNED_DISTANCE;
    }
    let identity = gjkd_pose {
        translation: [0.0; 3],
        rotation: [0.0, 0.0, 0.0, 1.0],
    };
    gjkd_pair_query {
        kind: ItemKind::Distance as u32,
        flags,
        a,
        b,
        pose_a: identity,
        pose_b: identity,
        tolerance: o.tolerance,
        margin: if o.use_margin { o.margin } else { 0.0 },
        // An unknown precision or a zero cap is left for the server to
        // refuse, row by row.
        max_iterations: if o.precision > 1 { 0 } else { o.max_iterations },
        reserved: 0,
    }
}

/// The distances of `count` pairs in one call: `queries[i]` in, its answer
/// into `out[i]`. The fastest batch of this API: the rows are copied into
/// the request's shared memory in one piece, and the answers, whole, from
/// the response's into `out`, as the Rust client does with its items.
///
/// A pair that fails (an unknown id, a bad pose given in its row, bad
/// options) has its `gjkd_error_code` in `out[i].error`, zeros elsewhere,
/// and the other pairs are answered: the call still returns `GJKD_OK`.
/// Batches larger than the server takes are split. A count of 0 does
/// nothing (`queries` and `out` may then be NULL).
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `queries`, `out`),
/// `GJKD_ERR_BUSY`, `GJKD_ERR_INVALID_ARGUMENT` (a count larger
/// than any array; a row not made by `gjkd_pair_query_of()`, or whose
/// `flags` has bits other than those it set and `GJKD_POSE_A |
/// GJKD_POSE_B` (a row asking `GJKD_PAIR_GRADIENT` goes through
/// `gjkd_query_pairs_gradients()`), or whose `reserved` is not 0:
/// nothing is sent);
/// `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT` (rows of the chunks answered
/// before are written, the others left as they were).
///
/// # Safety
/// `client` is NULL or a live handle; `queries` NULL or `count` readable
/// rows; `out` NULL or `count` writable rows.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_query_pairs(
    client: *mut gjkd_client,
    queries: *const gjkd_pair_query,
    count: usize,
    out: *mut gjkd_result,
) -> gjkd_status {
    guard("gjkd_query_pairs", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                if count == 0 {
                    return Ok(());
                }
                let queries = slice(queries, count, "queries")?;
                let out = slice_mut(out, count, "out")?.ok_or_else(|| Failure::null("out"))?;
                check_rows(queries, ROW_FLAGS)?;
                c.run_slices(as_items(queries), as_item_results(out))
            })
        }
    })
}

/// As `gjkd_query_pairs()`, for rows that may ask for their distance's
/// gradient (`row.flags |= GJKD_PAIR_GRADIENT`, and
/// `GJKD_PAIR_GRADIENT_BASE`): the gradient of the `k`-th row that asks
/// goes into `gradients[k]` (an array the caller owns and keeps from call
/// to call; a row that failed gets `columns` and `flags` 0), and
/// `*written` (if not NULL) is set to the number of gradients written.
/// Only the rows that ask carry a gradient, in the reply too: rows that
/// ask none cost what they cost in `gjkd_query_pairs()`.
///
/// Errors: those of `gjkd_query_pairs()`, and
/// `GJKD_ERR_INVALID_ARGUMENT` when `gradient_count` is less than the rows
/// that ask (nothing is sent); `gradients` may be NULL when none asks.
///
/// # Safety
/// As `gjkd_query_pairs()`; `gradients` NULL or `gradient_count` writable
/// rows; `written` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_query_pairs_gradients(
    client: *mut gjkd_client,
    queries: *const gjkd_pair_query,
    count: usize,
    out: *mut gjkd_result,
    gradients: *mut gjkd_gradient,
    gradient_count: usize,
    written: *mut usize,
) -> gjkd_status {
    guard("gjkd_query_pairs_gradients", || {
        // SAFETY: the caller's promises.
        unsafe {
            if let Some(w) = written.as_mut() {
                *w = 0;
            }
            with_client(client, |c| {
                if count == 0 {
                    return Ok(());
                }
                let queries = slice(queries, count, "queries")?;
                let out = slice_mut(out, count, "out")?.ok_or_else(|| Failure::null("out"))?;
                check_rows(queries, GRADIENT_ROW_FLAGS)?;
                let items = as_items(queries);
                let asked = ReplyEntry::gradients_asked(items);
                let gradients = match slice_mut(gradients, gradient_count, "gradients")? {
                    Some(g) => g,
                    None if asked == 0 => &mut [],
                    None => return Err(Failure::null("gradients")),
                };
                if gradients.len() < asked {
                    return Err(Failure::invalid(format!(
                        "gradient_count {gradient_count}: {asked} rows ask for a gradient"
                    )));
                }
                let n =
                    c.run_slices_gradients(items, as_item_results(out), as_gradients(gradients))?;
                if let Some(w) = written.as_mut() {
                    *w = n;
                }
                Ok(())
            })
        }
    })
}

/// The caller's gradient rows as the wire's gradients (same layout).
fn as_gradients(out: &mut [gjkd_gradient]) -> &mut [Gradient] {
    // SAFETY: same size, alignment and field offsets (asserted in
    // `gradient.rs`), every bit pattern valid in both.
    unsafe { std::slice::from_raw_parts_mut(out.as_mut_ptr().cast(), out.len()) }
}

/// The caller's rows as the wire's items (same layout).
fn as_items(queries: &[gjkd_pair_query]) -> &[Item] {
    // SAFETY: same size, alignment and field offsets (asserted above), and
    // every bit pattern valid in both.
    unsafe { std::slice::from_raw_parts(queries.as_ptr().cast(), queries.len()) }
}

/// The caller's answer rows as the wire's results (same layout).
fn as_item_results(out: &mut [gjkd_result]) -> &mut [ItemResult] {
    // SAFETY: as `as_items`.
    unsafe { std::slice::from_raw_parts_mut(out.as_mut_ptr().cast(), out.len()) }
}

/// Refuses the first row that is not a distance query or has bits the API
/// does not define, by index: such a row could change what the server
/// stores, or ask what this call does not document.
fn check_rows(queries: &[gjkd_pair_query], allowed: u32) -> Result<(), Failure> {
    let distance = ItemKind::Distance as u32;
    let bad = |q: &gjkd_pair_query| (q.kind ^ distance) | (q.flags & !allowed) | q.reserved;
    // One branch-free pass first: rows are almost always right.
    if queries.iter().fold(0, |acc, q| acc | bad(q)) == 0 {
        return Ok(());
    }
    let i = queries.iter().position(|q| bad(q) != 0).unwrap_or_default();
    let q = &queries[i];
    Err(Failure::invalid(if q.kind != distance {
        format!(
            "queries[{i}]: kind {} is not a distance query: make rows with gjkd_pair_query_of()",
            q.kind
        )
    } else if q.flags & !allowed & GRADIENT_ROW_FLAGS != 0 {
        format!(
            "queries[{i}]: asks for a gradient (GJKD_PAIR_GRADIENT): use \
             gjkd_query_pairs_gradients()"
        )
    } else if q.flags & !allowed != 0 {
        format!(
            "queries[{i}]: flags {:#x} has bits other than GJKD_POSE_A | GJKD_POSE_B, \
             GJKD_PAIR_GRADIENT | GJKD_PAIR_GRADIENT_BASE and those of gjkd_pair_query_of()",
            q.flags
        )
    } else {
        format!("queries[{i}]: reserved {} is not 0", q.reserved)
    }))
}
