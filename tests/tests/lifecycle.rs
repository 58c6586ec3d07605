//! A server that dies is reported, a restarted one serves again, shutdown is
//! clean, every wait strategy serves, scene files load.

use std::time::{Duration, Instant};

use gjkd_client::{Client, ClientError, ConnectError, QueryError, QueryOptions, RemoveError};
use gjkd_e2e::{
    Server, Solid, assert_same, gjk_options, is_gone, once_reached, services_exist, unique_service,
};
use nalgebra::{Isometry3, Vector3};

/// Registers two spheres 3 apart and checks their distance.
fn spheres(client: &mut Client) -> (gjkd_client::ObjectId, gjkd_client::ObjectId) {
    let a = client.register_sphere(0.5).expect("a");
    let b = client.register_sphere(0.5).expect("b");
    client
        .set_pose(b, &Isometry3::translation(3.0, 0.0, 0.0))
        .expect("pose");
    check(client, a, b);
    (a, b)
}

fn check(client: &mut Client, a: gjkd_client::ObjectId, b: gjkd_client::ObjectId) {
    let d = client
        .distance(a, b, &QueryOptions::default())
        .expect("served")
        .distance;
    assert!((d - 2.0).abs() < 1e-12, "{d}");
}

#[test]
fn a_killed_server_is_reported_and_a_restarted_one_serves() {
    let mut server = Server::start("kill", &[]);
    let timeout = Duration::from_millis(800);
    let mut client = server.client(timeout);
    let (a, b) = spheres(&mut client);

    server.kill9();
    let start = Instant::now();
    let err = client
        .distance(a, b, &QueryOptions::default())
        .expect_err("server is dead");
    // Informative only: the machine is too noisy to assert on time. The call
    // gives up at its deadline at the latest.
    eprintln!("dead server reported after {:?}: {err}", start.elapsed());
    assert!(is_gone(&err), "{err:?}");
    // Still gone, and said at once now that the client knows.
    assert!(is_gone(&client.stats().expect_err("still dead")));

    server.restart();
    let stats = once_reached(|| client.stats());
    assert_eq!(
        stats.objects, 2,
        "the restarted server reloaded both objects"
    );
    // Same ids, same answers; and this client still owns what it registered
    // (its identity is its node, which outlived the server).
    check(&mut client, a, b);
    client.remove(b).expect("still the owner after the restart");
    let (a2, b2) = spheres(&mut client);
    assert!(
        a2 != a && b2 != b && a2 != b && b2 != a,
        "ids are never reused"
    );
}

#[test]
fn without_persistence_a_restarted_server_starts_empty() {
    let mut server = Server::start("nopersist", &["--no-persist"]);
    let mut client = server.client(Duration::from_millis(800));
    let (a, b) = spheres(&mut client);
    server.kill9();
    server.restart();
    let stats = once_reached(|| client.stats());
    assert_eq!(stats.objects, 0, "a new server starts empty");
    // Ids of the dead server are unknown to the new one, never aliases.
    assert_eq!(
        client.distance(a, b, &QueryOptions::default()),
        Err(QueryError::UnknownObject)
    );
    let (a2, b2) = spheres(&mut client);
    assert_ne!((a2, b2), (a, b));
}

#[test]
fn a_server_restarted_before_the_client_notices_serves_it() {
    let mut server = Server::start("swap", &[]);
    let mut client = server.client(Duration::from_secs(2));
    spheres(&mut client);
    server.kill9();
    server.restart();
    // The client still holds its old ports; the next calls reach the new
    // server, at most after one ServerGone.
    once_reached(|| client.register_sphere(1.0));
    spheres(&mut client);
}

#[test]
fn sigterm_and_sigint_shut_down_cleanly_leaving_no_services() {
    for signal in [libc::SIGTERM, libc::SIGINT] {
        for wait in ["spin", "block", "adaptive"] {
            let mut server = Server::start("signal", &["--wait", wait]);
            let service = server.service.clone();
            let mut client = server.client(Duration::from_secs(1));
            spheres(&mut client);
            drop(client);
            assert!(services_exist(&service));
            let status = server.signal_and_wait(signal).expect("was running");
            assert!(status.success(), "{wait} after signal {signal}: {status}");
            assert!(!services_exist(&service), "{wait}: services left behind");
        }
    }
}

#[test]
fn a_stopped_server_is_reported_at_once() {
    let mut server = Server::start("stop", &[]);
    let mut client = server.client(Duration::from_secs(30));
    let (a, b) = spheres(&mut client);
    server.terminate();
    let start = Instant::now();
    let err = client
        .distance(a, b, &QueryOptions::default())
        .expect_err("stopped");
    eprintln!("stopped server reported after {:?}", start.elapsed());
    assert!(is_gone(&err), "{err:?}");
}

#[test]
fn connecting_without_a_server_fails() {
    let err = Client::builder(&unique_service("none"))
        .timeout(Duration::from_millis(200))
        .connect()
        .expect_err("nobody serves it");
    assert!(matches!(err, ConnectError::ServerGone(_)), "{err:?}");
    // The same fault in the error every call returns.
    assert!(is_gone(&ClientError::from(err)));
}

#[test]
fn every_wait_strategy_serves() {
    for wait in ["spin", "block", "adaptive"] {
        let server = Server::start("wait", &["--wait", wait]);
        let mut client = server.client(Duration::from_secs(5));
        let info = client.server_info().expect("connected");
        assert_eq!(
            gjkd_client::WaitMode::from_raw(info.wait).map(|m| format!("{m:?}").to_lowercase()),
            Some(wait.to_string())
        );
        assert!(info.max_clients >= 64);
        let (a, b) = spheres(&mut client);
        for _ in 0..50 {
            check(&mut client, a, b);
        }
    }
}

#[test]
fn a_second_server_on_the_same_service_refuses_to_start() {
    let first = Server::start("twice", &[]);
    let mut client = first.client(Duration::from_secs(5));
    let (a, b) = spheres(&mut client);
    let mut second = Server::start_on(&first.service, &[]);
    let status = second.wait_exit().expect("second server exits by itself");
    assert!(!status.success());
    check(&mut client, a, b);
}

#[test]
fn scene_objects_are_looked_up_by_name_and_read_only() {
    let dir = std::env::temp_dir().join(unique_service("scene"));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("scene.toml");
    std::fs::write(
        &path,
        r#"
[[object]]
name = "table"
type = "box"
half_extents = [1.0, 0.5, 0.05]
radius = 0.01
pose = { translation = [0.0, 0.0, 0.75] }

[[object]]
name = "cup"
type = "capsule"
a = [0.0, 0.0, 0.0]
b = [0.0, 0.0, 0.1]
radius = 0.04
pose = { translation = [0.2, 0.1, 1.2], axis_angle = [0.3, 0.0, 0.0] }

[[object]]
name = "gripper"
type = "compound"
[[object.pieces]]
type = "box"
half_extents = [0.01, 0.03, 0.05]
offset = { translation = [-0.05, 0.0, 0.0] }
[[object.pieces]]
type = "box"
half_extents = [0.01, 0.03, 0.05]
offset = { translation = [0.05, 0.0, 0.0] }
"#,
    )
    .expect("write scene");
    let server = Server::start("scene", &["--scene", path.to_str().expect("utf-8 path")]);
    let mut client = server.client(Duration::from_secs(5));
    let table = client.lookup("table").expect("table");
    let cup = client.lookup("cup").expect("cup");
    let gripper = client.lookup("gripper").expect("gripper");
    assert_eq!(client.stats().expect("stats").objects, 3);

    let scene_table: gjk::Shape = gjk::Convex::cuboid(Vector3::new(1.0, 0.5, 0.05), 0.01)
        .expect("box")
        .into();
    let scene_cup: gjk::Shape = Solid::Capsule(
        nalgebra::Point3::origin(),
        nalgebra::Point3::new(0.0, 0.0, 0.1),
        0.04,
    )
    .shape();
    let table_pose = Isometry3::translation(0.0, 0.0, 0.75);
    let cup_pose = Isometry3::new(Vector3::new(0.2, 0.1, 1.2), Vector3::new(0.3, 0.0, 0.0));
    let options = QueryOptions::cold();
    let got = client.distance(table, cup, &options).expect("answer");
    let want = gjk::distance(
        &scene_table,
        &table_pose,
        &scene_cup,
        &cup_pose,
        &gjk_options(&options),
        None,
    )
    .expect("in-process");
    assert_same(&got, &want, "table-cup");
    assert!(got.distance > 0.3 && got.distance < 0.4, "{}", got.distance);

    let hand = Isometry3::translation(0.2, 0.1, 1.25);
    client
        .set_pose(gripper, &hand)
        .expect("scene objects can move");
    let grip = client.distance(gripper, cup, &options).expect("answer");
    assert_eq!(grip.distance, 0.0, "the gripper reaches around the cup");

    assert_eq!(client.remove(table), Err(RemoveError::ReadOnly));
    assert!(client.lookup("table").is_ok());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A hung server (SIGSTOP) is reported within the call's timeout, as a
/// timeout: it is still there, it just does not answer. Once it resumes,
/// it serves the same objects.
#[test]
fn a_hung_server_times_out_and_serves_again_when_resumed() {
    let server = Server::start("hung", &["--wait", "block"]);
    let timeout = Duration::from_millis(500);
    let mut client = server.client(timeout);
    let (a, b) = spheres(&mut client);
    let pid = libc::pid_t::try_from(server.pid().expect("running")).expect("pid");
    // SAFETY: kill(2) on the server we spawned.
    unsafe { libc::kill(pid, libc::SIGSTOP) };
    let start = Instant::now();
    let err = client
        .distance(a, b, &QueryOptions::default())
        .expect_err("stopped");
    let took = start.elapsed();
    // SAFETY: as above.
    unsafe { libc::kill(pid, libc::SIGCONT) };
    eprintln!("hung server reported after {took:?}: {err}");
    assert_eq!(err, QueryError::Connection(ConnectError::Timeout(timeout)));
    assert!(took < timeout + Duration::from_millis(500), "{took:?}");
    check(&mut client, a, b);
}
