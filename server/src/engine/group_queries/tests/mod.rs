//! The group queries against brute force: every pair asked exactly with
//! gjk, no broadphase, no cache.

use gjk::{Compound, Convex, Shape};
use gjkd_proto::{
    ErrorCode, Item, ObjectId, PathMode, SceneKind, SceneReply, SceneRequest, SceneRow, Status,
    WaitMode, scene_flags, scene_reply_flags,
};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use proptest::prelude::*;

use crate::engine::robots::NewRobot;
use crate::engine::state::{Limits, NewObject, Owner, State};

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

mod continuous;
mod paths;
mod robots_and_refusals;
