//! Distance gradients: a pair row's (`GJKD_PAIR_GRADIENT`, answered by
//! `gjkd_query_pairs_gradients()`) and a scene
//! row's (`gjkd_scene_options::gradients`), with respect to the
//! coordinates that move the pair's first object.

use std::mem::offset_of;

use gjkd_proto::{GRADIENT_COLUMNS, Gradient, gradient_flags, item_flags};

/// Most columns of a `gjkd_gradient`.
pub const GJKD_GRADIENT_COLUMNS: usize = 16;
const _: () = assert!(GJKD_GRADIENT_COLUMNS == GRADIENT_COLUMNS);

/// `gjkd_pair_query::flags` bit (OR it in): also the distance's gradient,
/// into the caller's gradient array of `gjkd_query_pairs_gradients()`.
pub const GJKD_PAIR_GRADIENT: u32 = 1 << 8;
const _: () = assert!(GJKD_PAIR_GRADIENT == item_flags::GRADIENT);

/// `gjkd_pair_query::flags` bit, with `GJKD_PAIR_GRADIENT`: when `a` is a
/// robot link, the base pose's twist in the last 6 columns too.
pub const GJKD_PAIR_GRADIENT_BASE: u32 = 1 << 9;
const _: () = assert!(GJKD_PAIR_GRADIENT_BASE == item_flags::GRADIENT_BASE);

/// `gjkd_gradient::flags` bit: the gradient was computed.
pub const GJKD_GRADIENT_PRESENT: u32 = 1;
const _: () = assert!(GJKD_GRADIENT_PRESENT == gradient_flags::PRESENT);

/// `gjkd_gradient::flags` bit: the nearest points are not unique
/// (parallel faces or edges): the values are a one-sided (sub)gradient.
pub const GJKD_GRADIENT_NOT_UNIQUE: u32 = 2;
const _: () = assert!(GJKD_GRADIENT_NOT_UNIQUE == gradient_flags::NOT_UNIQUE);

/// `gjkd_gradient::flags` bit: the last 6 columns are the base's twist.
pub const GJKD_GRADIENT_BASE: u32 = 4;
const _: () = assert!(GJKD_GRADIENT_BASE == gradient_flags::BASE);

/// `gjkd_gradient::flags` bit: the objects overlap and no separating
/// direction is known; the values are zero.
pub const GJKD_GRADIENT_NO_DIRECTION: u32 = 8;
const _: () = assert!(GJKD_GRADIENT_NO_DIRECTION == gradient_flags::NO_DIRECTION);

/// The gradient of a pair's distance `d` with respect to the coordinates
/// that move its object `a`: `values[k] = ∂d/∂x_k` for `k < columns`. When
/// `a` is a robot link, the coordinates are the robot's moving joints (in
/// `gjkd_robot_joint_name()` order; a self-collision pair's other link
/// moves too), then, with the base asked, the base twist `[v, ω]` (world
/// frame, turning about the base origin); for any other object, its
/// pose's twist. `error` bounds each entry's error from the distance's
/// certified interval.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct gjkd_gradient {
    /// `∂d/∂x_k`, zero beyond `columns`.
    pub values: [f64; GJKD_GRADIENT_COLUMNS],
    /// Entries in use; 0 when not asked.
    pub columns: u32,
    /// `GJKD_GRADIENT_*` bits.
    pub flags: u32,
    /// A bound on each entry's error from the distance's interval.
    pub error: f64,
}

impl Default for gjkd_gradient {
    fn default() -> Self {
        gjkd_gradient::from(&Gradient::NONE)
    }
}

impl From<&Gradient> for gjkd_gradient {
    fn from(g: &Gradient) -> Self {
        gjkd_gradient {
            values: g.values,
            columns: g.columns,
            flags: g.flags,
            error: g.error,
        }
    }
}

// `gjkd_gradient` is the wire's `Gradient` under a C name.
const _: () = {
    assert!(size_of::<gjkd_gradient>() == size_of::<Gradient>());
    assert!(offset_of!(gjkd_gradient, values) == offset_of!(Gradient, values));
    assert!(offset_of!(gjkd_gradient, columns) == offset_of!(Gradient, columns));
    assert!(offset_of!(gjkd_gradient, flags) == offset_of!(Gradient, flags));
    assert!(offset_of!(gjkd_gradient, error) == offset_of!(Gradient, error));
};
