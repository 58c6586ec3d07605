//! A certified lower bound on the penetration depth from a kept simplex:
//! no support search at all, for a caller that keeps a query's
//! [`WarmStart`] of an overlapping pair and wants to know whether the pair
//! still overlaps at new poses.
//!
//! A query that finds the shapes' cores intersecting ends on a tetrahedron
//! of points `a_i - b_i`, `a_i` a vertex of A and `b_i` one of B, around the
//! origin. At any poses, the same vertices moved with their shapes are
//! still points of `A - B`, so their hull is inside it; when it still
//! holds a ball of radius `r` about the origin, so does `A - B`, and no
//! translation shorter than `r` separates the shapes.

use nalgebra::{Isometry3, Matrix3, Vector3};

use crate::query::WarmStart;
use crate::shape::Shape;

/// How many units of round-off, relative to the magnitudes of a point's
/// terms, a computed point may be away from the exact one: two rotations
/// of a vertex (one by the piece offset, one by the pose), the offsets'
/// and poses' translations added, and the difference, with room to spare.
const POINT_UNITS: f64 = 32.0;

/// How many units of round-off, relative to `M^3 / |n| + M` (`M` the
/// points' largest norm, `n` a face's cross product), a face plane's
/// computed distance from the origin may be off: the edge differences,
/// their cross product, the dot product and the division, with room to
/// spare.
const FACE_UNITS: f64 = 256.0;

/// A certified lower bound on the penetration depth of `a` at `pose_a` and
/// `b` at `pose_b` (the shortest translation that separates them), from
/// the tetrahedron of `warm` (a [`WarmStart`] a query of this pair handed
/// back, at whatever poses): the largest ball about the origin inside the
/// hull of its vertex pairs moved to these poses, less a bound on the
/// round-off. 0 when that proves nothing: the simplex is not a
/// tetrahedron, names a cylinder's point or an index the shapes do not
/// have, no longer surrounds the origin, or is too flat to tell. The
/// shapes' rounding radii are not counted (a lower bound still).
///
/// ```
/// use gjk::{distance, penetration_bound, Convex, Options, Shape};
/// use nalgebra::{Isometry3, Matrix3, Vector3};
///
/// let a: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?.into();
/// let b: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?.into();
/// let pose_b = Isometry3::translation(1.0, 0.2, 0.1);
/// let answer = distance(&a, &Isometry3::identity(), &b, &pose_b, &Options::default(), None)?;
/// assert_eq!(answer.distance, 0.0);
/// // B moved a little further in: the kept simplex still proves the overlap.
/// let nearer = Isometry3::translation(0.9, 0.2, 0.1);
/// let depth = penetration_bound(&a, &Isometry3::identity(), &b, &nearer, &answer.warm_start);
/// assert!(depth > 0.0 && depth <= 1.1);
/// // Apart, it proves nothing.
/// let apart = Isometry3::translation(3.0, 0.0, 0.0);
/// assert_eq!(penetration_bound(&a, &Isometry3::identity(), &b, &apart, &answer.warm_start), 0.0);
/// # Ok::<(), gjk::Error>(())
/// ```
pub fn penetration_bound(
    a: &Shape,
    pose_a: &Isometry3<f64>,
    b: &Shape,
    pose_b: &Isometry3<f64>,
    warm: &WarmStart,
) -> f64 {
    let pairs = warm.pairs();
    let [pa, pb] = warm.pieces();
    let (Some((offset_a, ca)), Some((offset_b, cb))) = (a.piece(pa as usize), b.piece(pb as usize))
    else {
        return 0.0;
    };
    if pairs.len() != 4 || ca.cylinder_dimensions().is_some() || cb.cylinder_dimensions().is_some()
    {
        return 0.0;
    }
    let (va, vb) = (ca.vertices(), cb.vertices());
    let (ra, ta) = placed(pose_a, &offset_a);
    let (rb, tb) = placed(pose_b, &offset_b);
    let shift = ta - tb;
    let mut points = [Vector3::zeros(); 4];
    for (w, &[i, j]) in points.iter_mut().zip(pairs) {
        let (Some(x), Some(y)) = (va.get(i as usize), vb.get(j as usize)) else {
            return 0.0;
        };
        *w = ra * x.coords - rb * y.coords + shift;
    }
    // Every vertex is within `reach` of its piece's origin (a 1-norm
    // within twice that).
    let terms = pose_a.translation.vector.abs().sum()
        + pose_b.translation.vector.abs().sum()
        + offset_a.translation.vector.abs().sum()
        + offset_b.translation.vector.abs().sum()
        + 2.0 * (ca.reach() + cb.reach());
    let error = POINT_UNITS * f64::EPSILON * terms;
    let radius = inner_radius(&points) - error;
    if radius > 0.0 { radius } else { 0.0 }
}

/// A piece placed by its offset and its shape's pose: the rotation
/// matrix and translation of `pose * offset`.
#[inline]
fn placed(pose: &Isometry3<f64>, offset: &Isometry3<f64>) -> (Matrix3<f64>, Vector3<f64>) {
    let rotation = (pose.rotation * offset.rotation).to_rotation_matrix();
    let translation = pose.rotation * offset.translation.vector + pose.translation.vector;
    (rotation.into_inner(), translation)
}

/// The smallest distance from the origin to a face plane of the
/// tetrahedron `p`, less its round-off, when the origin is inside it by
/// more than that on every face; 0 or less otherwise.
#[inline]
fn inner_radius(p: &[Vector3<f64>; 4]) -> f64 {
    let [p0, p1, p2, p3] = p;
    let m2 = p0
        .norm_squared()
        .max(p1.norm_squared())
        .max(p2.norm_squared())
        .max(p3.norm_squared());
    let m = m2.sqrt() * (1.0 + 4.0 * f64::EPSILON);
    let scale = (m * m * m, m);
    face_distance(p0, p1, p2, p3, scale)
        .min(face_distance(p0, p1, p3, p2, scale))
        .min(face_distance(p0, p2, p3, p1, scale))
        .min(face_distance(p1, p2, p3, p0, scale))
}

/// The distance of the origin inside the plane of face `a`, `b`, `c` (on
/// the side of `d`), less its round-off given the points' largest norm `m`
/// (`scale` is `(m^3, m)`); 0 when `d`'s side is not decided.
#[inline(always)]
fn face_distance(
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    c: &Vector3<f64>,
    d: &Vector3<f64>,
    scale: (f64, f64),
) -> f64 {
    let n = (b - a).cross(&(c - a));
    let inverse = 1.0 / n.norm();
    let slack = FACE_UNITS * f64::EPSILON * (scale.0 * inverse + scale.1);
    // The fourth point's side decides the outward normal: within the
    // round-off it is not decided, and neither is anything else.
    let opposite = n.dot(&(d - a)) * inverse;
    // (A NaN, from a degenerate face, decides nothing either.)
    if opposite.abs() <= slack || opposite.is_nan() || slack.is_nan() {
        return 0.0;
    }
    let outward = if opposite > 0.0 { -1.0 } else { 1.0 };
    outward * n.dot(a) * inverse - slack
}
