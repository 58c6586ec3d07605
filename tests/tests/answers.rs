//! Served answers equal in-process gjk answers bit for bit: one pair at a
//! time, batched, cold and warm.

use std::time::Duration;

use gjkd_client::{Item, ItemResult, Precision, QueryOptions};
use gjkd_e2e::{Rng, Server, Solid, assert_same, gjk_options};
use nalgebra::{Isometry3, Point3, Vector3};

const TIMEOUT: Duration = Duration::from_secs(5);

#[test]
fn single_pairs_equal_in_process_answers() {
    let server = Server::start("single", &["--wait", "spin"]);
    let mut client = server.client(TIMEOUT);
    let mut zoo = Solid::zoo();
    // A 2 000-point ellipsoid shell, rounded: large enough for the block
    // search, served as in process.
    let mut rng = Rng::new(5);
    let shell: Vec<Point3<f64>> = (0..2000)
        .map(|_| {
            let v = Vector3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            Point3::from((v / v.norm().max(1e-3)).component_mul(&Vector3::new(1.2, 0.6, 0.9)))
        })
        .collect();
    zoo.push(Solid::Polytope(shell, 0.02));
    let shapes: Vec<gjk::Shape> = zoo.iter().map(Solid::shape).collect();
    let ids: Vec<_> = zoo
        .iter()
        .map(|s| s.register(&mut client).expect("registered"))
        .collect();
    let mut rng = Rng::new(1);
    let option_sets = [
        QueryOptions::cold(),
        QueryOptions {
            tolerance: 1e-6,
            ..QueryOptions::cold()
        },
        QueryOptions {
            margin: Some(0.5),
            ..QueryOptions::cold()
        },
        QueryOptions {
            max_iterations: 2,
            ..QueryOptions::cold()
        },
        // The zoo's 30-point cloud takes the f32 scan, the shell the
        // exact block search.
        QueryOptions {
            precision: Precision::Single,
            ..QueryOptions::cold()
        },
    ];
    let mut checked = 0;
    for i in 0..zoo.len() {
        for j in 0..zoo.len() {
            for options in &option_sets {
                // Stored poses...
                let (pa, pb) = (rng.pose(2.0), rng.pose(2.0));
                client.set_pose(ids[i], &pa).expect("pose a");
                client.set_pose(ids[j], &pb).expect("pose b");
                let got = client.distance(ids[i], ids[j], options).expect("answer");
                // With i == j the second update wins.
                let pa_eff = if i == j { pb } else { pa };
                let want = gjk::distance(
                    &shapes[i],
                    &pa_eff,
                    &shapes[j],
                    &pb,
                    &gjk_options(options),
                    None,
                )
                .expect("in-process");
                assert_same(&got, &want, &format!("stored {i}-{j} {options:?}"));
                // ...and per-query poses.
                let (qa, qb) = (rng.pose(2.0), rng.pose(2.0));
                let got = client
                    .distance_at(ids[i], &qa, ids[j], &qb, options)
                    .expect("answer");
                let want = gjk::distance(
                    &shapes[i],
                    &qa,
                    &shapes[j],
                    &qb,
                    &gjk_options(options),
                    None,
                )
                .expect("in-process");
                assert_same(&got, &want, &format!("own poses {i}-{j} {options:?}"));
                assert!(!got.warm_started);
                checked += 2;
            }
        }
    }
    assert_eq!(checked, 360);
}

#[test]
fn warm_started_sequences_equal_in_process_sequences() {
    let server = Server::start("warm", &["--wait", "spin"]);
    let mut client = server.client(TIMEOUT);
    let zoo = Solid::zoo();
    let (a, b) = (&zoo[4], &zoo[3]);
    let (sa, sb) = (a.shape(), b.shape());
    let ida = a.register(&mut client).expect("a");
    let idb = b.register(&mut client).expect("b");
    let options = QueryOptions::default();
    let pose_b = Isometry3::translation(0.5, 0.3, 0.0);
    client.set_pose(idb, &pose_b).expect("pose b");
    let mut warm: Option<gjk::WarmStart> = None;
    let mut warm_hits = 0;
    for step in 0..200 {
        let s = step as f64 / 200.0;
        let pose_a = Isometry3::new(
            nalgebra::Vector3::new(-4.0 + 8.0 * s, 0.2, -0.1),
            nalgebra::Vector3::new(0.0, 0.0, 3.0 * s),
        );
        let got = client
            .distance_at(ida, &pose_a, idb, &pose_b, &options)
            .expect("answer");
        let want = gjk::distance(
            &sa,
            &pose_a,
            &sb,
            &pose_b,
            &gjk_options(&options),
            warm.as_ref(),
        )
        .expect("in-process");
        assert_same(&got, &want, &format!("step {step}"));
        assert_eq!(got.warm_started, step > 0, "step {step}");
        warm_hits += usize::from(got.warm_started);
        warm = Some(want.warm_start);
    }
    assert_eq!(warm_hits, 199);
    let stats = client.stats().expect("stats");
    assert_eq!(stats.cache_hits, 199);
    assert_eq!(stats.cache_entries, 1);
}

#[test]
fn batches_equal_in_process_answers() {
    let server = Server::start("batch", &["--wait", "spin"]);
    let mut client = server.client(TIMEOUT);
    let zoo = Solid::zoo();
    let shapes: Vec<gjk::Shape> = zoo.iter().map(Solid::shape).collect();
    let ids: Vec<_> = zoo
        .iter()
        .map(|s| s.register(&mut client).expect("registered"))
        .collect();
    let mut rng = Rng::new(9);
    // The server's stored poses, mirrored here.
    let mut poses = vec![Isometry3::identity(); zoo.len()];
    let options = QueryOptions::cold();
    for round in 0..10 {
        let mut items = Vec::new();
        let mut expect: Vec<Option<gjk::Answer>> = Vec::new();
        for k in 0..64 {
            let (i, j) = ((rng.next_u64() % 5) as usize, (rng.next_u64() % 5) as usize);
            match k % 3 {
                0 => {
                    let p = rng.pose(3.0);
                    poses[i] = p;
                    items.push(Item::set_pose(ids[i], &p));
                    expect.push(None);
                }
                1 => {
                    items.push(Item::distance(ids[i], ids[j], &options));
                    expect.push(Some(
                        gjk::distance(
                            &shapes[i],
                            &poses[i],
                            &shapes[j],
                            &poses[j],
                            &gjk_options(&options),
                            None,
                        )
                        .expect("in-process"),
                    ));
                }
                _ => {
                    let (pa, pb) = (rng.pose(3.0), rng.pose(3.0));
                    items.push(Item::distance_at(ids[i], &pa, ids[j], &pb, &options));
                    expect.push(Some(
                        gjk::distance(
                            &shapes[i],
                            &pa,
                            &shapes[j],
                            &pb,
                            &gjk_options(&options),
                            None,
                        )
                        .expect("in-process"),
                    ));
                }
            }
        }
        let mut results = vec![ItemResult::default(); items.len()];
        client.query_batch(&items, &mut results).expect("batch");
        for (k, (r, want)) in results.iter().zip(&expect).enumerate() {
            let got = r.answer().expect("item ok");
            match want {
                None => assert_eq!(got.status, None, "round {round} item {k}"),
                Some(want) => assert_same(&got, want, &format!("round {round} item {k}")),
            }
        }
    }
}

#[test]
fn the_largest_batch_is_answered_in_full() {
    let server = Server::start("maxbatch", &["--wait", "spin"]);
    let mut client = server.client(TIMEOUT);
    let max = client.server_info().expect("connected").max_batch as usize;
    assert_eq!(max, 1024);
    let a = client.register_sphere(0.5).expect("a");
    let b = client.register_sphere(0.25).expect("b");
    let items: Vec<Item> = (0..max)
        .map(|k| {
            Item::distance_at(
                a,
                &Isometry3::identity(),
                b,
                &Isometry3::translation(1.0 + k as f64, 0.0, 0.0),
                &QueryOptions::default(),
            )
        })
        .collect();
    let mut results = vec![ItemResult::default(); max];
    client.query_batch(&items, &mut results).expect("batch");
    for (k, r) in results.iter().enumerate() {
        let d = r.answer().expect("ok").distance;
        assert!((d - (0.25 + k as f64)).abs() < 1e-9, "item {k}: {d}");
    }
}
