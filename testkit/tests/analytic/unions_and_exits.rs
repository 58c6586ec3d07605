//! Compounds, penetration bounds, margins, iteration caps and warm
//! starts whose answers are known exactly.

use super::*;

// ---------------------------------------------------------------------------
// Compounds

#[test]
fn compound_reports_the_realising_pieces() {
    let ball = Convex::sphere(0.3).unwrap();
    let bar = Convex::capsule(p(-1., 0., 0.), p(1., 0., 0.), 0.05).unwrap();
    let dumbbell: Shape = Compound::new(vec![
        (iso(-1., 0., 0.), ball.clone()),
        (Isometry3::identity(), bar),
        (iso(1., 0., 0.), ball),
    ])
    .unwrap()
    .into();
    let probe: Shape = Convex::sphere(0.2).unwrap().into();
    let o = iso(0., 0., 0.);
    // Near the right ball.
    let ans = query(&dumbbell, &o, &probe, &iso(3., 0., 0.));
    assert_distance(&ans, 2.0 - 0.3 - 0.2, 1e-14);
    assert_eq!(ans.pieces, [2, 0]);
    assert_eq!(ans.warm_start.pieces(), [2, 0]);
    // Above the bar's middle: the bar (1) wins over the balls.
    let ans = query(&dumbbell, &o, &probe, &iso(0., 1., 0.));
    assert_distance(&ans, 1.0 - 0.05 - 0.2, 1e-14);
    assert_eq!(ans.pieces, [1, 0]);
    // Swapped argument order: pieces are [piece of A, piece of B].
    let ans = query(&probe, &o, &dumbbell, &iso(0., -1., 0.));
    assert_distance(&ans, 1.0 - 0.05 - 0.2, 1e-14);
    assert_eq!(ans.pieces, [0, 1]);
    // Near the left ball, rotated compound: the left ball sits at R·(-1, 0, 0).
    let rot =
        UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
    let pose = Isometry3::from_parts(Translation3::new(0., 0., 0.), rot);
    let ans = query(&dumbbell, &pose, &probe, &iso(0., -3., 0.));
    assert_distance(&ans, 2.0 - 0.3 - 0.2, 1e-14);
    assert_eq!(ans.pieces, [0, 0]);
    // Two compounds: the nearest pair is (0 of A, 2 of B) after B is turned.
    let pose_b = Isometry3::from_parts(Translation3::new(-5., 0., 0.), UnitQuaternion::identity());
    let ans = query(&dumbbell, &o, &dumbbell, &pose_b);
    // Right ball of B at x = -4, left ball of A at x = -1.
    assert_distance(&ans, 3.0 - 0.6, 1e-14);
    assert_eq!(ans.pieces, [0, 2]);
}

/// Two long bars side by side, a small box beside the first: the bars'
/// bounding spheres both overlap the box's, so only a run, or the nearest
/// pair's normal as a separating axis, shows the second bar to be farther.
/// The axis proves it with two support searches: the union costs exactly the
/// iterations of its nearest pair alone (before, the second pair ran until
/// its own lower bound passed the first's distance). Far from the origin and
/// turned, as a scene would place it.
#[test]
fn compound_piece_behind_the_nearest_costs_no_iteration() {
    let bar = Convex::cuboid(v(0.1, 5.0, 0.1), 0.0).unwrap();
    let bars: Shape = Compound::new(vec![
        (iso(0., 0., 0.), bar.clone()),
        (iso(1., 0., 0.), bar.clone()),
    ])
    .unwrap()
    .into();
    let probe: Shape = Convex::cuboid(v(0.1, 0.1, 0.1), 0.0).unwrap().into();
    let turn = UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7);
    let place = |x: f64| {
        Isometry3::from_parts(Translation3::new(1e3, -2e3, 5e2), turn)
            * Isometry3::translation(x, 0.3, 0.0)
    };
    let (pa, pb) = (place(0.0) * iso(0., -0.3, 0.), place(-1.0));
    let ans = query(&bars, &pa, &probe, &pb);
    assert_distance(&ans, 0.8, 1e-12);
    assert_eq!(ans.pieces, [0, 0]);
    // The first bar alone, at the same place: the same run.
    let alone = query(&bar.into(), &pa, &probe, &pb);
    assert_distance(&alone, 0.8, 1e-12);
    assert_eq!(ans.iterations, alone.iterations, "{ans:?}\n{alone:?}");
    // Put the probe between the bars: neither can be proven farther by the
    // other's axis, both pairs run, and the nearer (the second) is named.
    let between = place(0.6);
    let ans = query(&bars, &pa, &probe, &between);
    assert_distance(&ans, 0.2, 1e-12);
    assert_eq!(ans.pieces, [1, 0]);
}

// ---------------------------------------------------------------------------
// Penetration

#[test]
fn penetration_exact_when_only_shells_overlap() {
    // Rounded boxes whose cores are 0.4 apart face to face, radii 0.3 each.
    let a: Shape = Convex::cuboid(v(1., 1., 1.), 0.3).unwrap().into();
    let ans = query(&a, &iso(0., 0., 0.), &a, &iso(0.1, 2.4, -0.2));
    assert_distance(&ans, 0.0, 0.0);
    assert!((ans.penetration - 0.2).abs() < 1e-14, "{ans:?}");
    assert_vec(&ans.normal, &v(0., 1., 0.), 1e-14);
    assert!((ans.point_b - ans.point_a + ans.normal * ans.penetration).norm() < 1e-14);
    // Point–triangle core with a large radius.
    let tri = convex(&[p(0., 0., 0.), p(4., 0., 0.), p(0., 4., 0.)], 0.0);
    let ball: Shape = Convex::sphere(1.5).unwrap().into();
    let ans = query(&tri, &iso(0., 0., 0.), &ball, &iso(1., 1., 1.));
    assert!((ans.penetration - 0.5).abs() < 1e-14, "{ans:?}");
    // Separated shapes have zero penetration.
    let ans = query(&a, &iso(0., 0., 0.), &a, &iso(0., 0., 3.0));
    assert_eq!(ans.penetration, 0.0);
    assert_distance(&ans, 0.4, 1e-14);
}

/// A union's penetration bound is its deepest piece pair's, whichever pair
/// the answer names. A ball of radius 1 at the origin against a long capsule
/// (radius 1, core 1.9 above the origin: shells 0.1 deep) and a ball of
/// radius 1 at x = 1 (shells 1.0 deep). The capsule's loose bounding sphere
/// puts it first, and both overlapping pairs report distance 0, so the capsule
/// is named; before, only its 0.1 was reported. Separating the ball from the
/// union needs at least 1.0 (from the ball piece alone) and at most √3
/// (moving it along -y clears both).
#[test]
fn compound_penetration_is_the_deepest_pairs() {
    let a: Shape = Compound::new(vec![
        (
            iso(0., 1.9, 0.),
            Convex::capsule(p(-10., 0., 0.), p(10., 0., 0.), 1.0).unwrap(),
        ),
        (iso(1., 0., 0.), Convex::sphere(1.0).unwrap()),
    ])
    .unwrap()
    .into();
    let ball: Shape = Convex::sphere(1.0).unwrap().into();
    let ans = query(&a, &iso(0., 0., 0.), &ball, &iso(0., 0., 0.));
    assert_distance(&ans, 0.0, 0.0);
    assert_eq!(ans.pieces, [0, 0], "{ans:?}");
    assert!((ans.penetration - 1.0).abs() < 1e-14, "{ans:?}");
    assert!(ans.penetration <= 3f64.sqrt(), "{ans:?}");
}

// ---------------------------------------------------------------------------
// Margins

#[test]
fn margin_early_exits() {
    let a: Shape = Convex::cuboid(v(1., 1., 1.), 0.0).unwrap().into();
    let b: Shape = Convex::sphere(0.5).unwrap().into();
    let o = iso(0., 0., 0.);
    let pb = iso(4.0, 0.3, -0.2); // distance 2.5
    let with = |m: f64| {
        let opt = Options {
            margin: Some(m),
            ..Options::default()
        };
        distance(&a, &o, &b, &pb, &opt, None).unwrap()
    };
    for m in [0.0, 1.0, 2.4] {
        let ans = with(m);
        match ans.status {
            Status::Farther => assert!(ans.lower > m, "margin {m}: {ans:?}"),
            Status::Converged => assert!((ans.distance - 2.5).abs() < 1e-14, "margin {m}: {ans:?}"),
            _ => panic!("margin {m}: {ans:?}"),
        }
        assert!(ans.lower <= 2.5 && 2.5 <= ans.upper, "margin {m}: {ans:?}");
    }
    for m in [2.6, 3.0, 100.0] {
        let ans = with(m);
        match ans.status {
            Status::Closer => assert!(ans.upper <= m, "margin {m}: {ans:?}"),
            Status::Converged => assert!((ans.distance - 2.5).abs() < 1e-14, "margin {m}: {ans:?}"),
            _ => panic!("margin {m}: {ans:?}"),
        }
        assert!(ans.lower <= 2.5 && 2.5 <= ans.upper, "margin {m}: {ans:?}");
    }
    // Far inside the margin: decided on the first iterate.
    let ans = with(100.0);
    assert_eq!(ans.status, Status::Closer, "{ans:?}");
    assert_eq!(ans.iterations, 1, "{ans:?}");
    // Far beyond the margin: decided on the first iterate, before convergence.
    let ans = with(0.1);
    assert_eq!(ans.status, Status::Farther, "{ans:?}");
    assert_eq!(ans.iterations, 1, "{ans:?}");
}

/// An iteration cap never ends a run `Converged` short of the tolerance.
/// Two triangles with nearly parallel edges, exactly `h` apart: A's vertices
/// have y <= 0 and B's y >= h, and the edges (-1, 0, 0)–(1, 0, 0) and
/// (-1, h, 0.1)–(1, h, -0.1) cross at x = 0. After 2 iterations the
/// paper's rule (6.2) holds, which near contact allows |v| up to √ε·D off:
/// the run stopped there at 1.0000000050e-8 in [9.93e-9, 1.000005e-8] and
/// said `Converged`, where a run without the cap goes on to the truth.
#[test]
fn an_iteration_cap_never_claims_convergence_short_of_the_tolerance() {
    let a = convex(&[p(-1., 0., 0.), p(1., 0., 0.), p(0., -1., 0.3)], 0.0);
    let b = convex(&[p(-1., 0., 0.1), p(1., 0., -0.1), p(0.2, 1., 0.)], 0.0);
    for h in [1e-6, 1e-8] {
        let pb = iso(0., h, 0.);
        let full = query(&a, &iso(0., 0., 0.), &b, &pb);
        // ε·D is 5e-14 here (D, the size bound of (6.4), about 2.4).
        assert_distance(&full, h, 1e-13);
        assert_eq!(full.status, Status::Converged);
        for max_iterations in 1..=full.iterations + 1 {
            let opt = Options {
                max_iterations,
                ..Options::default()
            };
            let ans = distance(&a, &iso(0., 0., 0.), &b, &pb, &opt, None).unwrap();
            assert!(ans.lower <= h && h <= ans.upper, "{ans:?}");
            if ans.status == Status::Converged {
                // Within the tolerance's own interval (2 slack + 4 ε·D,
                // about 3e-13 here), not just (6.2)'s.
                assert!(
                    ans.upper - ans.lower <= 1e-12,
                    "cap {max_iterations}: {ans:?}"
                );
                assert_distance(&ans, h, 1e-13);
            } else {
                assert_eq!(ans.status, Status::IterationCap, "{ans:?}");
            }
        }
        let ans = distance(
            &a,
            &iso(0., 0., 0.),
            &b,
            &pb,
            &Options {
                max_iterations: 2,
                ..Options::default()
            },
            None,
        )
        .unwrap();
        assert_eq!(ans.status, Status::IterationCap, "{ans:?}");
    }
}

/// The distance after radii is never negative, so no negative margin can be
/// "Closer" (the doc: Closer = "the upper bound proved the distance at most
/// this margin"). A rounded cube (half extent 1, radius 1) and a unit sphere at
/// (1.8, 0.3, 0.2): cores 0.8 apart, distance 0. With margin -0.5 the first
/// iterate has |v| - rA - rB ≈ -0.67 <= -0.5 and the query says Closer; the
/// unclamped `norm - radii` is compared with the margin.
#[test]
fn negative_margin_is_never_closer() {
    let a: Shape = Convex::cuboid(v(1., 1., 1.), 1.0).unwrap().into();
    let b: Shape = Convex::sphere(1.0).unwrap().into();
    let opt = Options {
        margin: Some(-0.5),
        ..Options::default()
    };
    let ans = distance(&a, &iso(0., 0., 0.), &b, &iso(1.8, 0.3, 0.2), &opt, None).unwrap();
    assert_eq!(ans.lower, 0.0);
    assert_ne!(
        ans.status,
        Status::Closer,
        "distance 0 reported at most -0.5: {ans:?}"
    );
}

/// A compound's certified lower bound must hold for the whole union, also on
/// an early `Closer` exit. B is a point at the origin. A has two pieces: a
/// pentahedron whose nearest edge, (-0.1, 2, 0)–(0.1, 2, 0), is at distance 2
/// (its loose bounding sphere puts it first in the visiting order), and a
/// point at (0, -1.4, 0), distance 1.4. With margin 2.5 the first piece exits
/// Closer after one iterate (upper 2.0025 <= 2.5, lower 1.9925) and the loop
/// stops: the point never enters the union's lower bound.
#[test]
fn compound_closer_exit_keeps_a_valid_lower_bound() {
    let wedge = Convex::new(
        vec![
            p(-0.1, 2., 0.),
            p(0.1, 2., 0.),
            p(-10., 12., -10.),
            p(10., 12., -10.),
            p(0., 12., 10.),
        ],
        0.0,
    )
    .unwrap();
    let a: Shape = Compound::new(vec![
        (Isometry3::identity(), wedge),
        (iso(0., -1.4, 0.), Convex::sphere(0.0).unwrap()),
    ])
    .unwrap()
    .into();
    let b: Shape = Convex::sphere(0.0).unwrap().into();
    let o = Isometry3::identity();
    let truth = 1.4;
    let exact = query(&a, &o, &b, &o);
    assert_distance(&exact, truth, 1e-14);
    assert_eq!(exact.pieces, [1, 0]);
    let opt = Options {
        margin: Some(2.5),
        ..Options::default()
    };
    let ans = distance(&a, &o, &b, &o, &opt, None).unwrap();
    assert_eq!(ans.status, Status::Closer, "{ans:?}");
    assert!(
        ans.lower <= truth && truth <= ans.upper,
        "bounds [{}, {}] miss the union's distance {truth}: {ans:?}",
        ans.lower,
        ans.upper
    );
}

// ---------------------------------------------------------------------------
// Warm starts given by the caller

/// A warm start whose four vertex pairs form a flat tetrahedron: A is a square
/// (rotated, so its coordinates are inexact), B a point 3 above its centre
/// region. The warm simplex {a_i - b} is planar and far from the origin, yet
/// the query reports the shapes intersecting: distance 0, bounds [0, 1e-13].
/// (Found by `arbitrary_warm_starts_give_the_right_answer` with other seeds.)
#[test]
fn flat_warm_start_tetrahedron_is_not_an_intersection() {
    let square = [
        p(0.9252519317223473, 1.059207109038768, 0.14828743374204026),
        p(-0.7782435047981567, 0.5322542194784073, 1.054060004500177),
        p(
            -0.9252519317223473,
            -1.059207109038768,
            -0.14828743374204026,
        ),
        p(0.7782435047981567, -0.5322542194784073, -1.054060004500177),
    ];
    let point = [p(
        1.734011821721056,
        -1.5037438258200821,
        1.9447255612141285,
    )];
    let truth = hull_distance(&square, &point).distance;
    assert!((truth - 3.0).abs() < 1e-12, "test setup: {truth}");
    let a = convex(&square, 0.0);
    let b = convex(&point, 0.0);
    let o = Isometry3::identity();
    assert_distance(&query(&a, &o, &b, &o), truth, 1e-12);
    let w = WarmStart::new([0, 0], &[[0, 0], [1, 0], [2, 0], [3, 0]]).unwrap();
    let ans = distance(&a, &o, &b, &o, &Options::default(), Some(&w)).unwrap();
    assert_distance(&ans, truth, 1e-12);
}

/// A warm start of three collinear vertex pairs (a degenerate triangle): the
/// query ends in ToleranceNotMet with a relative error of 2.5e-6 instead of
/// converging. A: three collinear points (a rotated segment from -1 to 1 with
/// an interior point), B: a point.
#[test]
fn collinear_warm_start_triangle_still_converges() {
    let line = [
        p(
            -0.7576276233409753,
            -0.23436168760494958,
            0.6091592433294148,
        ),
        p(0.7576276233409753, 0.23436168760494958, -0.6091592433294148),
        p(
            0.2272882870022926,
            0.07030850628148488,
            -0.18274777299882441,
        ),
    ];
    let point = [p(
        1.7609164767785408,
        -2.2214617869118056,
        1.0071150336979677,
    )];
    let truth = hull_distance(&line, &point).distance;
    assert!(
        (truth - 9.01f64.sqrt()).abs() < 1e-12,
        "test setup: {truth}"
    );
    let a = convex(&line, 0.0);
    let b = convex(&point, 0.0);
    let o = Isometry3::identity();
    assert_distance(&query(&a, &o, &b, &o), truth, 1e-12);
    let w = WarmStart::new([0, 0], &[[0, 0], [1, 0], [2, 0]]).unwrap();
    let ans = distance(&a, &o, &b, &o, &Options::default(), Some(&w)).unwrap();
    assert_distance(&ans, truth, 1e-12);
}

/// Cores touching exactly: a unit cube, and a turned unit cube whose lowest
/// corner lies on the first cube's face x = 1 (computed world x: exactly 1).
/// The true depth is 0 (up to round-off, 1e-16); the reported penetration
/// "lower bound" is 8.7e-9, from the inner radius of a tetrahedron whose face
/// passes through the origin, computed as the square root of (5.10).
#[test]
fn touching_cores_penetration_is_at_most_the_depth() {
    let cube: Shape = Convex::cuboid(v(1., 1., 1.), 0.0).unwrap().into();
    let rot = Unit::new_unchecked(Quaternion::new(
        0.9838313410528056,
        0.14869156426260063,
        -0.014918919342160731,
        -0.0987123949919223,
    ));
    let pb = Isometry3::from_parts(
        Translation3::new(2.2285734405137556, 1.2272535104146536, -0.5598162824642664),
        rot,
    );
    let corners = Convex::cuboid(v(1., 1., 1.), 0.0)
        .unwrap()
        .vertices()
        .to_vec();
    let min_x = corners
        .iter()
        .map(|c| (pb * c).x)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(min_x, 1.0, "test setup");
    let depth = 1.0 - min_x;
    let ans = query(&cube, &Isometry3::identity(), &cube, &pb);
    assert_distance(&ans, 0.0, 1e-14);
    assert!(
        ans.penetration <= depth + 1e-12,
        "penetration {:e} exceeds the depth {depth:e}: {ans:?}",
        ans.penetration
    );
}
