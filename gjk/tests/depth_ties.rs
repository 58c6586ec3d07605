//! Whether a penetration depth's direction is unique (`SignedDistance::tied`),
//! on cases whose shortest separating translations are known in closed
//! form: a ball in a box (depth `r + ` the centre's distance to the nearest
//! face, tied when two faces are equally near), a box in a bigger box,
//! crossing capsules (depth the radii's sum along either normal of the
//! cores' plane), concentric and offset balls.

use gjk::{Convex, DepthOptions, Shape, SignedDistance, signed_distance};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// The signed distance of `a` at `pose_a` and `b` at `pose_b`, each also
/// moved by `shift` (far from the world's origin in some cases).
fn sd(a: Convex, pose_a: Isometry3<f64>, b: Convex, pose_b: Isometry3<f64>) -> SignedDistance {
    let (a, b): (Shape, Shape) = (a.into(), b.into());
    signed_distance(&a, &pose_a, &b, &pose_b, &DepthOptions::default()).expect("valid shapes")
}

fn unit_box() -> Convex {
    Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0).expect("box")
}

/// A ball of radius 0.5 with its centre at `c` inside the box `[-1, 1]³`:
/// its depth is `0.5 + ` the centre's distance to the nearest face.
fn ball_in_box(c: Vector3<f64>, frame: Isometry3<f64>) -> (SignedDistance, f64) {
    let depth = 0.5 + (1.0 - c.x.abs()).min(1.0 - c.y.abs()).min(1.0 - c.z.abs());
    let ball = Convex::sphere(0.5).expect("ball");
    let s = sd(
        unit_box(),
        frame,
        ball,
        frame * Isometry3::translation(c.x, c.y, c.z),
    );
    (s, depth)
}

fn assert_depth(s: &SignedDistance, depth: f64) {
    assert_depth_near(s, depth, 0.0);
}

/// As [`assert_depth`], for poses whose world coordinates were rounded
/// at a magnitude `far`: the shapes the query sees are then up to a few
/// ulps of `far` from the ones the closed form describes.
fn assert_depth_near(s: &SignedDistance, depth: f64, far: f64) {
    let slack = 16.0 * f64::EPSILON * far;
    assert!(
        (s.value + depth).abs() <= 1e-9 * depth + slack,
        "{s:?} vs -{depth}"
    );
    assert!(
        s.lower <= -depth + slack && -depth - slack <= s.upper,
        "{s:?} vs -{depth}"
    );
}

#[test]
fn a_ball_on_a_boxs_medial_axis_is_tied_off_it_is_not() {
    let far_away = Isometry3::from_parts(
        Translation3::new(1e3, -2e3, 5e2),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.3, -0.2, 0.7)),
    );
    for frame in [Isometry3::identity(), far_away] {
        let far = frame.translation.vector.norm();
        let assert_depth = |s: &SignedDistance, depth: f64| assert_depth_near(s, depth, far);
        // Equally near the faces x = 1 and y = 1: two shortest ways out.
        let (s, depth) = ball_in_box(Vector3::new(0.5, 0.5, 0.0), frame);
        assert_depth(&s, depth);
        assert!(s.tied, "{s:?}");
        // Three faces equally near (a corner's diagonal).
        let (s, depth) = ball_in_box(Vector3::new(0.4, 0.4, 0.4), frame);
        assert_depth(&s, depth);
        assert!(s.tied, "{s:?}");
        // Nearer the face x = 1 than any other: one way out.
        let (s, depth) = ball_in_box(Vector3::new(0.8, 0.1, 0.0), frame);
        assert_depth(&s, depth);
        assert!(!s.tied, "{s:?}");
        // A millimetre off the axis is far outside the interval: not tied.
        let (s, depth) = ball_in_box(Vector3::new(0.5, 0.499, 0.0), frame);
        assert_depth(&s, depth);
        assert!(!s.tied, "{s:?}");
        let normal = frame.rotation * Vector3::x();
        assert!((s.normal - normal).norm() < 1e-9, "{s:?}");
    }
}

#[test]
fn a_box_centred_in_a_bigger_box_is_tied_off_centre_it_is_not() {
    let small = Convex::cuboid(Vector3::new(0.5, 0.5, 0.5), 0.0).expect("box");
    // Centred: 1.5 out along each of the six axes.
    let s = sd(
        unit_box(),
        Isometry3::identity(),
        small.clone(),
        Isometry3::identity(),
    );
    assert_depth(&s, 1.5);
    assert!(s.tied, "{s:?}");
    // At (0.6, 0.1, 0.05): 0.9 along +x, 1.4 along +y, 1.45 along +z.
    let s = sd(
        unit_box(),
        Isometry3::identity(),
        small,
        Isometry3::translation(0.6, 0.1, 0.05),
    );
    assert_depth(&s, 0.9);
    assert!(!s.tied, "{s:?}");
    assert!((s.normal - Vector3::x()).norm() < 1e-9, "{s:?}");
}

#[test]
fn crossing_capsules_and_concentric_balls_are_tied_offset_balls_are_not() {
    // Cores crossing at the origin: 0.3 + 0.2 out along +z or -z.
    let along_x = Convex::capsule(Point3::new(-1.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0), 0.3)
        .expect("capsule");
    let along_y = Convex::capsule(Point3::new(0.0, -1.0, 0.0), Point3::new(0.0, 1.0, 0.0), 0.2)
        .expect("capsule");
    let s = sd(
        along_x,
        Isometry3::identity(),
        along_y,
        Isometry3::identity(),
    );
    assert_depth(&s, 0.5);
    assert!(s.tied, "{s:?}");
    // Concentric balls: every direction.
    let ball = || Convex::sphere(1.0).expect("ball");
    let s = sd(
        ball(),
        Isometry3::translation(2.0, 0.0, 0.0),
        ball(),
        Isometry3::translation(2.0, 0.0, 0.0),
    );
    assert_depth(&s, 2.0);
    assert!(s.tied, "{s:?}");
    // Offset by 0.3: one direction, along the centres' line.
    let s = sd(
        ball(),
        Isometry3::identity(),
        ball(),
        Isometry3::translation(0.0, 0.3, 0.0),
    );
    assert_depth(&s, 1.7);
    assert!(!s.tied, "{s:?}");
    assert!((s.normal - Vector3::y()).norm() < 1e-9, "{s:?}");
}

#[test]
fn pairs_apart_are_never_tied() {
    let ball = Convex::sphere(0.5).expect("ball");
    let s = sd(
        unit_box(),
        Isometry3::identity(),
        ball,
        Isometry3::translation(2.0, 2.0, 0.0),
    );
    let d = 2f64.sqrt() - 0.5;
    assert!((s.value - d).abs() < 1e-9, "{s:?}");
    assert!(!s.tied, "{s:?}");
}
