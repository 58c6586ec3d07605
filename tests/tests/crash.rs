//! Crashes lose nothing: a server killed with -9 under load is reported by
//! every client within its timeout and, restarted, serves every object it
//! acknowledged with the same id and the same answers; a client killed with
//! -9 in mid-request has its state freed while the others are served.

use std::time::{Duration, Instant};

use gjkd_client::{ObjectId, QueryOptions};
use gjkd_e2e::{
    LoadProcess, Rng, Server, Solid, assert_same, gjk_options, node_of_pid_exists, services_exist,
};
use nalgebra::Isometry3;

/// The call timeout of `gjkd-load`.
const LOAD_TIMEOUT_MS: u64 = 1000;
/// Scheduling slack on top of it: the machine is shared and noisy; a call
/// gives up at its deadline, not exactly on it.
const SLACK_MS: u64 = 500;

fn parse_reg(line: &str) -> Option<(u64, usize)> {
    let mut parts = line.strip_prefix("REG ")?.split(' ');
    Some((parts.next()?.parse().ok()?, parts.next()?.parse().ok()?))
}

/// Answers for every acknowledged object against a fixed probe, compared
/// bit for bit with in-process answers.
fn check_objects(client: &mut gjkd_client::Client, regs: &[(u64, usize)], context: &str) {
    let zoo = Solid::zoo();
    let probe_solid = Solid::Sphere(0.25);
    let probe = probe_solid.register(client).expect("probe");
    let options = QueryOptions::cold();
    let mut rng = Rng::new(99);
    for &(id, k) in regs {
        let (pa, pb) = (rng.pose(2.0), rng.pose(2.0));
        let got = client
            .distance_at(ObjectId::from_raw(id), &pa, probe, &pb, &options)
            .unwrap_or_else(|e| panic!("{context}: object {id:#x} ({k}) lost: {e}"));
        let want = gjk::distance(
            &zoo[k].shape(),
            &pa,
            &probe_solid.shape(),
            &pb,
            &gjk_options(&options),
            None,
        )
        .expect("in-process");
        assert_same(&got, &want, &format!("{context}: object {id:#x}"));
    }
    client.remove(probe).expect("probe removed");
}

#[test]
fn a_server_killed_under_load_loses_no_object_and_clients_notice_in_time() {
    let mut server = Server::start("crash-load", &["--wait", "adaptive"]);
    let old_pid = server.pid().expect("running");
    let mut loaders: Vec<LoadProcess> = (0..3)
        .map(|seed| LoadProcess::spawn(&server.service, "endless", 10 + seed, None))
        .collect();
    for l in &mut loaders {
        assert!(
            l.wait_for("READY", Duration::from_secs(20)).is_some(),
            "loader never got going: {:?}",
            l.seen
        );
    }
    // Let them run (and register) a little longer, then pull the plug.
    std::thread::sleep(Duration::from_millis(300));
    server.kill9();

    let mut regs = Vec::new();
    for (n, l) in loaders.iter_mut().enumerate() {
        let (status, lines) = l
            .finish(Duration::from_secs(10))
            .expect("a loader did not notice the dead server");
        assert_eq!(status.code(), Some(3), "loader {n}: {lines:?}");
        let gone = lines
            .iter()
            .find(|l| l.starts_with("GONE "))
            .expect("GONE line");
        let ms: u64 = gone
            .split(' ')
            .nth(1)
            .and_then(|m| m.parse().ok())
            .expect("ms");
        eprintln!("loader {n}: {gone}");
        assert!(
            ms <= LOAD_TIMEOUT_MS + SLACK_MS,
            "loader {n} took {ms} ms to report the loss"
        );
        regs.extend(lines.iter().filter_map(|l| parse_reg(l)));
    }
    assert!(regs.len() >= 15, "{} registrations", regs.len());

    server.restart();
    let mut client = server.client(Duration::from_secs(5));
    // The restarted server removed what the dead one left behind.
    let deadline = Instant::now() + Duration::from_secs(10);
    while node_of_pid_exists(old_pid) && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(
        !node_of_pid_exists(old_pid),
        "stale node of the dead server"
    );
    assert!(services_exist(&server.service));
    let stats = client.stats().expect("stats");
    // Every acknowledged registration is back. A registration in flight at
    // the kill may have been written without its reply reaching the client
    // (at most one per client): it is back too, but nobody printed its id.
    let acked = regs.len() as u64;
    assert!(
        (acked..=acked + loaders.len() as u64).contains(&stats.objects),
        "{} objects back for {acked} acknowledged",
        stats.objects
    );
    check_objects(&mut client, &regs, "after restart");
    eprintln!(
        "{acked} acknowledged registrations, {} objects back, all answers equal",
        stats.objects
    );
}

#[test]
fn a_client_killed_mid_request_is_forgotten_and_the_others_are_served() {
    let server = Server::start("crash-client", &["--wait", "adaptive"]);
    let mut victims: Vec<LoadProcess> = (0..2)
        .map(|seed| LoadProcess::spawn(&server.service, "victim", 20 + seed, None))
        .collect();
    for v in &mut victims {
        assert!(
            v.wait_for("READY", Duration::from_secs(20)).is_some(),
            "victim never got going: {:?}",
            v.seen
        );
    }
    let mut stats_client = server.client(Duration::from_secs(5));
    let before = stats_client.stats().expect("stats");
    assert!(before.cache_entries >= 2, "{before:?}");
    assert_eq!(before.objects, 10);

    // A survivor queries warm along a path the whole time, its answers
    // checked bit for bit against an in-process warm-started sequence.
    let service = server.service.clone();
    let stop = std::sync::atomic::AtomicBool::new(false);
    let (survivor_queries, after) = std::thread::scope(|scope| {
        let survivor = scope.spawn(|| {
            let zoo = Solid::zoo();
            let mut client = gjkd_e2e::connect(&service, Duration::from_secs(5));
            let a = zoo[4].register(&mut client).expect("a");
            let b = zoo[2].register(&mut client).expect("b");
            let (sa, sb) = (zoo[4].shape(), zoo[2].shape());
            let options = QueryOptions::default();
            let mut warm: Option<gjk::WarmStart> = None;
            let mut step = 0u64;
            while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                let t = step as f64 * 1e-3;
                let pa = Isometry3::new(
                    nalgebra::Vector3::new(-2.0 + (t % 4.0), 0.3, 0.1),
                    nalgebra::Vector3::new(0.0, t, 0.2),
                );
                let pb = Isometry3::translation(0.0, 0.0, 0.5);
                let got = client
                    .distance_at(a, &pa, b, &pb, &options)
                    .expect("survivor served");
                let want = gjk::distance(&sa, &pa, &sb, &pb, &gjk_options(&options), warm.as_ref())
                    .expect("in-process");
                assert_same(&got, &want, &format!("survivor step {step}"));
                warm = Some(want.warm_start);
                step += 1;
            }
            step
        });
        std::thread::sleep(Duration::from_millis(200));
        for v in &mut victims {
            v.kill9();
        }
        // The server notices within its housekeeping period (forced even
        // while the survivor keeps it busy).
        let deadline = Instant::now() + Duration::from_secs(20);
        let after = loop {
            let s = stats_client.stats().expect("stats");
            // Left: the survivor's one pair; clients: survivor and us.
            if s.cache_entries == 1 && s.clients == 2 {
                break s;
            }
            assert!(Instant::now() < deadline, "victims' state not freed: {s:?}");
            std::thread::sleep(Duration::from_millis(100));
        };
        std::thread::sleep(Duration::from_millis(100));
        stop.store(true, std::sync::atomic::Ordering::Relaxed);
        (survivor.join().expect("survivor ok"), after)
    });
    eprintln!("survivor answered {survivor_queries} queries; after: {after:?}");
    assert!(survivor_queries > 10);
    // Objects are not client state: the victims' registrations stay.
    assert_eq!(after.objects, 12);
    // And the server still serves new clients.
    let mut late = server.client(Duration::from_secs(5));
    let s = late.register_sphere(1.0).expect("new client served");
    late.remove(s).expect("removed");
}

/// Every byte of the state file matters: a server started on a truncated or
/// bit-flipped file sets it aside, says so, and starts empty rather than
/// half-loaded; a wrong-version file likewise.
#[test]
fn a_corrupt_state_file_is_set_aside_never_half_loaded() {
    let mut server = Server::start("corrupt", &["--wait", "block"]);
    let path = server.state_file().expect("helper-chosen state file");
    {
        let mut client = server.client(Duration::from_secs(5));
        for r in [0.5, 0.6, 0.7] {
            client.register_sphere(r).expect("registered");
        }
    }
    server.terminate();
    let good = std::fs::read(&path).expect("state file");
    type Spoil = Box<dyn Fn(&mut Vec<u8>)>;
    // The bit flipped is one of a stored radius: the payload, not a byte
    // the store's format leaves unused. The store keeps earlier copies of
    // its pages in free space; the bit is flipped in every copy.
    let radius = 0.6f64.to_le_bytes();
    let copies: Vec<usize> = good
        .windows(8)
        .enumerate()
        .filter(|(_, w)| *w == radius)
        .map(|(i, _)| i)
        .collect();
    assert!(!copies.is_empty(), "the radius is stored");
    let spoilers: [(&str, Spoil); 3] = [
        ("truncated", Box::new(|b| b.truncate(b.len() - 7))),
        (
            "bit flip",
            Box::new(move |b| copies.iter().for_each(|&at| b[at + 2] ^= 0x10)),
        ),
        ("version", Box::new(|b| b[8] = 9)),
    ];
    for (what, spoil) in &spoilers {
        let mut bytes = good.clone();
        spoil(&mut bytes);
        std::fs::write(&path, &bytes).expect("spoil");
        server.restart();
        let mut client = server.client(Duration::from_secs(5));
        assert_eq!(client.stats().expect("stats").objects, 0, "{what}");
        drop(client);
        server.terminate();
        let dir = path.parent().expect("dir");
        let aside: Vec<_> = std::fs::read_dir(dir)
            .expect("list")
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(".corrupt-"))
            .collect();
        assert_eq!(aside.len(), 1, "{what}: the bad file is kept aside");
        assert_eq!(
            std::fs::read(aside[0].path()).expect("read"),
            bytes,
            "{what}: kept as it was"
        );
        std::fs::remove_file(aside[0].path()).expect("clean");
    }
    // The intact file still loads all three.
    std::fs::write(&path, &good).expect("restore");
    server.restart();
    let mut client = server.client(Duration::from_secs(5));
    assert_eq!(client.stats().expect("stats").objects, 3);
}

/// A second server pointed at a state file in use refuses to start instead
/// of overwriting the first one's objects.
#[test]
fn a_state_file_in_use_is_not_shared() {
    let first = Server::start("lock-a", &["--wait", "block"]);
    let path = first.state_file().expect("state file");
    let mut client = first.client(Duration::from_secs(5));
    let id = client.register_sphere(0.5).expect("registered");
    let path_arg = path.to_str().expect("utf-8").to_owned();
    let mut second = Server::start("lock-b", &["--wait", "block", "--state-file", &path_arg]);
    let status = second.wait_exit().expect("second server exits by itself");
    assert!(!status.success());
    assert_eq!(client.stats().expect("stats").objects, 1);
    client.remove(id).expect("first server still owns its file");
    // The store can be read once the first server has let go of it.
    drop(client);
    let mut first = first;
    first.terminate();
    let (_, opened) = gjkd_server::persist::database::Database::open(&path, 1).expect("intact");
    assert!(opened.set_aside.is_empty() && !opened.fresh);
    let snap = opened.snapshot;
    assert!(snap.objects.is_empty());
}

/// Registrations and removals in their hundreds, then `kill -9` right
/// after the last acknowledged one: every acknowledged change is back after
/// the restart, each object with its own geometry, and no removed one.
#[test]
fn a_server_killed_after_many_changes_keeps_every_acknowledged_one() {
    let mut server = Server::start("crash-log", &["--wait", "block"]);
    let path = server.state_file().expect("helper-chosen state file");
    let mut client = server.client(Duration::from_secs(5));
    // Box i has half-extent 0.5 + i/1000 along x: its distance to the probe
    // tells which object answered.
    let mut live: Vec<(ObjectId, usize)> = Vec::new();
    let mut removed = Vec::new();
    for i in 0..700 {
        let half = nalgebra::Vector3::new(0.5 + i as f64 * 1e-3, 0.4, 0.3);
        let id = client.register_cuboid(half, 0.0).expect("registered");
        live.push((id, i));
        if i % 7 == 6 {
            let (gone, _) = live.remove(live.len() / 2);
            client.remove(gone).expect("removed");
            removed.push(gone);
        }
    }
    let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    drop(client);
    server.kill9();
    server.restart();
    let mut client = server.client(Duration::from_secs(5));
    assert_eq!(client.stats().expect("stats").objects, live.len() as u64);
    let probe = client.register_sphere(0.25).expect("probe");
    let at = Isometry3::translation(3.0, 0.0, 0.0);
    let options = QueryOptions::cold();
    for &(id, i) in &live {
        let got = client
            .distance_at(id, &Isometry3::identity(), probe, &at, &options)
            .unwrap_or_else(|e| panic!("object {i} lost: {e}"));
        let want = 3.0 - 0.25 - (0.5 + i as f64 * 1e-3);
        assert!((got.distance - want).abs() < 1e-9, "object {i}: {got:?}");
    }
    for &id in &removed {
        assert!(
            client
                .distance_at(id, &Isometry3::identity(), probe, &at, &options)
                .is_err(),
            "removed object {id:?} is back"
        );
    }
    eprintln!(
        "{} objects back, {} removals kept, store of {size} bytes at the kill",
        live.len(),
        removed.len()
    );
}

/// A server that dies between committing a registration and replying to
/// it (killed by its own fault-injection hook, `SIGKILL` right after the
/// commit): the client's `register` reconnects to the restarted server and
/// sends the registration again with its token, and gets the id of the
/// object that was stored. The store holds that one object, not two.
#[test]
fn a_registration_retried_across_a_kill_between_store_and_reply_is_stored_once() {
    use std::os::unix::process::ExitStatusExt;
    let mut server = Server::start_with_env(
        "kill-after-register",
        &["--wait", "adaptive"],
        &[(gjkd_server::server::KILL_AFTER_REGISTER, "1")],
    );
    let service = server.service.clone();
    // A call timeout long enough for the restart below.
    let registering = std::thread::spawn(move || {
        let mut client = gjkd_e2e::connect(&service, Duration::from_secs(30));
        client.register_sphere(0.5)
    });
    let mut status = None;
    for _ in 0..6 {
        status = server.wait_exit();
        if status.is_some() {
            break;
        }
    }
    let status = status.expect("the hook killed the server after the commit");
    assert_eq!(status.signal(), Some(libc::SIGKILL), "{status:?}");
    server.clear_env();
    server.restart();
    let id = registering
        .join()
        .expect("registering thread")
        .expect("the retry is answered by the restarted server");
    let mut client = server.client(Duration::from_secs(5));
    assert_eq!(
        client.stats().expect("stats").objects,
        1,
        "one object, not two"
    );
    let other = client.register_sphere(0.5).expect("registered");
    let answer = client
        .distance_at(
            id,
            &Isometry3::identity(),
            other,
            &Isometry3::translation(3.0, 0.0, 0.0),
            &QueryOptions::cold(),
        )
        .expect("the stored object answers");
    assert_eq!(answer.distance, 2.0);
}
