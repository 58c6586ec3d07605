//! Round-trip latency through a spinning gjkd server: one box pair, and a
//! batch of 64 box pairs, as a client sees it.
//!
//! The server runs on its own thread with its own iceoryx2 node (exactly what
//! `gjkd serve --wait spin` runs), the client on the bench thread, so the two
//! talk through shared memory across cores as separate processes would.
//! Besides criterion's estimates, a first pass times calls one by one and
//! prints p50 / p90 / p99, since the target is stated as a median of single
//! round trips.
//!
//! As in `gjkd bench latency`, the client is pinned to CPU 0 and the server to
//! CPU 1, so that the scheduler cannot put the two spinning threads on one
//! core (set `GJKD_BENCH_NO_PIN` to leave placement to it).
//!
//! Before the percentiles (and after them, with `GJKD_BENCH_PERCENTILES_ONLY`)
//! it prints the time for a cache line to go from CPU 0 to CPU 1 and back. On
//! a virtual machine that time is the host's doing and can change
//! several-fold between runs, and the round trips follow it with the GJK
//! work unchanged: read the figures against the probe.
//!
//! `cargo bench -p gjkd-bench --bench roundtrip` (set `GJKD_BENCH_PERCENTILES_ONLY`
//! to stop after the percentiles).

use std::hint::black_box;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group};
use gjkd_client::{Client, Item, ItemResult, ObjectId, QueryOptions};
use gjkd_proto::{AdminChunk, WaitMode};
use gjkd_server::engine::{Limits, State};
use gjkd_server::server::{ServeOptions, run};
use nalgebra::{Isometry3, Vector3};

struct Fixture {
    client: Client,
    a: ObjectId,
    b: ObjectId,
    batch: Vec<Item>,
    /// The same 64 items naming objects that do not exist: the server only
    /// looks the ids up, so the round trip is the transport of a batch of
    /// this size, to set the batch's time against.
    unknown: Vec<Item>,
    results: Vec<ItemResult>,
    shutdown: Arc<AtomicBool>,
    server: Option<std::thread::JoinHandle<()>>,
}

impl Fixture {
    fn start() -> Self {
        iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Error);
        let service = format!("gjkd-bench-{}", std::process::id());
        let shutdown = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&shutdown);
        let name = service.clone();
        let pinned = std::env::var_os("GJKD_BENCH_NO_PIN").is_none();
        if pinned {
            let _ = gjkd_rt::pin_current_thread(0);
        }
        let server = std::thread::spawn(move || {
            if pinned {
                let _ = gjkd_rt::pin_current_thread(1);
            }
            let state = State::new(Limits::default(), WaitMode::Spin, 1);
            let options = ServeOptions {
                service: name,
                wait: WaitMode::Spin,
                remove_departed: false,
            };
            if let Err(e) = run(&options, state, &flag, || {}) {
                eprintln!("bench server failed: {e}");
            }
        });
        let mut client = Client::builder(&service)
            .timeout(Duration::from_secs(5))
            .connect()
            .expect("bench server up");
        let half = Vector3::new(0.5, 0.4, 0.3);
        let a = client.register_cuboid(half, 0.0).expect("box a");
        let b = client.register_cuboid(half, 0.0).expect("box b");
        client
            .set_pose(
                b,
                &Isometry3::new(Vector3::new(1.6, 0.3, 0.1), Vector3::new(0.2, 0.4, 0.1)),
            )
            .expect("pose");
        // 64 distinct box pairs, each at its own pose (separate warm-start
        // entries, as a robot checking links against obstacles would have).
        let mut boxes = Vec::new();
        for _ in 0..65 {
            boxes.push(client.register_cuboid(half, 0.0).expect("box"));
        }
        let batch: Vec<Item> = (0..64)
            .map(|k| {
                let pose = Isometry3::new(
                    Vector3::new(1.5 + 0.01 * k as f64, 0.2, -0.1),
                    Vector3::new(0.1, 0.02 * k as f64, 0.3),
                );
                Item::distance(boxes[0], boxes[k + 1], &QueryOptions::default()).with_pose_b(&pose)
            })
            .collect();
        let unknown = batch
            .iter()
            .enumerate()
            .map(|(k, it)| Item {
                a: u64::MAX - 2 * k as u64,
                b: u64::MAX - 2 * k as u64 - 1,
                ..*it
            })
            .collect();
        Fixture {
            client,
            unknown,
            a,
            b,
            results: vec![ItemResult::default(); batch.len()],
            batch,
            shutdown,
            server: Some(server),
        }
    }

    fn single(&mut self) -> f64 {
        self.client
            .distance(self.a, self.b, &QueryOptions::default())
            .expect("answer")
            .distance
    }

    fn batch(&mut self) {
        self.client
            .query_batch(&self.batch, &mut self.results)
            .expect("batch");
    }

    fn transport_only(&mut self) {
        self.client
            .query_batch(&self.unknown, &mut self.results)
            .expect("batch");
        assert!(
            self.results.iter().all(|r| r.error != 0),
            "ids must be unknown"
        );
    }
}

impl Drop for Fixture {
    fn drop(&mut self) {
        self.shutdown.store(true, Ordering::Relaxed);
        if let Some(h) = self.server.take() {
            let _ = h.join();
        }
    }
}

fn percentiles(name: &str, mut f: impl FnMut()) {
    for _ in 0..20_000 {
        f();
    }
    let n = 200_000;
    let mut t = Vec::with_capacity(n);
    for _ in 0..n {
        let s = Instant::now();
        f();
        t.push(s.elapsed());
    }
    t.sort();
    let p = |q: f64| t[((n as f64 - 1.0) * q) as usize].as_secs_f64() * 1e6;
    println!(
        "{name:<34} p50 {:6.2} µs   p90 {:6.2} µs   p99 {:6.2} µs   ({n} calls)",
        p(0.5),
        p(0.9),
        p(0.99)
    );
}

fn benches(c: &mut Criterion) {
    // The host's cross-core latency decides much of a round trip on a VM.
    if let Some(ns) = gjkd_bench::latency::core_round_trip_ns(0, 1) {
        println!("cache-line round trip CPU 0 <-> CPU 1: {ns:.0} ns");
    }
    let mut fx = Fixture::start();
    println!("one call at a time (Instant around each call):");
    percentiles("roundtrip/single_box_pair", || {
        black_box(fx.single());
    });
    percentiles("roundtrip/batch_64_box_pairs", || fx.batch());
    percentiles("roundtrip/batch_64_transport_only", || fx.transport_only());
    if std::env::var_os("GJKD_BENCH_PERCENTILES_ONLY").is_some() {
        // Probed with the spinning server stopped: it holds CPU 1.
        drop(fx);
        if let Some(ns) = gjkd_bench::latency::core_round_trip_ns(0, 1) {
            println!("cache-line round trip CPU 0 <-> CPU 1: {ns:.0} ns");
        }
        return;
    }

    let mut g = c.benchmark_group("roundtrip");
    g.bench_function("single_box_pair", |bch| bch.iter(|| black_box(fx.single())));
    g.bench_function("batch_64_box_pairs", |bch| bch.iter(|| fx.batch()));
    g.finish();
    // Stop the spinning server: the in-process benches below need the core.
    let batch = fx.batch.clone();
    drop(fx);

    // The same work without IPC, for the server's share of the time.
    let mut state = State::new(Limits::default(), WaitMode::Spin, 2);
    let mut reg = gjkd_proto::AdminRequest::new(gjkd_proto::AdminOp::Register);
    reg.shape = gjkd_proto::shape_kind::CONVEX;
    reg.piece_count = 1;
    reg.pieces[0].vertex_count = 8;
    let verts: Vec<gjkd_proto::Vertex> = gjk::Convex::cuboid(Vector3::new(0.5, 0.4, 0.3), 0.0)
        .expect("box")
        .vertices()
        .iter()
        .map(|&p| p.into())
        .collect();
    let ids: Vec<ObjectId> = (0..65)
        .map(|_| {
            ObjectId::from_raw(
                state
                    .handle_admin(1, &reg, AdminChunk::from_vertices(&verts))
                    .id,
            )
        })
        .collect();
    let items: Vec<Item> = batch
        .iter()
        .enumerate()
        .map(|(k, it)| Item {
            a: ids[0].raw(),
            b: ids[k + 1].raw(),
            ..*it
        })
        .collect();
    // gjk alone on the same 64 pairs, warm-started as the server does.
    let shape: gjk::Shape = gjk::Convex::cuboid(Vector3::new(0.5, 0.4, 0.3), 0.0)
        .expect("box")
        .into();
    let poses: Vec<Isometry3<f64>> = items
        .iter()
        .map(|it| it.pair().pose_b.to_isometry_unchecked())
        .collect();
    let opts = gjk::Options::default();
    let mut warm: Vec<Option<gjk::WarmStart>> = vec![None; poses.len()];
    let mut g = c.benchmark_group("gjk");
    g.bench_function("batch_64_box_pairs", |bch| {
        bch.iter(|| {
            for (p, w) in poses.iter().zip(warm.iter_mut()) {
                let ans =
                    gjk::distance(&shape, &Isometry3::identity(), &shape, p, &opts, w.as_ref())
                        .expect("valid");
                *w = Some(ans.warm_start);
            }
        })
    });
    g.finish();

    let mut out = vec![ItemResult::default(); items.len()];
    let mut g = c.benchmark_group("handler");
    g.bench_function("single_box_pair", |bch| {
        bch.iter(|| state.handle(7, &items[..1], &mut out[..1]))
    });
    g.bench_function("batch_64_box_pairs", |bch| {
        bch.iter(|| state.handle(7, &items, &mut out))
    });
    g.finish();
}

criterion_group! {
    name = roundtrip;
    config = Criterion::default()
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    targets = benches
}

fn main() {
    roundtrip();
    Criterion::default().configure_from_args().final_summary();
}
