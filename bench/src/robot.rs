//! `gjkd bench robot`: what moving a robot by its joints on the server
//! costs, against moving it by link poses the client computed.
//!
//! A 7-joint arm ([`crate::robot_demo::ARM_URDF`], its seven arm links)
//! and 10 obstacles: 70 link-obstacle pairs, warm-started along a joint
//! path. Each step is one request either way:
//!
//! - **joints**: one `SetJoints` item (the server computes every link's pose
//!   by forward kinematics and stores it), then the 70 distance items;
//! - **client poses**: the client computes the link poses by the same
//!   forward kinematics (timed, as part of the step) and sends the 70
//!   distance items each carrying its link's pose.
//!
//! The two alternate step by step so that drift in the machine's speed
//! hits both alike; the table gives percentiles of each and of their
//! difference.

use std::time::Instant;

use gjkd_client::{Client, Item, ItemResult, LimitMode, ObjectId, QueryOptions};
use nalgebra::Isometry3;

use crate::robot_demo::{joint_path, register_arm, register_obstacles};
use crate::server_process::ServerProcess;
use crate::stats::{Csv, percentile};
use crate::{BenchError, CommonArgs, io, out_dir};

/// Flags of `gjkd bench robot`.
#[derive(clap::Args, Debug)]
pub struct RobotArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Steps (requests of each kind).
    #[arg(long, default_value_t = 20_000)]
    steps: usize,
    /// Steps along one pass of the joint path (the motion between requests).
    #[arg(long, default_value_t = 1000)]
    path_steps: usize,
}

/// Runs the benchmark.
///
/// # Errors
/// When the server cannot be started or an answer fails.
pub fn run(args: &RobotArgs) -> Result<(), BenchError> {
    let service = format!("gjkd-bench-robot-{}", std::process::id());
    let mut server = io(
        "start gjkd serve",
        ServerProcess::spawn(&service, &["--wait", "spin", "--no-persist"]),
    )?;
    let outcome = measure(&service, args);
    server.stop();
    outcome
}

fn measure(service: &str, args: &RobotArgs) -> Result<(), BenchError> {
    let mut client = Client::builder(service)
        .timeout(std::time::Duration::from_secs(10))
        .connect()?;
    let arm = register_arm(&mut client, "bench_arm")?;
    let obstacles = register_obstacles(&mut client, "bench_obstacle", 10)?;
    // The seven arm links, one per joint (the base never moves; the hand,
    // on fixed joints, is left out so that the pairs are 7 x 10).
    let links: Vec<(usize, ObjectId)> = arm
        .links
        .iter()
        .enumerate()
        .filter_map(|(i, l)| l.map(|l| (i, l)))
        .filter(|&(i, _)| i != arm.kinematics.root())
        .take(7)
        .collect();
    let pairs = links.len() * obstacles.len();
    let options = QueryOptions::default();
    let steps = if args.common.quick { 500 } else { args.steps };
    let mut joint_items: Vec<Item> = Vec::with_capacity(pairs + 1);
    let mut pose_items: Vec<Item> = Vec::with_capacity(pairs);
    let mut results = vec![ItemResult::default(); pairs + 1];
    let mut poses = Vec::new();
    let (mut by_joints, mut by_poses) = (Vec::with_capacity(steps), Vec::with_capacity(steps));
    let base = Isometry3::identity();
    let warmup = steps / 10;
    for step in 0..steps + warmup {
        let t = (step % args.path_steps) as f64 / args.path_steps as f64;
        let q = joint_path(t);

        let start = Instant::now();
        joint_items.clear();
        joint_items.push(Item::set_joints(arm.id, 0, &q, None, false));
        for &(_, link) in &links {
            joint_items.extend(obstacles.iter().map(|&o| Item::distance(link, o, &options)));
        }
        client.query_batch(&joint_items, &mut results)?;
        let joints_time = start.elapsed();
        check(&results[..pairs + 1])?;

        let start = Instant::now();
        let mut q_mut = q;
        arm.kinematics
            .link_poses_into(&base, &mut q_mut, LimitMode::Reject, &mut poses)
            .map_err(|e| BenchError::Other(e.to_string()))?;
        pose_items.clear();
        for &(i, link) in &links {
            pose_items.extend(
                obstacles
                    .iter()
                    .map(|&o| Item::distance(link, o, &options).with_pose_a(&poses[i])),
            );
        }
        client.query_batch(&pose_items, &mut results[..pairs])?;
        let poses_time = start.elapsed();
        check(&results[..pairs])?;
        if step >= warmup {
            by_joints.push(joints_time.as_secs_f64() * 1e6);
            by_poses.push(poses_time.as_secs_f64() * 1e6);
        }
    }
    report(args, pairs, &by_joints, &by_poses)
}

fn check(results: &[ItemResult]) -> Result<(), BenchError> {
    match results.iter().find(|r| r.error != 0) {
        Some(r) => Err(BenchError::Other(format!(
            "an item failed: {}",
            r.error_code()
        ))),
        None => Ok(()),
    }
}

fn report(args: &RobotArgs, pairs: usize, joints: &[f64], poses: &[f64]) -> Result<(), BenchError> {
    let mut diff: Vec<f64> = joints.iter().zip(poses).map(|(a, b)| a - b).collect();
    let (mut joints, mut poses) = (joints.to_vec(), poses.to_vec());
    for v in [&mut joints, &mut poses, &mut diff] {
        v.sort_by(f64::total_cmp);
    }
    println!(
        "gjkd bench robot: a 7-joint arm, 10 obstacles, {pairs} pairs warm along a joint path,\n\
         one request per step, {} steps of each kind, alternating (µs per step, as seen by the client):\n",
        joints.len()
    );
    println!(
        "{:<34} {:>9} {:>9} {:>9} {:>9}",
        "", "p10", "p50", "p90", "p99"
    );
    let mut csv = Csv::new(&["variant", "p10_us", "p50_us", "p90_us", "p99_us"]);
    for (name, v) in [
        ("joints (server FK) + queries", &joints),
        ("client FK + queries with poses", &poses),
        ("difference, step by step", &diff),
    ] {
        let p = [0.1, 0.5, 0.9, 0.99].map(|q| percentile(v, q));
        println!(
            "{name:<34} {:>9.2} {:>9.2} {:>9.2} {:>9.2}",
            p[0], p[1], p[2], p[3]
        );
        csv.row(&[
            name.to_string(),
            p[0].to_string(),
            p[1].to_string(),
            p[2].to_string(),
            p[3].to_string(),
        ]);
    }
    let extra = percentile(&joints, 0.5) - percentile(&poses, 0.5);
    println!("\np50(joints) - p50(client poses) = {extra:.2} µs (target: at most 2 µs)");
    let dir = out_dir(&args.common)?;
    let path = dir.join("robot.csv");
    io(format!("write {}", path.display()), csv.write(&path))?;
    println!("CSV: {}", path.display());
    Ok(())
}
