//! Load: N client processes × M queries each, every answer compared bit for
//! bit with the in-process one (inside `gjkd-load`); the server's own
//! counters equal the clients' (nothing lost, nothing duplicated), and its
//! memory stays flat after warm-up.
//!
//! `GJKD_LOAD_QUERIES` sets M (default 5000, a few seconds in a debug
//! build); `docs/reliability.md` quotes runs with more.

use std::time::Duration;

use gjkd_e2e::{LoadProcess, Server, rss_kib};

const CLIENTS: u64 = 4;

fn queries() -> u64 {
    std::env::var("GJKD_LOAD_QUERIES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(5000)
}

/// Runs one phase: `CLIENTS` processes of `count` queries each; returns
/// (queries, requests) summed over them, after checking each one's report.
fn phase(service: &str, seed: u64, count: u64) -> (u64, u64) {
    let mut procs: Vec<LoadProcess> = (0..CLIENTS)
        .map(|c| LoadProcess::spawn(service, "load", seed + c, Some(count)))
        .collect();
    let (mut queries, mut requests) = (0, 0);
    for (n, p) in procs.iter_mut().enumerate() {
        let (status, lines) = p
            .finish(Duration::from_secs(300))
            .expect("load process finished");
        let done = lines
            .iter()
            .find(|l| l.starts_with("DONE "))
            .unwrap_or_else(|| panic!("client {n} gave no summary: {lines:?}"));
        eprintln!("client {n}: {done}");
        let field = |name: &str| -> u64 {
            done.split(' ')
                .find_map(|kv| kv.strip_prefix(name)?.strip_prefix('='))
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| panic!("no {name} in {done}"))
        };
        assert_eq!(field("mismatched"), 0, "client {n}: wrong answers");
        assert_eq!(field("errors"), 0, "client {n}: lost requests");
        assert!(field("queries") >= count, "client {n}: {done}");
        assert!(status.success(), "client {n}: {status}");
        queries += field("queries");
        requests += field("requests");
    }
    (queries, requests)
}

#[test]
fn clients_under_load_get_every_answer_once_and_right_in_flat_memory() {
    let server = Server::start("load", &["--wait", "adaptive"]);
    let pid = server.pid().expect("running");
    let mut stats_client = server.client(Duration::from_secs(5));
    let m = queries();

    let s0 = stats_client.stats().expect("stats");
    let (wq, wr) = phase(&server.service, 100, (m / 4).max(1));
    let s1 = stats_client.stats().expect("stats");
    let rss_warm = rss_kib(pid).expect("server rss");
    let (q, r) = phase(&server.service, 200, m);
    let s2 = stats_client.stats().expect("stats");
    let rss_end = rss_kib(pid).expect("server rss");
    eprintln!(
        "{CLIENTS} clients x {m} queries: {q} queries in {r} requests; \
         server RSS {rss_warm} KiB after warm-up, {rss_end} KiB at the end"
    );

    // The server answered exactly the requests and items the clients sent
    // and got answers to: none lost, none answered twice.
    assert_eq!(s1.requests - s0.requests, wr);
    assert_eq!(s1.items - s0.items, wq);
    assert_eq!(s2.requests - s1.requests, r);
    assert_eq!(s2.items - s1.items, q);
    assert_eq!(s2.item_errors, 0);
    assert_eq!(s2.objects, 2 * CLIENTS * 5);
    let bound = rss_warm + (rss_warm / 10).max(4096);
    assert!(
        rss_end <= bound,
        "server memory grew from {rss_warm} KiB to {rss_end} KiB (bound {bound})"
    );
}
