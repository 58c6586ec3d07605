//! Scene queries through a real server, against the same server's per-pair
//! queries (every pair asked exactly, cold): clearance, pairs within a
//! margin, nearest objects and paths give the same pairs and distances,
//! truncated answers say so, every whole-request error has its code and
//! changes nothing, and two clients asking along different motions at once
//! never see each other's poses or bounds.

use std::time::Duration;

use gjkd_client::{
    Client, ClientError, ErrorCode, ObjectId, QueryOptions, SceneError, SceneRow, Status, Steps,
};
use gjkd_e2e::{Rng, Server};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};

const TIMEOUT: Duration = Duration::from_secs(10);
/// Two answers of one pair, each to the default relative tolerance, agree
/// to this (relative to the distance, plus an absolute floor).
const AGREE: f64 = 1e-9;

/// A small scene: a group of three moving objects and obstacles around.
struct Scene {
    group: Vec<ObjectId>,
    obstacles: Vec<ObjectId>,
}

impl Scene {
    fn all(&self) -> Vec<ObjectId> {
        self.group.iter().chain(&self.obstacles).copied().collect()
    }
}

fn build_scene(client: &mut Client, seed: u64, obstacles: usize) -> Scene {
    let mut rng = Rng::new(seed);
    let group = vec![
        client.register_sphere(0.3).expect("sphere"),
        client
            .register_capsule(Point3::new(0.0, 0.0, -0.4), Point3::new(0.0, 0.0, 0.4), 0.1)
            .expect("capsule"),
        client
            .register_cuboid(Vector3::new(0.2, 0.3, 0.1), 0.02)
            .expect("box"),
    ];
    for (i, &id) in group.iter().enumerate() {
        let pose = Isometry3::translation(0.0, i as f64 * 0.9 - 0.9, 0.0);
        client.set_pose(id, &pose).expect("group pose");
    }
    let mut list = Vec::new();
    for i in 0..obstacles {
        let id = match i % 3 {
            0 => client.register_sphere(rng.range(0.1, 0.5)),
            1 => client.register_cuboid(
                Vector3::new(
                    rng.range(0.1, 0.4),
                    rng.range(0.1, 0.4),
                    rng.range(0.1, 0.4),
                ),
                0.0,
            ),
            _ => {
                let pts: Vec<Point3<f64>> = (0..12)
                    .map(|_| {
                        Point3::new(
                            rng.range(-0.3, 0.3),
                            rng.range(-0.3, 0.3),
                            rng.range(-0.3, 0.3),
                        )
                    })
                    .collect();
                client.register_polytope(&pts, 0.0)
            }
        }
        .expect("obstacle");
        // Around the group, none inside it.
        let mut pose = rng.pose(4.0);
        if pose.translation.vector.norm() < 2.0 {
            pose.translation.vector *= 2.5 / pose.translation.vector.norm().max(0.1);
        }
        client.set_pose(id, &pose).expect("obstacle pose");
        list.push(id);
    }
    Scene {
        group,
        obstacles: list,
    }
}

/// The exact distance of a pair at the stored poses, asked alone and cold.
fn exact(client: &mut Client, a: ObjectId, b: ObjectId) -> f64 {
    client
        .distance(a, b, &QueryOptions::cold())
        .expect("pair query")
        .distance
}

fn assert_row_certifies(row: &SceneRow, want: f64, context: &str) {
    let r = &row.result;
    assert_eq!(r.error, 0, "{context}: row error {}", r.error);
    let slack = AGREE * (1.0 + want.abs());
    assert!(
        r.lower <= want + slack && want - slack <= r.upper,
        "{context}: interval [{}, {}] excludes {want}",
        r.lower,
        r.upper
    );
    if r.status != Status::Bounded as u32 {
        assert!(
            (r.distance - want).abs() <= slack,
            "{context}: distance {} against {want}",
            r.distance
        );
    }
}

fn start() -> (Server, Client) {
    let server = Server::start("scene", &["--wait", "spin"]);
    let client = server.client(TIMEOUT);
    (server, client)
}

#[test]
fn clearance_finds_each_members_nearest_obstacle() {
    let (_server, mut client) = start();
    let scene = build_scene(&mut client, 11, 15);
    let mut rows = [SceneRow::default(); 8];
    for warm in [false, true, true] {
        let summary = client
            .clearance(&scene.group)
            .warm(warm)
            .into_rows(&mut rows)
            .expect("clearance");
        assert_eq!(summary.written, scene.group.len());
        assert_eq!(summary.total, scene.group.len() as u64);
        assert!(!summary.truncated);
        assert_eq!(summary.steps, 1);
        for (row, &m) in rows[..summary.written].iter().zip(&scene.group) {
            assert_eq!(row.a, m.raw());
            let best = scene
                .obstacles
                .iter()
                .map(|&o| exact(&mut client, m, o))
                .fold(f64::INFINITY, f64::min);
            let b = ObjectId::from_raw(row.b);
            assert!(scene.obstacles.contains(&b), "b {b} is an obstacle");
            // Ties allowed: the partner's exact distance is the minimum.
            let theirs = exact(&mut client, m, b);
            assert!(
                (theirs - best).abs() <= AGREE * (1.0 + best),
                "{theirs} vs {best}"
            );
            assert_row_certifies(row, theirs, "clearance");
        }
    }
}

#[test]
fn clearance_with_a_cutoff_finds_the_near_members_partners() {
    let (_server, mut client) = start();
    let scene = build_scene(&mut client, 12, 9);
    let nearest: Vec<f64> = scene
        .group
        .clone()
        .iter()
        .map(|&m| {
            scene
                .obstacles
                .iter()
                .map(|&o| exact(&mut client, m, o))
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    let mut sorted = nearest.clone();
    sorted.sort_by(f64::total_cmp);
    let cutoff = 0.5 * (sorted[0] + sorted[1]);
    let mut pairs = [gjkd_client::ScenePair::default(); 3];
    let summary = client
        .clearance(&scene.group)
        .cutoff(cutoff)
        .into_pairs(&mut pairs)
        .expect("clearance");
    assert_eq!(summary.written, 3);
    for (pair, &d) in pairs.iter().zip(&nearest) {
        if d <= cutoff {
            let answer = pair.answer.expect("answer");
            assert!(pair.b.is_some());
            assert!((answer.distance - d).abs() <= AGREE * (1.0 + d));
        } else if let Some(b) = pair.b {
            // Objects beyond the cut-off are never searched for, but one
            // found on the way may be reported: then with its own answer.
            let theirs = exact(&mut client, pair.a, b);
            let answer = pair.answer.expect("answer");
            assert!(theirs > cutoff && answer.upper >= theirs - AGREE * (1.0 + theirs));
        }
    }
}

/// A margin halfway in the widest gap between the exact distances of
/// `pairs`, below their median, so that no pair sits near it.
fn margin_between(distances: &[f64]) -> f64 {
    let mut d = distances.to_vec();
    d.sort_by(f64::total_cmp);
    let half = &d[..d.len() / 2 + 1];
    let (i, _) = half
        .windows(2)
        .enumerate()
        .max_by(|x, y| (x.1[1] - x.1[0]).total_cmp(&(y.1[1] - y.1[0])))
        .expect("two distances");
    0.5 * (d[i] + d[i + 1])
}

fn sorted_pairs(rows: &[SceneRow]) -> Vec<(u64, u64)> {
    let mut v: Vec<(u64, u64)> = rows.iter().map(|r| (r.a.min(r.b), r.a.max(r.b))).collect();
    v.sort_unstable();
    v
}

#[test]
fn within_reports_exactly_the_pairs_under_the_margin() {
    let (_server, mut client) = start();
    let scene = build_scene(&mut client, 13, 18);
    let all = scene.all();
    let mut group_pairs = Vec::new();
    let mut every_pair = Vec::new();
    for (i, &a) in all.iter().enumerate() {
        for &b in &all[i + 1..] {
            let d = exact(&mut client, a, b);
            let key = (a.raw().min(b.raw()), a.raw().max(b.raw()));
            every_pair.push((key, d));
            if scene.group.contains(&a) != scene.group.contains(&b) {
                group_pairs.push((key, d));
            }
        }
    }
    let mut rows = vec![SceneRow::default(); 256];
    for (pairs, all_pairs) in [(&group_pairs, false), (&every_pair, true)] {
        let ds: Vec<f64> = pairs.iter().map(|p| p.1).collect();
        let margin = margin_between(&ds);
        let mut want: Vec<(u64, u64)> = pairs
            .iter()
            .filter(|p| p.1 <= margin)
            .map(|p| p.0)
            .collect();
        want.sort_unstable();
        assert!(!want.is_empty(), "the margin {margin} catches some pair");
        let query = client.within(&scene.group, margin);
        let query = if all_pairs { query.all_pairs() } else { query };
        let summary = query.into_rows(&mut rows).expect("within");
        assert!(!summary.truncated);
        assert_eq!(summary.total as usize, summary.written);
        let got = &rows[..summary.written];
        assert_eq!(sorted_pairs(got), want, "all_pairs {all_pairs}");
        for row in got {
            if !all_pairs {
                assert!(
                    scene.group.contains(&ObjectId::from_raw(row.a)),
                    "a is the member"
                );
            }
            let d = pairs
                .iter()
                .find(|p| p.0 == (row.a.min(row.b), row.a.max(row.b)));
            assert!(row.result.lower <= margin);
            let d = d.expect("a known pair").1;
            let r = &row.result;
            assert!(r.lower <= d + AGREE * (1.0 + d) && d - AGREE * (1.0 + d) <= r.upper);
        }
    }
}

#[test]
fn allowed_pairs_are_never_reported() {
    let (_server, mut client) = start();
    let scene = build_scene(&mut client, 14, 10);
    let mut rows = vec![SceneRow::default(); 64];
    let all = client
        .within(&scene.group, 100.0)
        .into_rows(&mut rows)
        .expect("within");
    assert_eq!(
        all.total as usize,
        scene.group.len() * scene.obstacles.len()
    );
    let allowed = [
        (scene.group[0], scene.obstacles[0]),
        (scene.obstacles[1], scene.group[2]),
    ];
    let summary = client
        .within(&scene.group, 100.0)
        .allow(&allowed)
        .into_rows(&mut rows)
        .expect("within");
    assert_eq!(summary.total, all.total - 2);
    for row in &rows[..summary.written] {
        for (x, y) in allowed {
            let pair = (x.raw(), y.raw());
            assert!((row.a, row.b) != pair && (row.b, row.a) != pair);
        }
    }
}

#[test]
fn nearest_k_are_the_k_smallest_distances() {
    let (_server, mut client) = start();
    let scene = build_scene(&mut client, 15, 14);
    let me = scene.group[1];
    let mut want: Vec<f64> = scene
        .all()
        .into_iter()
        .filter(|&o| o != me)
        .map(|o| exact(&mut client, me, o))
        .collect();
    want.sort_by(f64::total_cmp);
    let mut rows = [SceneRow::default(); 5];
    let summary = client.nearest(me, 5).into_rows(&mut rows).expect("nearest");
    assert_eq!(summary.written, 5);
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row.a, me.raw());
        let d = exact(&mut client, me, ObjectId::from_raw(row.b));
        // Ties allowed: the k-th row's exact distance is the k-th smallest.
        assert!(
            (d - want[k]).abs() <= AGREE * (1.0 + d),
            "row {k}: {d} vs {}",
            want[k]
        );
        assert_row_certifies(row, d, "nearest");
    }
}

/// The group's poses along a sweep in x: `steps` steps, every member
/// shifted by `dx` per step from its stored pose.
fn sweep(starts: &[Isometry3<f64>], steps: usize, dx: f64) -> Vec<Isometry3<f64>> {
    (0..steps)
        .flat_map(|s| {
            starts
                .iter()
                .map(move |p| Translation3::new(dx * s as f64, 0.0, 0.0) * p)
        })
        .collect()
}

fn stored_poses(scene: &Scene) -> Vec<Isometry3<f64>> {
    (0..scene.group.len())
        .map(|i| Isometry3::translation(0.0, i as f64 * 0.9 - 0.9, 0.0))
        .collect()
}

/// Exact clearance of every member at each step's poses, per-pair queries
/// with the member moved there: `[step][member]`. Leaves the members at the
/// last step's poses.
fn path_reference(client: &mut Client, scene: &Scene, poses: &[Isometry3<f64>]) -> Vec<Vec<f64>> {
    let n = scene.group.len();
    poses
        .chunks(n)
        .map(|step| {
            scene
                .group
                .iter()
                .zip(step)
                .map(|(&m, pose)| {
                    client.set_pose(m, pose).expect("move");
                    scene
                        .obstacles
                        .iter()
                        .map(|&o| exact(client, m, o))
                        .fold(f64::INFINITY, f64::min)
                })
                .collect()
        })
        .collect()
}

#[test]
fn path_clearance_matches_each_step_and_moves_nothing() {
    let (_server, mut client) = start();
    let scene = build_scene(&mut client, 16, 12);
    let starts = stored_poses(&scene);
    let poses = sweep(&starts, 6, 0.35);
    let want = path_reference(&mut client, &scene, &poses);
    for (&m, p) in scene.group.iter().zip(&starts) {
        client.set_pose(m, p).expect("back to the start");
    }
    let before: Vec<f64> = scene
        .group
        .iter()
        .map(|&m| exact(&mut client, m, scene.obstacles[0]))
        .collect();
    let mut rows = vec![SceneRow::default(); 64];
    let steps = Steps::Poses {
        objects: &scene.group,
        poses: &poses,
    };
    for _ in 0..2 {
        let summary = client
            .path(&scene.group, steps)
            .into_rows(&mut rows)
            .expect("path");
        assert_eq!(summary.steps, 6);
        assert_eq!(summary.written, 6 * scene.group.len());
        for row in &rows[..summary.written] {
            let m = scene
                .group
                .iter()
                .position(|g| g.raw() == row.a)
                .expect("member");
            let d = want[row.step as usize][m];
            let r = &row.result;
            let slack = AGREE * (1.0 + d);
            assert!(
                r.lower <= d + slack && d - slack <= r.upper,
                "step {} member {m}",
                row.step
            );
        }
    }
    let after: Vec<f64> = scene
        .group
        .iter()
        .map(|&m| exact(&mut client, m, scene.obstacles[0]))
        .collect();
    assert_eq!(before, after, "a path moves nothing");
}

#[test]
fn until_hit_stops_at_the_first_step_within_the_margin() {
    let (_server, mut client) = start();
    let scene = build_scene(&mut client, 17, 12);
    let starts = stored_poses(&scene);
    let poses = sweep(&starts, 10, 0.4);
    let want = path_reference(&mut client, &scene, &poses);
    for (&m, p) in scene.group.iter().zip(&starts) {
        client.set_pose(m, p).expect("back to the start");
    }
    let per_step: Vec<f64> = want
        .iter()
        .map(|s| s.iter().copied().fold(f64::INFINITY, f64::min))
        .collect();
    let margin = margin_between(&per_step);
    let first = per_step.iter().position(|&d| d <= margin);
    let mut rows = vec![SceneRow::default(); 64];
    let summary = client
        .within(&scene.group, margin)
        .until_hit(Steps::Poses {
            objects: &scene.group,
            poses: &poses,
        })
        .into_rows(&mut rows)
        .expect("first hit");
    assert_eq!(summary.first_hit, first.map(|f| f as u32));
    if let Some(f) = first {
        assert!(summary.written > 0);
        assert!(rows[..summary.written].iter().all(|r| r.step == f as u32));
    } else {
        assert_eq!(summary.written, 0);
    }
    // A margin below every distance: the whole path is clear.
    let clear = client
        .within(
            &scene.group,
            0.5 * per_step.iter().copied().fold(f64::INFINITY, f64::min),
        )
        .until_hit(Steps::Poses {
            objects: &scene.group,
            poses: &poses,
        })
        .into_rows(&mut rows)
        .expect("clear path");
    assert_eq!(clear.first_hit, None);
    assert_eq!(clear.written, 0);
}

#[test]
fn a_short_buffer_gets_a_prefix_and_the_truncated_flag() {
    let (_server, mut client) = start();
    let scene = build_scene(&mut client, 18, 10);
    let mut rows = [SceneRow::default(); 4];
    let summary = client
        .within(&scene.group, 100.0)
        .into_rows(&mut rows)
        .expect("within");
    assert!(summary.truncated);
    assert_eq!(summary.written, 4);
    assert_eq!(
        summary.total as usize,
        scene.group.len() * scene.obstacles.len()
    );
    // No buffer at all still counts.
    let count = client
        .within(&scene.group, 100.0)
        .into_rows(&mut [])
        .expect("count only");
    assert_eq!((count.written, count.total), (0, summary.total));
    assert!(count.truncated);
}

fn rejected(outcome: Result<gjkd_client::SceneSummary, SceneError>) -> ErrorCode {
    match outcome.map_err(ClientError::from) {
        Err(ClientError::Rejected(code)) => code,
        other => panic!("expected a rejection, got {other:?}"),
    }
}

#[test]
fn every_whole_request_error_has_its_code_and_changes_nothing() {
    let server = Server::start("scene-errors", &["--wait", "spin", "--max-batch", "16"]);
    let mut client = server.client(TIMEOUT);
    let scene = build_scene(&mut client, 19, 6);
    let g = &scene.group;
    let mut rows = [SceneRow::default(); 8];
    let before = exact(&mut client, g[0], scene.obstacles[0]);
    let moved = Isometry3::translation(50.0, 0.0, 0.0);
    let nan = Isometry3::translation(f64::NAN, 0.0, 0.0);
    let skew = Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::new_unchecked(Quaternion::new(2.0, 0.0, 0.0, 0.0)),
    );
    let gone = ObjectId::from_raw(0xdead_0000_0001);
    let cases: Vec<(
        &str,
        ErrorCode,
        Result<gjkd_client::SceneSummary, SceneError>,
    )> = vec![
        (
            "unknown group",
            ErrorCode::UnknownObject,
            client.clearance(gone).into_rows(&mut rows),
        ),
        (
            "unknown member",
            ErrorCode::UnknownObject,
            client
                .clearance(&[g[0], gone])
                .with_poses(&[(g[0], moved)])
                .into_rows(&mut rows),
        ),
        (
            "negative tolerance",
            ErrorCode::InvalidOptions,
            client.clearance(g).tolerance(-1.0).into_rows(&mut rows),
        ),
        (
            "zero iteration cap",
            ErrorCode::InvalidOptions,
            client.clearance(g).max_iterations(0).into_rows(&mut rows),
        ),
        (
            "NaN margin",
            ErrorCode::InvalidOptions,
            client.within(g, f64::NAN).into_rows(&mut rows),
        ),
        (
            "negative accepted accuracy",
            ErrorCode::InvalidOptions,
            client.clearance(g).accept(-1.0, 0.0).into_rows(&mut rows),
        ),
        (
            "nearest zero",
            ErrorCode::InvalidOptions,
            client.nearest(g[0], 0).into_rows(&mut rows),
        ),
        (
            "nearest of several",
            ErrorCode::Malformed,
            client
                .nearest(g[0], 2)
                .members(&g[..2])
                .into_rows(&mut rows),
        ),
        (
            "unknown allowed object",
            ErrorCode::UnknownObject,
            client
                .clearance(g)
                .allow(&[(g[0], gone)])
                .into_rows(&mut rows),
        ),
        (
            "first hit of a clearance",
            ErrorCode::Malformed,
            client
                .clearance(g)
                .until_hit(Steps::Poses {
                    objects: &g[..1],
                    poses: &[moved],
                })
                .into_rows(&mut rows),
        ),
        (
            "NaN pose",
            ErrorCode::NonFinitePose,
            client
                .clearance(g)
                .with_poses(&[(g[0], moved), (g[1], nan)])
                .into_rows(&mut rows),
        ),
        (
            "skewed rotation",
            ErrorCode::BadQuaternion,
            client
                .clearance(g)
                .with_poses(&[(g[0], moved), (g[1], skew)])
                .into_rows(&mut rows),
        ),
        (
            "more items than max_batch",
            ErrorCode::BatchTooLarge,
            client
                .clearance(g)
                .with_poses(&[(g[0], moved); 17])
                .into_rows(&mut rows),
        ),
    ];
    for (what, code, outcome) in cases {
        assert_eq!(rejected(outcome), code, "{what}");
    }
    assert_eq!(
        exact(&mut client, g[0], scene.obstacles[0]),
        before,
        "no refused request moved anything"
    );
    // An empty group is no error: nothing to answer.
    let empty = client
        .clearance(&[] as &[ObjectId])
        .into_rows(&mut rows)
        .expect("an empty group");
    assert_eq!((empty.written, empty.total), (0, 0));
    // The server still answers.
    let ok = client
        .clearance(g)
        .into_rows(&mut rows)
        .expect("still serving");
    assert_eq!(ok.written, g.len());
}

#[test]
fn ragged_steps_are_refused_before_sending() {
    let (_server, mut client) = start();
    let scene = build_scene(&mut client, 20, 3);
    let poses = [Isometry3::identity(); 5];
    let outcome = client
        .path(
            &scene.group,
            Steps::Poses {
                objects: &scene.group,
                poses: &poses,
            },
        )
        .into_rows(&mut []);
    assert_eq!(outcome, Err(SceneError::PartialSteps));
}

#[test]
fn two_clients_along_different_paths_see_only_their_own() {
    let (server, mut client) = start();
    let scene = build_scene(&mut client, 21, 12);
    let starts = stored_poses(&scene);
    let paths = [sweep(&starts, 5, 0.3), sweep(&starts, 5, -0.3)];
    let wants: Vec<Vec<Vec<f64>>> = paths
        .iter()
        .map(|p| path_reference(&mut client, &scene, p))
        .collect();
    for (&m, p) in scene.group.iter().zip(&starts) {
        client.set_pose(m, p).expect("back to the start");
    }
    let service = server.service.clone();
    let group = scene.group.clone();
    std::thread::scope(|s| {
        for (path, want) in paths.iter().zip(&wants) {
            let service = service.clone();
            let group = group.clone();
            s.spawn(move || {
                let mut client = gjkd_e2e::connect(&service, TIMEOUT);
                let mut rows = vec![SceneRow::default(); 32];
                for round in 0..40 {
                    let summary = client
                        .path(
                            &group,
                            Steps::Poses {
                                objects: &group,
                                poses: path,
                            },
                        )
                        .into_rows(&mut rows)
                        .expect("path");
                    assert_eq!(summary.written, 5 * group.len());
                    for row in &rows[..summary.written] {
                        let m = group.iter().position(|g| g.raw() == row.a).expect("member");
                        let d = want[row.step as usize][m];
                        let r = &row.result;
                        let slack = AGREE * (1.0 + d);
                        assert!(
                            r.lower <= d + slack && d - slack <= r.upper,
                            "round {round} step {} member {m}: [{}, {}] vs {d}",
                            row.step,
                            r.lower,
                            r.upper
                        );
                    }
                }
            });
        }
    });
}
