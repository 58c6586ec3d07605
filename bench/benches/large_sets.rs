//! Large vertex sets: the support search's cost against the number of
//! vertices. Two clouds of `n` points on a unit sphere (every point a hull
//! vertex, so parry's hull keeps them all), 1 024 to 100 000 points each,
//! queried at 200 steps of a motion that brings them from 2 units apart to
//! overlap: gjk cold (the block search, exact), gjk warm, and
//! `parry3d_f64::query::distance` (a scan of every vertex per support point)
//! on identical world geometry, in the same run.
//!
//! On round bodies the cold start, from the support point along the line of
//! centroids, is already near the answer; a warm start pays only when the
//! steps are small (with 50 steps for this motion, warm took more iterations
//! than cold).
//!
//! `cargo bench -p gjkd-bench --bench large_sets`. Throughput is per query.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use gjk::{Convex, Options, Shape, WarmStart};
use gjkd_testkit::parry::parry_pose;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use parry3d_f64::shape::ConvexPolyhedron;

const STEPS: usize = 200;

/// `n` points uniform on the unit sphere, from a fixed xorshift seed.
fn sphere_cloud(n: usize, seed: u64) -> Vec<Point3<f64>> {
    let mut s = seed;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let v = Vector3::new(next(), next(), next());
        let r = v.norm();
        if r > 0.1 && r <= 1.0 {
            out.push(Point3::from(v / r));
        }
    }
    out
}

fn large(c: &mut Criterion) {
    let poses: Vec<(Isometry3<f64>, Isometry3<f64>)> = (0..STEPS)
        .map(|t| {
            let s = t as f64 / STEPS as f64;
            (
                Isometry3::from_parts(
                    Translation3::new(10.0, -3.0, 2.0),
                    UnitQuaternion::from_scaled_axis(Vector3::new(0.3, 0.1, 0.2) * s * 3.0),
                ),
                Isometry3::from_parts(
                    Translation3::new(14.0 - 2.5 * s, -3.0 + 0.5 * s, 2.2),
                    UnitQuaternion::from_scaled_axis(Vector3::new(-0.2, 0.4, 0.1) * s * 5.0),
                ),
            )
        })
        .collect();
    let parry_poses: Vec<_> = poses
        .iter()
        .map(|(a, b)| (parry_pose(a), parry_pose(b)))
        .collect();
    let options = Options::default();
    let mut group = c.benchmark_group("large_sets");
    group.throughput(Throughput::Elements(STEPS as u64));
    for n in [1024usize, 16_384, 100_000] {
        let (va, vb) = (sphere_cloud(n, 11), sphere_cloud(n, 23));
        let to_parry = |v: &[Point3<f64>]| {
            let pts: Vec<_> = v
                .iter()
                .map(|p| parry3d_f64::math::Vector::new(p.x, p.y, p.z))
                .collect();
            ConvexPolyhedron::from_convex_hull(&pts).expect("a 3D hull")
        };
        let (pa, pb) = (to_parry(&va), to_parry(&vb));
        let a: Shape = Convex::new(va, 0.0).expect("finite").into();
        let b: Shape = Convex::new(vb, 0.0).expect("finite").into();
        for (name, warm_on) in [("gjk_cold", false), ("gjk_warm", true)] {
            group.bench_with_input(BenchmarkId::new(name, n), &n, |bench, _| {
                bench.iter(|| {
                    let mut warm: Option<WarmStart> = None;
                    let mut sum = 0.0;
                    for (p, q) in &poses {
                        let ans = gjk::distance(black_box(&a), p, &b, q, &options, warm.as_ref())
                            .expect("valid input");
                        sum += ans.distance;
                        warm = warm_on.then_some(ans.warm_start);
                    }
                    sum
                })
            });
        }
        group.bench_with_input(BenchmarkId::new("parry", n), &n, |bench, _| {
            bench.iter(|| {
                let mut sum = 0.0;
                for (p, q) in &parry_poses {
                    sum += parry3d_f64::query::distance(black_box(p), black_box(&pa), q, &pb)
                        .expect("supported pair")
                        .distance;
                }
                sum
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    targets = large
}
criterion_main!(benches);
