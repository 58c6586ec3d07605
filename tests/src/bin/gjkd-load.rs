//! A client process for the crash and load tests: it registers the test
//! zoo, then queries it and checks every answer against the in-process one.
//!
//! ```text
//! gjkd-load SERVICE load SEED COUNT      COUNT queries, then a summary line
//! gjkd-load SERVICE victim SEED          queries until killed ("READY" first)
//! gjkd-load SERVICE endless SEED         queries and registers until the
//!                                        server is gone, then "GONE <ms>"
//! ```
//!
//! Lines on stdout, one fact each, flushed at once (the test reads them
//! while the process runs):
//! - `REG <id> <zoo index>`: a registration was acknowledged;
//! - `READY`: the first queries were answered;
//! - `DONE queries=<n> mismatched=<n> errors=<n> requests=<n>`;
//! - `GONE <ms> <error>`: the call that found the server gone, and how long
//!   it took from its start.
//!
//! Exit status: 0 when every answer matched, 1 on a mismatch or an
//! unexpected error, 3 after `GONE`.

use std::io::Write;
use std::time::{Duration, Instant};

use gjkd_client::{Client, ClientError, Item, ItemResult, ObjectId, QueryOptions};
use gjkd_e2e::{Rng, Solid, gjk_options, is_gone, status_of};

/// Timeout of every call: the crash test asserts the loss is reported
/// within it.
const TIMEOUT: Duration = Duration::from_millis(1000);

fn say(line: &str) {
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "{line}");
    let _ = out.flush();
}

/// Whether a served result is the in-process answer, bit for bit.
fn same(got: &ItemResult, want: &gjk::Answer) -> bool {
    let Ok(a) = got.answer() else { return false };
    let b = |x: f64| x.to_bits();
    b(a.distance) == b(want.distance)
        && b(a.lower) == b(want.lower)
        && b(a.upper) == b(want.upper)
        && b(a.penetration) == b(want.penetration)
        && a.point_a.coords.map(b) == want.point_a.coords.map(b)
        && a.point_b.coords.map(b) == want.point_b.coords.map(b)
        && a.normal.map(b) == want.normal.map(b)
        && a.iterations == want.iterations
        && a.pieces == want.pieces
        && a.status == Some(status_of(want.status))
        && a.backup_used == want.backup_used
}

struct Load {
    client: Client,
    zoo: Vec<Solid>,
    shapes: Vec<gjk::Shape>,
    ids: Vec<ObjectId>,
    /// The in-process warm start of each ordered pair, mirroring the
    /// server's cache entry for this client.
    warm: Vec<Option<gjk::WarmStart>>,
    rng: Rng,
    queries: u64,
    mismatched: u64,
    errors: u64,
    requests: u64,
}

impl Load {
    fn new(service: &str, seed: u64) -> Result<Self, ClientError> {
        let mut client = Client::builder(service)
            .timeout(TIMEOUT)
            .connect_timeout(Duration::from_secs(10))
            .connect()?;
        let zoo = Solid::zoo();
        let shapes = zoo.iter().map(Solid::shape).collect();
        let mut ids = Vec::new();
        for (k, s) in zoo.iter().enumerate() {
            let id = s.register(&mut client)?;
            say(&format!("REG {} {k}", id.raw()));
            ids.push(id);
        }
        let n = zoo.len();
        Ok(Load {
            client,
            zoo,
            shapes,
            ids,
            warm: vec![None; n * n],
            rng: Rng::new(seed),
            queries: 0,
            mismatched: 0,
            errors: 0,
            requests: 0,
        })
    }

    /// One request of 1 to 4 pair queries at fresh poses, each checked.
    fn step(&mut self) -> Result<(), ClientError> {
        let n = self.zoo.len();
        let k = 1 + (self.rng.next_u64() % 4) as usize;
        let options = QueryOptions::default();
        let mut items = [Item::set_pose(self.ids[0], &Default::default()); 4];
        let mut want = Vec::with_capacity(k);
        let mut pairs = Vec::with_capacity(k);
        for item in items.iter_mut().take(k) {
            // Distinct pairs within a request, so that each one's warm start
            // is the previous request's.
            let (i, j) = loop {
                let i = (self.rng.next_u64() % n as u64) as usize;
                let j = (self.rng.next_u64() % n as u64) as usize;
                if !pairs.contains(&(i, j)) {
                    break (i, j);
                }
            };
            pairs.push((i, j));
            let (pa, pb) = (self.rng.pose(2.0), self.rng.pose(2.0));
            *item = Item::distance_at(self.ids[i], &pa, self.ids[j], &pb, &options);
            let answer = gjk::distance(
                &self.shapes[i],
                &pa,
                &self.shapes[j],
                &pb,
                &gjk_options(&options),
                self.warm[i * n + j].as_ref(),
            )
            .expect("valid in-process query");
            want.push(answer);
        }
        let mut results = [ItemResult::error(gjkd_client::ErrorCode::Internal); 4];
        self.client.query_batch(&items[..k], &mut results)?;
        self.requests += 1;
        for (q, (&(i, j), w)) in pairs.iter().zip(&want).enumerate() {
            self.queries += 1;
            if !same(&results[q], w) {
                self.mismatched += 1;
                eprintln!("mismatch {i}-{j}: {:?} vs {w:?}", results[q]);
            }
            self.warm[i * n + j] = Some(w.warm_start);
        }
        Ok(())
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        eprintln!("usage: gjkd-load SERVICE load|victim|endless SEED [COUNT]");
        std::process::exit(2);
    }
    // iceoryx2 warns about every dead node it cleans up: noise here.
    iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Error);
    let service = &args[1];
    let seed: u64 = args[3].parse().expect("seed");
    let mut load = match Load::new(service, seed) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("setup failed: {e}");
            std::process::exit(1);
        }
    };
    match args[2].as_str() {
        "load" => {
            let count: u64 = args.get(4).and_then(|c| c.parse().ok()).expect("count");
            while load.queries < count {
                if let Err(e) = load.step() {
                    eprintln!("query failed: {e}");
                    load.errors += 1;
                    break;
                }
            }
            say(&format!(
                "DONE queries={} mismatched={} errors={} requests={}",
                load.queries, load.mismatched, load.errors, load.requests
            ));
            let ok = load.mismatched == 0 && load.errors == 0;
            std::process::exit(if ok { 0 } else { 1 });
        }
        "victim" => {
            for _ in 0..50 {
                load.step().expect("served");
            }
            say("READY");
            loop {
                load.step().expect("served");
            }
        }
        "endless" => {
            let mut round = 0u64;
            loop {
                round += 1;
                let start = Instant::now();
                // A registration now and then, so that some are acknowledged
                // right before the crash.
                let outcome = if round.is_multiple_of(20) {
                    let k = (round / 20) as usize % load.zoo.len();
                    let solid = load.zoo[k].clone();
                    solid
                        .register(&mut load.client)
                        .map(|id| {
                            say(&format!("REG {} {k}", id.raw()));
                        })
                        .map_err(ClientError::from)
                } else {
                    load.step()
                };
                if round == 50 {
                    say("READY");
                }
                if let Err(e) = outcome {
                    // The test checks the kind (ServerGone, or a Timeout,
                    // which also reports the loss) and the time.
                    let kind = if is_gone(&e) { "gone" } else { "other" };
                    say(&format!("GONE {} {kind} {e}", start.elapsed().as_millis()));
                    std::process::exit(if load.mismatched == 0 { 3 } else { 1 });
                }
            }
        }
        other => {
            eprintln!("unknown mode {other}");
            std::process::exit(2);
        }
    }
}
