//! Section 8 of the paper: the collision sweep of `gjkd_testkit::paper::section8()`
//! (a two-piece object moved through five obstacles), the five distances at
//! `s = t/T` for `t = 0..=T`, started cold at every step (single point,
//! Section 6) against warm (each obstacle's previous final simplex). The
//! paper's Table 1 reports warm 1.7×, 2.9× and 3.1× faster for T = 10, 100
//! and 1000.
//!
//! `cold`/`warm` hand the two-piece object to `gjk::distance` as one compound
//! (5 queries per step; gjk warm-starts the nearest and the runner-up piece
//! pairs);
//! `pieces_cold`/`pieces_warm` query each piece against each obstacle with its
//! own warm start (10 convex queries per step), as the paper does.
//!
//! `cargo bench -p gjkd-bench --bench warm_start`. Throughput is per query.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use gjk::Options;
use gjkd_testkit::paper::{self, OBSTACLES};

fn sweep(c: &mut Criterion) {
    let motion = paper::section8();
    let options = Options::default();
    let mut group = c.benchmark_group("section8_sweep");
    for steps in [10usize, 100, 1000] {
        group.throughput(Throughput::Elements(((steps + 1) * OBSTACLES) as u64));
        for (name, warm) in [("cold", false), ("warm", true)] {
            group.bench_with_input(BenchmarkId::new(name, steps), &steps, |bench, &steps| {
                bench.iter(|| {
                    motion
                        .sweep(black_box(steps), &options, warm)
                        .expect("valid input")
                        .iterations
                })
            });
        }
        // The paper's own setup: each piece against each obstacle, every
        // convex pair with its own warm start (10 queries per step).
        group.throughput(Throughput::Elements(((steps + 1) * 2 * OBSTACLES) as u64));
        for (name, warm) in [("pieces_cold", false), ("pieces_warm", true)] {
            group.bench_with_input(BenchmarkId::new(name, steps), &steps, |bench, &steps| {
                bench.iter(|| {
                    motion
                        .sweep_pieces(black_box(steps), &options, warm)
                        .expect("valid input")
                        .iterations
                })
            });
        }
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    targets = sweep
}
criterion_main!(benches);
