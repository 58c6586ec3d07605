//! Exact volumes and weights, and the round-off of a face's distance, that
//! the simplex's refinements and the penetration bound share.

use nalgebra::Vector3;

/// The barycentric weights of `q` in the triangle `y` (`q` in its plane,
/// or its projection otherwise: the 2×2 normal equations of the first
/// corner's edges), `None` for a triangle too thin for them.
#[inline]
pub(crate) fn triangle_weights(y: [Vector3<f64>; 3], q: &Vector3<f64>) -> Option<[f64; 3]> {
    let (e1, e2, w) = (y[1] - y[0], y[2] - y[0], q - y[0]);
    let (g11, g12, g22) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
    let det = g11 * g22 - g12 * g12;
    // Also refuses a NaN, which fails every comparison.
    if det.is_nan() || det <= 1e-24 * g11 * g22 {
        return None;
    }
    let (r1, r2) = (w.dot(&e1), w.dot(&e2));
    let (s, t) = ((r1 * g22 - r2 * g12) / det, (g11 * r2 - g12 * r1) / det);
    Some([1.0 - s - t, s, t])
}

/// The signed volume of the tetrahedron `y` with the origin in place of
/// vertex `l`, det(q1 - q0, q2 - q0, q3 - q0), with its sign exact (Shewchuk's
/// adaptive predicate): the float volumes' own orientation, since
/// orient3d(pa, pb, pc, pd) is det(pa - pd, pb - pd, pc - pd).
pub(super) fn exact_volume_without(y: &[Vector3<f64>; 4], l: usize) -> f64 {
    let point = |p: Vector3<f64>| robust::Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    };
    let mut q = *y;
    q[l] = Vector3::zeros();
    robust::orient3d(point(q[1]), point(q[2]), point(q[3]), point(q[0]))
}

/// What round-off `delta` in each point of a face (`m2` the largest squared
/// norm of the points) may do to its plane's distance `|n·p| / |n|` from
/// the origin: `(shrink, widen)`, the most `|n·p|` may move and a bound on
/// how far `|n|²` may grow (see [`Simplex::inner_radius`]), so that
/// `(|n·p| - shrink)² / (|n|² + widen)` never exceeds the true squared
/// distance.
#[inline]
pub(crate) fn face_round_off(delta: f64, m2: f64) -> (f64, f64) {
    let m = m2.sqrt();
    let shrink = delta * (3.0 * m2 + delta * (3.0 * m + delta));
    let widen = 64.0 * delta * m2 * (m + delta);
    (shrink, widen)
}
