//! Benchmark (not a test): the C API beside the Rust client on the same
//! pairs, against one `gjkd serve --wait spin` server, in one run.
//!
//! ```text
//! cargo run --release -p gjkd-c --example bench_c_vs_rust -- [ROUNDS [SINGLES [BATCHES]]]
//! ```
//!
//! It writes `PAIRS` random box pairs, starts the server (pinned to CPU 1;
//! this process and the C program on CPU 0, so that a spinning server never
//! shares a core with its client), compiles `bench/round_trip.c` against
//! this build's `libgjkd_c.a`, and in each round runs the C program and
//! the same measurements in Rust: the p50 of a single-pair round trip
//! (`gjkd_distance` / `Client::distance`, pair 0 at its stored poses) and
//! the median per-pair cost of a batch of all pairs, each with its own
//! poses (`Client::query_batch`, items built once; in C both
//! `gjkd_distances`, ids and poses in, a field per array out, and
//! `gjkd_query_pairs`, prebuilt `gjkd_pair_query` rows in and whole
//! `gjkd_result` rows out, which is what the Rust side does with its items
//! and results). Which side goes first alternates by round. Prints each
//! round, the medians over rounds, and the median of each round's batch
//! ratios. Then, since whole rounds on a busy machine differ by more than
//! the two sides do, the same batch through each C entry point called in
//! this process (with the C structs) and through the Rust client, batch by
//! batch, order alternating: the median of each adjacent pair's ratio.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use rust_client::{Client, Item, ItemResult, ObjectId, QueryOptions};

const PAIRS: usize = 1000;

/// Pins thread or process `pid` (0: the calling thread) to `cpu`.
fn pin(pid: libc::pid_t, cpu: usize) -> bool {
    // SAFETY: a zeroed cpu_set_t is the empty set; CPU_SET writes inside it.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(pid, size_of::<libc::cpu_set_t>(), &set) == 0
    }
}

/// splitmix64: the same pairs on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }

    /// A pose `[x, y, z, qx, qy, qz, qw]` within `extent` of the origin.
    fn pose(&mut self, extent: f64) -> [f64; 7] {
        let t = [(); 3].map(|()| self.range(-extent, extent));
        let q = UnitQuaternion::from_quaternion(Quaternion::new(
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
        ));
        let c = q.coords;
        [t[0], t[1], t[2], c.x, c.y, c.z, c.w]
    }
}

/// Per pair: half extents of A and B, pose of A, pose of B.
fn pairs() -> Vec<[f64; 20]> {
    let mut rng = Rng(0x5eed_c0de);
    (0..PAIRS)
        .map(|_| {
            let mut row = [0.0; 20];
            for h in &mut row[..6] {
                *h = rng.range(0.2, 1.0);
            }
            row[6..13].copy_from_slice(&rng.pose(0.5));
            row[13..20].copy_from_slice(&rng.pose(4.0));
            row
        })
        .collect()
}

fn isometry(p: &[f64]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(p[0], p[1], p[2]),
        UnitQuaternion::new_unchecked(Quaternion::new(p[6], p[3], p[4], p[5])),
    )
}

fn write_pairs(rows: &[[f64; 20]], path: &Path) {
    let mut bytes = (rows.len() as f64).to_le_bytes().to_vec();
    for v in rows.iter().flatten() {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(path, bytes).expect("write the pairs file");
}

/// Compiles the C side against this build's static library.
fn compile(profile: &Path, out: &Path) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let status = Command::new(std::env::var("CC").unwrap_or_else(|_| "cc".into()))
        .args(["-std=c99", "-O2", "-Wall"])
        .arg("-I")
        .arg(dir.join("include"))
        .arg(dir.join("bench/round_trip.c"))
        // Built into deps/ for an example (not copied up).
        .arg(profile.join("deps/libgjkd_c.a"))
        .args([
            "-lgcc_s",
            "-lutil",
            "-lrt",
            "-lpthread",
            "-lm",
            "-ldl",
            "-lc",
            "-o",
        ])
        .arg(out)
        .status()
        .expect("run cc");
    assert!(status.success(), "compiling round_trip.c failed");
}

/// Runs the C side once: (single p50 ns, arrays batch ns per pair, rows
/// batch ns per pair).
fn run_c(
    exe: &Path,
    service: &str,
    file: &Path,
    singles: usize,
    batches: usize,
) -> (f64, f64, f64) {
    let out = Command::new(exe)
        .arg(service)
        .arg(file)
        .arg(singles.to_string())
        .arg(batches.to_string())
        .output()
        .expect("run round_trip");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "round_trip failed: {text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let value = |key: &str| -> f64 {
        text.lines()
            .find_map(|l| l.strip_prefix(key))
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or_else(|| panic!("no {key} in {text}"))
    };
    (
        value("single_p50_ns"),
        value("batch_ns_per_pair"),
        value("rows_ns_per_pair"),
    )
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// The Rust side: the same pairs registered by a Rust client.
struct RustSide {
    client: Client,
    a: ObjectId,
    b: ObjectId,
    items: Vec<Item>,
    results: Vec<ItemResult>,
}

impl RustSide {
    fn new(service: &str, rows: &[[f64; 20]]) -> Self {
        let mut client = Client::builder(service)
            .timeout(Duration::from_secs(5))
            .connect_timeout(Duration::from_secs(20))
            .connect()
            .expect("connect");
        let mut items = Vec::with_capacity(rows.len());
        let mut first = None;
        for r in rows {
            let a = client
                .register_cuboid(Vector3::new(r[0], r[1], r[2]), 0.0)
                .expect("register");
            let b = client
                .register_cuboid(Vector3::new(r[3], r[4], r[5]), 0.0)
                .expect("register");
            first.get_or_insert((a, b));
            let opts = QueryOptions::default();
            items.push(Item::distance_at(
                a,
                &isometry(&r[6..13]),
                b,
                &isometry(&r[13..20]),
                &opts,
            ));
        }
        let (a, b) = first.expect("at least one pair");
        client
            .set_pose(a, &isometry(&rows[0][6..13]))
            .expect("pose");
        client
            .set_pose(b, &isometry(&rows[0][13..20]))
            .expect("pose");
        let results = vec![ItemResult::default(); items.len()];
        RustSide {
            client,
            a,
            b,
            items,
            results,
        }
    }

    fn single_p50(&mut self, n: usize) -> f64 {
        let opts = QueryOptions::default();
        for _ in 0..n / 10 + 100 {
            self.client
                .distance(self.a, self.b, &opts)
                .expect("warm-up");
        }
        let mut t: Vec<f64> = (0..n)
            .map(|_| {
                let start = Instant::now();
                let r = self.client.distance(self.a, self.b, &opts);
                let ns = start.elapsed().as_nanos() as f64;
                r.expect("distance");
                ns
            })
            .collect();
        median(&mut t)
    }

    fn batch_per_pair(&mut self, n: usize) -> f64 {
        for _ in 0..20 {
            self.client
                .query_batch(&self.items, &mut self.results)
                .expect("warm-up");
        }
        let per = self.items.len() as f64;
        let mut t: Vec<f64> = (0..n)
            .map(|_| {
                let start = Instant::now();
                let r = self.client.query_batch(&self.items, &mut self.results);
                let ns = start.elapsed().as_nanos() as f64 / per;
                r.expect("batch");
                ns
            })
            .collect();
        median(&mut t)
    }
}

/// The C API called in this process, beside the Rust client, batch by
/// batch: both sides see the same moments of a busy machine, so the ratio
/// of each adjacent pair of batches is robust where whole rounds are not.
struct InProcessC {
    client: *mut gjkd_c::gjkd_client,
    pairs: Vec<u64>,
    poses_a: Vec<gjkd_c::gjkd_pose>,
    poses_b: Vec<gjkd_c::gjkd_pose>,
    /// distance, lower, upper (n each), point_a, point_b, normal (3n each).
    doubles: Vec<Vec<f64>>,
    /// status, iterations, error.
    words: Vec<Vec<u32>>,
    /// The rows of `gjkd_query_pairs`, each pair with its own poses.
    queries: Vec<gjkd_c::gjkd_pair_query>,
    /// Its answers.
    results: Vec<gjkd_c::gjkd_result>,
    /// The same queries as Rust items, for the Rust client to ask of the
    /// same objects.
    twin_items: Vec<Item>,
}

impl InProcessC {
    fn new(service: &str, rows: &[[f64; 20]]) -> Self {
        use gjkd_c::*;
        let service = std::ffi::CString::new(service).expect("service name");
        let mut client = std::ptr::null_mut();
        let pose = |p: &[f64]| gjkd_pose {
            translation: [p[0], p[1], p[2]],
            rotation: [p[3], p[4], p[5], p[6]],
        };
        let n = rows.len();
        let mut pairs = Vec::with_capacity(2 * n);
        // SAFETY: valid pointers, a live handle.
        unsafe {
            let s = gjkd_connect(service.as_ptr(), 5.0, 20.0, &mut client);
            assert_eq!(s, gjkd_status::GJKD_OK, "connect");
            for r in rows {
                for half in [&r[0..3], &r[3..6]] {
                    let mut id = 0;
                    let s = gjkd_register_box(
                        client,
                        half.as_ptr(),
                        0.0,
                        std::ptr::null(),
                        std::ptr::null(),
                        &mut id,
                    );
                    assert_eq!(s, gjkd_status::GJKD_OK, "register");
                    pairs.push(id);
                }
            }
        }
        let queries: Vec<gjkd_pair_query> = pairs
            .chunks(2)
            .zip(rows)
            .map(|(ab, r)| {
                // SAFETY: NULL options.
                let row = unsafe { gjkd_pair_query_of(ab[0], ab[1], std::ptr::null()) };
                gjkd_pair_query {
                    pose_a: pose(&r[6..13]),
                    pose_b: pose(&r[13..20]),
                    flags: row.flags | GJKD_POSE_A | GJKD_POSE_B,
                    ..row
                }
            })
            .collect();
        let twin_items = pairs
            .chunks(2)
            .zip(rows)
            .map(|(ab, r)| {
                Item::distance_at(
                    ObjectId::from_raw(ab[0]),
                    &isometry(&r[6..13]),
                    ObjectId::from_raw(ab[1]),
                    &isometry(&r[13..20]),
                    &QueryOptions::default(),
                )
            })
            .collect();
        InProcessC {
            client,
            pairs,
            queries,
            twin_items,
            results: vec![gjkd_result::default(); n],
            poses_a: rows.iter().map(|r| pose(&r[6..13])).collect(),
            poses_b: rows.iter().map(|r| pose(&r[13..20])).collect(),
            doubles: [1, 1, 1, 3, 3, 3]
                .iter()
                .map(|k| vec![0.0; k * n])
                .collect(),
            words: vec![vec![0; n]; 3],
        }
    }

    /// One `gjkd_distances` of every pair, with the fields `round_trip.c`
    /// asks for.
    fn batch(&mut self) {
        let d = &mut self.doubles;
        let w = &mut self.words;
        let out = gjkd_c::gjkd_results {
            distance: d[0].as_mut_ptr(),
            lower: d[1].as_mut_ptr(),
            upper: d[2].as_mut_ptr(),
            penetration: std::ptr::null_mut(),
            point_a: d[3].as_mut_ptr(),
            point_b: d[4].as_mut_ptr(),
            normal: d[5].as_mut_ptr(),
            status: w[0].as_mut_ptr(),
            iterations: w[1].as_mut_ptr(),
            pieces: std::ptr::null_mut(),
            error: w[2].as_mut_ptr(),
            warm_started: std::ptr::null_mut(),
        };
        // SAFETY: every array has room for its rows; a live handle.
        let s = unsafe {
            gjkd_c::gjkd_distances(
                self.client,
                self.pairs.as_ptr(),
                self.poses_a.len(),
                self.poses_a.as_ptr(),
                self.poses_b.as_ptr(),
                std::ptr::null(),
                &out,
            )
        };
        assert_eq!(s, gjkd_c::gjkd_status::GJKD_OK, "distances");
    }

    /// One `gjkd_query_pairs` of every pair.
    fn rows(&mut self) {
        // SAFETY: `results` has a row per query; a live handle.
        let s = unsafe {
            gjkd_c::gjkd_query_pairs(
                self.client,
                self.queries.as_ptr(),
                self.queries.len(),
                self.results.as_mut_ptr(),
            )
        };
        assert_eq!(s, gjkd_c::gjkd_status::GJKD_OK, "query_pairs");
    }
}

impl Drop for InProcessC {
    fn drop(&mut self) {
        // SAFETY: the handle from gjkd_connect, closed once.
        unsafe { gjkd_c::gjkd_close(self.client) };
    }
}

/// One batch through a C entry point.
type BatchCall = fn(&mut InProcessC);

/// `batches` adjacent pairs of batches, C and Rust, their order
/// alternating: (C median, Rust median, median of the pairs' ratios, C p10,
/// Rust p10), in ns per pair.
fn interleaved(
    c: &mut InProcessC,
    call: BatchCall,
    rust: &mut RustSide,
    items: &[Item],
    batches: usize,
) -> [f64; 5] {
    let per = items.len() as f64;
    for _ in 0..20 {
        call(c);
        rust.client
            .query_batch(items, &mut rust.results)
            .expect("warm-up");
    }
    let (mut tc, mut tr, mut ratio) = (vec![], vec![], vec![]);
    for k in 0..batches {
        let mut time_c = || {
            let start = Instant::now();
            call(c);
            start.elapsed().as_nanos() as f64 / per
        };
        let mut time_rust = || {
            let start = Instant::now();
            let r = rust.client.query_batch(items, &mut rust.results);
            let ns = start.elapsed().as_nanos() as f64 / per;
            r.expect("batch");
            ns
        };
        let (a, b) = if k % 2 == 0 {
            let a = time_c();
            (a, time_rust())
        } else {
            let b = time_rust();
            (time_c(), b)
        };
        tc.push(a);
        tr.push(b);
        ratio.push(a / b);
    }
    let p10 = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 10]
    };
    let (pc, pr) = (p10(&mut tc), p10(&mut tr));
    [median(&mut tc), median(&mut tr), median(&mut ratio), pc, pr]
}

fn spawn_server(service: &str) -> Child {
    let child = Command::new(gjkd_e2e::gjkd_binary())
        .args([
            "serve",
            "--service",
            service,
            "--wait",
            "spin",
            "--no-persist",
        ])
        .env("RUST_LOG", "warn")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .spawn()
        .expect("spawn gjkd serve");
    // The serving loop runs on the process's main thread.
    if let Ok(pid) = libc::pid_t::try_from(child.id()) {
        pin(pid, 1);
    }
    child
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("a number"))
        .collect();
    // Many short rounds, so that a slow spell of a shared machine falls on
    // both sides alike.
    let rounds = args.first().copied().unwrap_or(15);
    let singles = args.get(1).copied().unwrap_or(10_000);
    let batches = args.get(2).copied().unwrap_or(60);
    let profile: PathBuf = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent()?.parent().map(Path::to_path_buf))
        .expect("target/<profile>/examples");
    let work = profile.join("gjkd-c-bench");
    std::fs::create_dir_all(&work).expect("work folder");
    let (file, exe) = (work.join("pairs.bin"), work.join("round_trip"));
    let rows = pairs();
    write_pairs(&rows, &file);
    compile(&profile, &exe);
    let service = gjkd_e2e::unique_service("ffi-bench");
    let mut server = spawn_server(&service);
    let pinned = pin(0, 0);
    let mut rust = RustSide::new(&service, &rows);
    println!(
        "{PAIRS} box pairs, {rounds} rounds of {singles} single round trips and {batches} batches; client on CPU 0, server on CPU 1: {pinned}"
    );
    println!(
        "round   C single p50  Rust single p50  C arrays/pair    C rows/pair  Rust batch/pair   (ns)"
    );
    let mut columns: [Vec<f64>; 5] = Default::default();
    let (mut arrays_ratios, mut rows_ratios) = (vec![], vec![]);
    for round in 0..rounds {
        // Which side goes first alternates, so that whatever the first or
        // second place in a round costs (a server cache, a clock ramping)
        // falls on both sides alike.
        let (c_single, c_arrays, c_rows, r_single, r_batch) = if round % 2 == 0 {
            let (cs, ca, cr) = run_c(&exe, &service, &file, singles, batches);
            let rs = rust.single_p50(singles);
            (cs, ca, cr, rs, rust.batch_per_pair(batches))
        } else {
            let (rs, rb) = (rust.single_p50(singles), rust.batch_per_pair(batches));
            let (cs, ca, cr) = run_c(&exe, &service, &file, singles, batches);
            (cs, ca, cr, rs, rb)
        };
        println!(
            "{round:>5} {c_single:>14.0} {r_single:>16.0} {c_arrays:>14.1} {c_rows:>14.1} {r_batch:>16.1}"
        );
        for (column, v) in columns
            .iter_mut()
            .zip([c_single, r_single, c_arrays, c_rows, r_batch])
        {
            column.push(v);
        }
        arrays_ratios.push(c_arrays / r_batch);
        rows_ratios.push(c_rows / r_batch);
    }
    let [cs, rs, ca, cr, rb] = columns.map(|mut c| median(&mut c));
    println!("median {cs:>13.0} {rs:>16.0} {ca:>14.1} {cr:>14.1} {rb:>16.1}");
    println!(
        "single: C - Rust = {:+.0} ns (target <= +200); batch C / Rust (target <= 1.1): \
         gjkd_query_pairs {:.3} (median of the rounds' own ratios {:.3}), \
         gjkd_distances {:.3} ({:.3})",
        cs - rs,
        cr / rb,
        median(&mut rows_ratios),
        ca / rb,
        median(&mut arrays_ratios)
    );
    let mut in_process = InProcessC::new(&service, &rows);
    // Like with like: the Rust client asks the same objects (the server's
    // time differs from one set of objects to another), with its items
    // built once, as the C rows are.
    let twin = in_process.twin_items.clone();
    let own = rust.items.clone();
    let runs: [(&str, BatchCall, &[Item], &str); 3] = [
        (
            "gjkd_query_pairs",
            InProcessC::rows,
            &twin,
            "the same objects",
        ),
        (
            "gjkd_distances",
            InProcessC::batch,
            &twin,
            "the same objects",
        ),
        (
            "gjkd_query_pairs",
            InProcessC::rows,
            &own,
            "Rust's own objects",
        ),
    ];
    for (name, call, items, whose) in runs {
        let [c, r, ratio, c10, r10] =
            interleaved(&mut in_process, call, &mut rust, items, batches * rounds);
        println!(
            "in process, {name} beside Rust on {whose}, {} adjacent batch pairs: C {c:.1} \
             ns/pair, Rust {r:.1} (p10 {c10:.1}, {r10:.1}); C / Rust = {:.3}, median of \
             the pairs' ratios {ratio:.3}, of the p10s {:.3}",
            batches * rounds,
            c / r,
            c10 / r10
        );
    }
    drop(in_process);
    drop(rust);
    let _ = server.kill();
    let _ = server.wait();
    let _ = std::fs::remove_dir_all(&work);
}
