//! Paths: settled by travel, refused whole, searched again.

use super::*;

/// The exact answer of a pair at the given poses.
fn exact_at(s: &State, a: (u64, &Isometry3<f64>), b: (u64, &Isometry3<f64>)) -> gjk::Answer {
    let (oa, ob) = (s.object(a.0).unwrap(), s.object(b.0).unwrap());
    let options = gjk::Options {
        warm_start: false,
        ..Default::default()
    };
    gjk::distance(&oa.shape, a.1, &ob.shape, b.1, &options, None).unwrap()
}

/// Checks a path's within rows against brute force at every step:
/// `steps[t]` are the poses the path set up to step `t` (the others
/// stored), `pairs` the pairs asked; a row may lie beyond the margin by
/// at most the accepted width `accept` (its interval, that narrow, still
/// reaches below the margin).
fn check_path_within(
    s: &State,
    rows: &[SceneRow],
    steps: &[Vec<(u64, Isometry3<f64>)>],
    pairs: &[(u64, u64)],
    margin: f64,
    accept: f64,
) {
    for (t, set) in steps.iter().enumerate() {
        let pose = |id: u64| {
            set.iter()
                .rev()
                .find(|(i, _)| *i == id)
                .map_or(s.object(id).unwrap().pose, |(_, p)| *p)
        };
        let at: Vec<&SceneRow> = rows.iter().filter(|r| r.step == t as u32).collect();
        for row in &at {
            let e = exact_at(s, (row.a, &pose(row.a)), (row.b, &pose(row.b)));
            assert!(
                overlaps(row.result.lower, row.result.upper, &e),
                "step {t}: {row:?} excludes {e:?}"
            );
            assert!(
                e.lower <= margin + accept,
                "step {t}: {row:?} not within: {e:?}"
            );
        }
        for &(a, b) in pairs {
            let e = exact_at(s, (a, &pose(a)), (b, &pose(b)));
            if e.upper <= margin {
                assert!(
                    at.iter().any(|r| (r.a, r.b) == (a, b)),
                    "step {t}: missed ({a:#x}, {b:#x}) at {}",
                    e.distance
                );
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Paths of a group (and, with `others`, of a non-member too, which
    /// the lookahead must not be trusted with), asked twice so that the
    /// second starts from the first's bounds: at every step, no pair within
    /// the margin is missed and every interval holds the exact distance.
    #[test]
    fn paths_match_brute_force_at_every_step(
        far in prop::bool::ANY,
        others in prop::bool::ANY,
        seed in 1u64..1000,
        motions in prop::collection::vec(motion(), 1..24),
        margin in prop_oneof![Just(0.0), Just(0.6)],
        accept in prop_oneof![Just(0.0), Just(1e-3)],
    ) {
        let centre = if far { Vector3::new(1e6, -1e6, 5e5) } else { Vector3::zeros() };
        let (mut s, ids) = scene(40, centre, 3.0, seed);
        let group = ids[..2].to_vec();
        let mut moving = group.clone();
        if others {
            moving.push(ids[7]);
        }
        let mut items = members(&group);
        let mut steps = Vec::new();
        let mut now = poses(&s, &moving);
        for m in &motions {
            let mut set = Vec::new();
            for (pose, &id) in now.iter_mut().zip(&moving) {
                *pose = moved(pose, m, &centre);
                items.push(Item::set_pose(ObjectId::from_raw(id), pose));
                set.push((id, *pose));
            }
            items.push(Item::step());
            steps.push(set);
        }
        let before = poses(&s, &ids);
        let mut req = SceneRequest::new(SceneKind::Within, 0);
        req.path = PathMode::EveryStep as u32;
        req.margin = margin;
        req.accept_absolute = accept;
        let pairs = group_pairs(&group, &ids);
        for _ in 0..2 {
            let (reply, rows) = ask(&mut s, 1, &req, &items);
            prop_assert_eq!(reply.steps as usize, steps.len());
            check_path_within(&s, &rows, &steps, &pairs, margin, accept);
        }
        prop_assert_eq!(poses(&s, &ids), before);
    }
}

/// A ball rolling slowly along a row of balls, some touching it: the
/// lookahead settles most pairs from the travel alone, and every step's
/// pairs are those of the same question asked cold at that step's pose.
#[test]
fn slow_paths_settle_pairs_by_travel_and_agree_with_cold_steps() {
    let mut s = State::new(Limits::default(), WaitMode::Spin, 3);
    let mut ball = |x: f64, y: f64| {
        s.insert(
            NewObject {
                shape: Convex::sphere(0.5).unwrap().into(),
                pose: Isometry3::translation(x, y, 0.0),
                name: None,
            },
            Owner::Client(1),
        )
        .unwrap()
    };
    let mover = ball(0.0, 0.0);
    let mut ids = vec![mover];
    for i in 0..12 {
        ids.push(ball(f64::from(i), if i % 3 == 0 { 0.9 } else { 1.3 }));
    }
    let mut path = Vec::new();
    let mut steps = Vec::new();
    for i in 0..400 {
        let t = f64::from(i) * 0.03;
        let p = Isometry3::new(Vector3::new(t, 0.1 * t.sin(), 0.0), Vector3::z() * 0.02 * t);
        path.push(Item::set_pose(ObjectId::from_raw(mover), &p));
        path.push(Item::step());
        steps.push(vec![(mover, p)]);
    }
    let mut req = SceneRequest::new(SceneKind::Within, mover);
    req.path = PathMode::EveryStep as u32;
    req.margin = 0.05;
    let (reply, rows) = ask(&mut s, 1, &req, &path);
    check_path_within(
        &s,
        &rows,
        &steps,
        &group_pairs(&[mover], &ids),
        req.margin,
        0.0,
    );
    assert!(reply.bounded > reply.gjk_runs, "{reply:?}");
    let mut single = req;
    single.path = PathMode::Single as u32;
    single.flags &= !(scene_flags::MOTION_BOUNDS | scene_flags::WARM_START);
    for (i, chunk) in path.chunks(2).enumerate().step_by(7) {
        let mut cold = State::new(Limits::default(), WaitMode::Spin, 3);
        for &id in &ids {
            let o = s.object(id).unwrap();
            let new = NewObject {
                shape: o.shape.clone(),
                pose: o.pose,
                name: None,
            };
            assert_eq!(cold.insert(new, Owner::Client(1)).unwrap(), id);
        }
        let (_, expected) = ask(&mut cold, 9, &single, &chunk[..1]);
        let along: Vec<u64> = rows
            .iter()
            .filter(|r| r.step == i as u32)
            .map(|r| r.b)
            .collect();
        let cold_pairs: Vec<u64> = expected.iter().map(|r| r.b).collect();
        assert_eq!(along, cold_pairs, "step {i}");
    }
}

/// A path whose last step sets a pose that is not a rotation is refused
/// whole: no row, the store and the bounds of later paths untouched.
#[test]
fn paths_with_a_bad_step_are_refused_whole() {
    let (mut s, ids) = scene(30, Vector3::zeros(), 3.0, 8);
    let mover = ids[0];
    let before = poses(&s, &ids);
    let mut path = Vec::new();
    for i in 0..20 {
        let p = Isometry3::translation(0.1 * f64::from(i), 0.0, 0.0);
        path.push(Item::set_pose(ObjectId::from_raw(mover), &p));
        path.push(Item::step());
    }
    let mut req = SceneRequest::new(SceneKind::Within, mover);
    req.path = PathMode::EveryStep as u32;
    req.margin = 0.3;
    let mut bad = path.clone();
    bad[38].pose_a.rotation = [0.0; 4];
    let mut rows = vec![SceneRow::default(); 256];
    let reply = s.scene(1, &req, &bad, &mut rows);
    assert_ne!(reply.error_code(), ErrorCode::Ok);
    assert_eq!((reply.total, reply.steps), (0, 0));
    assert_eq!(poses(&s, &ids), before);
    let (reply, rows) = ask(&mut s, 1, &req, &path);
    assert_eq!(reply.steps, 20);
    let steps: Vec<Vec<(u64, Isometry3<f64>)>> = (0..20)
        .map(|i| vec![(mover, Isometry3::translation(0.1 * f64::from(i), 0.0, 0.0))])
        .collect();
    check_path_within(
        &s,
        &rows,
        &steps,
        &group_pairs(&[mover], &ids),
        req.margin,
        0.0,
    );
}

/// A path through the far ends of the number line overflows the travel:
/// the candidates are searched again rather than trusted, and the pair
/// met on the way back is found.
#[test]
fn overflowing_travel_searches_again() {
    let mut s = State::new(Limits::default(), WaitMode::Spin, 3);
    let mut ball = |x: f64| {
        s.insert(
            NewObject {
                shape: Convex::sphere(0.5).unwrap().into(),
                pose: Isometry3::translation(x, 0.0, 0.0),
                name: None,
            },
            Owner::Client(1),
        )
        .unwrap()
    };
    let (mover, other) = (ball(0.0), ball(2.0));
    let mut path = Vec::new();
    for x in [0.0, 2.6e300, -2.6e300, 1.5, 1.6] {
        let p = Isometry3::translation(x, 0.0, 0.0);
        path.push(Item::set_pose(ObjectId::from_raw(mover), &p));
        path.push(Item::step());
    }
    let mut req = SceneRequest::new(SceneKind::Within, mover);
    req.path = PathMode::EveryStep as u32;
    let (_, rows) = ask(&mut s, 1, &req, &path);
    let hits: Vec<(u32, u64)> = rows.iter().map(|r| (r.step, r.b)).collect();
    assert_eq!(hits, [(3, other), (4, other)]);
}

/// A box spinning fast in place, far from the origin or not, under a
/// box it never reaches and around a small box inside it, with one
/// teleport away and back: the travel and the poses' motion bound widen
/// by more than the gap and the depth at every step, so the pairs are
/// settled by re-certifying their kept bounds (the separated pair from its
/// normal, the overlapping one from its simplex) instead of GJK, and
/// every step still matches brute force.
#[test]
fn spinning_paths_recheck_kept_bounds_instead_of_running_gjk() {
    for centre in [Vector3::zeros(), Vector3::new(1e6, -1e6, 5e5)] {
        let mut s = State::new(Limits::default(), WaitMode::Spin, 3);
        let mut block = |half: f64| {
            s.insert(
                NewObject {
                    shape: Convex::cuboid(Vector3::repeat(half), 0.0).unwrap().into(),
                    pose: Isometry3::translation(centre.x, centre.y, centre.z),
                    name: None,
                },
                Owner::Client(1),
            )
            .unwrap()
        };
        let (mover, core) = (block(1.0), block(0.2));
        // A lid tilted about x, its lower face 0.5 above the box (the
        // box's support along its normal `n` is 1.357), its own box
        // reaching down past the box's.
        let tilt = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -0.5);
        let n = tilt * Vector3::z();
        // Spinning about the lid's normal, so that the box's support along
        // it stays as it was.
        let axis = nalgebra::Unit::new_normalize(n);
        let lid = s
            .insert(
                NewObject {
                    shape: Convex::cuboid(Vector3::new(2.0, 2.0, 0.5), 0.0)
                        .unwrap()
                        .into(),
                    pose: Isometry3::from_parts(Translation3::from(centre + n * 2.357), tilt),
                    name: None,
                },
                Owner::Client(1),
            )
            .unwrap();
        let ids = [mover, lid, core];
        let mut path = Vec::new();
        let mut steps = Vec::new();
        let spins: u32 = 60;
        for i in 0..spins {
            let turn = UnitQuaternion::from_axis_angle(&axis, 0.3 * f64::from(i));
            let at = if i == spins / 2 {
                centre + Vector3::new(50.0, 0.0, 0.0)
            } else {
                centre
            };
            let p = Isometry3::from_parts(Translation3::from(at), turn);
            path.push(Item::set_pose(ObjectId::from_raw(mover), &p));
            path.push(Item::step());
            steps.push(vec![(mover, p)]);
        }
        let mut req = SceneRequest::new(SceneKind::Within, mover);
        req.path = PathMode::EveryStep as u32;
        let (reply, rows) = ask(&mut s, 1, &req, &path);
        check_path_within(&s, &rows, &steps, &group_pairs(&[mover], &ids), 0.0, 0.0);
        // The core is inside the box at every step but the teleport's.
        let hits = rows.iter().filter(|r| r.b == core).count();
        assert_eq!(hits, spins as usize - 1, "{reply:?}");
        assert!(rows.iter().all(|r| r.b == core), "{rows:?}");
        // Each step moves points of the box by about 0.5, as much as the
        // lid's gap: without the rechecks both pairs would run GJK
        // at nearly every step.
        assert!(reply.gjk_runs <= 12, "{reply:?}");
        assert!(reply.bounded >= 2 * u64::from(spins) - 20, "{reply:?}");
    }
}
