//! Random small polytopes against the brute-force Minkowski depth: the
//! interval holds it on every overlapping case, rounded or not, and the
//! value is within the judged error.

use gjk::{Convex, Shape};
use gjkd_testkit::minkowski_depth::minkowski_depth;
use gjkd_testkit::reference::P;
use nalgebra::Isometry3;
use proptest::prelude::*;

use proptest::test_runner::Config;

use super::common::{config, pose, vec3};
use super::{assert_signed, sd};

/// 4 to 8 points in the unit cube, or 3 on a plane (a flat piece).
fn points() -> impl Strategy<Value = Vec<P>> {
    prop_oneof![
        4 => prop::collection::vec(vec3().prop_map(P::from), 4..=8),
        1 => prop::collection::vec(
            (-1.0..1.0f64, -1.0..1.0f64).prop_map(|(x, y)| P::new(x, y, 0.0)), 3..=5),
    ]
}

fn placed(points: &[P], pose: &Isometry3<f64>) -> Vec<P> {
    points.iter().map(|p| pose * p).collect()
}

/// The brute-force signed distance of the cores when they overlap, less
/// the radii; `None` when the cores are apart, touch, or have a flat
/// difference.
fn truth(a: &[P], pa: &Isometry3<f64>, b: &[P], pb: &Isometry3<f64>, radii: f64) -> Option<f64> {
    minkowski_depth(&placed(a, pa), &placed(b, pb)).map(|(depth, _)| -depth - radii)
}

/// Apart or touching pairs are drawn too and set aside: room for them.
fn hunting() -> Config {
    Config {
        max_global_rejects: 1 << 20,
        ..config(0x5d_0001)
    }
}

proptest! {
    #![proptest_config(hunting())]

    #[test]
    fn polytopes_against_the_minkowski_facets(
        a in points(), b in points(), pa in pose(0.6), pb in pose(0.6),
        ra in prop_oneof![Just(0.0), 0.0..0.3f64], rb in prop_oneof![Just(0.0), 0.0..0.3f64],
    ) {
        let want = truth(&a, &pa, &b, &pb, ra + rb);
        prop_assume!(want.is_some());
        let want = want.unwrap();
        let sa: Shape = Convex::new(a, ra).unwrap().into();
        let sb: Shape = Convex::new(b, rb).unwrap().into();
        let got = sd(&sa, &pa, &sb, &pb);
        assert_signed(&got, want, 2.0, "random pair");
    }

    /// The same at sizes from 1e-9 to 1e6, at one pose up to 1e9 from the
    /// origin (B's placement in its vertices: see the extremes).
    #[test]
    fn polytopes_at_every_scale_and_place(
        a in points(), b in points(), rel in pose(0.6), frame in pose(1.0),
        exponent in -9i32..=6, far in prop_oneof![Just(0.0), Just(1e3), Just(1e9)],
    ) {
        let s = 10f64.powi(exponent);
        let a: Vec<P> = a.iter().map(|p| P::from(p.coords * s)).collect();
        let rel = Isometry3::from_parts((rel.translation.vector * s).into(), rel.rotation);
        let b: Vec<P> = b.iter().map(|p| rel * P::from(p.coords * s)).collect();
        let want = minkowski_depth(&a, &b);
        prop_assume!(want.is_some());
        let (depth, _) = want.unwrap();
        let frame = Isometry3::from_parts((frame.translation.vector * far).into(), frame.rotation);
        let sa: Shape = Convex::new(a, 0.0).unwrap().into();
        let sb: Shape = Convex::new(b, 0.0).unwrap().into();
        let got = sd(&sa, &frame, &sb, &frame);
        assert_signed(&got, -depth, 2.0 * s, "scaled pair");
    }
}

#[test]
fn the_reference_agrees_on_two_boxes() {
    let corners = |h: f64| -> Vec<P> {
        (0..8)
            .map(|i| {
                P::new(
                    if i & 1 == 0 { -h } else { h },
                    if i & 2 == 0 { -h } else { h },
                    if i & 4 == 0 { -h } else { h },
                )
            })
            .collect()
    };
    let pb = Isometry3::translation(0.9, 0.3, -0.2);
    let want = truth(
        &corners(1.0),
        &Isometry3::identity(),
        &corners(0.5),
        &pb,
        0.0,
    )
    .unwrap();
    assert!((want + 0.6).abs() < 1e-15, "{want}");
    let a: Shape = Convex::new(corners(1.0), 0.0).unwrap().into();
    let b: Shape = Convex::new(corners(0.5), 0.0).unwrap().into();
    assert_signed(&sd(&a, &Isometry3::identity(), &b, &pb), want, 1.0, "boxes");
}
