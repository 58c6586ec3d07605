//! The object store's own cost per registration, without IPC: commits `N`
//! box registrations (default 10 000, or the first argument) to a fresh
//! store in `$TMPDIR` and prints the median commit time of the first and
//! the last 500, the slowest, and the file size.
//!
//! `cargo run --release -p gjkd-e2e --example store_commits`

use std::time::{Duration, Instant};

use gjkd_server::engine::records::{StoredObject, StoredOwner, StoredPose, StoredShape};
use gjkd_server::persist::database::Database;
use nalgebra::{Isometry3, Vector3};

fn main() {
    let n: u32 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(10_000);
    let dir = std::env::temp_dir().join(format!("gjkd-store-commits-{}", std::process::id()));
    let path = dir.join("objects");
    let epoch = 7u32;
    let (mut db, _) = Database::open(&path, epoch).expect("store");
    let mut times = Vec::with_capacity(n as usize);
    for i in 1..=n {
        let shape = gjk::Convex::cuboid(Vector3::new(0.5 + f64::from(i) * 1e-6, 0.4, 0.3), 0.0)
            .expect("box");
        let object = StoredObject {
            id: (u64::from(epoch) << 32) | u64::from(i),
            owner: StoredOwner::Client(1),
            name: None,
            pose: StoredPose::from_isometry(&Isometry3::identity()),
            shape: StoredShape::from_shape(&shape.into()),
            slot: i - 1,
        };
        let start = Instant::now();
        db.register(&object, i + 1, None).expect("commit");
        times.push(start.elapsed());
    }
    let median = |t: &[Duration]| {
        let mut t = t.to_vec();
        t.sort();
        t[t.len() / 2].as_secs_f64() * 1e3
    };
    let w = 500.min(times.len());
    let slowest = times.iter().max().copied().unwrap_or_default();
    let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    println!(
        "{n} commits: median of the first {w} {:.3} ms, of the last {w} {:.3} ms, slowest {:.1} ms; file {size} bytes",
        median(&times[..w]),
        median(&times[times.len() - w..]),
        slowest.as_secs_f64() * 1e3
    );
    drop(db);
    let _ = std::fs::remove_dir_all(&dir);
}
