//! The signed distance (`gjk::signed_distance`) against independent
//! answers: closed forms, the brute-force Minkowski depth of
//! `gjkd_testkit::minkowski_depth`, and extremes of size, place and shape.
//! On every case the certified interval holds the truth, and the value is
//! within `max(1e-6 × |truth|, 1e-9 × size)` of it.

#[path = "../common/mod.rs"]
mod common;

mod closed_forms;
mod extremes;
mod reference;

use gjk::{DepthOptions, Shape, SignedDistance, signed_distance};
use nalgebra::Isometry3;

/// The signed distance with the default options.
pub fn sd(
    a: &Shape,
    pose_a: &Isometry3<f64>,
    b: &Shape,
    pose_b: &Isometry3<f64>,
) -> SignedDistance {
    signed_distance(a, pose_a, b, pose_b, &DepthOptions::default()).expect("valid input")
}

/// `got` holds `truth` in its interval, its value is within the judged
/// error of it, and its witnesses and normal agree with its value:
/// `point_b - point_a = value · normal`, to the error allowed.
#[track_caller]
pub fn assert_signed(got: &SignedDistance, truth: f64, size: f64, what: &str) {
    assert!(
        got.lower <= truth && truth <= got.upper,
        "{what}: [{:e}, {:e}] excludes {truth:e} ({got:?})",
        got.lower,
        got.upper
    );
    let allowed = (1e-6 * truth.abs()).max(1e-9 * size);
    assert!(
        (got.value - truth).abs() <= allowed,
        "{what}: {:e} vs {truth:e} ({got:?})",
        got.value
    );
    let normal = got.normal.norm();
    assert!(
        (normal - 1.0).abs() < 1e-9,
        "{what}: normal {:?}",
        got.normal
    );
    let gap = got.point_b - got.point_a - got.normal * got.value;
    // The witnesses are placed in the world, where a pose far from the
    // origin rounds them by its own ulp.
    let place = got.point_a.coords.amax() * 4.0 * f64::EPSILON;
    assert!(
        gap.norm() <= 1e-6 * size + place,
        "{what}: witnesses {:?} {:?} off by {:e}",
        got.point_a,
        got.point_b,
        gap.norm()
    );
}
