//! A seed for an answer on a cylinder's cap, in closed form.
//!
//! Where the nearest point of a cylinder lies inside one of its caps, the
//! answer's direction is the cap's axis, where the rim's curvature
//! `r / |u_xy|` is unbounded: Newton's steps (see `seed`) cannot
//! converge there, and the plain run closes in on the disk one rim point an
//! iteration. The cap needs no iteration: along the axis the other shape's
//! support point `q` is known, and when `q` lies beyond the cap's plane and
//! projects inside its disk, the projection and `q` are a pair of points
//! whose distance equals the separation of the two shapes' projections on
//! the axis, so it is the distance. The seed is three points of the cap
//! around the projection (its centre and two rim points) against `q`, from
//! which the run's first iteration certifies the bounds as for any start;
//! when the test fails the seed is not given and nothing is lost.

use nalgebra::Vector3;

use crate::query::pair::{ConvexPair, rotate, rotate_back};
use crate::shape::cylinder;
use crate::support_map::SupportMap;

/// How near the rim (as a share of the radius) a projection may come and
/// still be seeded from the cap: nearer, the answer is on the rim, and the
/// triangle around the projection too thin to be worth it.
const RIM_MARGIN: f64 = 1e-6;

impl<A: SupportMap, B: SupportMap> ConvexPair<'_, A, B> {
    /// The seed of an answer on cylinder `k`'s cap (0 for A, 1 for B)
    /// that faces A's support direction `u` (pair frame, any length): `None`
    /// when shape `k` is no cylinder, `u` is perpendicular to its axis, or
    /// the other shape's support point along the axis is not beyond the cap
    /// or does not project inside it.
    pub(super) fn cap_seed(&self, k: usize, u: &Vector3<f64>) -> Option<[[u32; 2]; 3]> {
        let (r, h) = self.cylinder_at(k)?;
        let (r, h) = (r * self.scale, h * self.scale);
        let pairs = if k == 0 {
            let side = axis_sign(u.z)?;
            // B's support against A's cap: at -side·z in the pair frame.
            let d_b = rotate_back(&self.rotation, &Vector3::new(0.0, 0.0, -side));
            let (ib, point) = self.b.local_support(&d_b);
            let q = rotate(&self.rotation, &point) * self.scale + self.centroid_gap;
            let [c, p1, p2] = cap_triangle(&q, side, r, h)?;
            let ib = ib as u32;
            [[c, ib], [p1, ib], [p2, ib]]
        } else {
            // B's support direction is -u; its body frame's.
            let d_b = -rotate_back(&self.rotation, u);
            let side = axis_sign(d_b.z)?;
            let axis = rotate(&self.rotation, &Vector3::new(0.0, 0.0, side));
            let (ia, point) = self.a.local_support(&-axis);
            let q = rotate_back(&self.rotation, &(point * self.scale - self.centroid_gap));
            let [c, p1, p2] = cap_triangle(&q, side, r, h)?;
            let ia = ia as u32;
            [[ia, c], [ia, p1], [ia, p2]]
        };
        Some(pairs)
    }
}

/// The sign of an axis component, `None` at zero or NaN.
fn axis_sign(z: f64) -> Option<f64> {
    if z > 0.0 {
        Some(1.0)
    } else if z < 0.0 {
        Some(-1.0)
    } else {
        None
    }
}

/// The codes of three points of the cap at `side` (±1) of the cylinder of
/// radius `r` and half-height `h` whose triangle holds the projection of
/// `q` (the cylinder's body frame, scaled with `r` and `h`): the cap's
/// centre and the rim points at `±α` about the projection's angle, with
/// `cos α` halfway between the projection's share of the radius and 1, so
/// that the projection lies inside by a margin. `None` unless `q` lies
/// beyond the cap's plane and projects inside the disk.
fn cap_triangle(q: &Vector3<f64>, side: f64, r: f64, h: f64) -> Option<[u32; 3]> {
    let rho2 = q.x * q.x + q.y * q.y;
    let limit = r * (1.0 - RIM_MARGIN);
    // False for NaN too.
    let held = side * q.z > h && rho2 < limit * limit;
    if !held {
        return None;
    }
    let rho = rho2.sqrt();
    let (cx, sy) = if rho > 0.0 {
        (q.x / rho, q.y / rho)
    } else {
        (1.0, 0.0)
    };
    let cos = 0.5 * (1.0 + rho / r);
    let sin = (1.0 - cos * cos).sqrt();
    let code = |x: f64, y: f64| cylinder::support_code(&Vector3::new(x, y, side));
    Some([
        code(0.0, 0.0),
        code(cx * cos - sy * sin, sy * cos + cx * sin),
        code(cx * cos + sy * sin, sy * cos - cx * sin),
    ])
}

#[cfg(test)]
mod tests {
    use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

    use crate::johnson::Simplex;
    use crate::query::numerical_algorithm::RunOutcome;
    use crate::query::pair::{ConvexPair, PiecePlacement};
    use crate::shape::test_rng::Rng;
    use crate::{Convex, Options, Precision};

    /// The pair of `a` at the identity and `b` at `pose`.
    fn pair<'s>(a: &'s Convex, b: &'s Convex, pose: &Isometry3<f64>) -> ConvexPair<'s> {
        let id = Isometry3::identity();
        let place = |pose| PiecePlacement { pose, offset: None };
        ConvexPair::new(a, b, pose, (place(&id), place(pose)), Precision::Double)
    }

    /// The run of `pair` from `warm` (cold without).
    fn run(pair: &ConvexPair<'_>, warm: Option<&[[u32; 2]]>) -> RunOutcome {
        let mut simplex = Simplex::empty();
        pair.solve::<false>(&mut simplex, &Options::default(), warm, f64::INFINITY)
    }

    /// The lowest point of `shape` at `pose` along the world's z, by its
    /// vertices for a polytope and by the closed form `c_z - h·|R_zz| -
    /// r·|(R_zx, R_zy)|` for a cylinder.
    fn lowest(shape: &Convex, pose: &Isometry3<f64>) -> Point3<f64> {
        let Some((r, h)) = shape.cylinder_dimensions() else {
            return shape
                .vertices()
                .iter()
                .map(|p| pose * p)
                .min_by(|p, q| p.z.total_cmp(&q.z))
                .unwrap();
        };
        let m = pose.rotation.to_rotation_matrix();
        let row = Vector3::new(m[(2, 0)], m[(2, 1)], m[(2, 2)]);
        let rim = if row.x.hypot(row.y) > 0.0 {
            -Vector3::new(row.x, row.y, 0.0).normalize() * r
        } else {
            Vector3::zeros()
        };
        pose * Point3::from(rim - Vector3::z() * (h * row.z.signum()))
    }

    /// Shapes above A's top cap whose lowest point projects inside it: the
    /// cap seed is given, its run certifies in one iteration, and its
    /// bounds hold the closed-form distance (the lowest point's height
    /// over the cap); the same with the roles swapped (B's cap facing A),
    /// at sizes 1e-9 to 1e6.
    #[test]
    fn cap_answers_certify_from_the_seed_in_one_iteration() {
        let mut rng = Rng(0x5eed_ca95_eed0_0001);
        let mut checked = 0;
        for scale in [1e-9, 1.0, 1e6] {
            let a = Convex::cylinder(0.5 * scale, 0.8 * scale, 0.0).unwrap();
            let cylinder = Convex::cylinder(0.3 * scale, 0.2 * scale, 0.0).unwrap();
            let cuboid = Convex::cuboid(Vector3::new(0.2, 0.1, 0.15) * scale, 0.0).unwrap();
            for k in 0..300 {
                let b = if k % 2 == 0 { &cylinder } else { &cuboid };
                let tilt = UnitQuaternion::from_euler_angles(
                    rng.next() * 0.4,
                    rng.next() * 0.4,
                    rng.next() * 3.0,
                );
                let shift = Vector3::new(rng.next() * 0.2, rng.next() * 0.2, 1.6 + rng.next());
                let pose = Isometry3::from_parts(Translation3::from(shift * scale), tilt);
                let low = lowest(b, &pose);
                if low.x.hypot(low.y) >= 0.49 * scale || low.z <= 0.81 * scale {
                    continue;
                }
                let truth = low.z - 0.8 * scale;
                let tol = 1e-12 * scale;
                // A's cap against B's lowest point, then B's cap against A:
                // A's pose is the inverse, and the pair is swapped.
                let inverse = pose.inverse();
                let (forward, swapped) = (pair(&a, b, &pose), pair(b, &a, &inverse));
                for (which, pair, cap) in [(0, &forward, 0), (1, &swapped, 1)] {
                    let u = if cap == 0 {
                        Vector3::z()
                    } else {
                        inverse.rotation * -Vector3::z()
                    };
                    let pairs = pair
                        .cap_seed(cap, &u)
                        .unwrap_or_else(|| panic!("{scale:e} pose {k} {which}: no seed"));
                    let seeded = run(pair, Some(&pairs));
                    let cold = run(pair, None);
                    assert_eq!(seeded.iterations, 1, "{scale:e} pose {k} {which}");
                    for r in [&seeded, &cold] {
                        assert!(
                            r.lower - tol <= truth && truth <= r.norm + tol,
                            "{scale:e} pose {k} {which}: [{:e}, {:e}] against {truth:e}",
                            r.lower,
                            r.norm
                        );
                        assert!((r.norm - truth).abs() <= 1e-12 * scale);
                    }
                    // And from the warm start its answer keeps.
                    assert_eq!(run(pair, Some(&pairs)).iterations, 1);
                }
                checked += 1;
            }
        }
        assert!(checked > 300, "{checked}");
    }

    /// No cap seed where the cap does not hold the answer: the other
    /// shape's point beyond the rim, below the cap's plane, or a direction
    /// perpendicular to the axis; and none for a shape that is no
    /// cylinder.
    #[test]
    fn no_cap_seed_where_the_cap_cannot_hold_the_answer() {
        let a = Convex::cylinder(0.5, 0.8, 0.0).unwrap();
        let b = Convex::cuboid(Vector3::new(0.2, 0.1, 0.15), 0.0).unwrap();
        let up = Vector3::z();
        let beside = Isometry3::translation(0.8, 0.0, 1.5);
        assert!(pair(&a, &b, &beside).cap_seed(0, &up).is_none());
        // The box's support along -z is its (-, -, -) corner: within the
        // radius but for the rim margin, then inside by a hundredth.
        let edge = Isometry3::translation(0.7 - 5e-8, 0.1, 1.5);
        assert!(pair(&a, &b, &edge).cap_seed(0, &up).is_none());
        let inside = Isometry3::translation(0.69, 0.1, 1.5);
        assert!(pair(&a, &b, &inside).cap_seed(0, &up).is_some());
        let below = Isometry3::translation(0.0, 0.0, 0.9);
        assert!(pair(&a, &b, &below).cap_seed(0, &up).is_none());
        let above = Isometry3::translation(0.0, 0.0, 1.5);
        let p = pair(&a, &b, &above);
        assert!(p.cap_seed(0, &Vector3::x()).is_none());
        assert!(p.cap_seed(1, &up).is_none());
        assert!(p.cap_seed(0, &-up).is_none());
    }
}
