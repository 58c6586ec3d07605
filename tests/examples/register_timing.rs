//! How registration cost grows with the number of stored objects: starts a
//! persisting `gjkd serve` (the binary of `$GJKD_BIN`, as for the tests;
//! its store in `$TMPDIR`), registers `N` boxes in a row through the client
//! (default 10 000, or the first argument) and prints the time of the first
//! and the last 500 and the median and slowest single registration.
//!
//! `GJKD_BIN=target/release/gjkd cargo run --release -p gjkd-e2e --example register_timing`

use std::time::{Duration, Instant};

use gjkd_e2e::Server;
use nalgebra::Vector3;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(10_000);
    let server = Server::start("register-timing", &["--wait", "block"]);
    let mut client = server.client(Duration::from_secs(10));
    let mut times = Vec::with_capacity(n);
    for i in 0..n {
        let half = Vector3::new(0.5 + i as f64 * 1e-6, 0.4, 0.3);
        let start = Instant::now();
        client.register_cuboid(half, 0.0).expect("registered");
        times.push(start.elapsed());
    }
    let window = 500.min(n);
    let sum = |t: &[Duration]| t.iter().sum::<Duration>();
    let first = sum(&times[..window]);
    let last = sum(&times[n - window..]);
    let median = |t: &[Duration]| {
        let mut t = t.to_vec();
        t.sort();
        t[t.len() / 2].as_secs_f64() * 1e3
    };
    println!(
        "median of the first {window}: {:.3} ms, of the last {window}: {:.3} ms",
        median(&times[..window]),
        median(&times[n - window..])
    );
    let mut sorted = times.clone();
    sorted.sort();
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "{n} registrations: first {window} {:.1} ms ({:.3} ms each), last {window} {:.1} ms ({:.3} ms each); median {:.3} ms, p99 {:.3} ms, slowest {:.1} ms",
        ms(first),
        ms(first) / window as f64,
        ms(last),
        ms(last) / window as f64,
        ms(sorted[n / 2]),
        ms(sorted[n * 99 / 100]),
        ms(sorted[n - 1]),
    );
    if let Some(path) = server.state_file() {
        let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        println!("store file: {bytes} bytes");
    }
}
