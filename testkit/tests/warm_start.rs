//! Warm start along smooth motions: the same answers as a cold start, in fewer
//! iterations; and the right answer after a jump.

use gjk::{Answer, Compound, Convex, Options, Shape, Status, WarmStart, distance};
use gjkd_testkit::check::shape_distance;
use gjkd_testkit::input::{p, v};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

const STEPS: usize = 1000;

/// A truncated decagonal cone: 10 vertices on a circle of radius 1 at z = -1,
/// 10 of radius 0.6 at z = 1, the top ring turned by half a step.
fn truncated_cone() -> Convex {
    let mut pts = Vec::new();
    for k in 0..10 {
        let a = std::f64::consts::TAU * k as f64 / 10.0;
        pts.push(p(a.cos(), a.sin(), -1.0));
        let b = a + std::f64::consts::PI / 10.0;
        pts.push(p(0.6 * b.cos(), 0.6 * b.sin(), 1.0));
    }
    Convex::new(pts, 0.0).unwrap()
}

fn mover(radius: f64) -> Convex {
    Convex::cuboid(v(0.5, 0.3, 0.2), radius).unwrap()
}

/// Pose of the moving box at step `k`: translating along x past the cone at
/// height `y` while turning about a tilted axis.
fn motion(k: usize, y: f64, z: f64) -> Isometry3<f64> {
    let t = k as f64 / (STEPS - 1) as f64;
    let axis = Vector3::new(0.3, 1.0, 0.5).normalize();
    Isometry3::from_parts(
        Translation3::new(-4.0 + 8.0 * t, y, z + 0.3 * (5.0 * t).sin()),
        UnitQuaternion::from_scaled_axis(axis * (4.0 * std::f64::consts::PI * t)),
    )
}

struct Sweep {
    cold_iterations: u64,
    warm_iterations: u64,
    last_warm: WarmStart,
    touching_steps: usize,
}

/// Run a sweep, comparing warm and cold answers at every step and both with
/// the brute force every `check_every` steps. Returns the iteration totals.
fn sweep(
    a: &Shape,
    b: &Shape,
    pose_b: &Isometry3<f64>,
    path: impl Fn(usize) -> Isometry3<f64>,
    check_every: usize,
) -> Sweep {
    let opt = Options::default();
    let size = 4.0;
    let mut warm: Option<WarmStart> = None;
    let (mut cold_it, mut warm_it) = (0u64, 0u64);
    let mut failures = Vec::new();
    let mut touching_steps = 0;
    for k in 0..STEPS {
        let pa = path(k);
        let cold = distance(a, &pa, b, pose_b, &opt, None).unwrap();
        let hot = distance(a, &pa, b, pose_b, &opt, warm.as_ref()).unwrap();
        cold_it += u64::from(cold.iterations);
        warm_it += u64::from(hot.iterations);
        if cold.distance == 0.0 {
            touching_steps += 1;
        }
        let tol = 1e-9 * size;
        let agree = (hot.distance - cold.distance).abs() <= tol
            && hot.lower <= cold.distance + tol
            && cold.distance <= hot.upper + tol
            && cold.lower <= hot.distance + tol
            && hot.distance <= cold.upper + tol
            && hot.pieces == cold.pieces;
        if !agree || hot.status != Status::Converged || cold.status != Status::Converged {
            failures.push(format!(
                "step {k}: warm {warm:?}\n  cold {cold:?}\n  warm {hot:?}"
            ));
        }
        if k % check_every == 0 {
            let r = shape_distance(a, &pa, b, pose_b);
            for (name, ans) in [("cold", &cold), ("warm", &hot)] {
                if (ans.distance - r.distance).abs() > tol {
                    failures.push(format!(
                        "step {k}: {name} {} but brute force {}",
                        ans.distance, r.distance
                    ));
                }
            }
        }
        warm = Some(hot.warm_start);
    }
    assert!(
        failures.is_empty(),
        "{} failing steps:\n{}",
        failures.len(),
        failures.join("\n")
    );
    Sweep {
        cold_iterations: cold_it,
        warm_iterations: warm_it,
        last_warm: warm.unwrap(),
        touching_steps,
    }
}

#[test]
fn warm_start_along_a_separated_motion() {
    let a: Shape = mover(0.0).into();
    let b: Shape = truncated_cone().into();
    let pose_b = Isometry3::identity();
    let s = sweep(&a, &b, &pose_b, |k| motion(k, 1.9, 0.0), 100);
    assert_eq!(
        s.touching_steps, 0,
        "the path should stay clear of the cone"
    );
    assert!(
        2 * s.warm_iterations < s.cold_iterations,
        "warm {} not under half of cold {} iterations",
        s.warm_iterations,
        s.cold_iterations
    );
}

/// The path runs through the cone: separated, touching, intersecting and
/// separated again, with rounded shapes.
#[test]
fn warm_start_through_an_intersection() {
    let a: Shape = mover(0.05).into();
    let b: Shape = truncated_cone().into();
    let pose_b = Isometry3::identity();
    let s = sweep(&a, &b, &pose_b, |k| motion(k, 0.4, 0.2), 50);
    assert!(
        s.touching_steps > 100,
        "the path should cross the cone ({} steps)",
        s.touching_steps
    );
    assert!(
        2 * s.warm_iterations < s.cold_iterations,
        "warm {} not under half of cold {} iterations",
        s.warm_iterations,
        s.cold_iterations
    );
}

/// Compounds: the nearest piece pair changes along the path.
#[test]
fn warm_start_with_compounds() {
    let a: Shape = Compound::new(vec![
        (Isometry3::translation(-0.6, 0.0, 0.0), mover(0.0)),
        (
            Isometry3::translation(0.6, 0.0, 0.0),
            Convex::sphere(0.3).unwrap(),
        ),
    ])
    .unwrap()
    .into();
    let b: Shape = Compound::new(vec![
        (Isometry3::translation(0.0, 0.0, -1.0), truncated_cone()),
        (
            Isometry3::translation(0.0, 0.0, 1.5),
            Convex::capsule(p(-1., 0., 0.), p(1., 0., 0.), 0.2).unwrap(),
        ),
    ])
    .unwrap()
    .into();
    let pose_b = Isometry3::identity();
    let s = sweep(&a, &b, &pose_b, |k| motion(k, 2.0, 0.5), 100);
    assert!(
        s.warm_iterations < s.cold_iterations,
        "warm {} >= cold {} iterations",
        s.warm_iterations,
        s.cold_iterations
    );
}

/// After the pose jumps far (and turns), the stale warm start must still give
/// the right answer.
#[test]
fn warm_start_after_a_jump() {
    let a: Shape = mover(0.0).into();
    let b: Shape = truncated_cone().into();
    let pose_b = Isometry3::identity();
    let s = sweep(&a, &b, &pose_b, |k| motion(k, 1.9, 0.0), 100);
    let jumps: [Isometry3<f64>; 5] = [
        Isometry3::from_parts(
            Translation3::new(100.0, -50.0, 20.0),
            UnitQuaternion::from_euler_angles(3.0, 0.1, -1.0),
        ),
        Isometry3::from_parts(
            Translation3::new(-1.2, 0.0, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 1.5, 0.0),
        ),
        Isometry3::from_parts(Translation3::new(0.0, 0.0, 0.0), UnitQuaternion::identity()),
        Isometry3::from_parts(
            Translation3::new(0.0, 0.0, 1.25),
            UnitQuaternion::identity(),
        ),
        Isometry3::from_parts(
            Translation3::new(1e6, 1e6, 1e6),
            UnitQuaternion::from_euler_angles(-0.3, 0.2, 2.2),
        ),
    ];
    let mut failures = Vec::new();
    for (i, pa) in jumps.iter().enumerate() {
        let r = shape_distance(&a, pa, &b, &pose_b);
        let ans = distance(&a, pa, &b, &pose_b, &Options::default(), Some(&s.last_warm)).unwrap();
        let tol = 1e-9 * r.scale;
        if (ans.distance - r.distance).abs() > tol
            || ans.lower > r.distance + tol
            || r.distance > ans.upper + tol
        {
            failures.push(format!("jump {i}: truth {} got {ans:?}", r.distance));
        }
    }
    // The top face (z = 1) under the box's bottom face (z = 1.25 - 0.2): 0.05.
    let ans = distance(
        &a,
        &jumps[3],
        &b,
        &pose_b,
        &Options::default(),
        Some(&s.last_warm),
    )
    .unwrap();
    assert!((ans.distance - 0.05).abs() < 1e-12, "{ans:?}");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Handing an answer's own warm start back for the same poses reproduces the
/// answer in at most as many iterations.
#[test]
fn warm_start_at_the_same_pose_is_idempotent() {
    let a: Shape = mover(0.1).into();
    let b: Shape = truncated_cone().into();
    let pose_b = Isometry3::identity();
    for k in (0..STEPS).step_by(37) {
        let pa = motion(k, 1.9, 0.0);
        let first: Answer = distance(&a, &pa, &b, &pose_b, &Options::default(), None).unwrap();
        let again = distance(
            &a,
            &pa,
            &b,
            &pose_b,
            &Options::default(),
            Some(&first.warm_start),
        )
        .unwrap();
        assert!(
            (again.distance - first.distance).abs() <= 1e-12,
            "step {k}: {first:?} vs {again:?}"
        );
        assert!(
            again.iterations <= first.iterations,
            "step {k}: {} > {}",
            again.iterations,
            first.iterations
        );
        // Off, the warm start is ignored: the cold answer exactly.
        let off = Options {
            warm_start: false,
            ..Options::default()
        };
        let ignored = distance(&a, &pa, &b, &pose_b, &off, Some(&first.warm_start)).unwrap();
        assert_eq!(ignored, first, "step {k}");
    }
}

/// A warm query that ends early on its margin keeps that early end: its
/// interval is wide by the caller's choice, and running it again cold (as a
/// warm run that meant to converge and ended loose is) would only spend the
/// time twice. After a jump the stale simplex decides the margin in one
/// iteration; the decision, the bounds and the iteration count are checked.
#[test]
fn warm_start_with_a_margin_ends_at_the_margin() {
    let a: Shape = mover(0.0).into();
    let b: Shape = truncated_cone().into();
    let pose_b = Isometry3::identity();
    let s = sweep(&a, &b, &pose_b, |k| motion(k, 1.9, 0.0), 100);
    let jump = Isometry3::from_parts(
        Translation3::new(100.0, -50.0, 20.0),
        UnitQuaternion::from_euler_angles(3.0, 0.1, -1.0),
    );
    let truth = shape_distance(&a, &jump, &b, &pose_b).distance;
    assert!(truth > 100.0, "{truth}");
    for (margin, want) in [(1.0, Status::Farther), (1e3, Status::Closer)] {
        let options = Options {
            margin: Some(margin),
            ..Options::default()
        };
        let ans = distance(&a, &jump, &b, &pose_b, &options, Some(&s.last_warm)).unwrap();
        assert_eq!(ans.status, want, "margin {margin}: {ans:?}");
        assert!(ans.lower <= truth && truth <= ans.upper, "{ans:?}");
        assert!(
            ans.upper - ans.lower > 1e-6,
            "decided without a wide interval: {ans:?}"
        );
        assert_eq!(ans.iterations, 1, "margin {margin}: {ans:?}");
    }
}
