//! What a gradient is read from: the pair's witness points and unit
//! normal, and whether those points are unique.

use gjk::{Convex, DepthOptions, Shape, SupportMap};
use gjkd_proto::ItemResult;
use nalgebra::{Isometry3, Point3, Vector3};

use super::Side;

/// The witness points (world) and unit normal (from `a` towards `b`) of a
/// pair's distance.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Witness {
    pub point_a: Point3<f64>,
    pub point_b: Point3<f64>,
    pub normal: Vector3<f64>,
    /// A bound on `|n − n*|`, the reported normal's distance to the true
    /// one ([`normal_error`]).
    pub normal_error: f64,
    /// An overlapping pair's depth is reached along more than one
    /// direction (`gjk::SignedDistance::tied`): the witness is one of
    /// several.
    pub tied: bool,
}

/// The witness of `result`'s distance, `None` when the objects overlap
/// and no separating direction is known. The one place the gradients read
/// a pair's answer: when the answer carries a signed distance inside, its
/// direction is read here.
pub(crate) fn witness(result: &ItemResult) -> Option<Witness> {
    let normal = Vector3::from(result.normal);
    // The normal is zero when the cores touch or intersect.
    (normal.norm_squared() > 0.25).then(|| Witness {
        point_a: Point3::from(result.point_a),
        point_b: Point3::from(result.point_b),
        normal: normal.normalize(),
        normal_error: normal_error(result.lower, result.upper),
        tied: false,
    })
}

/// The witness of an overlapping (or touching) pair: gjk's signed
/// distance (the penetration depth by an expanding polytope), whose
/// certified lower bound on the depth also raises `result.penetration`.
/// `None` if gjk cannot answer (it answered the distance, so never).
pub(crate) fn overlap_witness(
    result: &mut ItemResult,
    a: &Side<'_>,
    b: &Side<'_>,
) -> Option<Witness> {
    let sd =
        gjk::signed_distance(a.shape, a.pose, b.shape, b.pose, &DepthOptions::default()).ok()?;
    depth_witness(result, &sd)
}

/// The witness of `sd`, the signed distance of the pair `result` answers
/// (computed by the caller, as a pair that asked for its signed distance
/// has); raises `result.penetration` to the depth's lower bound. `None`
/// when `sd` has no direction.
pub(crate) fn depth_witness(result: &mut ItemResult, sd: &gjk::SignedDistance) -> Option<Witness> {
    if sd.normal.norm_squared() <= 0.25 || !sd.normal.iter().all(|c| c.is_finite()) {
        return None;
    }
    result.penetration = result.penetration.max(-sd.upper);
    Some(Witness {
        point_a: sd.point_a,
        point_b: sd.point_b,
        normal: sd.normal.normalize(),
        // The depth's interval, read as the distance's is: a scale of the
        // normal's error, not a proof of it (the depth's normal is the
        // minimiser of a support function, not a nearest point).
        normal_error: normal_error(-sd.upper, -sd.lower),
        tied: sd.tied,
    })
}

/// A bound on `|n − n*|` for the reported unit normal `n` and the true one
/// `n*`: the reported vector is a point of the Minkowski difference no
/// longer than `upper`, and every point of it lies beyond `d* >= lower`
/// along `n*`, so `cos θ >= lower / upper`, and `|n − n*| = 2 sin(θ/2) =
/// sqrt(2 (1 − cos θ))`.
pub(crate) fn normal_error(lower: f64, upper: f64) -> f64 {
    if upper.is_nan() || upper <= 0.0 {
        return 2.0;
    }
    let cos = (lower / upper).clamp(0.0, 1.0);
    (2.0 * (1.0 - cos)).sqrt()
}

/// How far, in radians, the direction is tipped to find the supporting
/// feature: farther than the normal's own error (about the square root of
/// the tolerance), near enough that a curved surface's support point moves
/// by a small fraction of the shape.
const TIP: f64 = 1e-4;

/// A support point moving more than this fraction of its shape's size
/// under a tip is the end of a flat feature (an edge or a face), not a
/// curved surface's point sliding (`TIP` times the radius).
const FLAT: f64 = 1e-2;

/// Whether the nearest points of the pieces realising the distance are
/// not unique: the supporting features of `a` along `normal` and of `b`
/// against it are parallel (face and face, face and edge, parallel
/// edges), so the pair's witness can slide. Found by tipping the
/// direction both ways about two tangents and seeing how far each
/// support point jumps.
pub(crate) fn not_unique(
    (a, pose_a): (&Shape, &Isometry3<f64>),
    (b, pose_b): (&Shape, &Isometry3<f64>),
    pieces: [u32; 2],
    normal: &Vector3<f64>,
) -> bool {
    let (Some(fa), Some(fb)) = (
        feature(a, pose_a, pieces[0], normal),
        feature(b, pose_b, pieces[1], &-normal),
    ) else {
        return false;
    };
    match (fa, fb) {
        (Feature::Point, _) | (_, Feature::Point) => false,
        (Feature::Line(u), Feature::Line(v)) => u.cross(&v).norm() < FLAT,
        _ => true,
    }
}

/// The shape of a supporting feature.
#[derive(Clone, Copy, Debug)]
enum Feature {
    Point,
    /// An edge, along this unit vector.
    Line(Vector3<f64>),
    Face,
}

/// The feature of piece `piece` of `shape` (at `pose`) farthest along
/// `dir`; `None` when there is no such piece.
fn feature(
    shape: &Shape,
    pose: &Isometry3<f64>,
    piece: u32,
    dir: &Vector3<f64>,
) -> Option<Feature> {
    let (convex, pose) = match shape {
        Shape::Convex(c) => (c, *pose),
        Shape::Compound(c) => {
            let (offset, convex) = c.pieces().get(piece as usize)?;
            (convex, pose * offset)
        }
    };
    Some(convex_feature(convex, &pose, dir))
}

fn convex_feature(convex: &Convex, pose: &Isometry3<f64>, dir: &Vector3<f64>) -> Feature {
    let n = dir.normalize();
    let t1 = n
        .cross(&Vector3::x())
        .try_normalize(0.1)
        .unwrap_or_else(|| n.cross(&Vector3::y()).normalize());
    let t2 = n.cross(&t1);
    let at = |d: Vector3<f64>| convex.support(pose, &d).point;
    let centre = at(n);
    let scale = FLAT * (convex.size() + convex.radius()).max(f64::MIN_POSITIVE);
    let mut first: Option<Vector3<f64>> = None;
    for tip in [t1, -t1, t2, -t2] {
        let jump = at(n + tip * TIP) - centre;
        let jump = jump - n * n.dot(&jump);
        if jump.norm() <= scale {
            continue;
        }
        match first {
            None => first = Some(jump.normalize()),
            Some(u) if (jump - u * u.dot(&jump)).norm() > scale => return Feature::Face,
            Some(_) => {}
        }
    }
    first.map_or(Feature::Point, Feature::Line)
}
