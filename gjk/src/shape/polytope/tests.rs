//! The support searches against brute force: closed forms, the f32 scan's
//! slack, and the vector scans' first maximum.

use nalgebra::Point3;

use super::single::SINGLE_SLACK;
use super::*;
use crate::shape::test_rng::Rng;

/// The support index by brute force: the first vertex of largest `v·d`.
fn brute_force_support(c: &Convex, d: &Vector3<f64>) -> usize {
    let mut best = 0;
    for i in 1..c.len() {
        if c.local(i).dot(d) > c.local(best).dot(d) {
            best = i;
        }
    }
    best
}

#[test]
fn box_support_is_the_scan_including_ties() {
    let comps = [-1.5, -1e-300, -0.0, 0.0, 1e-300, 0.7];
    for half in [
        Vector3::new(0.5, 2.0, 0.25),
        Vector3::new(0.5, 2.0, 1e-200),
        Vector3::new(0.5, 2.0, 0.0),
    ] {
        let b = Convex::cuboid(half, 0.1).unwrap();
        assert_eq!(b.kind, SupportKind::Box);
        for &x in &comps {
            for &y in &comps {
                for &z in &comps {
                    let d = Vector3::new(x, y, z);
                    let (i, j) = (b.support_index(&d), brute_force_support(&b, &d));
                    assert_eq!(b.local(i).dot(&d), b.local(j).dot(&d), "{d:?}");
                    // A flat axis, or a component lost in the sum,
                    // ties the two faces: either is a support point.
                    let lost = [x, y, z].iter().any(|c| c.abs() == 1e-300);
                    if half.z > 1e-100 && !lost {
                        assert_eq!(i, j, "direction {d:?}");
                    }
                }
            }
        }
    }
}

#[test]
fn only_exact_boxes_in_cuboid_order_take_the_closed_form() {
    let b = Convex::cuboid(Vector3::new(1.0, 2.0, 3.0), 0.0).unwrap();
    let mut swapped = b.vertices().to_vec();
    swapped.swap(0, 7);
    let shifted: Vec<_> = b
        .vertices()
        .iter()
        .map(|v| v + Vector3::new(1e3, 0.0, 0.0))
        .collect();
    let mut skew = b.vertices().to_vec();
    skew[3].x += 1e-9;
    for (verts, kind) in [
        (swapped, scan_kind()),
        (skew, scan_kind()),
        (shifted, SupportKind::Box),
        (b.vertices()[..1].to_vec(), SupportKind::Point),
        (b.vertices()[..2].to_vec(), SupportKind::Few),
    ] {
        let c = Convex::new(verts, 0.0).unwrap();
        assert_eq!(c.kind, kind);
        for d in [
            Vector3::new(0.3, -0.2, 0.9),
            Vector3::new(-1.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, 0.0),
        ] {
            assert_eq!(
                c.support_index(&d),
                brute_force_support(&c, &d),
                "{kind:?} {d:?}"
            );
        }
    }
}

/// `n` points of a cloud of size `scale` at `offset` on x. Flat sets put
/// every other vertex within 3e-7 of the plane x = scale, far from the
/// centroid: with directions near +x, near-ties that f32 cannot
/// resolve, which is what the slack is for.
fn cloud(rng: &mut Rng, n: usize, scale: f64, offset: f64, flat: bool) -> Vec<Point3<f64>> {
    (0..n)
        .map(|i| {
            let x = if flat && i % 2 == 0 {
                1.0 + 3e-7 * rng.next()
            } else if flat {
                rng.next().min(0.0)
            } else {
                rng.next()
            };
            Point3::new(
                offset + x * scale,
                rng.next() * scale,
                rng.next() * scale * 1e-3,
            )
        })
        .collect()
}

/// The `k`-th direction of a test on a cloud of size `scale`: near +x
/// for a flat cloud, and by turns with a tiny component, signed zeros,
/// huge and subnormal.
fn direction(rng: &mut Rng, k: usize, flat: bool, scale: f64) -> Vector3<f64> {
    let mut d = Vector3::new(rng.next(), rng.next(), rng.next());
    if flat {
        d = Vector3::new(1.0, d.y * 1e-9, d.z * 1e-9);
    }
    match k % 5 {
        1 => d.y *= 1e-300,
        2 => d = Vector3::new(0.0, -0.0, d.z),
        // Subnormal: 1/max overflows, the f64 scan takes over.
        4 => d *= 1e-310,
        // Large, but not so large that the reference overflows.
        3 => d *= 1e120 / scale.max(1.0),
        _ => {}
    }
    d
}

/// The f32 scan's picks for `d` on `c` (which has its f32 copy): through
/// the support search, and straight from the portable and, where the
/// CPU has them, the AVX2 f32 scans.
fn single_picks(c: &Convex, d: &Vector3<f64>) -> Vec<usize> {
    let s = c.single.as_deref().expect("an f32 copy");
    let d32 = {
        let m = d.x.abs().max(d.y.abs()).max(d.z.abs());
        let u = d * (1.0 / m);
        [u.x as f32, u.y as f32, u.z as f32]
    };
    let mut picks = vec![c.support_index_single(d)];
    let scalable = d32.iter().all(|x| x.is_finite());
    if scalable {
        picks.push(scan_single(&s.xs, &s.ys, &s.zs, d32));
    }
    #[cfg(target_arch = "x86_64")]
    if scalable
        && std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
    {
        // SAFETY: the features were checked just above.
        picks.push(unsafe { scan_single_avx2(&s.xs, &s.ys, &s.zs, d32) });
    }
    picks
}

/// The f32 scan's choice is within `SINGLE_SLACK · size · |d|` of the
/// true support value, on both code paths, at every scale f64 allows,
/// far from the origin, for directions with components of wildly
/// different sizes (and ±0).
#[test]
fn single_precision_support_is_within_its_slack() {
    let mut rng = Rng(0x5eed_1234_abcd_0001);
    let mut checked = 0;
    let mut worst = 0.0f64;
    for n in [16, 17, 40, 1000] {
        // Sizes are found through squared lengths, so 1e±150 is the range.
        for scale in [1e-140, 1e-9, 1.0, 1e9, 1e140] {
            for (offset, flat) in [(0.0, false), (1e9, false), (0.0, true), (1e9, true)] {
                let mut c = Convex::new(cloud(&mut rng, n, scale, offset, flat), 0.0).unwrap();
                if offset * 1e-6 > scale {
                    // The vertices collapsed onto a few values.
                    continue;
                }
                // The f32 copy is only built where the exact search is
                // the portable scan; built here on any CPU, so that the
                // f32 path is tested everywhere.
                if c.single.is_none() {
                    c.single = F32Copy::of(&c.xs, &c.ys, &c.zs, c.size);
                }
                assert!(c.has_single(), "n {n} scale {scale:e}");
                for k in 0..64 {
                    let d = direction(&mut rng, k, flat, scale);
                    let best = c.local(brute_force_support(&c, &d)).dot(&d);
                    let slack = SINGLE_SLACK * c.size() * d.norm();
                    for i in single_picks(&c, &d) {
                        assert!(i < c.len());
                        let got = c.local(i).dot(&d);
                        worst = worst.max((best - got) / (c.size() * d.norm()));
                        assert!(
                            got >= best - slack,
                            "n {n} scale {scale:e} d {d:?}: {got:e} < {best:e} - {slack:e}"
                        );
                        checked += 1;
                    }
                }
            }
        }
    }
    assert!(checked > 3000, "{checked}");
    // The flat sets did produce misses, so the bound was tested, not
    // just the easy picks.
    assert!(worst > 0.0);
}

/// Directions whose largest component is near f64::MAX (1/m would be
/// subnormal), or that are subnormal themselves, go to the exact scan.
#[test]
fn single_precision_leaves_extreme_directions_to_the_exact_scan() {
    let mut ring = Convex::new(
        (0..40)
            .map(|i| {
                let a = f64::from(i) * 0.157;
                Point3::new(a.cos(), a.sin(), 0.1 * a)
            })
            .collect::<Vec<_>>(),
        0.0,
    )
    .unwrap();
    ring.single = F32Copy::of(&ring.xs, &ring.ys, &ring.zs, ring.size);
    assert!(ring.has_single());
    for d in [
        Vector3::new(1.7e308, 3e307, -2e307),
        Vector3::new(-1e-320, 5e-321, 0.0),
    ] {
        assert_eq!(ring.support_index_single(&d), ring.scan_index(&d), "{d:?}");
    }
}

/// Small and closed-form shapes keep the exact support under
/// `Precision::Single`; so do sets large enough for the cube map or the
/// block search, which are faster.
#[test]
fn shapes_without_an_f32_copy_keep_the_exact_support() {
    let small = Convex::new(
        (0..15)
            .map(|i| Point3::new(i as f64, (i * i) as f64, 1.0))
            .collect::<Vec<_>>(),
        0.0,
    )
    .unwrap();
    let cube = Convex::cuboid(Vector3::new(1.0, 2.0, 3.0), 0.0).unwrap();
    let large = Convex::new(
        (0..SINGLE_MAX_VERTICES)
            .map(|i| {
                let a = i as f64 * 0.37;
                Point3::new(a.cos(), a.sin(), (i % 17) as f64 * 0.1)
            })
            .collect::<Vec<_>>(),
        0.0,
    )
    .unwrap();
    assert!(matches!(
        large.kind,
        SupportKind::Blocks | SupportKind::Cones { .. }
    ));
    for c in [small, cube, large] {
        assert!(!c.has_single());
        let d = Vector3::new(0.3, -0.8, 0.1);
        assert_eq!(c.support_index_single(&d), brute_force_support(&c, &d));
    }
}

/// The scan's rule written out plainly, one vertex at a time: the first
/// vertex of largest dot product, computed as the support search computes
/// it on this machine (fused multiply-adds on the AVX2 path, which sets
/// of 8 or more vertices take when the CPU has AVX2 and FMA; plain
/// products and sums otherwise).
fn reference(c: &Convex, d: &Vector3<f64>) -> usize {
    #[cfg(target_arch = "x86_64")]
    let fused = c.len() >= 8
        && std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma");
    #[cfg(not(target_arch = "x86_64"))]
    let fused = false;
    reference_with(c, d, fused)
}

/// [`reference`] with the arithmetic chosen: fused or plain.
fn reference_with(c: &Convex, d: &Vector3<f64>, fused: bool) -> usize {
    let (mut top, mut best) = (f64::NEG_INFINITY, 0);
    for i in 0..c.len() {
        let (x, y, z) = (c.xs[i], c.ys[i], c.zs[i]);
        let dot = if fused {
            z.mul_add(d.z, y.mul_add(d.y, x * d.x))
        } else {
            x * d.x + y * d.y + z * d.z
        };
        if dot > top {
            (top, best) = (dot, i);
        }
    }
    best
}

/// The support index is the reference's, vertex for vertex (and the
/// portable scan's is the plain reference's), for every
/// set size from 2 to 200 and past the vector steps' boundaries: sets
/// full of exact ties (grid points, duplicates, a repeated maximum in
/// every lane), near-ties that fused and plain arithmetic round apart,
/// and directions that are zero, signed zeros, tiny, huge enough to
/// overflow the dot products to infinity, or that make them NaN.
#[test]
fn support_index_is_the_plain_scans_first_maximum() {
    let mut rng = Rng(0x5eed_0000_5ca1_0001);
    let mut checked = 0;
    for n in (2..=200).chain([255, 256, 257, 511]) {
        for style in 0..4 {
            let pts: Vec<Point3<f64>> = (0..n)
                .map(|i| match style {
                    // A coarse grid: many exact ties, duplicates.
                    0 => Point3::new(
                        (rng.next() * 3.0).round(),
                        (rng.next() * 3.0).round(),
                        (rng.next() * 2.0).round(),
                    ),
                    // The same point again and again but for a few.
                    1 if i % 7 != 3 => Point3::new(1.0, 2.0, 3.0),
                    // Near-ties: a sphere of radius 1 + a few ulps.
                    2 => {
                        let v = Vector3::new(rng.next(), rng.next(), rng.next());
                        Point3::from(v.normalize() * (1.0 + rng.next() * 1e-15))
                    }
                    _ => Point3::new(rng.next(), rng.next(), rng.next()),
                })
                .collect();
            let c = Convex::new(pts, 0.0).unwrap();
            if matches!(c.kind, SupportKind::Box | SupportKind::Point) {
                continue;
            }
            for k in 0..40 {
                let mut d = Vector3::new(rng.next(), rng.next(), rng.next());
                match k % 10 {
                    0 => d = d.map(|x| (x * 2.0).round()),
                    1 => d = Vector3::new(0.0, -0.0, 0.0),
                    2 => d = Vector3::new(-0.0, d.y, 0.0),
                    3 => d *= 1e-310,
                    4 => d *= 1e308,
                    5 => d = Vector3::new(f64::INFINITY, d.y, d.z),
                    6 => d = Vector3::new(f64::NAN, d.y, d.z),
                    _ => {}
                }
                assert_eq!(
                    c.support_index(&d),
                    reference(&c, &d),
                    "n {n} style {style} d {d:?}"
                );
                // The portable path, whatever this CPU has.
                assert_eq!(
                    scan_top(&c.xs, &c.ys, &c.zs, &d).1,
                    reference_with(&c, &d, false),
                    "portable: n {n} style {style} d {d:?}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 30_000, "{checked}");
}
