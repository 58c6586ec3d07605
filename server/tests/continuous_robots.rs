//! Continuous paths of the vendored Panda and UR5 among boxes, spheres and
//! cylinders, against dense sampling: 10 000 poses a segment, the links
//! moved by the model crate's forward kinematics, each link and obstacle
//! pair measured by the test kit's brute force between hulls (for a
//! cylinder, whose surface no hull holds, parry3d-f64's distance, and near
//! the margin alternating projections between the hull and the cylinder,
//! see [`hull_to_cylinder`]). A segment
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
use gjkd_testkit::reference::{Hull, distance, hulls_distance};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// Poses per segment of the dense truth.
const DENSE: usize = 10_000;
/// The margin asked.
const MARGIN: f64 = 0.01;
/// The widest bracket asked.
const BRACKET: f64 = 1e-6;
/// Agreement expected between the server's intervals and the truth: the
/// sampling's own allowance, far above the references' error.
const TOL: f64 = 1e-6;
/// How near the margin parry's distance to a cylinder is refined: parry's
/// run on a curved rim stops up to a few 1e-6 above the distance (a rim
/// contact of the Panda came out 1.3e-6 too far, beyond `TOL`).
const REFINE: f64 = 1e-4;

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
        (Piece::Hull(hull_a, oa, ra, hull), Piece::Cylinder(r, h)) => {
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
            let d = if (d.distance - ra - MARGIN).abs() <= REFINE {
                hull_to_cylinder(&hull_a.posed(&(pa * oa)), pb, *r, *h)
            } else {
                d.distance
            };
            (d - ra).max(0.0)
        }
        _ => unreachable!("links are hulls"),
    }
}

/// The distance between a posed hull and the solid cylinder of radius `r`
/// and half-height `h` about the z axis of `pose`, by alternating
/// projections (the cylinder's nearest point to a point of the hull in
/// closed form, the hull's nearest point to that by the test kit's brute
/// force), from the cylinder's point nearest the hull's centroid. Every
/// step holds a point of each shape, so the distance between them bounds
/// the truth from above and only decreases; between disjoint convex sets
/// it converges to the truth, here in a few steps.
fn hull_to_cylinder(hull: &Hull, pose: &Isometry3<f64>, r: f64, h: f64) -> f64 {
    let onto_cylinder = |p: &Point3<f64>| {
        let local = pose.inverse_transform_point(p);
        let rho = local.x.hypot(local.y);
        let shrink = if rho > r { r / rho } else { 1.0 };
        pose * Point3::new(local.x * shrink, local.y * shrink, local.z.clamp(-h, h))
    };
    let points = hull.points();
    let centroid = points
        .iter()
        .fold(Vector3::zeros(), |sum, p| sum + p.coords)
        / points.len() as f64;
    let mut y = onto_cylinder(&Point3::from(centroid));
    let mut best = f64::INFINITY;
    for _ in 0..1000 {
        let x = hulls_distance(hull, &Hull::new(&[y])).point_p;
        y = onto_cylinder(&x);
        let d = (x - y).norm();
        if d >= best * (1.0 - 1e-15) {
            return best.min(d);
        }
        best = d;
    }
    best
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
    /// The server's id and the shape of each link of `links`, then of each
    /// obstacle.
    objects: Vec<(u64, Shape)>,
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
    let mut objects = Vec::new();
    for (i, link) in model.links.iter().enumerate() {
        if let Some(shape) = &link.shape {
            let id = state
                .insert(
                    NewObject {
                        shape: shape.clone(),
                        pose: Isometry3::identity(),
                        name: Some(format!("{}/{}", model.name(), link.name)),
                    },
                    Owner::Client(1),
                )
                .unwrap();
            objects.push((id, shape.clone()));
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
        objects.push((id, shape.clone()));
        placed.push((pose, pieces(&shape), r));
    }
    Scene {
        state,
        model,
        robot,
        links,
        obstacles: placed,
        objects,
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

/// The rows of the continuous path through `waypoints`.
fn ask_edges(s: &mut Scene, waypoints: &[Vec<f64>]) -> Vec<SceneRow> {
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
    rows.truncate(reply.total as usize);
    rows
}

/// The joint positions `t` of the way from `ends[0]` to `ends[1]`.
fn joints_at(ends: &[Vec<f64>], t: f64) -> Vec<f64> {
    ends[0]
        .iter()
        .zip(&ends[1])
        .map(|(a, b)| a + (b - a) * t)
        .collect()
}

/// Asks the continuous path through `waypoints` and checks each segment
/// against dense sampling; returns the segments that touch.
fn check_edges(s: &mut Scene, waypoints: &[Vec<f64>]) -> usize {
    let rows = ask_edges(s, waypoints);
    let mut touching = 0;
    for (k, ends) in waypoints.windows(2).enumerate() {
        let row = rows.iter().find(|r| r.step == k as u32);
        let at = |t: f64| joints_at(ends, t);
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

/// Checks `paths` random paths of robot `name` among `obstacles`; returns
/// the segments that touch and the segments asked.
fn robot_edges(
    name: &str,
    seed: u64,
    paths: usize,
    obstacles: usize,
    reach_of_arm: f64,
) -> (usize, usize) {
    let mut s = scene(name, seed, obstacles, reach_of_arm);
    let mut rng = Rng(seed ^ 0x9e37_79b9_7f4a_7c15);
    let (mut touching, mut segments) = (0, 0);
    for _ in 0..paths {
        let w = waypoints(&s.model, &mut rng, 3, 0.8);
        touching += check_edges(&mut s, &w);
        segments += w.len() - 1;
    }
    (touching, segments)
}

/// Both answers asked: some segments touch, some are clear.
fn assert_both_answers((touching, segments): (usize, usize)) {
    assert!(
        touching > 0 && touching < segments,
        "{touching} of {segments} segments touch"
    );
}

#[test]
fn panda_edges_never_miss_a_contact() {
    assert_both_answers(robot_edges("panda", 0x9a4d_a5ee_d001, 2, 9, 0.7));
}

#[test]
fn ur5_edges_never_miss_a_contact() {
    assert_both_answers(robot_edges("ur5", 0x0e55_eed0_0002, 2, 9, 0.8));
}

/// More edges and obstacles: minutes in a debug build. Among 30
/// obstacles a scene's every segment may touch (five of the sixteen
/// scenes here), so both answers are asked of the whole run.
#[test]
#[ignore]
fn many_robot_edges_never_miss_a_contact() {
    let (mut touching, mut segments) = (0, 0);
    for seed in 0..8 {
        for (t, n) in [
            robot_edges("panda", 0x51ed + seed, 10, 30, 0.7),
            robot_edges("ur5", 0x52ed + seed, 10, 30, 0.8),
        ] {
            touching += t;
            segments += n;
        }
    }
    assert_both_answers((touching, segments));
}

/// The grazing contact the large test once failed on: the Panda's hand
/// passing a cylinder's rim, found at `s_hi` within the margin by
/// 1.2e-8, where parry's distance alone put that pose 1.3e-6 beyond it.
/// The server was right: its witness points are points of the two shapes
/// at the model's poses, nearer than the margin, and the reference, its
/// cylinder distance refined near the margin, agrees with its interval.
#[test]
fn a_hand_passing_a_cylinder_rim_is_within_the_margin_at_s_hi() {
    let mut s = scene("panda", 0x51ef, 30, 0.7);
    // Segment 0 of the eighth path of `robot_edges("panda", 0x51ef, ..)`.
    let ends = vec![
        vec![
            2.5306111346357363,
            -1.4964670424222575,
            -1.9350270641838963,
            -2.2225893289501855,
            2.759914531974158,
            2.116787753847114,
            0.47877636890141906,
            0.0074071578880888465,
        ],
        vec![
            2.7014959565830456,
            -1.3562256708897906,
            -2.4831661950829225,
            -2.006060838225377,
            2.2421771369841643,
            1.4873702376910938,
            -0.10417704169237263,
            0.0,
        ],
    ];
    let rows = ask_edges(&mut s, &ends);
    let row = rows.iter().find(|r| r.step == 0).expect("a contact");
    assert!(
        row.s_lo <= row.s_hi && row.s_hi - row.s_lo <= BRACKET,
        "{row:?}"
    );
    assert!((0.1522..0.1523).contains(&row.s_hi), "{row:?}");
    let r = &row.result;
    assert!(r.upper <= MARGIN, "certified within the margin: {r:?}");
    // Which link and obstacle: the hand and a cylinder.
    let object = |id: u64| s.objects.iter().position(|(i, _)| *i == id).unwrap();
    let (a, b) = (object(row.a), object(row.b));
    let obstacle = b - s.links.len();
    let Shape::Convex(cylinder) = &s.objects[b].1 else {
        panic!("obstacles are convex")
    };
    let (radius, half_height) = cylinder.cylinder_dimensions().expect("a cylinder");
    let q = joints_at(&ends, row.s_hi);
    let poses = s
        .model
        .kinematics
        .link_poses(&Isometry3::identity(), &q, LimitMode::Clamp)
        .unwrap();
    let (link, link_pieces, _) = &s.links[a];
    let (pose_a, pose_b) = (poses[*link], s.obstacles[obstacle].0);
    // The witness points lie on the shapes at the model's poses: A's on
    // its piece's hull, B's in the cylinder (on its rim), each to
    // round-off. Their distance bounds the truth from above.
    let Piece::Hull(hull, offset, rounding, _) = &link_pieces[r.pieces[0] as usize] else {
        panic!("links are hulls")
    };
    assert_eq!(*rounding, 0.0);
    let point_a = Point3::from(Vector3::from(r.point_a));
    let point_b = Point3::from(Vector3::from(r.point_b));
    let off_hull = hulls_distance(&hull.posed(&(pose_a * offset)), &Hull::new(&[point_a]));
    assert!(off_hull.distance <= 1e-12, "{}", off_hull.distance);
    let in_b = pose_b.inverse_transform_point(&point_b);
    let slack = 1e-12;
    assert!(in_b.x.hypot(in_b.y) <= radius + slack && in_b.z.abs() <= half_height + slack);
    assert!((point_a - point_b).norm() <= MARGIN);
    // The reference at `s_hi`, independently: within the margin, and
    // within the server's interval but for round-off.
    let moving = vec![true; s.model.links.len()];
    let truth = least_at(&s, &q, &moving);
    assert!(truth <= MARGIN, "{truth}");
    assert!(
        r.lower - 1e-12 <= truth && truth <= r.upper + 1e-12,
        "{truth} {r:?}"
    );
}
