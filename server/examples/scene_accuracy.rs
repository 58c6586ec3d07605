//! The speed and accuracy of the scene service's clearance question,
//! in-process (no IPC), for a 7-link arm moving along a 1 000-step path
//! among 1 000 obstacles, with and without motion bounds and accepted
//! accuracies, beside parry3d-f64 doing the same job in process with its
//! own BVH and distance queries:
//!
//! ```text
//! cargo run --release -p gjkd-server --example scene_accuracy
//! ```
//!
//! Every variant answers every step; the error columns compare each
//! link's reported distance with the exact one (GJK run on every
//! candidate, no motion bound), and count intervals that exclude it.

use gjk::{Convex, Shape};
use gjkd_proto::{
    Item, ObjectId, SceneKind, SceneRequest, SceneRow, Status, WaitMode, scene_flags,
};
use gjkd_server::engine::state::{Limits, NewObject, Owner, State};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Rot3, Vector};
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use parry3d_f64::shape::{Ball, Capsule, ConvexPolyhedron, Cuboid, Shape as ParryShape};

/// This thread's CPU time in seconds: on a shared machine, wall time
/// counts the other processes' turns too.
fn cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: a valid clock id and a pointer to a timespec we own.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

const OBSTACLES: usize = 1000;
const STEPS: usize = 1000;
const LINKS: usize = 7;
const PASSES: usize = 5;

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
}

/// A shape and its parry twin.
fn obstacle(i: usize, rng: &mut Lcg) -> (Shape, Box<dyn ParryShape>) {
    let s = rng.range(0.05, 0.25);
    match i % 3 {
        0 => {
            let h = Vector3::new(s, rng.range(0.05, 0.25), rng.range(0.05, 0.25));
            (
                Convex::cuboid(h, 0.0).unwrap().into(),
                Box::new(Cuboid::new(Vector::new(h.x, h.y, h.z))),
            )
        }
        1 => (Convex::sphere(s).unwrap().into(), Box::new(Ball::new(s))),
        _ => {
            let n = 8 + (rng.next() * 57.0) as usize;
            let pts: Vec<Point3<f64>> = (0..n)
                .map(|_| {
                    let d = Vector3::new(
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                        rng.range(-1.0, 1.0),
                    );
                    Point3::from(d.normalize() * s)
                })
                .collect();
            let hull: Vec<Vector> = pts.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
            (
                Convex::new(pts, 0.0).unwrap().into(),
                Box::new(ConvexPolyhedron::from_convex_hull(&hull).unwrap()),
            )
        }
    }
}

/// Link `i` of the arm: capsules, boxes and a polytope.
fn link(i: usize) -> (Shape, Box<dyn ParryShape>) {
    match i % 3 {
        0 => (
            Convex::capsule(Point3::new(0.0, 0.0, 0.0), Point3::new(0.3, 0.0, 0.0), 0.05)
                .unwrap()
                .into(),
            Box::new(Capsule::new(Vector::ZERO, Vector::new(0.3, 0.0, 0.0), 0.05)),
        ),
        1 => (
            Convex::cuboid(Vector3::new(0.15, 0.05, 0.05), 0.0)
                .unwrap()
                .into(),
            Box::new(Cuboid::new(Vector::new(0.15, 0.05, 0.05))),
        ),
        _ => {
            let pts: Vec<Point3<f64>> = (0..12)
                .map(|k| {
                    let a = f64::from(k) * std::f64::consts::FRAC_PI_6;
                    Point3::new(
                        if k % 2 == 0 { -0.1 } else { 0.1 },
                        0.06 * a.cos(),
                        0.06 * a.sin(),
                    )
                })
                .collect();
            let hull: Vec<Vector> = pts.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
            (
                Convex::new(pts, 0.0).unwrap().into(),
                Box::new(ConvexPolyhedron::from_convex_hull(&hull).unwrap()),
            )
        }
    }
}

/// The arm's link poses at step `t`: a base gliding through the scene and
/// joints swinging, the whole sweep in `STEPS * slowdown` steps.
fn arm(t: usize, slowdown: f64) -> [Isometry3<f64>; LINKS] {
    let s = t as f64 / (STEPS as f64 * slowdown);
    let base = Isometry3::from_parts(
        Translation3::new(-4.0 + 8.0 * s, 1.5 * (6.0 * s).sin(), 0.5 * (4.0 * s).cos()),
        UnitQuaternion::from_euler_angles(0.0, 0.0, 2.0 * s),
    );
    let mut pose = base;
    let mut out = [Isometry3::identity(); LINKS];
    for (j, o) in out.iter_mut().enumerate() {
        let angle = 0.6 * (3.0 * s + j as f64).sin();
        let axis = if j % 2 == 0 {
            Vector3::z_axis()
        } else {
            Vector3::y_axis()
        };
        pose *= UnitQuaternion::from_axis_angle(&axis, angle);
        *o = pose;
        pose *= Isometry3::translation(0.32, 0.0, 0.0);
    }
    out
}

fn parry_pose(p: &Isometry3<f64>) -> Pose {
    let q = p.rotation.quaternion();
    let t = p.translation.vector;
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rot3::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

struct World {
    state: State,
    links: Vec<u64>,
    parry_links: Vec<Box<dyn ParryShape>>,
    parry_obstacles: Vec<(Box<dyn ParryShape>, Pose)>,
}

fn world() -> World {
    let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
    let mut rng = Lcg(7);
    let mut parry_obstacles = Vec::new();
    for i in 0..OBSTACLES {
        let (shape, twin) = obstacle(i, &mut rng);
        let t = Vector3::new(
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
            rng.range(-5.0, 5.0),
        );
        let r = Vector3::new(
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
            rng.range(-3.0, 3.0),
        );
        let pose = Isometry3::new(t, r);
        parry_obstacles.push((twin, parry_pose(&pose)));
        state
            .insert(
                NewObject {
                    shape,
                    pose,
                    name: None,
                },
                Owner::Scene,
            )
            .unwrap();
    }
    let mut links = Vec::new();
    let mut parry_links = Vec::new();
    for i in 0..LINKS {
        let (shape, twin) = link(i);
        parry_links.push(twin);
        let new = NewObject {
            shape,
            pose: Isometry3::identity(),
            name: None,
        };
        links.push(state.insert(new, Owner::Client(1)).unwrap());
    }
    World {
        state,
        links,
        parry_links,
        parry_obstacles,
    }
}

/// One variant's answers: per step and link, distance and interval.
struct Run {
    seconds: f64,
    rows: Vec<SceneRow>,
    gjk_runs: u64,
    bounded: u64,
}

fn run_scene(
    w: &mut World,
    slowdown: f64,
    client: u128,
    flags: u32,
    accept_absolute: f64,
    accept_relative: f64,
) -> Run {
    let mut request = SceneRequest::new(SceneKind::Clearance, 0);
    request.flags = flags;
    request.accept_absolute = accept_absolute;
    request.accept_relative = accept_relative;
    let mut items: Vec<Item> = w
        .links
        .iter()
        .map(|&l| Item::member(ObjectId::from_raw(l)))
        .collect();
    let n = items.len();
    items.extend(
        w.links
            .iter()
            .map(|&l| Item::set_pose(ObjectId::from_raw(l), &Isometry3::identity())),
    );
    let mut buffer = [SceneRow::default(); LINKS];
    let mut out = Vec::with_capacity(STEPS * LINKS);
    let (mut gjk_runs, mut bounded) = (0, 0);
    let start = cpu_seconds();
    for t in 0..STEPS {
        for (item, pose) in items[n..].iter_mut().zip(arm(t, slowdown)) {
            item.pose_a = gjkd_proto::Pose::from_isometry(&pose);
        }
        let reply = w.state.scene(client, &request, &items, &mut buffer);
        assert_eq!(reply.error, 0);
        gjk_runs += reply.gjk_runs;
        bounded += reply.bounded;
        out.extend_from_slice(&buffer);
    }
    Run {
        seconds: cpu_seconds() - start,
        rows: out,
        gjk_runs,
        bounded,
    }
}

/// parry3d-f64 in process: a BVH over the (static) obstacles, and per
/// link a best-first search whose leaf cost is parry's distance query.
fn run_parry(w: &World, slowdown: f64) -> (f64, Vec<f64>) {
    let aabbs: Vec<_> = w
        .parry_obstacles
        .iter()
        .map(|(s, p)| s.compute_aabb(p))
        .collect();
    let bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &aabbs);
    let mut out = Vec::with_capacity(STEPS * LINKS);
    let start = cpu_seconds();
    for t in 0..STEPS {
        for (shape, pose) in w.parry_links.iter().zip(arm(t, slowdown)) {
            let pose = parry_pose(&pose);
            let aabb = shape.compute_aabb(&pose);
            let best = bvh.find_best(
                f64::MAX,
                |node, _| {
                    let n = node.aabb();
                    let gap = (n.mins - aabb.maxs)
                        .max(aabb.mins - n.maxs)
                        .max(Vector::ZERO);
                    gap.length()
                },
                |leaf, _| {
                    let (other, at) = &w.parry_obstacles[leaf as usize];
                    parry3d_f64::query::distance(&pose, shape.as_ref(), at, other.as_ref())
                        .ok()
                        .map(|d| d.distance)
                },
            );
            out.push(best.map_or(f64::INFINITY, |(_, d)| d));
        }
    }
    (cpu_seconds() - start, out)
}

fn main() {
    let mut w = world();
    for (slowdown, what) in [
        (1.0, "a planner's path: the sweep in 1 000 steps"),
        (
            10.0,
            "a control loop: the first tenth of the sweep in 1 000 steps",
        ),
    ] {
        table(&mut w, slowdown, what);
    }
}

fn table(w: &mut World, slowdown: f64, what: &str) {
    let exact = run_scene(w, slowdown, u128::MAX, scene_flags::WARM_START, 0.0, 0.0);
    let variants = [
        (
            "warm starts only (exact)",
            scene_flags::WARM_START,
            0.0,
            0.0,
        ),
        (
            "motion bounds, nothing accepted",
            scene_flags::WARM_START | scene_flags::MOTION_BOUNDS,
            0.0,
            0.0,
        ),
        (
            "motion bounds, accept_absolute 1e-3",
            scene_flags::WARM_START | scene_flags::MOTION_BOUNDS,
            1e-3,
            0.0,
        ),
        (
            "motion bounds, accept_relative 1e-2",
            scene_flags::WARM_START | scene_flags::MOTION_BOUNDS,
            0.0,
            1e-2,
        ),
        (
            "motion bounds, accept_absolute 1e-2",
            scene_flags::WARM_START | scene_flags::MOTION_BOUNDS,
            1e-2,
            0.0,
        ),
    ];
    println!(
        "\nclearance of a {LINKS}-link arm among {OBSTACLES} obstacles, {what}, in process, thread CPU time, fastest of {PASSES} passes\n"
    );
    println!(
        "| variant | µs/step | GJK runs/step | bounded/step | max error | intervals excluding the exact distance |"
    );
    println!("|---|---:|---:|---:|---:|---:|");
    // A fresh client per pass: no warm start carried between passes; the
    // fastest of the passes, against the noise of a shared machine.
    let mut client = 1;
    for (name, flags, abs, rel) in variants {
        let mut r = run_scene(w, slowdown, client, flags, abs, rel);
        for _ in 1..PASSES {
            client += 1;
            let again = run_scene(w, slowdown, client, flags, abs, rel);
            if again.seconds < r.seconds {
                r = again;
            }
        }
        client += 1;
        let mut max_error: f64 = 0.0;
        let mut excluded = 0;
        for (row, e) in r.rows.iter().zip(&exact.rows) {
            max_error = max_error.max((row.result.distance - e.result.distance).abs());
            if row.result.lower > e.result.upper || row.result.upper < e.result.lower {
                excluded += 1;
            }
        }
        let bounded_rows = r
            .rows
            .iter()
            .filter(|x| x.result.status == Status::Bounded as u32)
            .count();
        println!(
            "| {name} | {:.2} | {:.1} | {:.1} | {max_error:.2e} | {excluded} (bounded rows: {bounded_rows}) |",
            r.seconds / STEPS as f64 * 1e6,
            r.gjk_runs as f64 / STEPS as f64,
            r.bounded as f64 / STEPS as f64,
        );
    }
    let (mut seconds, distances) = run_parry(w, slowdown);
    for _ in 1..PASSES {
        seconds = seconds.min(run_parry(w, slowdown).0);
    }
    let max_error = distances
        .iter()
        .zip(&exact.rows)
        .map(|(d, e)| (d - e.result.distance).abs())
        .fold(0.0, f64::max);
    println!(
        "| parry3d-f64 in process (BVH + find_best + distance) | {:.2} | | | {max_error:.2e} | |",
        seconds / STEPS as f64 * 1e6
    );
}
