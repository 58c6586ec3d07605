//! Randomised extremes (see `gjkd_testkit::sweep`): scales 1e-9 to 1e6, poses
//! up to 1e9 from the origin, gaps from the size down to 1e-12 of it and 0,
//! vertex, face, edge and nearly parallel edge contacts, overlaps shallow,
//! deep and of the rounded shells only, degenerate vertex sets and identical
//! bodies. Every case's distance must be within the requirement and
//! its bounds must contain the truth, which is known by construction, asked
//! cold and warm (from the answer at a pose nudged by 1 % of the size).
//!
//! `SWEEP_CASES` and `SWEEP_SEED` set a longer hunt (release mode advised):
//! `SWEEP_CASES=1000000 SWEEP_SEED=$RANDOM cargo test --release -p gjkd-testkit --test random_extremes`.
//! `SWEEP_BIG_EVERY=1` lets every case of the main sweep draw a 100 000-point
//! body (a sphere's or a box's surface), instead of one in 500.

use gjkd_testkit::input::{points, printed_pose as pose};
use gjkd_testkit::sweep;
use gjkd_testkit::sweep::{Case, Contact, Rng, bounds_error, depth_error, distance_error, draw};

mod found;
mod hunt;
mod unions;

use gjk::{Options, Status, distance};

fn env(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Converged, or the Backup Procedure's honest `ToleranceNotMet` with a
/// certified interval of the requirement's order (twice it: at a gap of
/// exactly 1e-9 of the size, the interval [0, truth] is the requirement
/// itself, and its upper end carries round-off): near contact the direction
/// of `v` carries round-off of `ε·D/|v|`, which can keep the lower bound of
/// Theorem 4.1 from `ε·D` while `|v|` itself is right (a flat tetrahedron of
/// four coplanar points of K at nearly parallel edges; twin segments).
fn status_error(case: &Case, ans: &gjk::Answer) -> Option<String> {
    let allowed = (1e-6 * case.truth).max(1e-9 * case.size);
    let narrow = ans.upper - ans.lower <= 2.0 * allowed;
    match ans.status {
        Status::Converged => None,
        Status::ToleranceNotMet if ans.backup_used && narrow => None,
        s => Some(format!("status {s:?}")),
    }
}

/// Fails the test with every failure listed.
#[track_caller]
fn none_failed(failed: &[String]) {
    assert!(
        failed.is_empty(),
        "{} failed:\n{}",
        failed.len(),
        failed.join("\n")
    );
}

/// Why `ans` misses the requirement for `case`, if it does.
fn check(case: &Case, ans: &gjk::Answer) -> Vec<String> {
    [
        distance_error(case, ans.distance),
        bounds_error(case, ans.lower, ans.upper),
        depth_error(case, ans.penetration),
        status_error(case, ans),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// [`check`] for `Precision::Single`, whose f32 support search may miss the
/// support value by 2⁻²⁰ of each shape's size: the distance may be off by
/// twice that more (as `tests/extremes.rs` allows), the bounds must hold all
/// the same, and the status is not asked (the search's slack widens the
/// interval).
fn check_single(case: &Case, ans: &gjk::Answer) -> Vec<String> {
    let allowed = (1e-6 * case.truth).max(1e-9 * case.size) + 2f64.powi(-18) * case.size;
    let err = ans.distance - case.truth;
    let mut why: Vec<String> = bounds_error(case, ans.lower, ans.upper)
        .into_iter()
        .collect();
    if err.is_nan() || err.abs() > allowed + case.truth_slack {
        why.push(format!("error {err:e} > allowed {allowed:e}"));
    }
    why
}

/// A as the nearer piece of a union whose other piece, a copy, sits 3 sizes
/// behind it, away from B: farther from B than the truth by at least twice
/// the size (its centre is, and each body reaches at most half the size from
/// its centre), so the union's distance is the case's truth.
fn union(case: &Case) -> gjk::Shape {
    let piece = || gjk::Convex::new(case.a.vertices.clone(), case.a.radius).unwrap();
    // B's centre in A's body frame through the relative pose, whose
    // translation is a difference of the poses' (exact when they are near
    // each other): at 1e9 from the origin, world centres lose 1e-7.
    let rel = case.pa.inv_mul(&case.pb);
    let away = (rel * case.b.centre() - case.a.centre())
        .try_normalize(0.0)
        .unwrap_or_else(nalgebra::Vector3::x);
    let behind = nalgebra::Isometry3::translation(
        -3.0 * case.size * away.x,
        -3.0 * case.size * away.y,
        -3.0 * case.size * away.z,
    );
    gjk::Compound::new(vec![
        (nalgebra::Isometry3::identity(), piece()),
        (behind, piece()),
    ])
    .unwrap()
    .into()
}

/// Every failing case, described. Each case is asked cold, then warm: with
/// the warm start of B nudged by up to 1 % of the size, the way a motion
/// hands the last answer to the next query; in f32; and with A as the near
/// piece of a union, cold and warm.
fn failures(cases: impl Iterator<Item = Case>) -> (usize, Vec<String>) {
    let mut n = 0;
    let mut out = Vec::new();
    let mut rng = Rng::new(7);
    for case in cases {
        n += 1;
        let (a, b) = (case.a.shape(), case.b.shape());
        let o = Options::default();
        let nudge = nalgebra::Translation3::from(rng.direction() * (0.01 * case.size));
        let near = nudge * case.pb;
        let asked = distance(&a, &case.pa, &b, &near, &o, None).and_then(|prev| {
            let cold = distance(&a, &case.pa, &b, &case.pb, &o, None)?;
            let warm = distance(&a, &case.pa, &b, &case.pb, &o, Some(&prev.warm_start))?;
            let single = Options {
                precision: gjk::Precision::Single,
                ..o
            };
            let f32 = distance(&a, &case.pa, &b, &case.pb, &single, None)?;
            let u = union(&case);
            let prev = distance(&u, &case.pa, &b, &near, &o, None)?;
            let union_cold = distance(&u, &case.pa, &b, &case.pb, &o, None)?;
            let union_warm = distance(&u, &case.pa, &b, &case.pb, &o, Some(&prev.warm_start))?;
            Ok([
                ("cold", cold),
                ("warm", warm),
                ("single", f32),
                ("union", union_cold),
                ("union warm", union_warm),
            ])
        });
        let answers = match asked {
            Ok(x) => x,
            Err(e) => {
                out.push(format!("{}: error {e:?}", case.describe()));
                continue;
            }
        };
        for (how, ans) in answers {
            let why = if how == "single" {
                check_single(&case, &ans)
            } else {
                check(&case, &ans)
            };
            if !why.is_empty() {
                out.push(format!(
                    "{} ({how}): got {:e} [{:e}, {:e}] pen {:e} after {} iterations: {}",
                    case.describe(),
                    ans.distance,
                    ans.lower,
                    ans.upper,
                    ans.penetration,
                    ans.iterations,
                    why.join("; ")
                ));
            }
        }
    }
    (n, out)
}

/// One found case against its truth, computed in exact rational arithmetic
/// from the f64 inputs (the minimum over vertex-triangle and edge-edge pairs,
/// the hulls being disjoint by construction): the distance within 1e-9 of
/// the size, the bounds around the truth and no wider than that, and
/// converged.
#[track_caller]
fn found(
    a: &gjk::Shape,
    pa: &nalgebra::Isometry3<f64>,
    b: &gjk::Shape,
    pb: &nalgebra::Isometry3<f64>,
    truth: f64,
    size: f64,
) {
    let ans = distance(a, pa, b, pb, &Options::default(), None).unwrap();
    assert!(
        (ans.distance - truth).abs() <= 1e-9 * size,
        "{truth:e}: {ans:?}"
    );
    let eps = 1e-15 * size;
    assert!(
        ans.lower <= truth + eps && truth <= ans.upper + eps,
        "{truth:e}: {ans:?}"
    );
    assert_eq!(ans.status, Status::Converged, "{ans:?}");
}

/// Copies of `body` as pieces of a union, none nearer to the other body than
/// `body` itself: each copy is turned (or not), shrunk about its centre (or
/// not) and placed so that its reach along `u` (the body-frame direction
/// towards the other body) is `body`'s own less a drawn `δ` from 0 (a tie) to
/// 3 sizes, and slid across `u` by up to 2 sizes. The construction puts the
/// other body's core beyond the plane where `body`'s reach along `u` ends, so
/// each copy stays behind that plane and the union's distance is the case's
/// truth. `body` itself is one of the pieces, at a drawn place in the order.
fn copies(
    rng: &mut Rng,
    body: &sweep::Body,
    u: &sweep::V,
    size: f64,
) -> (gjk::Shape, Vec<(nalgebra::Isometry3<f64>, gjk::Convex)>) {
    let reach = |vertices: &[sweep::P], r: f64| {
        vertices
            .iter()
            .map(|x| u.dot(&x.coords))
            .fold(f64::NEG_INFINITY, f64::max)
            + r
    };
    let own = reach(&body.vertices, body.radius);
    let centre = body.centre();
    let count = 1 + rng.below(4);
    let mut pieces = vec![(
        nalgebra::Isometry3::identity(),
        gjk::Convex::new(body.vertices.clone(), body.radius).unwrap(),
    )];
    for _ in 0..count {
        let turn = if rng.below(2) == 0 {
            nalgebra::UnitQuaternion::identity()
        } else {
            rng.rotation()
        };
        let (shrink, radius) = if rng.below(2) == 0 {
            (1.0, body.radius)
        } else {
            (rng.uniform(0.1, 0.9), body.radius * rng.unit_interval())
        };
        let vertices: Vec<sweep::P> = body
            .vertices
            .iter()
            .map(|x| centre + (x - centre) * shrink)
            .collect();
        let turned: Vec<sweep::P> = vertices.iter().map(|x| turn * x).collect();
        let delta = rng.pick(&[0.0, 1e-9, 1e-6, 1e-3, 0.1, 1.0, 3.0]) * size;
        let across = rng.direction();
        let across = (across - u * u.dot(&across)) * (rng.uniform(0.0, 2.0) * size);
        let t = u * (own - reach(&turned, radius) - delta) + across;
        pieces.push((
            nalgebra::Isometry3::from_parts(t.into(), turn),
            gjk::Convex::new(vertices, radius).unwrap(),
        ));
    }
    rng.shuffle(&mut pieces);
    let shape = gjk::Compound::new(pieces.clone()).unwrap().into();
    (shape, pieces)
}
