//! Distance gradients of the pair query and the scene rows against
//! central finite differences of an independent distance (the brute-force
//! exact distance between the shapes' hulls, no GJK) moved by the model
//! crate's forward kinematics: the vendored Panda and UR5 and the model
//! tests' hand-written arm (prismatic, continuous, fixed and mimic joints),
//! on random configurations; a free object's twist; self-collision rows;
//! path rows at each step's configuration.

#[path = "../../model/tests/files.rs"]
mod files;

use files::Rng;
use gjk::{Convex, Shape};
use gjkd_model::{LimitMode, PackagePath, RobotModel};
use gjkd_proto::{
    Gradient, GradientRow, Item, ItemResult, ObjectId, PathMode, QueryOptions, SceneKind,
    SceneRequest, SceneRow, WaitMode, gradient_flags, item_flags, scene_flags,
};
use gjkd_server::engine::robots::NewRobot;
use gjkd_server::engine::state::{Limits, NewObject, Owner, State};
use gjkd_testkit::reference::{Hull, distance};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// Central-difference step.
const H: f64 = 1e-6;
/// The relative error judged.
const RELATIVE: f64 = 1e-6;

/// One convex piece for the reference: its hull, its offset in the object
/// frame and its rounding.
struct Piece {
    hull: Hull,
    offset: Isometry3<f64>,
    radius: f64,
}

fn pieces(shape: &Shape) -> Vec<Piece> {
    let piece = |offset: Isometry3<f64>, c: &Convex| Piece {
        hull: Hull::new(c.vertices()),
        offset,
        radius: c.radius(),
    };
    match shape {
        Shape::Convex(c) => vec![piece(Isometry3::identity(), c)],
        Shape::Compound(c) => c.pieces().iter().map(|(o, c)| piece(*o, c)).collect(),
    }
}

/// The reference distance between two objects' pieces at their poses.
fn reference(a: &[Piece], pose_a: &Isometry3<f64>, b: &[Piece], pose_b: &Isometry3<f64>) -> f64 {
    let mut best = f64::INFINITY;
    for pa in a {
        for pb in b {
            let d = distance(
                &pa.hull,
                &(pose_a * pa.offset),
                pa.radius,
                &pb.hull,
                &(pose_b * pb.offset),
                pb.radius,
            );
            best = best.min(d.distance);
        }
    }
    best
}

/// A robot in a fresh state, with obstacles around its reach.
struct Scene {
    state: State,
    model: RobotModel,
    robot: u64,
    /// Per link, its object id (links without shape have none).
    links: Vec<Option<u64>>,
    obstacles: Vec<(u64, Isometry3<f64>, Vec<Piece>)>,
}

fn scene(model: RobotModel, base: Isometry3<f64>, rng: &mut Rng, reach: f64) -> Scene {
    let mut state = State::new(Limits::default(), WaitMode::Spin, 7);
    let name = model.name().to_owned();
    let mut links = Vec::new();
    for link in &model.links {
        match &link.shape {
            Some(shape) => {
                let id = state
                    .insert(
                        NewObject {
                            shape: shape.clone(),
                            pose: Isometry3::identity(),
                            name: Some(format!("{name}/{}", link.name)),
                        },
                        Owner::Client(1),
                    )
                    .unwrap();
                links.push(Some(id));
            }
            None => links.push(None),
        }
    }
    let urdf = model_urdf(&model);
    let robot = state
        .attach_robot(NewRobot {
            name: &name,
            urdf: &urdf,
            srdf: None,
            base,
            positions: None,
            owner: Owner::Client(1),
        })
        .unwrap();
    let mut obstacles = Vec::new();
    for i in 0..4 {
        let size = rng.uniform(0.03, 0.1);
        let shape: Shape = match i % 3 {
            0 => Convex::cuboid(Vector3::new(size, 0.7 * size, 0.4 * size), 0.0)
                .unwrap()
                .into(),
            1 => Convex::sphere(size).unwrap().into(),
            _ => Convex::capsule(
                Point3::new(-size, 0.0, 0.0),
                Point3::new(size, 0.0, 0.0),
                0.02,
            )
            .unwrap()
            .into(),
        };
        let axis = Vector3::new(
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        );
        let pose = Isometry3::from_parts(
            Translation3::from(
                base.translation.vector
                    + Vector3::new(
                        rng.uniform(-reach, reach),
                        rng.uniform(-reach, reach),
                        rng.uniform(0.0, reach),
                    ),
            ),
            UnitQuaternion::from_scaled_axis(axis),
        );
        let id = state
            .insert(
                NewObject {
                    shape: shape.clone(),
                    pose,
                    name: None,
                },
                Owner::Client(1),
            )
            .unwrap();
        obstacles.push((id, pose, pieces(&shape)));
    }
    Scene {
        state,
        model,
        robot,
        links,
        obstacles,
    }
}

thread_local! {
    static URDFS: std::cell::RefCell<Vec<(String, String)>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The URDF text a model was read from (kept by [`load`]).
fn model_urdf(model: &RobotModel) -> String {
    URDFS.with(|u| {
        u.borrow()
            .iter()
            .find(|(n, _)| n == model.name())
            .map(|(_, t)| t.clone())
            .unwrap()
    })
}

fn load(path: &std::path::Path, packages: &PackagePath) -> RobotModel {
    let text = std::fs::read_to_string(path).unwrap();
    let model = RobotModel::from_urdf_str(&text, path.parent(), packages).unwrap();
    URDFS.with(|u| u.borrow_mut().push((model.name().to_owned(), text)));
    model
}

fn random_positions(model: &RobotModel, rng: &mut Rng) -> Vec<f64> {
    model
        .kinematics
        .moving_joints()
        .map(|j| {
            let lo = j.lower.max(-std::f64::consts::PI) + 10.0 * H;
            let hi = j.upper.min(std::f64::consts::PI) - 10.0 * H;
            rng.uniform(lo, hi)
        })
        .collect()
}

fn set_joints(s: &mut Scene, q: &[f64], base: &Isometry3<f64>) {
    let robot = ObjectId::from_raw(s.robot);
    let mut items = Vec::new();
    for (k, chunk) in q.chunks(gjkd_proto::JOINTS_PER_ITEM).enumerate() {
        let first = (k * gjkd_proto::JOINTS_PER_ITEM) as u32;
        items.push(Item::set_joints(robot, first, chunk, Some(base), false));
    }
    let mut results = vec![ItemResult::default(); items.len()];
    s.state.handle(1, &items, &mut results);
    assert!(results.iter().all(|r| r.error == 0), "{results:?}");
}

/// A pair's result with the gradient that travels apart from it.
#[derive(Debug)]
struct WithGradient {
    result: ItemResult,
    gradient: Gradient,
}

impl std::ops::Deref for WithGradient {
    type Target = ItemResult;
    fn deref(&self) -> &ItemResult {
        &self.result
    }
}

fn pair_with_gradient(s: &mut State, a: u64, b: u64, base: bool) -> WithGradient {
    let mut item = Item::distance(
        ObjectId::from_raw(a),
        ObjectId::from_raw(b),
        &QueryOptions::cold(),
    );
    item.flags |= item_flags::GRADIENT;
    if base {
        item.flags |= item_flags::GRADIENT_BASE;
    }
    let mut out = [ItemResult::default()];
    let mut rows = [GradientRow::default()];
    s.handle_with_gradients(1, &[item], &mut out, &mut rows);
    assert_eq!(out[0].error, 0, "{:?}", out[0]);
    assert_eq!(rows[0].item, 0);
    WithGradient {
        result: out[0],
        gradient: rows[0].gradient,
    }
}

/// Twisted pose: `Translation(c + v) · Rotation(ω) · Translation(−c) · pose`.
fn twisted(pose: &Isometry3<f64>, twist: &[f64; 6]) -> Isometry3<f64> {
    let c = pose.translation.vector;
    Translation3::from(c + Vector3::new(twist[0], twist[1], twist[2]))
        * UnitQuaternion::from_scaled_axis(Vector3::new(twist[3], twist[4], twist[5]))
        * Translation3::from(-c)
        * pose
}

/// Compares a gradient against its finite differences; returns whether it
/// was judged (the distance positive and the witness unique).
fn judge(got: &WithGradient, want: &[f64], what: &str) -> bool {
    let g = got.gradient;
    assert!(g.is_present(), "{what}");
    assert_eq!(g.as_slice().len(), want.len(), "{what}");
    if got.distance <= 1e-6 || g.is_not_unique() {
        return false;
    }
    let norm = want.iter().map(|x| x * x).sum::<f64>().sqrt();
    let error = g
        .as_slice()
        .iter()
        .zip(want)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt();
    // The differences' own round-off, about 1e-16 · d / H, is the floor.
    assert!(
        error <= RELATIVE * norm + 1e-9,
        "{what}: {:?} against {want:?} (error {error:e}, stated bound {:e})",
        g.as_slice(),
        g.error
    );
    // The stated bound is about the normal's error alone; it must still
    // be a number.
    assert!(g.error.is_finite() && g.error >= 0.0, "{what}");
    true
}

/// For random configurations and bases: every link–obstacle pair's
/// gradient (joints, then base twist) against finite differences of the
/// reference distance; each obstacle's twist gradient; self-collision
/// pairs of non-adjacent links; returns how many gradients were judged.
fn check_robot(model: RobotModel, seed: u64, reach: f64) -> usize {
    let mut rng = Rng(seed);
    let base = Isometry3::from_parts(
        Translation3::new(0.1, -0.2, 0.05),
        UnitQuaternion::from_euler_angles(0.0, 0.0, 0.3),
    );
    let mut s = scene(model, base, &mut rng, reach);
    // The links' hulls for the reference, built here: the brute force's
    // facet search over a mesh's vertices is the costly part of a scene,
    // and only the finite differences need it.
    let link_pieces: Vec<Vec<Piece>> = s
        .model
        .links
        .iter()
        .map(|l| l.shape.as_ref().map(pieces).unwrap_or_default())
        .collect();
    let kin = s.model.kinematics.clone();
    let dof = kin.dof();
    let mut judged = 0;
    for _ in 0..3 {
        let q = random_positions(&s.model, &mut rng);
        set_joints(&mut s, &q, &base);
        let poses_at =
            |q: &[f64], base: &Isometry3<f64>| kin.link_poses(base, q, LimitMode::Reject).unwrap();
        let poses = poses_at(&q, &base);
        let links: Vec<(usize, u64)> = s
            .links
            .iter()
            .enumerate()
            .filter_map(|(i, l)| l.map(|id| (i, id)))
            .collect();
        for &(link, id) in &links {
            for o in 0..s.obstacles.len() {
                let (obstacle, pose_o) = (s.obstacles[o].0, s.obstacles[o].1);
                let got = pair_with_gradient(&mut s.state, id, obstacle, true);
                let lp = &link_pieces[link];
                let op = &s.obstacles[o].2;
                let mut want = Vec::with_capacity(dof + 6);
                for k in 0..dof {
                    let at = |dq: f64| {
                        let mut moved = q.clone();
                        moved[k] += dq;
                        reference(lp, &poses_at(&moved, &base)[link], op, &pose_o)
                    };
                    want.push((at(H) - at(-H)) / (2.0 * H));
                }
                for i in 0..6 {
                    let at = |t: f64| {
                        let mut twist = [0.0; 6];
                        twist[i] = t;
                        reference(
                            lp,
                            &poses_at(&q, &twisted(&base, &twist))[link],
                            op,
                            &pose_o,
                        )
                    };
                    want.push((at(H) - at(-H)) / (2.0 * H));
                }
                let what = format!(
                    "{} link {} obstacle {o}",
                    s.model.name(),
                    s.model.links[link].name
                );
                judged += usize::from(judge(&got, &want, &what));
                // The obstacle's own twist, asked the other way round.
                let got = pair_with_gradient(&mut s.state, obstacle, id, false);
                let want: Vec<f64> = (0..6)
                    .map(|i| {
                        let at = |t: f64| {
                            let mut twist = [0.0; 6];
                            twist[i] = t;
                            reference(op, &twisted(&pose_o, &twist), lp, &poses[link])
                        };
                        (at(H) - at(-H)) / (2.0 * H)
                    })
                    .collect();
                judged += usize::from(judge(&got, &want, &format!("{what}, obstacle's twist")));
            }
        }
        // Self-collision: both links move with the joints.
        let adjacent = kin.adjacent_links();
        for (i, &(la, ida)) in links.iter().enumerate() {
            for &(lb, idb) in &links[i + 1..] {
                if adjacent.contains(&(la, lb)) || adjacent.contains(&(lb, la)) {
                    continue;
                }
                let got = pair_with_gradient(&mut s.state, ida, idb, false);
                let (pa, pb) = (&link_pieces[la], &link_pieces[lb]);
                let want: Vec<f64> = (0..dof)
                    .map(|k| {
                        let at = |dq: f64| {
                            let mut moved = q.clone();
                            moved[k] += dq;
                            let p = poses_at(&moved, &base);
                            reference(pa, &p[la], pb, &p[lb])
                        };
                        (at(H) - at(-H)) / (2.0 * H)
                    })
                    .collect();
                let what = format!("{} self {la}-{lb}", s.model.name());
                judged += usize::from(judge(&got, &want, &what));
            }
        }
    }
    judged
}

fn real(name: &str) -> RobotModel {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../model/tests/data");
    let robots = data.join("example-robot-data/robots");
    let path = match name {
        "panda" => robots.join("panda_description/urdf/panda.urdf"),
        _ => robots.join("ur_description/urdf/ur5_robot.urdf"),
    };
    load(&path, &PackagePath::new([data]))
}

#[test]
fn panda_gradients_match_finite_differences_of_the_reference() {
    let judged = check_robot(real("panda"), 0xbeef, 0.6);
    assert!(judged > 50, "only {judged} gradients judged");
}

#[test]
fn ur5_gradients_match_finite_differences_of_the_reference() {
    let judged = check_robot(real("ur5"), 0xcafe, 0.7);
    assert!(judged > 30, "only {judged} gradients judged");
}

#[test]
fn test_arm_gradients_match_finite_differences_of_the_reference() {
    let dir = files::scratch("gradients-arm");
    let (urdf, packages) = files::write_arm(&dir);
    let model = load(&urdf, &PackagePath::new([packages]));
    let judged = check_robot(model, 0xa5a5, 0.3);
    assert!(judged > 20, "only {judged} gradients judged");
}

/// The scene rows carry the same gradients as the pair query, at the
/// request's configuration and at each path step's.
#[test]
fn scene_rows_carry_the_pair_query_gradients() {
    let mut rng = Rng(0x5ce9e);
    let base = Isometry3::identity();
    let mut s = scene(real("ur5"), base, &mut rng, 0.7);
    let dof = s.model.kinematics.dof();
    let configurations: Vec<Vec<f64>> = (0..3)
        .map(|_| random_positions(&s.model, &mut rng))
        .collect();
    let mut request = SceneRequest::new(SceneKind::Within, s.robot);
    request.margin = 10.0;
    request.max_rows = 256;
    request.flags = scene_flags::GRADIENTS;
    // A path: the rows of each step against the pair query at that step.
    request.path = PathMode::EveryStep as u32;
    let robot = ObjectId::from_raw(s.robot);
    let items: Vec<Item> = configurations
        .iter()
        .map(|q| Item::set_joints(robot, 0, q, None, false).ending_step())
        .collect();
    let mut rows = vec![SceneRow::default(); 256];
    let reply = s.state.scene(1, &request, &items, &mut rows);
    assert_eq!(reply.error, 0);
    let written = reply.total as usize;
    assert!(written > 10 && written <= rows.len(), "{written}");
    for (step, q) in configurations.iter().enumerate() {
        set_joints(&mut s, q, &base);
        let step_rows: Vec<&SceneRow> = rows[..written]
            .iter()
            .filter(|r| r.step == step as u32)
            .collect();
        assert!(!step_rows.is_empty());
        for row in step_rows {
            let pair = pair_with_gradient(&mut s.state, row.a, row.b, false);
            let g = row.gradient;
            assert_eq!(g.columns as usize, dof);
            assert_eq!(g.flags & gradient_flags::PRESENT, gradient_flags::PRESENT);
            for (x, y) in g.as_slice().iter().zip(pair.gradient.as_slice()) {
                assert!(
                    (x - y).abs() <= 1e-9 * (1.0 + y.abs()),
                    "step {step}: {x} against {y}: {row:?} {pair:?}"
                );
            }
        }
    }
    // A single question at the last configuration (the stored one now),
    // base twist included.
    request.path = PathMode::Single as u32;
    request.flags = scene_flags::GRADIENTS | scene_flags::GRADIENT_BASE;
    let reply = s.state.scene(1, &request, &[], &mut rows);
    assert_eq!(reply.error, 0);
    for row in &rows[..reply.total as usize] {
        let pair = pair_with_gradient(&mut s.state, row.a, row.b, true);
        assert_eq!(row.gradient.columns as usize, dof + 6);
        assert!(row.gradient.has_base());
        assert_eq!(row.gradient.as_slice(), pair.gradient.as_slice());
    }
    // Without the flag, no gradient.
    request.flags = 0;
    s.state.scene(1, &request, &[], &mut rows);
    assert!(!rows[0].gradient.is_present());
}

/// Parallel faces: a box above a box, face to face, has witness points
/// that can slide; the gradient says so and is still the one of the
/// points reported (a valid one-sided gradient: translation along the
/// normal changes the distance one for one).
#[test]
fn parallel_faces_are_flagged_not_unique() {
    let mut state = State::new(Limits::default(), WaitMode::Spin, 9);
    let cube = |state: &mut State, z: f64| {
        state
            .insert(
                NewObject {
                    shape: Convex::cuboid(Vector3::new(0.5, 0.5, 0.5), 0.0)
                        .unwrap()
                        .into(),
                    pose: Isometry3::translation(0.1, 0.0, z),
                    name: None,
                },
                Owner::Client(1),
            )
            .unwrap()
    };
    let a = cube(&mut state, 0.0);
    let b = cube(&mut state, 2.0);
    let got = pair_with_gradient(&mut state, a, b, false);
    assert!((got.distance - 1.0).abs() < 1e-12);
    let g = got.gradient;
    assert!(g.is_not_unique(), "{g:?}");
    // Moving A up closes the gap one for one.
    assert!((g.values[2] + 1.0).abs() < 1e-12, "{g:?}");
    // A ball above a box's face: unique.
    let ball = state
        .insert(
            NewObject {
                shape: Convex::sphere(0.2).unwrap().into(),
                pose: Isometry3::translation(0.0, 0.0, 2.0),
                name: None,
            },
            Owner::Client(1),
        )
        .unwrap();
    let got = pair_with_gradient(&mut state, a, ball, false);
    assert!(!got.gradient.is_not_unique(), "{:?}", got.gradient);
}

/// A pose of this query only for a link is refused with a gradient (its
/// joints do not put it there).
#[test]
fn gradients_that_cannot_be_given_are_refused() {
    let mut rng = Rng(3);
    let mut s = scene(real("ur5"), Isometry3::identity(), &mut rng, 0.5);
    let link = s.links.iter().flatten().next().copied().unwrap();
    let obstacle = s.obstacles[0].0;
    let mut item = Item::distance(
        ObjectId::from_raw(link),
        ObjectId::from_raw(obstacle),
        &QueryOptions::cold(),
    )
    .with_pose_a(&Isometry3::translation(0.0, 0.0, 3.0));
    item.flags |= item_flags::GRADIENT;
    let mut out = [ItemResult::default()];
    let mut rows = [GradientRow::default()];
    s.state
        .handle_with_gradients(1, &[item], &mut out, &mut rows);
    assert_eq!(out[0].error, gjkd_proto::ErrorCode::InvalidOptions as u32);
    assert_eq!(rows[0].gradient, Gradient::NONE);
    // Without room for its gradient, a pair that asks is refused too,
    // where the same pair without the pose is answered with room.
    item.flags &= !item_flags::POSE_A;
    s.state.handle(1, &[item], &mut out);
    assert_eq!(out[0].error, gjkd_proto::ErrorCode::InvalidOptions as u32);
    s.state
        .handle_with_gradients(1, &[item], &mut out, &mut rows);
    assert_eq!(out[0].error, 0);
    assert!(rows[0].gradient.is_present());
}

/// The gradient section holds one row per item that asks, in item order,
/// each naming its item, also for an item that failed; items that do not
/// ask take none.
#[test]
fn gradient_rows_follow_the_items_that_ask() {
    let mut rng = Rng(5);
    let mut s = scene(real("ur5"), Isometry3::identity(), &mut rng, 0.5);
    let link = s.links.iter().flatten().next().copied().unwrap();
    let obstacle = s.obstacles[0].0;
    let pair = Item::distance(
        ObjectId::from_raw(link),
        ObjectId::from_raw(obstacle),
        &QueryOptions::cold(),
    );
    let ghost = Item::distance(
        ObjectId::from_raw(link),
        ObjectId::from_raw(12345),
        &QueryOptions::cold(),
    );
    let items = [
        pair,
        pair.with_gradient(false),
        ghost.with_gradient(false),
        pair,
        pair.with_gradient(true),
    ];
    assert_eq!(gjkd_proto::ReplyEntry::gradients_asked(&items), 3);
    let mut out = [ItemResult::default(); 5];
    let mut rows = [GradientRow::default(); 3];
    s.state
        .handle_with_gradients(1, &items, &mut out, &mut rows);
    assert_eq!(rows.map(|r| r.item), [1, 2, 4]);
    assert_eq!(out[2].error, gjkd_proto::ErrorCode::UnknownObject as u32);
    assert_eq!(rows[1].gradient, Gradient::NONE);
    let alone = pair_with_gradient(&mut s.state, link, obstacle, false);
    assert_eq!(rows[0].gradient, alone.gradient);
    assert!(rows[2].gradient.has_base());
    assert_eq!(
        rows[2].gradient.as_slice()[..alone.gradient.as_slice().len()],
        *alone.gradient.as_slice()
    );
    // The distances are the same as without gradients.
    assert!(out.iter().all(|r| r.error == 0 || r.error == out[2].error));
    assert_eq!(out[0].distance, out[1].distance);
}

/// Overlapping pairs: the gradient of the signed distance (minus the
/// penetration depth) against closed forms: two balls (along the line of
/// centres), a ball sunk into a box's face (along the face normal, turning
/// the ball about its centre changes nothing).
#[test]
fn overlapping_pairs_have_the_signed_distance_gradient() {
    let mut state = State::new(Limits::default(), WaitMode::Spin, 11);
    let mut put = |shape: Shape, pose: Isometry3<f64>| {
        state
            .insert(
                NewObject {
                    shape,
                    pose,
                    name: None,
                },
                Owner::Client(1),
            )
            .unwrap()
    };
    let ball = put(
        Convex::sphere(0.5).unwrap().into(),
        Isometry3::translation(0.0, 0.0, 0.0),
    );
    let other = put(
        Convex::sphere(0.5).unwrap().into(),
        Isometry3::translation(0.6, 0.8, 0.0),
    );
    let slab = put(
        Convex::cuboid(Vector3::new(2.0, 2.0, 0.5), 0.0)
            .unwrap()
            .into(),
        Isometry3::translation(5.0, 0.0, 0.0),
    );
    let sunk = put(
        Convex::sphere(0.3).unwrap().into(),
        Isometry3::translation(5.1, 0.2, 0.4),
    );
    // Radii 0.5 + 0.5, centres moved 0.9 apart: 0.1 deep.
    let mut item = Item::set_pose(
        ObjectId::from_raw(other),
        &Isometry3::translation(0.54, 0.72, 0.0),
    );
    item.flags = 0;
    let mut out = [ItemResult::default()];
    state.handle(1, &[item], &mut out);
    let got = pair_with_gradient(&mut state, ball, other, false);
    assert_eq!(got.distance, 0.0);
    // Depth 0.1: the certified lower bound on the depth is that close.
    assert!((got.penetration - 0.1).abs() < 1e-8, "{got:?}");
    let g = got.gradient;
    assert_eq!(g.flags & gradient_flags::NO_DIRECTION, 0, "{g:?}");
    let want = [-0.6, -0.8, 0.0, 0.0, 0.0, 0.0];
    for (x, y) in g.as_slice().iter().zip(want) {
        assert!((x - y).abs() < 1e-6, "{g:?}");
    }
    // The ball's centre 0.1 under the slab's top face (z = 0.5), radius
    // 0.3: 0.4 deep; moving the ball up raises the signed distance one for
    // one.
    let got = pair_with_gradient(&mut state, sunk, slab, false);
    assert!((got.penetration - 0.4).abs() < 1e-8, "{got:?}");
    let want = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    for (x, y) in got.gradient.as_slice().iter().zip(want) {
        assert!((x - y).abs() < 1e-6, "{:?}", got.gradient);
    }
}
