//! The kind-dependent part of an [`Item`](crate::Item): a pair query's
//! pose of B and options, or a joint update's positions. Two views of the
//! same 80 bytes, so that the query service keeps one fixed-size item type
//! (one zero-copy slice) while every field is named for what it holds.

use std::fmt;

use iceoryx2::prelude::ZeroCopySend;

use crate::{JOINTS_PER_ITEM, Pose};

/// The body of a [`ItemKind::SetPose`](crate::ItemKind::SetPose),
/// [`ItemKind::Distance`](crate::ItemKind::Distance) and scene-only item:
/// the pose of B and the query options.
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.PairBody")]
pub struct PairBody {
    /// This query's pose of B with [`item_flags::POSE_B`](crate::item_flags::POSE_B).
    pub pose_b: Pose,
    /// Relative tolerance.
    pub tolerance: f64,
    /// Early-exit margin, with [`item_flags::MARGIN`](crate::item_flags::MARGIN).
    pub margin: f64,
    /// Iteration cap.
    pub max_iterations: u32,
    /// Zero.
    pub reserved: u32,
}

/// The body of a [`ItemKind::SetJoints`](crate::ItemKind::SetJoints) item:
/// joint positions `first .. first + count` of the robot.
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.JointsBody")]
pub struct JointsBody {
    /// The positions (radians or metres, in the robot's joint order); only
    /// the first `count` are read.
    pub positions: [f64; JOINTS_PER_ITEM],
    /// Number of positions in use, 0 to [`JOINTS_PER_ITEM`]: none moves only
    /// the base, as a robot without moving joints needs.
    pub count: u32,
    /// Index of the joint `positions[0]` sets.
    pub first: u32,
}

/// The two views of an item's body. Both are plain old data of the same
/// size without padding, so every bit pattern is a valid value of either:
/// reading the view the item's kind does not use gives numbers, never
/// undefined behaviour. [`Item::pair`](crate::Item::pair) and
/// [`Item::joints`](crate::Item::joints) read it without `unsafe`.
#[derive(Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.ItemBody")]
pub union ItemBody {
    /// Pose updates, pair queries and scene-only items.
    pub pair: PairBody,
    /// Joint updates.
    pub joints: JointsBody,
}

// The soundness of reading either view rests on these: same size, no
// padding in either (every byte belongs to a field of each view).
const _: () = {
    assert!(size_of::<PairBody>() == size_of::<ItemBody>());
    assert!(size_of::<JointsBody>() == size_of::<ItemBody>());
    assert!(size_of::<PairBody>() == size_of::<Pose>() + 2 * 8 + 2 * 4);
    assert!(size_of::<JointsBody>() == JOINTS_PER_ITEM * 8 + 2 * 4);
};

impl ItemBody {
    /// The pair view.
    pub fn pair(&self) -> &PairBody {
        // SAFETY: both views are padding-free plain old data of the same
        // size (asserted above); any bytes are a valid `PairBody`.
        unsafe { &self.pair }
    }

    /// The pair view, to change.
    pub fn pair_mut(&mut self) -> &mut PairBody {
        // SAFETY: as in `pair`; writing through it keeps every byte valid
        // for the other view too.
        unsafe { &mut self.pair }
    }

    /// The joints view.
    pub fn joints(&self) -> &JointsBody {
        // SAFETY: as in `pair`.
        unsafe { &self.joints }
    }

    /// The joints view, to change.
    pub fn joints_mut(&mut self) -> &mut JointsBody {
        // SAFETY: as in `pair_mut`.
        unsafe { &mut self.joints }
    }
}

impl fmt::Debug for ItemBody {
    /// Both views: the body does not know its item's kind.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ItemBody")
            .field("pair", self.pair())
            .field("joints", self.joints())
            .finish()
    }
}

impl PartialEq for ItemBody {
    /// Equal when the pair views are equal (the pair view's floats
    /// compare as floats, as a derived comparison of the old flat item
    /// did) and the joints views are too.
    fn eq(&self, other: &Self) -> bool {
        self.pair() == other.pair() && self.joints() == other.joints()
    }
}
