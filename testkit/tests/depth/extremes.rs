//! Extremes: sizes from 1e-9 to 1e6, pairs 1e9 from the origin, one shape
//! inside the other, identical shapes at one pose, touching faces, flat
//! and needle-thin shapes, and unions whose deepest piece pair decides.

use gjk::{Compound, Convex, Shape};
use gjkd_testkit::minkowski_depth::minkowski_depth;
use gjkd_testkit::reference::P;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::{assert_signed, sd};

fn tetra(s: f64) -> Vec<P> {
    vec![
        P::new(s, 0.1 * s, -0.2 * s),
        P::new(-0.7 * s, s, 0.3 * s),
        P::new(-0.4 * s, -0.9 * s, 0.5 * s),
        P::new(0.2 * s, 0.1 * s, -s),
        P::new(0.1 * s, -0.2 * s, 0.9 * s),
    ]
}

/// A pair at scale `s` placed at one pose `far` from the origin (B's
/// placement against A in its vertices, so that the poses round nothing
/// the brute force does not see), against the brute force in the body
/// frame.
#[test]
fn sizes_from_1e_minus_9_to_1e6_and_1e9_from_the_origin() {
    let turn_a = UnitQuaternion::from_euler_angles(0.3, 0.2, -0.4);
    let turn_b = UnitQuaternion::from_euler_angles(-1.1, 0.5, 0.8);
    for s in [1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e6] {
        for far in [0.0, 1e3, 1e9] {
            let rel_b =
                Isometry3::from_parts(Translation3::new(0.3 * s, -0.2 * s, 0.1 * s), turn_b);
            let pa_local = tetra(s);
            let pb_local: Vec<P> = tetra(0.8 * s).iter().map(|p| rel_b * p).collect();
            let (depth, _) = minkowski_depth(&pa_local, &pb_local).expect("overlapping");
            let a: Shape = Convex::new(pa_local, 0.0).unwrap().into();
            let b: Shape = Convex::new(pb_local, 0.0).unwrap().into();
            let frame = Isometry3::from_parts(Translation3::new(far, -far, 0.5 * far), turn_a);
            let got = sd(&a, &frame, &b, &frame);
            assert_signed(&got, -depth, s, &format!("size {s:e} at {far:e}"));
        }
    }
}

/// Two poses 2^30 (about 1e9) from the origin whose difference is exact.
#[test]
fn two_poses_1e9_from_the_origin() {
    let far = 2f64.powi(30);
    let a: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)
        .unwrap()
        .into();
    let b: Shape = Convex::cuboid(Vector3::new(0.5, 0.5, 0.5), 0.0)
        .unwrap()
        .into();
    let pa = Isometry3::translation(far, -far, far);
    let pb = Isometry3::translation(far + 1.25, -far + 0.125, far);
    let got = sd(&a, &pa, &b, &pb);
    assert_signed(&got, -0.25, 1.0, "boxes at 2^30");
}

#[test]
fn one_inside_the_other_and_identical_at_one_pose() {
    let big: Shape = Convex::cuboid(Vector3::new(2.0, 3.0, 4.0), 0.0)
        .unwrap()
        .into();
    let small: Shape = Convex::cuboid(Vector3::new(0.1, 0.2, 0.3), 0.0)
        .unwrap()
        .into();
    // Inside, off centre: out through the nearest face of the big box.
    let got = sd(
        &big,
        &Isometry3::identity(),
        &small,
        &Isometry3::translation(1.5, 0.0, 0.0),
    );
    assert_signed(&got, -(2.0 - 1.5 + 0.1), 4.0, "inside");
    // Identical shapes at one pose: the whole width along the least axis.
    let turn = Isometry3::from_parts(
        Translation3::new(3.0, 1.0, -2.0),
        UnitQuaternion::from_euler_angles(0.2, 0.9, -0.3),
    );
    let got = sd(&big, &turn, &big, &turn);
    assert_signed(&got, -4.0, 4.0, "identical boxes");
    let ball: Shape = Convex::sphere(0.7).unwrap().into();
    let got = sd(&ball, &turn, &ball, &turn);
    assert_signed(&got, -1.4, 1.0, "identical spheres");
    let can: Shape = Convex::cylinder(0.5, 2.0, 0.0).unwrap().into();
    let got = sd(&can, &turn, &can, &turn);
    assert_signed(&got, -1.0, 2.0, "identical cylinders");
}

#[test]
fn touching_faces_edges_and_corners() {
    let a: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)
        .unwrap()
        .into();
    for (what, t) in [
        ("face", Vector3::new(2.0, 0.3, -0.4)),
        ("edge", Vector3::new(2.0, 2.0, 0.5)),
        ("corner", Vector3::new(2.0, 2.0, 2.0)),
    ] {
        let got = sd(
            &a,
            &Isometry3::identity(),
            &a,
            &Isometry3::translation(t.x, t.y, t.z),
        );
        assert_signed(&got, 0.0, 1.0, what);
    }
}

#[test]
fn flat_and_needle_thin_shapes() {
    let bx: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)
        .unwrap()
        .into();
    // A flat square through the box's top face, 0.3 below it.
    let square: Shape = Convex::cuboid(Vector3::new(0.5, 0.5, 0.0), 0.0)
        .unwrap()
        .into();
    let got = sd(
        &bx,
        &Isometry3::identity(),
        &square,
        &Isometry3::translation(0.0, 0.0, 0.7),
    );
    assert_signed(&got, -0.3, 1.0, "flat square");
    // Two coplanar overlapping squares: their difference is flat, and a
    // translation out of the plane of any length separates them.
    let got = sd(
        &square,
        &Isometry3::identity(),
        &square,
        &Isometry3::translation(0.3, 0.2, 0.0),
    );
    assert_signed(&got, 0.0, 1.0, "coplanar squares");
    // A needle through the box along x, near its top face.
    let needle: Shape = Convex::new(vec![P::new(-3.0, 0.0, 0.0), P::new(3.0, 1e-7, 0.0)], 0.0)
        .unwrap()
        .into();
    let got = sd(
        &bx,
        &Isometry3::identity(),
        &needle,
        &Isometry3::translation(0.0, 0.2, 0.9),
    );
    assert_signed(&got, -0.1, 3.0, "needle");
    // A thin slab (1e-6 thick) half through a face.
    let slab: Shape = Convex::cuboid(Vector3::new(0.5, 0.5, 1e-6), 0.0)
        .unwrap()
        .into();
    let got = sd(
        &bx,
        &Isometry3::identity(),
        &slab,
        &Isometry3::translation(0.0, 1.4, 0.0),
    );
    assert_signed(&got, -0.1, 1.0, "slab");
}

#[test]
fn deep_overlaps() {
    let a: Shape = Convex::cuboid(Vector3::new(10.0, 10.0, 10.0), 0.5)
        .unwrap()
        .into();
    let b: Shape = Convex::cuboid(Vector3::new(9.0, 9.0, 9.0), 0.0)
        .unwrap()
        .into();
    let got = sd(
        &a,
        &Isometry3::identity(),
        &b,
        &Isometry3::translation(0.5, -0.2, 0.1),
    );
    assert_signed(&got, -(10.5 + 9.0 - 0.5), 10.0, "deep");
}

#[test]
fn unions_take_their_deepest_piece_pair() {
    let ball = Convex::sphere(0.5).unwrap();
    let dumbbell: Shape = Compound::new(vec![
        (Isometry3::translation(-2.0, 0.0, 0.0), ball.clone()),
        (Isometry3::translation(2.0, 0.0, 0.0), ball),
    ])
    .unwrap()
    .into();
    let bx: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)
        .unwrap()
        .into();
    // The right ball 0.3 into the box's face x = -1 ... the box at x = 3.2:
    // its face x = 2.2, the right ball reaching 2.5: 0.3 deep; the left
    // ball far away.
    let got = sd(
        &dumbbell,
        &Isometry3::identity(),
        &bx,
        &Isometry3::translation(3.2, 0.0, 0.0),
    );
    assert_signed(&got, -0.3, 2.5, "dumbbell into a box");
    assert_eq!(got.pieces, [1, 0]);
    // Both balls in, the larger deeper: it decides.
    let uneven: Shape = Compound::new(vec![
        (
            Isometry3::translation(-2.0, 0.0, 0.0),
            Convex::sphere(0.5).unwrap(),
        ),
        (
            Isometry3::translation(2.0, 0.0, 0.0),
            Convex::sphere(0.6).unwrap(),
        ),
    ])
    .unwrap()
    .into();
    let long: Shape = Convex::cuboid(Vector3::new(3.0, 1.0, 1.0), 0.0)
        .unwrap()
        .into();
    let got = sd(
        &uneven,
        &Isometry3::identity(),
        &long,
        &Isometry3::translation(0.0, 1.2, 0.0),
    );
    // Each ball's centre 0.2 below the face y = 0.2.
    assert_signed(&got, -0.4, 3.0, "both balls in");
    assert_eq!(got.pieces, [1, 0]);
}
