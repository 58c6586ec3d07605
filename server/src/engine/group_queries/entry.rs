//! One object as the broadphase indexes it, and how far any of its points
//! can have moved: what the index ([`super::broadphase`]) and the motion
//! bounds ([`super::motion_bound`]) share.

use nalgebra::{Isometry3, Point3};

/// Relative slack on every computed box and sphere, far above the few ulps
/// the arithmetic can lose, so that a box always contains its object.
pub(crate) const ROUND_OFF: f64 = 1e-12;

/// One object in the index.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Entry {
    /// Its id.
    pub id: u64,
    /// Its centroid in its body frame.
    pub centre: Point3<f64>,
    /// The largest distance of any of its points from `centre`, radius
    /// included (an upper bound).
    pub extent: f64,
    /// The largest distance of any of its points from its body origin.
    pub reach: f64,
    /// The centre of its box in its body frame.
    pub local_centre: [f64; 3],
    /// The half-sides of its box in its body frame.
    pub local_half: [f64; 3],
    /// The pose its box was computed at: the stored pose, or a path's.
    pub pose: Isometry3<f64>,
    /// `centre` at `pose`.
    pub world_centre: Point3<f64>,
    /// Its box at `pose`.
    pub mins: [f64; 3],
    /// Its box at `pose`.
    pub maxs: [f64; 3],
    /// Whether the slot holds an object.
    pub live: bool,
    /// Whether `pose` is a path's, not the stored one.
    pub overlaid: bool,
    /// Whether its box waits for the next refit.
    pub(super) queued: bool,
    /// Along a path: the sum of the largest distances any of its points
    /// moved at each of its moves ([`Broadphase::move_along`]), which bounds
    /// how far any point moved between two steps; 0 at stored poses.
    pub travel: f64,
}

/// The largest distance any point of `entry` can have moved from `from`
/// to its index pose, rounded up: the formula of the module plus a
/// relative [`ROUND_OFF`] of every magnitude involved (translations,
/// centroid, extent), which covers the round-off of the arithmetic here and
/// of the rotation matrices the poses stand for.
pub(crate) fn displacement(entry: &Entry, from: &Isometry3<f64>) -> f64 {
    if entry.pose == *from {
        return 0.0;
    }
    displacement_from(entry, from, &(from * entry.centre))
}

/// [`displacement`] from `from`, where the centroid was `from_centre`
/// (computed as `from * entry.centre`).
pub(crate) fn displacement_from(
    entry: &Entry,
    from: &Isometry3<f64>,
    from_centre: &Point3<f64>,
) -> f64 {
    let to = &entry.pose;
    let moved = (entry.world_centre - from_centre).norm();
    let relative = to.rotation * from.rotation.inverse();
    // |imaginary part| of a unit quaternion is sin(theta / 2), for either
    // sign of the quaternion.
    let half_chord = relative.quaternion().imag().norm().min(1.0);
    let turned = 2.0 * half_chord * entry.extent;
    let magnitudes = from.translation.vector.abs().sum()
        + to.translation.vector.abs().sum()
        + entry.centre.coords.abs().sum()
        + entry.extent;
    (moved + turned) * (1.0 + ROUND_OFF) + ROUND_OFF * magnitudes + f64::MIN_POSITIVE
}
