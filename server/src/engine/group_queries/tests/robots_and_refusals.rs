//! Robot groups, refused requests and the index following the store.

use super::*;

/// A three-link arm on revolute joints, links touching their neighbours.
const ARM: &str = r#"<robot name="arm">
  <link name="l0"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="l1"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.1 0.1"/></geometry></collision></link>
  <link name="l2"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.1 0.1"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="l0"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="1 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#;

pub(super) fn arm_state() -> (State, u64, Vec<u64>, u64) {
    let mut s = State::new(Limits::default(), WaitMode::Spin, 3);
    let model = gjkd_model::RobotModel::from_urdf_str(ARM, None, &Default::default()).unwrap();
    let mut links = Vec::new();
    for link in &model.links {
        let new = NewObject {
            shape: link.shape.clone().unwrap(),
            pose: Isometry3::identity(),
            name: Some(format!("arm/{}", link.name)),
        };
        links.push(s.insert(new, Owner::Client(1)).unwrap());
    }
    let obstacle = s
        .insert(
            NewObject {
                shape: Convex::sphere(0.2).unwrap().into(),
                pose: Isometry3::translation(1.0, 1.0, 0.1),
                name: None,
            },
            Owner::Client(1),
        )
        .unwrap();
    let robot = s
        .attach_robot(NewRobot {
            name: "arm",
            urdf: ARM,
            srdf: None,
            base: Isometry3::identity(),
            positions: None,
            owner: Owner::Client(1),
        })
        .unwrap();
    (s, robot, links, obstacle)
}

#[test]
fn robot_groups_skip_their_own_links_and_allowed_pairs() {
    let (mut s, robot, links, obstacle) = arm_state();
    // Clearance: each link's nearest is the obstacle, never another link.
    let req = SceneRequest::new(SceneKind::Clearance, robot);
    let (_, rows) = ask(&mut s, 1, &req, &[]);
    assert_eq!(rows.len(), 3);
    assert!(rows.iter().all(|r| r.b == obstacle));
    // All pairs within 0.05: the adjacent links touch but are allowed; a
    // user's allowed pair hides the obstacle once it touches l2.
    let mut all = SceneRequest::new(SceneKind::Within, robot);
    all.flags |= scene_flags::ALL_PAIRS;
    all.margin = 0.05;
    let (_, rows) = ask(&mut s, 1, &all, &[]);
    assert!(rows.is_empty(), "{rows:?}");
    let touch = Item::set_pose(
        ObjectId::from_raw(obstacle),
        &Isometry3::translation(1.5, 0.25, 0.1),
    );
    let (_, rows) = ask(&mut s, 1, &all, &[touch]);
    assert_eq!(rows.len(), 1);
    assert_eq!(
        (rows[0].a.min(rows[0].b), rows[0].a.max(rows[0].b)),
        (links[2].min(obstacle), links[2].max(obstacle))
    );
    let allow = Item::allow(ObjectId::from_raw(obstacle), ObjectId::from_raw(links[2]));
    let (_, rows) = ask(&mut s, 1, &all, &[allow]);
    assert!(rows.is_empty());
    // A path of joint positions: the arm folds onto the obstacle and back;
    // the stored joints stay.
    let stored = s.robots.get(robot).unwrap().positions.clone();
    let mut path = Vec::new();
    for i in 0..8 {
        let q = [0.2 * f64::from(i), -0.1 * f64::from(i)];
        path.push(Item::set_joints(
            ObjectId::from_raw(robot),
            0,
            &q,
            None,
            false,
        ));
        path.push(Item::step());
    }
    let mut within = SceneRequest::new(SceneKind::Within, robot);
    within.margin = 0.3;
    within.path = PathMode::EveryStep as u32;
    let (reply, rows) = ask(&mut s, 1, &within, &path);
    assert_eq!(reply.steps, 8);
    assert_eq!(s.robots.get(robot).unwrap().positions, stored);
    // Every reported pair holds at that step's forward kinematics.
    let kin = s.robots.get(robot).unwrap().kinematics.clone();
    for row in &rows {
        let q = [0.2 * f64::from(row.step), -0.1 * f64::from(row.step)];
        let fk = kin
            .link_poses(&Isometry3::identity(), &q, gjkd_model::LimitMode::Reject)
            .unwrap();
        let i = links.iter().position(|&l| l == row.a).unwrap();
        let (oa, ob) = (s.object(row.a).unwrap(), s.object(row.b).unwrap());
        let e = gjk::distance(
            &oa.shape,
            &fk[i],
            &ob.shape,
            &ob.pose,
            &Default::default(),
            None,
        )
        .unwrap();
        assert!(overlaps(row.result.lower, row.result.upper, &e));
    }
}

#[test]
fn bad_requests_get_their_codes_and_change_nothing() {
    let (mut s, robot, links, obstacle) = arm_state();
    let all: Vec<u64> = links.iter().copied().chain([obstacle]).collect();
    // Warm the cache so that a change to it would show.
    let req = SceneRequest::new(SceneKind::Clearance, robot);
    ask(&mut s, 1, &req, &[]);
    let before = (
        poses(&s, &all),
        s.robots.get(robot).unwrap().positions.clone(),
        s.stats().cache_entries,
    );
    let id = |x: u64| ObjectId::from_raw(x);
    let good_move = Item::set_pose(id(obstacle), &Isometry3::translation(3.0, 0.0, 0.0));
    let good_joints = Item::set_joints(id(robot), 0, &[0.5, 0.5], None, false);
    let with = |f: &dyn Fn(&mut SceneRequest)| {
        let mut r = SceneRequest::new(SceneKind::Clearance, robot);
        f(&mut r);
        r
    };
    let mut bad_quat = good_move;
    bad_quat.pose_a.rotation = [0.0, 0.0, 0.0, 2.0];
    let mut bad_flag = good_move;
    bad_flag.flags |= 1 << 30;
    let mut reserved = good_move;
    reserved.pair_mut().reserved = 1;
    let cases: Vec<(SceneRequest, Vec<Item>, ErrorCode)> = vec![
        (with(&|r| r.kind = 0), vec![good_move], ErrorCode::Malformed),
        (with(&|r| r.kind = 9), vec![good_move], ErrorCode::Malformed),
        (with(&|r| r.path = 7), vec![good_move], ErrorCode::Malformed),
        (
            with(&|r| r.flags |= 1 << 20),
            vec![good_move],
            ErrorCode::Malformed,
        ),
        (
            with(&|r| r.margin = f64::NAN),
            vec![good_move],
            ErrorCode::InvalidOptions,
        ),
        (
            with(&|r| r.accept_absolute = f64::NAN),
            vec![good_move],
            ErrorCode::InvalidOptions,
        ),
        (
            with(&|r| r.accept_relative = -1.0),
            vec![good_move],
            ErrorCode::InvalidOptions,
        ),
        (
            with(&|r| r.tolerance = f64::INFINITY),
            vec![good_move],
            ErrorCode::InvalidOptions,
        ),
        (
            with(&|r| r.max_iterations = 0),
            vec![good_move],
            ErrorCode::InvalidOptions,
        ),
        (
            with(&|r| r.group = 12345),
            vec![good_move],
            ErrorCode::UnknownObject,
        ),
        (
            with(&|r| r.kind = SceneKind::Nearest as u32),
            vec![good_move],
            ErrorCode::InvalidOptions,
        ),
        (
            with(&|r| {
                r.kind = SceneKind::Nearest as u32;
                r.k = 2;
            }),
            vec![good_move],
            ErrorCode::Malformed,
        ),
        (
            with(&|r| r.path = PathMode::FirstHit as u32),
            vec![good_move, Item::step()],
            ErrorCode::Malformed,
        ),
        (
            with(&|r| {
                r.kind = SceneKind::Nearest as u32;
                r.k = 1;
                r.group = obstacle;
                r.flags |= scene_flags::SELF_PAIRS;
            }),
            vec![good_move],
            ErrorCode::Malformed,
        ),
        (
            with(&|_| {}),
            vec![good_move, Item::step()],
            ErrorCode::Malformed,
        ),
        (
            with(&|r| r.path = PathMode::EveryStep as u32),
            vec![good_move, Item::step(), good_joints],
            ErrorCode::Malformed,
        ),
        (
            with(&|r| r.path = PathMode::EveryStep as u32),
            vec![good_move],
            ErrorCode::Malformed,
        ),
        // A step's end flagged outside a path, on a step item, or with
        // poses after the last step.
        (
            with(&|_| {}),
            vec![good_move.ending_step()],
            ErrorCode::Malformed,
        ),
        (
            with(&|r| r.path = PathMode::EveryStep as u32),
            vec![good_move.ending_step(), Item::step().ending_step()],
            ErrorCode::Malformed,
        ),
        (
            with(&|r| r.path = PathMode::EveryStep as u32),
            vec![good_joints.ending_step(), good_move],
            ErrorCode::Malformed,
        ),
        (
            with(&|_| {}),
            vec![good_move, bad_quat],
            ErrorCode::BadQuaternion,
        ),
        (
            with(&|_| {}),
            vec![good_joints, bad_flag],
            ErrorCode::Malformed,
        ),
        (
            with(&|_| {}),
            vec![good_move, reserved],
            ErrorCode::Malformed,
        ),
        (
            with(&|_| {}),
            vec![good_move, Item::member(id(obstacle))],
            ErrorCode::Malformed,
        ),
        (
            with(&|r| r.group = 0),
            vec![good_move, Item::member(id(99))],
            ErrorCode::UnknownObject,
        ),
        (
            with(&|_| {}),
            vec![good_move, Item::allow(id(obstacle), id(98))],
            ErrorCode::UnknownObject,
        ),
        (
            with(&|_| {}),
            vec![good_move, Item::set_pose(id(97), &Isometry3::identity())],
            ErrorCode::UnknownObject,
        ),
        (
            with(&|_| {}),
            vec![
                good_move,
                good_joints,
                Item::set_joints(id(robot), 0, &[0.5, 9.0], None, false),
            ],
            ErrorCode::OutOfLimits,
        ),
        (
            with(&|_| {}),
            vec![
                good_joints,
                Item::set_joints(id(robot), 1, &[0.5, 0.1], None, false),
            ],
            ErrorCode::Malformed,
        ),
        (
            with(&|r| r.path = PathMode::EveryStep as u32),
            vec![
                good_joints,
                Item::step(),
                Item::set_joints(id(robot), 0, &[f64::NAN], None, false),
                Item::step(),
            ],
            ErrorCode::NonFinitePose,
        ),
        (
            with(&|_| {}),
            vec![
                good_move,
                Item::distance(id(obstacle), id(links[0]), &Default::default()),
            ],
            ErrorCode::Malformed,
        ),
    ];
    for (req, items, code) in cases {
        let mut rows = [SceneRow::default(); 8];
        let reply = s.scene(1, &req, &items, &mut rows);
        assert_eq!(reply.error_code(), code, "{req:?} {items:?}");
        assert_eq!((reply.total, reply.first_hit), (0, u32::MAX));
        let now = (
            poses(&s, &all),
            s.robots.get(robot).unwrap().positions.clone(),
            s.stats().cache_entries,
        );
        assert_eq!(now, before, "{req:?} {items:?}");
    }
    // Clamping instead of refusing: the same out-of-limit joints apply.
    let mut clamp = SceneRequest::new(SceneKind::Clearance, robot);
    clamp.flags |= scene_flags::CLAMP;
    let items = [Item::set_joints(id(robot), 0, &[0.5, 9.0], None, false)];
    ask(&mut s, 1, &clamp, &items);
    assert_eq!(s.robots.get(robot).unwrap().positions, [0.5, 3.0]);
}

#[test]
fn the_index_follows_registrations_and_removals() {
    let (mut s, ids) = scene(30, Vector3::zeros(), 3.0, 8);
    let req = SceneRequest::new(SceneKind::Clearance, ids[0]);
    let (_, rows) = ask(&mut s, 1, &req, &[]);
    let nearest = rows[0].b;
    s.remove(nearest, 1).unwrap();
    let (_, rows) = ask(&mut s, 1, &req, &[]);
    assert_ne!(rows[0].b, nearest);
    let rest: Vec<u64> = ids.iter().copied().filter(|&i| i != nearest).collect();
    check_clearance(&s, &rows, &[ids[0]], &rest);
    // A new object right next to it becomes the nearest.
    let at = s.object(ids[0]).unwrap().pose * Isometry3::translation(0.0, 0.0, 0.0);
    let close = s
        .insert(
            NewObject {
                shape: Convex::sphere(0.01).unwrap().into(),
                pose: at,
                name: None,
            },
            Owner::Client(1),
        )
        .unwrap();
    let (_, rows) = ask(&mut s, 1, &req, &[]);
    let mut now = rest;
    now.push(close);
    check_clearance(&s, &rows, &[ids[0]], &now);
    assert_eq!(rows[0].result.lower, 0.0);
}

#[test]
fn overlapping_pairs_stay_within_by_their_penetration() {
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
    let (mover, other) = (ball(0.0), ball(0.8));
    // Overlapping by 0.2 and moving 0.01 a step towards separation: the
    // first steps are decided by the penetration bound; the last ones,
    // separated, are not within 0.
    let mut path = Vec::new();
    for i in 0..30 {
        let p = Isometry3::translation(-0.01 * f64::from(i), 0.0, 0.0);
        path.push(Item::set_pose(ObjectId::from_raw(mover), &p));
        path.push(Item::step());
    }
    let mut req = SceneRequest::new(SceneKind::Within, mover);
    req.path = PathMode::EveryStep as u32;
    let (reply, rows) = ask(&mut s, 1, &req, &path);
    assert!(reply.bounded > 0, "{reply:?}");
    // Centres 0.8 + 0.01 i apart, radii 0.5 each: within 0 up to i = 20.
    let steps: Vec<u32> = rows.iter().map(|r| r.step).collect();
    assert_eq!(steps, (0..=20).collect::<Vec<u32>>());
    assert!(rows.iter().all(|r| r.b == other && r.result.lower == 0.0));
    assert!(
        rows.iter()
            .any(|r| r.result.status == Status::Bounded as u32 && r.result.upper == 0.0)
    );
}

#[test]
fn departed_clients_nearest_objects_are_forgotten() {
    let (mut s, ids) = scene(30, Vector3::zeros(), 3.0, 8);
    let req = SceneRequest::new(SceneKind::Clearance, ids[0]);
    let (_, first) = ask(&mut s, 1, &req, &[]);
    let (_, second) = ask(&mut s, 2, &req, &[]);
    let remembered = |s: &State, client: u128| s.groups.nearest.get(&(client, ids[0])).copied();
    assert_eq!(remembered(&s, 1), Some(first[0].b));
    assert_eq!(remembered(&s, 2), Some(second[0].b));
    s.retain_clients(|c| c == 2);
    assert_eq!(remembered(&s, 1), None);
    assert_eq!(remembered(&s, 2), Some(second[0].b));
    // The one who stays still gets the same answer.
    let (_, again) = ask(&mut s, 2, &req, &[]);
    assert_eq!(again[0].b, second[0].b);
    assert_eq!(again[0].result.upper, second[0].result.upper);
}

/// The arm's pairs that are not allowed: l0 and l2 (l1 touches both), and
/// each link with the obstacle.
fn arm_pairs(links: &[u64], obstacle: u64) -> Vec<(u64, u64)> {
    let mut pairs = vec![(links[0], links[2])];
    pairs.extend(links.iter().map(|&l| (l, obstacle)));
    pairs
}

#[test]
fn self_pairs_add_the_groups_own_pairs_but_the_allowed_ones() {
    let (mut s, robot, links, obstacle) = arm_state();
    let margin = 0.05;
    let mut own = SceneRequest::new(SceneKind::Within, robot);
    own.margin = margin;
    own.flags |= scene_flags::SELF_PAIRS;
    let mut rest = own;
    rest.flags &= !scene_flags::SELF_PAIRS;
    let key = |a: u64, b: u64| (a.min(b), a.max(b));
    let mut folded = 0;
    // Straight, folded back over l0 both ways, and bent towards the
    // obstacle: the reported pairs are those brute force finds within the
    // margin, the arm's own ones only when asked for.
    for q in [[0.0, 0.0], [0.0, 3.0], [0.0, -3.0], [0.6, 2.95], [0.8, 0.6]] {
        let set = Item::set_joints(ObjectId::from_raw(robot), 0, &q, None, false);
        let (_, with_own) = ask(&mut s, 1, &own, &[set]);
        let (_, without) = ask(&mut s, 1, &rest, &[]);
        check_within(&s, &with_own, &arm_pairs(&links, obstacle), margin);
        let own_rows: Vec<_> = with_own.iter().map(|r| key(r.a, r.b)).collect();
        let rest_rows: Vec<_> = without.iter().map(|r| key(r.a, r.b)).collect();
        let self_row = key(links[0], links[2]);
        assert!(!rest_rows.contains(&self_row), "{q:?}: {rest_rows:?}");
        let expected: Vec<_> = own_rows
            .iter()
            .copied()
            .filter(|&p| p != self_row)
            .collect();
        assert_eq!(rest_rows, expected, "{q:?}");
        let e = exact(&s, links[0], links[2]);
        if e.upper <= margin {
            folded += 1;
            assert!(own_rows.contains(&self_row), "{q:?}: {own_rows:?}");
        }
    }
    assert!(
        folded >= 2,
        "the folded configurations must bring l2 onto l0"
    );
    // Along a path that folds the arm (the obstacle moved out of its way),
    // the first hit is the first step at which l2 comes within the margin
    // of l0 (brute force at each step).
    let away = Item::set_pose(
        ObjectId::from_raw(obstacle),
        &Isometry3::translation(10.0, 0.0, 0.0),
    );
    ask(&mut s, 1, &rest, &[away]);
    let mut path = Vec::new();
    let mut first = None;
    let kin = s.robots.get(robot).unwrap().kinematics.clone();
    for i in 0..=30 {
        let q = [0.0, 0.1 * f64::from(i)];
        path.push(Item::set_joints(
            ObjectId::from_raw(robot),
            0,
            &q,
            None,
            false,
        ));
        path.push(Item::step());
        let fk = kin
            .link_poses(&Isometry3::identity(), &q, gjkd_model::LimitMode::Reject)
            .unwrap();
        let (o0, o2) = (s.object(links[0]).unwrap(), s.object(links[2]).unwrap());
        let d = gjk::distance(
            &o0.shape,
            &fk[0],
            &o2.shape,
            &fk[2],
            &Default::default(),
            None,
        )
        .unwrap();
        if first.is_none() && d.upper <= margin {
            first = Some(i);
        }
    }
    let first = first.expect("the fold reaches l0");
    // Clearance with the group's own pairs, folded: l0's and l2's nearest
    // is each other (l1 is adjacent to both), l1's the obstacle far away.
    let mut clear = SceneRequest::new(SceneKind::Clearance, robot);
    clear.flags |= scene_flags::SELF_PAIRS;
    let fold = Item::set_joints(ObjectId::from_raw(robot), 0, &[0.0, 2.5], None, false);
    let (_, rows) = ask(&mut s, 1, &clear, &[fold]);
    let nearest: Vec<u64> = rows.iter().map(|r| r.b).collect();
    assert_eq!(nearest, vec![links[2], obstacle, links[0]], "{rows:?}");
    check_clearance_rows(&s, &rows);
    clear.flags &= !scene_flags::SELF_PAIRS;
    let (_, rows) = ask(&mut s, 1, &clear, &[]);
    assert!(rows.iter().all(|r| r.b == obstacle), "{rows:?}");
    let mut hit = own;
    hit.path = PathMode::FirstHit as u32;
    let (reply, rows) = ask(&mut s, 1, &hit, &path);
    assert_eq!(reply.first_hit, first);
    assert!(
        rows.iter()
            .any(|r| key(r.a, r.b) == key(links[0], links[2]))
    );
    hit.flags &= !scene_flags::SELF_PAIRS;
    let (reply, _) = ask(&mut s, 1, &hit, &path);
    assert_eq!(
        reply.first_hit,
        u32::MAX,
        "without self pairs the fold is no hit"
    );
}

/// Each clearance row's interval holds the exact distance of its pair.
fn check_clearance_rows(s: &State, rows: &[SceneRow]) {
    for row in rows {
        let e = exact(s, row.a, row.b);
        assert!(
            overlaps(row.result.lower, row.result.upper, &e),
            "{row:?} {e:?}"
        );
    }
}
