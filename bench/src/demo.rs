//! `gjkd demo`: the paper's Section 8 experiment, run through a real server.
//!
//! It starts `gjkd serve` as a child process on a private service name,
//! registers the Section 8 scene (a compound object moving and turning
//! through five fixed obstacles, from `gjkd_paper::section8`) through the
//! client library, sweeps the path at T = 10, 100 and 1000 steps, and prints
//! the distance to each obstacle along the path and the time of cold-started
//! sweeps against sweeps warm-started from the server's per-pair cache, beside
//! the paper's Table 1.
//!
//! Then a robot ([`crate::robot_demo`]): a 7-joint arm from a built-in
//! URDF sweeps a joint path among obstacles, one joint request per step,
//! and its links' clearances are printed.
//!
//! Each sweep is sent as few batches as the server's batch limit allows, every
//! item carrying the moving object's pose of its step: the items of a batch
//! are applied in order, so each step's query of an obstacle starts from the
//! simplex the previous step left for that pair, exactly as in the paper.

use std::io::Write;
use std::time::{Duration, Instant};

use gjk::Options;
use gjkd_client::{Client, QueryOptions};
use gjkd_paper::{self as paper, Motion, OBSTACLES};

pub use crate::served_sweep::DemoError;
use crate::served_sweep::{
    Buffers, PAPER_RATIOS, PathBuffers, Registered, SERVER_ARGS, path_sweep, register, sweep,
};
pub use crate::server_process::ServerProcess;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// The flags of `gjkd demo`.
#[derive(clap::Args, Debug)]
pub struct DemoArgs {
    /// Sweep steps to time, besides the paper's 10, 100 and 1000.
    #[arg(long, value_delimiter = ',', default_values_t = [10usize, 100, 1000])]
    pub steps: Vec<usize>,
    /// Repetitions of each timed sweep (the median is reported).
    #[arg(long, default_value_t = 7)]
    pub repeats: usize,
}

/// Runs the demo, printing to stdout.
///
/// # Errors
/// [`DemoError`] when the server cannot be started or reached, or an answer
/// disagrees with the in-process computation.
pub fn run(steps: &[usize], repeats: usize) -> Result<(), DemoError> {
    let service = format!("gjkd-demo-{}", std::process::id());
    let mut server = ServerProcess::spawn(&service, &SERVER_ARGS).map_err(DemoError::Spawn)?;
    let outcome = run_with_server(&service, steps, repeats);
    let clean = server.stop();
    let () = outcome?;
    if !clean {
        eprintln!("gjkd demo: the server did not exit cleanly");
    }
    Ok(())
}

fn run_with_server(service: &str, steps: &[usize], repeats: usize) -> Result<(), DemoError> {
    let mut out = std::io::stdout().lock();
    let motion = paper::section8();
    let mut client = Client::builder(service)
        .timeout(Duration::from_secs(10))
        .connect()?;
    let max_batch = client.server_info().map_or(1024, |i| i.max_batch as usize);
    let scene = register(&mut client, &motion)?;
    let mut buffers = Buffers {
        items: Vec::new(),
        results: Vec::new(),
    };

    let _ = writeln!(
        out,
        "gjkd demo: Section 8 of Gilbert, Johnson & Keerthi (1986) through a gjkd server\n\
         (service `{service}`, server pid {}, busy-polling). A compound object of two convex\n\
         pieces (20 vertices) moves and turns along its path through five fixed obstacles.\n",
        client.server_info().map_or(0, |i| i.pid)
    );

    // The distances along the path, checked against the library in-process.
    let t_plot = 100;
    let served = sweep(
        &mut client,
        &motion,
        &scene,
        t_plot,
        &QueryOptions::cold(),
        max_batch,
        &mut buffers,
    )?;
    let local = motion
        .sweep(
            t_plot,
            &Options {
                warm_start: false,
                ..Options::default()
            },
            false,
        )
        .map_err(|e| DemoError::Check(format!("in-process sweep: {e}")))?;
    let identical = served
        .distances
        .iter()
        .flatten()
        .zip(local.distances.iter().flatten())
        .all(|(a, b)| a.to_bits() == b.to_bits());
    if !identical {
        return Err(DemoError::Check(
            "the server's distances differ from the in-process ones".into(),
        ));
    }
    print_plot(&mut out, &served.distances);
    let _ = writeln!(
        out,
        "All {} distances equal the in-process gjk answers bit for bit.\n",
        served.distances.len() * OBSTACLES
    );

    let _ = writeln!(
        out,
        "Time of a sweep of T steps (5(T+1) queries, median of {repeats}), cold start against the\n\
         server's per-pair warm start, beside the paper's Table 1 (a Harris 800 in 1986):\n"
    );
    let _ = writeln!(
        out,
        "{:>6} {:>8} {:>12} {:>12} {:>10} {:>10} {:>7} {:>10} {:>7}",
        "T", "queries", "cold", "warm", "cold/query", "warm/query", "ratio", "in-process", "paper"
    );
    for &t in steps {
        let mut cold = Vec::with_capacity(repeats);
        let mut warm = Vec::with_capacity(repeats);
        let (mut it_cold, mut it_warm) = (0, 0);
        let (mut local_cold, mut local_warm) = (Vec::new(), Vec::new());
        let opts = Options::default();
        // Alternate so that drift in the machine's speed hits both alike.
        for _ in 0..repeats {
            let start = Instant::now();
            motion
                .sweep(t, &opts, false)
                .map_err(|e| DemoError::Check(format!("in-process sweep: {e}")))?;
            local_cold.push(start.elapsed());
            let start = Instant::now();
            motion
                .sweep(t, &opts, true)
                .map_err(|e| DemoError::Check(format!("in-process sweep: {e}")))?;
            local_warm.push(start.elapsed());
            let c = sweep(
                &mut client,
                &motion,
                &scene,
                t,
                &QueryOptions::cold(),
                max_batch,
                &mut buffers,
            )?;
            let w = sweep(
                &mut client,
                &motion,
                &scene,
                t,
                &QueryOptions::default(),
                max_batch,
                &mut buffers,
            )?;
            it_cold = c.iterations;
            it_warm = w.iterations;
            cold.push(c.elapsed);
            warm.push(w.elapsed);
        }
        let (c, w) = (median(cold), median(warm));
        let local_ratio =
            median(local_cold).as_secs_f64() / median(local_warm).as_secs_f64().max(1e-12);
        let queries = (t + 1) * OBSTACLES;
        let per = |d: Duration| format!("{:.2} µs", d.as_secs_f64() * 1e6 / queries as f64);
        let paper = PAPER_RATIOS
            .iter()
            .find(|(pt, _)| *pt == t)
            .map_or("-".to_string(), |(_, r)| format!("{r:.1}×"));
        let _ = writeln!(
            out,
            "{:>6} {:>8} {:>12} {:>12} {:>10} {:>10} {:>6.1}× {:>9.1}× {:>7}",
            t,
            queries,
            format!("{:.3} ms", c.as_secs_f64() * 1e3),
            format!("{:.3} ms", w.as_secs_f64() * 1e3),
            per(c),
            per(w),
            c.as_secs_f64() / w.as_secs_f64().max(1e-12),
            local_ratio,
            paper
        );
        let _ = writeln!(
            out,
            "{:>6} {:>8} {:>12} {:>12}   (subalgorithm iterations)",
            "", "", it_cold, it_warm
        );
        collision_row(&mut out, &mut client, &motion, &scene, t, repeats, c)?;
    }
    let _ = writeln!(out);
    crate::contact_intervals::print(&mut out, &mut client, &motion, &scene, 1000)?;
    let stats = client.stats()?;
    let _ = writeln!(
        out,
        "\nServer: {} requests, {} items; warm-start cache {} of {} entries, {} hits, {} misses, {} evictions.",
        stats.requests,
        stats.items,
        stats.cache_entries,
        stats.cache_capacity,
        stats.cache_hits,
        stats.cache_misses,
        stats.cache_evictions
    );
    let _ = writeln!(
        out,
        "Times are as seen by the client, batches of up to {} queries per round trip;\n\
         `in-process` is the same ratio for the gjk library called directly, for reference.",
        (max_batch / OBSTACLES).max(1) * OBSTACLES
    );
    let _ = writeln!(out);
    crate::robot_demo::run(&mut client, &mut out, 20)?;
    Ok(())
}

/// The collision-sweep row of the table: is any obstacle within margin 0
/// at each step, as one path request through the server, against `cold`,
/// the cold sweep's time.
fn collision_row(
    out: &mut impl Write,
    client: &mut Client,
    motion: &Motion,
    scene: &Registered,
    t: usize,
    repeats: usize,
    cold: Duration,
) -> Result<(), DemoError> {
    if !crate::scene_call::available() {
        let _ = writeln!(
            out,
            "{:>6} {:>8} (collision sweep: this build has no scene requests)",
            "", ""
        );
        return Ok(());
    }
    let mut buf = PathBuffers::new(t);
    let mut times = Vec::with_capacity(repeats);
    let mut hits = 0;
    for _ in 0..repeats {
        let p = path_sweep(
            client,
            motion,
            scene,
            t,
            gjkd_proto::PathMode::EveryStep,
            &mut buf,
        )
        .map_err(|e| DemoError::Check(format!("path request: {e}")))?;
        hits = p.hits.iter().filter(|&&h| h != 0).count();
        times.push(p.elapsed);
    }
    let path = median(times);
    let _ = writeln!(
        out,
        "{:>6} {:>8} {:>12}   collision sweep (any obstacle within margin 0?) as one path request: \
         cold / path {:.1}×; {hits} of {} steps hit",
        "",
        "",
        format!("{:.3} ms", path.as_secs_f64() * 1e3),
        cold.as_secs_f64() / path.as_secs_f64().max(1e-12),
        t + 1
    );
    Ok(())
}

/// Distances along the path: one sparkline per obstacle (`█` high, `▁` near,
/// `×` touching or overlapping) and a table at every tenth of the path.
fn print_plot(out: &mut impl Write, d: &[[f64; OBSTACLES]]) {
    const BARS: [char; 8] = ['▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];
    let max = d.iter().flatten().fold(0.0f64, |m, &x| m.max(x)).max(1e-12);
    let steps = d.len().saturating_sub(1).max(1);
    let _ = writeln!(
        out,
        "Distance to each obstacle along the path, s = 0 → 1 ({} steps; full bar = {max:.2}):",
        steps
    );
    for i in 0..OBSTACLES {
        let line: String = d
            .iter()
            .step_by(2)
            .map(|row| {
                let x = row[i];
                if x <= 0.0 {
                    '×'
                } else {
                    BARS[((x / max) * (BARS.len() - 1) as f64).round() as usize]
                }
            })
            .collect();
        let _ = writeln!(out, "  d{} {line}", i + 1);
    }
    let _ = writeln!(out);
    let _ = write!(out, "{:>6}", "s");
    for i in 0..OBSTACLES {
        let _ = write!(out, " {:>8}", format!("d{}", i + 1));
    }
    let _ = writeln!(out);
    for k in 0..=10 {
        let t = k * steps / 10;
        let _ = write!(out, "{:>6.2}", t as f64 / steps as f64);
        for x in d[t.min(d.len() - 1)] {
            let _ = write!(out, " {x:>8.4}");
        }
        let _ = writeln!(out);
    }
    let _ = writeln!(out);
}
