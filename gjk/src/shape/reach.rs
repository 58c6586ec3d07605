//! How far a shape may reach from its body origin, and two shapes lie
//! apart, before a query's arithmetic could overflow.

use nalgebra::Isometry3;

/// How far a shape's vertices (or a compound's pieces) may reach from its
/// body origin: 2^999, about 5.4e300. With the relative translation of a
/// query held to [`MAX_SHIFT`], every sum of coordinates, rotated coordinate
/// and support dot product of a query stays below 2^1006, far from f64's
/// overflow at 2^1024: beyond, a query could overflow and certify bounds
/// that do not hold, so such shapes are refused when built.
pub(crate) const MAX_REACH: f64 = 5.357543035931337e300;

/// How far apart (each coordinate of the relative translation) two shapes
/// may be in a query: 2^1000, about 1.07e301.
pub(crate) const MAX_SHIFT: f64 = 1.0715086071862673e301;

/// Whether the relative pose of a query is finite and its translation
/// within [`MAX_SHIFT`] on every axis. Comparisons are false for NaN, and
/// `&` keeps them branch-free.
#[inline]
pub(crate) fn shift_is_in_range(p: &Isometry3<f64>) -> bool {
    let t = &p.translation.vector;
    let q = &p.rotation.coords;
    let q0 = (q.x * 0.0 + q.y * 0.0) + (q.z * 0.0 + q.w * 0.0);
    (t.x.abs() <= MAX_SHIFT) & (t.y.abs() <= MAX_SHIFT) & (t.z.abs() <= MAX_SHIFT) & (q0 == 0.0)
}

/// Whether every component of `p` is finite.
pub(crate) fn pose_is_finite(p: &Isometry3<f64>) -> bool {
    // x·0 is NaN exactly when x is infinite or NaN; no branch per component.
    let t = &p.translation.vector;
    let q = &p.rotation.coords;
    let poison = t.x * 0.0 + t.y * 0.0 + t.z * 0.0;
    let poison = poison + q.x * 0.0 + q.y * 0.0 + q.z * 0.0 + q.w * 0.0;
    poison == 0.0
}
