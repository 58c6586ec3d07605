//! `gjkd bench scene-robot`: a 7-link arm among 1 000 obstacles, per step
//! the *clearance* (each link's nearest obstacle) and the pairs *within* 5 %
//! of the arm's size, done four ways in one run:
//!
//! - **parry3d-f64** in process, its BVH over the obstacles and its
//!   distance queries, pruned as its users would write it
//!   ([`crate::scene_parry`]);
//! - **gjkd per-pair**: one request per step through the server, the links'
//!   poses then every link-obstacle pair (warm-started, no broadphase, no
//!   motion bounds; *within* with the margin's early exit);
//! - **gjkd scene**: one scene request per step through the server, the
//!   links' poses and the question
//!   ([`SceneKind::Clearance`], [`SceneKind::Within`]);
//! - **gjkd scene engine, in process**: the same requests handed to the
//!   server's state directly ([`crate::scene_inprocess`]), no round trip:
//!   the engine's own work, for telling it from the transport's.
//!
//! The scene is [`crate::scene_world`]'s. The variants take turns in
//! chunks of consecutive steps, so drift in the machine's speed hits all
//! alike while each still sees an unbroken path. The answers are
//! checked against each other: the same nearest obstacle per link (ties
//! allowed, judged by the per-pair distances) and the same pairs within
//! the margin (pairs within round-off of the margin excepted); the
//! disagreements are counted and printed.

use std::collections::HashMap;
use std::time::Instant;

use gjkd_client::{Client, Item, ItemResult, ObjectId, QueryOptions, Status};
use gjkd_proto::{SceneKind, SceneReply, SceneRequest, SceneRow};
use gjkd_testkit::parry::parry_pose;
use nalgebra::Isometry3;
use parry3d_f64::shape::Shape as ParryShape;

use crate::scene_inprocess::InProcess;
use crate::scene_parry::ParryScene;
use crate::scene_world::{Arm, Obstacles, joint_path};
use crate::server_process::ServerProcess;
use crate::stats::{Csv, Progress, mean, percentile};
use crate::{BenchError, CommonArgs, io, out_dir, scene_call};

/// Flags of `gjkd bench scene-robot`.
#[derive(clap::Args, Debug)]
pub struct SceneRobotArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Steps along the joint path.
    #[arg(long, default_value_t = 1000)]
    steps: usize,
    /// Obstacles.
    #[arg(long, default_value_t = 1000)]
    obstacles: usize,
    /// The margin of *within*, as a share of the arm's size.
    #[arg(long, default_value_t = 0.05)]
    margin: f64,
    /// Seed of the obstacles' shapes and places.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

/// Steps each variant runs in turn: long enough for warm starts and
/// motion bounds to carry from step to step as along an undisturbed path,
/// short enough that drift in the machine's speed hits every variant
/// alike. (A 7 000-pair request between two scene requests would also
/// flush the caches a controller's server keeps hot.)
const CHUNK: usize = 50;

/// The variants, in the table's order.
const VARIANTS: [&str; 4] = [
    "parry3d-f64 in process",
    "gjkd per-pair (server)",
    "gjkd scene (server)",
    "gjkd engine in process",
];

/// Runs the benchmark.
///
/// # Errors
/// When the server cannot be started or an answer fails.
pub fn run(args: &SceneRobotArgs) -> Result<(), BenchError> {
    let service = format!("gjkd-bench-scene-robot-{}", std::process::id());
    let mut server = io(
        "start gjkd serve",
        ServerProcess::spawn(
            &service,
            &["--wait", "spin", "--no-persist", "--max-batch", "16384"],
        ),
    )?;
    let outcome = measure(&service, args);
    server.stop();
    outcome
}

/// The ids a scene holds the arm's links and the obstacles under.
struct Ids {
    links: Vec<ObjectId>,
    /// Obstacle index of an object id.
    index: HashMap<u64, u32>,
}

impl Ids {
    fn new(links: Vec<ObjectId>, obstacles: &[ObjectId]) -> Self {
        let index = obstacles
            .iter()
            .enumerate()
            .map(|(i, o)| (o.raw(), i as u32))
            .collect();
        Ids { links, index }
    }
}

/// The scene, registered and converted.
struct Setup {
    arm: Arm,
    links: Vec<ObjectId>,
    obstacles: Vec<ObjectId>,
    /// The server's ids.
    ids: Ids,
    /// The in-process engine's ids.
    engine_ids: Ids,
    parry: ParryScene,
    parry_links: Vec<Box<dyn ParryShape>>,
    margin: f64,
}

fn setup(
    client: &mut Client,
    args: &SceneRobotArgs,
    steps: usize,
) -> Result<(Setup, InProcess), BenchError> {
    let arm = Arm::new();
    let count = if args.common.quick {
        args.obstacles.min(200)
    } else {
        args.obstacles
    };
    let world = Obstacles::new(&arm, count, steps, args.seed);
    let mut poses = Vec::new();
    arm.link_poses(&joint_path(0.0), &mut poses);
    let links = arm
        .links
        .iter()
        .zip(&poses)
        .enumerate()
        .map(|(i, ((b, _), p))| client.register_named(&format!("arm_link{i}"), &b.geometry(), p))
        .collect::<Result<Vec<_>, _>>()?;
    let obstacles = world
        .bodies
        .iter()
        .enumerate()
        .map(|(i, (b, p))| client.register_named(&format!("obstacle{i}"), &b.geometry(), p))
        .collect::<Result<Vec<_>, _>>()?;
    let mut engine = InProcess::new();
    let engine_links = arm
        .links
        .iter()
        .zip(&poses)
        .map(|((b, _), p)| engine.add(b, p))
        .collect::<Result<Vec<_>, _>>()?;
    let engine_obstacles = world
        .bodies
        .iter()
        .map(|(b, p)| engine.add(b, p))
        .collect::<Result<Vec<_>, _>>()?;
    let parry = ParryScene::new(&world.bodies)?;
    let parry_links = arm
        .links
        .iter()
        .map(|(b, _)| b.parry())
        .collect::<Result<Vec<_>, _>>()?;
    let margin = args.margin * arm.size();
    let setup = Setup {
        ids: Ids::new(links.clone(), &obstacles),
        engine_ids: Ids::new(engine_links, &engine_obstacles),
        arm,
        links,
        obstacles,
        parry,
        parry_links,
        margin,
    };
    Ok((setup, engine))
}

/// One step's answers of one variant: per link the nearest obstacle, and
/// the pairs (link, obstacle) within the margin, sorted.
#[derive(Default)]
struct Answers {
    nearest: Vec<Option<(u32, f64)>>,
    within: Vec<(u32, u32)>,
}

/// Timings (µs per step) and answers' statistics of one variant.
#[derive(Default)]
struct Tally {
    clearance: Vec<f64>,
    within: Vec<f64>,
    /// Pairs found within the margin, over all steps.
    within_pairs: usize,
    /// The smallest clearance found along the path.
    closest: f64,
    nearest_disagree: usize,
    within_disagree: usize,
    max_distance_gap: f64,
    gjk_runs: u64,
    bounded: u64,
    candidates: u64,
}

/// Reusable buffers of the gjkd variants.
struct Buffers {
    items: Vec<Item>,
    results: Vec<ItemResult>,
    rows: Vec<SceneRow>,
    /// Every pair's distance of the step (link-major), from the per-pair
    /// clearance: the judge of ties.
    all: Vec<f64>,
}

fn measure(service: &str, args: &SceneRobotArgs) -> Result<(), BenchError> {
    let steps = if args.common.quick {
        args.steps.min(100)
    } else {
        args.steps
    };
    let connect = || {
        Client::builder(service)
            .timeout(std::time::Duration::from_secs(10))
            .connect()
    };
    // Separate clients, so that each variant warm-starts from its own
    // caches only.
    let (mut pair_client, mut scene_client) = (connect()?, connect()?);
    let (s, mut engine) = setup(&mut pair_client, args, steps)?;
    let with_scene = scene_call::available();
    let pairs = s.links.len() * s.obstacles.len();
    let mut buf = Buffers {
        items: Vec::with_capacity(pairs + 2 * s.links.len()),
        results: vec![ItemResult::default(); pairs + s.links.len()],
        rows: vec![SceneRow::default(); 4096],
        all: vec![0.0; pairs],
    };
    let mut tallies: [Tally; 4] = Default::default();
    for t in &mut tallies {
        t.closest = f64::INFINITY;
    }
    let mut floor = Vec::with_capacity(steps);
    let progress = Progress::new(steps as u64);
    progress.step("scene-robot");
    let mut chunk_start = 0;
    while chunk_start < steps {
        let chunk: Vec<Vec<Isometry3<f64>>> = (chunk_start..steps.min(chunk_start + CHUNK))
            .map(|step| {
                let mut poses = Vec::new();
                s.arm
                    .link_poses(&joint_path(step as f64 / steps as f64), &mut poses);
                poses
            })
            .collect();
        let parry: Vec<Answers> = chunk
            .iter()
            .map(|poses| parry_step(&s, poses, &mut tallies[0]))
            .collect();
        let mut scene = Vec::with_capacity(chunk.len());
        let mut in_process = Vec::with_capacity(chunk.len());
        if with_scene {
            let mut call = |r: &SceneRequest, i: &[Item], rows: &mut [SceneRow]| {
                scene_call::query(&mut scene_client, r, i, rows)
            };
            for poses in &chunk {
                let t = &mut tallies[2];
                scene.push(scene_step(&mut call, &s, &s.ids, poses, &mut buf, t)?);
            }
        }
        let mut call =
            |r: &SceneRequest, i: &[Item], rows: &mut [SceneRow]| engine.query(r, i, rows);
        for poses in &chunk {
            let t = &mut tallies[3];
            in_process.push(scene_step(
                &mut call,
                &s,
                &s.engine_ids,
                poses,
                &mut buf,
                t,
            )?);
        }
        for poses in &chunk {
            floor.push(round_trip_floor(&mut pair_client, &s, poses, &mut buf)?);
        }
        for (k, poses) in chunk.iter().enumerate() {
            let g = pair_step(&mut pair_client, &s, poses, &mut buf, &mut tallies[1])?;
            judge(&s, &buf.all, &g, &g, &mut tallies[1]);
            judge(&s, &buf.all, &g, &parry[k], &mut tallies[0]);
            if let Some(sc) = scene.get(k) {
                judge(&s, &buf.all, &g, sc, &mut tallies[2]);
            }
            judge(&s, &buf.all, &g, &in_process[k], &mut tallies[3]);
            progress.inc();
        }
        chunk_start += chunk.len();
    }
    progress.finish();
    report(args, &s, steps, with_scene, &mut tallies)?;
    let f = summary(&floor);
    println!(
        "Round-trip floor: a request carrying only the 7 link poses took {:.1} µs mean, {:.1} µs p50, \
         {:.1} µs p99.",
        f[0], f[1], f[3]
    );
    Ok(())
}

/// Time (µs) of a request that only stores the links' poses: what any
/// gjkd answer pays before the first pair.
fn round_trip_floor(
    client: &mut Client,
    s: &Setup,
    poses: &[Isometry3<f64>],
    buf: &mut Buffers,
) -> Result<f64, BenchError> {
    let start = Instant::now();
    buf.items.clear();
    buf.items.extend(
        s.links
            .iter()
            .zip(poses)
            .map(|(&l, p)| Item::set_pose(l, p)),
    );
    client.query_batch(&buf.items, &mut buf.results)?;
    Ok(start.elapsed().as_secs_f64() * 1e6)
}

fn parry_step(s: &Setup, poses: &[Isometry3<f64>], tally: &mut Tally) -> Answers {
    let mut a = Answers::default();
    let start = Instant::now();
    let poses: Vec<_> = poses.iter().map(parry_pose).collect();
    for (link, pose) in s.parry_links.iter().zip(&poses) {
        a.nearest.push(s.parry.clearance(&**link, pose));
    }
    tally.clearance.push(start.elapsed().as_secs_f64() * 1e6);
    let start = Instant::now();
    let mut found = Vec::new();
    for (k, (link, pose)) in s.parry_links.iter().zip(&poses).enumerate() {
        found.clear();
        s.parry.within(&**link, pose, s.margin, &mut found);
        a.within.extend(found.iter().map(|&o| (k as u32, o)));
    }
    tally.within.push(start.elapsed().as_secs_f64() * 1e6);
    a.within.sort_unstable();
    a
}

/// The per-pair items of a step: the links' poses, then every pair.
fn pair_items(s: &Setup, poses: &[Isometry3<f64>], options: &QueryOptions, items: &mut Vec<Item>) {
    items.clear();
    items.extend(
        s.links
            .iter()
            .zip(poses)
            .map(|(&l, p)| Item::set_pose(l, p)),
    );
    for &l in &s.links {
        items.extend(s.obstacles.iter().map(|&o| Item::distance(l, o, options)));
    }
}

fn pair_step(
    client: &mut Client,
    s: &Setup,
    poses: &[Isometry3<f64>],
    buf: &mut Buffers,
    tally: &mut Tally,
) -> Result<Answers, BenchError> {
    let n = s.links.len();
    let per_link = s.obstacles.len();
    let mut a = Answers::default();
    let start = Instant::now();
    pair_items(s, poses, &QueryOptions::default(), &mut buf.items);
    client.query_batch(&buf.items, &mut buf.results)?;
    for (k, answers) in buf.results[n..n + n * per_link]
        .chunks(per_link)
        .enumerate()
    {
        let mut best: Option<(u32, f64)> = None;
        for (o, r) in answers.iter().enumerate() {
            let d = r.answer().map_err(BenchError::from_code)?.distance;
            buf.all[k * per_link + o] = d;
            if best.is_none_or(|(_, b)| d < b) {
                best = Some((o as u32, d));
            }
        }
        a.nearest.push(best);
    }
    tally.clearance.push(start.elapsed().as_secs_f64() * 1e6);
    let start = Instant::now();
    let options = QueryOptions {
        margin: Some(s.margin),
        ..QueryOptions::default()
    };
    pair_items(s, poses, &options, &mut buf.items);
    client.query_batch(&buf.items, &mut buf.results)?;
    for (k, answers) in buf.results[n..n + n * per_link]
        .chunks(per_link)
        .enumerate()
    {
        for (o, r) in answers.iter().enumerate() {
            let answer = r.answer().map_err(BenchError::from_code)?;
            let inside = match answer.status {
                Some(Status::Closer) => true,
                Some(Status::Farther) => false,
                _ => answer.distance <= s.margin,
            };
            if inside {
                a.within.push((k as u32, o as u32));
            }
        }
    }
    tally.within.push(start.elapsed().as_secs_f64() * 1e6);
    Ok(a)
}

/// The scene request of a step: the links' poses, the group's members.
fn scene_items(links: &[ObjectId], poses: &[Isometry3<f64>], items: &mut Vec<Item>) {
    items.clear();
    items.extend(links.iter().zip(poses).map(|(&l, p)| Item::set_pose(l, p)));
    items.extend(links.iter().map(|&l| Item::member(l)));
}

/// How a scene request is sent: through a client, or to the engine in
/// process.
type SceneCall<'a> =
    dyn FnMut(&SceneRequest, &[Item], &mut [SceneRow]) -> Result<SceneReply, BenchError> + 'a;

fn scene_step(
    call: &mut SceneCall<'_>,
    s: &Setup,
    ids: &Ids,
    poses: &[Isometry3<f64>],
    buf: &mut Buffers,
    tally: &mut Tally,
) -> Result<Answers, BenchError> {
    let mut a = Answers {
        nearest: vec![None; ids.links.len()],
        within: Vec::new(),
    };
    let link_index = |id: u64| ids.links.iter().position(|l| l.raw() == id);
    let start = Instant::now();
    scene_items(&ids.links, poses, &mut buf.items);
    let mut request = SceneRequest::new(SceneKind::Clearance, 0);
    request.max_rows = buf.rows.len() as u32;
    let reply = call(&request, &buf.items, &mut buf.rows)?;
    for row in &buf.rows[..reply_rows(&reply)?] {
        let (Some(k), Some(&o)) = (link_index(row.a), ids.index.get(&row.b)) else {
            continue;
        };
        a.nearest[k] = Some((o, row.result.distance));
    }
    tally.clearance.push(start.elapsed().as_secs_f64() * 1e6);
    count_work(tally, &reply);
    let start = Instant::now();
    scene_items(&ids.links, poses, &mut buf.items);
    let mut request = SceneRequest::new(SceneKind::Within, 0);
    request.margin = s.margin;
    request.max_rows = buf.rows.len() as u32;
    let reply = call(&request, &buf.items, &mut buf.rows)?;
    for row in &buf.rows[..reply_rows(&reply)?] {
        if let (Some(k), Some(&o)) = (link_index(row.a), ids.index.get(&row.b)) {
            a.within.push((k as u32, o));
        }
    }
    tally.within.push(start.elapsed().as_secs_f64() * 1e6);
    count_work(tally, &reply);
    a.within.sort_unstable();
    Ok(a)
}

/// The number of rows of a reply, or an error when it was truncated (the
/// buffer is sized so that it never is).
fn reply_rows(reply: &SceneReply) -> Result<usize, BenchError> {
    if reply.flags & gjkd_proto::scene_reply_flags::TRUNCATED != 0 {
        return Err(BenchError::Other(format!(
            "a scene reply was truncated ({} rows)",
            reply.total
        )));
    }
    Ok(reply.total as usize)
}

fn count_work(tally: &mut Tally, reply: &SceneReply) {
    tally.gjk_runs += reply.gjk_runs;
    tally.bounded += reply.bounded;
    tally.candidates += reply.candidates;
}

/// Compares `got` with the per-pair answers `reference`, judging ties and
/// the margin's edge by `all`, the per-pair distances of the step.
fn judge(s: &Setup, all: &[f64], reference: &Answers, got: &Answers, tally: &mut Tally) {
    judge_answers(s.obstacles.len(), s.margin, all, reference, got, tally);
}

/// [`judge`] for `per_link` obstacles and margin `margin`.
fn judge_answers(
    per_link: usize,
    margin: f64,
    all: &[f64],
    reference: &Answers,
    got: &Answers,
    tally: &mut Tally,
) {
    tally.within_pairs += got.within.len();
    tally.closest = got
        .nearest
        .iter()
        .flatten()
        .fold(tally.closest, |m, &(_, d)| m.min(d));
    let near = |x: f64, y: f64| (x - y).abs() <= 1e-6 * (1.0 + x.abs().max(y.abs()));
    for (k, (r, g)) in reference.nearest.iter().zip(&got.nearest).enumerate() {
        match (r, g) {
            (Some((ro, rd)), Some((go, gd))) => {
                tally.max_distance_gap = tally.max_distance_gap.max((rd - gd).abs());
                let row = &all[k * per_link..(k + 1) * per_link];
                if ro != go && !near(row[*ro as usize], row[*go as usize]) {
                    tally.nearest_disagree += 1;
                }
            }
            (None, None) => {}
            _ => tally.nearest_disagree += 1,
        }
    }
    let on_edge = |&(k, o): &(u32, u32)| near(all[k as usize * per_link + o as usize], margin);
    let missing = reference
        .within
        .iter()
        .filter(|p| got.within.binary_search(p).is_err() && !on_edge(p));
    let extra = got
        .within
        .iter()
        .filter(|p| reference.within.binary_search(p).is_err() && !on_edge(p));
    tally.within_disagree += missing.count() + extra.count();
}

fn summary(v: &[f64]) -> [f64; 4] {
    let mut sorted = v.to_vec();
    sorted.sort_by(f64::total_cmp);
    [
        mean(v),
        percentile(&sorted, 0.5),
        percentile(&sorted, 0.9),
        percentile(&sorted, 0.99),
    ]
}

fn report(
    args: &SceneRobotArgs,
    s: &Setup,
    steps: usize,
    with_scene: bool,
    tallies: &mut [Tally; 4],
) -> Result<(), BenchError> {
    println!(
        "gjkd bench scene-robot: a 7-link arm (capsules, boxes, polytopes) along a {steps}-step joint path\n\
         among {} obstacles (boxes, balls, polytopes of 8 to 64 vertices); within = {:.0} % of the arm's\n\
         size ({:.3} m). µs per step as seen by the caller (gjkd: one round trip per question).\n\
         Machine: {}; load average {}.\n",
        s.obstacles.len(),
        args.margin * 100.0,
        s.margin,
        crate::machine(),
        crate::load_average()
    );
    println!(
        "{:<24} | {:>8} {:>8} {:>8} {:>8} {:>7} {:>7} | {:>8} {:>8} {:>8} {:>8} {:>7} {:>7}",
        "clearance / within:",
        "mean",
        "p50",
        "p90",
        "p99",
        "mean/P",
        "p50/P",
        "mean",
        "p50",
        "p90",
        "p99",
        "mean/P",
        "p50/P"
    );
    let mut csv = Csv::new(&[
        "variant",
        "question",
        "mean_us",
        "p50_us",
        "p90_us",
        "p99_us",
        "ratio_to_parry",
    ]);
    let base = [summary(&tallies[0].clearance), summary(&tallies[0].within)];
    let shown: &[usize] = if with_scene {
        &[0, 1, 2, 3]
    } else {
        &[0, 1, 3]
    };
    for &v in shown {
        let (name, t) = (VARIANTS[v], &tallies[v]);
        let mut line = format!("{name:<24}");
        for (q, (v, b)) in [&t.clearance, &t.within].into_iter().zip(&base).enumerate() {
            let x = summary(v);
            let ratio = x[0] / b[0];
            line.push_str(&format!(
                " | {:>8.1} {:>8.1} {:>8.1} {:>8.1} {:>7.3} {:>7.3}",
                x[0],
                x[1],
                x[2],
                x[3],
                ratio,
                x[1] / b[1]
            ));
            let question = ["clearance", "within"][q];
            let mut row = vec![name.to_string(), question.to_string()];
            row.extend(x.iter().map(f64::to_string));
            row.push(ratio.to_string());
            row.push((x[1] / b[1]).to_string());
            csv.row(&row);
        }
        println!("{line}");
    }
    println!();
    report_agreement(tallies, shown, steps);
    let dir = out_dir(&args.common)?;
    let path = dir.join("scene-robot.csv");
    io(format!("write {}", path.display()), csv.write(&path))?;
    println!("CSV: {}", path.display());
    Ok(())
}

fn report_agreement(tallies: &[Tally; 4], shown: &[usize], steps: usize) {
    println!(
        "Agreement with gjkd's per-pair answers (nearest obstacle per link, ties allowed; pairs within the margin):"
    );
    for &v in shown {
        let (name, t) = (VARIANTS[v], &tallies[v]);
        println!(
            "  {name:<24} {} nearest disagree, {} within-pairs disagree, largest nearest-distance gap {:.2e} m",
            t.nearest_disagree, t.within_disagree, t.max_distance_gap
        );
    }
    if let Some(t) = tallies.get(1) {
        println!(
            "  (the path's closest approach: {:.4} m; {:.2} pairs within the margin per step on average)",
            t.closest,
            t.within_pairs as f64 / steps as f64
        );
    }
    if shown.contains(&2) {
        let t = &tallies[2];
        let per = |x: u64| x as f64 / (2 * steps) as f64;
        println!(
            "  gjkd scene work per request: {:.1} broadphase candidates, {:.1} GJK runs, {:.1} answered from motion bounds",
            per(t.candidates),
            per(t.gjk_runs),
            per(t.bounded)
        );
        let c = mean(&t.clearance) / mean(&tallies[0].clearance);
        let m = summary(&t.clearance)[1] / summary(&tallies[0].clearance)[1];
        println!(
            "\ngjkd scene / parry3d-f64, clearance per step: {c:.3} by the mean, {m:.3} by the median \
             (target: at most 0.5)"
        );
    } else {
        println!("\n(no scene column: this build's client has no scene requests)");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn judging_allows_ties_and_the_margins_edge_only() {
        // Two links, three obstacles; obstacles 0 and 1 tie for link 0.
        let all = [0.5, 0.5, 0.9, 0.2, 0.1 + 1e-12, 0.05];
        let reference = Answers {
            nearest: vec![Some((0, 0.5)), Some((2, 0.05))],
            within: vec![(1, 1), (1, 2)],
        };
        let mut tally = Tally::default();
        let tie = Answers {
            nearest: vec![Some((1, 0.5)), Some((2, 0.05))],
            // (1, 1) is within round-off of the margin: leaving it out is
            // no disagreement.
            within: vec![(1, 2)],
        };
        judge_answers(3, 0.1, &all, &reference, &tie, &mut tally);
        assert_eq!((tally.nearest_disagree, tally.within_disagree), (0, 0));
        let wrong = Answers {
            nearest: vec![Some((2, 0.9)), None],
            within: vec![(0, 0), (1, 1)],
        };
        judge_answers(3, 0.1, &all, &reference, &wrong, &mut tally);
        // A farther obstacle and a missing answer; an extra pair and a
        // missing one.
        assert_eq!((tally.nearest_disagree, tally.within_disagree), (2, 2));
        assert_eq!(tally.within_pairs, 1 + 2);
    }
}
