//! Closed-form cases: every expected value below is computed by hand (or by the
//! independent brute force of `gjkd_testkit::reference`), never by GJK. Also
//! every error path.

use gjk::{Answer, Compound, Convex, Error, Options, Shape, Status, WarmStart, distance};
use gjkd_testkit::input::{p, v};
use gjkd_testkit::reference::{
    P, V, aabb_distance, closest_on_segment, hull_distance, penetration_depth,
};
use nalgebra::{Isometry3, Quaternion, Translation3, Unit, UnitQuaternion};

mod closed_forms;
mod errors;
mod unions_and_exits;

use std::panic::{AssertUnwindSafe, catch_unwind};

fn iso(x: f64, y: f64, z: f64) -> Isometry3<f64> {
    Isometry3::translation(x, y, z)
}

fn query(a: &Shape, pa: &Isometry3<f64>, b: &Shape, pb: &Isometry3<f64>) -> Answer {
    distance(a, pa, b, pb, &Options::default(), None).expect("valid input")
}

fn convex(points: &[P], r: f64) -> Shape {
    Convex::new(points.to_vec(), r).unwrap().into()
}

/// Distance, bounds and status against a known truth.
#[track_caller]
fn assert_distance(ans: &Answer, truth: f64, tol: f64) {
    assert!(
        (ans.distance - truth).abs() <= tol,
        "distance {} != truth {truth} (tol {tol}); answer {ans:?}",
        ans.distance
    );
    assert!(
        ans.lower <= truth + tol * 1e-3 && truth <= ans.upper + tol * 1e-3,
        "bounds [{}, {}] miss truth {truth}; answer {ans:?}",
        ans.lower,
        ans.upper
    );
    assert!(ans.lower <= ans.distance && ans.distance <= ans.upper);
    assert_eq!(ans.status, Status::Converged, "answer {ans:?}");
}

#[track_caller]
fn assert_point(got: &P, want: &P, tol: f64) {
    assert!(
        (got - want).norm() <= tol,
        "point {got:?} != expected {want:?}"
    );
}

#[track_caller]
fn assert_vec(got: &V, want: &V, tol: f64) {
    assert!(
        (got - want).norm() <= tol,
        "vector {got:?} != expected {want:?}"
    );
}

// ---------------------------------------------------------------------------
// Failure paths: the right error for each bad input, and no panic.

fn no_panic<T>(what: &str, f: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|_| panic!("panicked on {what}"))
}
