//! The signed distances of a batch of pairs: `gjkd_distances()` with an
//! optional output for the signed distance and its certified interval.

use gjkd_proto::{item_flags, result_flags};
use rust_client::{Item, ItemResult};

use crate::args::slice_mut;
use crate::handle::gjkd_client;
use crate::query::distances_with;
use crate::status::{Failure, gjkd_status};
use crate::types::{gjkd_id, gjkd_pose, gjkd_query_options, gjkd_results};

/// The caller's arrays for the signed distances of `count` pairs (see
/// `gjkd_signed_distances()`): `value` is required, `lower` and `upper`
/// may be NULL (not wanted). Row `i` of a failed pair has zeros.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct gjkd_signed_results {
    /// `count` signed distances: the distance apart, minus the
    /// penetration depth (the shortest translation that separates the
    /// shapes) overlapping. Required.
    pub value: *mut f64,
    /// `count` certified lower bounds on the signed distance.
    pub lower: *mut f64,
    /// `count` certified upper bounds on the signed distance.
    pub upper: *mut f64,
}

/// The caller's signed-distance arrays, as slices.
struct SignedOutputs<'a> {
    value: &'a mut [f64],
    lower: Option<&'a mut [f64]>,
    upper: Option<&'a mut [f64]>,
}

impl SignedOutputs<'_> {
    fn write(&mut self, start: usize, results: &[ItemResult]) {
        for (i, r) in (start..).zip(results) {
            // A failed row carries no answer: zeros, as `gjkd_results`'s.
            let answered = r.flags & result_flags::SIGNED_DISTANCE != 0;
            let (v, lo, up) = if answered {
                (r.signed_distance, r.signed_lower, r.signed_upper)
            } else {
                (0.0, 0.0, 0.0)
            };
            self.value[i] = v;
            if let Some(lower) = self.lower.as_deref_mut() {
                lower[i] = lo;
            }
            if let Some(upper) = self.upper.as_deref_mut() {
                upper[i] = up;
            }
        }
    }
}

/// `gjkd_distances()` that also answers each pair's signed distance with
/// its certified interval into `signed_out` (see `gjkd_signed_results`),
/// or, when `signed_out` is NULL, exactly `gjkd_distances()`.
///
/// A pair apart has its distance as signed distance (the same interval;
/// it costs nothing more); a pair that may overlap is expanded, and its
/// row's `point_a`, `point_b`, `normal` and `pieces` in `out` are then the
/// depth's witnesses, direction (along which B leaves A) and deepest piece
/// pair, with `point_b - point_a = value * normal`.
///
/// Errors: as `gjkd_distances()`, plus `GJKD_ERR_NULL_POINTER` for
/// `signed_out->value` (with a non-zero count).
///
/// # Safety
/// As `gjkd_distances()`; `signed_out` is NULL or readable, and each of
/// its non-NULL pointers points to `count` doubles.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gjkd_signed_distances(
    client: *mut gjkd_client,
    pairs: *const gjkd_id,
    count: usize,
    poses_a: *const gjkd_pose,
    poses_b: *const gjkd_pose,
    options: *const gjkd_query_options,
    out: *const gjkd_results,
    signed_out: *const gjkd_signed_results,
) -> gjkd_status {
    // SAFETY: the caller's promise: NULL or readable.
    let signed_out = unsafe { signed_out.as_ref() };
    // `signed_out`'s arrays are read once the common arguments are
    // checked (a count of 0 reads nothing).
    let prepare = |mut template: Item| {
        let Some(s) = signed_out else {
            return Ok((template, None));
        };
        template.flags |= item_flags::SIGNED_DISTANCE;
        // SAFETY: the caller's promise: `count` doubles each.
        let outputs = unsafe {
            SignedOutputs {
                value: slice_mut(s.value, count, "signed_out.value")?
                    .ok_or_else(|| Failure::null("signed_out.value"))?,
                lower: slice_mut(s.lower, count, "signed_out.lower")?,
                upper: slice_mut(s.upper, count, "signed_out.upper")?,
            }
        };
        Ok((template, Some(outputs)))
    };
    // SAFETY: forwarded.
    unsafe {
        distances_with(
            "gjkd_signed_distances",
            client,
            (pairs, count),
            (poses_a, poses_b),
            options,
            out,
            prepare,
            |signed: &mut Option<SignedOutputs<'_>>, start, results| {
                if let Some(signed) = signed.as_mut() {
                    signed.write(start, results);
                }
            },
        )
    }
}
