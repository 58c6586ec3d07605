//! Dense sampling of a motion for its first pose within a distance, with
//! samples skipped only where a certified bound already decides them.
//!
//! The continuous-path tests judge the server against the brute-force
//! distance at thousands of evenly spaced poses a segment. Far from contact
//! most of those evaluations only confirm what the last one implies: no
//! point of a body moves farther between two poses than
//! [`displacement`] says, so a distance `d` measured at one sample stays
//! above `d - moved` at every later one. [`first_within`] skips a sample
//! exactly when that bound already puts it above the threshold, and
//! measures every other sample: the first sample at or below the threshold
//! is the one a plain scan of every sample finds.

use nalgebra::Isometry3;

/// An upper bound on how far any point within `reach` of the body origin
/// moves between poses `a` and `b`: the translation's length plus the
/// rotation's, `‖R_a − R_b‖ ≤ 2 min(|q_a − q_b|, |q_a + q_b|)` (the
/// quaternions' chord, which loses no accuracy at small angles as an angle
/// from `acos` would).
pub fn displacement(a: &Isometry3<f64>, b: &Isometry3<f64>, reach: f64) -> f64 {
    let (qa, qb) = (a.rotation.coords, b.rotation.coords);
    let chord = (qa - qb).norm().min((qa + qb).norm());
    (a.translation.vector - b.translation.vector).norm() + 2.0 * chord * reach
}

/// The first of the samples `s = i / count`, `i` in `0..=count`, at which
/// one of `pairs` pairs is at or below `threshold`, or `None`.
///
/// `poses(s)` places the moving bodies; `moved(j, a, b)` bounds from above
/// how much pair `j`'s distance can change between placements `a` and `b`
/// (the [`displacement`] of its moving body against a still one, the sum of
/// both when both move); `distance(j, p)` is pair `j`'s distance at `p`, or
/// a lower bound of it that is the distance itself wherever either is at or
/// below `threshold` (a pair a bounding-sphere test leaves out may give its
/// spheres' gap). A pair is skipped at a sample when its last measured
/// distance less what moved since stays above `threshold + slack`; `slack`
/// covers the round-off of the distance and of the bound.
pub fn first_within<P: Clone>(
    count: usize,
    threshold: f64,
    slack: f64,
    pairs: usize,
    poses: impl Fn(f64) -> P,
    moved: impl Fn(usize, &P, &P) -> f64,
    mut distance: impl FnMut(usize, &P) -> f64,
) -> Option<f64> {
    let mut last: Vec<Option<(P, f64)>> = vec![None; pairs];
    for i in 0..=count {
        let s = i as f64 / count as f64;
        let p = poses(s);
        for (j, last) in last.iter_mut().enumerate() {
            if let Some((at, d)) = last
                && *d - moved(j, at, &p) > threshold + slack
            {
                continue;
            }
            let d = distance(j, &p);
            if d <= threshold {
                return Some(s);
            }
            *last = Some((p.clone(), d));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::Rng;
    use nalgebra::{Point3, UnitQuaternion};

    #[test]
    fn displacement_bounds_every_point_it_covers() {
        let mut rng = Rng::new(0x2545_f491_4f6c_dd1d);
        for k in 0..2_000 {
            // Small turns as often as large ones: the chord must hold at both.
            let angle = if k % 2 == 0 { 1e-7 } else { 3.0 };
            let mut pose = |turn: f64| {
                let axis = rng.direction() * rng.uniform(0.0, turn);
                Isometry3::from_parts(
                    (rng.direction() * rng.unit_interval()).into(),
                    UnitQuaternion::from_scaled_axis(axis),
                )
            };
            let a = pose(3.0);
            let b = a * pose(angle);
            let p = Point3::from(rng.direction() * rng.uniform(0.0, 2.0));
            let reach = p.coords.norm();
            let moved = (a * p - b * p).norm();
            assert!(
                moved <= displacement(&a, &b, reach) * (1.0 + 1e-12) + 1e-15,
                "{moved} > {}",
                displacement(&a, &b, reach)
            );
        }
    }

    #[test]
    fn skipping_finds_the_sample_a_full_scan_finds() {
        // A point moving along x to x = 1.125 and back.
        let x = |s: f64| 3.0 * s * (1.0 - s) * 1.5;
        let poses = |s: f64| Isometry3::translation(x(s), 0.0, 0.0);
        let moved = |_: usize, a: &Isometry3<f64>, b: &Isometry3<f64>| displacement(a, b, 0.0);
        // Two walls, at x = 1 and x = 1.1: the nearer decides.
        let wall = |j: usize, p: &Isometry3<f64>| (1.0 + 0.1 * j as f64 - p.translation.x).abs();
        for threshold in [-0.2, 0.0, 0.05, 0.3, 0.9] {
            let full = (0..=1000)
                .map(|i| f64::from(i) / 1000.0)
                .find(|&s| wall(0, &poses(s)).min(wall(1, &poses(s))) <= threshold);
            let mut measured = 0;
            let skipped = first_within(1000, threshold, 1e-12, 2, poses, moved, |j, p| {
                measured += 1;
                wall(j, p)
            });
            assert_eq!(skipped, full, "threshold {threshold}");
            assert!(measured < 2000, "{measured} measured at {threshold}");
        }
    }
}
