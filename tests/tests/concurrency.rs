//! Many clients at once each get their own answers, with their own warm
//! starts, and the service takes at least 64 clients.

use std::sync::Barrier;
use std::time::Duration;

use gjkd_client::{ObjectId, QueryOptions};
use gjkd_e2e::{Server, Solid, assert_same, gjk_options};
use nalgebra::{Isometry3, Vector3};

const TIMEOUT: Duration = Duration::from_secs(10);

fn path_pose(client: usize, step: usize) -> Isometry3<f64> {
    let s = step as f64 / 100.0;
    Isometry3::new(
        Vector3::new(
            -3.0 + 6.0 * s,
            0.3 * client as f64 - 1.0,
            0.1 * client as f64,
        ),
        Vector3::new(0.0, 0.2 * client as f64, 2.0 * s),
    )
}

/// Threads query the same pair along different paths at the same time, warm
/// start on. Each one's answers equal an in-process warm-started sequence
/// along its own path: nobody got a simplex, or a pose, from anyone else.
#[test]
fn concurrent_clients_get_their_own_warm_answers() {
    let server = Server::start("threads", &["--wait", "adaptive"]);
    let zoo = Solid::zoo();
    let mut setup = server.client(TIMEOUT);
    let a = zoo[4].register(&mut setup).expect("a");
    let b = zoo[2].register(&mut setup).expect("b");
    let (sa, sb) = (zoo[4].shape(), zoo[2].shape());
    let pose_b = Isometry3::translation(0.0, 0.0, 0.5);
    setup.set_pose(b, &pose_b).expect("pose b");

    // The clients stay connected until the statistics are read: the
    // server's housekeeping forgets a departed client's cache entries, and
    // under load it may run between the threads' end and `stats`.
    let (done, read) = (Barrier::new(9), Barrier::new(9));
    let stats = std::thread::scope(|scope| {
        for c in 0..8 {
            let (sa, sb, service) = (&sa, &sb, &server.service);
            let (done, read) = (&done, &read);
            scope.spawn(move || {
                // Waits also when an assertion fails, so the test fails
                // instead of hanging.
                let mut hold = HoldUntilRead(done, read, None);
                let client = hold.2.insert(gjkd_e2e::connect(service, TIMEOUT));
                let options = QueryOptions::default();
                let mut warm: Option<gjk::WarmStart> = None;
                for step in 0..=100 {
                    let pose_a = path_pose(c, step);
                    let got = client
                        .distance_at(a, &pose_a, b, &pose_b, &options)
                        .expect("answer");
                    let want = gjk::distance(
                        sa,
                        &pose_a,
                        sb,
                        &pose_b,
                        &gjk_options(&options),
                        warm.as_ref(),
                    )
                    .expect("in-process");
                    assert_same(&got, &want, &format!("client {c} step {step}"));
                    assert_eq!(got.warm_started, step > 0, "client {c} step {step}");
                    warm = Some(want.warm_start);
                }
            });
        }
        done.wait();
        let stats = setup.stats();
        read.wait();
        stats.expect("stats")
    });
    assert_eq!(stats.cache_hits, 8 * 100);
    assert_eq!(stats.cache_entries, 8);
}

/// 64 clients connected at the same time (iceoryx2's own default is 8), each
/// with its own object and stored pose, queried round-robin.
#[test]
fn sixty_four_clients_at_once() {
    let server = Server::start("many", &["--wait", "adaptive"]);
    let mut clients: Vec<_> = (0..64).map(|_| server.client(TIMEOUT)).collect();
    let fixed = clients[0].register_sphere(1.0).expect("fixed");
    let mine: Vec<ObjectId> = clients
        .iter_mut()
        .enumerate()
        .map(|(k, c)| {
            let id = c.register_sphere(0.5).expect("own");
            c.set_pose(id, &Isometry3::translation(2.0 + k as f64, 0.0, 0.0))
                .expect("pose");
            id
        })
        .collect();
    for round in 0..3 {
        for (k, c) in clients.iter_mut().enumerate() {
            let d = c
                .distance(fixed, mine[k], &QueryOptions::default())
                .expect("answer")
                .distance;
            assert!(
                (d - (0.5 + k as f64)).abs() < 1e-9,
                "round {round} client {k}: {d}"
            );
        }
    }
    assert_eq!(clients[5].stats().expect("stats").objects, 65);
}

/// Keeps a client thread's client connected until the statistics are read:
/// when dropped, waits on the first barrier, then the second, and only then
/// drops the client.
struct HoldUntilRead<'a>(&'a Barrier, &'a Barrier, Option<gjkd_client::Client>);

impl Drop for HoldUntilRead<'_> {
    fn drop(&mut self) {
        self.0.wait();
        self.1.wait();
    }
}
