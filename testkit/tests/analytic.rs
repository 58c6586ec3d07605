//! Closed-form cases: every expected value below is computed by hand (or by the
//! independent brute force of `gjkd_testkit::reference`), never by GJK. Also
//! every error path.

use std::panic::{AssertUnwindSafe, catch_unwind};

use gjk::{Answer, Compound, Convex, Error, Options, Shape, Status, WarmStart, distance};
use gjkd_testkit::input::{p, v};
use gjkd_testkit::reference::{
    P, V, aabb_distance, closest_on_segment, hull_distance, penetration_depth,
};
use nalgebra::{Isometry3, Quaternion, Translation3, Unit, UnitQuaternion};

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
// Spheres

#[test]
fn sphere_sphere_separated() {
    let a: Shape = Convex::sphere(1.0).unwrap().into();
    let b: Shape = Convex::sphere(0.5).unwrap().into();
    let (pa, pb) = (iso(1.0, 2.0, 3.0), iso(4.0, 6.0, 3.0)); // centres 5 apart
    let ans = query(&a, &pa, &b, &pb);
    assert_distance(&ans, 3.5, 1e-14);
    assert_vec(&ans.normal, &v(0.6, 0.8, 0.0), 1e-15);
    assert_point(&ans.point_a, &p(1.6, 2.8, 3.0), 1e-14);
    assert_point(&ans.point_b, &p(3.7, 5.6, 3.0), 1e-14);
    assert_eq!(ans.penetration, 0.0);
    assert_eq!(ans.pieces, [0, 0]);
}

#[test]
fn sphere_sphere_touching_and_overlapping() {
    let a: Shape = Convex::sphere(1.0).unwrap().into();
    let b: Shape = Convex::sphere(0.5).unwrap().into();
    // Touching: centres 1.5 apart.
    let ans = query(&a, &iso(0., 0., 0.), &b, &iso(0., 0., 1.5));
    assert_distance(&ans, 0.0, 1e-15);
    assert!(ans.penetration.abs() <= 1e-15);
    assert_point(&ans.point_a, &p(0., 0., 1.), 1e-15);
    assert_point(&ans.point_b, &p(0., 0., 1.), 1e-15);
    // Overlapping shells only: exact penetration rA + rB - |c|.
    let ans = query(&a, &iso(0., 0., 0.), &b, &iso(0., 1.0, 0.));
    assert_distance(&ans, 0.0, 0.0);
    assert!((ans.penetration - 0.5).abs() <= 1e-15, "{ans:?}");
    assert_vec(&ans.normal, &v(0., 1., 0.), 1e-15);
    // Deepest points along the normal: b - a = -penetration · normal.
    assert_point(&ans.point_a, &p(0., 1., 0.), 1e-15);
    assert_point(&ans.point_b, &p(0., 0.5, 0.), 1e-15);
    // Concentric: cores coincide; normal undefined, penetration rA + rB.
    let ans = query(&a, &iso(2., 2., 2.), &b, &iso(2., 2., 2.));
    assert_distance(&ans, 0.0, 0.0);
    assert_eq!(ans.normal, V::zeros());
    assert!((ans.penetration - 1.5).abs() <= 1e-15);
}

// ---------------------------------------------------------------------------
// Boxes

#[test]
fn boxes_separated_along_axis_and_diagonal() {
    let ha = v(1.0, 2.0, 3.0);
    let hb = v(0.5, 0.5, 0.5);
    let a: Shape = Convex::cuboid(ha, 0.0).unwrap().into();
    let b: Shape = Convex::cuboid(hb, 0.0).unwrap().into();
    // Face to face along x: gap 0.25.
    let ans = query(&a, &iso(0., 0., 0.), &b, &iso(1.75, 0.3, -1.0));
    assert_distance(&ans, 0.25, 1e-15);
    assert_vec(&ans.normal, &v(1., 0., 0.), 1e-14);
    assert!((ans.point_a.x - 1.0).abs() < 1e-14 && (ans.point_b.x - 1.25).abs() < 1e-14);
    assert!((ans.point_b - ans.point_a - ans.normal * ans.distance).norm() < 1e-14);
    // Corner to corner: gaps (1, 2, 3) on each axis.
    let cb = v(1.0 + 0.5 + 1.0, -(2.0 + 0.5 + 2.0), 3.0 + 0.5 + 3.0);
    let ans = query(
        &a,
        &iso(0., 0., 0.),
        &b,
        &Isometry3::from(Translation3::from(cb)),
    );
    let truth = aabb_distance(&V::zeros(), &ha, &cb, &hb);
    assert!((truth - 14f64.sqrt()).abs() < 1e-15);
    assert_distance(&ans, truth, 1e-14);
    assert_point(&ans.point_a, &p(1., -2., 3.), 1e-14);
    assert_point(&ans.point_b, &p(2., -4., 6.), 1e-14);
    // Edge to edge: gap on x and z only.
    let cb = v(2.5, 0.0, 4.5);
    let ans = query(
        &a,
        &iso(0., 0., 0.),
        &b,
        &Isometry3::from(Translation3::from(cb)),
    );
    assert_distance(&ans, 2f64.sqrt(), 1e-14);
}

#[test]
fn boxes_touching() {
    let a: Shape = Convex::cuboid(v(1., 1., 1.), 0.0).unwrap().into();
    // Face to face, exactly touching, offset so faces overlap partially.
    let ans = query(&a, &iso(0., 0., 0.), &a, &iso(2.0, 0.5, 0.5));
    assert_distance(&ans, 0.0, 1e-15);
    assert_eq!(ans.penetration, 0.0);
    // Corner to corner, exactly touching.
    let ans = query(&a, &iso(0., 0., 0.), &a, &iso(2.0, 2.0, 2.0));
    assert_distance(&ans, 0.0, 1e-15);
    assert_eq!(ans.penetration, 0.0);
}

#[test]
fn boxes_overlapping_penetration_is_a_bound() {
    let h = v(1., 1., 1.);
    let a: Shape = Convex::cuboid(h, 0.0).unwrap().into();
    for (offset, depth) in [
        (v(1.5, 0.2, 0.1), 0.5),
        (v(0.3, -1.2, 0.9), 0.8),
        (v(-1.9, 1.7, 1.95), 0.05),
        (v(0.05, -0.02, 0.01), 1.95),
    ] {
        let pose_b = Isometry3::from(Translation3::from(offset));
        let ans = query(&a, &iso(0., 0., 0.), &a, &pose_b);
        assert_distance(&ans, 0.0, 1e-14);
        assert_eq!(ans.normal, V::zeros(), "offset {offset:?}");
        assert!(
            ans.penetration > 0.0 && ans.penetration <= depth + 1e-14,
            "offset {offset:?}: penetration {} not in (0, {depth}]",
            ans.penetration
        );
    }
    // Rotated cube: depth from the brute-force SAT.
    let rot = UnitQuaternion::from_euler_angles(0.3, -0.5, 0.7);
    let pose_b = Isometry3::from_parts(Translation3::new(1.2, 0.4, -0.3), rot);
    let ans = query(&a, &iso(0., 0., 0.), &a, &pose_b);
    let pa: Vec<P> = Convex::cuboid(h, 0.).unwrap().vertices().to_vec();
    let pb: Vec<P> = pa.iter().map(|x| pose_b * x).collect();
    let depth = penetration_depth(&pa, &pb);
    assert!(depth > 0.1, "test setup: depth {depth}");
    assert_distance(&ans, 0.0, 0.0);
    assert!(
        ans.penetration > 0.0 && ans.penetration <= depth + 1e-14,
        "penetration {} not in (0, {depth}]",
        ans.penetration
    );
}

/// Identical cubes at the same place: depth 2. The cold start's first support
/// point `s_A(0) - s_B(0)` is exactly the origin, so GJK stops with a single
/// point and reports a penetration bound of 0 for the deepest possible overlap.
#[test]
fn concentric_cubes_penetration_positive() {
    let a: Shape = Convex::cuboid(v(1., 1., 1.), 0.0).unwrap().into();
    let ans = query(&a, &iso(0., 0., 0.), &a, &iso(0., 0., 0.));
    assert_distance(&ans, 0.0, 0.0);
    assert!(
        ans.penetration > 0.0 && ans.penetration <= 2.0 + 1e-14,
        "identical cubes, depth 2: penetration {} not in (0, 2]; {ans:?}",
        ans.penetration
    );
}

/// Cubes overlapping by 0.1, 0.1, 0.05 on the axes (depth 0.05). The offset
/// puts the origin of the Minkowski difference exactly on the plane x + y = 0
/// spanned by three difference vertices; round-off leaves |v| ≈ 6e-17. That is
/// contact (zero normal), and the final simplex is a triangle through the
/// origin, so (5.9) proves no positive depth: the bound must be in [0, 0.05].
#[test]
fn symmetric_overlap_is_reported_as_intersection() {
    let a: Shape = Convex::cuboid(v(1., 1., 1.), 0.0).unwrap().into();
    let ans = query(&a, &iso(0., 0., 0.), &a, &iso(-1.9, 1.9, 1.95));
    assert_distance(&ans, 0.0, 1e-14);
    assert!(
        ans.normal == V::zeros() && ans.penetration >= 0.0 && ans.penetration <= 0.05 + 1e-14,
        "depth 0.05: want zero normal and penetration in [0, 0.05]; {ans:?}"
    );
}

#[test]
fn rounded_box_corner_and_face() {
    let a: Shape = Convex::cuboid(v(1., 1., 1.), 0.5).unwrap().into();
    let b: Shape = Convex::sphere(0.25).unwrap().into();
    // Along the corner diagonal.
    let ans = query(&a, &iso(0., 0., 0.), &b, &iso(3., 3., 3.));
    let truth = 2.0 * 3f64.sqrt() - 0.5 - 0.25;
    assert_distance(&ans, truth, 1e-14);
    let dir = v(1., 1., 1.) / 3f64.sqrt();
    assert_vec(&ans.normal, &dir, 1e-14);
    assert_point(&ans.point_a, &(p(1., 1., 1.) + dir * 0.5), 1e-14);
    assert_point(&ans.point_b, &(p(3., 3., 3.) - dir * 0.25), 1e-14);
    // Facing a face.
    let ans = query(&a, &iso(0., 0., 0.), &b, &iso(0.2, 3.0, -0.4));
    assert_distance(&ans, 3.0 - 1.0 - 0.5 - 0.25, 1e-14);
    // Rounded boxes, rotated pose of both: face to face in the relative frame.
    let rot = UnitQuaternion::from_euler_angles(1.0, 0.2, -0.4);
    let pa = Isometry3::from_parts(Translation3::new(5., -1., 2.), rot);
    let pb = pa * iso(0.3, 0.1, 3.0);
    let ans = query(&a, &pa, &a, &pb);
    assert_distance(&ans, 3.0 - 2.0 - 1.0, 1e-13);
    assert_vec(&ans.normal, &(rot * v(0., 0., 1.)), 1e-13);
}

// ---------------------------------------------------------------------------
// Capsules and segments

#[test]
fn capsule_capsule_crossing_and_parallel() {
    // Perpendicular axes, 3 apart along z.
    let a: Shape = Convex::capsule(p(-2., 0., 0.), p(2., 0., 0.), 0.5)
        .unwrap()
        .into();
    let b: Shape = Convex::capsule(p(0., -2., 0.), p(0., 2., 0.), 0.25)
        .unwrap()
        .into();
    let ans = query(&a, &iso(0., 0., 0.), &b, &iso(0.5, -0.7, 3.0));
    assert_distance(&ans, 3.0 - 0.75, 1e-14);
    assert_point(&ans.point_a, &p(0.5, 0., 0.5), 1e-14);
    assert_point(&ans.point_b, &p(0.5, 0., 2.75), 1e-14);
    // Parallel, overlapping in projection, 2 apart.
    let ans = query(&a, &iso(0., 0., 0.), &a, &iso(1.0, 2.0, 0.0));
    assert_distance(&ans, 1.0, 1e-14);
    // Collinear, end to end, gap 1 between the caps.
    let ans = query(&a, &iso(0., 0., 0.), &a, &iso(6.0, 0.0, 0.0));
    assert_distance(&ans, 6.0 - 4.0 - 1.0, 1e-14);
    assert_vec(&ans.normal, &v(1., 0., 0.), 1e-15);
    // Shells overlap only: exact penetration.
    let ans = query(&a, &iso(0., 0., 0.), &b, &iso(1.0, 0.0, 0.6));
    assert_distance(&ans, 0.0, 0.0);
    assert!((ans.penetration - (0.75 - 0.6)).abs() < 1e-14, "{ans:?}");
}

#[test]
fn segment_segment_cases() {
    let seg = |a: P, b: P| convex(&[a, b], 0.0);
    let o = iso(0., 0., 0.);
    let cases: [(P, P, P, P, f64); 8] = [
        // skew, interior-interior
        (
            p(-1., 0., 0.),
            p(1., 0., 0.),
            p(0., -1., 2.),
            p(0., 1., 2.),
            2.0,
        ),
        // parallel, offset 1, overlapping projection
        (
            p(0., 0., 0.),
            p(2., 0., 0.),
            p(1., 1., 0.),
            p(5., 1., 0.),
            1.0,
        ),
        // parallel, disjoint projection: end to end
        (
            p(0., 0., 0.),
            p(1., 0., 0.),
            p(4., 4., 0.),
            p(5., 4., 0.),
            5.0,
        ),
        // collinear, separated
        (
            p(0., 0., 0.),
            p(1., 0., 0.),
            p(3., 0., 0.),
            p(7., 0., 0.),
            2.0,
        ),
        // collinear, overlapping
        (
            p(0., 0., 0.),
            p(3., 0., 0.),
            p(1., 0., 0.),
            p(7., 0., 0.),
            0.0,
        ),
        // crossing in a plane
        (
            p(-1., 0., 0.),
            p(1., 0., 0.),
            p(0., -1., 0.),
            p(0., 1., 0.),
            0.0,
        ),
        // T: endpoint to interior
        (
            p(-1., 0., 0.),
            p(1., 0., 0.),
            p(0.3, 0.5, 0.),
            p(0.3, 4., 0.),
            0.5,
        ),
        // degenerate: a segment and a point (repeated vertex)
        (
            p(-1., 0., 0.),
            p(1., 0., 0.),
            p(3., 4., 0.),
            p(3., 4., 0.),
            20f64.sqrt(),
        ),
    ];
    for (a0, a1, b0, b1, truth) in cases {
        let ans = query(&seg(a0, a1), &o, &seg(b0, b1), &o);
        let r = hull_distance(&[a0, a1], &[b0, b1]).distance;
        assert!((r - truth).abs() < 1e-14, "reference {r} vs {truth}");
        assert_distance(&ans, truth, 1e-14);
    }
}

#[test]
fn point_triangle_regions() {
    let tri = convex(&[p(0., 0., 0.), p(4., 0., 0.), p(0., 4., 0.)], 0.0);
    let pt: Shape = Convex::sphere(0.0).unwrap().into();
    let o = iso(0., 0., 0.);
    let cases = [
        (p(1., 1., 2.), 2.0, p(1., 1., 0.)),           // face region
        (p(-1., -2., 0.), 5f64.sqrt(), p(0., 0., 0.)), // vertex region
        (p(2., -3., 4.), 5.0, p(2., 0., 0.)),          // edge region
        (p(3., 3., 0.), 2f64.sqrt(), p(2., 2., 0.)),   // hypotenuse, in plane
        (p(1., 1., 0.), 0.0, p(1., 1., 0.)),           // on the face
        (p(5., 5., -1.), (18f64 + 1.0).sqrt(), p(2., 2., 0.)), // hypotenuse, off plane
    ];
    for (x, truth, on_tri) in cases {
        let ans = query(
            &tri,
            &o,
            &pt,
            &Isometry3::from(Translation3::from(x.coords)),
        );
        assert_distance(&ans, truth, 1e-14);
        assert_point(&ans.point_a, &on_tri, 1e-14);
        assert_point(&ans.point_b, &x, 1e-14);
    }
}

/// A segment through a triangle just inside one edge (an overlap of depth
/// `δ` that no separating axis shows clearly) and just outside it (a gap of
/// exactly `δ`), for `δ` from 1e-3 to 1e-9: the brute force once took the
/// first for a gap of `δ`. Both it and GJK must tell the two apart.
#[test]
fn segment_piercing_a_triangle_near_its_edge() {
    let tri = [p(0., 0., 0.), p(2., 0., 0.), p(0., 2., 0.)];
    let a = convex(&tri, 0.0);
    for k in 3..=9 {
        let delta = 10f64.powi(-k);
        for (y, truth) in [(delta, 0.0), (-delta, delta)] {
            let seg = [p(0.7, y, -1.0), p(0.7, y, 1.0)];
            assert_eq!(
                hull_distance(&tri, &seg).distance,
                truth,
                "brute force, y = {y}"
            );
            let ans = query(&a, &iso(0., 0., 0.), &convex(&seg, 0.0), &iso(0., 0., 0.));
            assert_distance(&ans, truth, 1e-15);
            if truth == 0.0 {
                // Moving the segment out by δ (across the edge) separates.
                assert!(ans.penetration <= delta * (1.0 + 1e-9), "{ans:?}");
            } else {
                assert_point(&ans.point_a, &p(0.7, 0.0, 0.0), 1e-15);
            }
        }
    }
}

/// A point 1e-9 to 1e-13 from the middle of a tilted segment of length 1.5:
/// the distance is the gap itself. The brute force once called these
/// overlapping: its witness axis, from nearest points with round-off of
/// 1e-16, is tilted by 1e-16/gap and no other axis it tried was square to
/// the segment.
#[test]
fn point_a_hair_from_a_tilted_segment() {
    let rot = UnitQuaternion::from_euler_angles(0.3, -1.1, 0.7);
    let (a, b) = (rot * p(-0.5, 0.2, 0.1), rot * p(1.0, -0.4, 0.3));
    let mid = a + (b - a) * 0.37;
    let across = (b - a).cross(&v(0.2, 1.0, -0.3)).normalize();
    for k in 9..=13 {
        let gap = 10f64.powi(-k);
        let x = mid + across * gap;
        let truth = (closest_on_segment(&x, &a, &b) - x).norm();
        assert!(
            (truth - gap).abs() <= 1e-15,
            "closed form {truth} against {gap}"
        );
        let brute = hull_distance(&[x], &[a, b]).distance;
        assert!(
            (brute - truth).abs() <= 1e-15,
            "brute force {brute} against {truth}"
        );
        let point: Shape = Convex::sphere(0.0).unwrap().into();
        let ans = query(
            &convex(&[a, b], 0.0),
            &iso(0., 0., 0.),
            &point,
            &Isometry3::from(Translation3::from(x.coords)),
        );
        assert_distance(&ans, truth, 1e-15);
    }
}

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

// ---------------------------------------------------------------------------
// Failure paths: the right error for each bad input, and no panic.

fn no_panic<T>(what: &str, f: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|_| panic!("panicked on {what}"))
}

#[test]
fn constructor_errors() {
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let ok = p(0., 0., 0.);
    assert_eq!(
        no_panic("empty", || Convex::new(Vec::<P>::new(), 0.0)),
        Err(Error::EmptyVertices)
    );
    assert_eq!(
        no_panic("NaN vertex", || Convex::new(
            vec![ok, ok, p(0., nan, 0.)],
            0.0
        )),
        Err(Error::NonFiniteVertex(2))
    );
    assert_eq!(
        no_panic("inf vertex", || Convex::new(vec![p(inf, 0., 0.), ok], 0.0)),
        Err(Error::NonFiniteVertex(0))
    );
    assert_eq!(
        no_panic("-inf vertex", || Convex::new(
            vec![ok, p(0., 0., -inf)],
            0.0
        )),
        Err(Error::NonFiniteVertex(1))
    );
    // Finite vertices whose spread overflows.
    assert!(matches!(
        no_panic("overflowing spread", || Convex::new(
            vec![p(-1.7e308, 0., 0.), p(1.7e308, 0., 0.)],
            0.0
        )),
        Err(Error::NonFiniteVertex(_))
    ));
    assert_eq!(
        no_panic("negative radius", || Convex::sphere(-1.0)),
        Err(Error::InvalidRadius(-1.0))
    );
    assert!(matches!(
        no_panic("NaN radius", || Convex::new(vec![ok], nan)),
        Err(Error::InvalidRadius(r)) if r.is_nan()
    ));
    assert_eq!(
        no_panic("inf radius", || Convex::new(vec![ok], inf)),
        Err(Error::InvalidRadius(inf))
    );
    assert_eq!(
        no_panic("NaN capsule", || Convex::capsule(ok, p(nan, 0., 0.), 1.0)),
        Err(Error::NonFiniteVertex(1))
    );
    assert!(matches!(
        no_panic("negative half extent", || Convex::cuboid(
            v(1., -1., 1.),
            0.0
        )),
        Err(Error::NonFiniteVertex(_))
    ));
    assert!(matches!(
        no_panic("NaN half extent", || Convex::cuboid(v(1., 1., nan), 0.0)),
        Err(Error::NonFiniteVertex(_))
    ));
    assert!(matches!(
        no_panic("cuboid bad radius", || Convex::cuboid(v(1., 1., 1.), -0.5)),
        Err(Error::InvalidRadius(_))
    ));
    // Zero is a valid radius and a valid half extent.
    assert!(Convex::sphere(0.0).is_ok());
    assert!(Convex::cuboid(v(0., 0., 0.), 0.0).is_ok());
    assert_eq!(
        no_panic("empty compound", || Compound::new(vec![])),
        Err(Error::EmptyCompound)
    );
    let piece = Convex::sphere(1.0).unwrap();
    assert_eq!(
        no_panic("NaN offset", || Compound::new(vec![(
            iso(0., nan, 0.),
            piece.clone()
        )])),
        Err(Error::NonFinitePose)
    );
    assert_eq!(
        no_panic("inf offset", || Compound::new(vec![
            (Isometry3::identity(), piece.clone()),
            (iso(inf, 0., 0.), piece.clone())
        ])),
        Err(Error::NonFinitePose)
    );
    // WarmStart holds at most four pairs.
    assert!(WarmStart::new([0, 0], &[[0, 0]; 5]).is_none());
    assert_eq!(
        WarmStart::new([0, 0], &[[1, 2], [3, 4]]).unwrap().pairs(),
        &[[1, 2], [3, 4]]
    );
}

#[test]
fn query_errors() {
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let a: Shape = Convex::cuboid(v(1., 1., 1.), 0.0).unwrap().into();
    let b: Shape = Convex::capsule(p(0., 0., 0.), p(0., 0., 1.), 0.1)
        .unwrap()
        .into();
    let o = Isometry3::identity();
    let far = iso(5., 0., 0.);
    let run = |pa: &Isometry3<f64>, pb: &Isometry3<f64>, opt: &Options, w: Option<&WarmStart>| {
        no_panic("query", || distance(&a, pa, &b, pb, opt, w))
    };
    let d = Options::default();
    // Poses.
    assert_eq!(
        run(&iso(nan, 0., 0.), &far, &d, None),
        Err(Error::NonFinitePose)
    );
    assert_eq!(
        run(&o, &iso(0., 0., -inf), &d, None),
        Err(Error::NonFinitePose)
    );
    let bad_rot = Isometry3::from_parts(
        Translation3::new(0., 0., 0.),
        Unit::new_unchecked(Quaternion::new(nan, 0., 0., 0.)),
    );
    assert_eq!(run(&o, &bad_rot, &d, None), Err(Error::NonFinitePose));
    // Options.
    for tolerance in [nan, -1e-3, inf] {
        let opt = Options { tolerance, ..d };
        assert!(
            matches!(run(&o, &far, &opt, None), Err(Error::InvalidOption(_))),
            "tolerance {tolerance}"
        );
    }
    let opt = Options {
        max_iterations: 0,
        ..d
    };
    assert!(matches!(
        run(&o, &far, &opt, None),
        Err(Error::InvalidOption(_))
    ));
    for m in [nan, inf, -inf] {
        let opt = Options {
            margin: Some(m),
            ..d
        };
        assert!(
            matches!(run(&o, &far, &opt, None), Err(Error::InvalidOption(_))),
            "margin {m}"
        );
    }
    // Edge values that are valid.
    assert!(
        run(
            &o,
            &far,
            &Options {
                tolerance: 0.0,
                ..d
            },
            None
        )
        .is_ok()
    );
    assert!(
        run(
            &o,
            &far,
            &Options {
                max_iterations: 1,
                ..d
            },
            None
        )
        .is_ok()
    );
    assert!(
        run(
            &o,
            &far,
            &Options {
                margin: Some(-1.0),
                ..d
            },
            None
        )
        .is_ok()
    );
    // Warm start indices: A has 8 vertices, B has 2; one piece each.
    let w = |pieces, pairs: &[[u32; 2]]| WarmStart::new(pieces, pairs).unwrap();
    assert_eq!(
        run(&o, &far, &d, Some(&w([0, 0], &[[8, 0]]))),
        Err(Error::WarmStartOutOfRange)
    );
    assert_eq!(
        run(&o, &far, &d, Some(&w([0, 0], &[[0, 0], [7, 2]]))),
        Err(Error::WarmStartOutOfRange)
    );
    assert_eq!(
        run(&o, &far, &d, Some(&w([1, 0], &[[0, 0]]))),
        Err(Error::WarmStartOutOfRange)
    );
    assert_eq!(
        run(&o, &far, &d, Some(&w([0, 1], &[[0, 0]]))),
        Err(Error::WarmStartOutOfRange)
    );
    assert_eq!(
        run(&o, &far, &d, Some(&w([0, 0], &[[u32::MAX, 0]]))),
        Err(Error::WarmStartOutOfRange)
    );
    // In range: the right answer (box face at x = 1, capsule axis at x = 5).
    let ans = run(&o, &far, &d, Some(&w([0, 0], &[[7, 1], [0, 0]]))).unwrap();
    assert!((ans.distance - 3.9).abs() < 1e-14, "{ans:?}");
    // An empty warm start is the cold start.
    let ans = run(&o, &far, &d, Some(&w([0, 0], &[]))).unwrap();
    assert!((ans.distance - 3.9).abs() < 1e-14, "{ans:?}");
}

#[test]
fn compound_warm_start_out_of_range() {
    let piece = Convex::cuboid(v(1., 1., 1.), 0.0).unwrap();
    let c: Shape = Compound::new(vec![
        (iso(-2., 0., 0.), piece.clone()),
        (iso(2., 0., 0.), piece),
    ])
    .unwrap()
    .into();
    let s: Shape = Convex::sphere(1.0).unwrap().into();
    let o = Isometry3::identity();
    let far = iso(0., 5., 0.);
    let d = Options::default();
    for (pieces, pairs) in [
        ([2, 0], [[0, 0]]),
        ([0, 1], [[0, 0]]),
        ([1, 0], [[8, 0]]),
        ([1, 0], [[0, 1]]),
    ] {
        let w = WarmStart::new(pieces, &pairs).unwrap();
        assert_eq!(
            no_panic("compound warm", || distance(&c, &o, &s, &far, &d, Some(&w))),
            Err(Error::WarmStartOutOfRange),
            "pieces {pieces:?} pairs {pairs:?}"
        );
    }
    let w = WarmStart::new([1, 0], &[[7, 0]]).unwrap();
    let ans = distance(&c, &o, &s, &far, &d, Some(&w)).unwrap();
    // Nearest point of piece 1 ([1, 3] × [-1, 1]²) to (0, 5, 0) is (1, 1, 0).
    assert!(
        (ans.distance - (17f64.sqrt() - 1.0)).abs() < 1e-14,
        "{ans:?}"
    );
    assert_eq!(ans.pieces, [1, 0]);
}

#[test]
fn overflowing_poses_are_an_error_not_a_panic() {
    // Finite inputs whose relative pose overflows f64.
    let a: Shape = Convex::cuboid(v(1., 1., 1.), 0.0).unwrap().into();
    let pa = iso(-1.7e308, 0., 0.);
    let pb = iso(1.7e308, 0., 0.);
    let got = no_panic("poses at ±1.7e308", || {
        distance(&a, &pa, &a, &pb, &Options::default(), None)
    });
    assert_eq!(got, Err(Error::NonFinitePose));
}
