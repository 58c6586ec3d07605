//! The brute-force reference against closed forms and exact arithmetic, so
//! that every test and measurement that leans on it leans on something that
//! was checked: its nearest points of thin triangles, its decision at near
//! contact, the facet search of larger sets and its distances on the paper's
//! family.

use gjk::{Convex, Options, Shape, distance};
use gjkd_testkit::input::{p, v};
use gjkd_testkit::paper::{self, Case};
use gjkd_testkit::reference::{
    Hull, P, V, aabb_distance, closest_on_triangle, distance as reference_distance, hull_distance,
    penetration_depth, point_to_hull,
};
use nalgebra::Isometry3;

fn query(a: &Shape, pa: &Isometry3<f64>, b: &Shape, pb: &Isometry3<f64>) -> gjk::Answer {
    distance(a, pa, b, pb, &Options::default(), None).expect("valid input")
}

fn convex(points: &[P], r: f64) -> Shape {
    Convex::new(points.to_vec(), r).unwrap().into()
}

fn iso(x: f64, y: f64, z: f64) -> Isometry3<f64> {
    Isometry3::translation(x, y, z)
}

/// The reference's nearest point of a sliver triangle (sine 2.6e-6, found
/// by `mid_sets`) stays in the triangle. The truth, 7.75266935395461e-12,
/// is the triangle's exact minimum norm over these f64 vertices in rational
/// arithmetic (Python `fractions`). A plane projection started from the far
/// vertex gives 7.3649e-12, 5 % below it, since round-off tilts the plane.
#[test]
fn reference_triangle_point_stays_on_a_sliver() {
    let near = p(
        -1.2237576977973657e-08,
        2.2952237034835573e-06,
        1.5266993908833425e-11,
    );
    let far = p(
        -0.05701717767976833,
        -0.4270769237365812,
        -0.3172605197185606,
    );
    let tiny = p(
        -5.0319757041727975e-12,
        -3.306002591419577e-13,
        1.5266993908833425e-11,
    );
    let truth = 7.75266935395461e-12;
    for [a, b, c] in [[far, near, tiny], [near, far, tiny], [tiny, near, far]] {
        let q = closest_on_triangle(&P::origin(), &a, &b, &c);
        let d = q.coords.norm();
        assert!((d - truth).abs() <= 1e-6 * truth, "{d} against {truth}");
    }
}

/// A case of the property tests: a segment meeting a triangle of size 1e-2 within
/// 1e-15 of its border, in world coordinates as the property test forms them.
/// Over these f64 points the segment meets the triangle (rational arithmetic,
/// Python `fractions`): the truth is 0. No axis gap decides it and the
/// nearest vertex, edge and triangle pairs are 1.3e-15 apart in f64, which the
/// reference took for the distance until it asked exact orientation
/// predicates whether a segment of one set meets a triangle of the other.
#[test]
fn reference_sees_a_segment_meeting_a_triangle_at_its_border() {
    let seg_end = p(
        0.011403511547707272,
        0.008526607285277505,
        -0.017933667927162455,
    );
    let a = [
        p(
            0.014199311081814839,
            0.000335742027556863,
            -0.012201220226457655,
        ),
        seg_end,
        seg_end,
    ];
    let b = [
        p(
            0.006405027855799991,
            -0.006141172505594758,
            -0.012292973017363332,
        ),
        p(
            0.0067224512215572916,
            -0.005455698286760175,
            -0.012227261740608501,
        ),
        p(
            0.018526150049322176,
            0.003727126980333957,
            -0.01218028713881628,
        ),
    ];
    assert_eq!(hull_distance(&a, &b).distance, 0.0);
    assert_eq!(hull_distance(&b, &a).distance, 0.0);
    // GJK on the same points, in the world frame: its interval holds 0.
    let ans = query(
        &convex(&a, 0.0),
        &iso(0., 0., 0.),
        &convex(&b, 0.0),
        &iso(0., 0., 0.),
    );
    assert_eq!(ans.lower, 0.0, "{ans:?}");
    assert!(ans.distance <= 1e-15, "{ans:?}");
}

/// The same case at scale 1e-3: the segment's end lies 6.356e-20 above the
/// thin triangle's plane, over it (rational arithmetic). The reference's
/// projection, weights solved once from the Gram system, put it 1.3e-16
/// away; one refinement step on the residual brings it to round-off.
#[test]
fn reference_point_above_a_thin_triangle() {
    let x = p(
        0.0014199311081814839,
        3.3574202755686346e-5,
        -0.0012201220226457656,
    );
    let (a, b, c) = (
        p(
            0.0006405027855799991,
            -0.0006141172505594758,
            -0.0012292973017363333,
        ),
        p(
            0.000672245122155729,
            -0.0005455698286760174,
            -0.00122272617406085,
        ),
        p(
            0.0018526150049322171,
            0.0003727126980333957,
            -0.0012180287138816278,
        ),
    );
    let truth = 6.356440386617582e-20;
    let d = (closest_on_triangle(&x, &a, &b, &c) - x).norm();
    assert!((d - truth).abs() <= 1e-18, "{d:e} against {truth:e}");
}

#[test]
fn reference_matches_closed_forms() {
    // Unit cubes, one containing the other: 0 (no feature pair is at 0).
    let cube = |c: V, h: f64| -> Vec<P> {
        (0..8)
            .map(|i| {
                P::from(
                    c + v(
                        if i & 1 == 0 { -h } else { h },
                        if i & 2 == 0 { -h } else { h },
                        if i & 4 == 0 { -h } else { h },
                    ),
                )
            })
            .collect()
    };
    assert_eq!(
        hull_distance(&cube(v(0., 0., 0.), 2.0), &cube(v(0.1, 0., 0.), 0.5)).distance,
        0.0
    );
    // Boxes separated along a diagonal: corner to corner.
    let d = hull_distance(&cube(v(0., 0., 0.), 1.0), &cube(v(3., 4., 5.), 1.0)).distance;
    assert!((d - (1.0f64 + 4.0 + 9.0).sqrt()).abs() < 1e-14);
    // Coplanar triangles in z = 0, separated in-plane by 1.
    let t1 = [p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.)];
    let t2 = [p(2., 0., 0.), p(3., 0., 0.), p(2., 1., 0.)];
    assert!((hull_distance(&t1, &t2).distance - 1.0).abs() < 1e-15);
    // Coplanar overlapping triangles: 0.
    let t3 = [p(0.2, 0.2, 0.), p(3., 0.2, 0.), p(0.2, 3., 0.)];
    assert_eq!(hull_distance(&t1, &t3).distance, 0.0);
    // Parallel segments offset by 1.
    let s1 = [p(0., 0., 0.), p(2., 0., 0.)];
    let s2 = [p(1., 1., 0.), p(5., 1., 0.)];
    assert!((hull_distance(&s1, &s2).distance - 1.0).abs() < 1e-15);
    // Collinear segments, gap 3.
    let s3 = [p(5., 0., 0.), p(9., 0., 0.)];
    assert!((hull_distance(&s1, &s3).distance - 3.0).abs() < 1e-15);
    // Collinear and overlapping.
    let s4 = [p(1., 0., 0.), p(9., 0., 0.)];
    assert_eq!(hull_distance(&s1, &s4).distance, 0.0);
    // Crossing segments in a plane.
    let s5 = [p(1., -1., 0.), p(1., 1., 0.)];
    assert_eq!(hull_distance(&s1, &s5).distance, 0.0);
    // Duplicated points behave as one point.
    let dup = [p(0., 0., 3.), p(0., 0., 3.), p(0., 0., 3.), p(0., 0., 3.)];
    assert!((hull_distance(&t1, &dup).distance - 3.0).abs() < 1e-15);
    // A point inside a tetrahedron.
    let tet = [p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.), p(0., 0., 1.)];
    assert_eq!(point_to_hull(&p(0.1, 0.1, 0.1), &tet), 0.0);
    assert!((point_to_hull(&p(1., 1., 1.), &tet) - 2.0 / 3.0f64.sqrt()).abs() < 1e-15);
    // Penetration depth of overlapping axis-aligned cubes: the smallest overlap.
    let pd = penetration_depth(&cube(v(0., 0., 0.), 1.0), &cube(v(1.5, 0.2, 0.1), 1.0));
    assert!((pd - 0.5).abs() < 1e-15);
}

// Larger sets, through the facet search, and posed hulls.

fn cube(h: f64) -> Vec<P> {
    (0..8)
        .map(|i| {
            P::new(
                if i & 1 == 0 { -h } else { h },
                if i & 2 == 0 { -h } else { h },
                if i & 4 == 0 { -h } else { h },
            )
        })
        .collect()
}

/// An icosahedron-like cloud of 20+ points so that the facet search, not
/// the small-set path, is used.
fn prism(n: usize, r: f64, h: f64) -> Vec<P> {
    let mut v = Vec::new();
    for z in [-h, h] {
        for k in 0..n {
            let a = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
            v.push(P::new(r * a.cos(), r * a.sin(), z));
        }
    }
    v
}

#[test]
fn boxes_match_the_analytic_distance() {
    let h = Hull::new(&cube(1.0));
    for (t, want) in [
        (V::new(3.5, 0.0, 0.0), 1.5),
        (V::new(3.0, 3.0, 0.0), 2.0f64.sqrt()),
        (V::new(2.0, 0.5, 0.0), 0.0),
        (V::new(0.5, 0.2, 0.1), 0.0),
    ] {
        let r = reference_distance(
            &h,
            &Isometry3::identity(),
            0.0,
            &h,
            &Isometry3::translation(t.x, t.y, t.z),
            0.0,
        );
        assert!((r.distance - want).abs() < 1e-14, "{t:?}: {r:?}");
        let analytic = aabb_distance(&V::zeros(), &V::repeat(1.0), &t, &V::repeat(1.0));
        assert!((analytic - want).abs() < 1e-15);
    }
}

#[test]
fn facet_search_finds_a_rotated_prism_distance() {
    // A 12-gon prism (24 points, facet path) above a cube: the nearest
    // feature is the prism's bottom face, 0.5 above the cube's top.
    let prism = Hull::new(&prism(12, 0.5, 0.25));
    assert!(prism.edge_count() >= 36, "{} edges", prism.edge_count());
    let cube = Hull::new(&cube(1.0));
    let pose = Isometry3::new(V::new(0.1, -0.2, 1.75), V::new(0.0, 0.0, 0.3));
    let r = reference_distance(&cube, &Isometry3::identity(), 0.0, &prism, &pose, 0.0);
    assert!(r.separated);
    assert!((r.distance - 0.5).abs() < 1e-14, "{r:?}");
    // Rounded: the radii come off, and overlap reads 0.
    let r = reference_distance(&cube, &Isometry3::identity(), 0.2, &prism, &pose, 0.1);
    assert!((r.distance - 0.2).abs() < 1e-14);
    let deep = Isometry3::translation(0.0, 0.0, 1.0);
    let r = reference_distance(&cube, &Isometry3::identity(), 0.0, &prism, &deep, 0.0);
    assert!(!r.separated && r.distance == 0.0);
}

#[test]
fn a_small_box_inside_a_big_one_overlaps() {
    // No boundary features meet, so only the axis test can tell.
    let big = Hull::new(&prism(10, 5.0, 5.0));
    let small = Hull::new(&cube(0.1));
    let r = reference_distance(
        &big,
        &Isometry3::identity(),
        0.0,
        &small,
        &Isometry3::translation(0.3, 0.2, 0.1),
        0.0,
    );
    assert!(!r.separated);
    assert_eq!(r.distance, 0.0);
}

#[test]
fn degenerate_sets_are_exact() {
    let seg = Hull::new(&[P::new(0.0, 0.0, -1.0), P::new(0.0, 0.0, 1.0)]);
    let other = Hull::new(&[P::new(-1.0, 0.0, 0.0), P::new(1.0, 0.0, 0.0)]);
    // Skew segments 2 apart.
    let r = reference_distance(
        &seg,
        &Isometry3::identity(),
        0.0,
        &other,
        &Isometry3::translation(0.0, 2.0, 0.5),
        0.0,
    );
    assert!((r.distance - 2.0).abs() < 1e-15, "{r:?}");
    // Crossing segments in one plane touch.
    let r = reference_distance(
        &seg,
        &Isometry3::identity(),
        0.0,
        &other,
        &Isometry3::identity(),
        0.0,
    );
    assert_eq!(r.distance, 0.0);
    // Two points.
    let pt = Hull::new(&[P::origin()]);
    let r = reference_distance(
        &pt,
        &Isometry3::identity(),
        0.5,
        &pt,
        &Isometry3::translation(3.0, 4.0, 0.0),
        0.5,
    );
    assert!((r.distance - 4.0).abs() < 1e-15);
}

#[test]
fn paper_family_matches_its_construction() {
    // The paper's cases are built by sliding along near-point lines, so
    // a separated case's gap is known; touching and intersecting cases
    // are at distance 0. (Five pairs, small sets and the facet search
    // both: the brute force is slow unoptimised.)
    let family = paper::family();
    let hulls: Vec<Option<Hull>> = family
        .iter()
        .enumerate()
        .map(|(i, c)| {
            [0, 1, 2, 3, 6, 8]
                .contains(&i)
                .then(|| Hull::new(c.vertices()))
        })
        .collect();
    for case in Case::ALL {
        for c in paper::cases(case, 1, 5) {
            let (Some(ha), Some(hb)) = (&hulls[c.a], &hulls[c.b]) else {
                continue;
            };
            let r = reference_distance(ha, &c.pose_a, 0.0, hb, &c.pose_b, 0.0);
            match case {
                Case::Separated => {
                    assert!(r.separated, "pair {}", c.pair);
                    assert!(
                        (r.distance - c.expected).abs() < 1e-9,
                        "pair {}: {r:?} vs {}",
                        c.pair,
                        c.expected
                    );
                }
                Case::Touching => assert!(r.distance < 1e-9, "pair {}: {r:?}", c.pair),
                Case::Intersecting => {
                    assert!(!r.separated && r.distance == 0.0, "pair {}: {r:?}", c.pair);
                }
            }
        }
    }
}
