//! Inputs found by `fuzz/` (target `gjk_query`) that broke an invariant,
//! kept as regression tests: no panic, no NaN, `lower <= distance <= upper`.

mod common;

use gjk::{Convex, Options, Shape, distance};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};

fn check(
    a: &Shape,
    pa: &Isometry3<f64>,
    b: &Shape,
    pb: &Isometry3<f64>,
    o: &Options,
) -> gjk::Answer {
    let ans = distance(a, pa, b, pb, o, None).expect("valid input");
    assert!(
        !ans.distance.is_nan() && !ans.lower.is_nan() && !ans.upper.is_nan(),
        "{ans:?}"
    );
    assert!(
        ans.lower <= ans.distance && ans.distance <= ans.upper,
        "{ans:?}"
    );
    ans
}

fn check_warm(
    a: &Shape,
    pa: &Isometry3<f64>,
    b: &Shape,
    pb: &Isometry3<f64>,
    o: &Options,
    w: &gjk::WarmStart,
) -> gjk::Answer {
    let ans = distance(a, pa, b, pb, o, Some(w)).expect("valid input");
    assert!(
        !ans.distance.is_nan() && !ans.lower.is_nan() && !ans.upper.is_nan(),
        "{ans:?}"
    );
    assert!(
        ans.lower <= ans.distance && ans.distance <= ans.upper,
        "{ans:?}"
    );
    ans
}

/// Vertices of magnitude 1e100 and 1e108 next to ones of magnitude 1,
/// queried warm from another pose: the subalgorithm's cofactors overflowed
/// to NaN weights, `|v|` became NaN, the upper bound fell to 0 under the
/// lower one and `clamp` panicked. Now the last finite iterate is kept and
/// the answer agrees with brute force.
#[test]
fn mixed_magnitudes_1e108_and_1() {
    let a: Shape = Convex::new(
        vec![
            Point3::new(9.9e100, 9.900000000000002e108, 9.9e100),
            Point3::new(9.9e100, 9.9e100, 9.9e100),
            Point3::new(9.9e100, 9.9e100, 9.9e100),
            Point3::new(6.1875, 9.9e100, 9.9e100),
        ],
        6.4000000000000006e100,
    )
    .expect("valid")
    .into();
    let b: Shape = Convex::new(
        vec![
            Point3::new(9.9e100, 9.9e100, -6.25),
            Point3::new(-6.25, -6.25, -6.25),
            Point3::new(-6.25, -6.25, -6.25),
            Point3::new(-6.25, -6.25, -6.25),
        ],
        0.0,
    )
    .expect("valid")
    .into();
    let pose = Isometry3::from_parts(
        Translation3::new(-6.25, -6.25, -6.25),
        UnitQuaternion::new_unchecked(Quaternion::new(-0.5, -0.5, -0.5, -0.5)),
    );
    let o = Options {
        tolerance: 2.220446049250313e-14,
        max_iterations: 55,
        margin: None,
        warm_start: true,
        ..Options::default()
    };
    let first = check(&a, &pose, &b, &pose, &o);
    // The crash: warm from that answer's simplex, B turned a little.
    let turned = Isometry3::from_parts(
        Translation3::new(-6.25, -6.25, -6.25),
        UnitQuaternion::new_unchecked(Quaternion::new(
            -0.51231551957856,
            -0.51231551957856,
            -0.51231551957856,
            0.46108396762070397,
        )),
    );
    let warm = check_warm(&a, &pose, &b, &turned, &o, &first.warm_start);
    let cold = check(&a, &pose, &b, &turned, &o);
    // The brute-force distance of the hulls, grown by the radius.
    let (Shape::Convex(ca), Shape::Convex(cb)) = (&a, &b) else {
        unreachable!("both convex")
    };
    let wa = common::world_convex(ca, &pose);
    let wb = common::world_convex(cb, &turned);
    let truth = common::rounded_distance(&wa.points, wa.radius, &wb.points, wb.radius);
    let slack = 1e-3 * truth;
    for ans in [warm, cold] {
        assert!(
            ans.lower <= truth + slack && truth - slack <= ans.upper,
            "{truth:e}: {ans:?}"
        );
        assert!((ans.distance - truth).abs() <= slack, "{truth:e}: {ans:?}");
    }
}
