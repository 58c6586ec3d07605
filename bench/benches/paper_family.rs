//! Section 7 of the paper: time per distance query on the family of twelve
//! polytopes and twenty pairs, grouped by `M = M1 + M2` (one pair per `M`), for
//! separated, just touching and intersecting poses; gjk and
//! `parry3d_f64::query::distance` side by side on identical world geometry.
//!
//! `cargo bench -p gjkd-bench --bench paper_family`. Each benchmark runs all
//! `PER_PAIR` examples of one pair and case; the throughput is per query.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use gjk::{Options, Shape};
use gjkd_testkit::paper::{self, Case, PAIRS};
use gjkd_testkit::parry::{parry_family, parry_pose};

const PER_PAIR: usize = 100;
const SEED: u64 = 7;

fn family(c: &mut Criterion) {
    let family = paper::family();
    let parry = parry_family(&family);
    let shapes: Vec<Shape> = family.iter().cloned().map(Shape::from).collect();
    let options = Options::default();
    for case in Case::ALL {
        let cases = paper::cases(case, PER_PAIR, SEED);
        let mut group = c.benchmark_group(format!("paper_family/{}", case.name()));
        group.throughput(Throughput::Elements(PER_PAIR as u64));
        for (pair, chunk) in cases.chunks(PER_PAIR).enumerate() {
            let (a, b) = PAIRS[pair];
            let m = chunk[0].m;
            let parry_poses: Vec<_> = chunk
                .iter()
                .map(|c| (parry_pose(&c.pose_a), parry_pose(&c.pose_b)))
                .collect();
            group.bench_with_input(BenchmarkId::new("gjk", m), chunk, |bench, chunk| {
                bench.iter(|| {
                    let mut sum = 0.0;
                    for c in chunk {
                        let ans = gjk::distance(
                            black_box(&shapes[a]),
                            black_box(&c.pose_a),
                            &shapes[b],
                            black_box(&c.pose_b),
                            &options,
                            None,
                        )
                        .expect("valid input");
                        sum += ans.distance;
                    }
                    sum
                })
            });
            group.bench_with_input(
                BenchmarkId::new("parry", m),
                &parry_poses,
                |bench, poses| {
                    bench.iter(|| {
                        let mut sum = 0.0;
                        for (pa, pb) in poses {
                            let d = parry3d_f64::query::distance(
                                black_box(pa),
                                black_box(&*parry[a]),
                                black_box(pb),
                                &*parry[b],
                            )
                            .expect("supported pair");
                            sum += d.distance;
                        }
                        sum
                    })
                },
            );
        }
        group.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1));
    targets = family
}
criterion_main!(benches);
