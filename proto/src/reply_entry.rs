//! The query reply's slice: the items' results, then the gradients of the
//! items that asked for one.

use std::fmt;

use iceoryx2::prelude::ZeroCopySend;

use crate::{Gradient, ItemResult};

/// The gradient of one pair item of a query request, in the reply's
/// gradient section (see [`ReplyEntry`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.GradientRow")]
pub struct GradientRow {
    /// Index of the item it answers in the request.
    pub item: u32,
    /// Zero.
    pub reserved: u32,
    /// The item's gradient; [`Gradient::NONE`] when the item failed.
    pub gradient: Gradient,
}

/// One element of the query reply's slice. The first
/// [`ReplyHeader::count`](crate::ReplyHeader::count) are results, one per
/// item in order; the next [`ReplyHeader::gradients`](crate::ReplyHeader::gradients)
/// are gradients, one per item flagged
/// [`item_flags::GRADIENT`](crate::item_flags::GRADIENT), in item order.
/// One element type keeps the query service one zero-copy slice, and a
/// pair that asks no gradient carries none: the gradient is nearly as
/// large as the result. Both views are padding-free plain old data of the
/// same size, so any bytes are valid in either, and the slice views below
/// cast without copying.
#[derive(Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.ReplyEntry")]
pub union ReplyEntry {
    /// An item's result.
    pub result: ItemResult,
    /// A gradient-asking item's gradient.
    pub gradient: GradientRow,
}

const _: () = {
    assert!(size_of::<ItemResult>() == size_of::<GradientRow>());
    assert!(align_of::<ItemResult>() == align_of::<GradientRow>());
    assert!(size_of::<ReplyEntry>() == size_of::<ItemResult>());
    assert!(align_of::<ReplyEntry>() == align_of::<ItemResult>());
};

impl Default for ReplyEntry {
    fn default() -> Self {
        ReplyEntry {
            result: ItemResult::default(),
        }
    }
}

impl fmt::Debug for ReplyEntry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // SAFETY: any 152 bytes are a valid `ItemResult` (f64s and u32s).
        let result = unsafe { self.result };
        f.debug_struct("ReplyEntry")
            .field("result", &result)
            .finish()
    }
}

impl ReplyEntry {
    /// Entries needed to answer `items`: one result each, and a gradient
    /// for each flagged [`item_flags::GRADIENT`](crate::item_flags::GRADIENT).
    pub fn gradients_asked(items: &[crate::Item]) -> usize {
        items
            .iter()
            .filter(|i| i.flags & crate::item_flags::GRADIENT != 0)
            .count()
    }

    /// `entries` seen as its first `count` results and the gradients after
    /// them, without copying; `None` when `entries` is shorter than
    /// `count`.
    pub fn split(entries: &[ReplyEntry], count: usize) -> Option<(&[ItemResult], &[GradientRow])> {
        if entries.len() < count {
            return None;
        }
        let (results, gradients) = entries.split_at(count);
        // SAFETY: `ReplyEntry` is a `repr(C)` union with both as fields,
        // of the same size and alignment (asserted above); any bytes are
        // valid in either.
        unsafe {
            Some((
                std::slice::from_raw_parts(results.as_ptr().cast(), results.len()),
                std::slice::from_raw_parts(gradients.as_ptr().cast(), gradients.len()),
            ))
        }
    }

    /// As [`ReplyEntry::split`], writable.
    pub fn split_mut(
        entries: &mut [ReplyEntry],
        count: usize,
    ) -> Option<(&mut [ItemResult], &mut [GradientRow])> {
        if entries.len() < count {
            return None;
        }
        let (results, gradients) = entries.split_at_mut(count);
        // SAFETY: as in `split`; the two halves do not overlap.
        unsafe {
            Some((
                std::slice::from_raw_parts_mut(results.as_mut_ptr().cast(), results.len()),
                std::slice::from_raw_parts_mut(gradients.as_mut_ptr().cast(), gradients.len()),
            ))
        }
    }
}
