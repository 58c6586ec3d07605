//! The scene of `gjkd bench scene-robot`: a 7-link arm of capsules, boxes
//! and polytopes moving along a joint path among obstacles (boxes, balls and
//! polytopes of 8 to 64 vertices), each shape available both as a gjkd
//! [`Geometry`] and as the parry3d-f64 shape a parry user would pick.
//!
//! The arm is a chain of seven revolute joints alternating about z and y,
//! each link a convex body along its joint's z axis; its link poses come
//! from the few lines of forward kinematics in [`Arm::link_poses`], so that
//! gjkd and parry are handed exactly the same poses.
//!
//! Obstacles are scattered over a large floor, a share of them around the
//! arm, and any that the arm's links could touch along the path (by
//! bounding volumes, at every step) is drawn again: the arm never collides,
//! and a handful of obstacles come within a few centimetres of it.

use gjkd_client::Geometry;
use gjkd_testkit::sweep::Rng;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::math::Vector as PVector;
use parry3d_f64::shape::{Ball, Capsule, ConvexPolyhedron, Cuboid, Shape as ParryShape};

use crate::BenchError;

/// A convex body, owned, in its body frame (centred on its origin).
#[derive(Clone, Debug)]
pub enum Body {
    /// A ball.
    Sphere(f64),
    /// A capsule along z: half length of its segment, radius.
    Capsule(f64, f64),
    /// A box: half extents.
    Cuboid(Vector3<f64>),
    /// The hull of these points (every one a hull vertex).
    Polytope(Vec<Point3<f64>>),
}

impl Body {
    /// As a gjkd geometry.
    pub fn geometry(&self) -> Geometry<'_> {
        match self {
            Body::Sphere(r) => Geometry::Sphere { radius: *r },
            Body::Capsule(h, r) => Geometry::Capsule {
                a: Point3::new(0.0, 0.0, -h),
                b: Point3::new(0.0, 0.0, *h),
                radius: *r,
            },
            Body::Cuboid(h) => Geometry::Cuboid {
                half_extents: *h,
                radius: 0.0,
            },
            Body::Polytope(v) => Geometry::Polytope {
                vertices: v,
                radius: 0.0,
            },
        }
    }

    /// As the parry shape a parry user would pick: `Ball`, `Capsule`,
    /// `Cuboid`, `ConvexPolyhedron::from_convex_hull`.
    ///
    /// # Errors
    /// When parry cannot build the hull.
    pub fn parry(&self) -> Result<Box<dyn ParryShape>, BenchError> {
        Ok(match self {
            Body::Sphere(r) => Box::new(Ball::new(*r)),
            Body::Capsule(h, r) => Box::new(Capsule::new_z(*h, *r)),
            Body::Cuboid(h) => Box::new(Cuboid::new(PVector::new(h.x, h.y, h.z))),
            Body::Polytope(v) => {
                let pts: Vec<PVector> = v.iter().map(|p| PVector::new(p.x, p.y, p.z)).collect();
                Box::new(
                    ConvexPolyhedron::from_convex_hull(&pts)
                        .ok_or_else(|| BenchError::Other("parry could not build a hull".into()))?,
                )
            }
        })
    }

    /// A capsule about the body's z axis holding the body: the half length
    /// of its segment and its radius.
    pub fn bounding_capsule(&self) -> (f64, f64) {
        match self {
            Body::Capsule(h, r) => (*h, *r),
            Body::Cuboid(h) => (h.z, h.xy().norm()),
            _ => (0.0, self.bounding_radius()),
        }
    }

    /// As a gjk convex body.
    ///
    /// # Errors
    /// The algorithm's, for a degenerate body.
    pub fn gjk(&self) -> Result<gjk::Convex, gjk::Error> {
        match self {
            Body::Sphere(r) => gjk::Convex::sphere(*r),
            Body::Capsule(h, r) => {
                gjk::Convex::capsule(Point3::new(0.0, 0.0, -h), Point3::new(0.0, 0.0, *h), *r)
            }
            Body::Cuboid(h) => gjk::Convex::cuboid(*h, 0.0),
            Body::Polytope(v) => gjk::Convex::new(v.clone(), 0.0),
        }
    }

    /// Radius of a ball about the body origin holding the body.
    pub fn bounding_radius(&self) -> f64 {
        match self {
            Body::Sphere(r) => *r,
            Body::Capsule(h, r) => h + r,
            Body::Cuboid(h) => h.norm(),
            Body::Polytope(v) => v.iter().map(|p| p.coords.norm()).fold(0.0, f64::max),
        }
    }
}

/// Points on an ellipsoid's surface with these semi-axes, turned by a
/// random rotation: every point is a vertex of their hull.
fn ellipsoid_points(rng: &mut Rng, n: usize, axes: Vector3<f64>) -> Vec<Point3<f64>> {
    let turn = rng.rotation();
    (0..n)
        .map(|_| {
            let d = rng.direction();
            Point3::from(turn * d.component_mul(&axes))
        })
        .collect()
}

/// The arm: seven links, link `i` turning about z (even `i`) or y (odd
/// `i`) at the end of link `i - 1`, and reaching `length` along its z axis.
pub struct Arm {
    /// Each link's body (centred half way along the link) and length.
    pub links: Vec<(Body, f64)>,
    /// Height of the first joint above the floor.
    pub base: f64,
}

impl Arm {
    /// The benchmark's arm: capsules, boxes and two polytopes.
    pub fn new() -> Self {
        let mut rng = Rng::new(7);
        let links = vec![
            (Body::Capsule(0.15, 0.07), 0.30),
            (Body::Cuboid(Vector3::new(0.055, 0.055, 0.15)), 0.30),
            (Body::Capsule(0.14, 0.055), 0.28),
            (Body::Cuboid(Vector3::new(0.045, 0.045, 0.125)), 0.25),
            (Body::Capsule(0.10, 0.045), 0.20),
            (
                Body::Polytope(ellipsoid_points(
                    &mut rng,
                    24,
                    Vector3::new(0.05, 0.05, 0.06),
                )),
                0.12,
            ),
            (
                Body::Polytope(ellipsoid_points(
                    &mut rng,
                    16,
                    Vector3::new(0.08, 0.03, 0.05),
                )),
                0.10,
            ),
        ];
        Arm { links, base: 0.1 }
    }

    /// The arm's size: the distance its outstretched chain reaches from
    /// the floor (the margin of the benchmark's *within* is a share of it).
    pub fn size(&self) -> f64 {
        self.base + self.links.iter().map(|(_, l)| l).sum::<f64>()
    }

    /// Every link's pose (its body's frame) at joint positions `q`.
    pub fn link_poses(&self, q: &[f64; 7], out: &mut Vec<Isometry3<f64>>) {
        out.clear();
        let mut frame = Isometry3::translation(0.0, 0.0, self.base);
        for (i, ((_, length), &angle)) in self.links.iter().zip(q).enumerate() {
            let axis = if i % 2 == 0 {
                Vector3::z_axis()
            } else {
                Vector3::y_axis()
            };
            frame *= UnitQuaternion::from_axis_angle(&axis, angle);
            out.push(frame * Translation3::new(0.0, 0.0, length / 2.0));
            frame *= Translation3::new(0.0, 0.0, *length);
        }
    }
}

impl Default for Arm {
    fn default() -> Self {
        Self::new()
    }
}

/// The joint path at `t` in [0, 1]: the arm swings round and reaches out
/// and down, as the demo arm's path.
pub fn joint_path(t: f64) -> [f64; 7] {
    crate::robot_demo::joint_path(t)
}

/// The obstacles: bodies and fixed poses.
pub struct Obstacles {
    /// Each obstacle's body and pose.
    pub bodies: Vec<(Body, Isometry3<f64>)>,
}

/// One obstacle's body: a box, a ball or a polytope of 8 to 64 vertices,
/// in turn, 3 to 20 cm across each way.
fn obstacle_body(rng: &mut Rng, i: usize) -> Body {
    let mut size = || rng.uniform(0.03, 0.2);
    match i % 3 {
        0 => Body::Cuboid(Vector3::new(size(), size(), size())),
        1 => Body::Sphere(size()),
        _ => {
            let axes = Vector3::new(size(), size(), size());
            let n = 8 + rng.below(57);
            Body::Polytope(ellipsoid_points(rng, n, axes))
        }
    }
}

impl Obstacles {
    /// `count` obstacles: a tenth around the arm (0.3 to 1.9 m from its
    /// axis), the rest over a 20 m × 20 m floor up to 4 m high; none whose
    /// bounding sphere meets a link's bounding capsule at any of the path's
    /// `steps` steps.
    pub fn new(arm: &Arm, count: usize, steps: usize, seed: u64) -> Self {
        let mut rng = Rng::new(seed);
        // Each link's bounding capsule at every step: its segment's ends
        // and radius.
        let mut capsules = Vec::with_capacity(steps * arm.links.len());
        let mut poses = Vec::new();
        for s in 0..steps {
            arm.link_poses(&joint_path(s as f64 / steps as f64), &mut poses);
            for (p, (body, _)) in poses.iter().zip(&arm.links) {
                let (h, r) = body.bounding_capsule();
                let a = p * Point3::new(0.0, 0.0, -h);
                let b = p * Point3::new(0.0, 0.0, h);
                capsules.push((a.coords, b.coords, r));
            }
        }
        let near = count / 10;
        let mut bodies = Vec::with_capacity(count);
        while bodies.len() < count {
            let i = bodies.len();
            let body = obstacle_body(&mut rng, i);
            let centre = if i < near {
                let (s, c) = rng.uniform(0.0, std::f64::consts::TAU).sin_cos();
                let r = rng.uniform(0.3, 1.9);
                Vector3::new(r * c, r * s, rng.uniform(0.0, 1.8))
            } else {
                Vector3::new(
                    rng.uniform(-10.0, 10.0),
                    rng.uniform(-10.0, 10.0),
                    rng.uniform(0.0, 4.0),
                )
            };
            let reach = body.bounding_radius();
            let clear = capsules
                .iter()
                .all(|(a, b, r)| segment_distance(a, b, &centre) > r + reach);
            if clear {
                let pose = Isometry3::from_parts(centre.into(), rng.rotation());
                bodies.push((body, pose));
            }
        }
        Obstacles { bodies }
    }
}

/// Distance from `p` to the segment from `a` to `b`.
fn segment_distance(a: &Vector3<f64>, b: &Vector3<f64>, p: &Vector3<f64>) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
    (a + ab * t - p).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn link_poses_chain_the_links_end_to_end() {
        let arm = Arm::new();
        let mut poses = Vec::new();
        arm.link_poses(&[0.0; 7], &mut poses);
        // Straight up: link i's centre is at the base plus the lengths
        // below it plus half its own.
        let mut z = arm.base;
        for (p, (_, l)) in poses.iter().zip(&arm.links) {
            assert!((p.translation.vector - Vector3::new(0.0, 0.0, z + l / 2.0)).norm() < 1e-12);
            z += l;
        }
        assert!((z - arm.size()).abs() < 1e-12);
        // Turning joint 2 (about y) by 90° lays everything above it flat.
        let mut q = [0.0; 7];
        q[1] = std::f64::consts::FRAC_PI_2;
        arm.link_poses(&q, &mut poses);
        let top = poses[6] * Point3::new(0.0, 0.0, arm.links[6].1 / 2.0);
        let lifted = arm.base + arm.links[0].1;
        assert!((top.z - lifted).abs() < 1e-12);
        assert!((top.x - (arm.size() - lifted)).abs() < 1e-12);
    }

    #[test]
    fn obstacles_keep_clear_of_the_arm_and_some_are_near() {
        let arm = Arm::new();
        let obstacles = Obstacles::new(&arm, 1000, 50, 1);
        assert_eq!(obstacles.bodies.len(), 1000);
        let mut poses = Vec::new();
        let mut nearest = f64::INFINITY;
        for s in 0..50 {
            arm.link_poses(&joint_path(s as f64 / 50.0), &mut poses);
            for (p, (link, _)) in poses.iter().zip(&arm.links) {
                let (h, r) = link.bounding_capsule();
                let a = (p * Point3::new(0.0, 0.0, -h)).coords;
                let b = (p * Point3::new(0.0, 0.0, h)).coords;
                for (body, pose) in &obstacles.bodies {
                    let gap = segment_distance(&a, &b, &pose.translation.vector)
                        - r
                        - body.bounding_radius();
                    assert!(gap > 0.0);
                    nearest = nearest.min(gap);
                }
            }
        }
        assert!(nearest < 0.1, "nearest bounding-volume gap {nearest}");
    }

    #[test]
    fn polytope_points_are_all_hull_vertices_for_parry() {
        let mut rng = Rng::new(3);
        for i in 0..30 {
            let body = obstacle_body(&mut rng, 3 * i + 2);
            let Body::Polytope(v) = &body else {
                panic!("not a polytope")
            };
            assert!((8..=64).contains(&v.len()));
            let hull = body.parry().unwrap();
            let hull = hull.as_convex_polyhedron().unwrap();
            assert_eq!(hull.points().len(), v.len());
        }
    }
}
