//! `gjk::separation_bound` and `gjk::penetration_bound`, the cheap
//! re-certifications of a kept answer at new poses, against the
//! brute-force distance and depth of `gjkd_testkit::reference`: never
//! above the truth (far from the origin and at extreme sizes too), equal
//! to the analytic answer where there is one, and proving nothing from
//! bad input.

mod common;

use common::{pose, vec3};

use gjk::{
    Compound, Convex, Options, Shape, WarmStart, distance, penetration_bound, separation_bound,
};
use gjkd_testkit::check::{shape_distance, world_pieces};
use gjkd_testkit::reference::{P, hull_distance, penetration_depth};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use proptest::prelude::*;
use proptest::test_runner::Config;

fn config() -> Config {
    common::config(0x7265_6368)
}

fn points() -> impl Strategy<Value = Vec<P>> {
    prop::collection::vec(vec3().prop_map(P::from), 4..=12)
}

fn radius() -> impl Strategy<Value = f64> {
    prop_oneof![2 => Just(0.0), 1 => 0.0..0.3f64]
}

/// A convex piece, or a union of one to three.
fn shape() -> impl Strategy<Value = Shape> {
    prop_oneof![
        (points(), radius()).prop_map(|(p, r)| Convex::new(p, r).unwrap().into()),
        prop::collection::vec((pose(0.8), points(), radius()), 1..=3).prop_map(|pieces| {
            let pieces = pieces
                .into_iter()
                .map(|(o, p, r)| (o, Convex::new(p, r).unwrap()))
                .collect();
            Compound::new(pieces).unwrap().into()
        }),
    ]
}

/// The largest depth of a piece pair of `a` and `b` whose cores
/// intersect (0 if none do).
fn deepest_piece_pair(a: &Shape, pa: &Isometry3<f64>, b: &Shape, pb: &Isometry3<f64>) -> f64 {
    let mut deepest = 0.0f64;
    for x in world_pieces(a, pa) {
        for y in world_pieces(b, pb) {
            if hull_distance(&x.points, &y.points).distance == 0.0 {
                deepest = deepest.max(penetration_depth(&x.points, &y.points));
            }
        }
    }
    deepest
}

/// Point sets scaled by `s` and placed `off` sizes from the origin.
struct Extreme {
    s: f64,
    shift: Vector3<f64>,
    off: f64,
}

impl Extreme {
    fn new(s: f64, off: f64) -> Self {
        Extreme {
            s,
            shift: Vector3::new(off, -0.5 * off, 0.25 * off) * s,
            off,
        }
    }

    fn build(&self, pts: &[P]) -> Shape {
        let scaled: Vec<P> = pts.iter().map(|p| P::from(p.coords * self.s)).collect();
        Convex::new(scaled, 0.0).unwrap().into()
    }

    fn place(&self, p: &Isometry3<f64>) -> Isometry3<f64> {
        let at = p.translation.vector * self.s + self.shift;
        Isometry3::from_parts(Translation3::from(at), p.rotation)
    }

    /// The pose that [`Extreme::place`] takes to `p`.
    fn unplace(&self, p: &Isometry3<f64>) -> Isometry3<f64> {
        let at = (p.translation.vector - self.shift) / self.s;
        Isometry3::from_parts(Translation3::from(at), p.rotation)
    }

    /// What coordinates this far out and this large round off.
    fn tolerance(&self) -> f64 {
        1e-12 * self.s + 64.0 * (1.0 + self.off) * self.s * f64::EPSILON
    }
}

proptest! {
    #![proptest_config(config())]

    /// Any direction, unions and rounded pieces: the slab bound is at most
    /// the brute-force distance; along a convex pair's own normal it is
    /// that distance, to round-off.
    #[test]
    fn separation_bound_never_exceeds_the_distance(
        a in shape(), pa in pose(3.0), b in shape(), pb in pose(3.0),
        direction in vec3(), use_normal in prop::bool::ANY,
    ) {
        let truth = shape_distance(&a, &pa, &b, &pb);
        let answer = distance(&a, &pa, &b, &pb, &Options::default(), None).unwrap();
        let n = if use_normal { answer.normal } else { direction };
        let lower = separation_bound(&a, &pa, &b, &pb, &n);
        prop_assert!(lower <= truth.distance + 1e-12 * truth.scale,
            "bound {lower} above the distance {}", truth.distance);
        let convex = matches!((&a, &b), (Shape::Convex(_), Shape::Convex(_)));
        if use_normal && convex && answer.distance > 1e-6 * truth.scale {
            prop_assert!(lower >= answer.distance - 1e-6 * truth.scale,
                "along the normal, bound {lower} well below the distance {}", answer.distance);
        }
    }

    /// The same far from the origin and at tiny and huge sizes.
    #[test]
    fn separation_bound_holds_at_extremes(
        a in points(), pa in pose(3.0), b in points(), pb in pose(3.0), direction in vec3(),
        s in prop_oneof![Just(1e-9), Just(1.0), Just(1e9)],
        off in prop_oneof![Just(0.0), Just(1e6), Just(1e12)],
    ) {
        let x = Extreme::new(s, off);
        let (a, b, pa, pb) = (x.build(&a), x.build(&b), x.place(&pa), x.place(&pb));
        let truth = shape_distance(&a, &pa, &b, &pb);
        let tol = x.tolerance();
        for n in [direction, (pb.translation.vector - pa.translation.vector)] {
            let lower = separation_bound(&a, &pa, &b, &pb, &n);
            prop_assert!(lower <= truth.distance + tol,
                "scale {s:e}, offset {off:e}: bound {lower} above {}", truth.distance);
        }
    }

    /// A kept simplex of an overlapping pair, at poses moved by up to a
    /// step's worth: when it still proves an overlap, the cores do
    /// overlap, by at least that much.
    #[test]
    fn penetration_bound_never_exceeds_the_depth(
        a in shape(), pa in pose(0.4), b in shape(), pb in pose(0.4),
        da in pose(0.2), db in pose(0.2), turn in 0.0..0.5f64,
    ) {
        let answer = distance(&a, &pa, &b, &pb, &Options::default(), None).unwrap();
        let nudge = |p: &Isometry3<f64>, d: &Isometry3<f64>| {
            let r = UnitQuaternion::from_scaled_axis(d.rotation.scaled_axis() * turn);
            Isometry3::from_parts(Translation3::from(p.translation.vector + d.translation.vector), r * p.rotation)
        };
        for (qa, qb) in [(pa, pb), (nudge(&pa, &da), nudge(&pb, &db))] {
            let depth = penetration_bound(&a, &qa, &b, &qb, &answer.warm_start);
            prop_assert!(depth >= 0.0);
            if depth > 0.0 {
                let truth = deepest_piece_pair(&a, &qa, &b, &qb);
                let scale = shape_distance(&a, &qa, &b, &qb).scale;
                prop_assert!(depth <= truth + 1e-12 * scale,
                    "bound {depth} above the deepest piece pair's depth {truth}");
            }
        }
    }

    /// The same far from the origin and at tiny and huge sizes.
    #[test]
    fn penetration_bound_holds_at_extremes(
        a in points(), pa in pose(0.4), b in points(), pb in pose(0.4), db in pose(0.1),
        s in prop_oneof![Just(1e-9), Just(1.0), Just(1e9)],
        off in prop_oneof![Just(0.0), Just(1e6), Just(1e12)],
    ) {
        let x = Extreme::new(s, off);
        let (a, b, pa, pb) = (x.build(&a), x.build(&b), x.place(&pa), x.place(&pb));
        let answer = distance(&a, &pa, &b, &pb, &Options::default(), None).unwrap();
        let moved = x.place(&(db * x.unplace(&pb)));
        let depth = penetration_bound(&a, &pa, &b, &moved, &answer.warm_start);
        if depth > 0.0 {
            let truth = deepest_piece_pair(&a, &pa, &b, &moved);
            let tol = x.tolerance();
            prop_assert!(depth <= truth + tol,
                "scale {s:e}, offset {off:e}: bound {depth} above the depth {truth}");
        }
    }
}

/// Spheres, boxes and a cylinder: the slab bound along a direction is the
/// analytic gap of the two slabs.
#[test]
fn separation_bound_is_the_slab_gap_of_simple_shapes() {
    let id = Isometry3::identity();
    let ball = |r: f64| -> Shape { Convex::sphere(r).unwrap().into() };
    let far = Isometry3::translation(3.0, 4.0, 0.0);
    let lower = separation_bound(
        &ball(1.0),
        &id,
        &ball(0.5),
        &far,
        &Vector3::new(3.0, 4.0, 0.0),
    );
    assert!(lower <= 3.5 && lower > 3.5 - 1e-12, "{lower}");
    // Boxes, one turned about z by a quarter: the gap along x.
    let block = |h: Vector3<f64>| -> Shape { Convex::cuboid(h, 0.0).unwrap().into() };
    let turned = Isometry3::new(
        Vector3::new(5.0, 0.3, 0.0),
        Vector3::z() * std::f64::consts::FRAC_PI_2,
    );
    let (a, b) = (
        block(Vector3::new(1.0, 2.0, 3.0)),
        block(Vector3::new(0.5, 1.5, 1.0)),
    );
    let lower = separation_bound(&a, &id, &b, &turned, &Vector3::x());
    assert!(lower <= 2.5 && lower > 2.5 - 1e-12, "{lower}");
    // A cylinder of radius 0.5 and half-height 1 and a ball of 0.25 at
    // (2, 0, 0.3): along x the gap is 1.25; along (1, 0, 1) the slabs
    // are (0.5 + 1) / √2 and (2.3) / √2 - 0.25.
    let can: Shape = Convex::cylinder(0.5, 1.0, 0.0).unwrap().into();
    let beside = Isometry3::translation(2.0, 0.0, 0.3);
    let lower = separation_bound(&can, &id, &ball(0.25), &beside, &Vector3::x());
    assert!(lower <= 1.25 && lower > 1.25 - 1e-12, "{lower}");
    let slanted = 0.8 / 2f64.sqrt() - 0.25;
    let lower = separation_bound(
        &can,
        &id,
        &ball(0.25),
        &beside,
        &Vector3::new(1.0, 0.0, 1.0),
    );
    assert!(lower <= slanted && lower > slanted - 1e-12, "{lower}");
    // Overlapping along the direction: negative, proving nothing.
    assert!(separation_bound(&can, &id, &ball(0.25), &id, &Vector3::x()) < 0.0);
    // Rounded pieces in a union: the largest piece's slab counts.
    let pair: Shape = Compound::new(vec![
        (
            Isometry3::translation(-1.0, 0.0, 0.0),
            Convex::sphere(0.5).unwrap(),
        ),
        (
            Isometry3::translation(1.0, 0.0, 0.0),
            Convex::cuboid(Vector3::repeat(0.5), 0.1).unwrap(),
        ),
    ])
    .unwrap()
    .into();
    let lower = separation_bound(
        &pair,
        &id,
        &ball(0.5),
        &Isometry3::translation(4.0, 0.0, 0.0),
        &Vector3::x(),
    );
    assert!(lower <= 1.9 && lower > 1.9 - 1e-12, "{lower}");
}

#[test]
fn separation_bound_proves_nothing_from_bad_directions() {
    let id = Isometry3::identity();
    let ball: Shape = Convex::sphere(1.0).unwrap().into();
    let far = Isometry3::translation(5.0, 0.0, 0.0);
    for n in [
        Vector3::zeros(),
        Vector3::new(f64::NAN, 1.0, 0.0),
        Vector3::new(f64::INFINITY, 0.0, 0.0),
    ] {
        assert_eq!(
            separation_bound(&ball, &id, &ball, &far, &n),
            f64::NEG_INFINITY
        );
    }
}

/// Two boxes overlapping, then turned and pushed a little: the kept
/// simplex still proves an overlap, below the brute-force depth; pulled
/// apart, it proves nothing.
#[test]
fn penetration_bound_follows_a_small_motion_of_two_boxes() {
    let block: Shape = Convex::cuboid(Vector3::new(1.0, 0.6, 0.4), 0.0)
        .unwrap()
        .into();
    let pa = Isometry3::identity();
    let pb = Isometry3::new(Vector3::new(0.5, 0.2, 0.1), Vector3::z() * 0.3);
    let answer = distance(&block, &pa, &block, &pb, &Options::default(), None).unwrap();
    assert_eq!(answer.distance, 0.0);
    let mut proved = 0;
    for i in 0..10 {
        let t = f64::from(i) * 0.02;
        let moved = Isometry3::new(Vector3::new(0.5 + t, 0.2, 0.1), Vector3::z() * (0.3 + t));
        let depth = penetration_bound(&block, &pa, &block, &moved, &answer.warm_start);
        let truth = deepest_piece_pair(&block, &pa, &block, &moved);
        assert!(depth <= truth + 1e-12, "step {i}: {depth} above {truth}");
        proved += usize::from(depth > 0.0);
    }
    assert!(proved >= 5, "{proved} of 10");
    let apart = Isometry3::translation(4.0, 0.0, 0.0);
    assert_eq!(
        penetration_bound(&block, &pa, &block, &apart, &answer.warm_start),
        0.0
    );
}

#[test]
fn penetration_bound_proves_nothing_from_bad_simplexes() {
    let block: Shape = Convex::cuboid(Vector3::repeat(1.0), 0.0).unwrap().into();
    let id = Isometry3::identity();
    // Fewer than four pairs, an index past the vertices, a piece past the
    // shape's, a flat simplex (one vertex of B four times over a face of A).
    let bad = [
        WarmStart::new([0, 0], &[[0, 0], [1, 1], [2, 2]]).unwrap(),
        WarmStart::new([0, 0], &[[0, 7], [1, 6], [2, 5], [99, 0]]).unwrap(),
        WarmStart::new([1, 0], &[[0, 7], [1, 6], [2, 5], [4, 3]]).unwrap(),
        WarmStart::new([0, 0], &[[0, 0], [1, 0], [2, 0], [3, 0]]).unwrap(),
    ];
    for warm in &bad {
        assert_eq!(
            penetration_bound(&block, &id, &block, &id, warm),
            0.0,
            "{warm:?}"
        );
    }
    // The same cubes on top of each other: the opposite corners' tetrahedron
    // holds the origin.
    let good = WarmStart::new([0, 0], &[[0, 7], [3, 4], [5, 2], [6, 1]]).unwrap();
    let depth = penetration_bound(&block, &id, &block, &id, &good);
    assert!(depth > 0.0 && depth <= 2.0, "{depth}");
    // A cylinder's codes are not vertices: nothing is proved.
    let can: Shape = Convex::cylinder(1.0, 1.0, 0.0).unwrap().into();
    let answer = distance(&can, &id, &block, &id, &Options::default(), None).unwrap();
    assert_eq!(
        penetration_bound(&can, &id, &block, &id, &answer.warm_start),
        0.0
    );
}
