//! Sizes from the smallest to the largest the crate accepts, gaps down
//! to zero, in f64 and f32, the paper's family among them.

use super::*;

// ---------------------------------------------------------------------------

/// Scales from 1e-9 to 1e6, with rotated poses and gaps down to 1e-12 of the
/// object size.
#[test]
fn scales_and_gaps() {
    let mut cases = Vec::new();
    for s in [1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e6] {
        for rot in rotations() {
            for g in GAPS {
                let ha = v(1.0, 0.5, 2.0) * s;
                let hb = v(0.75, 1.5, 0.25) * s;
                let size = 2.0 * ha.norm();
                let ta = v(0.3, -0.7, 0.2) * s;
                let rel = v(ha.x + hb.x + g * size, 0.2 * s, -0.1 * s);
                let tb = ta + rot * rel;
                let rel_actual = rot.inverse_transform_vector(&(tb - ta));
                let truth = aabb_distance(&V::zeros(), &ha, &rel_actual, &hb);
                cases.push(Case::new(
                    format!("boxes scale {s:e}, rot {rot:?}, gap {g:e}"),
                    cuboid(ha, 0.0),
                    posed(ta, rot),
                    cuboid(hb, 0.0),
                    posed(tb, rot),
                    truth,
                    size,
                ));
                // Tetrahedron face against a point: the point above the
                // face x + y + z = s at distance g·size along its normal.
                let tet: Shape = Convex::new(
                    vec![p(0., 0., 0.), p(s, 0., 0.), p(0., s, 0.), p(0., 0., s)],
                    0.0,
                )
                .unwrap()
                .into();
                let n = v(1., 1., 1.) / 3f64.sqrt();
                let foot = v(s, s, s) / 3.0;
                let q = foot + n * (g * s);
                let pa = posed(V::zeros(), rot);
                let pb = at(rot * q);
                let local = rot.inverse_transform_vector(&pb.translation.vector);
                let truth = ((local.x + local.y + local.z - s) / 3f64.sqrt()).max(0.0);
                cases.push(Case::new(
                    format!("tetra/point scale {s:e}, rot {rot:?}, gap {g:e}"),
                    tet,
                    pa,
                    sphere(0.0),
                    pb,
                    truth,
                    s,
                ));
            }
        }
    }
    run(&cases);
}

/// The whole f64 range: objects of size 2^-1000 (1e-301) to 2^996 (7e299,
/// whose reach stays within the 2^1000 a query accepts), rotated, with gaps
/// from their size down to touching. The cofactors are
/// products of up to three squared lengths, so without the run's scaling
/// they leave f64 beyond about 1e±50 (at 1e-300 they used to vanish and
/// certify [0, 0] around a true distance of 1e-300). The scales are powers
/// of two, so the closed forms are evaluated exactly at scale 1 and scaled.
#[test]
fn the_whole_range_of_scales() {
    let mut cases = Vec::new();
    for e in [-1000, -600, -300, -150, 150, 300, 600, 996] {
        let s = 2f64.powi(e);
        for rot in rotations() {
            for g in [1.0, 1e-6, 0.0] {
                let (ha, hb) = (v(1.0, 0.5, 2.0), v(0.75, 1.5, 0.25));
                let size = 2.0 * ha.norm() * s;
                let rel = v(ha.x + hb.x + g * 2.0 * ha.norm(), 0.2, -0.1);
                let ta = v(0.3, -0.7, 0.2) * s;
                let tb = ta + rot * (rel * s);
                let rel_actual = rot.inverse_transform_vector(&(tb - ta));
                let truth = aabb_distance(&V::zeros(), &ha, &(rel_actual / s), &hb) * s;
                cases.push(Case::new(
                    format!("boxes at scale 2^{e}, rot {rot:?}, gap {g:e}"),
                    cuboid(ha * s, 0.0),
                    posed(ta, rot),
                    cuboid(hb * s, 0.0),
                    posed(tb, rot),
                    truth,
                    size,
                ));
                cases.push(Case::new(
                    format!("dotted boxes at scale 2^{e}, rot {rot:?}, gap {g:e}"),
                    dotted_box(ha * s),
                    posed(ta, rot),
                    dotted_box(hb * s),
                    posed(tb, rot),
                    truth,
                    size,
                ));
                // A rounded tetrahedron face against a sphere.
                let tet: Shape = Convex::new(
                    vec![p(0., 0., 0.), p(s, 0., 0.), p(0., s, 0.), p(0., 0., s)],
                    0.25 * s,
                )
                .unwrap()
                .into();
                let n = v(1., 1., 1.) / 3f64.sqrt();
                let q = v(s, s, s) / 3.0 + n * ((0.5 + g) * s);
                let pa = posed(V::zeros(), rot);
                let pb = at(rot * q);
                let local = rot.inverse_transform_vector(&pb.translation.vector);
                let core = (local.x + local.y + local.z - s) / 3f64.sqrt();
                cases.push(Case::new(
                    format!("rounded tetra/sphere at scale 2^{e}, rot {rot:?}, gap {g:e}"),
                    tet,
                    pa,
                    sphere(0.25 * s),
                    pb,
                    (core - 0.5 * s).max(0.0),
                    s,
                ));
            }
        }
    }
    run(&cases);
    run_with(&cases, Precision::Single);
}

/// `Precision::Single` at the extremes: boxes as many-point sets (so the f32
/// scan runs) at scales 1e-9 to 1e6, 1e9 from the origin, rotated, with gaps
/// down to 1e-12 of their size and touching. The bounds must hold exactly;
/// the distance within the f32 allowance.
#[test]
fn single_precision_at_scales_offsets_and_gaps() {
    let mut cases = Vec::new();
    for s in [1e-9, 1e-3, 1.0, 1e6] {
        for off in [0.0, 1e9] {
            for rot in rotations() {
                for g in GAPS {
                    let ha = v(1.0, 0.5, 2.0) * s;
                    let hb = v(0.75, 1.5, 0.25) * s;
                    let size = 2.0 * ha.norm();
                    let ta = v(off + 0.3 * s, -0.7 * s, off);
                    let rel = v(ha.x + hb.x + g * size, 0.2 * s, -0.1 * s);
                    let tb = ta + rot * rel;
                    let rel_actual = rot.inverse_transform_vector(&(tb - ta));
                    let truth = aabb_distance(&V::zeros(), &ha, &rel_actual, &hb);
                    cases.push(Case::new(
                        format!("dotted boxes scale {s:e}, offset {off:e}, rot {rot:?}, gap {g:e}"),
                        dotted_box(ha),
                        posed(ta, rot),
                        dotted_box(hb),
                        posed(tb, rot),
                        truth,
                        size,
                    ));
                }
            }
        }
    }
    run_with(&cases, Precision::Single);
    // The same cases in f64 meet the tighter requirement.
    run(&cases);
}

/// The paper's family, separated, touching and intersecting, scaled by powers
/// of two (exact, so the constructed distance scales with it) from 2^-200 to
/// 2^200 and moved up to 1e9 of its size from the origin, in f64 and with the
/// f32 support search: every answer within the requirement (plus, for f32,
/// its slack) of the constructed distance, whose own round-off (1e-15 of the
/// scene, and the ulp of the offset) is allowed for.
#[test]
fn paper_family_at_scales_and_offsets() {
    let family = gjkd_testkit::paper::family();
    let mut failures = Vec::new();
    let mut checked = 0;
    for precision in [Precision::Double, Precision::Single] {
        let options = Options {
            precision,
            ..Options::default()
        };
        for e in [-200, -60, 20, 200] {
            let s = 2f64.powi(e);
            let shapes: Vec<Shape> = family
                .iter()
                .map(|c| {
                    let pts: Vec<P> = c.vertices().iter().map(|q| q * s).collect();
                    Convex::new(pts, c.radius() * s).unwrap().into()
                })
                .collect();
            for off in [0.0, 1e9] {
                let shift = v(off, -off, 0.5 * off) * s;
                for case in gjkd_testkit::paper::Case::ALL {
                    for c in gjkd_testkit::paper::cases(case, 2, 3) {
                        let place = |p: &Isometry3<f64>| {
                            Isometry3::from_parts(
                                Translation3::from(p.translation.vector * s + shift),
                                p.rotation,
                            )
                        };
                        let (pa, pb) = (place(&c.pose_a), place(&c.pose_b));
                        let truth = c.expected * s;
                        let size = 20.0 * s; // The polytopes lie within radius 10.
                        let known = 1e-14 * size + 4.0 * f64::EPSILON * off * s;
                        let slack = match precision {
                            Precision::Double => 0.0,
                            Precision::Single => 2f64.powi(-18) * size,
                        };
                        let allowed = (1e-6 * truth).max(1e-9 * size) + known + slack;
                        let ans =
                            distance(&shapes[c.a], &pa, &shapes[c.b], &pb, &options, None).unwrap();
                        checked += 1;
                        if (ans.distance - truth).abs() > allowed
                            || ans.lower > truth + known
                            || truth > ans.upper + known
                        {
                            failures.push(format!(
                                "{precision:?} 2^{e} offset {off:e} {case:?} pair {}: truth {truth:e}, got {:e} [{:e}, {:e}]",
                                c.pair, ans.distance, ans.lower, ans.upper
                            ));
                        }
                    }
                }
            }
        }
    }
    assert_eq!(checked, 2 * 4 * 2 * 3 * 40);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
