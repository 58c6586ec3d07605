//! `gjkd bench latency`: the round trip a client sees, through every way of
//! asking, on the same messages, in one run.
//!
//! Five transports answer the same requests with the same handler:
//!
//! - `spin`, `block`, `adaptive`: a real `gjkd serve --wait MODE` child
//!   process (this executable) and a [`gjkd_client::Client`];
//! - `uds`: a Unix-stream-socket server with blocking reads, also a child
//!   process of its own (`gjkd bench uds-server`, [`super::uds`]), pinned
//!   like the others;
//! - `in-process`: [`State::handle`] called directly, the floor.
//!
//! Each is asked a single pair (`Client::distance`, the pair at its stored
//! poses) and batches of 1, 8, 64 and 512 distinct box pairs, each item with
//! its own pose, warm-started as the server does by default; back to back,
//! and with a gap (a busy-wait of `--gap-us`, 100 µs by default) between the
//! end of one request and the start of the next, long enough for an
//! `adaptive` server to fall asleep. Servers run one at a time, so a
//! spinning server never steals the core of the one being measured.
//!
//! Each configuration sends `--requests` requests (100 000 by default)
//! unless that would take longer than `--max-seconds`; then it sends fewer,
//! never fewer than `--min-requests`, and the table says how many.

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use gjkd_client::{Client, Item, ItemResult, ObjectId, QueryOptions};
use gjkd_proto::{AdminOp, AdminRequest, Vertex, WaitMode, shape_kind};
use hdrhistogram::Histogram;
use nalgebra::{Isometry3, Vector3};

use super::plot::{self, Axis, Chart, Mark, Series};
use super::stats::{Csv, Progress};
use super::uds::{UdsClient, UdsServer};
use super::{BenchError, CommonArgs, io, out_dir};
use crate::demo::ServerProcess;
use gjkd_server::engine::{Limits, State};

/// Flags of `gjkd bench latency`.
#[derive(clap::Args, Debug, Clone)]
pub struct LatencyArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Requests per configuration.
    #[arg(long, default_value_t = 100_000)]
    requests: u64,
    /// Longest a configuration may take: fewer requests are sent (never
    /// fewer than --min-requests) when the estimate is longer.
    #[arg(long, default_value_t = 4.0)]
    max_seconds: f64,
    /// Fewest requests per configuration.
    #[arg(long, default_value_t = 10_000)]
    min_requests: u64,
    /// Gap between requests in the paced runs, microseconds.
    #[arg(long, default_value_t = 100)]
    gap_us: u64,
    /// Batch sizes (besides the single pair).
    #[arg(long, value_delimiter = ',', default_values_t = [1usize, 8, 64, 512])]
    batches: Vec<usize>,
    /// Transports to measure (default: all).
    #[arg(long, value_delimiter = ',', value_enum)]
    transports: Vec<Transport>,
    /// Rounds: every configuration is measured a share at a time in each
    /// round, servers restarted, so slow spells of a shared machine fall on
    /// all transports alike.
    #[arg(long, default_value_t = 4)]
    rounds: usize,
    /// Leave the scheduler free to place client and server: by default the
    /// client is pinned to CPU 0 and every server to CPU 1, as `taskset`
    /// would, so that a woken server is never queued behind its own spinning
    /// client on one core.
    #[arg(long)]
    no_pin: bool,
}

/// Pins thread or process `pid` (0: the calling thread) to `cpu`; whether it
/// worked.
pub fn pin(pid: libc::pid_t, cpu: usize) -> bool {
    // SAFETY: a zeroed cpu_set_t is the empty set; CPU_SET writes inside it;
    // sched_setaffinity reads `size_of::<cpu_set_t>()` bytes of it.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(pid, std::mem::size_of::<libc::cpu_set_t>(), &set) == 0
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
            let ok = pin(0, b);
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
            let ok = pin(0, a);
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

/// Lets the calling thread run on every CPU again.
fn unpin() {
    // SAFETY: as in `pin`, with every CPU the set can name.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        for cpu in 0..libc::CPU_SETSIZE as usize {
            libc::CPU_SET(cpu, &mut set);
        }
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set);
    }
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
    /// iceoryx2, server spinning 50 µs after each request, then sleeping.
    Adaptive,
    /// iceoryx2, server sleeping on an event.
    Block,
}

impl Transport {
    /// All, in the order they are measured and shown.
    pub const ALL: [Transport; 5] = [
        Transport::Spin,
        Transport::Adaptive,
        Transport::Block,
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

const HALF: [f64; 3] = [0.5, 0.4, 0.3];

/// The batch item `k`: box 0 against box `k + 1` at a pose of its own, so
/// that every item is its own warm-start entry, as a robot's links against
/// its obstacles would be.
fn batch_pose(k: usize) -> Isometry3<f64> {
    Isometry3::new(
        Vector3::new(1.5 + 0.001 * k as f64, 0.2, -0.1),
        Vector3::new(0.1, 0.003 * k as f64, 0.3),
    )
}

fn single_pose() -> Isometry3<f64> {
    Isometry3::new(Vector3::new(1.6, 0.3, 0.1), Vector3::new(0.2, 0.4, 0.1))
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

/// A state with the bench's objects, registered through the admin handler
/// exactly as a client's requests would be. Deterministic: the socket server
/// child builds the same one, so these ids name its objects too.
pub(crate) fn local_state(max_batch: usize) -> (State, ObjectId, ObjectId, Vec<ObjectId>) {
    let mut state = State::new(Limits::default(), WaitMode::Block, 0x5eed);
    let mut reg = AdminRequest::new(AdminOp::Register);
    reg.shape = shape_kind::CONVEX;
    reg.piece_count = 1;
    reg.pieces[0].vertex_count = 8;
    let verts: Vec<Vertex> = (0..8)
        .map(|i| Vertex {
            x: if i & 1 == 0 { -HALF[0] } else { HALF[0] },
            y: if i & 2 == 0 { -HALF[1] } else { HALF[1] },
            z: if i & 4 == 0 { -HALF[2] } else { HALF[2] },
        })
        .collect();
    let mut reg_one = || ObjectId::from_raw(state.handle_admin(1, &reg, &verts).id);
    let a = reg_one();
    let b = reg_one();
    let boxes: Vec<ObjectId> = (0..=max_batch).map(|_| reg_one()).collect();
    let mut set = [Item::set_pose(b, &single_pose())];
    let mut out = [ItemResult::default()];
    state.handle(0, &set, &mut out);
    set[0] = Item::set_pose(a, &Isometry3::identity());
    state.handle(0, &set, &mut out);
    (state, a, b, boxes)
}

fn start(
    t: Transport,
    max_batch: usize,
    dir: &Path,
    server_cpu: Option<usize>,
) -> Result<Target, BenchError> {
    if let Some(wait) = t.wait() {
        let service = format!("gjkd-bench-{}-{wait}", std::process::id());
        let server = io(
            "spawn gjkd serve",
            ServerProcess::spawn(&service, &["--wait", wait]),
        )?;
        if let (Some(cpu), Ok(pid)) = (server_cpu, libc::pid_t::try_from(server.id())) {
            // The serving loop runs on the process's main thread.
            pin(pid, cpu);
        }
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
    args: &LatencyArgs,
    target: &mut Target,
    w: Workload,
    gap: Option<Duration>,
) -> Result<u64, BenchError> {
    let warm = if args.common.quick { 50 } else { 500 };
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
    let fit = (args.max_seconds / per) as u64;
    Ok(fit.clamp(args.min_requests.min(args.requests), args.requests))
}

/// Runs `gjkd bench latency`.
///
/// # Errors
/// When a server cannot be started or a request fails.
pub fn run(args: &LatencyArgs) -> Result<(), BenchError> {
    let mut args = args.clone();
    if args.common.quick {
        args.requests = args.requests.min(2_000);
        args.min_requests = args.min_requests.min(300);
        args.max_seconds = args.max_seconds.min(0.2);
    }
    let dir = out_dir(&args.common)?;
    let max_batch = args.batches.iter().copied().max().unwrap_or(1).max(1);
    let mut workloads = vec![Workload::Single];
    workloads.extend(args.batches.iter().map(|&n| Workload::Batch(n.max(1))));
    let gaps = [None, Some(Duration::from_micros(args.gap_us))];
    let transports: Vec<Transport> = if args.transports.is_empty() {
        Transport::ALL.to_vec()
    } else {
        Transport::ALL
            .into_iter()
            .filter(|t| args.transports.contains(t))
            .collect()
    };
    let total = transports.len() * workloads.len() * gaps.len();
    println!(
        "gjkd bench latency: {} transports x {} request shapes x {} pacings, up to {} requests each (at most ~{} s per configuration)\nmachine: {}",
        transports.len(),
        workloads.len(),
        gaps.len(),
        args.requests,
        args.max_seconds,
        super::machine()
    );
    let pinned = !args.no_pin
        && std::thread::available_parallelism().is_ok_and(|n| n.get() >= 2)
        && pin(0, 0);
    let server_cpu = pinned.then_some(1);
    println!(
        "{}",
        if pinned {
            "client pinned to CPU 0, servers to CPU 1"
        } else {
            "not pinned: the scheduler places client and servers"
        }
    );
    let rounds = if args.common.quick {
        1
    } else {
        args.rounds.max(1)
    };
    let progress = Progress::new((total * rounds) as u64);
    // Every configuration is measured a share at a time in each round, and
    // each round starts every server afresh: load that comes and goes on a
    // shared machine then falls on all transports alike, and the ratios
    // between them hold.
    let mut configs: Vec<(Transport, Option<Duration>, Workload)> = Vec::new();
    for &t in &transports {
        for gap in gaps {
            for &w in &workloads {
                configs.push((t, gap, w));
            }
        }
    }
    let mut planned: Vec<u64> = vec![0; configs.len()];
    let mut hists: Vec<Option<Histogram<u64>>> = vec![None; configs.len()];
    // The host's cross-core latency, before each round and after the last.
    let mut probes: Vec<f64> = Vec::new();
    let probe = |probes: &mut Vec<f64>| {
        if !args.common.quick
            && let Some(ns) = core_round_trip_ns(0, 1)
        {
            probes.push(ns);
        }
    };
    for round in 0..rounds {
        probe(&mut probes);
        for &t in &transports {
            progress.step(format!(
                "round {}/{rounds}, {}: starting",
                round + 1,
                t.name()
            ));
            let mut target = start(t, max_batch, &dir, server_cpu)?;
            for (ci, &(ct, gap, w)) in configs.iter().enumerate() {
                if ct != t {
                    continue;
                }
                let pacing = gap.map_or("back-to-back".into(), |g| {
                    format!("gap {} µs", g.as_micros())
                });
                let what = format!(
                    "round {}/{rounds}, {} {} {}",
                    round + 1,
                    t.name(),
                    w.name(),
                    pacing
                );
                progress.step(format!("{what}: warming up"));
                // The first round also sizes the configuration to the budget;
                // later ones only warm the caches up.
                if round == 0 {
                    planned[ci] = plan(&args, &mut target, w, gap)?;
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
    let rows: Vec<Row> = configs
        .iter()
        .zip(hists)
        .filter_map(|(&(transport, gap, workload), hist)| {
            hist.map(|hist| Row {
                transport,
                workload,
                gap,
                hist,
            })
        })
        .collect();
    probe(&mut probes);
    progress.finish();
    if pinned {
        unpin();
    }
    report(&rows, &dir, &args, pinned, &probes)
}

fn report(
    rows: &[Row],
    dir: &Path,
    args: &LatencyArgs,
    pinned: bool,
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
    ]);
    let mut md = String::new();
    md.push_str("| transport | request | pacing | requests | p50 µs | p90 µs | p99 µs | p99.9 µs | max µs |\n|---|---|---|---:|---:|---:|---:|---:|---:|\n");
    for r in rows {
        let f = |v: f64| format!("{v:.2}");
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
        ]);
        md.push_str(&format!(
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
    let p50 = |t: Transport, w: Workload, gapped: bool| {
        rows.iter()
            .find(|r| r.transport == t && r.workload == w && r.gap.is_some() == gapped)
            .map_or(f64::NAN, |r| r.us(0.5))
    };
    let mut summary = String::new();
    for (gapped, label) in [(false, "back to back"), (true, "with gaps")] {
        let spin = p50(Transport::Spin, Workload::Single, gapped);
        summary.push_str(&format!(
            "\nSingle pair, {label}: p50 spin {spin:.2} µs, adaptive {:.2} µs ({:.2}x spin), block {:.2} µs ({:.2}x spin), UDS {:.2} µs ({:.1}x spin), in-process {:.2} µs\n",
            p50(Transport::Adaptive, Workload::Single, gapped),
            p50(Transport::Adaptive, Workload::Single, gapped) / spin,
            p50(Transport::Block, Workload::Single, gapped),
            p50(Transport::Block, Workload::Single, gapped) / spin,
            p50(Transport::Uds, Workload::Single, gapped),
            p50(Transport::Uds, Workload::Single, gapped) / spin,
            p50(Transport::InProcess, Workload::Single, gapped),
        ));
    }
    if !probes.is_empty() {
        let list: Vec<String> = probes.iter().map(|ns| format!("{ns:.0}")).collect();
        summary.push_str(&format!(
            "\nCache-line round trip CPU 0 <-> CPU 1 before each round and after the last: {} ns (the host's state: this VM has shown ~65 ns and ~340 ns at different times, and the slow state doubles a single round trip)\n",
            list.join(", ")
        ));
    }
    println!("\n{md}{summary}");
    let mut doc = format!(
        "Machine: {}\n\nCommand: `gjkd bench latency{}{}` (requests per configuration: up to {}, at most ~{} s each, at least {}, in {} rounds; gap {} µs; {})\n\n",
        super::machine(),
        if args.common.quick { " --quick" } else { "" },
        if args.no_pin { " --no-pin" } else { "" },
        args.requests,
        args.max_seconds,
        args.min_requests,
        if args.common.quick { 1 } else { args.rounds },
        args.gap_us,
        if pinned {
            "client on CPU 0, servers on CPU 1"
        } else {
            "threads not pinned"
        }
    );
    doc.push_str(&md);
    doc.push_str(&summary);
    io("write latency.csv", csv.write(&dir.join("latency.csv")))?;
    io(
        "write latency.md",
        std::fs::write(dir.join("latency.md"), doc),
    )?;
    plots(rows, dir)?;
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

fn plots(rows: &[Row], dir: &Path) -> Result<(), BenchError> {
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
        let mut local = start(Transport::InProcess, 8, &dir, None).expect("local");
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
