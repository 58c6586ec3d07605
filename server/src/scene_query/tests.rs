//! The scene engine against brute force: every pair asked exactly with
//! gjk, no broadphase, no cache.

use gjk::{Compound, Convex, Shape};
use gjkd_proto::{
    ErrorCode, Item, ObjectId, PathMode, SceneKind, SceneReply, SceneRequest, SceneRow, Status,
    WaitMode, scene_flags, scene_reply_flags,
};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use proptest::prelude::*;

use crate::robots::{NewRobot, attach};
use crate::state::{Limits, NewObject, Owner, State};

/// A small deterministic generator, so that scenes are the same run to run.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }

    fn rotation(&mut self) -> UnitQuaternion<f64> {
        let axis = Vector3::new(
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
        );
        UnitQuaternion::from_scaled_axis(axis * 3.0)
    }

    fn pose(&mut self, centre: &Vector3<f64>, spread: f64) -> Isometry3<f64> {
        let t = centre
            + Vector3::new(
                self.range(-spread, spread),
                self.range(-spread, spread),
                self.range(-spread, spread),
            );
        Isometry3::from_parts(Translation3::from(t), self.rotation())
    }
}

/// One shape of each kind the store holds, picked by `i`.
fn shape(i: usize, rng: &mut Lcg) -> Shape {
    let s = rng.range(0.2, 0.8);
    match i % 6 {
        0 => Convex::cuboid(Vector3::new(s, 0.5 * s, 0.3), 0.0)
            .unwrap()
            .into(),
        1 => Convex::sphere(s).unwrap().into(),
        2 => Convex::capsule(Point3::new(-s, 0.0, 0.0), Point3::new(s, 0.0, 0.0), 0.1)
            .unwrap()
            .into(),
        3 => {
            let n = 8 + (rng.next() * 56.0) as usize;
            let v: Vec<Point3<f64>> = (0..n)
                .map(|_| {
                    Point3::new(
                        rng.range(-s, s) + 0.3,
                        rng.range(-s, s),
                        rng.range(-s, s) - 0.2,
                    )
                })
                .collect();
            Convex::new(v, 0.0).unwrap().into()
        }
        4 => Convex::cylinder(0.3 * s, s, 0.02).unwrap().into(),
        _ => Shape::Compound(
            Compound::new(vec![
                (
                    Isometry3::translation(-s, 0.0, 0.0),
                    Convex::sphere(0.2).unwrap(),
                ),
                (
                    Isometry3::translation(s, 0.2, 0.0),
                    Convex::cuboid(Vector3::new(0.2, 0.1, 0.3), 0.05).unwrap(),
                ),
            ])
            .unwrap(),
        ),
    }
}

/// A state with `n` objects scattered in a cube of half-side `spread`
/// about `centre`; returns their ids.
fn scene(n: usize, centre: Vector3<f64>, spread: f64, seed: u64) -> (State, Vec<u64>) {
    let mut s = State::new(Limits::default(), WaitMode::Spin, 3);
    let mut rng = Lcg(seed);
    let ids = (0..n)
        .map(|i| {
            let new = NewObject {
                shape: shape(i, &mut rng),
                pose: rng.pose(&centre, spread),
                name: None,
            };
            s.insert(new, Owner::Client(1)).unwrap()
        })
        .collect();
    (s, ids)
}

/// The exact answer of a pair at the stored poses.
fn exact(s: &State, a: u64, b: u64) -> gjk::Answer {
    let (oa, ob) = (s.object(a).unwrap(), s.object(b).unwrap());
    let options = gjk::Options {
        warm_start: false,
        ..Default::default()
    };
    gjk::distance(&oa.shape, &oa.pose, &ob.shape, &ob.pose, &options, None).unwrap()
}

fn overlaps(lower: f64, upper: f64, e: &gjk::Answer) -> bool {
    lower <= e.upper && e.lower <= upper
}

fn members(ids: &[u64]) -> Vec<Item> {
    ids.iter()
        .map(|&id| Item::member(ObjectId::from_raw(id)))
        .collect()
}

fn ask(
    s: &mut State,
    client: u128,
    request: &SceneRequest,
    items: &[Item],
) -> (SceneReply, Vec<SceneRow>) {
    let mut rows = vec![SceneRow::default(); 4096];
    let reply = s.scene(client, request, items, &mut rows);
    assert_eq!(reply.error_code(), ErrorCode::Ok, "{request:?}");
    rows.truncate(reply.total.min(4096) as usize);
    (reply, rows)
}

/// Checks a within answer against brute force over `pairs`.
fn check_within(s: &State, rows: &[SceneRow], pairs: &[(u64, u64)], margin: f64) {
    for row in rows {
        let e = exact(s, row.a, row.b);
        assert!(
            overlaps(row.result.lower, row.result.upper, &e),
            "{row:?} excludes {e:?}"
        );
        // An interval accepted from motion bounds is reported when it
        // reaches below the margin: the pair may lie beyond by its width.
        let reach = if row.result.status == Status::Bounded as u32 {
            row.result.lower
        } else {
            e.lower
        };
        assert!(reach <= margin, "{row:?} is not within {margin}: {e:?}");
    }
    for &(a, b) in pairs {
        let e = exact(s, a, b);
        let found = rows
            .iter()
            .any(|r| (r.a, r.b) == (a, b) || (r.a, r.b) == (b, a));
        if e.upper <= margin {
            assert!(found, "missed ({a:#x}, {b:#x}) at {}", e.distance);
        }
    }
}

/// Checks a clearance answer against brute force over non-members.
fn check_clearance(s: &State, rows: &[SceneRow], group: &[u64], all: &[u64]) {
    assert_eq!(rows.len(), group.len());
    for (row, &a) in rows.iter().zip(group) {
        assert_eq!(row.a, a);
        let best = all
            .iter()
            .filter(|b| !group.contains(b))
            .map(|&b| exact(s, a, b))
            .min_by(|x, y| x.distance.total_cmp(&y.distance))
            .unwrap();
        assert!(
            overlaps(row.result.lower, row.result.upper, &best),
            "{row:?} misses the nearest {best:?}"
        );
        let e = exact(s, a, row.b);
        assert!(
            overlaps(row.result.lower, row.result.upper, &e),
            "{row:?} excludes {e:?}"
        );
    }
}

fn group_pairs(group: &[u64], all: &[u64]) -> Vec<(u64, u64)> {
    let mut pairs = Vec::new();
    for &a in group {
        for &b in all.iter().filter(|b| !group.contains(b)) {
            pairs.push((a, b));
        }
    }
    pairs
}

fn all_pairs(all: &[u64]) -> Vec<(u64, u64)> {
    let mut pairs = Vec::new();
    for (i, &a) in all.iter().enumerate() {
        for &b in &all[i + 1..] {
            pairs.push((a, b));
        }
    }
    pairs
}

#[test]
fn within_and_clearance_match_brute_force() {
    for seed in 1..4 {
        let (mut s, ids) = scene(120, Vector3::zeros(), 6.0, seed);
        let group = &ids[..5];
        let margin = 1.0;
        let mut req = SceneRequest::new(SceneKind::Within, 0);
        req.margin = margin;
        let (reply, rows) = ask(&mut s, 1, &req, &members(group));
        assert!(reply.candidates < (group.len() * (ids.len() - group.len())) as u64);
        check_within(&s, &rows, &group_pairs(group, &ids), margin);
        req.flags |= scene_flags::ALL_PAIRS;
        let (_, rows) = ask(&mut s, 1, &req, &[]);
        check_within(&s, &rows, &all_pairs(&ids), margin);
        let req = SceneRequest::new(SceneKind::Clearance, 0);
        let (reply, rows) = ask(&mut s, 1, &req, &members(group));
        assert_eq!(reply.steps, 1);
        check_clearance(&s, &rows, group, &ids);
    }
}

#[test]
fn nearest_k_match_brute_force() {
    let (mut s, ids) = scene(80, Vector3::zeros(), 5.0, 9);
    let a = ids[7];
    let mut req = SceneRequest::new(SceneKind::Nearest, a);
    req.k = 6;
    let (_, rows) = ask(&mut s, 1, &req, &[]);
    let mut brute: Vec<gjk::Answer> = ids
        .iter()
        .filter(|&&b| b != a)
        .map(|&b| exact(&s, a, b))
        .collect();
    brute.sort_by(|x, y| x.distance.total_cmp(&y.distance));
    assert_eq!(rows.len(), 6);
    for (row, e) in rows.iter().zip(&brute) {
        assert!(
            overlaps(row.result.lower, row.result.upper, e),
            "{row:?} vs {e:?}"
        );
    }
    // With a cut-off nearer than the third, at most the two nearest.
    req.flags |= scene_flags::CUTOFF;
    req.margin = 0.5 * (brute[1].distance + brute[2].distance);
    let (_, rows) = ask(&mut s, 1, &req, &[]);
    assert_eq!(rows.len(), 2);
}

#[test]
fn truncated_answers_count_every_row() {
    let (mut s, ids) = scene(60, Vector3::zeros(), 3.0, 4);
    let mut req = SceneRequest::new(SceneKind::Within, 0);
    req.margin = 2.0;
    req.flags |= scene_flags::ALL_PAIRS;
    let (full, _) = ask(&mut s, 1, &req, &[]);
    assert!(full.total > 3 && full.flags & scene_reply_flags::TRUNCATED == 0);
    let mut rows = [SceneRow::default(); 3];
    let reply = s.scene(1, &req, &[], &mut rows);
    assert_eq!(reply.total, full.total);
    assert_ne!(reply.flags & scene_reply_flags::TRUNCATED, 0);
    assert!(rows.iter().all(|r| ids.contains(&r.a)));
}

/// One motion of the group between two steps.
#[derive(Clone, Debug)]
enum Motion {
    /// A small move and turn.
    Nudge([f64; 3], [f64; 3]),
    /// A fast rotation about the object's place.
    Spin([f64; 3]),
    /// A jump anywhere in the scene.
    Teleport([f64; 3], [f64; 3]),
}

fn motion() -> impl Strategy<Value = Motion> {
    let v = |r: f64| prop::array::uniform3(-r..r);
    prop_oneof![
        3 => (v(0.05), v(0.05)).prop_map(|(t, r)| Motion::Nudge(t, r)),
        1 => v(3.0).prop_map(Motion::Spin),
        1 => (v(4.0), v(3.0)).prop_map(|(t, r)| Motion::Teleport(t, r)),
    ]
}

fn moved(pose: &Isometry3<f64>, m: &Motion, centre: &Vector3<f64>) -> Isometry3<f64> {
    let rot = |r: &[f64; 3]| UnitQuaternion::from_scaled_axis(Vector3::from(*r));
    match m {
        Motion::Nudge(t, r) => Isometry3::from_parts(
            Translation3::from(pose.translation.vector + Vector3::from(*t)),
            rot(r) * pose.rotation,
        ),
        Motion::Spin(r) => Isometry3::from_parts(pose.translation, rot(r) * pose.rotation),
        Motion::Teleport(t, r) => {
            Isometry3::from_parts(Translation3::from(centre + Vector3::from(*t)), rot(r))
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Along random motions, near and far from the origin, with motion
    /// bounds and an accepted accuracy: no pair within the margin is
    /// missed, every interval holds the exact distance, every clearance is
    /// the nearest.
    #[test]
    fn motions_keep_every_answer_certified(
        far in prop::bool::ANY,
        seed in 1u64..1000,
        motions in prop::collection::vec(motion(), 1..12),
        accept in prop_oneof![Just(0.0), Just(1e-3), Just(0.05)],
    ) {
        let centre = if far { Vector3::new(1e6, -1e6, 5e5) } else { Vector3::zeros() };
        let (mut s, ids) = scene(40, centre, 4.0, seed);
        let group = ids[..3].to_vec();
        let margin = 0.6;
        let mut within = SceneRequest::new(SceneKind::Within, 0);
        within.margin = margin;
        within.accept_absolute = accept;
        let mut clearance = SceneRequest::new(SceneKind::Clearance, 0);
        clearance.accept_relative = accept;
        let group_items = members(&group);
        for m in &motions {
            let mut items = group_items.clone();
            for &id in &group {
                let pose = moved(&s.object(id).unwrap().pose, m, &centre);
                items.push(Item::set_pose(ObjectId::from_raw(id), &pose));
            }
            let (_, rows) = ask(&mut s, 1, &within, &items);
            check_within(&s, &rows, &group_pairs(&group, &ids), margin);
            let (_, rows) = ask(&mut s, 1, &clearance, &group_items);
            check_clearance(&s, &rows, &group, &ids);
        }
    }
}

#[test]
fn motion_bounds_answer_small_moves_without_gjk() {
    let (mut s, ids) = scene(50, Vector3::zeros(), 5.0, 21);
    let group = &ids[..3];
    let mut req = SceneRequest::new(SceneKind::Clearance, 0);
    req.accept_absolute = 0.05;
    let items = members(group);
    let (first, _) = ask(&mut s, 1, &req, &items);
    assert!(first.gjk_runs > 0);
    let mut bounded_rows = 0;
    for step in 1..20 {
        let mut step_items = items.clone();
        for &id in group {
            let p = s.object(id).unwrap().pose;
            let p = Isometry3::translation(1e-4 * f64::from(step), 0.0, 0.0) * p;
            step_items.push(Item::set_pose(ObjectId::from_raw(id), &p));
        }
        let (reply, rows) = ask(&mut s, 1, &req, &step_items);
        assert!(reply.bounded > 0, "step {step}: {reply:?}");
        check_clearance(&s, &rows, group, &ids);
        bounded_rows += rows
            .iter()
            .filter(|r| r.result.status == Status::Bounded as u32)
            .count();
    }
    assert!(bounded_rows > 0);
    // Without MOTION_BOUNDS every candidate runs GJK.
    req.flags &= !scene_flags::MOTION_BOUNDS;
    let (reply, _) = ask(&mut s, 1, &req, &items);
    assert_eq!(reply.bounded, 0);
    assert!(reply.gjk_runs > 0);
}

/// Stored poses of every object.
fn poses(s: &State, ids: &[u64]) -> Vec<Isometry3<f64>> {
    ids.iter().map(|&id| s.object(id).unwrap().pose).collect()
}

#[test]
fn paths_leave_the_store_alone_and_clients_keep_their_own_bounds() {
    let (mut s, ids) = scene(60, Vector3::zeros(), 5.0, 33);
    let mover = ids[0];
    let before = poses(&s, &ids);
    // Client 1 sweeps the mover along a path; client 2 asks at the stored
    // poses, with motion bounds and a generous accepted accuracy: its
    // answers must hold at the stored poses, not at client 1's.
    let mut path = Vec::new();
    let mut rng = Lcg(5);
    for _ in 0..30 {
        let p = rng.pose(&Vector3::zeros(), 5.0);
        path.push(Item::set_pose(ObjectId::from_raw(mover), &p));
        path.push(Item::step());
    }
    let mut req = SceneRequest::new(SceneKind::Clearance, mover);
    req.path = PathMode::EveryStep as u32;
    req.accept_absolute = 10.0;
    let (reply, rows) = ask(&mut s, 1, &req, &path);
    assert_eq!((reply.steps, rows.len()), (30, 30));
    assert!(rows.iter().enumerate().all(|(i, r)| r.step == i as u32));
    assert_eq!(poses(&s, &ids), before);
    let mut single = SceneRequest::new(SceneKind::Clearance, mover);
    single.accept_absolute = 10.0;
    for client in [2, 1] {
        let (_, rows) = ask(&mut s, client, &single, &[]);
        check_clearance(&s, &rows, &[mover], &ids);
    }
    // Each step of the path answered at that step's pose: the last one
    // equals a single question there.
    let mut within = SceneRequest::new(SceneKind::Within, mover);
    within.margin = 1.0;
    within.path = PathMode::EveryStep as u32;
    let (_, rows) = ask(&mut s, 3, &within, &path);
    let last: Vec<(u64, u64)> = rows
        .iter()
        .filter(|r| r.step == 29)
        .map(|r| (r.a, r.b))
        .collect();
    let mut at_end = path[58];
    at_end.kind = gjkd_proto::ItemKind::SetPose as u32;
    within.path = PathMode::Single as u32;
    let (_, rows) = ask(&mut s, 4, &within, &[at_end]);
    let mut single_pairs: Vec<(u64, u64)> = rows.iter().map(|r| (r.a, r.b)).collect();
    let mut last = last;
    last.sort_unstable();
    single_pairs.sort_unstable();
    assert_eq!(last, single_pairs);
}

#[test]
fn a_pose_flagged_to_end_its_step_is_a_step_item_after_it() {
    let (mut s, ids) = scene(60, Vector3::zeros(), 5.0, 33);
    let (mover, other) = (ids[0], ids[1]);
    let mut rng = Lcg(8);
    let (mut with_items, mut with_flags) = (Vec::new(), Vec::new());
    for _ in 0..25 {
        // Two objects move per step: the flag is on the step's last pose.
        let p = rng.pose(&Vector3::zeros(), 5.0);
        let q = rng.pose(&Vector3::zeros(), 5.0);
        let (first, last) = (
            Item::set_pose(ObjectId::from_raw(mover), &p),
            Item::set_pose(ObjectId::from_raw(other), &q),
        );
        with_items.extend([first, last, Item::step()]);
        with_flags.extend([first, last.ending_step()]);
    }
    let mut req = SceneRequest::new(SceneKind::Within, 0);
    req.path = PathMode::EveryStep as u32;
    req.margin = 1.0;
    let members = [mover, other].map(|id| Item::member(ObjectId::from_raw(id)));
    let ask_path = |s: &mut State, client, steps: &[Item]| {
        let items: Vec<Item> = members.iter().chain(steps).copied().collect();
        ask(s, client, &req, &items)
    };
    // Separate clients, so that neither starts from the other's caches.
    let (reply, rows) = ask_path(&mut s, 1, &with_items);
    let (flagged, flagged_rows) = ask_path(&mut s, 2, &with_flags);
    assert_eq!(reply.error, ErrorCode::Ok as u32);
    assert_eq!((reply.steps, flagged.steps), (25, 25));
    assert!(!rows.is_empty());
    let key = |r: &SceneRow| (r.a, r.b, r.step, r.result.lower, r.result.upper);
    assert_eq!(
        rows.iter().map(key).collect::<Vec<_>>(),
        flagged_rows.iter().map(key).collect::<Vec<_>>()
    );
}

#[test]
fn first_hit_stops_at_the_first_step_within_the_margin() {
    let mut s = State::new(Limits::default(), WaitMode::Spin, 3);
    let ball = |s: &mut State, x: f64| {
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
    let mover = ball(&mut s, 0.0);
    let wall = ball(&mut s, 10.0);
    let mut path = Vec::new();
    for i in 0..10 {
        let p = Isometry3::translation(f64::from(i), 0.0, 0.0);
        path.push(Item::set_pose(ObjectId::from_raw(mover), &p));
        path.push(Item::step());
    }
    let mut req = SceneRequest::new(SceneKind::Within, mover);
    req.path = PathMode::FirstHit as u32;
    req.margin = 1.5;
    let (reply, rows) = ask(&mut s, 1, &req, &path);
    // Centres 10 - i apart, radii 0.5 each: within 1.5 from i = 8 on.
    assert_eq!((reply.first_hit, reply.steps), (8, 9));
    assert_eq!(rows.len(), 1);
    assert_eq!((rows[0].b, rows[0].step), (wall, 8));
    assert!((rows[0].result.distance - 1.0).abs() < 1e-9);
    // At margin 0.5 only the last step (touching) hits; without it, none.
    req.margin = 0.5;
    let (reply, rows) = ask(&mut s, 1, &req, &path);
    assert_eq!((reply.first_hit, reply.steps, rows.len()), (9, 10, 1));
    let (reply, rows) = ask(&mut s, 1, &req, &path[..18]);
    assert_eq!((reply.first_hit, reply.steps, rows.len()), (u32::MAX, 9, 0));
}

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

fn arm_state() -> (State, u64, Vec<u64>, u64) {
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
    let robot = attach(
        &mut s,
        NewRobot {
            name: "arm",
            urdf: ARM,
            srdf: None,
            base: Isometry3::identity(),
            positions: None,
            owner: Owner::Client(1),
        },
    )
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
    reserved.reserved = 1;
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
    let remembered = |s: &State, client: u128| s.scene.nearest.get(&(client, ids[0])).copied();
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
    for x in [0.0, 1e308, -1e308, 1.5, 1.6] {
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
