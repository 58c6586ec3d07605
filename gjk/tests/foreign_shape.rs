//! A shape the crate does not have, defined in the tests alone
//! (`shapes/ellipsoid.rs`) and queried through the public API: an ellipsoid `x²/a² + y²/b² + z²/c² <= 1`, whose support
//! function is analytic, `s(d) = A²d / |A d|` with `A = diag(a, b, c)`.
//!
//! Its distances are checked against independent answers: the analytic
//! height above a plane (a large box's face, and a cylinder's cap), and a
//! dense two-parameter minimisation over the surface against a sphere.
//! Every certified interval must hold the truth.

use gjk::{
    Convex, DepthOptions, Error, Options, WarmStart, distance_between, signed_distance_between,
    support_of_difference,
};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

// The ellipsoid and its dense surface distance, shared with the
// compound tests.
#[path = "shapes/ellipsoid.rs"]
mod ellipsoid;

use ellipsoid::{Ellipsoid, surface_distance};

fn rotation(seed: u64) -> UnitQuaternion<f64> {
    // A fixed spread of rotations, no generator needed.
    let t = seed as f64;
    UnitQuaternion::from_euler_angles(0.7 * t + 0.3, 1.3 * t - 0.2, 0.4 * t + 1.1)
}

/// The largest gap a converged answer may leave from the truth here: the
/// tolerance's `ε·D` with room.
const CLOSE: f64 = 1e-9;

#[test]
fn ellipsoid_above_a_box_face_is_its_analytic_height() {
    // The box's top face is the plane z = 0, far wider than the ellipsoid.
    let slab = Convex::cuboid(Vector3::new(100.0, 100.0, 1.0), 0.0).expect("box");
    let slab_pose = Isometry3::translation(0.0, 0.0, -1.0);
    let egg = Ellipsoid::new(1.5, 0.7, 0.4);
    let options = Options::default();
    for seed in 0..40 {
        let r = rotation(seed);
        let height = 2.0 + 0.05 * seed as f64;
        let pose = Isometry3::from_parts(Translation3::new(0.3, -0.2, height), r);
        // The lowest point is the support along -z: its height is the
        // centre's less h(-z) in the body frame.
        let down_in_body = r.inverse_transform_vector(&-Vector3::z());
        let truth = height - egg.support_value(&down_in_body);
        assert!(truth > 0.3, "the poses keep the ellipsoid above the face");
        let answer =
            distance_between(&egg, &pose, &slab, &slab_pose, &options, None).expect("queried");
        assert!(
            (answer.distance - truth).abs() <= CLOSE,
            "seed {seed}: {} against {truth}",
            answer.distance
        );
        assert!(
            answer.lower <= truth && truth <= answer.upper,
            "seed {seed}"
        );
        // The nearest points: B's on the face, A's on the ellipsoid's
        // lowest point, as the query rebuilt it from its index.
        assert!(answer.point_b.z.abs() <= CLOSE, "seed {seed}");
        assert!((answer.point_a.z - truth).abs() <= CLOSE, "seed {seed}");
        let lowest = pose * Point3::from(egg.support_of(&down_in_body));
        assert!((answer.point_a - lowest).norm() <= 1e-4, "seed {seed}");
        // The other way round: the same distance, the points swapped.
        let swapped =
            distance_between(&slab, &slab_pose, &egg, &pose, &options, None).expect("queried");
        assert!((swapped.distance - truth).abs() <= CLOSE, "seed {seed}");
        assert!(
            swapped.lower <= truth && truth <= swapped.upper,
            "seed {seed}"
        );
    }
}

#[test]
fn ellipsoid_to_a_sphere_matches_a_dense_minimisation() {
    let egg = Ellipsoid::new(1.2, 0.8, 0.5);
    let radius = 0.3;
    let ball = Convex::sphere(radius).expect("sphere");
    let options = Options::default();
    for seed in 0..12 {
        let r = rotation(seed);
        let pose = Isometry3::from_parts(Translation3::new(0.1, 0.2, -0.3), r);
        let angle = 0.9 * seed as f64;
        let centre = Vector3::new(
            2.0 * angle.cos(),
            1.6 * angle.sin(),
            0.8 - 0.1 * seed as f64,
        );
        let ball_pose = Isometry3::translation(centre.x, centre.y, centre.z);
        let in_body = pose.inverse_transform_point(&Point3::from(centre)).coords;
        let truth = surface_distance(&egg, &in_body) - radius;
        let answer =
            distance_between(&egg, &pose, &ball, &ball_pose, &options, None).expect("queried");
        assert!(
            (answer.distance - truth).abs() <= 1e-8,
            "seed {seed}: {} against {truth}",
            answer.distance
        );
        // The grid's answer is itself within about 1e-12 of the truth.
        assert!(
            answer.lower <= truth + 1e-11 && truth - 1e-11 <= answer.upper,
            "seed {seed}: [{}, {}] against {truth}",
            answer.lower,
            answer.upper
        );
        // Warm from its own answer: the same distance, from the indices the
        // ellipsoid handed out.
        let warm = distance_between(
            &egg,
            &pose,
            &ball,
            &ball_pose,
            &options,
            Some(&answer.warm_start),
        )
        .expect("queried warm");
        assert!((warm.distance - truth).abs() <= 1e-8, "seed {seed} warm");
        assert!(warm.iterations <= answer.iterations, "seed {seed}");
    }
}

#[test]
fn ellipsoid_on_a_cylinder_cap_is_seeded_through_the_hook() {
    // A cylinder (the crate's seeded shape) beside a shape with no seed:
    // the pair takes the seeded run, and the answer is the height of the
    // ellipsoid's lowest point above the cap, which it overhangs.
    let can = Convex::cylinder(2.0, 1.0, 0.0).expect("cylinder");
    let egg = Ellipsoid::new(0.9, 0.6, 0.3);
    let options = Options::default();
    for seed in 0..20 {
        let r = rotation(seed);
        let height = 2.2 + 0.03 * seed as f64;
        let pose = Isometry3::from_parts(Translation3::new(0.4, -0.3, height), r);
        let down_in_body = r.inverse_transform_vector(&-Vector3::z());
        let lowest = pose * Point3::from(egg.support_of(&down_in_body));
        assert!(lowest.coords.xy().norm() < 1.9, "over the cap");
        let truth = lowest.z - 1.0;
        let answer = distance_between(&can, &Isometry3::identity(), &egg, &pose, &options, None)
            .expect("queried");
        assert!(
            (answer.distance - truth).abs() <= CLOSE,
            "seed {seed}: {} against {truth}",
            answer.distance
        );
        assert!(
            answer.lower <= truth && truth <= answer.upper,
            "seed {seed}"
        );
    }
}

#[test]
fn the_crate_s_shapes_answer_as_through_distance() {
    // Two stored shapes through the generic entry: the same answer, bit
    // for bit, as `distance` gives.
    let a = Convex::cuboid(Vector3::new(0.5, 0.4, 0.3), 0.05).expect("box");
    let b = Convex::cylinder(0.3, 0.6, 0.0).expect("cylinder");
    let options = Options::default();
    for seed in 0..20 {
        let pose = Isometry3::from_parts(
            Translation3::new(1.2, 0.1 * seed as f64, 0.2),
            rotation(seed),
        );
        let through_trait = distance_between(&a, &Isometry3::identity(), &b, &pose, &options, None)
            .expect("queried");
        let through_shape = gjk::distance(
            &a.clone().into(),
            &Isometry3::identity(),
            &b.clone().into(),
            &pose,
            &options,
            None,
        )
        .expect("queried");
        assert_eq!(format!("{through_trait:?}"), format!("{through_shape:?}"));
    }
}

#[test]
fn a_warm_start_the_ellipsoid_never_handed_out_is_refused() {
    let egg = Ellipsoid::new(1.0, 1.0, 1.0);
    let ball = Convex::sphere(0.5).expect("sphere");
    let id = Isometry3::identity();
    let far = Isometry3::translation(4.0, 0.0, 0.0);
    let options = Options::default();
    // Nothing handed out yet: index 0 names no point.
    let warm = WarmStart::new([0, 0], &[[0, 0]]).expect("one pair");
    assert_eq!(
        distance_between(&egg, &id, &ball, &far, &options, Some(&warm)),
        Err(Error::WarmStartOutOfRange)
    );
    // A piece other than 0 of a single shape.
    let answer = distance_between(&egg, &id, &ball, &far, &options, None).expect("queried");
    assert!((answer.distance - 2.5).abs() <= CLOSE);
    let other_piece = WarmStart::new([1, 0], &[[0, 0]]).expect("one pair");
    assert_eq!(
        distance_between(&egg, &id, &ball, &far, &options, Some(&other_piece)),
        Err(Error::WarmStartOutOfRange)
    );
    // Bad poses and options are refused as for the crate's shapes.
    let nan = Isometry3::translation(f64::NAN, 0.0, 0.0);
    assert_eq!(
        distance_between(&egg, &id, &ball, &nan, &options, None),
        Err(Error::NonFinitePose)
    );
}

#[test]
fn the_difference_support_takes_the_foreign_shape() {
    // What a penetration depth expands by: the ellipsoid's support less
    // the sphere's, at their poses.
    let egg = Ellipsoid::new(2.0, 1.0, 0.5);
    let ball = Convex::sphere(0.25).expect("sphere");
    let at = Isometry3::translation(0.0, 0.0, 1.0);
    let s = support_of_difference(&egg, &Isometry3::identity(), &ball, &at, &Vector3::x());
    assert_eq!(s.witness_a.point, Point3::new(2.0, 0.0, 0.0));
    assert_eq!(s.witness_b.point, Point3::new(-0.25, 0.0, 1.0));
    assert_eq!(s.point, Vector3::new(2.25, 0.0, -1.0));
}

#[test]
fn ellipsoid_sunk_into_a_box_face_has_its_analytic_depth() {
    // Overlapping the face by less than the box's thickness and far from
    // its sides: the shortest separating move is straight up, by the depth
    // of the lowest point, so the signed distance is its (negative) height.
    let slab = Convex::cuboid(Vector3::new(100.0, 100.0, 1.0), 0.0).expect("box");
    let slab_pose = Isometry3::translation(0.0, 0.0, -1.0);
    let egg = Ellipsoid::new(1.5, 0.7, 0.4);
    let options = DepthOptions::default();
    for seed in 0..20 {
        let r = rotation(seed);
        let down_in_body = r.inverse_transform_vector(&-Vector3::z());
        let reach = egg.support_value(&down_in_body);
        let height = reach - 0.05 - 0.01 * seed as f64;
        let pose = Isometry3::from_parts(Translation3::new(0.3, -0.2, height), r);
        let truth = height - reach;
        let sd =
            signed_distance_between(&egg, &pose, &slab, &slab_pose, &options).expect("queried");
        assert!(
            sd.lower <= truth && truth <= sd.upper,
            "seed {seed}: [{}, {}] against {truth}",
            sd.lower,
            sd.upper
        );
        assert!(
            (sd.value - truth).abs() <= 1e-6,
            "seed {seed}: {} against {truth}",
            sd.value
        );
        assert!(sd.expansions > 0, "seed {seed}: the depth was expanded");
        // Apart, it is the distance itself.
        let above = Isometry3::from_parts(Translation3::new(0.3, -0.2, reach + 0.5), r);
        let apart =
            signed_distance_between(&egg, &above, &slab, &slab_pose, &options).expect("queried");
        assert!((apart.value - 0.5).abs() <= CLOSE, "seed {seed}");
        assert_eq!(apart.expansions, 0);
    }
}
