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
//! - `in-process`: [`State::handle`] called directly, the GJK work alone.
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

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use gjkd_client::{Client, Item, ItemResult, ObjectId, QueryOptions};
use gjkd_server::engine::State;
use hdrhistogram::Histogram;
use nalgebra::Vector3;

use super::busy::Competitors;
use super::latency_objects::{HALF, batch_pose, local_state, single_pose};
use super::plot::{self, Axis, Chart, Mark, Series};
use super::raw_ipc::{RawClient, RawServer};
use super::stats::{Csv, Progress};
use super::uds::{UdsClient, UdsServer};
use super::{BenchError, CommonArgs, io, out_dir};
use crate::demo::ServerProcess;

/// Flags of `gjkd bench latency`.
#[derive(clap::Args, Debug, Clone)]
pub struct LatencyArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Requests per configuration.
    #[arg(long, default_value_t = 100_000)]
    requests: u64,
    /// Longest a configuration may take: fewer requests are sent (never
    /// fewer than --min-requests) when the estimate is longer. Default 4 s,
    /// 1 s with --contention.
    #[arg(long)]
    max_seconds: Option<f64>,
    /// Fewest requests per configuration. Default 10 000, 300 with
    /// --contention.
    #[arg(long)]
    min_requests: Option<u64>,
    /// Gaps between requests in the paced runs, microseconds (a list).
    /// Default 100; 10,100,1000 with --contention.
    #[arg(long, value_delimiter = ',')]
    gap_us: Vec<u64>,
    /// Batch sizes (besides the single pair). Default 1,8,64,512; none
    /// with --contention.
    #[arg(long, value_delimiter = ',')]
    batches: Vec<usize>,
    /// Transports to measure (default: all; all but uds with --contention).
    #[arg(long, value_delimiter = ',', value_enum)]
    transports: Vec<Transport>,
    /// Rounds: every configuration is measured a share at a time in each
    /// round, servers restarted, so slow spells of a shared machine fall on
    /// all transports alike.
    #[arg(long, default_value_t = 4)]
    rounds: usize,
    /// Competing busy processes, one condition per count (a list). Default
    /// 0; 0,1 with --contention.
    #[arg(long, value_delimiter = ',')]
    competitors: Vec<usize>,
    /// Placements, one condition each (a list): `pinned` puts the client on
    /// CPU 0 and every server on CPU 1, as `taskset` would, so that a woken
    /// server is never queued behind its own spinning client on one core;
    /// `unpinned` leaves the scheduler free. Default pinned; both with
    /// --contention.
    #[arg(long, value_delimiter = ',', value_enum)]
    pinning: Vec<Pinning>,
    /// Same as `--pinning unpinned`.
    #[arg(long)]
    no_pin: bool,
    /// SCHED_FIFO priorities for the client thread and the servers, one
    /// condition each (a list; 0: ordinary scheduling). Default 0.
    #[arg(long, value_delimiter = ',')]
    priority: Vec<i32>,
    /// The deployment guide's tables: single pairs, back to back and at
    /// 10 µs, 100 µs and 1 ms, quiet and beside one busy process, pinned and
    /// unpinned (flags given explicitly still win).
    #[arg(long)]
    contention: bool,
}

/// Where the client and the servers run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Pinning {
    /// Client on CPU 0, servers on CPU 1.
    Pinned,
    /// Wherever the scheduler puts them.
    Unpinned,
}

/// What runs beside the measurement, and where it runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Condition {
    /// Competing busy processes.
    pub competitors: usize,
    /// Client on CPU 0, servers on CPU 1 (false: unpinned).
    pub pinned: bool,
    /// SCHED_FIFO priority of the client and the servers, if any.
    pub priority: Option<i32>,
}

impl Condition {
    /// The heading of its table.
    pub fn label(&self) -> String {
        let load = match self.competitors {
            0 => "quiet".to_owned(),
            1 => "1 competing busy process".to_owned(),
            n => format!("{n} competing busy processes"),
        };
        let place = if self.pinned {
            "pinned (client CPU 0, servers CPU 1)"
        } else {
            "unpinned"
        };
        match self.priority {
            Some(p) => format!("{load}, {place}, SCHED_FIFO {p}"),
            None => format!("{load}, {place}"),
        }
    }
}

/// The settings of one run, defaults filled in.
#[derive(Clone, Debug)]
struct Plan {
    requests: u64,
    max_seconds: f64,
    min_requests: u64,
    gaps: Vec<Duration>,
    batches: Vec<usize>,
    transports: Vec<Transport>,
    rounds: usize,
    conditions: Vec<Condition>,
    quick: bool,
}

impl Plan {
    fn new(args: &LatencyArgs) -> Self {
        let c = args.contention;
        let or = |v: &Vec<u64>, plain: &[u64], contention: &[u64]| -> Vec<u64> {
            if !v.is_empty() {
                v.clone()
            } else if c {
                contention.to_vec()
            } else {
                plain.to_vec()
            }
        };
        let gaps = or(&args.gap_us, &[100], &[10, 100, 1000])
            .into_iter()
            .map(Duration::from_micros)
            .collect();
        let batches = if !args.batches.is_empty() {
            args.batches.iter().map(|&n| n.max(1)).collect()
        } else if c {
            Vec::new()
        } else {
            vec![1, 8, 64, 512]
        };
        let competitors = if !args.competitors.is_empty() {
            args.competitors.clone()
        } else if c {
            vec![0, 1]
        } else {
            vec![0]
        };
        let pinnings = if args.no_pin {
            vec![Pinning::Unpinned]
        } else if !args.pinning.is_empty() {
            args.pinning.clone()
        } else if c {
            vec![Pinning::Pinned, Pinning::Unpinned]
        } else {
            vec![Pinning::Pinned]
        };
        let priorities: Vec<Option<i32>> = if args.priority.is_empty() {
            vec![None]
        } else {
            args.priority
                .iter()
                .map(|&p| (p > 0).then_some(p))
                .collect()
        };
        let mut conditions = Vec::new();
        for &competitors in &competitors {
            for &pinning in &pinnings {
                for &priority in &priorities {
                    conditions.push(Condition {
                        competitors,
                        pinned: pinning == Pinning::Pinned,
                        priority,
                    });
                }
            }
        }
        let transports = if args.transports.is_empty() {
            // The socket server answers every condition alike (tens of µs,
            // a blocking read): the contention tables leave it out.
            Transport::ALL
                .into_iter()
                .filter(|&t| !c || t != Transport::Uds)
                .collect()
        } else {
            Transport::ALL
                .into_iter()
                .filter(|t| args.transports.contains(t))
                .collect()
        };
        let mut plan = Plan {
            requests: args.requests,
            max_seconds: args.max_seconds.unwrap_or(if c { 1.0 } else { 4.0 }),
            min_requests: args.min_requests.unwrap_or(if c { 300 } else { 10_000 }),
            gaps,
            batches,
            transports,
            rounds: args.rounds.max(1),
            conditions,
            quick: args.common.quick,
        };
        if plan.quick {
            plan.requests = plan.requests.min(2_000);
            plan.min_requests = plan.min_requests.min(if c { 100 } else { 300 });
            plan.max_seconds = plan.max_seconds.min(if c { 0.25 } else { 0.2 });
            plan.rounds = 1;
        }
        plan
    }

    /// The command line that gives this plan, for the tables.
    fn command(&self, args: &LatencyArgs) -> String {
        let mut cmd = String::from("gjkd bench latency");
        if args.contention {
            cmd.push_str(" --contention");
        }
        if args.common.quick {
            cmd.push_str(" --quick");
        }
        let list = |v: Vec<String>| v.join(",");
        if !args.gap_us.is_empty() {
            cmd.push_str(&format!(
                " --gap-us {}",
                list(args.gap_us.iter().map(u64::to_string).collect())
            ));
        }
        if !args.competitors.is_empty() {
            cmd.push_str(&format!(
                " --competitors {}",
                list(args.competitors.iter().map(usize::to_string).collect())
            ));
        }
        if args.no_pin {
            cmd.push_str(" --no-pin");
        } else if !args.pinning.is_empty() {
            cmd.push_str(&format!(
                " --pinning {}",
                list(
                    args.pinning
                        .iter()
                        .map(|p| format!("{p:?}").to_lowercase())
                        .collect()
                )
            ));
        }
        if !args.priority.is_empty() {
            cmd.push_str(&format!(
                " --priority {}",
                list(args.priority.iter().map(i32::to_string).collect())
            ));
        }
        cmd
    }
}

/// The median time, in ns, for one cache line to go from CPU `a` to CPU `b`
/// and back (two threads pinned there bouncing an atomic counter), or `None`
/// when the threads cannot be pinned. Every round trip through shared memory
/// is a handful of such transfers, and on a virtual machine their cost is
/// the host's business and can change several-fold between runs. Printed
/// with each run so that its figures can be read against the state it ran
/// in.
pub fn core_round_trip_ns(a: usize, b: usize) -> Option<f64> {
    use std::sync::atomic::{AtomicU64, Ordering};
    #[repr(align(128))]
    struct Line(AtomicU64);
    const BATCH: u64 = 2_000;
    const BATCHES: u64 = 15;
    let line = Line(AtomicU64::new(0));
    let line = &line;
    // Two threads of their own, so the caller's affinity is left alone. The
    // probe gives up after a quarter of a second: on a loaded machine whose
    // threads take turns on a core, each bounce can cost a time slice.
    const DONE: u64 = u64::MAX;
    let deadline = Instant::now() + Duration::from_millis(250);
    std::thread::scope(|scope| {
        let echo = scope.spawn(move || {
            let ok = gjkd_rt::pin_current_thread(b).is_ok();
            // An odd value is a ping; answer with the next even one. A
            // failed pin still answers, so the other side never hangs.
            loop {
                let v = line.0.load(Ordering::Acquire);
                if v == DONE {
                    return ok;
                }
                if v % 2 == 1 {
                    line.0.store(v + 1, Ordering::Release);
                } else {
                    std::hint::spin_loop();
                }
            }
        });
        let ping = scope.spawn(move || {
            let ok = gjkd_rt::pin_current_thread(a).is_ok();
            let mut times = Vec::with_capacity(BATCHES as usize);
            'batches: for k in 0..BATCHES {
                let start = Instant::now();
                for i in k * BATCH..(k + 1) * BATCH {
                    line.0.store(2 * i + 1, Ordering::Release);
                    while line.0.load(Ordering::Acquire) != 2 * i + 2 {
                        std::hint::spin_loop();
                    }
                }
                times.push(start.elapsed().as_nanos() as f64 / BATCH as f64);
                if Instant::now() > deadline {
                    break 'batches;
                }
            }
            line.0.store(DONE, Ordering::Release);
            times.sort_by(f64::total_cmp);
            ok.then(|| times[times.len() / 2])
        });
        let echoed = echo.join().unwrap_or(false);
        ping.join().ok().flatten().filter(|_| echoed)
    })
}

/// How requests are carried.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Transport {
    /// The handler called directly.
    InProcess,
    /// A Unix-socket server process.
    Uds,
    /// iceoryx2, server busy-polling.
    Spin,
    /// iceoryx2, server spinning briefly after each request, then sleeping.
    Adaptive,
    /// iceoryx2, server sleeping on an event.
    Block,
    /// A bare iceoryx2 server, both sides busy-polling, no GJK: the floor.
    Iceoryx2,
}

impl Transport {
    /// All, in the order they are measured and shown.
    pub const ALL: [Transport; 6] = [
        Transport::Spin,
        Transport::Adaptive,
        Transport::Block,
        Transport::Iceoryx2,
        Transport::Uds,
        Transport::InProcess,
    ];

    /// The name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Transport::InProcess => "in-process",
            Transport::Uds => "uds",
            Transport::Spin => "spin",
            Transport::Adaptive => "adaptive",
            Transport::Block => "block",
            Transport::Iceoryx2 => "iceoryx2",
        }
    }

    fn wait(self) -> Option<&'static str> {
        match self {
            Transport::Spin => Some("spin"),
            Transport::Adaptive => Some("adaptive"),
            Transport::Block => Some("block"),
            _ => None,
        }
    }
}

/// What one request asks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Workload {
    /// One pair at its stored poses (`Client::distance`).
    Single,
    /// `n` pairs, each item with its own pose (`Client::query_batch`).
    Batch(usize),
}

impl Workload {
    /// The name in tables.
    pub fn name(self) -> String {
        match self {
            Workload::Single => "single".into(),
            Workload::Batch(n) => format!("batch {n}"),
        }
    }
}

/// One measured configuration.
pub struct Row {
    /// What ran beside it, and where.
    pub condition: Condition,
    /// Transport.
    pub transport: Transport,
    /// Request shape.
    pub workload: Workload,
    /// Gap between requests, `None` for back to back.
    pub gap: Option<Duration>,
    /// Round trips, nanoseconds.
    pub hist: Histogram<u64>,
}

impl Row {
    fn us(&self, q: f64) -> f64 {
        self.hist.value_at_quantile(q) as f64 / 1e3
    }
    fn pacing(&self) -> String {
        match self.gap {
            None => "back-to-back".into(),
            Some(g) => format!("gap {} µs", g.as_micros()),
        }
    }
}

/// The requests, for a server that gave these ids.
struct Requests {
    single: Item,
    batch: Vec<Item>,
    results: Vec<ItemResult>,
}

impl Requests {
    fn new(a: ObjectId, b: ObjectId, boxes: &[ObjectId], max_batch: usize) -> Self {
        let batch: Vec<Item> = (0..max_batch)
            .map(|k| {
                Item::distance(boxes[0], boxes[k + 1], &QueryOptions::default())
                    .with_pose_b(&batch_pose(k))
            })
            .collect();
        Requests {
            single: Item::distance(a, b, &QueryOptions::default()),
            results: vec![ItemResult::default(); batch.len().max(1)],
            batch,
        }
    }
}

/// Something that answers requests.
enum Target {
    Ipc {
        client: Box<Client>,
        a: ObjectId,
        b: ObjectId,
        req: Requests,
        _server: ServerProcess,
    },
    Uds {
        client: UdsClient,
        req: Requests,
        _server: UdsServer,
    },
    Raw {
        client: RawClient,
        req: Requests,
        _server: RawServer,
    },
    Local {
        state: Box<State>,
        req: Requests,
    },
}

impl Target {
    fn call(&mut self, w: Workload) -> Result<(), BenchError> {
        match self {
            Target::Ipc {
                client, a, b, req, ..
            } => match w {
                Workload::Single => {
                    black_box(client.distance(*a, *b, &QueryOptions::default())?);
                }
                Workload::Batch(n) => client.query_batch(&req.batch[..n], &mut req.results[..n])?,
            },
            Target::Uds { client, req, .. } => {
                let items = match w {
                    Workload::Single => std::slice::from_ref(&req.single),
                    Workload::Batch(n) => &req.batch[..n],
                };
                let n = items.len();
                io("uds round trip", client.query(items, &mut req.results[..n]))?;
            }
            Target::Raw { client, req, .. } => {
                let items = match w {
                    Workload::Single => std::slice::from_ref(&req.single),
                    Workload::Batch(n) => &req.batch[..n],
                };
                let n = items.len();
                client.query(items, &mut req.results[..n])?;
            }
            Target::Local { state, req } => {
                let items = match w {
                    Workload::Single => std::slice::from_ref(&req.single),
                    Workload::Batch(n) => &req.batch[..n],
                };
                let n = items.len();
                state.handle(0, items, &mut req.results[..n]);
                black_box(&req.results[..n]);
            }
        }
        Ok(())
    }
}

fn start(
    t: Transport,
    max_batch: usize,
    dir: &Path,
    server_cpu: Option<usize>,
    priority: Option<i32>,
) -> Result<Target, BenchError> {
    if let Some(wait) = t.wait() {
        let service = format!("gjkd-bench-{}-{wait}", std::process::id());
        let cpu = server_cpu.map(|c| c.to_string());
        let prio = priority.map(|p| p.to_string());
        let mut flags = vec!["--wait", wait, "--no-persist"];
        if let Some(cpu) = &cpu {
            flags.extend(["--cpu", cpu]);
        }
        if let Some(prio) = &prio {
            flags.extend(["--priority", prio]);
        }
        let server = io("spawn gjkd serve", ServerProcess::spawn(&service, &flags))?;
        let mut client = Client::builder(&service)
            .timeout(Duration::from_secs(5))
            .connect_timeout(Duration::from_secs(20))
            .connect()?;
        let half = Vector3::from(HALF);
        let a = client.register_cuboid(half, 0.0)?;
        let b = client.register_cuboid(half, 0.0)?;
        client.set_pose(b, &single_pose())?;
        let boxes = (0..=max_batch)
            .map(|_| client.register_cuboid(half, 0.0))
            .collect::<Result<Vec<_>, _>>()?;
        let req = Requests::new(a, b, &boxes, max_batch);
        return Ok(Target::Ipc {
            client: Box::new(client),
            a,
            b,
            req,
            _server: server,
        });
    }
    let (state, a, b, boxes) = local_state(max_batch);
    let req = Requests::new(a, b, &boxes, max_batch);
    if t == Transport::Iceoryx2 {
        let service = format!("gjkd-bench-{}-raw", std::process::id());
        let server = io(
            "start gjkd bench raw-server",
            RawServer::spawn(&service, max_batch, server_cpu),
        )?;
        let client = RawClient::connect(&service, max_batch)?;
        return Ok(Target::Raw {
            client,
            req,
            _server: server,
        });
    }
    if t == Transport::Uds {
        let path = dir.join(format!("gjkd-bench-{}.sock", std::process::id()));
        let server = io(
            "start gjkd bench uds-server",
            UdsServer::spawn(&path, max_batch, server_cpu),
        )?;
        let client = io("connect the unix socket", UdsClient::connect(server.path()))?;
        let mut target = Target::Uds {
            client,
            req,
            _server: server,
        };
        // The child registered its own objects: check that our ids name them.
        target.call(Workload::Single)?;
        if let Target::Uds { req, .. } = &target
            && let Err(e) = req.results[0].answer()
        {
            return Err(BenchError::Other(format!(
                "the socket server does not know the bench's objects: {e:?}"
            )));
        }
        return Ok(target);
    }
    Ok(Target::Local {
        state: Box::new(state),
        req,
    })
}

/// Busy-waits until `until`: a sleep would overshoot by tens of µs.
fn spin_until(until: Instant) {
    while Instant::now() < until {
        std::hint::spin_loop();
    }
}

/// Times `n` requests (after a warm-up), recording each in nanoseconds.
fn measure(
    target: &mut Target,
    w: Workload,
    gap: Option<Duration>,
    n: u64,
) -> Result<Histogram<u64>, BenchError> {
    let mut hist = Histogram::<u64>::new_with_bounds(1, 60_000_000_000, 3)
        .map_err(|e| BenchError::Other(format!("histogram: {e}")))?;
    let mut last = Instant::now();
    for _ in 0..n {
        if let Some(g) = gap {
            spin_until(last + g);
        }
        let t0 = Instant::now();
        target.call(w)?;
        last = Instant::now();
        let ns = (last - t0).as_nanos().max(1) as u64;
        hist.saturating_record(ns);
    }
    Ok(hist)
}

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
        super::machine()
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

/// The p50 or another quantile of `t`'s single pair at `gap`, µs, among
/// `rows` (NaN when not measured).
fn single_us(rows: &[&Row], t: Transport, gap: Option<Duration>, q: f64) -> f64 {
    rows.iter()
        .find(|r| r.transport == t && r.workload == Workload::Single && r.gap == gap)
        .map_or(f64::NAN, |r| r.us(q))
}

/// The lines under a condition's table: each mode against `block` and
/// `spin` against the floor, single pair, per pacing.
fn condition_summary(rows: &[&Row], gaps: &[Option<Duration>]) -> String {
    let mut out = String::new();
    for &gap in gaps {
        let label = gap.map_or("back to back".into(), |g| {
            format!("gap {} µs", g.as_micros())
        });
        let u = |t, q| single_us(rows, t, gap, q);
        let spin = u(Transport::Spin, 0.5);
        let floor = u(Transport::Iceoryx2, 0.5) + u(Transport::InProcess, 0.5);
        out.push_str(&format!(
            "Single pair, {label}: p50 spin {spin:.2} µs ({:.2}x the floor: iceoryx2 {:.2} + in-process {:.2}), adaptive {:.2} µs (p99 {:.1}), block {:.2} µs (p99 {:.1}); adaptive / block: p50 {:.2}x, p99 {:.2}x\n",
            spin / floor,
            u(Transport::Iceoryx2, 0.5),
            u(Transport::InProcess, 0.5),
            u(Transport::Adaptive, 0.5),
            u(Transport::Adaptive, 0.99),
            u(Transport::Block, 0.5),
            u(Transport::Block, 0.99),
            u(Transport::Adaptive, 0.5) / u(Transport::Block, 0.5),
            u(Transport::Adaptive, 0.99) / u(Transport::Block, 0.99),
        ));
    }
    out
}

fn report(
    rows: &[Row],
    dir: &Path,
    plan: &Plan,
    command: &str,
    probes: &[f64],
) -> Result<(), BenchError> {
    let mut csv = Csv::new(&[
        "transport",
        "request",
        "pacing",
        "requests",
        "p50_us",
        "p90_us",
        "p99_us",
        "p99_9_us",
        "max_us",
        "mean_us",
        "competitors",
        "pinned",
        "priority",
    ]);
    let f = |v: f64| format!("{v:.2}");
    let mut gaps = vec![None];
    gaps.extend(plan.gaps.iter().copied().map(Some));
    let mut text = String::new();
    let mut conditions: Vec<Condition> = Vec::new();
    for r in rows {
        if !conditions.contains(&r.condition) {
            conditions.push(r.condition);
        }
    }
    for condition in &conditions {
        let sel: Vec<&Row> = rows.iter().filter(|r| r.condition == *condition).collect();
        let Some(first) = sel.first() else { continue };
        text.push_str(&format!("\n### {}\n\n", first.condition.label()));
        text.push_str("| transport | request | pacing | requests | p50 µs | p90 µs | p99 µs | p99.9 µs | max µs |\n|---|---|---|---:|---:|---:|---:|---:|---:|\n");
        for r in &sel {
            csv.row(&[
                r.transport.name().to_owned(),
                r.workload.name(),
                r.pacing(),
                r.hist.len().to_string(),
                f(r.us(0.5)),
                f(r.us(0.9)),
                f(r.us(0.99)),
                f(r.us(0.999)),
                f(r.hist.max() as f64 / 1e3),
                f(r.hist.mean() / 1e3),
                r.condition.competitors.to_string(),
                r.condition.pinned.to_string(),
                r.condition.priority.unwrap_or(0).to_string(),
            ]);
            text.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                r.transport.name(),
                r.workload.name(),
                r.pacing(),
                r.hist.len(),
                f(r.us(0.5)),
                f(r.us(0.9)),
                f(r.us(0.99)),
                f(r.us(0.999)),
                f(r.hist.max() as f64 / 1e3),
            ));
        }
        text.push('\n');
        text.push_str(&condition_summary(&sel, &gaps));
    }
    if !probes.is_empty() {
        let list: Vec<String> = probes.iter().map(|ns| format!("{ns:.0}")).collect();
        text.push_str(&format!(
            "\nCache-line round trip CPU 0 <-> CPU 1 before each round and after the last: {} ns (the host's state: this VM has shown ~65 ns and ~340 ns at different times, and the slow state doubles a single round trip)\n",
            list.join(", ")
        ));
    }
    println!("{text}");
    let doc = format!(
        "Machine: {}\n\nCommand: `{command}` (requests per configuration: up to {}, at most ~{} s each, at least {}, in {} rounds)\n{text}",
        super::machine(),
        plan.requests,
        plan.max_seconds,
        plan.min_requests,
        plan.rounds,
    );
    io("write latency.csv", csv.write(&dir.join("latency.csv")))?;
    io(
        "write latency.md",
        std::fs::write(dir.join("latency.md"), doc),
    )?;
    // The plots show the first condition at the first gap: the classic
    // figures; the other conditions are in the tables.
    let first_gap = plan.gaps.first().copied();
    let first: Vec<&Row> = rows
        .iter()
        .filter(|r| r.condition == rows[0].condition && (r.gap.is_none() || r.gap == first_gap))
        .collect();
    plots(&first, dir)?;
    println!(
        "wrote {0}/latency.csv, {0}/latency.md, {0}/latency-back-to-back.svg, {0}/latency-gaps.svg, {0}/latency-p50.svg",
        dir.display()
    );
    Ok(())
}

/// `q = 1 - 10^-x` as a percentage label: the x axis of a percentile
/// spectrum counts nines.
fn nines(x: &f64) -> String {
    let q = 100.0 * (1.0 - 10f64.powf(-x));
    if *x < 0.5 {
        "0%".into()
    } else {
        let digits = (x.round() as usize).saturating_sub(2);
        format!("{q:.digits$}%")
    }
}

fn us_ticks(v: &f64) -> String {
    if *v >= 10.0 {
        format!("{v:.0}")
    } else if *v >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

fn plots(rows: &[&Row], dir: &Path) -> Result<(), BenchError> {
    let color = |t: Transport| Transport::ALL.iter().position(|&x| x == t).unwrap_or(0);
    let spectrum = |r: &Row| -> Vec<(f64, f64)> {
        let mut pts: Vec<(f64, f64)> = r
            .hist
            .iter_quantiles(4)
            .filter(|v| v.quantile_iterated_to() < 1.0)
            .map(|v| {
                (
                    -(1.0 - v.quantile_iterated_to()).log10(),
                    v.value_iterated_to() as f64 / 1e3,
                )
            })
            .filter(|p| p.0 <= 5.0)
            .collect();
        pts.dedup_by(|a, b| (a.0 - b.0).abs() < 0.01);
        pts
    };
    for (gapped, file, what) in [
        (false, "latency-back-to-back.svg", "back to back"),
        (true, "latency-gaps.svg", "with gaps"),
    ] {
        let mut charts = Vec::new();
        let workloads: Vec<Workload> = rows
            .iter()
            .filter(|r| r.transport == Transport::Spin && r.gap.is_some() == gapped)
            .map(|r| r.workload)
            .collect();
        for w in workloads {
            let sel: Vec<&Row> = rows
                .iter()
                .copied()
                .filter(|r| r.workload == w && r.gap.is_some() == gapped)
                .collect();
            let series: Vec<Series> = sel
                .iter()
                .map(|r| Series {
                    name: r.transport.name().into(),
                    points: spectrum(r),
                    mark: Mark::Line,
                    color: color(r.transport),
                })
                .collect();
            let y = Axis::fit(
                series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
                true,
            );
            charts.push(Chart {
                title: format!("{}, {what}: round trip by percentile", w.name()),
                x: Axis::linear("percentile (log scale of 1 - q)", (0.0, 5.0))
                    .with_ticks(nines)
                    .with_labels(6),
                y: Axis::log("round trip, µs (log)", y).with_ticks(us_ticks),
                series,
                legend: plot::Corner::LowerRight,
            });
        }
        let path = dir.join(file);
        plot::render(&path, &charts, 3, (520, 360))
            .map_err(|e| BenchError::Plot(path.display().to_string(), e))?;
    }
    let mut charts = Vec::new();
    for (gapped, what) in [(false, "back to back"), (true, "with gaps")] {
        let series: Vec<Series> = Transport::ALL
            .iter()
            .map(|&t| Series {
                name: t.name().into(),
                points: rows
                    .iter()
                    .filter(|r| r.transport == t && r.gap.is_some() == gapped)
                    .filter_map(|r| match r.workload {
                        Workload::Batch(n) => Some((n as f64, r.us(0.5))),
                        Workload::Single => None,
                    })
                    .collect(),
                mark: Mark::LinePoints,
                color: color(t),
            })
            .collect();
        let x = Axis::fit(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.0)),
            true,
        );
        let y = Axis::fit(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
            true,
        );
        charts.push(Chart {
            title: format!("median round trip against batch size, {what}"),
            x: Axis::log("pairs per request (log)", x).with_ticks(|v| format!("{v:.0}")),
            y: Axis::log("p50 round trip, µs (log)", y).with_ticks(us_ticks),
            series,
            legend: plot::Corner::UpperLeft,
        });
    }
    let path = dir.join("latency-p50.svg");
    plot::render(&path, &charts, 2, (560, 380))
        .map_err(|e| BenchError::Plot(path.display().to_string(), e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nines_label_the_percentile_axis() {
        assert_eq!(nines(&0.0), "0%");
        assert_eq!(nines(&1.0), "90%");
        assert_eq!(nines(&2.0), "99%");
        assert_eq!(nines(&3.0), "99.9%");
        assert_eq!(nines(&5.0), "99.999%");
    }

    #[test]
    fn in_process_answers_and_measures() {
        // The socket server is a child `gjkd` process: the e2e smoke test of
        // `gjkd bench latency` covers it.
        let dir = std::env::temp_dir();
        let mut local = start(Transport::InProcess, 8, &dir, None, None).expect("local");
        local.call(Workload::Batch(8)).expect("batch");
        local.call(Workload::Single).expect("single");
        let Target::Local { req, .. } = &local else {
            unreachable!()
        };
        assert!(req.results[0].answer().expect("ok").distance > 0.0);
        let hist = measure(&mut local, Workload::Batch(8), None, 10).expect("measure");
        assert_eq!(hist.len(), 10);
    }
}
