//! Continuous paths against dense sampling: 10 000 poses a segment, each
//! pair by the test kit's brute force between hulls. A segment answered
//! clear must have no sampled contact; a contact's bracket must hold the
//! first sampled contact (allowing the sampling step) and its `s_hi` must
//! be within the margin. Samples that the last measured distance and the
//! bodies' displacement since already put beyond the margin are skipped
//! (`gjkd_testkit::dense`): the first sampled contact is the same.

use super::*;
use gjkd_testkit::dense::{displacement, first_within};
use gjkd_testkit::reference::{self, Hull};

/// Poses per segment of the dense truth.
const DENSE: usize = 10_000;

type Pieces = Vec<(Isometry3<f64>, Hull, f64)>;

fn pieces(shape: &Shape) -> Pieces {
    let convex: Vec<(Isometry3<f64>, &Convex)> = match shape {
        Shape::Convex(c) => vec![(Isometry3::identity(), c)],
        Shape::Compound(c) => c.pieces().iter().map(|(o, p)| (*o, p)).collect(),
    };
    convex
        .into_iter()
        .map(|(o, c)| (o, Hull::new(c.vertices()), c.radius()))
        .collect()
}

fn reach_of(shape: &Shape) -> f64 {
    super::super::broadphase::bounding_sphere(shape).2
}

/// The farthest point of a shape's pieces from its body origin, radius
/// included (the motion bound of the dense sampling's skips).
fn body_reach(pieces: &Pieces) -> f64 {
    pieces
        .iter()
        .flat_map(|(o, h, r)| h.points().iter().map(move |v| (o * v).coords.norm() + r))
        .fold(0.0, f64::max)
}

/// Round-off allowed the skips at coordinates of magnitude `scale`.
fn slack(scale: f64) -> f64 {
    1e-9 * (1.0 + scale)
}

fn brute(a: &Pieces, pa: &Isometry3<f64>, b: &Pieces, pb: &Isometry3<f64>) -> f64 {
    let mut best = f64::INFINITY;
    for (oa, ha, ra) in a {
        for (ob, hb, rb) in b {
            let d = reference::distance(ha, &(pa * oa), *ra, hb, &(pb * ob), *rb).distance;
            best = best.min(d);
        }
    }
    best
}

/// The pose at `s` of a rigid motion, computed apart from the server:
/// translation linear, rotation by nalgebra's slerp (or its linear
/// quaternion, renormalised).
fn rigid_at(from: &Isometry3<f64>, to: &Isometry3<f64>, s: f64, linear: bool) -> Isometry3<f64> {
    let t = from.translation.vector.lerp(&to.translation.vector, s);
    let r = if linear {
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::from(
            from.rotation.coords.lerp(&to.rotation.coords, s),
        ))
    } else {
        from.rotation.slerp(&to.rotation, s)
    };
    Isometry3::from_parts(Translation3::from(t), r)
}

/// Checks one segment's answer (`row`, `None` for clear) against `first`,
/// the first dense `s` whose least distance over the segment's pairs is at
/// or below `margin - tol`, and that least distance at any `s`
/// (`least(s)`); `tol` is the agreement expected between the server's
/// intervals and brute force.
fn check_segment(
    row: Option<&SceneRow>,
    bracket: f64,
    margin: f64,
    tol: f64,
    first: Option<f64>,
    least: impl Fn(f64) -> f64,
) -> Option<f64> {
    match row {
        None => assert!(first.is_none(), "certified clear, touches at s = {first:?}"),
        Some(r) => {
            assert!(r.s_lo <= r.s_hi && r.s_hi - r.s_lo <= bracket, "{r:?}");
            assert!(r.result.lower <= margin, "{r:?}");
            let at_hi = least(r.s_hi);
            assert!(at_hi <= margin + tol, "s_hi {} is {at_hi} away", r.s_hi);
            if let Some(f) = first {
                assert!(f >= r.s_lo - 1e-12, "contact at {f} before s_lo {}", r.s_lo);
                // A contact at `s_hi` beyond doubt bounds the first from
                // above (one sampling step allowed); one within `tol` of
                // the margin may be a grazing pass the server kept.
                if at_hi <= margin - tol {
                    assert!(
                        f <= r.s_hi + 1.0 / DENSE as f64,
                        "{f} long after {}",
                        r.s_hi
                    );
                }
            }
        }
    }
    first
}

fn continuous(margin: f64, bracket: f64) -> SceneRequest {
    let mut r = SceneRequest::new(SceneKind::Within, 0);
    r.path = PathMode::Continuous as u32;
    r.margin = margin;
    r.bracket = bracket;
    r
}

fn pose_step(id: u64, pose: &Isometry3<f64>) -> Item {
    Item::set_pose(ObjectId::from_raw(id), pose).ending_step()
}

/// Moves `mover` along `waypoints` among everything else in `s` and
/// checks every segment; returns how many segments touch.
fn check_rigid(
    s: &mut State,
    mover: u64,
    waypoints: &[Isometry3<f64>],
    margin: f64,
    linear: bool,
    tol: f64,
) -> usize {
    let bracket = 1e-6;
    let mut request = continuous(margin, bracket);
    request.group = mover;
    if linear {
        request.flags |= scene_flags::LINEAR_QUATERNION;
    }
    let items: Vec<Item> = waypoints.iter().map(|p| pose_step(mover, p)).collect();
    let (reply, rows) = ask(s, 1, &request, &items);
    assert_eq!(reply.steps as usize, waypoints.len() - 1);
    let shape = pieces(&s.object(mover).unwrap().shape);
    let others: Vec<(Pieces, Isometry3<f64>, f64, Point3<f64>)> = s
        .store
        .objects()
        .filter(|(id, _)| *id != mover)
        .map(|(_, o)| {
            let (c, r) = (o.pose.translation.vector, reach_of(&o.shape));
            (pieces(&o.shape), o.pose, r, Point3::from(c))
        })
        .collect();
    let reach = reach_of(&s.object(mover).unwrap().shape);
    let moves = body_reach(&shape);
    let scale = waypoints
        .iter()
        .map(|p| p.translation.vector.norm())
        .fold(0.0, f64::max);
    let mut touching = 0;
    for (k, pair) in waypoints.windows(2).enumerate() {
        let row = rows.iter().find(|r| r.step == k as u32);
        if let Some(r) = row {
            assert_eq!(r.a, mover);
        }
        // The brute force for a pair whose bounding spheres come within the
        // margin, the spheres' gap (beyond it, a lower bound) for another.
        let lower = |j: usize, p: &Isometry3<f64>| {
            let (b, pb, r, c) = &others[j];
            let gap = (c - Point3::from(p.translation.vector)).norm() - r - reach;
            if gap <= margin + 1e-6 {
                brute(&shape, p, b, pb)
            } else {
                gap
            }
        };
        let first = first_within(
            DENSE,
            margin - tol,
            slack(scale),
            others.len(),
            |t| rigid_at(&pair[0], &pair[1], t, linear),
            |_, a, b| displacement(a, b, moves),
            lower,
        );
        let least = |t: f64| {
            let p = rigid_at(&pair[0], &pair[1], t, linear);
            others
                .iter()
                .filter(|(_, _, r, c)| {
                    (c - Point3::from(p.translation.vector)).norm() - r - reach <= margin + 1e-6
                })
                .map(|(b, pb, _, _)| brute(&shape, &p, b, pb))
                .fold(f64::INFINITY, f64::min)
        };
        if check_segment(row, bracket, margin, tol, first, least).is_some() || row.is_some() {
            touching += 1;
        }
    }
    touching
}

/// `n` obstacles of every kind the brute force handles (no cylinders)
/// about `centre`, and a mover; returns the state, the mover and a random
/// pose generator's next waypoints.
fn rigid_scene(seed: u64, centre: Vector3<f64>) -> (State, u64, Vec<Isometry3<f64>>) {
    let mut s = State::new(Limits::default(), WaitMode::Spin, 3);
    let mut rng = Lcg(seed);
    for i in 0..30 {
        let kind = [0, 1, 2, 3, 5][i % 5];
        let new = NewObject {
            shape: shape(kind, &mut rng),
            pose: rng.pose(&centre, 3.0),
            name: None,
        };
        s.insert(new, Owner::Client(1)).unwrap();
    }
    let mover = s
        .insert(
            NewObject {
                shape: shape(5, &mut rng),
                pose: Isometry3::identity(),
                name: None,
            },
            Owner::Client(1),
        )
        .unwrap();
    let waypoints = (0..4).map(|_| rng.pose(&centre, 3.5)).collect();
    (s, mover, waypoints)
}

#[test]
fn random_rigid_motions_never_miss_a_contact() {
    let mut touching = 0;
    for seed in 0..6 {
        for margin in [0.0, 0.15] {
            let (mut s, mover, way) = rigid_scene(seed, Vector3::zeros());
            touching += check_rigid(&mut s, mover, &way, margin, false, 1e-9);
        }
    }
    // Both answers are exercised.
    assert!(
        (6..36).contains(&touching),
        "{touching} of 36 segments touch"
    );
}

#[test]
fn linear_quaternions_and_far_offsets_hold_too() {
    for seed in 20..24 {
        let (mut s, mover, way) = rigid_scene(seed, Vector3::zeros());
        check_rigid(&mut s, mover, &way, 0.05, true, 1e-9);
        // Poses 1e6 from the origin carry round-off of about 1e-12 of
        // their magnitude, which the server's intervals are widened by: a
        // pass that near the margin is reported, never cleared.
        let far = Vector3::new(1e6, -1e6, 1e6);
        let (mut s, mover, way) = rigid_scene(seed, far);
        check_rigid(&mut s, mover, &way, 0.05, false, 2e-5);
    }
}

fn insert(s: &mut State, shape: Shape, pose: Isometry3<f64>) -> u64 {
    s.insert(
        NewObject {
            shape,
            pose,
            name: None,
        },
        Owner::Client(1),
    )
    .unwrap()
}

#[test]
fn a_thin_plate_missed_by_sampling_is_found() {
    let mut s = State::new(Limits::default(), WaitMode::Spin, 3);
    // A plate 1e-4 thick, a ball 100 times its thickness crossing it.
    let plate = Convex::cuboid(Vector3::new(0.5e-4, 1.0, 1.0), 0.0).unwrap();
    insert(&mut s, plate.into(), Isometry3::translation(0.0, 0.0, 0.0));
    let ball = insert(
        &mut s,
        Convex::sphere(0.01).unwrap().into(),
        Isometry3::identity(),
    );
    let way = [
        Isometry3::translation(-3.0, 0.1, 0.0),
        Isometry3::translation(3.03, 0.2, 0.0),
    ];
    // Sampled at OMPL's resolution (ten steps), the plate slips between.
    let mut sampled = SceneRequest::new(SceneKind::Within, ball);
    sampled.path = PathMode::EveryStep as u32;
    let steps: Vec<Item> = (0..=10)
        .map(|i| {
            pose_step(
                ball,
                &rigid_at(&way[0], &way[1], f64::from(i) / 10.0, false),
            )
        })
        .collect();
    assert_eq!(ask(&mut s, 1, &sampled, &steps).0.total, 0);
    assert_eq!(check_rigid(&mut s, ball, &way, 0.0, false, 1e-12), 1);
    let (_, rows) = ask(
        &mut s,
        1,
        &continuous(0.0, 1e-9),
        &[
            Item::member(ObjectId::from_raw(ball)),
            pose_step(ball, &way[0]),
            pose_step(ball, &way[1]),
        ],
    );
    // The ball first touches where its centre is 0.01 + 0.5e-4 before the
    // plate's middle: x(s) = -3 + 6.03 s.
    let exact = (3.0 - 0.01 - 0.5e-4) / 6.03;
    assert_eq!(rows.len(), 1);
    assert!(
        rows[0].s_lo <= exact && exact <= rows[0].s_hi + 1e-12,
        "{:?}",
        rows[0]
    );
    assert!(rows[0].s_hi - rows[0].s_lo <= 1e-9);
}

#[test]
fn fast_rotations_sweep_what_their_ends_miss() {
    let mut s = State::new(Limits::default(), WaitMode::Spin, 3);
    // A bar 4 long turning by 3 rad about its middle: its ends clear the
    // post at both waypoints and strike it between.
    let bar = Convex::cuboid(Vector3::new(2.0, 0.02, 0.02), 0.0).unwrap();
    let bar = insert(&mut s, bar.into(), Isometry3::identity());
    let post = Convex::cuboid(Vector3::new(0.05, 0.05, 1.0), 0.0).unwrap();
    insert(&mut s, post.into(), Isometry3::translation(0.0, 1.5, 0.0));
    let turn = |a: f64| {
        Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_euler_angles(0.0, 0.0, a),
        )
    };
    let way = [turn(-1.4), turn(1.6), turn(1.4)];
    assert_eq!(check_rigid(&mut s, bar, &way, 0.0, false, 1e-9), 2);
    assert_eq!(check_rigid(&mut s, bar, &way, 0.0, true, 1e-9), 2);
}

#[test]
fn grazing_passes_are_told_apart_at_a_billionth() {
    for (offset, touches) in [(1e-9, 0), (-1e-9, 1)] {
        let mut s = State::new(Limits::default(), WaitMode::Spin, 3);
        let block = Convex::cuboid(Vector3::new(0.5, 0.5, 0.5), 0.0).unwrap();
        insert(&mut s, block.into(), Isometry3::identity());
        let ball = insert(
            &mut s,
            Convex::sphere(0.5).unwrap().into(),
            Isometry3::identity(),
        );
        let margin = 0.1;
        let y = 1.0 + margin + offset;
        let way = [
            Isometry3::translation(-2.0, y, 0.0),
            Isometry3::translation(2.0, y, 0.0),
        ];
        assert_eq!(
            check_rigid(&mut s, ball, &way, margin, false, 1e-12),
            touches
        );
    }
}

/// The three-link arm of the robot tests, and obstacles about it.
fn arm_scene(seed: u64) -> (State, u64, Vec<u64>) {
    let (mut s, robot, links, _) = super::robots_and_refusals::arm_state();
    let mut rng = Lcg(seed);
    for i in 0..6 {
        let kind = [0, 1, 2, 3, 5][i % 5];
        let sh = shape(kind, &mut rng);
        let pose = rng.pose(&Vector3::new(0.0, 0.0, 0.1), 1.8);
        insert(&mut s, sh, pose);
    }
    (s, robot, links)
}

#[test]
fn robot_edges_never_miss_a_contact() {
    let mut touching = 0;
    for seed in 0..10 {
        let (mut s, robot, links) = arm_scene(seed);
        let mut rng = Lcg(seed + 100);
        let qs: Vec<[f64; 2]> = (0..3)
            .map(|_| [rng.range(-3.0, 3.0), rng.range(-3.0, 3.0)])
            .collect();
        let mut request = continuous(0.02, 1e-6);
        request.group = robot;
        let items: Vec<Item> = qs
            .iter()
            .map(|q| Item::set_joints(ObjectId::from_raw(robot), 0, q, None, false).ending_step())
            .collect();
        let (_, rows) = ask(&mut s, 1, &request, &items);
        let r = s.robots.get(robot).unwrap();
        let kin = r.kinematics.clone();
        let shapes: Vec<Pieces> = links
            .iter()
            .map(|&id| pieces(&s.object(id).unwrap().shape))
            .collect();
        let reaches: Vec<f64> = links
            .iter()
            .map(|&id| reach_of(&s.object(id).unwrap().shape))
            .collect();
        let others: Vec<(Pieces, Isometry3<f64>, f64)> = s
            .store
            .objects()
            .filter(|(id, _)| !links.contains(id))
            .map(|(_, o)| (pieces(&o.shape), o.pose, reach_of(&o.shape)))
            .collect();
        let moves: Vec<f64> = shapes.iter().map(body_reach).collect();
        for (k, q) in qs.windows(2).enumerate() {
            let row = rows.iter().find(|r| r.step == k as u32);
            let poses_at = |t: f64| {
                let at: Vec<f64> = (0..2).map(|j| q[0][j] + (q[1][j] - q[0][j]) * t).collect();
                kin.link_poses(&Isometry3::identity(), &at, gjkd_model::LimitMode::Clamp)
                    .unwrap()
            };
            // Pair `j` is link `j / n` and obstacle `j % n`: the brute
            // force when their bounding spheres come within the margin, the
            // spheres' gap (a lower bound) with `gaps`, else nothing.
            let n = others.len();
            let measure = |j: usize, poses: &Vec<Isometry3<f64>>, gaps: bool| {
                let (link, (b, pb, rb)) = (j / n, &others[j % n]);
                let pose = &poses[link];
                let apart = (pose.translation.vector - pb.translation.vector).norm();
                if apart - reaches[link] - rb <= 0.02 + 1e-6 {
                    brute(&shapes[link], pose, b, pb)
                } else if gaps {
                    apart - reaches[link] - rb
                } else {
                    f64::INFINITY
                }
            };
            let moved = |j: usize, a: &Vec<Isometry3<f64>>, b: &Vec<Isometry3<f64>>| {
                displacement(&a[j / n], &b[j / n], moves[j / n])
            };
            let first = first_within(
                DENSE,
                0.02 - 1e-9,
                slack(4.0),
                links.len() * n,
                poses_at,
                moved,
                |j, p| measure(j, p, true),
            );
            let least = |t: f64| {
                let poses = poses_at(t);
                (0..links.len() * n)
                    .map(|j| measure(j, &poses, false))
                    .fold(f64::INFINITY, f64::min)
            };
            if check_segment(row, 1e-6, 0.02, 1e-9, first, least).is_some() || row.is_some() {
                touching += 1;
            }
        }
    }
    assert!(
        (4..20).contains(&touching),
        "{touching} of 20 segments touch"
    );
}

#[test]
fn bad_continuous_paths_get_their_codes_and_change_nothing() {
    let (mut s, robot, links, obstacle) = super::robots_and_refusals::arm_state();
    let all: Vec<u64> = links.iter().copied().chain([obstacle]).collect();
    let before = (
        poses(&s, &all),
        s.robots.get(robot).unwrap().positions.clone(),
    );
    let id = ObjectId::from_raw(robot);
    let joints = |q: [f64; 2]| Item::set_joints(id, 0, &q, None, false).ending_step();
    let mut req = continuous(0.0, 1e-6);
    req.group = robot;
    let with = |f: &dyn Fn(&mut SceneRequest)| {
        let mut r = req;
        f(&mut r);
        r
    };
    let good = vec![joints([0.0, 0.0]), joints([1.0, 0.5])];
    let moved = Item::set_pose(ObjectId::from_raw(links[1]), &Isometry3::identity()).ending_step();
    let cases: Vec<(SceneRequest, Vec<Item>, ErrorCode)> = vec![
        (
            req,
            vec![joints([0.0, 0.0]), joints([f64::NAN, 0.5])],
            ErrorCode::NonFinitePose,
        ),
        (
            req,
            vec![joints([0.0, 0.0]), joints([4.0, 0.5])],
            ErrorCode::OutOfLimits,
        ),
        (
            with(&|r| r.bracket = 0.0),
            good.clone(),
            ErrorCode::InvalidOptions,
        ),
        (
            with(&|r| r.bracket = -1e-3),
            good.clone(),
            ErrorCode::InvalidOptions,
        ),
        (
            with(&|r| r.bracket = f64::NAN),
            good.clone(),
            ErrorCode::InvalidOptions,
        ),
        (
            req,
            vec![joints([0.5, 0.5]), joints([0.5, 0.5])],
            ErrorCode::Malformed,
        ),
        (req, vec![joints([0.5, 0.5])], ErrorCode::Malformed),
        (
            req,
            vec![joints([0.0, 0.0]), moved, joints([1.0, 0.5])],
            ErrorCode::Malformed,
        ),
        (
            with(&|r| r.kind = SceneKind::Clearance as u32),
            good.clone(),
            ErrorCode::Malformed,
        ),
        (
            with(&|r| {
                r.path = PathMode::EveryStep as u32;
                r.flags |= scene_flags::LINEAR_QUATERNION;
            }),
            good.clone(),
            ErrorCode::Malformed,
        ),
    ];
    for (request, items, code) in cases {
        let mut rows = vec![SceneRow::default(); 8];
        let reply = s.scene(1, &request, &items, &mut rows);
        assert_eq!(reply.error_code(), code, "{request:?} {items:?}");
        assert_eq!(reply.total, 0);
        let after = (
            poses(&s, &all),
            s.robots.get(robot).unwrap().positions.clone(),
        );
        assert_eq!(after, before);
    }
    // The same path, well formed, answers and still changes nothing.
    let mut rows = vec![SceneRow::default(); 8];
    assert_eq!(
        s.scene(1, &req, &good, &mut rows).error_code(),
        ErrorCode::Ok
    );
    assert_eq!(
        (
            poses(&s, &all),
            s.robots.get(robot).unwrap().positions.clone()
        ),
        before
    );
}

#[test]
fn self_pairs_find_a_robot_folding_onto_itself() {
    let (mut s, robot, links, obstacle) = super::robots_and_refusals::arm_state();
    let away = Item::set_pose(
        ObjectId::from_raw(obstacle),
        &Isometry3::translation(10.0, 0.0, 0.0),
    );
    let mut single = SceneRequest::new(SceneKind::Within, robot);
    single.margin = 0.02;
    ask(&mut s, 1, &single, &[away]);
    let kin = s.robots.get(robot).unwrap().kinematics.clone();
    let (l0, l2) = (
        pieces(&s.object(links[0]).unwrap().shape),
        pieces(&s.object(links[2]).unwrap().shape),
    );
    let moves = [body_reach(&l0), body_reach(&l2)];
    // l1 is adjacent to both (allowed): l0 and l2 are the arm's only pair.
    let edges = [
        ([0.0, 0.0], [0.0, 3.0]),
        ([0.5, -1.0], [0.3, -3.0]),
        ([0.0, 0.0], [0.0, 1.0]),
    ];
    let mut touching = 0;
    for (q0, q1) in edges {
        let mut request = continuous(0.02, 1e-6);
        request.group = robot;
        request.flags |= scene_flags::SELF_PAIRS;
        let items = [q0, q1]
            .map(|q| Item::set_joints(ObjectId::from_raw(robot), 0, &q, None, false).ending_step());
        let (_, rows) = ask(&mut s, 1, &request, &items);
        let poses_at = |t: f64| {
            let at = [q0[0] + (q1[0] - q0[0]) * t, q0[1] + (q1[1] - q0[1]) * t];
            kin.link_poses(&Isometry3::identity(), &at, gjkd_model::LimitMode::Clamp)
                .unwrap()
        };
        let measure = |poses: &Vec<Isometry3<f64>>| brute(&l0, &poses[0], &l2, &poses[2]);
        // Both links may move: their displacements add.
        let moved = |_: usize, a: &Vec<Isometry3<f64>>, b: &Vec<Isometry3<f64>>| {
            displacement(&a[0], &b[0], moves[0]) + displacement(&a[2], &b[2], moves[1])
        };
        let first = first_within(
            DENSE,
            0.02 - 1e-9,
            slack(4.0),
            1,
            poses_at,
            moved,
            |_, p| measure(p),
        );
        let least = |t: f64| measure(&poses_at(t));
        if check_segment(rows.first(), 1e-6, 0.02, 1e-9, first, least).is_some() {
            touching += 1;
            assert_eq!(rows.len(), 1);
            let (a, b) = (rows[0].a.min(rows[0].b), rows[0].a.max(rows[0].b));
            assert_eq!((a, b), (links[0].min(links[2]), links[0].max(links[2])));
            // Without the group's own pairs the fold is no contact.
            request.flags &= !scene_flags::SELF_PAIRS;
            let (_, rows) = ask(&mut s, 1, &request, &items);
            assert!(rows.is_empty(), "{rows:?}");
        }
    }
    assert_eq!(
        touching, 2,
        "the two folding edges touch, the third is clear"
    );
}
