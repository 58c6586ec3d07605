//! The gradient of a pair's distance with respect to the coordinates that
//! move its first object, as it travels in a query reply's gradient
//! section ([`GradientRow`](crate::GradientRow)) or a scene row
//! ([`SceneRow::gradient`](crate::SceneRow::gradient)).
//!
//! Asked with [`item_flags::GRADIENT`](crate::item_flags::GRADIENT) on a
//! pair query or [`scene_flags::GRADIENTS`](crate::scene_flags::GRADIENTS)
//! on a scene request. The coordinates are those that move object `a` (the
//! group's member in a scene row):
//!
//! - `a` a link of a robot: the robot's moving joints, in the order of its
//!   position array, then (with [`item_flags::GRADIENT_BASE`](crate::item_flags::GRADIENT_BASE)
//!   or [`scene_flags::GRADIENT_BASE`](crate::scene_flags::GRADIENT_BASE))
//!   the base pose's twist. When `b` is a link of the same robot
//!   (self-collision), its motion is in the gradient too.
//! - any other object: its pose's twist.
//!
//! A twist is `[v, ω]` in world coordinates, turning about the pose's
//! origin `c`: the pose moves to `Translation(c + v·t) · Rotation(ω·t) ·
//! Translation(−c) · pose` (the same as `gjkd_model::twist_jacobian`).
//!
//! Entry `k` is `∂d/∂x_k = n · (J_b(p_b) − J_a(p_a))_k` from the witness
//! points `p_a`, `p_b` and the unit normal `n` (from `a` towards `b`), where
//! `J` are the points' Jacobians (columns of objects that `x_k` does not move
//! are zero): GJK paper, equations 2.9–2.10.

use iceoryx2::prelude::ZeroCopySend;

/// Most columns a gradient carries: a robot's moving joints plus, when
/// asked, the 6 of its base twist. A gradient of a robot with more is
/// refused with [`ErrorCode::InvalidOptions`](crate::ErrorCode::InvalidOptions).
pub const GRADIENT_COLUMNS: usize = 16;

/// Bits of [`Gradient::flags`].
pub mod gradient_flags {
    /// The gradient was computed: [`Gradient::columns`](super::Gradient::columns)
    /// entries hold it.
    pub const PRESENT: u32 = 1;
    /// The nearest points are not unique (parallel faces or edges, a face
    /// and an edge along it), or, for overlapping objects, the penetration
    /// depth is reached along more than one direction within its certified
    /// interval (a sphere's centre on a box's medial axis, a box centred in
    /// a bigger one, crossing capsules): the distance may have no gradient
    /// here, and the values are a one-sided (sub)gradient, that of the
    /// witness points reported.
    pub const NOT_UNIQUE: u32 = 1 << 1;
    /// The last 6 columns are the robot base's twist.
    pub const BASE: u32 = 1 << 2;
    /// The objects overlap and no separating direction is known: the values
    /// are zero.
    pub const NO_DIRECTION: u32 = 1 << 3;
}

/// A pair distance's gradient with respect to the coordinates that move its
/// first object: a robot link's joints (then its base twist when asked), or
/// another object's pose twist `[v, ω]` (world frame, about its origin); entry
/// `k` is `n · (J_b(p_b) − J_a(p_a))_k`. Asked with
/// [`item_flags::GRADIENT`](crate::item_flags::GRADIENT) or
/// [`scene_flags::GRADIENTS`](crate::scene_flags::GRADIENTS).
#[derive(Clone, Copy, Debug, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("gjkd.v4.Gradient")]
pub struct Gradient {
    /// `∂d/∂x_k` for `k < columns`; zero beyond.
    pub values: [f64; GRADIENT_COLUMNS],
    /// Columns in use: a robot's moving joints (plus 6 with
    /// [`gradient_flags::BASE`]), or 6 for a free object's twist; 0 when
    /// not asked.
    pub columns: u32,
    /// [`gradient_flags`] bits.
    pub flags: u32,
    /// A bound on each entry's error that comes from the distance's
    /// certified interval: the normal is within angle `θ`, `cos θ =
    /// lower/upper`, of the true one, so an entry is off by at most `2
    /// sin(θ/2)` times the largest `|J_b − J_a|` column. Witness points
    /// that are not unique add what [`gradient_flags::NOT_UNIQUE`] says.
    pub error: f64,
}

impl Default for Gradient {
    fn default() -> Self {
        Gradient::NONE
    }
}

impl Gradient {
    /// No gradient (not asked).
    pub const NONE: Gradient = Gradient {
        values: [0.0; GRADIENT_COLUMNS],
        columns: 0,
        flags: 0,
        error: 0.0,
    };

    /// The entries in use; empty when no gradient was computed.
    pub fn as_slice(&self) -> &[f64] {
        if self.is_present() {
            &self.values[..(self.columns as usize).min(GRADIENT_COLUMNS)]
        } else {
            &[]
        }
    }

    /// Whether a gradient was computed ([`gradient_flags::PRESENT`]).
    pub fn is_present(&self) -> bool {
        self.flags & gradient_flags::PRESENT != 0
    }

    /// Whether the nearest points are not unique
    /// ([`gradient_flags::NOT_UNIQUE`]): the values are a one-sided
    /// (sub)gradient.
    pub fn is_not_unique(&self) -> bool {
        self.flags & gradient_flags::NOT_UNIQUE != 0
    }

    /// Whether the last 6 entries are the base's twist
    /// ([`gradient_flags::BASE`]).
    pub fn has_base(&self) -> bool {
        self.flags & gradient_flags::BASE != 0
    }
}

impl crate::Item {
    /// This pair query also asks its distance's gradient with respect to
    /// the coordinates that move A (see [`Gradient`]); with `base`, when A
    /// is a robot link, the base twist's 6 columns too.
    pub fn with_gradient(mut self, base: bool) -> Self {
        self.flags |= crate::item_flags::GRADIENT;
        if base {
            self.flags |= crate::item_flags::GRADIENT_BASE;
        }
        self
    }
}
