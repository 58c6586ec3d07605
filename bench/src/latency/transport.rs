//! How requests are carried: the transports, the requests they carry,
//! starting a target and timing its round trips.

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use gjkd_client::{Client, Item, ItemResult, ObjectId, QueryOptions};
use gjkd_server::engine::State;
use hdrhistogram::Histogram;
use nalgebra::Vector3;

use crate::demo::ServerProcess;
use crate::latency_objects::{HALF, batch_pose, local_state, single_pose};
use crate::raw_ipc::{RawClient, RawServer};
use crate::uds::{UdsClient, UdsServer};
use crate::{BenchError, io};

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

    pub(super) fn wait(self) -> Option<&'static str> {
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

/// The requests, for a server that gave these ids.
pub(super) struct Requests {
    single: Item,
    batch: Vec<Item>,
    results: Vec<ItemResult>,
}

impl Requests {
    pub(super) fn new(a: ObjectId, b: ObjectId, boxes: &[ObjectId], max_batch: usize) -> Self {
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
pub(super) enum Target {
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
    pub(super) fn call(&mut self, w: Workload) -> Result<(), BenchError> {
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

pub(super) fn start(
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
pub(super) fn spin_until(until: Instant) {
    while Instant::now() < until {
        std::hint::spin_loop();
    }
}

/// Times `n` requests (after a warm-up), recording each in nanoseconds.
pub(super) fn measure(
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

#[cfg(test)]
mod tests {
    use super::*;

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
