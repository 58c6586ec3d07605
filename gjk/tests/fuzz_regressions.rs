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
    let brute = common::rounded_distance(&wa.points, wa.radius, &wb.points, wb.radius);
    // The f64 brute force works in world coordinates of 1e108 and is off by
    // about 1e-5 here; the same minimum over vertex-triangle and edge-edge
    // distances in 60-digit arithmetic (mpmath) gives the truth below.
    let truth = 7.582268067529549e100;
    assert!(
        (brute - truth).abs() <= 1e-4 * truth,
        "brute force {brute:e}"
    );
    for ans in [warm, cold] {
        assert!(
            ans.lower <= truth * (1.0 + 1e-12) && truth <= ans.upper * (1.0 + 1e-12),
            "{truth:e}: {ans:?}"
        );
        assert!(
            (ans.distance - truth).abs() <= 1e-6 * truth,
            "{truth:e}: {ans:?}"
        );
    }
}

/// Two points 9.7e-229 apart (one coordinate subnormal): the squares of
/// their offsets underflow f64, which made the fuzz target's own check think
/// them coincident once gjk's scaled run answered exactly. The truth is
/// `6.828527034422786e-229 · √2`.
#[test]
fn points_whose_squared_gap_underflows() {
    let a: Shape = Convex::new(
        vec![Point3::new(
            -6.828527034422786e-229,
            -6.828527034422786e-229,
            1.37689932639989e-309,
        )],
        0.0,
    )
    .unwrap()
    .into();
    let b: Shape = Convex::new(vec![Point3::origin()], 0.0).unwrap().into();
    let truth = 6.828527034422786e-229 * std::f64::consts::SQRT_2;
    for o in [
        Options::default(),
        Options {
            max_iterations: 1,
            margin: Some(0.0),
            ..Options::default()
        },
    ] {
        let pose = Isometry3::identity();
        let ans = check(&a, &pose, &b, &pose, &o);
        assert!(
            ans.lower <= truth * (1.0 + 1e-14) && truth <= ans.upper * (1.0 + 1e-14),
            "{ans:?}"
        );
        assert!((ans.distance - truth).abs() <= 1e-14 * truth, "{ans:?}");
    }
}
