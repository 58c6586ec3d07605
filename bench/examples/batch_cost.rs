//! Times the Rust client's `query_batch` on the box pairs that
//! `python/bench/compare.py` wrote, against a running server, so that the
//! Python figures have the Rust ones beside them from the same run.
//!
//! `cargo run --release -p gjkd-bench --example batch_cost SERVICE PAIRS_FILE REPEATS`; the file holds `n` (as an
//! f64), then per pair the half extents of A and B (6 f64) and the poses of
//! A and B (`[x, y, z, qx, qy, qz, qw]`, 14 f64), little-endian. Prints one
//! line: `query_batch_ns_per_pair <median over repeats>`.

use std::time::Instant;

use gjkd_client::{Client, Item, ItemResult, QueryOptions};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

fn pose(v: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::new_unchecked(Quaternion::new(v[6], v[3], v[4], v[5])),
    )
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, service, path, repeats] = args.as_slice() else {
        return Err("usage: gjkd-batch-cost SERVICE PAIRS_FILE REPEATS".into());
    };
    let repeats: usize = repeats.parse()?;
    let bytes = std::fs::read(path)?;
    let data: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap_or_default()))
        .collect();
    let n = data[0] as usize;
    let mut client = Client::connect(service)?;
    let mut items = Vec::with_capacity(n);
    for row in data[1..].chunks_exact(20).take(n) {
        let a = client.register_cuboid(Vector3::new(row[0], row[1], row[2]), 0.0)?;
        let b = client.register_cuboid(Vector3::new(row[3], row[4], row[5]), 0.0)?;
        items.push(Item::distance_at(
            a,
            &pose(&row[6..13]),
            b,
            &pose(&row[13..20]),
            &QueryOptions::default(),
        ));
    }
    let mut results = vec![ItemResult::default(); n];
    for _ in 0..20 {
        client.query_batch(&items, &mut results)?;
    }
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        let start = Instant::now();
        client.query_batch(&items, &mut results)?;
        times.push(start.elapsed().as_nanos() as f64 / n as f64);
    }
    times.sort_by(f64::total_cmp);
    println!("query_batch_ns_per_pair {}", times[times.len() / 2]);
    Ok(())
}
