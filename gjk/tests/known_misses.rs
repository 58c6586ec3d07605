//! Answers known to miss the requirement (1e-9 of the size near contact), kept
//! as tests that run with `--ignored`, so the next fix has its case at hand:
//! `cargo test --release -p gjk --test known_misses -- --ignored`.
//!
//! Found on 2026-11-24 by a hunt over sets of 64 to 511 vertices (round,
//! flat, lattice, two-plane, prism, needle, duplicate and collinear sets,
//! scales 1e-6 to 1e6): about 30 placements in 200 000 miss by 1.2× to 9×,
//! every one with one shape flat, collinear, needle-like or a single point
//! and a true distance of 0 or at most about 1e-10 of the size. The code of
//! 1ac9cba (before that day's speed work) gives the same answers bit for
//! bit. The certified interval always holds the truth (its lower end is 0);
//! what misses is the reported distance, the upper end, with the status
//! `Converged` (sometimes after the Backup Procedure) or `ToleranceNotMet`.

// The cases' poses are data printed to the last bit, not approximations of
// named constants.
#![allow(clippy::approx_constant)]

use gjk::{Convex, Options, distance};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};

include!("data/needle_on_polygon.rs");

fn pose(p: ([f64; 4], [f64; 3])) -> Isometry3<f64> {
    let q = UnitQuaternion::new_unchecked(Quaternion::new(p.0[0], p.0[1], p.0[2], p.0[3]));
    Isometry3::from_parts(Translation3::new(p.1[0], p.1[1], p.1[2]), q)
}

/// An upper bound on the true distance, by brute force: every vertex of B
/// (in A's frame) against every segment between two vertices of A.
fn vertex_to_segments(a: &[Point3<f64>], b: &[Point3<f64>], rel: &Isometry3<f64>) -> f64 {
    let o = a[0];
    let mut best = f64::INFINITY;
    for i in 0..a.len() {
        for j in i..a.len() {
            let (p0, e) = (a[i] - o, a[j] - a[i]);
            let ee = e.norm_squared();
            for q in b {
                let w = rel * q - o;
                let t = if ee > 0.0 {
                    ((w - p0).dot(&e) / ee).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let d: Vector3<f64> = w - (p0 + e * t);
                best = best.min(d.norm());
            }
        }
    }
    best
}

#[test]
#[ignore = "known miss: a flat polygon touching a needle ends 3.75x the requirement away (see the module docs)"]
fn needle_touching_a_flat_polygon() {
    let pts = |v: &[[f64; 3]]| -> Vec<Point3<f64>> {
        v.iter().map(|c| Point3::new(c[0], c[1], c[2])).collect()
    };
    let (a, b) = (pts(A), pts(B));
    let (pa, pb) = (pose(PA), pose(PB));
    let (ca, cb) = (
        Convex::new(a.clone(), RA).unwrap(),
        Convex::new(b.clone(), RB).unwrap(),
    );
    let size = ca.size().max(cb.size());
    let ans = distance(&ca.into(), &pa, &cb.into(), &pb, &Options::default(), None).unwrap();
    let truth_at_most = (vertex_to_segments(&a, &b, &pa.inv_mul(&pb)) - RA - RB).max(0.0);
    assert!(truth_at_most < 1e-12, "{truth_at_most:e}");
    assert!(ans.lower <= truth_at_most, "bounds: {ans:?}");
    // Today: distance 3.076e-9 in [0, 3.076e-9], ToleranceNotMet after the
    // Backup Procedure, 12 iterations; the requirement is 8.2e-10.
    assert!(
        ans.distance - truth_at_most <= 1e-9 * size,
        "distance {:e} (interval [{:e}, {:e}], {:?}) against a truth of at most {truth_at_most:e}",
        ans.distance,
        ans.lower,
        ans.upper,
        ans.status
    );
}
