//! gjk's two compiled forms of the query, the one for any CPU and the one
//! for AVX2 and FMA, against each other over the paper's fixtures. Here
//! rather than beside the query because the fixtures live in the test kit,
//! which depends on gjk.

#![cfg(target_arch = "x86_64")]

use gjk::{
    Answer, Options, Precision, Shape, WarmStart, Workspace, distance_in, distance_in_baseline,
};
use gjkd_testkit::paper::{self, Case, OBSTACLES};
use nalgebra::Isometry3;

/// The query in both compiled forms, which must agree to the last bit of
/// every field (`Debug` prints each float exactly, the sign of zero too).
fn both(
    ws: &mut Workspace,
    (a, pose_a): (&Shape, &Isometry3<f64>),
    (b, pose_b): (&Shape, &Isometry3<f64>),
    options: &Options,
    warm: Option<&WarmStart>,
) -> Answer {
    let base = distance_in_baseline(ws, a, pose_a, b, pose_b, options, warm);
    let avx2 = distance_in(ws, a, pose_a, b, pose_b, options, warm);
    assert_eq!(format!("{base:?}"), format!("{avx2:?}"), "{options:?}");
    avx2.expect("valid input")
}

/// The baseline and AVX2 forms of a query (convex pairs and unions alike)
/// give the same answer bit for bit, as gjk's query promises: the AVX2
/// form is what this machine runs, the baseline what a CPU without AVX2
/// runs, so only this test runs the baseline here.
#[test]
fn the_compiled_forms_agree_bit_for_bit() {
    if !(is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")) {
        return;
    }
    let d = Options::default();
    let options = [
        d,
        Options {
            max_iterations: 3,
            ..d
        },
        Options {
            margin: Some(0.3),
            ..d
        },
        Options {
            tolerance: 1e-6,
            ..d
        },
        Options {
            precision: Precision::Single,
            ..d
        },
    ];
    let family: Vec<Shape> = paper::family().into_iter().map(Shape::from).collect();
    let mut ws = Workspace::new();
    let mut asked = 0;
    for case in Case::ALL {
        for c in paper::cases(case, 3, 5) {
            let (a, b) = ((&family[c.a], &c.pose_a), (&family[c.b], &c.pose_b));
            for o in &options {
                let cold = both(&mut ws, a, b, o, None);
                both(&mut ws, a, b, o, Some(&cold.warm_start));
                asked += 2;
            }
        }
    }
    // Unions: the Section 8 object through its obstacles, warm along the
    // path, either way round, and against itself.
    let motion = paper::section8();
    let moving = motion.moving();
    let mut last: [Option<WarmStart>; OBSTACLES] = [None; OBSTACLES];
    for t in 0..=100 {
        let pose = motion.pose(f64::from(t) / 100.0);
        for (i, (obstacle, at)) in motion.obstacles().iter().enumerate() {
            let ans = both(
                &mut ws,
                (moving, &pose),
                (obstacle, at),
                &d,
                last[i].as_ref(),
            );
            last[i] = Some(ans.warm_start);
            both(
                &mut ws,
                (obstacle, at),
                (moving, &pose),
                &options[t as usize % 5],
                None,
            );
            asked += 2;
        }
        let other = motion.pose(1.0 - f64::from(t) / 100.0);
        both(&mut ws, (moving, &pose), (moving, &other), &d, None);
        asked += 1;
    }
    assert_eq!(asked, 60 * 3 * 5 * 2 + 101 * (2 * OBSTACLES + 1));
}
