//! Paths longer than one request takes come back whole: a 1 000-step
//! Panda path with the server's default limits, and paths through a server
//! whose limits are a few items and rows, split by the client into many
//! requests, answer as the exact per-pair reference (and as the same
//! question asked one step at a time).

use std::path::{Path, PathBuf};
use std::time::Duration;

use gjkd_client::{Client, Geometry, ObjectId, PackagePath, QueryOptions, SceneRow, Status, Steps};
use gjkd_e2e::{Rng, Server};
use nalgebra::{Isometry3, Translation3, Vector3};

const TIMEOUT: Duration = Duration::from_secs(20);
/// Two answers of one pair, each to the default relative tolerance, agree
/// to this (relative to the distance, plus an absolute floor).
const AGREE: f64 = 1e-9;

fn real_robots() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../model/tests/data")
}

/// Whether `row`'s interval holds `want` and, unless answered from motion
/// bounds, its distance is `want`.
fn certifies(row: &SceneRow, want: f64) -> bool {
    let r = &row.result;
    let slack = AGREE * (1.0 + want.abs());
    r.error == 0
        && r.lower <= want + slack
        && want - slack <= r.upper
        && (r.status == Status::Bounded as u32 || (r.distance - want).abs() <= slack)
}

#[test]
fn a_1000_step_panda_path_comes_back_whole_with_default_limits() {
    let urdf = real_robots().join("example-robot-data/robots/panda_description/urdf/panda.urdf");
    let server = Server::start("long-panda", &["--no-persist"]);
    let mut client = server.client(TIMEOUT);
    let info = client.server_info().expect("connected");
    let packages = PackagePath::new([real_robots()]);
    let mut panda = client
        .register_robot("panda", &urdf, None, &packages, &Isometry3::identity())
        .expect("panda");
    let obstacle = client
        .register_named(
            "box",
            &Geometry::Cuboid {
                half_extents: Vector3::new(0.1, 0.4, 0.3),
                radius: 0.0,
            },
            &Isometry3::translation(0.6, 0.0, 0.4),
        )
        .expect("box");
    let dof = panda.positions.len();
    let links = panda.links.iter().flatten().count();
    let steps = 1000;
    let limits: Vec<(f64, f64)> = panda
        .kinematics
        .moving_joints()
        .map(|j| (j.lower, j.upper))
        .collect();
    assert_eq!(limits.len(), dof);
    let positions: Vec<f64> = (0..steps)
        .flat_map(|s| {
            let t = s as f64 / steps as f64;
            limits.iter().enumerate().map(move |(j, &(lo, hi))| {
                let (mid, half) = if lo.is_finite() && hi.is_finite() {
                    (0.5 * (lo + hi), 0.4 * (hi - lo))
                } else {
                    (0.0, 1.0)
                };
                mid + half * (t * 6.0 + j as f64).sin()
            })
        })
        .collect();
    assert!(
        steps * links > info.max_batch as usize,
        "the path's rows are more than one request's items"
    );
    let mut rows = vec![SceneRow::default(); steps * links + 16];
    let summary = client
        .path(&panda, Steps::joints(&panda, &positions))
        .into_rows(&mut rows)
        .expect("path");
    assert!(!summary.truncated, "{summary:?}");
    assert_eq!(summary.steps as usize, steps);
    assert_eq!(summary.written, steps * links);
    assert_eq!(summary.total as usize, steps * links);
    for (i, row) in rows[..summary.written].iter().enumerate() {
        assert_eq!(row.step as usize, i / links, "rows in step order");
    }
    // Steps across the requests the client made, against the same question
    // asked at that step alone.
    let mut alone = vec![SceneRow::default(); links];
    for s in [0, 1, 333, 334, 500, 998, 999] {
        client
            .set_joints(&mut panda, &positions[s * dof..(s + 1) * dof], None)
            .expect("joints");
        let one = client
            .clearance(&panda)
            .motion_bounds(false)
            .into_rows(&mut alone)
            .expect("alone");
        assert_eq!(one.written, links);
        for want in &alone {
            let got = rows[s * links..(s + 1) * links]
                .iter()
                .find(|r| r.a == want.a)
                .expect("the link's row");
            assert_eq!(got.b, want.b, "step {s}: the nearest object");
            assert!(
                certifies(got, want.result.distance),
                "step {s} link {:#x}: {:?} against {}",
                want.a,
                got.result,
                want.result.distance
            );
        }
        assert_eq!(
            alone.iter().filter(|r| r.b == obstacle.raw()).count(),
            alone.iter().filter(|r| r.b != 0).count()
        );
    }
}

/// Three moving spheres and boxes among obstacles, on a server of `args`.
fn scene(client: &mut Client, seed: u64) -> (Vec<ObjectId>, Vec<ObjectId>) {
    let mut rng = Rng::new(seed);
    let group: Vec<ObjectId> = (0..3)
        .map(|i| {
            let id = if i % 2 == 0 {
                client.register_sphere(0.2)
            } else {
                client.register_cuboid(Vector3::new(0.2, 0.1, 0.15), 0.0)
            }
            .expect("member");
            client
                .set_pose(id, &Isometry3::translation(0.0, i as f64 * 0.8 - 0.8, 0.0))
                .expect("pose");
            id
        })
        .collect();
    let obstacles = (0..15)
        .map(|_| {
            let id = client
                .register_sphere(rng.range(0.1, 0.3))
                .expect("obstacle");
            let mut pose = rng.pose(3.0);
            pose.translation.vector.x = rng.range(-1.0, 5.0);
            client.set_pose(id, &pose).expect("pose");
            id
        })
        .collect();
    (group, obstacles)
}

/// The members' poses along `steps` steps of 0.1 along x.
fn sweep(client: &mut Client, group: &[ObjectId], steps: usize) -> Vec<Isometry3<f64>> {
    let starts: Vec<Isometry3<f64>> = (0..group.len())
        .map(|i| Isometry3::translation(0.0, i as f64 * 0.8 - 0.8, 0.0))
        .collect();
    let _ = client;
    (0..steps)
        .flat_map(|s| {
            starts
                .iter()
                .map(move |p| Translation3::new(0.1 * s as f64, 0.0, 0.0) * p)
        })
        .collect()
}

/// Exact distance of every member to every obstacle at each step:
/// `[step][member][obstacle]`, moving the members; puts them back.
fn reference(
    client: &mut Client,
    group: &[ObjectId],
    obstacles: &[ObjectId],
    poses: &[Isometry3<f64>],
) -> Vec<Vec<Vec<f64>>> {
    let out = poses
        .chunks(group.len())
        .map(|step| {
            group
                .iter()
                .zip(step)
                .map(|(&m, pose)| {
                    client.set_pose(m, pose).expect("move");
                    obstacles
                        .iter()
                        .map(|&o| {
                            client
                                .distance(m, o, &QueryOptions::cold())
                                .expect("pair")
                                .distance
                        })
                        .collect()
                })
                .collect()
        })
        .collect();
    for (&m, p) in group.iter().zip(&poses[..group.len()]) {
        client.set_pose(m, p).expect("back");
    }
    out
}

#[test]
fn paths_split_by_the_client_answer_as_the_exact_reference() {
    // Sixteen items and 24 rows a request: a 40-step path of three
    // members takes ten requests or more.
    let server = Server::start(
        "long-split",
        &["--no-persist", "--max-batch", "16", "--max-rows", "24"],
    );
    let mut client = server.client(TIMEOUT);
    let (group, obstacles) = scene(&mut client, 41);
    let steps = 40;
    let poses = sweep(&mut client, &group, steps);
    let want = reference(&mut client, &group, &obstacles, &poses);
    let path = Steps::Poses {
        objects: &group,
        poses: &poses,
    };
    let mut rows = vec![SceneRow::default(); 4096];

    // Clearance: one row a member and step, whatever the requests.
    let summary = client
        .path(&group, path)
        .into_rows(&mut rows)
        .expect("clearance path");
    assert!(!summary.truncated);
    assert_eq!(
        (summary.steps as usize, summary.written),
        (steps, steps * 3)
    );
    for (i, row) in rows[..summary.written].iter().enumerate() {
        assert_eq!(row.step as usize, i / 3);
        let m = group.iter().position(|g| g.raw() == row.a).expect("member");
        let d = want[i / 3][m].iter().copied().fold(f64::INFINITY, f64::min);
        assert!(certifies(row, d), "step {} member {m}", row.step);
    }

    // Within: rows a step vary, and the steps one request takes have more
    // rows than it holds (the client asks again from the step cut); every
    // pair under the margin is there, once.
    let margin = 2.0;
    let summary = client
        .within(&group, margin)
        .motion_bounds(false)
        .along(path)
        .into_rows(&mut rows)
        .expect("within path");
    let mut expected: Vec<(u32, u64, u64)> = Vec::new();
    for (s, members) in want.iter().enumerate() {
        for (m, ds) in members.iter().enumerate() {
            for (o, &d) in ds.iter().enumerate() {
                assert!((d - margin).abs() > 1e-6, "a margin on a distance");
                if d <= margin {
                    expected.push((s as u32, group[m].raw(), obstacles[o].raw()));
                }
            }
        }
    }
    let per_step: Vec<usize> = want
        .iter()
        .map(|s| s.iter().flatten().filter(|&&d| d <= margin).count())
        .collect();
    assert!(
        per_step.iter().all(|&n| n <= 24)
            && per_step.windows(4).any(|w| w.iter().sum::<usize>() > 24),
        "steps that fit a request, four together that do not: {per_step:?}"
    );
    let mut got: Vec<(u32, u64, u64)> = rows[..summary.written]
        .iter()
        .map(|r| (r.step, r.a, r.b))
        .collect();
    got.sort_unstable();
    expected.sort_unstable();
    assert!(!summary.truncated);
    assert_eq!(summary.total as usize, expected.len());
    assert_eq!(got, expected);

    // The first step within a margin, found in a later request.
    let per_step: Vec<f64> = want
        .iter()
        .map(|s| s.iter().flatten().copied().fold(f64::INFINITY, f64::min))
        .collect();
    let early = per_step[..4].iter().copied().fold(f64::INFINITY, f64::min);
    let hit_margin = 0.5 * early;
    let first = per_step.iter().position(|&d| d <= hit_margin);
    let hit = client
        .within(&group, hit_margin)
        .until_hit(path)
        .into_rows(&mut rows)
        .expect("until hit");
    assert_eq!(hit.first_hit, first.map(|f| f as u32), "{per_step:?}");
    if let Some(f) = first {
        assert!(hit.written > 0);
        assert!(rows[..hit.written].iter().all(|r| r.step as usize == f));
    }

    // A buffer shorter than the answer: a prefix, the whole count.
    let mut short = vec![SceneRow::default(); 25];
    let cut = client
        .path(&group, path)
        .into_rows(&mut short)
        .expect("short buffer");
    assert!(cut.truncated);
    assert_eq!((cut.written, cut.total as usize), (25, steps * 3));
    for (i, row) in short.iter().enumerate() {
        assert_eq!((row.step as usize, row.a), (i / 3, group[i % 3].raw()));
    }
}
