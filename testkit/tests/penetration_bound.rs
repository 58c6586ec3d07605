//! The grown penetration bound (`Options::penetration_expansions`) against
//! the brute-force depth of `gjkd_testkit::reference`: never above the true
//! depth, never below the plain bound, nothing else of the answer changed;
//! close to the depth on simple overlaps; ignored for cylinders.

mod common;

use common::{pose, vec3};

use gjk::{Compound, Convex, Options, Shape, distance};
use gjkd_testkit::check::shape_distance;
use gjkd_testkit::reference::{P, hull_distance, penetration_depth};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use proptest::prelude::*;
use proptest::test_runner::Config;

fn config() -> Config {
    common::config(0x6570_6120)
}

fn grown(expansions: u32) -> Options {
    Options {
        penetration_expansions: expansions,
        ..Options::default()
    }
}

/// 4 to 12 points in general position (any set: the hull is what counts),
/// or a few points on a plane (a flat piece).
fn points() -> impl Strategy<Value = Vec<P>> {
    prop_oneof![
        3 => prop::collection::vec(vec3().prop_map(P::from), 4..=12),
        1 => (vec3(), vec3(), vec3(), prop::collection::vec((-1.0..1.0f64, -1.0..1.0f64), 3..=6))
            .prop_map(|(a, e1, e2, uv)| uv.iter().map(|(u, w)| P::from(a + e1 * *u + e2 * *w)).collect()),
    ]
}

fn radius() -> impl Strategy<Value = f64> {
    prop_oneof![3 => Just(0.0), 1 => 0.0..0.3f64]
}

/// Everything of `plain` but the penetration equals `deep`'s, and `deep`'s
/// penetration is at least `plain`'s.
fn same_but_deeper(plain: &gjk::Answer, deep: &gjk::Answer) -> Result<(), String> {
    let mut same = *deep;
    same.penetration = plain.penetration;
    if same != *plain {
        return Err(format!("answers differ\nplain {plain:?}\ndeep  {deep:?}"));
    }
    if deep.penetration < plain.penetration || deep.penetration.is_nan() {
        return Err(format!(
            "grown bound {} below the plain {}",
            deep.penetration, plain.penetration
        ));
    }
    Ok(())
}

/// Checks the grown bound of two convex pieces at their poses against the
/// brute-force depth, `tol` allowing for the brute force's own round-off.
fn check_pair(
    (a, pa): (&Convex, &Isometry3<f64>),
    (b, pb): (&Convex, &Isometry3<f64>),
    expansions: u32,
    tol: f64,
) -> Result<(), String> {
    let (sa, sb): (Shape, Shape) = (a.clone().into(), b.clone().into());
    let plain = distance(&sa, pa, &sb, pb, &Options::default(), None).map_err(|e| e.to_string())?;
    let deep = distance(&sa, pa, &sb, pb, &grown(expansions), None).map_err(|e| e.to_string())?;
    same_but_deeper(&plain, &deep)?;
    let wa: Vec<P> = a.vertices().iter().map(|v| pa * v).collect();
    let wb: Vec<P> = b.vertices().iter().map(|v| pb * v).collect();
    let radii = a.radius() + b.radius();
    if hull_distance(&wa, &wb).distance > 0.0 {
        // Cores apart: the exact shell overlap, untouched.
        if deep.penetration != plain.penetration {
            return Err(format!("cores apart, yet the bound grew: {deep:?}"));
        }
        return Ok(());
    }
    let depth = penetration_depth(&wa, &wb) + radii;
    if deep.penetration > depth + tol {
        return Err(format!(
            "grown bound {} above the true depth {depth} (plain {})\nA = {wa:?}\nB = {wb:?}",
            deep.penetration, plain.penetration
        ));
    }
    Ok(())
}

proptest! {
    #![proptest_config(config())]

    /// Overlapping and touching pieces of any shape: the grown bound stays
    /// at most the true depth, whatever the number of expansions.
    #[test]
    fn grown_bound_never_exceeds_the_depth(
        a in points(), ra in radius(), pa in pose(0.4),
        b in points(), rb in radius(), pb in pose(0.4),
        expansions in prop_oneof![Just(1u32), Just(4), Just(16), Just(1000)],
    ) {
        let (a, b) = (Convex::new(a, ra).unwrap(), Convex::new(b, rb).unwrap());
        let scale = shape_distance(&a.clone().into(), &pa, &b.clone().into(), &pb).scale;
        if let Err(e) = check_pair((&a, &pa), (&b, &pb), expansions, 1e-12 * scale) {
            prop_assert!(false, "{}", e);
        }
    }

    /// The same far from the origin and at tiny and huge sizes, where the
    /// round-off allowance is what keeps the bound below the depth.
    #[test]
    fn grown_bound_holds_at_extremes(
        a in points(), pa in pose(0.4), b in points(), pb in pose(0.4),
        s in prop_oneof![Just(1e-9), Just(1.0), Just(1e9)],
        off in prop_oneof![Just(0.0), Just(1e6), Just(1e12)],
    ) {
        let build = |pts: &[P]| Convex::new(pts.iter().map(|p| P::from(p.coords * s)).collect::<Vec<_>>(), 0.0).unwrap();
        let shift = Vector3::new(off, -0.5 * off, 0.25 * off) * s;
        let place = |p: &Isometry3<f64>| Isometry3::from_parts(Translation3::from(p.translation.vector * s + shift), p.rotation);
        let (a, b) = (build(&a), build(&b));
        let (pa, pb) = (place(&pa), place(&pb));
        // The brute force works in world coordinates: its own round-off
        // grows with the offset.
        let tol = 1e-12 * s + 64.0 * (1.0 + off) * s * f64::EPSILON;
        if let Err(e) = check_pair((&a, &pa), (&b, &pb), 16, tol) {
            prop_assert!(false, "scale {s:e}, offset {off:e}: {}", e);
        }
    }

    /// A union's bound, the largest of its piece pairs', stays below the
    /// deepest piece pair's true depth (itself at most the union's).
    #[test]
    fn compound_bound_stays_below_its_pieces_depth(
        pieces in prop::collection::vec((pose(0.6), points()), 1..=3),
        pa in pose(0.3), b in points(), pb in pose(0.3),
    ) {
        let pieces: Vec<(Isometry3<f64>, Convex)> =
            pieces.into_iter().map(|(o, p)| (o, Convex::new(p, 0.0).unwrap())).collect();
        let a: Shape = Compound::new(pieces.clone()).unwrap().into();
        let b = Convex::new(b, 0.0).unwrap();
        let sb: Shape = b.clone().into();
        let plain = distance(&a, &pa, &sb, &pb, &Options::default(), None).unwrap();
        let deep = distance(&a, &pa, &sb, &pb, &grown(16), None).unwrap();
        if let Err(e) = same_but_deeper(&plain, &deep) {
            prop_assert!(false, "{}", e);
        }
        let wb: Vec<P> = b.vertices().iter().map(|v| pb * v).collect();
        let deepest = pieces
            .iter()
            .map(|(o, c)| {
                let wa: Vec<P> = c.vertices().iter().map(|v| pa * o * v).collect();
                if hull_distance(&wa, &wb).distance > 0.0 { 0.0 } else { penetration_depth(&wa, &wb) }
            })
            .fold(0.0, f64::max);
        let scale = shape_distance(&a, &pa, &sb, &pb).scale;
        prop_assert!(deep.penetration <= deepest + 1e-12 * scale,
            "grown bound {} above the deepest piece pair's depth {deepest}", deep.penetration);
    }
}

/// Two boxes overlapping, one turned: the grown bound reaches the
/// brute-force depth to round-off, where the final tetrahedron's inner
/// radius falls well short.
#[test]
fn grown_bound_reaches_the_depth_of_two_boxes() {
    let cube = |r: f64| -> Shape {
        Convex::cuboid(Vector3::new(1.0, 0.6, 0.4), r)
            .unwrap()
            .into()
    };
    let pa = Isometry3::identity();
    for (shift, axis, angle) in [
        (Vector3::new(1.7, 0.9, 0.3), Vector3::z(), 0.3),
        (
            Vector3::new(0.4, 1.0, 0.5),
            Vector3::new(1.0, 1.0, 0.0),
            0.7,
        ),
        (
            Vector3::new(-1.5, 0.2, -0.6),
            Vector3::new(1.0, -2.0, 3.0),
            2.0,
        ),
    ] {
        let pb = Isometry3::from_parts(
            Translation3::from(shift),
            UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle),
        );
        let corners = |pose: &Isometry3<f64>| -> Vec<P> {
            let Shape::Convex(c) = cube(0.0) else {
                unreachable!()
            };
            c.vertices().iter().map(|v| pose * v).collect()
        };
        let depth = penetration_depth(&corners(&pa), &corners(&pb));
        for r in [0.0, 0.1] {
            let plain = distance(&cube(r), &pa, &cube(r), &pb, &Options::default(), None).unwrap();
            let deep = distance(&cube(r), &pa, &cube(r), &pb, &grown(16), None).unwrap();
            let want = depth + 2.0 * r;
            if r == 0.0 {
                assert!(
                    plain.penetration < 0.5 * want,
                    "plain {}",
                    plain.penetration
                );
            }
            assert!(
                deep.penetration <= want + 1e-12 && deep.penetration > want - 1e-9,
                "{shift:?} r {r}: grown {} plain {} depth {want}",
                deep.penetration,
                plain.penetration
            );
        }
    }
}

/// Touching boxes (depth 0): no bound beyond round-off.
#[test]
fn touching_boxes_get_no_depth() {
    let s: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)
        .unwrap()
        .into();
    let pa = Isometry3::identity();
    for pb in [
        Isometry3::translation(2.0, 0.3, 0.1),
        Isometry3::translation(2.0, 2.0, 0.0),
        Isometry3::translation(2.0, 2.0, 2.0),
    ] {
        let deep = distance(&s, &pa, &s, &pb, &grown(16), None).unwrap();
        assert!(deep.penetration <= 1e-14, "{pb:?}: {deep:?}");
    }
}

/// Pairs with a cylinder keep the plain bound: the option changes nothing.
#[test]
fn cylinders_keep_the_plain_bound() {
    let cyl: Shape = Convex::cylinder(0.5, 1.0, 0.0).unwrap().into();
    let cube: Shape = Convex::cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)
        .unwrap()
        .into();
    let pa = Isometry3::identity();
    let pb = Isometry3::translation(0.3, 0.2, 0.1);
    for (a, b) in [(&cyl, &cube), (&cube, &cyl), (&cyl, &cyl)] {
        let plain = distance(a, &pa, b, &pb, &Options::default(), None).unwrap();
        let deep = distance(a, &pa, b, &pb, &grown(16), None).unwrap();
        assert_eq!(plain, deep);
        assert_eq!(plain.distance, 0.0);
    }
}

/// The default asks for no expansion: a default answer keeps the final
/// tetrahedron's bound, short of the depth the grown one reaches.
#[test]
fn default_options_do_not_grow_the_bound() {
    assert_eq!(Options::default().penetration_expansions, 0);
    let s: Shape = Convex::cuboid(Vector3::new(1.0, 0.6, 0.4), 0.0)
        .unwrap()
        .into();
    let pb = Isometry3::from_parts(
        Translation3::new(1.7, 0.9, 0.3),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.3),
    );
    let pa = Isometry3::identity();
    let plain = distance(&s, &pa, &s, &pb, &Options::default(), None).unwrap();
    let none = distance(&s, &pa, &s, &pb, &grown(0), None).unwrap();
    let deep = distance(&s, &pa, &s, &pb, &grown(16), None).unwrap();
    assert_eq!(plain, none);
    assert!(
        plain.penetration < 0.5 * deep.penetration,
        "{plain:?} {deep:?}"
    );
}
