//! Distances with closed forms: spheres, boxes, rounded boxes, capsules,
//! segments, triangles.

use super::*;

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
