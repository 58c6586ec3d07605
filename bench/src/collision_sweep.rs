//! `gjkd bench sweep`: the paper's Section 8 as a collision sweep. At each
//! of the path's T + 1 steps, is any obstacle within margin 0 of the moving
//! object? Answered two ways through the same server:
//!
//! - **cold per-pair**: the demo's sweep, every step's five queries cold, in
//!   as few batches as the server's batch limit allows (also with the
//!   margin's early exit, which is all the question needs);
//! - **path request**: one scene request ([`SceneKind::Within`](gjkd_proto::SceneKind::Within), margin 0,
//!   [`PathMode::EveryStep`]) carrying every step's pose, the server
//!   carrying warm starts and motion bounds from step to step; and the same
//!   with [`PathMode::FirstHit`], which stops at the first step that hits.
//!
//! Beside them the paper's Table 1 ratio (cold over warm-started sweeps).
//! The steps that hit are compared between the two ways.

use std::time::Duration;

use gjkd_client::{Client, Item, ObjectId, QueryOptions};
use gjkd_proto::{PathMode, SceneRequest, SceneRow};
use gjkd_testkit::paper::{self, Motion, OBSTACLES};

use crate::scene_inprocess::InProcess;
use crate::served_sweep::{
    Buffers, DemoError, PAPER_RATIOS, PathBuffers, Registered, SERVER_ARGS, path_sweep,
    path_sweep_with, register, sweep,
};
use crate::server_process::ServerProcess;
use crate::stats::Csv;
use crate::{BenchError, CommonArgs, io, out_dir, scene_call};

/// Flags of `gjkd bench sweep`.
#[derive(clap::Args, Debug)]
pub struct SweepArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Path steps T (the sweep has T + 1 poses).
    #[arg(long, value_delimiter = ',', default_values_t = [10usize, 100, 1000])]
    steps: Vec<usize>,
    /// Repetitions of each timed sweep (the median is reported).
    #[arg(long, default_value_t = 15)]
    repeats: usize,
}

/// Runs the benchmark.
///
/// # Errors
/// When the server cannot be started or an answer fails.
pub fn run(args: &SweepArgs) -> Result<(), BenchError> {
    let service = format!("gjkd-bench-sweep-{}", std::process::id());
    let mut server = io(
        "start gjkd serve",
        ServerProcess::spawn(&service, &SERVER_ARGS),
    )?;
    let outcome = measure(&service, args);
    server.stop();
    outcome
}

/// The Section 8 scene in an in-process engine, and its ids.
fn in_process(motion: &Motion) -> Result<(InProcess, Registered), BenchError> {
    let mut engine = InProcess::new();
    let moving = engine.add_shape(motion.moving().clone(), &motion.pose(0.0))?;
    let mut obstacles = [ObjectId::from_raw(0); OBSTACLES];
    for (slot, (shape, pose)) in obstacles.iter_mut().zip(motion.obstacles()) {
        *slot = engine.add_shape(shape.clone(), pose)?;
    }
    Ok((engine, Registered { moving, obstacles }))
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn ms(d: Duration) -> String {
    format!("{:.3} ms", d.as_secs_f64() * 1e3)
}

/// Medians of one T's timings, and what the answers said.
struct Row {
    /// The fastest cold sweep over the fastest path request: the ratio
    /// least disturbed by a loaded machine.
    fastest_ratio: Option<f64>,
    cold: Duration,
    cold_margin: Duration,
    path: Option<Duration>,
    /// The same path handed to the engine in process.
    engine: Duration,
    first: Option<Duration>,
    first_hit: Option<usize>,
    /// Steps whose hits differ between the cold sweep and the path.
    disagree: usize,
    /// The same for the in-process engine's path.
    engine_disagree: usize,
    hitting_steps: usize,
    work: (u64, u64),
}

fn measure_steps(
    client: &mut Client,
    motion: &Motion,
    scene: &Registered,
    t: usize,
    repeats: usize,
) -> Result<Row, BenchError> {
    let max_batch = client.server_info().map_or(1024, |i| i.max_batch as usize);
    let with_scene = scene_call::available();
    let mut buffers = Buffers {
        items: Vec::new(),
        results: Vec::new(),
    };
    let mut path_buf = PathBuffers::new(t);
    let (mut cold, mut cold_margin, mut path, mut first) = (vec![], vec![], vec![], vec![]);
    let mut engine_times = Vec::new();
    let (mut engine, engine_ids) = in_process(motion)?;
    let mut engine_call =
        |r: &SceneRequest, i: &[Item], rows: &mut [SceneRow]| engine.query(r, i, rows);
    let demo = |e: DemoError| BenchError::Other(e.to_string());
    let margin0 = QueryOptions {
        margin: Some(0.0),
        ..QueryOptions::cold()
    };
    let mut row = Row {
        fastest_ratio: None,
        cold: Duration::ZERO,
        cold_margin: Duration::ZERO,
        path: None,
        engine: Duration::ZERO,
        first: None,
        first_hit: None,
        disagree: 0,
        engine_disagree: 0,
        hitting_steps: 0,
        work: (0, 0),
    };
    // Alternate so that drift in the machine's speed hits all alike.
    for _ in 0..repeats.max(1) {
        let c = sweep(
            client,
            motion,
            scene,
            t,
            &QueryOptions::cold(),
            max_batch,
            &mut buffers,
        )
        .map_err(demo)?;
        cold.push(c.elapsed);
        let m = sweep(client, motion, scene, t, &margin0, max_batch, &mut buffers).map_err(demo)?;
        cold_margin.push(m.elapsed);
        row.hitting_steps = c.hits.iter().filter(|&&h| h != 0).count();
        let e = path_sweep_with(
            &mut engine_call,
            motion,
            &engine_ids,
            t,
            PathMode::EveryStep,
            &mut path_buf,
        )?;
        engine_times.push(e.elapsed);
        row.engine_disagree = c.hits.iter().zip(&e.hits).filter(|(a, b)| a != b).count();
        if with_scene {
            let p = path_sweep(client, motion, scene, t, PathMode::EveryStep, &mut path_buf)?;
            let f = path_sweep(client, motion, scene, t, PathMode::FirstHit, &mut path_buf)?;
            path.push(p.elapsed);
            first.push(f.elapsed);
            row.disagree = c.hits.iter().zip(&p.hits).filter(|(a, b)| a != b).count();
            row.first_hit = f.first_hit;
            row.work = p.work;
        }
    }
    if let (Some(c), Some(p)) = (cold.iter().min(), path.iter().min()) {
        row.fastest_ratio = Some(c.as_secs_f64() / p.as_secs_f64().max(1e-12));
    }
    row.engine = median(engine_times);
    row.cold = median(cold);
    row.cold_margin = median(cold_margin);
    if with_scene {
        row.path = Some(median(path));
        row.first = Some(median(first));
    }
    Ok(row)
}

fn measure(service: &str, args: &SweepArgs) -> Result<(), BenchError> {
    let motion = paper::section8();
    let mut client = Client::builder(service)
        .timeout(Duration::from_secs(10))
        .connect()?;
    let scene = register(&mut client, &motion).map_err(|e| BenchError::Other(e.to_string()))?;
    let repeats = if args.common.quick { 2 } else { args.repeats };
    println!(
        "gjkd bench sweep: the paper's Section 8 as a collision sweep through a gjkd server. At each of\n\
         the T + 1 steps, is any obstacle within margin 0? Median of {repeats} runs, as seen by the client.\n\
         Machine: {}; load average {}.\n",
        crate::machine(),
        crate::load_average()
    );
    println!(
        "{:>6} {:>12} {:>12} {:>12} {:>9} {:>9} {:>12} {:>8} {:>7} {:>8}",
        "T",
        "cold",
        "cold, m=0",
        "path",
        "cold/path",
        "fastest",
        "first hit",
        "at step",
        "paper",
        "disagree"
    );
    let mut csv = Csv::new(&[
        "T",
        "cold_ms",
        "cold_margin_ms",
        "path_ms",
        "first_hit_ms",
        "ratio",
        "paper",
    ]);
    for &t in &args.steps {
        let r = measure_steps(&mut client, &motion, &scene, t, repeats)?;
        print_row(t, &r, &mut csv);
    }
    println!(
        "\ncold: the demo's cold per-pair sweep, full distances, 5 queries per step in batches of up\n\
         to {} queries; cold, m=0: the same with the margin-0 early exit; path: one scene request\n\
         (Within, margin 0, EveryStep); cold/path: ratio of the medians; fastest: of the fastest runs;
first hit: the path request stopping at the first step that hits;\n\
         paper: Table 1's cold/warm ratio; disagree: steps whose hits differ between cold and path.",
        client.server_info().map_or(0, |i| i.max_batch as usize) / OBSTACLES * OBSTACLES
    );
    let dir = out_dir(&args.common)?;
    let path = dir.join("sweep.csv");
    io(format!("write {}", path.display()), csv.write(&path))?;
    println!("CSV: {}", path.display());
    Ok(())
}

fn print_row(t: usize, r: &Row, csv: &mut Csv) {
    let paper = PAPER_RATIOS
        .iter()
        .find(|(pt, _)| *pt == t)
        .map_or("-".to_string(), |(_, x)| format!("{x:.1}×"));
    let dash = || "-".to_string();
    let ratio = r
        .path
        .map(|p| r.cold.as_secs_f64() / p.as_secs_f64().max(1e-12));
    println!(
        "{:>6} {:>12} {:>12} {:>12} {:>9} {:>9} {:>12} {:>8} {:>7} {:>8}",
        t,
        ms(r.cold),
        ms(r.cold_margin),
        r.path.map_or_else(dash, ms),
        ratio.map_or_else(dash, |x| format!("{x:.1}×")),
        r.fastest_ratio.map_or_else(dash, |x| format!("{x:.1}×")),
        r.first.map_or_else(dash, ms),
        r.first_hit.map_or_else(dash, |s| s.to_string()),
        paper,
        if r.path.is_some() {
            r.disagree.to_string()
        } else {
            dash()
        },
    );
    let work = if r.path.is_some() {
        format!(
            "; the path request ran GJK {} times, answered {} pairs from motion bounds",
            r.work.0, r.work.1
        )
    } else {
        String::new()
    };
    println!("{:>6} {} of {} steps hit{work}", "", r.hitting_steps, t + 1);
    println!(
        "{:>6} the same path handed to the scene engine in process (no server): {} ({} steps disagree)",
        "",
        ms(r.engine),
        r.engine_disagree
    );
    let opt =
        |d: Option<Duration>| d.map_or(String::new(), |d| (d.as_secs_f64() * 1e3).to_string());
    csv.row(&[
        t.to_string(),
        (r.cold.as_secs_f64() * 1e3).to_string(),
        (r.cold_margin.as_secs_f64() * 1e3).to_string(),
        opt(r.path),
        opt(r.first),
        ratio.map_or(String::new(), |x| x.to_string()),
        r.fastest_ratio.map_or(String::new(), |x| x.to_string()),
        paper,
    ]);
}
