//! `gjkd bench edges`: a planner's edge check, the question OMPL's motion
//! validator asks most: is the straight joint-space motion from `q0` to
//! `q1` clear? The 7-link arm of `bench scene-robot` among its 1 000
//! obstacles ([`crate::scene_world`]), random edges of several lengths,
//! margin 0, checked four ways in one run:
//!
//! - **gjkd continuous (server)**: one scene request per edge
//!   ([`PathMode::Continuous`]): certified clear, or the first contact
//!   bracketed;
//! - **gjkd sampled (server)**: one first-hit path request per edge
//!   ([`PathMode::FirstHit`]) at OMPL's default resolution (1 % of the
//!   joint space's extent between states, both ends included);
//! - **parry3d-f64 in process**, sampled at the same resolution as a parry
//!   user would write it: per state, per link, the obstacles whose AABB
//!   meets the link's, each with `closest_points` and the margin, stopping
//!   at the first contact ([`crate::scene_parry`]);
//! - **parry3d-f64's nonlinear time of impact in process** (FCL-style
//!   conservative advancement per pair, the peer a parry user reaches
//!   for): per link, the rigid motion from its pose at `q0` to its pose at
//!   `q1` (translation linear, rotation at a constant rate about its
//!   origin), against each obstacle whose AABB meets the link's swept AABB
//!   (`compute_swept_aabb`), stopping at the first impact. The link's
//!   true motion along a joint-space edge is not that rigid motion, so
//!   this check can miss.
//!
//! Each edge's truth is dense sampling with parry (a state every 1e-3 rad
//! of the edge's largest joint motion): an edge a checker calls clear that
//! the dense check finds touching is a **missed collision**. The four take
//! turns edge by edge, so drift in the machine's speed hits all alike.
//!
//! The arm is attached to the server as a robot whose URDF places each
//! link's object at its body's centre, so the server's forward kinematics
//! gives exactly [`Arm::link_poses`]'s poses.

use std::fmt::Write as _;
use std::time::Instant;

use gjkd_client::{Client, Item, RobotHandle, Steps};
use gjkd_proto::{PathMode, SceneKind, SceneRequest, SceneRow};
use gjkd_testkit::parry::parry_pose;
use gjkd_testkit::sweep::Rng;
use nalgebra::Isometry3;
use parry3d_f64::math::Vector;
use parry3d_f64::query::NonlinearRigidMotion;
use parry3d_f64::shape::Shape as ParryShape;

use crate::scene_parry::ParryScene;
use crate::scene_world::{Arm, Obstacles, joint_path};
use crate::server_process::ServerProcess;
use crate::stats::{mean, percentile};
use crate::{BenchError, CommonArgs, io, out_dir};

/// Flags of `gjkd bench edges`.
#[derive(clap::Args, Debug)]
pub struct EdgesArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Edges of each length.
    #[arg(long, default_value_t = 200)]
    edges: usize,
    /// Edge lengths (joint-space Euclidean norm, radians).
    #[arg(long, value_delimiter = ',', default_values_t = [0.2, 0.5, 1.0, 2.0])]
    lengths: Vec<f64>,
    /// Obstacles.
    #[arg(long, default_value_t = 1000)]
    obstacles: usize,
    /// The widest bracket of a first contact, in s.
    #[arg(long, default_value_t = 1e-3)]
    bracket: f64,
    /// Seed of the obstacles and edges.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

/// The variants, in the table's order.
const VARIANTS: [&str; 4] = [
    "gjkd continuous (server)",
    "gjkd sampled, OMPL resolution (server)",
    "parry3d-f64 sampled, OMPL resolution",
    "parry3d-f64 nonlinear time of impact per pair",
];

/// OMPL's default longest valid segment: this share of the space's
/// extent (`StateSpace::setLongestValidSegmentFraction`).
const OMPL_FRACTION: f64 = 0.01;

/// Joint limits of the benchmark's arm (every joint).
const LIMIT: f64 = std::f64::consts::PI;

/// The arm as a URDF: joint `i` turns link `i`'s frame, a fixed joint puts
/// the link's object half way along it, as [`Arm::link_poses`] does.
fn arm_urdf(arm: &Arm) -> String {
    let mut s = String::from("<robot name=\"edgearm\"><link name=\"base\"/>");
    let mut parent = "base".to_owned();
    let mut offset = arm.base;
    for (i, (_, length)) in arm.links.iter().enumerate() {
        let axis = if i % 2 == 0 { "0 0 1" } else { "0 1 0" };
        let _ = write!(
            s,
            "<link name=\"j{i}\"/><link name=\"link{i}\"/>\
             <joint name=\"q{i}\" type=\"revolute\"><parent link=\"{parent}\"/><child link=\"j{i}\"/>\
             <origin xyz=\"0 0 {offset}\"/><axis xyz=\"{axis}\"/>\
             <limit lower=\"{lo}\" upper=\"{LIMIT}\" effort=\"1\" velocity=\"1\"/></joint>\
             <joint name=\"c{i}\" type=\"fixed\"><parent link=\"j{i}\"/><child link=\"link{i}\"/>\
             <origin xyz=\"0 0 {half}\"/></joint>",
            lo = -LIMIT,
            half = length / 2.0,
        );
        parent = format!("link{i}");
        offset = length / 2.0;
    }
    s.push_str("</robot>");
    s
}

/// One edge: its ends and the dense truth.
struct Edge {
    q0: [f64; 7],
    q1: [f64; 7],
    length: f64,
    touches: bool,
}

/// The joint positions at `t` along an edge.
fn along(e: &Edge, t: f64) -> [f64; 7] {
    std::array::from_fn(|j| e.q0[j] + (e.q1[j] - e.q0[j]) * t)
}

/// What parry needs.
struct Parry {
    scene: ParryScene,
    links: Vec<Box<dyn ParryShape>>,
}

/// Whether any link touches an obstacle at `q` (parry, margin 0).
fn parry_touches(arm: &Arm, p: &Parry, q: &[f64; 7], poses: &mut Vec<Isometry3<f64>>) -> bool {
    arm.link_poses(q, poses);
    let mut out = Vec::new();
    for (link, pose) in p.links.iter().zip(poses.iter()) {
        p.scene.within(&**link, &parry_pose(pose), 0.0, &mut out);
        if !out.is_empty() {
            return true;
        }
    }
    false
}

/// Whether parry's nonlinear time of impact finds an impact of a link,
/// each link moved rigidly from its pose at the edge's start to its pose at
/// its end.
fn parry_impact(
    arm: &Arm,
    p: &Parry,
    e: &Edge,
    start: &mut Vec<Isometry3<f64>>,
    end: &mut Vec<Isometry3<f64>>,
) -> bool {
    arm.link_poses(&e.q0, start);
    arm.link_poses(&e.q1, end);
    p.links
        .iter()
        .zip(start.iter())
        .zip(end.iter())
        .any(|((link, a), b)| {
            let (pa, pb) = (parry_pose(a), parry_pose(b));
            let swept = link.compute_swept_aabb(&pa, &pb);
            let dt = b.translation.vector - a.translation.vector;
            let w = (b.rotation * a.rotation.inverse()).scaled_axis();
            let motion = NonlinearRigidMotion::new(
                pa,
                Vector::ZERO,
                Vector::new(dt.x, dt.y, dt.z),
                Vector::new(w.x, w.y, w.z),
            );
            p.scene.impact(&**link, &motion, &swept)
        })
}

/// Interior states of OMPL's discrete motion check: `n` segments of at
/// most the resolution.
fn ompl_segments(length: f64) -> usize {
    let extent = (7.0 * (2.0 * LIMIT).powi(2)).sqrt();
    (length / (OMPL_FRACTION * extent)).ceil().max(1.0) as usize
}

/// Runs the benchmark.
///
/// # Errors
/// When the server cannot be started or an answer fails.
pub fn run(args: &EdgesArgs) -> Result<(), BenchError> {
    let service = format!("gjkd-bench-edges-{}", std::process::id());
    let mut server = io(
        "start gjkd serve",
        ServerProcess::spawn(&service, &["--wait", "spin", "--no-persist"]),
    )?;
    let outcome = measure(&service, args);
    server.stop();
    outcome
}

fn measure(service: &str, args: &EdgesArgs) -> Result<(), BenchError> {
    let arm = Arm::new();
    let (count, per_length) = if args.common.quick {
        (args.obstacles.min(200), args.edges.min(20))
    } else {
        (args.obstacles, args.edges)
    };
    let world = Obstacles::new(&arm, count, 200, args.seed);
    let mut client = Client::builder(service)
        .timeout(std::time::Duration::from_secs(10))
        .connect()?;
    let mut poses = Vec::new();
    arm.link_poses(&joint_path(0.0), &mut poses);
    for (i, ((b, _), p)) in arm.links.iter().zip(&poses).enumerate() {
        client.register_named(&format!("edgearm/link{i}"), &b.geometry(), p)?;
    }
    for (i, (b, p)) in world.bodies.iter().enumerate() {
        client.register_named(&format!("obstacle{i}"), &b.geometry(), p)?;
    }
    let robot = client.attach_robot("edgearm", &arm_urdf(&arm), None, &Isometry3::identity())?;
    let parry = Parry {
        scene: ParryScene::new(&world.bodies)?,
        links: arm
            .links
            .iter()
            .map(|(b, _)| b.parry())
            .collect::<Result<Vec<_>, _>>()?,
    };
    // The edges and their dense truth.
    let mut rng = Rng::new(args.seed ^ 0x5eed);
    let mut edges = Vec::new();
    for &length in &args.lengths {
        for _ in 0..per_length {
            let q0: [f64; 7] = std::array::from_fn(|_| rng.uniform(-2.5, 2.5));
            let mut d: [f64; 7] = std::array::from_fn(|_| rng.uniform(-1.0, 1.0));
            let norm = d.iter().map(|x| x * x).sum::<f64>().sqrt();
            d.iter_mut().for_each(|x| *x *= length / norm);
            let q1: [f64; 7] = std::array::from_fn(|j| (q0[j] + d[j]).clamp(-LIMIT, LIMIT));
            let mut e = Edge {
                q0,
                q1,
                length,
                touches: false,
            };
            let widest = (0..7).map(|j| (q1[j] - q0[j]).abs()).fold(0.0, f64::max);
            let dense = ((widest / 1e-3).ceil() as usize).max(1000);
            e.touches = (0..=dense).any(|i| {
                parry_touches(
                    &arm,
                    &parry,
                    &along(&e, i as f64 / dense as f64),
                    &mut poses,
                )
            });
            edges.push(e);
        }
    }
    // Times (µs) and verdicts per variant, edge by edge.
    let mut times = vec![Vec::new(); VARIANTS.len()];
    let mut clear = vec![Vec::new(); VARIANTS.len()];
    // The continuous check's GJK runs per edge: its work, free of the
    // host's noise.
    let mut runs = Vec::new();
    let mut rows = vec![SceneRow::default(); 4];
    let mut ends = Vec::new();
    let mut items = Vec::new();
    for e in &edges {
        let start = Instant::now();
        let (c, r) = continuous_clear(&mut client, &robot, e, args.bracket, &mut rows)?;
        runs.push(r);
        times[0].push(start.elapsed().as_secs_f64() * 1e6);
        let start = Instant::now();
        let s = sampled_clear(&mut client, &robot, e, &mut items, &mut rows)?;
        times[1].push(start.elapsed().as_secs_f64() * 1e6);
        let start = Instant::now();
        let n = ompl_segments(e.length);
        let p = !(0..=n)
            .any(|i| parry_touches(&arm, &parry, &along(e, i as f64 / n as f64), &mut poses));
        times[2].push(start.elapsed().as_secs_f64() * 1e6);
        let start = Instant::now();
        let t = !parry_impact(&arm, &parry, e, &mut poses, &mut ends);
        times[3].push(start.elapsed().as_secs_f64() * 1e6);
        for (v, verdict) in [c, s, p, t].into_iter().enumerate() {
            clear[v].push(verdict);
        }
    }
    report(args, &edges, &times, &clear, &runs)
}

fn continuous_clear(
    client: &mut Client,
    robot: &RobotHandle,
    e: &Edge,
    bracket: f64,
    rows: &mut [SceneRow],
) -> Result<(bool, (f64, f64)), BenchError> {
    let both: Vec<f64> = e.q0.iter().chain(&e.q1).copied().collect();
    let summary = client
        .within(robot, 0.0)
        .continuous(Steps::joints(robot, &both), bracket)
        .into_rows(rows)?;
    Ok((
        summary.total == 0,
        (summary.gjk_runs as f64, summary.candidates as f64),
    ))
}

fn sampled_clear(
    client: &mut Client,
    robot: &RobotHandle,
    e: &Edge,
    items: &mut Vec<Item>,
    rows: &mut [SceneRow],
) -> Result<bool, BenchError> {
    let n = ompl_segments(e.length);
    items.clear();
    for i in 0..=n {
        let q = along(e, i as f64 / n as f64);
        items.push(Item::set_joints(robot.id, 0, &q, None, false).ending_step());
    }
    let mut request = SceneRequest::new(SceneKind::Within, robot.id.raw());
    request.path = PathMode::FirstHit as u32;
    request.max_rows = rows.len() as u32;
    let reply = crate::scene_call::query(client, &request, items, rows)?;
    Ok(reply.first_hit == u32::MAX)
}

fn report(
    args: &EdgesArgs,
    edges: &[Edge],
    times: &[Vec<f64>],
    clear: &[Vec<bool>],
    runs: &[(f64, f64)],
) -> Result<(), BenchError> {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "| edge length (rad) | edges (touching) | checker | mean µs/edge | p50 | p90 | missed collisions | vs parry (mean) |\n|---|---|---|---|---|---|---|---|"
    );
    for &length in &args.lengths {
        let idx: Vec<usize> = (0..edges.len())
            .filter(|&i| edges[i].length == length)
            .collect();
        let touching = idx.iter().filter(|&&i| edges[i].touches).count();
        let parry_mean = mean(&idx.iter().map(|&i| times[2][i]).collect::<Vec<_>>());
        for (v, name) in VARIANTS.iter().enumerate() {
            let mut t: Vec<f64> = idx.iter().map(|&i| times[v][i]).collect();
            t.sort_by(f64::total_cmp);
            let missed = idx
                .iter()
                .filter(|&&i| clear[v][i] && edges[i].touches)
                .count();
            let m = mean(&t);
            let _ = writeln!(
                md,
                "| {length} | {} ({touching}) | {name} | {m:.1} | {:.1} | {:.1} | {missed} | {:.2}× |",
                idx.len(),
                percentile(&t, 0.5),
                percentile(&t, 0.9),
                m / parry_mean,
            );
        }
    }
    // Every edge the continuous check calls clear must be clear densely,
    // and every edge dense sampling finds touching must be caught.
    let wrong = (0..edges.len())
        .filter(|&i| clear[0][i] && edges[i].touches)
        .count();
    let _ = write!(
        md,
        "\nThe continuous check's work per edge (mean GJK runs, candidate pairs):"
    );
    for &length in &args.lengths {
        let of = |f: fn(&(f64, f64)) -> f64| {
            let r: Vec<f64> = (0..edges.len())
                .filter(|&i| edges[i].length == length)
                .map(|i| f(&runs[i]))
                .collect();
            mean(&r)
        };
        let _ = write!(md, " {length} rad {:.0}, {:.0};", of(|r| r.0), of(|r| r.1));
    }
    md.push('\n');
    println!("{md}");
    println!("gjkd continuous: {wrong} edges called clear that dense sampling finds touching.");
    let dir = out_dir(&args.common)?;
    io("write edges.md", std::fs::write(dir.join("edges.md"), md))?;
    Ok(())
}
