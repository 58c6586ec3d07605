//! What a signed-distance query returns: [`SignedDistance`].

use nalgebra::{Point3, Vector3};

/// The signed distance between two shapes: their distance when apart,
/// minus the penetration depth (the shortest translation that separates
/// them) when they overlap; for unions, the least over piece pairs.
///
/// Always `point_b - point_a = value · normal` (up to round-off): moving B
/// along `normal` increases the value at unit rate.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SignedDistance {
    /// The signed distance: `> 0` apart, `< 0` overlapping, `0` touching.
    pub value: f64,
    /// Certified lower bound on the true signed distance.
    pub lower: f64,
    /// Certified upper bound on the true signed distance.
    pub upper: f64,
    /// A's witness point, in world coordinates: the nearest point when
    /// apart, the deepest point of A inside B along `normal` when
    /// overlapping.
    pub point_a: Point3<f64>,
    /// B's witness point, in world coordinates.
    pub point_b: Point3<f64>,
    /// Unit vector, in world coordinates, along which B moves away from A
    /// fastest: from A's nearest point towards B's when apart, the
    /// direction of the shortest separating translation of B when
    /// overlapping.
    pub normal: Vector3<f64>,
    /// `[piece of A, piece of B]` that realise the value (`[0, 0]` for two
    /// convex shapes).
    pub pieces: [u32; 2],
    /// Support points the expanding polytope added (0 when apart).
    pub expansions: u32,
    /// Whether the stopping rule held: the distance query's, or the
    /// expansion's tolerance. The interval holds either way.
    pub converged: bool,
    /// Overlapping: another direction, more than about a milliradian from
    /// `normal`, separates the shapes as fast (its support value is within
    /// the interval): the shortest separating translation, hence `normal`
    /// and the witnesses, are not unique (a ball's centre on a box's
    /// medial axis, a box centred in a bigger one, two crossing capsules),
    /// and the signed distance has no gradient here; the answer is one of
    /// its one-sided ones. Also set when the search could not decide.
    /// Always `false` apart: whether nearest points are unique there is a
    /// question of the features that realise them.
    pub tied: bool,
}
