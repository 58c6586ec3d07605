//! A reused workspace (a caller's, or the one `distance` keeps for each
//! thread) gives the same answers, bit for bit, as a fresh one: nothing of
//! one query's scratch state reaches the next, whatever ran before it (a
//! query of another kind, a compound, an error).

use gjk::{Answer, Error, Options, Precision, Shape, WarmStart, Workspace, distance, distance_in};
use gjkd_testkit::paper::{self, Case};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

/// Every number of an answer as bits, so that -0.0 and 0.0 differ.
fn bits(a: &Answer) -> Vec<u64> {
    let mut out = vec![
        a.distance.to_bits(),
        a.lower.to_bits(),
        a.upper.to_bits(),
        a.penetration.to_bits(),
        u64::from(a.iterations),
        u64::from(a.backup_used),
        u64::from(a.pieces[0]) << 32 | u64::from(a.pieces[1]),
    ];
    for p in [a.point_a.coords, a.point_b.coords, a.normal] {
        out.extend(p.iter().map(|x| x.to_bits()));
    }
    out.extend(
        a.warm_start
            .pairs()
            .iter()
            .map(|&[i, j]| u64::from(i) << 32 | u64::from(j)),
    );
    out.extend(a.warm_start.pieces().map(u64::from));
    out
}

/// One query three ways: in a fresh workspace (the reference), in the
/// caller's reused one, and through `distance` (the thread's).
fn ask_three_ways(
    ws: &mut Workspace,
    (a, pa): (&Shape, &Isometry3<f64>),
    (b, pb): (&Shape, &Isometry3<f64>),
    options: &Options,
    warm: Option<&WarmStart>,
) -> Result<Answer, Error> {
    let fresh = distance_in(&mut Workspace::new(), a, pa, b, pb, options, warm);
    let reused = distance_in(ws, a, pa, b, pb, options, warm);
    let threads = distance(a, pa, b, pb, options, warm);
    match (&fresh, &reused, &threads) {
        (Ok(f), Ok(r), Ok(t)) => {
            assert_eq!(bits(f), bits(r), "caller's workspace: {f:?} against {r:?}");
            assert_eq!(bits(f), bits(t), "thread's workspace: {f:?} against {t:?}");
            assert_eq!((f.status, f.status), (r.status, t.status));
        }
        (Err(f), Err(r), Err(t)) => assert_eq!((f, f), (r, t)),
        _ => panic!("{fresh:?} / {reused:?} / {threads:?}"),
    }
    fresh
}

/// The paper's family (every kind, mixed so that each query follows one of
/// another kind) with three option sets, then the Section 8 compound along
/// its motion with warm starts, with a failing query between.
fn mixed_queries() -> usize {
    let family: Vec<Shape> = paper::family().into_iter().map(Shape::from).collect();
    let mut cases: Vec<_> = Case::ALL
        .iter()
        .flat_map(|&kind| paper::cases(kind, 3, 5))
        .collect();
    // Round-robin over the kinds: separated, touching, intersecting, ...
    let n = cases.len() / 3;
    cases = (0..cases.len())
        .map(|i| cases[(i % 3) * n + i / 3])
        .collect();
    let options = [
        Options::default(),
        Options {
            margin: Some(0.5),
            ..Options::default()
        },
        Options {
            precision: Precision::Single,
            max_iterations: 3,
            ..Options::default()
        },
    ];
    let mut ws = Workspace::new();
    let mut asked = 0;
    for (i, c) in cases.iter().enumerate() {
        let o = &options[i % options.len()];
        let a = (&family[c.a], &c.pose_a);
        ask_three_ways(&mut ws, a, (&family[c.b], &c.pose_b), o, None).unwrap();
        asked += 1;
        if i % 7 == 0 {
            let nan = Isometry3::from_parts(
                Translation3::new(f64::NAN, 0.0, 0.0),
                UnitQuaternion::identity(),
            );
            let err = ask_three_ways(&mut ws, a, (&family[c.b], &nan), o, None);
            assert_eq!(err.unwrap_err(), Error::NonFinitePose);
        }
    }
    let motion = paper::section8();
    let mut last: Vec<Option<WarmStart>> = vec![None; motion.obstacles().len()];
    for s in 0..=100 {
        let pose = motion.pose(s as f64 / 100.0);
        for (k, (shape, at)) in motion.obstacles().iter().enumerate() {
            let ans = ask_three_ways(
                &mut ws,
                (motion.moving(), &pose),
                (shape, at),
                &Options::default(),
                last[k].as_ref(),
            )
            .unwrap();
            last[k] = Some(ans.warm_start);
            asked += 1;
        }
    }
    asked
}

#[test]
fn a_reused_workspace_gives_the_same_answers_bit_for_bit() {
    assert!(mixed_queries() > 600);
}

/// A new thread's first query makes its workspace; the answers are the same.
#[test]
fn a_new_thread_gives_the_same_answers() {
    let asked = std::thread::spawn(mixed_queries).join().unwrap();
    assert!(asked > 600);
}
