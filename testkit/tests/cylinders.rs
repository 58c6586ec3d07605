//! Cylinders against independent answers: closed forms (parallel axes side
//! by side, coaxial caps, a cap on a box face, a sphere against side, cap
//! and rim, crossing axes) at sizes from 1e-9 to 1e6 and far from the
//! origin; fine prisms that bracket the truth from inside and outside; warm
//! starts along a motion; every path (compounds, margins, f32, warm start).

use gjk::{Compound, Convex, Options, Precision, Shape, Status, WarmStart, distance};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// The judged error bound: relative 1e-6, absolute 1e-9 × size near zero.
fn within(got: f64, exact: f64, size: f64) -> bool {
    (got - exact).abs() <= 1e-6 * exact.abs() + 1e-9 * size
}

/// What a query should answer: the exact distance, the shapes' size (for
/// the absolute part of the error bound) and the magnitude of the
/// coordinates the closed form was computed from (for its own round-off).
struct Expect {
    exact: f64,
    size: f64,
    mag: f64,
}

/// The query's answer, checked against `e.exact`: within the error bound,
/// the bounds bracketing it (to the round-off of `exact` itself, a few ε of
/// `e.mag`).
fn check(
    a: &Shape,
    pa: &Isometry3<f64>,
    b: &Shape,
    pb: &Isometry3<f64>,
    e: Expect,
    what: &str,
) -> gjk::Answer {
    let Expect { exact, size, mag } = e;
    let ans = distance(a, pa, b, pb, &Options::default(), None).unwrap();
    assert_eq!(ans.status, Status::Converged, "{what}");
    assert!(
        within(ans.distance, exact, size),
        "{what}: {} vs {exact}",
        ans.distance
    );
    let fuzz = 8.0 * f64::EPSILON * mag;
    assert!(
        ans.lower <= exact + fuzz && exact <= ans.upper + fuzz,
        "{what}: [{}, {}] vs {exact}",
        ans.lower,
        ans.upper
    );
    // The nearest points are that far apart (0 when they touch or overlap).
    if exact > 0.0 {
        let gap = (ans.point_b - ans.point_a).norm();
        // Far from the origin the points' coordinates round by ε of it.
        assert!(
            within(gap, exact, size) || (gap - exact).abs() <= fuzz,
            "{what}: points {gap} apart vs {exact}"
        );
    }
    ans
}

fn cyl(r: f64, h: f64, rounding: f64) -> Shape {
    Convex::cylinder(r, h, rounding).unwrap().into()
}

fn at(x: f64, y: f64, z: f64) -> Isometry3<f64> {
    Isometry3::translation(x, y, z)
}

/// Scales and base offsets the closed forms are checked at.
const SCALES: [f64; 5] = [1e-9, 1e-3, 1.0, 1e3, 1e6];
const BASES: [f64; 3] = [0.0, 1e3, 1e9];

/// Two poses `base` and `base + off`, and the offset as the poses hold it
/// (the sum rounds far from the origin; the closed form must use what the
/// query sees).
fn pair_at(base: f64, off: Vector3<f64>) -> (Isometry3<f64>, Isometry3<f64>, Vector3<f64>) {
    let pa = at(base, -base, base);
    let pb = at(base + off.x, -base + off.y, base + off.z);
    let held = pb.translation.vector - pa.translation.vector;
    (pa, pb, held)
}

#[test]
fn parallel_axes_side_by_side() {
    for s in SCALES {
        for base in BASES {
            if base * 1e-12 > s {
                continue; // The offset would round to nothing.
            }
            let (r1, h1, r2, h2, rho1, rho2) = (0.5 * s, 1.0 * s, 0.3 * s, 2.0 * s, 0.05 * s, 0.0);
            let a = cyl(r1, h1, rho1);
            let b = cyl(r2, h2, rho2);
            for (gap, dz) in [
                (0.2, 0.5),
                (1e-3, -1.5),
                (0.0, 0.0),
                (-0.1, 0.3),
                (3.0, 2.9),
            ] {
                let centre = r1 + r2 + rho1 + rho2 + gap * s;
                let dir = Vector3::new(0.6, -0.8, 0.0);
                let (pa, pb, held) = pair_at(base, dir * centre + Vector3::new(0.0, 0.0, dz * s));
                let exact = (held.xy().norm() - r1 - r2 - rho1 - rho2).max(0.0);
                check(
                    &a,
                    &pa,
                    &b,
                    &pb,
                    Expect {
                        exact,
                        size: s,
                        mag: s + base,
                    },
                    &format!("side s {s} base {base} gap {gap}"),
                );
            }
        }
    }
}

#[test]
fn coaxial_end_caps() {
    for s in SCALES {
        for base in BASES {
            if base * 1e-12 > s {
                continue;
            }
            let a = cyl(1.0 * s, 0.5 * s, 0.0);
            let b = cyl(0.2 * s, 0.7 * s, 0.01 * s);
            for (gap, lateral) in [(0.3, 0.0), (1e-4, 0.9), (0.0, 0.5), (2.0, 1.1)] {
                let off = Vector3::new(lateral * s, 0.0, (0.5 + 0.7 + 0.01 + gap) * s);
                let (pa, pb, held) = pair_at(base, off);
                let exact = (held.z - 0.5 * s - 0.7 * s - 0.01 * s).max(0.0);
                check(
                    &a,
                    &pa,
                    &b,
                    &pb,
                    Expect {
                        exact,
                        size: s,
                        mag: s + base,
                    },
                    &format!("caps s {s} base {base} gap {gap}"),
                );
            }
        }
    }
}

#[test]
fn end_cap_and_side_against_a_box_face() {
    for s in SCALES {
        for base in BASES {
            if base * 1e-12 > s {
                continue;
            }
            let boxed: Shape = Convex::cuboid(Vector3::new(2.0, 3.0, 0.5) * s, 0.0)
                .unwrap()
                .into();
            let can = cyl(0.4 * s, 0.6 * s, 0.0);
            for gap in [0.25, 1e-5, 0.0] {
                // Upright, its bottom cap over the box's top face.
                let (pa, pb, held) = pair_at(base, Vector3::new(0.7, -1.1, 0.5 + 0.6 + gap) * s);
                let exact = held.z - 1.1 * s;
                check(
                    &boxed,
                    &pa,
                    &can,
                    &pb,
                    Expect {
                        exact: exact.max(0.0),
                        size: s,
                        mag: s + base,
                    },
                    &format!("cap/face s {s} base {base} gap {gap}"),
                );
                // Lying on its side (axis along x): its side over the face.
                let (pa, pb, held) = pair_at(base, Vector3::new(0.2, 0.3, 0.5 + 0.4 + gap) * s);
                let lying =
                    pb * UnitQuaternion::from_euler_angles(0.0, std::f64::consts::FRAC_PI_2, 0.0);
                let exact = held.z - 0.9 * s;
                check(
                    &boxed,
                    &pa,
                    &can,
                    &lying,
                    Expect {
                        exact: exact.max(0.0),
                        size: s,
                        mag: s + base,
                    },
                    &format!("side/face s {s} base {base} gap {gap}"),
                );
            }
        }
    }
}

/// A distance in closed form, of a sphere centre's offset.
type ClosedForm = fn(Vector3<f64>) -> f64;

#[test]
fn sphere_against_side_cap_and_rim() {
    let (r, h, ball) = (0.8, 1.2, 0.3);
    for s in SCALES {
        for base in BASES {
            if base * 1e-12 > s {
                continue;
            }
            let can = cyl(r * s, h * s, 0.0);
            let sphere: Shape = Convex::sphere(ball * s).unwrap().into();
            let cases: [(Vector3<f64>, ClosedForm); 3] = [
                // Beside the side, within the height.
                (Vector3::new(1.5, 0.4, 0.9), |c| c.xy().norm() - 0.8 - 0.3),
                // Over the cap, within the disk.
                (Vector3::new(0.3, -0.2, 1.9), |c| c.z - 1.2 - 0.3),
                // Off the rim: beyond the side and above the cap.
                (Vector3::new(-1.1, 0.6, -1.7), |c| {
                    (c.xy().norm() - 0.8).hypot(c.z.abs() - 1.2) - 0.3
                }),
            ];
            for (centre, form) in cases {
                let (pa, pb, held) = pair_at(base, centre * s);
                let exact = form(held / s) * s;
                check(
                    &can,
                    &pa,
                    &sphere,
                    &pb,
                    Expect {
                        exact,
                        size: s,
                        mag: s + base,
                    },
                    &format!("sphere s {s} base {base} at {centre:?}"),
                );
            }
        }
    }
}

/// A rim touching a perpendicular cylinder's cap near its rim, found by
/// `cylinder_stress` (bench/examples): the run's first separating
/// direction came only after a hundred iterations, and the Newton seed
/// taken from it, at a distance lost in round-off, restarted the run,
/// which then hit the iteration cap a thousand judged bounds off (cold,
/// and warm from both caps' centres). The truth is the stress reference's
/// bracket (alternating projections and closed-form support functions),
/// both ends within 1e-17 of it.
#[test]
fn rim_touching_a_perpendicular_cap_is_not_reseeded() {
    let pose = |t: [f64; 3], q: [f64; 4]| {
        Isometry3::from_parts(
            Translation3::new(t[0], t[1], t[2]),
            UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3])),
        )
    };
    let cold_case = (
        cyl(0.03910272096730396, 0.039577244213837626, 0.0),
        pose(
            [-115.18324912166604, 231.27114400726663, 23.913074181739383],
            [
                0.41051905424610213,
                -0.9116566391037441,
                -0.0016298462769313918,
                -0.018804841931399054,
            ],
        ),
        cyl(0.05053096488986053, 9.505416056180188e-8, 0.0),
        pose(
            [-115.22460045378655, 231.34572219962587, 23.902428758485044],
            [
                0.9333756214996974,
                -0.3541460648892098,
                0.006185773811807788,
                -0.05789861929174282,
            ],
        ),
        None,
        4.345e-15,
        0.03910272096730396f64.hypot(0.039577244213837626),
    );
    let warm_case = (
        cyl(0.4618163061956477, 0.2902422242669282, 0.0),
        pose(
            [-9.761426453562613, 438.5069692938249, 78.11639897925818],
            [
                0.7912771848476325,
                0.2319183859249886,
                0.5445937974087482,
                0.15333582371211407,
            ],
        ),
        cyl(0.6430367782529866, 0.047543788989737046, 0.0),
        pose(
            [-9.467129866015124, 438.7653290770869, 78.95974629871141],
            [
                0.5994013419989748,
                -0.40212134576332054,
                0.4509074626628472,
                0.5250703901442901,
            ],
        ),
        WarmStart::new([0, 0], &[[0, 0]]),
        1.883e-14,
        0.6430367782529866f64.hypot(0.047543788989737046),
    );
    for (what, (a, pa, b, pb, warm, truth, size)) in [("cold", cold_case), ("warm", warm_case)] {
        let ans = distance(&a, &pa, &b, &pb, &Options::default(), warm.as_ref()).unwrap();
        assert!(
            within(ans.distance, truth, size),
            "{what}: {} ({:?}) vs {truth}",
            ans.distance,
            ans.status
        );
        assert!(
            ans.lower <= truth + 1e-17 && truth <= ans.upper + 1e-17,
            "{what}"
        );
    }
}

/// Two long cylinders whose axes cross at any angle, `D` apart along their
/// common perpendicular: the nearest points lie on it, `D - r1 - r2` apart.
#[test]
fn crossing_axes() {
    let mut seed = 0x5eed_c0ffee_u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for s in SCALES {
        for k in 0..40 {
            let angle = 0.2 + 2.7 * next();
            let (r1, r2) = (0.3 + next(), 0.1 + next());
            let gap = if k % 4 == 0 { 0.0 } else { next() * 2.0 };
            let d = (r1 + r2 + gap) * s;
            let a = cyl(r1 * s, 5.0 * s, 0.0);
            let b = cyl(r2 * s, 5.0 * s, 0.0);
            // A along z; B's axis turned about y (the common perpendicular)
            // by `angle`, then moved D along y, and both turned at random.
            let turn = UnitQuaternion::from_euler_angles(next() * 6.0, next() * 6.0, next() * 6.0);
            let pa = Isometry3::from_parts(Translation3::identity(), turn);
            let pb = Isometry3::from_parts(
                Translation3::from(turn * Vector3::new(0.0, d, 0.0)),
                turn * UnitQuaternion::from_euler_angles(0.0, angle, 0.0),
            );
            check(
                &a,
                &pa,
                &b,
                &pb,
                Expect {
                    exact: gap * s,
                    size: s,
                    mag: s,
                },
                &format!("crossing s {s} angle {angle}"),
            );
        }
    }
}

/// An `n`-sided prism with its vertices at radius `rim`.
fn prism(rim: f64, h: f64, n: usize) -> Convex {
    let mut pts = Vec::with_capacity(2 * n);
    for k in 0..n {
        let t = std::f64::consts::TAU * k as f64 / n as f64;
        for z in [-h, h] {
            pts.push(Point3::new(rim * t.cos(), rim * t.sin(), z));
        }
    }
    Convex::new(pts, 0.0).unwrap()
}

/// The inscribed and circumscribed prisms bracket the cylinder: its
/// distance to anything lies between theirs, so between the outer prism's
/// lower bound and the inner prism's upper bound; at random poses, against
/// boxes, cylinders and point clouds, its answer and its bounds agree.
#[test]
fn fine_prisms_bracket_random_poses() {
    let n = 4096;
    let widen = 1.0 / (std::f64::consts::PI / n as f64).cos();
    let mut seed = 0x5eed_b7ac_4e70_0001_u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let (r, h) = (0.7, 1.1);
    let can = cyl(r, h, 0.0);
    let inner: Shape = prism(r, h, n).into();
    let outer: Shape = prism(r * widen, h, n).into();
    let others: Vec<Shape> = vec![
        Convex::cuboid(Vector3::new(0.5, 0.2, 0.9), 0.0)
            .unwrap()
            .into(),
        cyl(0.4, 0.3, 0.1),
        Convex::new(
            (0..30)
                .map(|_| Point3::new(next(), next(), next()))
                .collect::<Vec<_>>(),
            0.0,
        )
        .unwrap()
        .into(),
    ];
    for k in 0..600 {
        let other = &others[k % others.len()];
        let reach = if k % 5 == 0 { 1.6 } else { 4.0 };
        let pb = Isometry3::from_parts(
            Translation3::new(next() * reach, next() * reach, next() * reach),
            UnitQuaternion::from_euler_angles(next() * 3.0, next() * 3.0, next() * 3.0),
        );
        let pa = Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_euler_angles(next() * 3.0, next() * 3.0, next() * 3.0),
        );
        let opts = Options::default();
        let got = distance(&can, &pa, other, &pb, &opts, None).unwrap();
        let lo = distance(&outer, &pa, other, &pb, &opts, None)
            .unwrap()
            .lower;
        let hi = distance(&inner, &pa, other, &pb, &opts, None)
            .unwrap()
            .upper;
        let fuzz = 1e-12;
        assert!(
            lo - fuzz <= got.distance && got.distance <= hi + fuzz,
            "{k}: {} not in [{lo}, {hi}]",
            got.distance
        );
        // The bounds hold the bracket's part of the truth: they cannot both
        // miss it.
        assert!(
            got.lower <= hi + fuzz && got.upper >= lo - fuzz,
            "{k}: [{}, {}] vs [{lo}, {hi}]",
            got.lower,
            got.upper
        );
        assert!(
            got.upper - got.lower <= 1e-6 * got.distance + 1e-9,
            "{k}: loose bounds"
        );
    }
}

/// Along a motion past a cylinder, the warm start gives the cold answers
/// within the tolerance and takes fewer iterations; its codes round-trip
/// through the public `WarmStart`.
#[test]
fn warm_start_along_a_motion_matches_cold() {
    let can = cyl(0.5, 1.0, 0.02);
    let other = cyl(0.3, 0.6, 0.0);
    let (mut warm, mut cold_iterations, mut warm_iterations) = (None::<WarmStart>, 0, 0);
    for k in 0..500 {
        let t = k as f64 / 499.0;
        let pose = Isometry3::from_parts(
            Translation3::new(-3.0 + 6.0 * t, 0.2, 0.9 * (4.0 * t).sin()),
            UnitQuaternion::from_scaled_axis(Vector3::new(0.3, 1.0, 0.5).normalize() * 6.0 * t),
        );
        let id = Isometry3::identity();
        let opts = Options::default();
        let cold = distance(&can, &id, &other, &pose, &opts, None).unwrap();
        let hot = distance(&can, &id, &other, &pose, &opts, warm.as_ref()).unwrap();
        assert!(
            within(hot.distance, cold.distance, 1.0),
            "{k}: {} vs {}",
            hot.distance,
            cold.distance
        );
        assert!(hot.lower <= cold.upper && cold.lower <= hot.upper, "{k}");
        cold_iterations += cold.iterations;
        warm_iterations += hot.iterations;
        let pairs = hot.warm_start.pairs();
        warm = WarmStart::new(hot.warm_start.pieces(), pairs);
    }
    assert!(
        warm_iterations < cold_iterations,
        "{warm_iterations} vs {cold_iterations}"
    );
}

/// A box moving past a cylinder, each query from the previous answer: the
/// answer runs over the box's faces (on either half of each), its edges
/// and the cylinder's rim and side, and from one step to the next the
/// seed must name the feature and the triangle of it that holds the
/// answer, so that the run certifies at once. Before the seed turned a
/// face's triangle towards the answer, let go of a face the answer had
/// left and chose a side's and an edge's parallelogram half, 228 of these
/// 3 000 steps took 3 to 33 iterations. Before a side let go was left on
/// the constraints still held, the step where the answer leaves the side
/// for the rim against a box edge took 12. Every 100th step is checked
/// against the bracket of the fine prisms, every step against the cold
/// query.
#[test]
fn warm_cylinder_against_a_box_certifies_at_once_along_a_motion() {
    let half = Vector3::new(0.4, 0.3, 0.5);
    let cuboid = bracketed_plain(Convex::cuboid(half, 0.0).unwrap().into(), half.norm());
    let (at_once, worst) = warm_motion_against(&cuboid);
    // A handful of steps remain where the answer changes feature, none
    // slower than its cold query by more than an iteration or two.
    assert!(at_once >= 2990, "{at_once} of 3000 in one iteration");
    assert!(worst <= 4, "a warm step took {worst} iterations");
}

/// A cylinder moving past another, as above: the answer runs over both
/// rims and sides (a side against a rim, a rim against a rim, near the
/// top cap's axis too), where the warm start's features are solved for in
/// closed form (`gjk/src/query/feature_seed.rs`), and the seed must be
/// exact enough for the run to certify at once. Before the closed form's
/// converged step shrank with a rim's sine to its axis, 67 of these steps,
/// near the axis, took 2 to 4 iterations; before two rims were solved on
/// their angles where the direction is nearer A's axis than the sphere's
/// closed form goes, 12 steps took 3 to 34.
#[test]
fn warm_cylinder_against_a_cylinder_certifies_at_once_along_a_motion() {
    let other = bracketed_cylinder(0.3, 0.6, 0.0);
    let (at_once, worst) = warm_motion_against(&other);
    // One step, where the answer changes feature, takes two.
    assert!(at_once >= 2998, "{at_once} of 3000 in one iteration");
    assert!(worst <= 2, "a warm step took {worst} iterations");
}

/// The steps, of 3 000 along a motion of `other` past a cylinder, whose
/// warm query certified in one iteration, and the most iterations a warm
/// step took; every step agrees with the cold query and every 100th with
/// the bracket of the fine prisms.
fn warm_motion_against(other: &Bracketed) -> (u32, u32) {
    let cylinder = bracketed_cylinder(0.5, 0.8, 0.0);
    let (opts, id) = (Options::default(), Isometry3::identity());
    let steps = 3000;
    let (mut warm, mut at_once, mut worst) = (None::<WarmStart>, 0, 0);
    for k in 0..steps {
        let t = f64::from(k) / f64::from(steps);
        let pose = Isometry3::from_parts(
            Translation3::new(-3.0 + 6.0 * t, 0.3, 1.4 * (3.0 * t).sin()),
            UnitQuaternion::from_scaled_axis(Vector3::new(0.3, 1.0, 0.5).normalize() * 5.0 * t),
        );
        let hot = distance(
            &cylinder.exact,
            &id,
            &other.exact,
            &pose,
            &opts,
            warm.as_ref(),
        )
        .unwrap();
        let cold = distance(&cylinder.exact, &id, &other.exact, &pose, &opts, None).unwrap();
        assert!(hot.lower <= cold.upper && cold.lower <= hot.upper, "{k}");
        assert!(within(hot.distance, cold.distance, 1.0), "{k}");
        if k % 100 == 0 {
            let lo = distance(&cylinder.outer, &id, &other.outer, &pose, &opts, None).unwrap();
            let hi = distance(&cylinder.inner, &id, &other.inner, &pose, &opts, None).unwrap();
            assert!(
                within_bracket(hot.distance, lo.lower, hi.upper, 1.0),
                "{k}: {} against [{}, {}]",
                hot.distance,
                lo.lower,
                hi.upper
            );
        }
        at_once += u32::from(hot.iterations == 1);
        if warm.is_some() {
            worst = worst.max(hot.iterations);
        }
        warm = Some(hot.warm_start);
    }
    (at_once, worst)
}

/// Random motions of boxes, point clouds' hulls and thin cylinders past a
/// cylinder, each query asked cold and from the previous answer: near
/// contact a cold run can crawl along a rim, an iteration a digit, and a
/// warm one seldom takes more than two iterations beyond its cold one;
/// every warm answer agrees with the cold one. Of these 48 161 separated
/// warm steps, before Newton's steps halved an overshoot into directions
/// that do not separate the shapes (near contact they are a narrow cone),
/// 188 cold queries took 20 or more iterations, then 113, and 101 once a
/// face whose seed projects past its outer edge was let go. Beyond cold + 2
/// and of 20 or more iterations warm: 12 and 23 before a run that crept
/// along a rim was read as the rim's and a warm seed no longer counted
/// against the run's two; 9 and 11 after; 5 and 3 with the halving.
#[test]
fn motions_past_a_cylinder_seldom_crawl_warm_or_cold() {
    let mut rng = Rng(0x5eed_7a11_0000_0001);
    let (opts, id) = (Options::default(), Isometry3::identity());
    let (mut steps, mut slower, mut crawled, mut cold_crawled) = (0u32, 0u32, 0u32, 0u32);
    for _ in 0..200 {
        let cylinder = cyl(rng.range(0.1, 1.1), rng.range(0.1, 1.1), 0.0);
        let other: Shape = match rng.range(0.0, 3.0) as u32 {
            0 => Convex::cuboid(
                Vector3::new(
                    rng.range(0.1, 1.1),
                    rng.range(0.1, 1.1),
                    rng.range(0.1, 1.1),
                ),
                0.0,
            )
            .unwrap()
            .into(),
            1 => {
                let points = (0..12).map(|_| Point3::new(rng.next(), rng.next(), rng.next()));
                Convex::new(points.collect::<Vec<_>>(), 0.0).unwrap().into()
            }
            _ => cyl(rng.range(0.05, 0.25), rng.range(0.5, 1.5), 0.0),
        };
        let start = Vector3::new(rng.next(), rng.next(), rng.next()) * 3.0;
        let travel = (Vector3::new(rng.next(), rng.next(), rng.next()) * 0.8 - start) * 2.0;
        let axis = Vector3::new(rng.next(), rng.next(), rng.next()).normalize();
        let spin = 3.0 * rng.next();
        let turned =
            UnitQuaternion::from_euler_angles(rng.next() * 3.0, rng.next() * 3.0, rng.next() * 3.0);
        let mut warm: Option<WarmStart> = None;
        for k in 0..400 {
            let t = f64::from(k) / 400.0;
            let pose = Isometry3::from_parts(
                Translation3::from(start + travel * t),
                UnitQuaternion::from_scaled_axis(axis * spin * t) * turned,
            );
            let hot = distance(&cylinder, &id, &other, &pose, &opts, warm.as_ref()).unwrap();
            let cold = distance(&cylinder, &id, &other, &pose, &opts, None).unwrap();
            assert!(hot.lower <= cold.upper && cold.lower <= hot.upper, "{k}");
            assert!(within(hot.distance, cold.distance, 1.0), "{k}");
            if warm.is_some() && cold.distance > 0.0 {
                steps += 1;
                slower += u32::from(hot.iterations > cold.iterations + 2);
                crawled += u32::from(hot.iterations >= 20);
                cold_crawled += u32::from(cold.iterations >= 20);
            }
            warm = Some(hot.warm_start);
        }
    }
    assert!(steps > 40_000, "{steps} separated warm steps");
    assert!(slower <= 6, "{slower} of {steps} slower than cold + 2");
    assert!(crawled <= 5, "{crawled} of {steps} took 20 or more");
    assert!(
        cold_crawled <= 110,
        "{cold_crawled} of {steps} took 20 or more cold"
    );
}

/// Compounds holding cylinders, margins, f32 and hand-made warm starts
/// (any code is a point of the cylinder) all give the plain answer.
#[test]
fn every_path_takes_cylinders() {
    let can = Convex::cylinder(0.5, 1.0, 0.0).unwrap();
    let ball: Shape = Convex::sphere(0.25).unwrap().into();
    let pb = at(2.0, 0.0, 0.3);
    let exact = 1.25;
    let id = Isometry3::identity();
    let plain: Shape = can.clone().into();
    // As a compound's piece, beside a far one, the compound moved.
    let dumbbell: Shape = Compound::new(vec![
        (at(1.0, 0.0, 0.0), can.clone()),
        (
            at(-9.0, 0.0, 0.0),
            Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0).unwrap(),
        ),
    ])
    .unwrap()
    .into();
    let ans = distance(
        &dumbbell,
        &at(-1.0, 0.0, 0.0),
        &ball,
        &pb,
        &Options::default(),
        None,
    )
    .unwrap();
    assert!(
        within(ans.distance, exact, 1.0) && ans.pieces == [0, 0],
        "{ans:?}"
    );
    // Swapped order.
    let ans = distance(
        &ball,
        &pb,
        &dumbbell,
        &at(-1.0, 0.0, 0.0),
        &Options::default(),
        None,
    )
    .unwrap();
    assert!(within(ans.distance, exact, 1.0), "{ans:?}");
    // A margin the pair is proved beyond, and one it is within.
    for (margin, beyond) in [(1.0, true), (2.0, false)] {
        let opts = Options {
            margin: Some(margin),
            ..Options::default()
        };
        let ans = distance(&plain, &id, &ball, &pb, &opts, None).unwrap();
        assert!(ans.lower <= exact && exact <= ans.upper);
        assert_eq!(ans.lower > margin, beyond, "{ans:?}");
    }
    // f32 falls back to the exact support.
    let opts = Options {
        precision: Precision::Single,
        ..Options::default()
    };
    let ans = distance(&plain, &id, &ball, &pb, &opts, None).unwrap();
    assert!(within(ans.distance, exact, 1.0), "{ans:?}");
    // Any code is a valid warm start, the largest included.
    for pairs in [[[u32::MAX, 0]], [[0, 0]], [[1 << 31, 0]], [[12345, 0]]] {
        let w = WarmStart::new([0, 0], &pairs).unwrap();
        let ans = distance(&plain, &id, &ball, &pb, &Options::default(), Some(&w)).unwrap();
        assert!(within(ans.distance, exact, 1.0), "{pairs:?}: {ans:?}");
    }
    // A vertex index past the sphere's one vertex is still refused.
    let w = WarmStart::new([0, 0], &[[0, 1]]).unwrap();
    assert!(matches!(
        distance(&plain, &id, &ball, &pb, &Options::default(), Some(&w)),
        Err(gjk::Error::WarmStartOutOfRange)
    ));
}

#[test]
fn bad_dimensions_are_refused() {
    for (r, h, rounding) in [
        (-1.0, 1.0, 0.0),
        (1.0, f64::NAN, 0.0),
        (f64::INFINITY, 1.0, 0.0),
        (1.0, 6e300, 0.0),
        (4e300, 4e300, 0.0),
    ] {
        assert_eq!(
            Convex::cylinder(r, h, rounding),
            Err(gjk::Error::NonFiniteVertex(0))
        );
    }
    for rounding in [-0.1, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            Convex::cylinder(1.0, 1.0, rounding),
            Err(gjk::Error::InvalidRadius(_))
        ));
    }
    let c = Convex::cylinder(2.0, 3.0, 0.5).unwrap();
    assert_eq!(c.cylinder_dimensions(), Some((2.0, 3.0)));
    assert_eq!(c.radius(), 0.5);
    assert!(c.vertices().is_empty());
    // Flat and needle cylinders are valid: a disk and a segment.
    let disk = cyl(1.0, 0.0, 0.0);
    let needle = cyl(0.0, 1.0, 0.0);
    let ans = distance(
        &disk,
        &Isometry3::identity(),
        &needle,
        &at(0.0, 0.0, 1.5),
        &Options::default(),
        None,
    )
    .unwrap();
    assert!(within(ans.distance, 0.5, 1.0), "{ans:?}");
}

/// A seeded xorshift generator, uniform in [-1, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    /// Uniform in [lo, hi).
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * 0.5 * (self.next() + 1.0)
    }

    fn rotation(&mut self) -> UnitQuaternion<f64> {
        UnitQuaternion::from_euler_angles(self.next() * 3.2, self.next() * 1.6, self.next() * 3.2)
    }

    fn unit(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(self.next(), self.next(), self.next());
            let n = v.norm();
            if n > 0.1 && n <= 1.0 {
                return v / n;
            }
        }
    }
}

/// A shape of the sweep with its bracket: the shape itself, and what
/// replaces it in the reference queries from inside and from outside (a
/// cylinder's inscribed and circumscribed fine prisms; anything else is
/// its own bracket).
struct Bracketed {
    exact: Shape,
    inner: Shape,
    outer: Shape,
    size: f64,
}

/// Sides of the reference prisms: the circumscribed one reaches
/// `1/cos(π/n) - 1 < 1.2e-9` of the radius past the cylinder, inside the
/// judged absolute bound of 1e-9 of the size.
const FINE_SIDES: usize = 65_536;

fn bracketed_cylinder(r: f64, h: f64, rounding: f64) -> Bracketed {
    let widen = 1.0 / (std::f64::consts::PI / FINE_SIDES as f64).cos();
    let with_rounding =
        |c: Convex| -> Shape { Convex::new(c.vertices().to_vec(), rounding).unwrap().into() };
    Bracketed {
        exact: cyl(r, h, rounding),
        inner: with_rounding(prism(r, h, FINE_SIDES)),
        outer: with_rounding(prism(r * widen, h, FINE_SIDES)),
        size: r.hypot(h) + rounding,
    }
}

fn bracketed_plain(shape: Shape, size: f64) -> Bracketed {
    Bracketed {
        exact: shape.clone(),
        inner: shape.clone(),
        outer: shape,
        size,
    }
}

/// How B is placed about A in the sweep.
#[derive(Clone, Copy, Debug)]
enum Placement {
    /// Random rotation, centre 1 to 4 sizes away.
    Random,
    /// Moved along the normal of a random placement until the two touch.
    Touching,
    /// B's axis parallel (or antiparallel) to A's, beside it or overlapping.
    ParallelAxes,
    /// B's z axis along A's, B beyond A's end cap: cap against cap or face.
    EndCap,
}

/// The judged error bound around the fine-prism bracket `[lo, hi]` (which
/// holds the truth): an answer within it of both ends is within it of
/// the truth.
fn within_bracket(got: f64, lo: f64, hi: f64, size: f64) -> bool {
    let bound = 1e-6 * lo.max(0.0) + 1e-9 * size;
    (got - lo).abs() <= bound && (got - hi).abs() <= bound
}

/// A hidden-set-like sweep: random cylinders (some rounded, some flat or
/// needle-thin) against cylinders, boxes, spheres and point clouds, from
/// 1e-9 to 1e6 in size, at the origin and far from it, placed at random,
/// touching, with parallel axes and cap against face. Every answer is
/// within the judged error bound of the truth, bracketed by the fine
/// prisms' certified bounds, and its own bounds contain that bracket's
/// share of the truth.
#[test]
fn hidden_like_sweep_against_fine_prisms() {
    let mut rng = Rng(0x5eed_c711_5eeb_0001);
    let mut checked = 0;
    for scale in SCALES {
        // Unit-sized shapes, built once per scale.
        let mut shapes = vec![
            bracketed_cylinder(0.5 * scale, 0.8 * scale, 0.0),
            bracketed_cylinder(0.3 * scale, 0.05 * scale, 0.02 * scale),
            bracketed_cylinder(0.02 * scale, 1.0 * scale, 0.0),
        ];
        let box_half = Vector3::new(0.4, 0.3, 0.6) * scale;
        shapes.push(bracketed_plain(
            Convex::cuboid(box_half, 0.0).unwrap().into(),
            box_half.norm(),
        ));
        shapes.push(bracketed_plain(
            Convex::sphere(0.35 * scale).unwrap().into(),
            0.35 * scale,
        ));
        let cloud: Vec<Point3<f64>> = (0..20)
            .map(|_| Point3::from(Vector3::new(rng.next(), rng.next(), rng.next()) * 0.5 * scale))
            .collect();
        shapes.push(bracketed_plain(
            Convex::new(cloud, 0.0).unwrap().into(),
            0.9 * scale,
        ));
        // Far from the origin: 1e9 for shapes whose size the coordinates
        // there still resolve, else a million sizes out.
        let far = if scale >= 1e-3 { 1e9 } else { 1e6 * scale };
        for base in [0.0, far] {
            for a in 0..3 {
                for (b, other) in shapes.iter().enumerate() {
                    for placement in [
                        Placement::Random,
                        Placement::Touching,
                        Placement::ParallelAxes,
                        Placement::EndCap,
                    ] {
                        let what =
                            format!("scale {scale:e}, base {base:e}, {a}/{b}, {placement:?}");
                        sweep_case(&mut rng, &shapes[a], other, scale, base, placement, &what);
                        checked += 1;
                    }
                }
            }
        }
    }
    assert_eq!(checked, SCALES.len() * 2 * 3 * 6 * 4);
}

/// One case of the sweep (see [`hidden_like_sweep_against_fine_prisms`]).
fn sweep_case(
    rng: &mut Rng,
    a: &Bracketed,
    b: &Bracketed,
    scale: f64,
    base: f64,
    placement: Placement,
    what: &str,
) {
    let opts = Options::default();
    let rot_a = rng.rotation();
    let axis_a = rot_a * Vector3::z();
    let pa = Isometry3::from_parts(Translation3::new(base, -base, base), rot_a);
    let place = |offset: Vector3<f64>, rot: UnitQuaternion<f64>| {
        Isometry3::from_parts(Translation3::from(pa.translation.vector + offset), rot)
    };
    let pb = match placement {
        Placement::Random | Placement::Touching => {
            let pb = place(rng.unit() * rng.range(1.0, 4.0) * scale, rng.rotation());
            if matches!(placement, Placement::Touching) {
                let ans = distance(&a.exact, &pa, &b.exact, &pb, &opts, None).unwrap();
                place(
                    pb.translation.vector - pa.translation.vector - ans.normal * ans.distance,
                    pb.rotation,
                )
            } else {
                pb
            }
        }
        Placement::ParallelAxes => {
            let flip = if rng.next() > 0.0 {
                UnitQuaternion::identity()
            } else {
                UnitQuaternion::from_scaled_axis(Vector3::x() * std::f64::consts::PI)
            };
            let spin = UnitQuaternion::from_scaled_axis(Vector3::z() * rng.next() * 3.0);
            let side = rot_a * Vector3::new(rng.next(), rng.next(), 0.0).normalize();
            let offset = side * rng.range(0.3, 1.5) * scale + axis_a * rng.next() * scale;
            place(offset, rot_a * flip * spin)
        }
        Placement::EndCap => {
            let spin = UnitQuaternion::from_scaled_axis(Vector3::z() * rng.next() * 3.0);
            let sideways = rot_a * Vector3::new(rng.next(), rng.next(), 0.0) * 0.6 * scale;
            let offset = axis_a * rng.range(0.9, 2.0) * scale + sideways;
            place(offset, rot_a * spin)
        }
    };
    let got = distance(&a.exact, &pa, &b.exact, &pb, &opts, None).unwrap();
    let lo = distance(&a.outer, &pa, &b.outer, &pb, &opts, None)
        .unwrap()
        .lower;
    let hi = distance(&a.inner, &pa, &b.inner, &pb, &opts, None)
        .unwrap()
        .upper;
    let size = a.size + b.size;
    assert_eq!(got.status, Status::Converged, "{what}");
    assert!(lo <= hi + 1e-12 * size, "{what}: bracket [{lo}, {hi}]");
    assert!(
        within_bracket(got.distance, lo, hi, size),
        "{what}: {} vs [{lo}, {hi}]",
        got.distance
    );
    // The bounds are certified: they cannot both miss the bracket, and
    // they are no wider than the judged bound.
    let fuzz = 1e-12 * size;
    assert!(
        got.lower <= hi + fuzz && got.upper >= lo - fuzz,
        "{what}: [{}, {}] vs [{lo}, {hi}]",
        got.lower,
        got.upper
    );
    assert!(
        got.upper - got.lower <= 1e-6 * got.distance + 1e-9 * size,
        "{what}: bounds [{}, {}]",
        got.lower,
        got.upper
    );
}
