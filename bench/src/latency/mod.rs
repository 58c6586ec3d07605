//! `gjkd bench latency`: the round trip a client sees, through every way of
//! asking, on the same messages, in one run; quiet or beside competing busy
//! processes, pinned or not.
//!
//! Six transports answer the same requests:
//!
//! - `spin`, `block`, `adaptive`: a real `gjkd serve --wait MODE` child
//!   process (this executable) and a [`gjkd_client::Client`];
//! - `iceoryx2`: a bare iceoryx2 request-response server child
//!   ([`super::raw_ipc`]), both sides busy-polling, no GJK: the floor of
//!   the transport;
//! - `uds`: a Unix-stream-socket server with blocking reads, also a child
//!   process of its own (`gjkd bench uds-server`, [`super::uds`]);
//! - `in-process`: [`State::handle`](gjkd_server::engine::State::handle) called directly, the GJK work alone.
//!
//! Each is asked a single pair (`Client::distance`, the pair at its stored
//! poses) and batches of 1, 8, 64 and 512 distinct box pairs, each item with
//! its own pose, warm-started as the server does by default; back to back,
//! and paced: a busy-wait of each `--gap-us` (100 µs by default; a list)
//! between the end of one request and the start of the next. Servers run
//! one at a time, so a spinning server never steals the core of the one
//! being measured.
//!
//! A condition is a number of competing busy processes (`--competitors`,
//! [`super::busy`]; started before the condition, killed by process id
//! after it) and a placement (`--pinning`: client on CPU 0 and servers on
//! CPU 1, or wherever the scheduler puts them); every condition gets a
//! table of its own. `--contention` measures the deployment guide's set in
//! one command: single pairs at gaps of 10 µs, 100 µs and 1 ms (a 1 kHz
//! control loop) and back to back, quiet and beside one busy process,
//! pinned and not.
//!
//! Each configuration sends `--requests` requests (100 000 by default)
//! unless that would take longer than `--max-seconds`; then it sends fewer,
//! never fewer than `--min-requests`, and the table says how many.
//!
//! One file a concept: the flags and conditions (`args.rs`), the run's
//! settings (`plan.rs`), the transports and their timing (`transport.rs`),
//! a measured row (`row.rs`), tables (`report.rs`) and plots (`charts.rs`);
//! this file runs them.

use std::path::Path;
use std::time::{Duration, Instant};

use hdrhistogram::Histogram;

use crate::busy::Competitors;
use crate::stats::Progress;
use crate::{BenchError, out_dir};

mod args;
mod charts;
mod plan;
mod report;
mod row;
mod transport;

pub use self::args::{Condition, LatencyArgs, Pinning};
pub use self::row::Row;
pub use self::transport::{Transport, Workload, core_round_trip_ns};

use self::plan::Plan;
use self::report::report;
use self::transport::{Target, measure, spin_until, start};

/// How many requests fit the time budget, from a timed warm-up (which also
/// fills the server's warm-start cache).
fn plan(
    plan: &Plan,
    target: &mut Target,
    w: Workload,
    gap: Option<Duration>,
) -> Result<u64, BenchError> {
    let warm = if plan.quick { 50 } else { 500 };
    let t0 = Instant::now();
    let mut last = t0;
    for _ in 0..warm {
        if let Some(g) = gap {
            spin_until(last + g);
        }
        target.call(w)?;
        last = Instant::now();
    }
    let per = t0.elapsed().as_secs_f64() / f64::from(warm);
    let fit = (plan.max_seconds / per) as u64;
    Ok(fit.clamp(plan.min_requests.min(plan.requests), plan.requests))
}

/// Runs `gjkd bench latency`.
///
/// # Errors
/// When a server cannot be started or a request fails.
pub fn run(args: &LatencyArgs) -> Result<(), BenchError> {
    let plan = Plan::new(args);
    let dir = out_dir(&args.common)?;
    let max_batch = plan.batches.iter().copied().max().unwrap_or(1).max(1);
    let mut workloads = vec![Workload::Single];
    workloads.extend(plan.batches.iter().map(|&n| Workload::Batch(n)));
    let mut gaps = vec![None];
    gaps.extend(plan.gaps.iter().copied().map(Some));
    let per_condition = plan.transports.len() * workloads.len() * gaps.len();
    println!(
        "gjkd bench latency: {} conditions x {} transports x {} request shapes x {} pacings, up to {} requests each (at most ~{} s per configuration)\nmachine: {}",
        plan.conditions.len(),
        plan.transports.len(),
        workloads.len(),
        gaps.len(),
        plan.requests,
        plan.max_seconds,
        crate::machine()
    );
    let two_cpus = std::thread::available_parallelism().is_ok_and(|n| n.get() >= 2);
    let progress = Progress::new((plan.conditions.len() * per_condition * plan.rounds) as u64);
    let mut rows = Vec::new();
    let mut probes: Vec<f64> = Vec::new();
    for &asked in &plan.conditions {
        // Pinned only where it worked: a one-CPU machine or a cpuset without
        // CPU 0 runs the condition unpinned, and its table says so.
        let pinned = asked.pinned && two_cpus && gjkd_rt::pin_current_thread(0).is_ok();
        if !pinned {
            let _ = gjkd_rt::unpin_current_thread();
        }
        let condition = Condition { pinned, ..asked };
        let rt = match condition.priority {
            Some(p) => Some(gjkd_rt::set_realtime_priority(p).map_err(|e| {
                BenchError::Other(format!("--priority {p} for the client thread: {e}"))
            })?),
            None => None,
        };
        // The busy processes outlive the condition's estimate by a margin,
        // and are killed by pid as soon as it is measured.
        let budget = per_condition as f64 * plan.max_seconds * 2.0
            + (plan.transports.len() * plan.rounds) as f64 * 5.0
            + 30.0;
        let competitors = Competitors::start(condition.competitors, budget)?;
        if condition.competitors > 0 {
            progress.println(format!(
                "{}: busy processes {:?}",
                condition.label(),
                competitors.pids()
            ));
        }
        let measured = measure_condition(
            &plan,
            condition,
            &workloads,
            &gaps,
            max_batch,
            &dir,
            &progress,
            &mut probes,
        );
        drop(competitors);
        if rt.is_some() {
            gjkd_rt::reset_priority()
                .map_err(|e| BenchError::Other(format!("leave SCHED_FIFO: {e}")))?;
        }
        rows.extend(measured?);
    }
    progress.finish();
    let _ = gjkd_rt::unpin_current_thread();
    report(&rows, &dir, &plan, &plan.command(args), &probes)
}

/// Measures every configuration of one condition, in rounds.
#[allow(clippy::too_many_arguments)]
fn measure_condition(
    plan: &Plan,
    condition: Condition,
    workloads: &[Workload],
    gaps: &[Option<Duration>],
    max_batch: usize,
    dir: &Path,
    progress: &Progress,
    probes: &mut Vec<f64>,
) -> Result<Vec<Row>, BenchError> {
    let rounds = plan.rounds;
    let server_cpu = condition.pinned.then_some(1);
    // Every configuration is measured a share at a time in each round, and
    // each round starts every server afresh: load that comes and goes on a
    // shared machine then falls on all transports alike, and the ratios
    // between them hold.
    let mut configs: Vec<(Transport, Option<Duration>, Workload)> = Vec::new();
    for &t in &plan.transports {
        for &gap in gaps {
            for &w in workloads {
                configs.push((t, gap, w));
            }
        }
    }
    let mut planned: Vec<u64> = vec![0; configs.len()];
    let mut hists: Vec<Option<Histogram<u64>>> = vec![None; configs.len()];
    // The host's cross-core latency, before each round of the quiet pinned
    // condition and after its last.
    let probing = !plan.quick && condition.competitors == 0 && condition.pinned;
    let probe = |probes: &mut Vec<f64>| {
        if probing && let Some(ns) = core_round_trip_ns(0, 1) {
            probes.push(ns);
        }
    };
    let label = condition.label();
    for round in 0..rounds {
        probe(probes);
        // Each round starts with the next transport: a server started right
        // after another one stopped (its shared memory cleaned up, the
        // competitors' scheduling history reset) is not always the same one.
        let n = plan.transports.len();
        for &t in plan
            .transports
            .iter()
            .cycle()
            .skip(round % n.max(1))
            .take(n)
        {
            progress.step(format!(
                "{label}, round {}/{rounds}, {}: starting",
                round + 1,
                t.name()
            ));
            let mut target = start(t, max_batch, dir, server_cpu, condition.priority)?;
            for (ci, &(ct, gap, w)) in configs.iter().enumerate() {
                if ct != t {
                    continue;
                }
                let pacing = gap.map_or("back-to-back".into(), |g| {
                    format!("gap {} µs", g.as_micros())
                });
                let what = format!(
                    "{label}, round {}/{rounds}, {} {} {}",
                    round + 1,
                    t.name(),
                    w.name(),
                    pacing
                );
                progress.step(format!("{what}: warming up"));
                // The first round also sizes the configuration to the budget;
                // later ones only warm the caches up.
                if round == 0 {
                    planned[ci] = self::plan(plan, &mut target, w, gap)?;
                } else {
                    for _ in 0..100 {
                        target.call(w)?;
                    }
                }
                let share = planned[ci].div_ceil(rounds as u64);
                progress.step(format!("{what}: {share} of {} requests", planned[ci]));
                let h = measure(&mut target, w, gap, share)?;
                match &mut hists[ci] {
                    Some(all) => all
                        .add(&h)
                        .map_err(|e| BenchError::Other(format!("histogram: {e}")))?,
                    slot => *slot = Some(h),
                }
                progress.inc();
            }
            drop(target);
        }
    }
    probe(probes);
    Ok(configs
        .iter()
        .zip(hists)
        .filter_map(|(&(transport, gap, workload), hist)| {
            hist.map(|hist| Row {
                condition,
                transport,
                workload,
                gap,
                hist,
            })
        })
        .collect())
}
