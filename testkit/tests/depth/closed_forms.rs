//! Pairs whose signed distance is a closed form: spheres, a sphere against
//! a box's face, edge and corner, boxes face to face, capsules, coaxial and
//! parallel cylinders.

use gjk::{Convex, Shape};
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};

use super::{assert_signed, sd};

fn at(x: f64, y: f64, z: f64) -> Isometry3<f64> {
    Isometry3::translation(x, y, z)
}

#[test]
fn sphere_sphere_apart_touching_overlapping_and_concentric() {
    let a: Shape = Convex::sphere(1.0).unwrap().into();
    let b: Shape = Convex::sphere(0.5).unwrap().into();
    for c in [3.0, 1.5, 1.2, 0.7, 0.1, 0.0] {
        let dir = Vector3::new(0.3, -0.4, 0.5).normalize();
        let p = dir * c;
        let got = sd(&a, &Isometry3::identity(), &b, &at(p.x, p.y, p.z));
        assert_signed(&got, c - 1.5, 1.5, &format!("centres {c} apart"));
        if c > 0.0 {
            assert!((got.normal - dir).norm() < 1e-9, "{c}: {:?}", got.normal);
        }
    }
}

/// The signed distance from a sphere of radius `r` at `c` to the box of
/// half extents `h` at the origin: the distance from `c` to the box less
/// `r`, or, inside, minus the depth to the nearest face less `r`.
fn sphere_box(c: Vector3<f64>, h: Vector3<f64>, r: f64) -> f64 {
    let outside = Vector3::from_fn(|i, _| (c[i].abs() - h[i]).max(0.0));
    if outside.norm() > 0.0 {
        outside.norm() - r
    } else {
        -(0..3)
            .map(|i| h[i] - c[i].abs())
            .fold(f64::INFINITY, f64::min)
            - r
    }
}

#[test]
fn sphere_against_a_box_face_edge_and_corner() {
    let h = Vector3::new(1.0, 0.7, 0.4);
    let bx: Shape = Convex::cuboid(h, 0.0).unwrap().into();
    let r = 0.3;
    let ball: Shape = Convex::sphere(r).unwrap().into();
    let cases = [
        ("face", Vector3::new(1.1, 0.2, -0.1)),
        ("face, centre inside", Vector3::new(0.9, 0.2, -0.1)),
        ("deep, centre inside", Vector3::new(0.1, -0.05, 0.02)),
        ("edge", Vector3::new(1.1, 0.75, 0.0)),
        ("corner", Vector3::new(1.1, 0.75, 0.45)),
        ("corner, touching", Vector3::new(1.0, 0.7, 0.7)),
        ("apart", Vector3::new(1.6, 0.0, 0.0)),
    ];
    for (what, c) in cases {
        let got = sd(&bx, &Isometry3::identity(), &ball, &at(c.x, c.y, c.z));
        assert_signed(&got, sphere_box(c, h, r), 1.0, what);
        // The same the other way round, with the normal reversed.
        let back = sd(&ball, &at(c.x, c.y, c.z), &bx, &Isometry3::identity());
        assert_signed(&back, sphere_box(c, h, r), 1.0, what);
    }
}

#[test]
fn boxes_face_to_face_and_rotated_together() {
    let ha = Vector3::new(1.0, 2.0, 3.0);
    let hb = Vector3::new(0.5, 0.5, 0.5);
    let a: Shape = Convex::cuboid(ha, 0.0).unwrap().into();
    let b: Shape = Convex::cuboid(hb, 0.0).unwrap().into();
    let turn = UnitQuaternion::from_euler_angles(0.4, -0.3, 1.1);
    let centres: [Vector3<f64>; 4] = [
        Vector3::new(1.2, 0.3, -0.2),
        Vector3::new(0.0, 2.3, 1.0),
        Vector3::new(0.1, 0.1, 3.1),
        Vector3::new(0.0, 0.0, 0.0),
    ];
    for c in centres {
        // Least overlap over the axes (aligned boxes).
        let truth = -(0..3)
            .map(|i| ha[i] + hb[i] - c[i].abs())
            .fold(f64::INFINITY, f64::min);
        let got = sd(&a, &Isometry3::identity(), &b, &at(c.x, c.y, c.z));
        assert_signed(&got, truth, 3.0, &format!("{c:?}"));
        // A common rotation and translation changes nothing.
        let frame = Isometry3::from_parts(Vector3::new(5.0, -3.0, 2.0).into(), turn);
        let moved = sd(&a, &frame, &b, &(frame * at(c.x, c.y, c.z)));
        assert_signed(&moved, truth, 3.0, &format!("{c:?}, moved"));
    }
}

#[test]
fn capsules_parallel_crossing_and_end_to_end() {
    let r1 = 0.4;
    let r2 = 0.25;
    let a: Shape = Convex::capsule(Point3::new(-1.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0), r1)
        .unwrap()
        .into();
    let b: Shape = Convex::capsule(Point3::new(-0.5, 0.0, 0.0), Point3::new(0.5, 0.0, 0.0), r2)
        .unwrap()
        .into();
    // Parallel, offset sideways: the axes' distance less the radii.
    for y in [1.0, 0.5, 0.2, 0.05] {
        let got = sd(&a, &Isometry3::identity(), &b, &at(0.3, y, 0.0));
        assert_signed(&got, y - r1 - r2, 1.5, &format!("parallel at {y}"));
    }
    // End to end along the axis.
    let got = sd(&a, &Isometry3::identity(), &b, &at(1.6, 0.0, 0.0));
    assert_signed(&got, 0.1 - r1 - r2, 1.5, "end to end");
    // Crossing at right angles through each other: the cores meet, and
    // the difference of the segments is a flat square, so the depth is
    // the radii alone.
    let cross = Isometry3::from_parts(
        Vector3::new(0.2, 0.0, 0.0).into(),
        UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
    );
    let got = sd(&a, &Isometry3::identity(), &b, &cross);
    assert_signed(&got, -(r1 + r2), 1.5, "crossing");
    // Crossing with a gap between the axes along z.
    let above = Isometry3::from_parts(Vector3::new(0.2, 0.0, 0.3).into(), cross.rotation);
    let got = sd(&a, &Isometry3::identity(), &b, &above);
    assert_signed(&got, 0.3 - (r1 + r2), 1.5, "crossing above");
}

#[test]
fn cylinders_coaxial_and_parallel() {
    let (ra, ha) = (1.0, 2.0);
    let (rb, hb) = (0.5, 0.75);
    let a: Shape = Convex::cylinder(ra, ha, 0.0).unwrap().into();
    let b: Shape = Convex::cylinder(rb, hb, 0.0).unwrap().into();
    for (e, z) in [
        (0.0, 2.5),
        (0.0, 0.0),
        (0.0, -2.2),
        (1.2, 0.3),
        (1.4, -1.0),
        (0.3, 2.6),
        (1.0, 2.7),
    ] {
        // To separate: along the axis by the caps' overlap, or sideways by
        // the disks' overlap.
        let truth: f64 = -((ha + hb - f64::abs(z)).min(ra + rb - e));
        let dir = Vector3::new(0.6, 0.8, 0.0);
        let got = sd(&a, &Isometry3::identity(), &b, &at(dir.x * e, dir.y * e, z));
        assert_signed(&got, truth, 2.0, &format!("offset {e}, height {z}"));
    }
    // Rounded cylinders: the radii add to the depth.
    let a: Shape = Convex::cylinder(ra, ha, 0.1).unwrap().into();
    let b: Shape = Convex::cylinder(rb, hb, 0.05).unwrap().into();
    let got = sd(&a, &Isometry3::identity(), &b, &at(0.0, 1.2, 0.4));
    assert_signed(&got, -(ra + rb - 1.2) - 0.15, 2.0, "rounded, parallel");
}
