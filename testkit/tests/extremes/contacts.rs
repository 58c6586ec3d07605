//! Degenerate vertex sets and hard contacts: identical objects, touching
//! faces, nearly parallel edges, deep intersections, and a body of
//! 100 000 vertices.

use super::*;

// ---------------------------------------------------------------------------

/// Duplicate, collinear, coplanar and single-point vertex sets.
#[test]
fn degenerate_vertex_sets() {
    let mut cases = Vec::new();
    for rot in rotations() {
        for g in GAPS {
            let gap = g * 2.0;
            // Box vertices, each three times, in scrambled order.
            let cube: Vec<P> = Convex::cuboid(v(1., 1., 1.), 0.)
                .unwrap()
                .vertices()
                .to_vec();
            let mut dup = Vec::new();
            for k in 0..24 {
                dup.push(cube[(k * 5) % 8]);
            }
            let a: Shape = Convex::new(dup, 0.0).unwrap().into();
            let q = v(1.0 + gap, 0.3, -0.6);
            cases.push(Case::new(
                format!("duplicates, rot {rot:?}, gap {g:e}"),
                a,
                posed(V::zeros(), rot),
                sphere(0.0),
                at(rot * q),
                rel_box_point(&rot, &(rot * q), 1.0),
                2.0,
            ));
            // 50 collinear points on [-1, 1]·x (plus repeats of the ends).
            let line: Vec<P> = (0..50)
                .map(|k| p(-1.0 + 2.0 * (k as f64) / 49.0, 0.0, 0.0))
                .collect();
            let a: Shape = Convex::new(line, 0.0).unwrap().into();
            // Off the end of the segment, and beside its middle.
            for q in [v(1.0 + gap, 0.0, 0.0), v(0.1, 0.0, gap)] {
                let pb = at(rot * q);
                let local = rot.inverse_transform_vector(&pb.translation.vector);
                let cl = v(local.x.clamp(-1.0, 1.0), 0.0, 0.0);
                let truth = (local - cl).norm();
                cases.push(Case::new(
                    format!("collinear, rot {rot:?}, q {q:?}"),
                    a.clone(),
                    posed(V::zeros(), rot),
                    sphere(0.0),
                    pb,
                    truth,
                    2.0,
                ));
            }
            // A 7×7 grid in the square [-1, 1]² of z = 0, against a point
            // above it, beside an edge in its plane, and against a segment.
            let grid: Vec<P> = (0..49)
                .map(|k| {
                    p(
                        -1.0 + (k % 7) as f64 / 3.0,
                        -1.0 + (k / 7) as f64 / 3.0,
                        0.0,
                    )
                })
                .collect();
            let a: Shape = Convex::new(grid, 0.0).unwrap().into();
            for q in [v(0.2, -0.3, gap), v(1.0 + gap, 0.4, 0.0)] {
                let pb = at(rot * q);
                let local = rot.inverse_transform_vector(&pb.translation.vector);
                let cl = v(local.x.clamp(-1.0, 1.0), local.y.clamp(-1.0, 1.0), 0.0);
                cases.push(Case::new(
                    format!("coplanar, rot {rot:?}, q {q:?}"),
                    a.clone(),
                    posed(V::zeros(), rot),
                    sphere(0.0),
                    pb,
                    (local - cl).norm(),
                    2.0,
                ));
            }
            // Two coplanar squares side by side in the same plane.
            let pb = posed(rot * v(2.0 + gap, 0.5, 0.0), rot);
            let rel = rot.inverse_transform_vector(&pb.translation.vector);
            let truth = aabb_distance(&V::zeros(), &v(1., 1., 0.), &rel, &v(1., 1., 0.));
            cases.push(Case::new(
                format!("coplanar squares, rot {rot:?}, gap {g:e}"),
                a.clone(),
                posed(V::zeros(), rot),
                a.clone(),
                pb,
                truth,
                2.0,
            ));
            // Single points.
            let d = v(0.3, -0.4, 1.2) * (1.0 + g);
            cases.push(Case::new(
                format!("points, gap {g:e}"),
                sphere(0.0),
                at(v(1., 2., 3.)),
                sphere(0.0),
                at(v(1., 2., 3.) + d),
                (v(1., 2., 3.) + d - v(1., 2., 3.)).norm(),
                1.0,
            ));
        }
    }
    run(&cases);
}

/// Identical objects at identical poses, and parallel faces exactly touching.
#[test]
fn identical_objects_and_touching_faces() {
    let mut cases = Vec::new();
    let h = v(1.0, 0.5, 2.0);
    for o in [0.0, 1e6, 1e9] {
        for rot in rotations() {
            let pose = posed(v(o, 2.0 * o, -o), rot);
            cases.push(Case::new(
                format!("identical boxes at {o:e}, rot {rot:?}"),
                cuboid(h, 0.0),
                pose,
                cuboid(h, 0.0),
                pose,
                0.0,
                4.0,
            ));
            let tet: Shape = Convex::new(
                vec![p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.), p(0., 0., 1.)],
                0.1,
            )
            .unwrap()
            .into();
            cases.push(Case::new(
                format!("identical rounded tetrahedra at {o:e}, rot {rot:?}"),
                tet.clone(),
                pose,
                tet,
                pose,
                0.0,
                1.0,
            ));
            // Parallel faces exactly touching (in the relative frame).
            let pb = posed(pose.translation.vector + rot * v(2.0 * h.x, 0.3, -0.5), rot);
            let rel =
                rot.inverse_transform_vector(&(pb.translation.vector - pose.translation.vector));
            let truth = aabb_distance(&V::zeros(), &h, &rel, &h);
            cases.push(Case::new(
                format!("faces touching at {o:e}, rot {rot:?}"),
                cuboid(h, 0.0),
                pose,
                cuboid(h, 0.0),
                pb,
                truth,
                4.0,
            ));
        }
    }
    run(&cases);
}

/// Nearly parallel edges: segment A on the x axis, B at height d through
/// (0, 0, d) at angle θ, with exactly symmetric endpoints, so that the
/// projections cross at the origin and the distance is exactly d.
#[test]
fn nearly_parallel_edges() {
    let mut cases = Vec::new();
    for theta in [1e-2f64, 1e-4, 1e-6, 1e-8, 1e-12, 0.0] {
        for d in [1.0, 1e-3, 1e-6, 1e-9, 1e-12] {
            let (c, s) = (theta.cos(), theta.sin());
            let a = segment(p(-1., 0., 0.), p(1., 0., 0.), 0.0);
            let b = segment(p(-c, -s, d), p(c, s, d), 0.0);
            let o = Isometry3::identity();
            cases.push(Case::new(
                format!("segments at angle {theta:e}, height {d:e}"),
                a,
                o,
                b,
                o,
                d,
                2.0,
            ));
        }
    }
    run(&cases);
}

/// Deep intersection: a small box well inside a big one, and spheres deep in
/// each other. The penetration bound must be positive and at most the depth.
#[test]
fn deep_intersection() {
    let mut cases = Vec::new();
    for o in [0.0, 1e6] {
        for rot in rotations() {
            // The true depth of a box inside a box is the smallest H_i + h_i - |δ_i|.
            let big = v(3.0, 2.0, 4.0);
            let small = v(0.5, 0.25, 0.1);
            let ta = v(o, o, -o);
            let pb = posed(ta + rot * v(0.2, -0.1, 0.3), rot);
            let rel = rot.inverse_transform_vector(&(pb.translation.vector - ta));
            let mut c = Case::new(
                format!("box inside box at {o:e}, rot {rot:?}"),
                cuboid(big, 0.0),
                posed(ta, rot),
                cuboid(small, 0.0),
                pb,
                0.0,
                10.0,
            );
            c.depth = Some(
                (0..3)
                    .map(|i| big[i] + small[i] - rel[i].abs())
                    .fold(f64::INFINITY, f64::min),
            );
            cases.push(c);
        }
        // Spheres deep in each other, distinct centres: shells only, exact depth.
        let ta = v(o, -o, o);
        let tb = ta + v(0.1, 0.2, 0.0);
        let mut c = Case::new(
            format!("sphere in sphere at {o:e}"),
            sphere(2.0),
            at(ta),
            sphere(0.5),
            at(tb),
            0.0,
            4.0,
        );
        c.depth = Some(2.5 - (tb - ta).norm());
        cases.push(c);
    }
    run(&cases);
}

#[test]
fn hundred_thousand_vertices() {
    const N: usize = 100_000;
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let ball: Shape = Convex::new(sphere_points(2.0, N), 0.0).unwrap().into();
    let h = v(1.0, 2.0, 0.5);
    let blob: Shape = Convex::new(box_points(h, N, &mut rng), 0.0).unwrap().into();
    let mut cases = Vec::new();
    for rot in rotations() {
        for g in [1.0, 1e-3, 1e-6, 1e-9, 0.0] {
            // A point above the pole, in A's frame.
            let pa = posed(v(5., -3., 1.), rot);
            let q = v(0.0, 0.0, 2.0 + g * 4.0);
            let pb = at((pa * P::from(q)).coords);
            let l = pa.inverse_transform_point(&P::from(pb.translation.vector));
            let truth = (l.z - 2.0).max(0.0);
            cases.push(Case::new(
                format!("point over 1e5-point sphere, rot {rot:?}, gap {g:e}"),
                ball.clone(),
                pa,
                sphere(0.0),
                pb,
                truth,
                4.0,
            ));
            // The point cloud box against a sphere, over a face.
            let c = v(0.3, -0.5, 0.5 + 0.25 + g * 4.0);
            let pb = at((pa * P::from(c)).coords);
            let l = pa.inverse_transform_point(&P::from(pb.translation.vector));
            let truth = (l.z - 0.5 - 0.25).max(0.0);
            cases.push(Case::new(
                format!("sphere over 1e5-point box, rot {rot:?}, gap {g:e}"),
                blob.clone(),
                pa,
                sphere(0.25),
                pb,
                truth,
                4.0,
            ));
            // 1e5 against 1e5: the box cloud's bottom face (z = -0.5) over the
            // sphere's north pole, same rotation (relative frame: translation).
            let pb = posed(
                pa.translation.vector + rot * v(0.2, -0.1, 2.0 + 0.5 + g * 4.0),
                rot,
            );
            let rel =
                rot.inverse_transform_vector(&(pb.translation.vector - pa.translation.vector));
            let truth = (rel.z - 0.5 - 2.0).max(0.0);
            cases.push(Case::new(
                format!("1e5-point box over 1e5-point sphere, rot {rot:?}, gap {g:e}"),
                ball.clone(),
                pa,
                blob.clone(),
                pb,
                truth,
                4.0,
            ));
        }
    }
    run(&cases);
    run_with(&cases, Precision::Single);
}
