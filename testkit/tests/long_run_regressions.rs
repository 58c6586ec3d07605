//! Inputs found by long runs of the property tests (100 000 cases a test,
//! random seeds: `PROPTEST_CASES=100000 PROPTEST_RNG_SEED=<n> cargo test
//! --release -p gjkd-testkit --test properties`) that broke a promise, kept with the
//! brute force of `gjkd_testkit::reference` as their truth.

use gjk::{Options, Shape, Status, distance};
use gjkd_testkit::check::shape_distance;
use gjkd_testkit::input::{points as shape, printed_pose as pose};
use gjkd_testkit::reference::point_to_hull;
use nalgebra::Isometry3;

/// The answer against the brute force: bounds around the truth (to round-off
/// of the brute force) and the distance within 1e-9 of the scene's size.
#[track_caller]
fn check(
    a: &Shape,
    pa: &Isometry3<f64>,
    b: &Shape,
    pb: &Isometry3<f64>,
    o: &Options,
) -> gjk::Answer {
    let truth = shape_distance(a, pa, b, pb);
    let ans = distance(a, pa, b, pb, o, None).unwrap();
    let eps = 1e-14 * truth.scale;
    assert!(
        ans.lower <= truth.distance + eps && truth.distance <= ans.upper + eps,
        "bounds miss {}: {ans:?}",
        truth.distance
    );
    assert!(
        (ans.distance - truth.distance).abs() <= 1e-9 * truth.scale,
        "distance {} against {}: {ans:?}",
        ans.distance,
        truth.distance
    );
    ans
}

/// A point touching a flat five-point polytope, where GJK's last simplex is
/// a sliver triangle (width 5e-6, three nearly collinear points of K) with
/// the origin on its long edge. The cofactors' round-off put `v` 2.2e-9 from
/// the origin, and the support point, a vertex of that triangle, ended the
/// run as converged with the interval [0, 2.2e-9]. The true distance is
/// 1.07e-16 (exact rational arithmetic). Now a repeated support point with a
/// `g` above round-off sends the run to the Backup Procedure, which picks
/// the candidate by the length of the `v` it gives: the edge, 1e-16 away.
#[test]
fn point_touching_a_flat_polytope_through_a_sliver_triangle() {
    let a = shape(&[
        [1.019349241613302, -1.3530605765029082, -0.46664571315251197],
        [1.2789262063173767, -1.2503799709344179, -0.3665644962912866],
        [0.7726237778160425, -1.4391535366730823, -0.6152900808977939],
        [1.0463707891245904, -1.331487806293497, -0.5068607108772359],
        [0.8771339458646912, -1.4026867075185938, -0.5523204254900316],
    ]);
    let b = shape(&[[0.9735613174998863, -1.3690383059660265, -0.4942297167317289]]);
    let id = Isometry3::identity();
    for tolerance in [Options::default().tolerance, 1e-16, 0.0] {
        let o = Options {
            tolerance,
            ..Options::default()
        };
        let ans = check(&a, &id, &b, &id, &o);
        assert!(ans.distance < 1e-13, "{ans:?}");
        assert!(ans.upper < 1e-13, "{ans:?}");
        assert_eq!(ans.status, Status::Converged, "{ans:?}");
    }
}

/// B holds its two points five and two times over. With tolerance 0 the run
/// went past the round-off floor, pushed a point on the nearest edge's
/// line, got a worse `v` from the degenerate triangle and stopped on it as
/// converged (1.25645 against 1.25015). Every exit now keeps the nearer of
/// the last two iterates.
#[test]
fn duplicate_vertices_with_tolerance_zero() {
    let a = shape(&[
        [-0.21081948153167385, 1.2638059321073152, 1.0875730182761205],
        [-0.5939506083424364, 2.9128236092718565, -1.7129218678700868],
        [-0.6643013607551965, 3.2156171601277945, -2.2271503097314134],
        [-0.2281712436880346, 1.3384888814254121, 0.9607404072350577],
    ]);
    let (p0, p1) = (
        [0.0, 0.25890618642728286, 0.3451851391468265],
        [-0.9499412498400739, 0.7090744654083216, 0.31547800088111655],
    );
    let b = shape(&[p0, p1, p1, p0, p0, p0, p0]);
    let pa = pose(
        [
            0.9352417112536535,
            0.15974780037609462,
            0.28839753753934955,
            0.1289590715986152,
        ],
        [0.5013571931474021, 0.4463804862987512, -0.30519530692126806],
    );
    let pb = pose(
        [
            0.299311253273064,
            0.7416642211213424,
            -0.6002377568409003,
            -0.007848059326012366,
        ],
        [
            -0.9149916763927788,
            0.10698784342960622,
            -0.6415872186082893,
        ],
    );
    for max_iterations in [3, 6, 100] {
        for tolerance in [0.0, 1e-10, Options::default().tolerance] {
            let o = Options {
                tolerance,
                max_iterations,
                ..Options::default()
            };
            let ans = check(&a, &pa, &b, &pb, &o);
            assert!(ans.upper - ans.lower < 1e-12, "{ans:?}");
        }
    }
}

/// A nearly collinear four-point B (a segment with points along it) moved
/// to touch a small polytope: the thin triangle of the last simplex left the
/// Backup Procedure at 1.6e-12 and the run ended as `ToleranceNotMet`. The
/// Backup Procedure now ranks candidates by the `v` they give, and the run
/// converges to 7e-14.
#[test]
fn collinear_segment_touching_a_polytope() {
    let a = shape(&[
        [
            0.07827334919005685,
            -0.02103012563931539,
            -0.06519150545303969,
        ],
        [
            0.04863838953671813,
            0.09317103393568482,
            0.03233643089851764,
        ],
        [
            0.05307083196878514,
            0.06761413271981771,
            0.012220528469543471,
        ],
        [
            0.08022172659606805,
            0.07592953106764122,
            -0.0034602798779392405,
        ],
        [
            0.025373967704677827,
            0.06160058346182397,
            0.029827199504797487,
        ],
        [
            0.06931108863643602,
            -0.04502051795126057,
            -0.07387366050338376,
        ],
        [
            0.05550930139562036,
            0.004491623706963044,
            -0.030849063353147785,
        ],
    ]);
    let b = shape(&[
        [
            -0.7583784566294737,
            2.4032735414138386,
            -0.21292405430685632,
        ],
        [-0.924382050858692, 2.313506553049815, 0.046078932810396454],
        [-2.6146985488844967, 1.3994623595229916, 2.683353289399],
        [-0.6469833486262073, 2.46351081163903, -0.38672550636009617],
    ]);
    let pa = pose(
        [
            0.07593671071899723,
            -0.7084862408409724,
            -0.6750305797769837,
            -0.19134936339103925,
        ],
        [1.9160922119217343, -1.7168769147883605, 0.24740431076353991],
    );
    let pb = pose(
        [
            0.1929289543700242,
            0.9800669857919969,
            0.04661822179300793,
            0.008594377414141846,
        ],
        [
            -0.06855872434477675,
            -3.2824568761787347,
            0.5185011465172573,
        ],
    );
    let ans = check(&a, &pa, &b, &pb, &Options::default());
    assert_eq!(ans.status, Status::Converged, "{ans:?}");
    assert!(ans.upper < 1e-12, "{ans:?}");
}

/// Two triangles of size 1.7e4 touching 1e7 from the origin (B nearly
/// collinear). The run ends on a flat tetrahedron holding the origin, and
/// its cofactor weights put `Σ λ_i y_i` 2.4e-5 from the origin, so the
/// nearest point, `Σ λ_i a_i` for both shapes, was 2.4e-5 outside B (1.4e-9
/// of the size). The weights of a tetrahedron now get one refinement step.
#[test]
fn touching_triangles_far_out_share_a_point_of_both() {
    let a = shape(&[
        [-1409.3821569138545, -5212.941462484556, -4607.428266037536],
        [9075.28229966157, 13295.458846061578, -14706.026055567434],
        [-14865.631624326505, 16093.143091566411, 2899.440319603746],
    ]);
    let b = shape(&[
        [-4249.881435371744, 253.01374445799135, 3554.318229175237],
        [116.58570410555876, 1122.0242652246495, 1813.557323831502],
        [2053.624835285726, 1507.532120972254, 1041.3261621232587],
    ]);
    let pa = pose(
        [
            -0.5614520632937275,
            0.5449542224690167,
            -0.5827019500143455,
            -0.21967001043812293,
        ],
        [2535044.6426081755, 9681338.150909241, -7774.93827017703],
    );
    let pb = pose(
        [
            -0.9544566773597133,
            -0.24403332105033804,
            -0.16613163309697246,
            -0.04313316293911047,
        ],
        [2532466.834039514, 9689435.378295429, -397.8633423780231],
    );
    let truth = shape_distance(&a, &pa, &b, &pb);
    let ans = distance(&a, &pa, &b, &pb, &Options::default(), None).unwrap();
    assert!(
        ans.lower <= truth.distance + 1e-6 && truth.distance <= ans.upper + 1e-6,
        "{ans:?}"
    );
    let size = 17029.937258479084;
    let on_a = point_to_hull(&ans.point_a, &truth.pieces_a[0].points);
    let on_b = point_to_hull(&ans.point_b, &truth.pieces_b[0].points);
    assert!(
        on_a <= 1e-9 * size && on_b <= 1e-9 * size,
        "{on_a:e} {on_b:e}: {ans:?}"
    );
}

/// A point 6.4e-7 from a six-point polytope. GJK's triangle had
/// the right `|v|` but a direction 4e-7 rad off (Johnson's absolute error
/// over a small `|v|`), so the support point, a vertex of K, seemed 1e-6
/// beyond it; the tetrahedron it made failed every test of Theorem 5.2, the
/// Backup Procedure gave the same triangle back, and the run ended
/// `ToleranceNotMet` with the interval [0, 6.4e-7]. Now the Backup
/// Procedure's `v` is refined like any other when its support point
/// repeats: converged, the interval 2.6e-13 wide.
#[test]
fn point_near_a_polytope_after_the_backup_procedure() {
    let a = shape(&[[0.4288650930956947, 0.7673668302098899, -0.8359669313612114]]);
    let b = shape(&[
        [
            -0.10139386171450789,
            -0.18114483874530896,
            1.8373773687491055,
        ],
        [-1.4310402014356518, 4.465161361294857, 1.2778767459942941],
        [0.23072867355445864, -1.3994631349828008, 2.213847934857871],
        [-0.25143035458104174, 0.4172430290854605, 1.47051145402525],
        [0.23743151900258602, -1.2687810206887602, 1.5850143671640304],
        [-0.7666175173618951, 1.938540877440295, 2.397180799049291],
    ]);
    let pa = pose(
        [
            -0.4265915088784146,
            -0.5301484100987622,
            0.5557246749304,
            -0.4776321110395459,
        ],
        [-1.9230562683305288, 1.211716536952994, 1.9841842846050257],
    );
    let pb = pose(
        [
            -0.08184933059847838,
            -0.6218112833433539,
            -0.6179901139007595,
            -0.47406711983473243,
        ],
        [-2.4693723940005015, 1.068258687324044, 1.1960919025838705],
    );
    let ans = check(&a, &pa, &b, &pb, &Options::default());
    assert_eq!(ans.status, Status::Converged, "{ans:?}");
    assert!(ans.upper - ans.lower < 1e-12, "{ans:?}");
}
