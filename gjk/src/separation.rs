//! A certified lower bound on the distance from one separating direction:
//! two support values instead of a query, for a caller that knows a
//! direction that separated the shapes a moment ago (a kept normal) and
//! wants to know whether it still does.
//!
//! For any unit `n`, every point `a` of A and `b` of B satisfy
//! `|b - a| >= (b - a)·n >= min_B x·n - max_A x·n = -h_A(n) - h_B(-n)`, with
//! `h` the support function (Theorem 4.1's lower bound, at any direction).
//! A union's support function is the largest of its pieces'.

use nalgebra::{Isometry3, Vector3};

use crate::shape::{Convex, Shape};

/// How many units of round-off, relative to the magnitudes involved, the
/// computed bound may be above the exact one: the direction rotated into
/// two frames (a few units per component), dot products of three terms,
/// the sums of up to five of them, and the division by `|n|`, with room
/// to spare.
const ALLOWANCE_UNITS: f64 = 64.0;

/// A certified lower bound on the distance between `a` at `pose_a` and `b`
/// at `pose_b` from `direction` (world frame, pointing from A towards B,
/// any length): how far apart the two shapes' slabs along it are, less a
/// bound on the round-off. Never above the true distance; negative (and
/// so proving nothing) when the direction does not separate them.
///
/// Costs one support search per convex piece, no iteration: a recheck of a
/// separation found earlier (for example a previous answer's
/// [`Answer::normal`](crate::Answer::normal) carried with A's pose), which
/// a full [`distance`](crate::distance) would refine.
///
/// A zero, NaN or infinite direction, or a non-finite pose, gives
/// `f64::NEG_INFINITY`.
///
/// ```
/// use gjk::{separation_bound, Convex, Shape};
/// use nalgebra::{Isometry3, Vector3};
///
/// let a: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?.into();
/// let b: Shape = Convex::sphere(0.5)?.into();
/// let pose_b = Isometry3::translation(3.0, 0.0, 0.0);
/// let x = Vector3::x();
/// let lower = separation_bound(&a, &Isometry3::identity(), &b, &pose_b, &x);
/// assert!(lower <= 1.5 && lower > 1.5 - 1e-12);
/// // A slanted direction proves less, never more.
/// let slanted = Vector3::new(1.0, 1.0, 0.0);
/// assert!(separation_bound(&a, &Isometry3::identity(), &b, &pose_b, &slanted) < lower);
/// # Ok::<(), gjk::Error>(())
/// ```
pub fn separation_bound(
    a: &Shape,
    pose_a: &Isometry3<f64>,
    b: &Shape,
    pose_b: &Isometry3<f64>,
    direction: &Vector3<f64>,
) -> f64 {
    let length = direction.norm();
    if !(length > 0.0 && length.is_finite()) {
        return f64::NEG_INFINITY;
    }
    let n = direction / length;
    let (ha, ma) = support_value(a, pose_a, &n);
    let (hb, mb) = support_value(b, pose_b, &-n);
    let lower = -ha - hb - ALLOWANCE_UNITS * f64::EPSILON * (ma + mb) - f64::MIN_POSITIVE;
    if lower.is_nan() {
        f64::NEG_INFINITY
    } else {
        lower
    }
}

/// The support value of `shape` at `pose` along the unit world direction
/// `n` (the largest of its pieces'), and the magnitude its round-off is
/// relative to.
fn support_value(shape: &Shape, pose: &Isometry3<f64>, n: &Vector3<f64>) -> (f64, f64) {
    let d = pose.rotation.inverse_transform_vector(n);
    let t = &pose.translation.vector;
    let base = t.dot(n);
    let scale = t.abs().sum();
    match shape {
        Shape::Convex(c) => {
            let (h, m) = piece_value(c, &d);
            (base + h, scale + m)
        }
        Shape::Compound(compound) => {
            let mut best = f64::NEG_INFINITY;
            let mut magnitude = 0.0f64;
            for (offset, c) in compound.pieces() {
                let e = offset.rotation.inverse_transform_vector(&d);
                let o = &offset.translation.vector;
                let (h, m) = piece_value(c, &e);
                best = best.max(o.dot(&d) + h);
                magnitude = magnitude.max(o.abs().sum() + m);
            }
            (base + best, scale + magnitude)
        }
    }
}

/// The support value of a convex piece along `d` (its body frame, unit
/// up to round-off), and the magnitude of its terms.
fn piece_value(c: &Convex, d: &Vector3<f64>) -> (f64, f64) {
    let centroid = c.centroid().coords;
    let core = match c.cylinder_dimensions() {
        // The closed form, not the support point's code, whose rim point
        // may fall short of the maximum.
        Some((radius, half_height)) => radius * d.x.hypot(d.y) + half_height * d.z.abs(),
        None => c.support_point(d).1.dot(d),
    };
    let value = centroid.dot(d) + core + c.radius() * d.norm();
    let magnitude = centroid.abs().sum() + 2.0 * c.size() + c.radius();
    (value, magnitude)
}
