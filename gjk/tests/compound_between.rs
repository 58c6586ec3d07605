//! Compounds of support maps through the public API
//! (`distance_between_compounds`): unions of ellipsoids (a shape the crate
//! does not have, `shapes/ellipsoid.rs`) and of the crate's own shapes,
//! mixed in one compound through a piece type of the test's own.
//!
//! A union's distance is the least over its piece pairs, (2.3) and (2.8).
//! The truth is that minimum taken independently of the union search:
//! against balls, each ellipsoid's dense surface distance to the ball's
//! centre; otherwise each piece pair asked alone through
//! `distance_between`, the pieces placed by hand. Every certified interval
//! must hold the truth, cold and warm along a motion.

#[path = "shapes/ellipsoid.rs"]
mod ellipsoid;

use ellipsoid::{Ellipsoid, surface_distance};
use gjk::{
    Compound, Convex, Error, Options, SeedForm, Shape, SupportMap, WarmStart, distance,
    distance_between, distance_between_compounds,
};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// A compound's piece: an ellipsoid, or one of the crate's shapes. A
/// compound holds one piece type, so pieces of several kinds go through
/// an enum of the caller's, which delegates each method, the seed hook
/// included (a cylinder piece keeps its seeded run).
enum Piece {
    Egg(Ellipsoid),
    Stored(Convex),
}

impl SupportMap for Piece {
    fn local_support(&self, dir: &Vector3<f64>) -> (usize, Vector3<f64>) {
        match self {
            Piece::Egg(e) => e.local_support(dir),
            Piece::Stored(c) => c.local_support(dir),
        }
    }

    fn local_point(&self, index: usize) -> Vector3<f64> {
        match self {
            Piece::Egg(e) => e.local_point(index),
            Piece::Stored(c) => c.local_point(index),
        }
    }

    fn centre(&self) -> Point3<f64> {
        match self {
            Piece::Egg(e) => e.centre(),
            Piece::Stored(c) => c.centre(),
        }
    }

    fn rounding(&self) -> f64 {
        match self {
            Piece::Egg(e) => e.rounding(),
            Piece::Stored(c) => c.rounding(),
        }
    }

    fn size(&self) -> f64 {
        match self {
            Piece::Egg(e) => e.size(),
            Piece::Stored(c) => c.size(),
        }
    }

    fn index_count(&self) -> usize {
        match self {
            Piece::Egg(e) => e.index_count(),
            Piece::Stored(c) => c.index_count(),
        }
    }

    fn seed_form(&self) -> Option<SeedForm> {
        match self {
            Piece::Egg(e) => e.seed_form(),
            Piece::Stored(c) => c.seed_form(),
        }
    }
}

fn rotation(seed: u64) -> UnitQuaternion<f64> {
    let t = seed as f64;
    UnitQuaternion::from_euler_angles(0.7 * t + 0.3, 1.3 * t - 0.2, 0.4 * t + 1.1)
}

/// The least distance over piece pairs, each pair asked alone (no union
/// search: every pair runs, cold, its pieces placed by hand), with the
/// pair's certified interval and its pieces.
fn least_over_pairs<A: SupportMap, B: SupportMap>(
    a: &Compound<A>,
    pose_a: &Isometry3<f64>,
    b: &Compound<B>,
    pose_b: &Isometry3<f64>,
) -> (f64, f64, f64, [u32; 2]) {
    let mut best = (f64::INFINITY, f64::INFINITY, f64::INFINITY, [0, 0]);
    for (i, (offset_a, piece_a)) in a.pieces().iter().enumerate() {
        for (j, (offset_b, piece_b)) in b.pieces().iter().enumerate() {
            let answer = distance_between(
                piece_a,
                &(pose_a * offset_a),
                piece_b,
                &(pose_b * offset_b),
                &Options::default(),
                None,
            )
            .expect("a piece pair");
            if answer.distance < best.0 {
                best = (
                    answer.distance,
                    answer.lower,
                    answer.upper,
                    [i as u32, j as u32],
                );
            }
        }
    }
    best
}

/// Three ellipsoids in a row, turned apart.
fn eggs() -> Compound<Ellipsoid> {
    Compound::new(vec![
        (
            Isometry3::translation(-1.5, 0.0, 0.0),
            Ellipsoid::new(0.8, 0.4, 0.3),
        ),
        (
            Isometry3::from_parts(Translation3::new(0.0, 0.3, 0.0), rotation(7)),
            Ellipsoid::new(0.6, 0.5, 0.2),
        ),
        (
            Isometry3::translation(1.5, 0.0, 0.2),
            Ellipsoid::new(0.5, 0.5, 0.5),
        ),
    ])
    .expect("a compound")
}

#[test]
fn ellipsoids_against_balls_match_a_dense_minimisation() {
    let eggs = eggs();
    let radii = [0.25, 0.4];
    let balls = Compound::new(vec![
        (
            Isometry3::translation(0.0, 0.0, 0.0),
            Convex::sphere(radii[0]).expect("ball"),
        ),
        (
            Isometry3::translation(0.0, 1.2, 0.5),
            Convex::sphere(radii[1]).expect("ball"),
        ),
    ])
    .expect("a compound");
    let options = Options::default();
    let mut warm: Option<WarmStart> = None;
    for seed in 0..10 {
        let pose_a = Isometry3::from_parts(Translation3::new(0.1, -0.2, 0.3), rotation(seed));
        let angle = 0.6 * seed as f64;
        let pose_b = Isometry3::from_parts(
            Translation3::new(2.6 * angle.cos(), 2.2 * angle.sin(), 0.4),
            rotation(seed + 20),
        );
        // The truth: each ball's centre against each ellipsoid's surface.
        let mut truth = f64::INFINITY;
        let mut nearest = [0, 0];
        for (i, (offset_a, egg)) in eggs.pieces().iter().enumerate() {
            for (j, (offset_b, _)) in balls.pieces().iter().enumerate() {
                let centre = pose_b * offset_b * Point3::origin();
                let in_egg = (pose_a * offset_a).inverse_transform_point(&centre).coords;
                let d = surface_distance(egg, &in_egg) - radii[j];
                if d < truth {
                    (truth, nearest) = (d, [i as u32, j as u32]);
                }
            }
        }
        assert!(truth > 0.05, "seed {seed}: the poses keep the unions apart");
        for (how, warm) in [("cold", None), ("warm", warm.as_ref())] {
            let answer =
                distance_between_compounds(&eggs, &pose_a, &balls, &pose_b, &options, warm)
                    .expect("queried");
            assert!(
                (answer.distance - truth).abs() <= 1e-8,
                "seed {seed} {how}: {} against {truth}",
                answer.distance
            );
            // The grid's answer is itself within about 1e-12 of the truth.
            assert!(
                answer.lower <= truth + 1e-11 && truth - 1e-11 <= answer.upper,
                "seed {seed} {how}: [{}, {}] against {truth}",
                answer.lower,
                answer.upper
            );
            assert_eq!(answer.pieces, nearest, "seed {seed} {how}");
        }
        warm = Some(
            distance_between_compounds(&eggs, &pose_a, &balls, &pose_b, &options, None)
                .expect("queried")
                .warm_start,
        );
    }
}

/// An ellipsoid and a box in one compound, a cylinder and a capsule in
/// the other, through [`Piece`].
fn mixed() -> (Compound<Piece>, Compound<Piece>) {
    let a = Compound::new(vec![
        (
            Isometry3::translation(-0.8, 0.0, 0.0),
            Piece::Egg(Ellipsoid::new(0.7, 0.4, 0.3)),
        ),
        (
            Isometry3::from_parts(Translation3::new(0.8, 0.2, 0.0), rotation(3)),
            Piece::Stored(Convex::cuboid(Vector3::new(0.3, 0.5, 0.2), 0.0).expect("box")),
        ),
    ])
    .expect("a compound");
    let b = Compound::new(vec![
        (
            Isometry3::identity(),
            Piece::Stored(Convex::cylinder(0.3, 0.6, 0.0).expect("cylinder")),
        ),
        (
            Isometry3::translation(0.0, 1.0, 0.0),
            Piece::Stored(
                Convex::capsule(Point3::new(-0.5, 0.0, 0.0), Point3::new(0.5, 0.0, 0.0), 0.1)
                    .expect("capsule"),
            ),
        ),
    ])
    .expect("a compound");
    (a, b)
}

#[test]
fn mixed_pieces_take_the_least_of_their_pairs_along_a_motion() {
    let (a, b) = mixed();
    let options = Options::default();
    let mut warm: Option<WarmStart> = None;
    for k in 0..40 {
        let s = k as f64 / 40.0;
        let pose_a = Isometry3::from_parts(
            Translation3::new(0.0, 0.0, 0.0),
            UnitQuaternion::from_euler_angles(0.3 * s, 0.8 * s, 1.5 * s),
        );
        let pose_b = Isometry3::from_parts(
            Translation3::new(2.5 - 1.2 * s, 0.5 * s - 0.4, 0.6 - 0.5 * s),
            rotation(k / 8),
        );
        let (truth, lower, upper, nearest) = least_over_pairs(&a, &pose_a, &b, &pose_b);
        assert!(truth > 0.0, "step {k}: the motion keeps the unions apart");
        let cold = distance_between_compounds(&a, &pose_a, &b, &pose_b, &options, None)
            .expect("queried cold");
        let warmed = distance_between_compounds(&a, &pose_a, &b, &pose_b, &options, warm.as_ref())
            .expect("queried warm");
        for (how, answer) in [("cold", &cold), ("warm", &warmed)] {
            assert!(
                (answer.distance - truth).abs() <= 1e-9,
                "step {k} {how}: {} against {truth}",
                answer.distance
            );
            // Both intervals hold the distance: they overlap, and the
            // union's upper bound is a pair's own.
            assert!(
                answer.lower <= upper && lower <= answer.upper,
                "step {k} {how}: [{}, {}] against [{lower}, {upper}]",
                answer.lower,
                answer.upper
            );
            assert_eq!(answer.pieces, nearest, "step {k} {how}");
        }
        warm = Some(warmed.warm_start);
    }
}

#[test]
fn convex_pieces_answer_as_through_distance() {
    // The stored shapes' compounds: the same search, so the same answer,
    // bit for bit, as `distance` on the `Shape`s.
    let ball = Convex::sphere(0.4).expect("ball");
    let block = Convex::cuboid(Vector3::new(0.5, 0.3, 0.2), 0.05).expect("box");
    let can = Convex::cylinder(0.3, 0.5, 0.0).expect("cylinder");
    let a = Compound::new(vec![
        (Isometry3::translation(-1.0, 0.0, 0.0), ball.clone()),
        (Isometry3::translation(1.0, 0.0, 0.0), block),
    ])
    .expect("a compound");
    let b = Compound::new(vec![
        (Isometry3::identity(), can),
        (Isometry3::translation(0.0, 0.0, 1.2), ball),
    ])
    .expect("a compound");
    let (shape_a, shape_b) = (Shape::from(a.clone()), Shape::from(b.clone()));
    let options = Options::default();
    let mut warm: Option<WarmStart> = None;
    for seed in 0..20 {
        let pose_a = Isometry3::from_parts(Translation3::new(0.0, 0.1, 0.0), rotation(seed));
        let angle = 0.4 * seed as f64;
        let pose_b = Isometry3::from_parts(
            Translation3::new(2.4 * angle.cos(), 2.4 * angle.sin(), 0.1),
            rotation(seed + 5),
        );
        let through_shapes = distance(
            &shape_a,
            &pose_a,
            &shape_b,
            &pose_b,
            &options,
            warm.as_ref(),
        )
        .expect("queried");
        let through_compounds =
            distance_between_compounds(&a, &pose_a, &b, &pose_b, &options, warm.as_ref())
                .expect("queried");
        assert_eq!(through_compounds, through_shapes, "seed {seed}");
        warm = Some(through_shapes.warm_start);
    }
}

#[test]
fn bad_input_is_refused() {
    let (a, b) = mixed();
    let options = Options::default();
    let (pose_a, pose_b) = (Isometry3::identity(), Isometry3::translation(3.0, 0.0, 0.0));
    // A warm start naming a piece B does not have.
    let beyond = WarmStart::new([0, 2], &[[0, 0]]).expect("a warm start");
    assert_eq!(
        distance_between_compounds(&a, &pose_a, &b, &pose_b, &options, Some(&beyond)),
        Err(Error::WarmStartOutOfRange)
    );
    // An index the ellipsoid never handed out.
    let unseen = WarmStart::new([0, 0], &[[1_000_000, 0]]).expect("a warm start");
    assert_eq!(
        distance_between_compounds(&a, &pose_a, &b, &pose_b, &options, Some(&unseen)),
        Err(Error::WarmStartOutOfRange)
    );
    let nan = Isometry3::translation(f64::NAN, 0.0, 0.0);
    assert_eq!(
        distance_between_compounds(&a, &nan, &b, &pose_b, &options, None),
        Err(Error::NonFinitePose)
    );
    let negative = Options {
        tolerance: -1.0,
        ..Options::default()
    };
    assert!(matches!(
        distance_between_compounds(&a, &pose_a, &b, &pose_b, &negative, None),
        Err(Error::InvalidOption(_))
    ));
    // No pieces: refused when built.
    assert_eq!(
        Compound::<Ellipsoid>::new(Vec::new()).err(),
        Some(Error::EmptyCompound)
    );
}
