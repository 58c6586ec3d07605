//! Whether the depth's direction is unique: after the expansion met its
//! tolerance on one face, whether `K`'s support value reaches the same
//! least value (within the certified interval) along a direction far from
//! that face's normal too. Then the shortest separating translation is
//! not unique (a ball's centre on a box's medial axis, a box centred in a
//! bigger one, two crossing segments), and the signed distance has no
//! gradient there.
//!
//! Why the search looks only at faces whose plane passes within the
//! interval: the polytope lies inside `K`, so along a tied direction `m`
//! the ray from the origin leaves the polytope no farther out than
//! `h_K(m)`, through a face whose plane is then at most that far. Each such
//! face is either proved a tie (the support value along its own normal is
//! within the interval) or grown by its support point until its plane
//! passes beyond the interval.

use nalgebra::Vector3;

use super::frame::PairFrame;
use super::polytope::{Face, Polytope};
use crate::support_map::SupportMap;

/// Two unit normals less than this far apart (in radians, about) are one
/// direction: on a round `K`, the faces next to the converged one have
/// normals that differ from it by about the square root of the
/// tolerance, and their support values are within the interval.
pub(super) const TIE_ANGLE: f64 = 1e-3;

/// The most support points the search adds: a tied direction on a
/// polytope `K` is a face of `K` that a few points complete; a round `K`
/// refines the faces near the interval's edge, and a search that has not
/// decided by then reports a tie (the one-sided answer, not a wrong one).
const TIE_POINTS: usize = 48;

/// Whether some direction more than [`TIE_ANGLE`] from `nearest`'s normal
/// has a support value of `K` at most `bound` (the interval's upper end
/// with the tolerance's room), growing `polytope` (at most `max_points`
/// points) to decide.
pub(super) fn tied<A: SupportMap, B: SupportMap>(
    frame: &PairFrame<'_, A, B>,
    polytope: &mut Polytope,
    nearest: &Face,
    bound: f64,
    max_points: usize,
) -> bool {
    let Some(n0) = nearest.unit_normal() else {
        return false;
    };
    let limit = max_points.min(polytope.points.len() + TIE_POINTS);
    loop {
        let candidate = polytope
            .faces()
            .iter()
            .copied()
            .find(|f| f.distance <= bound && f.unit_normal().is_some_and(|n| far(&n, &n0)));
        let Some(face) = candidate else {
            return false;
        };
        let Some(n) = face.unit_normal() else {
            return false;
        };
        let w = frame.support(&n);
        // The point errs by `delta`, the product by a few ε of `|w|`:
        // a value that may be within the bound counts as a tie.
        let h = n.dot(&w.y) - frame.delta - 8.0 * f64::EPSILON * w.y.norm();
        if h <= bound {
            return true;
        }
        if polytope.points.len() >= limit || !polytope.add(w, &face) {
            // Undecided: a face within the interval that could not be
            // grown past it.
            return true;
        }
    }
}

/// Whether unit vectors `n` and `m` are more than [`TIE_ANGLE`] apart.
pub(super) fn far(n: &Vector3<f64>, m: &Vector3<f64>) -> bool {
    (n - m).norm() > TIE_ANGLE
}
