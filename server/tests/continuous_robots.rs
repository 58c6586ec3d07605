//! Continuous paths of the vendored Panda and UR5 among boxes, spheres and
//! cylinders, against dense sampling: 10 000 poses a segment, the links
//! moved by the model crate's forward kinematics, each link and obstacle
//! pair measured by the test kit's brute force between hulls (parry3d-f64's
//! distance for a cylinder, whose surface no hull holds). A segment
//! answered clear must have no sampled contact; a contact's bracket must
//! hold the first sampled contact (allowing the sampling step), and the
//! pose at its `s_hi` must be within the margin. A pair is skipped at a
//! sample where its last measured distance, less how far its link moved
//! since, stays beyond the margin (`gjkd_testkit::dense`): the first
//! sampled contact is the one a measure of every pair at every sample
//! finds.

// The model tests' deterministic generator (the same motions every run).
#[path = "../../model/tests/files.rs"]
mod files;

use files::Rng;

use gjk::{Convex, Shape};
use gjkd_model::{LimitMode, PackagePath, RobotModel};
use gjkd_proto::{Item, ObjectId, PathMode, SceneKind, SceneRequest, SceneRow, WaitMode};
use gjkd_server::engine::robots::NewRobot;
use gjkd_server::engine::state::{Limits, NewObject, Owner, State};
use gjkd_testkit::dense::{displacement, first_within};
use gjkd_testkit::reference::{Hull, distance};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// Poses per segment of the dense truth.
const DENSE: usize = 10_000;
/// The margin asked.
const MARGIN: f64 = 0.01;
/// The widest bracket asked.
const BRACKET: f64 = 1e-6;
/// Agreement expected between the server's intervals and the truth (parry's
/// distance to a cylinder converges to about this).
const TOL: f64 = 1e-6;

/// One convex piece of the truth.
enum Piece {
    /// A hull for the test kit's brute force, its offset in the object
    /// frame and its rounding, and the same hull for parry.
    Hull(
        Hull,
        Isometry3<f64>,
        f64,
        Option<Box<parry3d_f64::shape::ConvexPolyhedron>>,
    ),
    /// A cylinder for parry: radius and half-height about the body z axis.
    Cylinder(f64, f64),
}

fn pieces(shape: &Shape) -> Vec<Piece> {
    let piece = |offset: Isometry3<f64>, c: &Convex| match c.cylinder_dimensions() {
        Some((r, h)) => Piece::Cylinder(r, h),
        None => {
            let points: Vec<parry3d_f64::math::Vector> = c
                .vertices()
                .iter()
                .map(|p| parry3d_f64::math::Vector::new(p.x, p.y, p.z))
                .collect();
            // Flat or single-point sets have no parry hull; only links meet
            // cylinders, and their hulls are solid.
            let parry = parry3d_f64::shape::ConvexPolyhedron::from_convex_hull(&points);
            Piece::Hull(
                Hull::new(c.vertices()),
                offset,
                c.radius(),
                parry.map(Box::new),
            )
        }
    };
    match shape {
        Shape::Convex(c) => vec![piece(Isometry3::identity(), c)],
        Shape::Compound(c) => c.pieces().iter().map(|(o, c)| piece(*o, c)).collect(),
    }
}

/// The truth's distance between a link's piece (a hull) and an obstacle's.
fn piece_distance(a: &Piece, pa: &Isometry3<f64>, b: &Piece, pb: &Isometry3<f64>) -> f64 {
    match (a, b) {
        (Piece::Hull(ha, oa, ra, _), Piece::Hull(hb, ob, rb, _)) => {
            distance(ha, &(pa * oa), *ra, hb, &(pb * ob), *rb).distance
        }
        (Piece::Hull(_, oa, ra, hull), Piece::Cylinder(r, h)) => {
            // parry's cylinder is about its y axis, gjk's about z.
            let turn =
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
            let cylinder = parry3d_f64::shape::Cylinder::new(*h, *r);
            let d = parry3d_f64::query::distance(
                &parry_pose(&(pa * oa)),
                &**hull.as_ref().expect("a link's hull is solid"),
                &parry_pose(&(pb * Isometry3::from_parts(Translation3::identity(), turn))),
                &cylinder,
            )
            .expect("a supported pair");
            (d.distance - ra).max(0.0)
        }
        _ => unreachable!("links are hulls"),
    }
}

/// An nalgebra isometry as parry's pose.
fn parry_pose(p: &Isometry3<f64>) -> parry3d_f64::math::Pose {
    let (q, t) = (p.rotation.quaternion(), p.translation.vector);
    parry3d_f64::math::Pose::from_parts(
        parry3d_f64::math::Vector::new(t.x, t.y, t.z),
        parry3d_f64::math::Rot3::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

fn least(a: &[Piece], pa: &Isometry3<f64>, b: &[Piece], pb: &Isometry3<f64>) -> f64 {
    let mut best = f64::INFINITY;
    for x in a {
        for y in b {
            best = best.min(piece_distance(x, pa, y, pb));
        }
    }
    best
}

/// A robot among obstacles, with what the truth needs.
struct Scene {
    state: State,
    model: RobotModel,
    robot: u64,
    /// Per link with a shape: its index, pieces and reach from its frame.
    links: Vec<(usize, Vec<Piece>, f64)>,
    /// Per obstacle: its pose, pieces and reach from its centre.
    obstacles: Vec<(Isometry3<f64>, Vec<Piece>, f64)>,
}

/// The largest distance of a hull point from the body origin.
fn reach(shape: &Shape) -> f64 {
    let mut most: f64 = 0.0;
    let mut add = |offset: &Isometry3<f64>, c: &Convex| {
        let r = c.radius();
        match c.cylinder_dimensions() {
            Some((radius, h)) => most = most.max((radius * radius + h * h).sqrt() + r),
            None => {
                for v in c.vertices() {
                    most = most.max((offset * v).coords.norm() + r);
                }
            }
        }
    };
    match shape {
        Shape::Convex(c) => add(&Isometry3::identity(), c),
        Shape::Compound(c) => c.pieces().iter().for_each(|(o, c)| add(o, c)),
    }
    most
}

fn scene(name: &str, seed: u64, obstacles: usize, reach_of_arm: f64) -> Scene {
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../model/tests/data");
    let robots = data.join("example-robot-data/robots");
    let path = match name {
        "panda" => robots.join("panda_description/urdf/panda.urdf"),
        _ => robots.join("ur_description/urdf/ur5_robot.urdf"),
    };
    let urdf = std::fs::read_to_string(&path).unwrap();
    let model = RobotModel::from_urdf_str(&urdf, path.parent(), &PackagePath::new([data])).unwrap();
    let mut state = State::new(Limits::default(), WaitMode::Spin, 7);
    let mut links = Vec::new();
    for (i, link) in model.links.iter().enumerate() {
        if let Some(shape) = &link.shape {
            state
                .insert(
                    NewObject {
                        shape: shape.clone(),
                        pose: Isometry3::identity(),
                        name: Some(format!("{}/{}", model.name(), link.name)),
                    },
                    Owner::Client(1),
                )
                .unwrap();
            links.push((i, pieces(shape), reach(shape)));
        }
    }
    let robot = state
        .attach_robot(NewRobot {
            name: model.name(),
            urdf: &urdf,
            srdf: None,
            base: Isometry3::identity(),
            positions: None,
            owner: Owner::Client(1),
        })
        .unwrap();
    let mut rng = Rng(seed);
    let mut placed = Vec::new();
    for i in 0..obstacles {
        let size = rng.uniform(0.03, 0.1);
        let shape: Shape = match i % 3 {
            0 => Convex::cuboid(Vector3::new(size, 0.6 * size, 0.3 * size), 0.0)
                .unwrap()
                .into(),
            1 => Convex::sphere(size).unwrap().into(),
            _ => Convex::cylinder(0.5 * size, size, 0.0).unwrap().into(),
        };
        let axis = Vector3::new(
            rng.uniform(-2.0, 2.0),
            rng.uniform(-2.0, 2.0),
            rng.uniform(-2.0, 2.0),
        );
        let pose = Isometry3::from_parts(
            Translation3::new(
                rng.uniform(-reach_of_arm, reach_of_arm),
                rng.uniform(-reach_of_arm, reach_of_arm),
                rng.uniform(0.0, reach_of_arm),
            ),
            UnitQuaternion::from_scaled_axis(axis),
        );
        let r = reach(&shape);
        state
            .insert(
                NewObject {
                    shape: shape.clone(),
                    pose,
                    name: None,
                },
                Owner::Client(1),
            )
            .unwrap();
        placed.push((pose, pieces(&shape), r));
    }
    Scene {
        state,
        model,
        robot,
        links,
        obstacles: placed,
    }
}

/// The least distance over the link and obstacle pairs at `q`, links that
/// stay still along the segment (`moving[link]` false) and pairs whose
/// bounding spheres are beyond the margin skipped: a continuous path asks
/// only pairs it moves.
fn least_at(s: &Scene, q: &[f64], moving: &[bool]) -> f64 {
    let poses = s
        .model
        .kinematics
        .link_poses(&Isometry3::identity(), q, LimitMode::Clamp)
        .unwrap();
    let mut best = f64::INFINITY;
    for (link, pieces, ra) in s.links.iter().filter(|(l, _, _)| moving[*l]) {
        let pose = &poses[*link];
        for (pb, b, rb) in &s.obstacles {
            let apart = (pose.translation.vector - pb.translation.vector).norm();
            if apart - ra - rb <= MARGIN + 1e-6 {
                best = best.min(least(pieces, pose, b, pb));
            }
        }
    }
    best
}

/// Asks the continuous path through `waypoints` and checks each segment
/// against dense sampling; returns the segments that touch.
fn check_edges(s: &mut Scene, waypoints: &[Vec<f64>]) -> usize {
    let robot = ObjectId::from_raw(s.robot);
    let mut items = Vec::new();
    for q in waypoints {
        let chunks: Vec<&[f64]> = q.chunks(gjkd_proto::JOINTS_PER_ITEM).collect();
        for (k, chunk) in chunks.iter().enumerate() {
            let first = (k * gjkd_proto::JOINTS_PER_ITEM) as u32;
            let item = Item::set_joints(robot, first, chunk, None, false);
            items.push(if k + 1 == chunks.len() {
                item.ending_step()
            } else {
                item
            });
        }
    }
    let mut request = SceneRequest::new(SceneKind::Within, s.robot);
    request.path = PathMode::Continuous as u32;
    request.margin = MARGIN;
    request.bracket = BRACKET;
    request.max_rows = 64;
    let mut rows = vec![SceneRow::default(); 64];
    let reply = s.state.scene(1, &request, &items, &mut rows);
    assert_eq!(reply.error, 0, "{reply:?}");
    let rows = &rows[..reply.total as usize];
    let mut touching = 0;
    for (k, ends) in waypoints.windows(2).enumerate() {
        let row = rows.iter().find(|r| r.step == k as u32);
        let at = |t: f64| -> Vec<f64> {
            ends[0]
                .iter()
                .zip(&ends[1])
                .map(|(a, b)| a + (b - a) * t)
                .collect()
        };
        // A link moves when its pose differs at the segment's two ends
        // (a fixed base's links stay bit for bit).
        let fk = |q: &[f64]| {
            s.model
                .kinematics
                .link_poses(&Isometry3::identity(), q, LimitMode::Clamp)
                .unwrap()
        };
        let (p0, p1) = (fk(&ends[0]), fk(&ends[1]));
        let moving: Vec<bool> = p0.iter().zip(&p1).map(|(a, b)| a != b).collect();
        // Pair `j` is moving link `j / n` and obstacle `j % n`: the truth
        // when their bounding spheres come within the margin, their gap (a
        // lower bound) when not.
        let moving_links: Vec<&(usize, Vec<Piece>, f64)> =
            s.links.iter().filter(|(l, _, _)| moving[*l]).collect();
        let n = s.obstacles.len();
        let pair_at = |j: usize, poses: &Vec<Isometry3<f64>>| {
            let ((link, pieces, ra), (pb, b, rb)) = (moving_links[j / n], &s.obstacles[j % n]);
            let pose = &poses[*link];
            let gap = (pose.translation.vector - pb.translation.vector).norm() - ra - rb;
            if gap <= MARGIN + 1e-6 {
                least(pieces, pose, b, pb)
            } else {
                gap
            }
        };
        let moved = |j: usize, a: &Vec<Isometry3<f64>>, b: &Vec<Isometry3<f64>>| {
            let (link, _, reach) = moving_links[j / n];
            displacement(&a[*link], &b[*link], *reach)
        };
        let first = first_within(
            DENSE,
            MARGIN - TOL,
            // Twice the truth's own error (parry's, at a cylinder).
            2.0 * TOL,
            moving_links.len() * n,
            |t| fk(&at(t)),
            moved,
            pair_at,
        );
        match row {
            None => assert!(
                first.is_none(),
                "segment {k} certified clear, touches at s = {first:?}"
            ),
            Some(r) => {
                touching += 1;
                assert!(r.s_lo <= r.s_hi && r.s_hi - r.s_lo <= BRACKET, "{r:?}");
                let at_hi = least_at(s, &at(r.s_hi), &moving);
                assert!(at_hi <= MARGIN + TOL, "s_hi {} is {at_hi} away", r.s_hi);
                if let Some(f) = first {
                    assert!(f >= r.s_lo - 1e-12, "contact at {f} before s_lo {}", r.s_lo);
                    if at_hi <= MARGIN - TOL {
                        assert!(
                            f <= r.s_hi + 1.0 / DENSE as f64,
                            "{f} long after {}",
                            r.s_hi
                        );
                    }
                }
            }
        }
    }
    touching
}

/// Random waypoints within the joints' limits, each `step` (at most, per
/// joint) from the last.
fn waypoints(model: &RobotModel, rng: &mut Rng, count: usize, step: f64) -> Vec<Vec<f64>> {
    let limits: Vec<(f64, f64)> = model
        .kinematics
        .moving_joints()
        .map(|j| {
            (
                j.lower.max(-std::f64::consts::PI),
                j.upper.min(std::f64::consts::PI),
            )
        })
        .collect();
    let mut q: Vec<f64> = limits.iter().map(|&(lo, hi)| rng.uniform(lo, hi)).collect();
    let mut out = vec![q.clone()];
    for _ in 1..count {
        q = q
            .iter()
            .zip(&limits)
            .map(|(x, &(lo, hi))| (x + rng.uniform(-step, step)).clamp(lo, hi))
            .collect();
        out.push(q.clone());
    }
    out
}

fn robot_edges(name: &str, seed: u64, paths: usize, obstacles: usize, reach_of_arm: f64) {
    let mut s = scene(name, seed, obstacles, reach_of_arm);
    let mut rng = Rng(seed ^ 0x9e37_79b9_7f4a_7c15);
    let (mut touching, mut segments) = (0, 0);
    for _ in 0..paths {
        let w = waypoints(&s.model, &mut rng, 3, 0.8);
        touching += check_edges(&mut s, &w);
        segments += w.len() - 1;
    }
    // Both answers asked: some segments touch, some are clear.
    assert!(
        touching > 0 && touching < segments,
        "{touching} of {segments} segments touch"
    );
}

#[test]
fn panda_edges_never_miss_a_contact() {
    robot_edges("panda", 0x9a4d_a5ee_d001, 2, 9, 0.7);
}

#[test]
fn ur5_edges_never_miss_a_contact() {
    robot_edges("ur5", 0x0e55_eed0_0002, 2, 9, 0.8);
}

/// More edges and obstacles: minutes in a debug build.
#[test]
#[ignore]
fn many_robot_edges_never_miss_a_contact() {
    for seed in 0..8 {
        robot_edges("panda", 0x51ed + seed, 10, 30, 0.7);
        robot_edges("ur5", 0x52ed + seed, 10, 30, 0.8);
    }
}
