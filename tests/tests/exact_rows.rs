//! `exact`: every reported scene row carries its converged distance, where
//! without it rows proved inside a margin early (`Closer`) or answered
//! from motion bounds (`Bounded`) carry estimates; against closed-form
//! distances between a ball and boxes.

use std::time::Duration;

use gjkd_client::{ObjectId, SceneRow, Status, Steps};
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Point3, Vector3};

/// Distance from `p` to the axis-aligned box of half extents `h` at `c`.
fn point_box(p: Point3<f64>, c: Point3<f64>, h: Vector3<f64>) -> f64 {
    let d = (p - c).abs() - h;
    d.map(|x| x.max(0.0)).norm()
}

#[test]
fn exact_rows_carry_converged_distances() {
    let server = Server::start("exact-rows", &["--no-persist"]);
    let mut client = server.client(Duration::from_secs(10));
    let radius = 0.1;
    let ball = client.register_sphere(radius).expect("ball");
    let h = Vector3::new(0.2, 0.3, 0.25);
    let centres: Vec<Point3<f64>> = (0..12)
        .map(|i| {
            let a = i as f64 * 0.52;
            Point3::new(1.5 * a.cos() + 0.3, 1.5 * a.sin(), 0.2 * (i % 3) as f64)
        })
        .collect();
    let boxes: Vec<ObjectId> = centres
        .iter()
        .map(|c| {
            let id = client.register_cuboid(h, 0.0).expect("box");
            client
                .set_pose(id, &Isometry3::translation(c.x, c.y, c.z))
                .expect("pose");
            id
        })
        .collect();
    let margin = 3.0;
    let steps = 30;
    let poses: Vec<Isometry3<f64>> = (0..steps)
        .map(|s| Isometry3::translation(0.01 * s as f64, 0.005 * s as f64, 0.0))
        .collect();
    let path = Steps::Poses {
        objects: &[ball],
        poses: &poses,
    };
    let mut rows = vec![SceneRow::default(); 1024];
    let check = |rows: &[SceneRow], exact: bool| -> usize {
        let mut estimates = 0;
        for row in rows {
            let p = poses[row.step as usize].translation.vector.into();
            let i = boxes.iter().position(|b| b.raw() == row.b).expect("a box");
            let want = point_box(p, centres[i], h) - radius;
            let r = &row.result;
            assert!(r.lower <= want + 1e-9 && want - 1e-9 <= r.upper);
            let estimate = r.status == Status::Closer as u32 || r.status == Status::Bounded as u32;
            if exact {
                assert!(!estimate, "status {} in an exact answer", r.status);
                assert!(
                    (r.distance - want).abs() <= 1e-9 * (1.0 + want),
                    "{} against {want}",
                    r.distance
                );
            }
            estimates += usize::from(estimate);
        }
        estimates
    };
    // Twice each: the second pass answers from the first's motion bounds.
    let mut estimates = 0;
    for _ in 0..2 {
        let s = client
            .within(ball, margin)
            .along(path)
            .into_rows(&mut rows)
            .expect("within");
        assert_eq!(s.written, steps * boxes.len());
        estimates += check(&rows[..s.written], false);
    }
    assert!(estimates > 0, "estimates without exact");
    for _ in 0..2 {
        let s = client
            .within(ball, margin)
            .along(path)
            .exact(true)
            .into_rows(&mut rows)
            .expect("exact within");
        assert_eq!(s.written, steps * boxes.len());
        check(&rows[..s.written], true);
        let s = client
            .clearance(ball)
            .along(path)
            .exact(true)
            .accept(10.0, 1.0)
            .into_rows(&mut rows)
            .expect("exact clearance");
        assert_eq!(s.written, steps);
        check(&rows[..s.written], true);
    }
}

#[test]
fn at_poses_answers_there_and_stores_nothing() {
    let server = Server::start("at-poses", &["--no-persist"]);
    let mut client = server.client(Duration::from_secs(10));
    let ball = client.register_sphere(0.1).expect("ball");
    let h = Vector3::new(0.2, 0.2, 0.2);
    let near = client.register_cuboid(h, 0.0).expect("near");
    let far = client.register_cuboid(h, 0.0).expect("far");
    client
        .set_pose(near, &Isometry3::translation(1.0, 0.0, 0.0))
        .expect("pose");
    client
        .set_pose(far, &Isometry3::translation(-3.0, 0.0, 0.0))
        .expect("pose");
    let mut rows = vec![SceneRow::default(); 8];
    // At a pose given for the question, `near` allowed: the nearest is
    // `far`, 2.5 - 0.2 - 0.1 away.
    let there = [(ball, Isometry3::translation(-0.5, 0.0, 0.0))];
    for kind in ["clearance", "nearest"] {
        // Allowed pairs borrowed for the question only (not 'static).
        let allowed = vec![(ball, near)];
        let q = match kind {
            "clearance" => client.clearance(ball),
            _ => client.nearest(ball, 1),
        };
        let s = q
            .at_poses(&there)
            .allow(&allowed)
            .exact(true)
            .into_rows(&mut rows)
            .expect(kind);
        assert_eq!(s.written, 1, "{kind}");
        assert_eq!(rows[0].b, far.raw(), "{kind}");
        assert!((rows[0].result.distance - 2.2).abs() < 1e-9, "{kind}");
        drop(allowed);
    }
    // Nothing was stored: at the stored identity pose the nearest is
    // `near`, 1.0 - 0.2 - 0.1 away.
    let s = client
        .clearance(ball)
        .exact(true)
        .into_rows(&mut rows)
        .expect("stored");
    assert_eq!((s.written, rows[0].b), (1, near.raw()));
    assert!((rows[0].result.distance - 0.7).abs() < 1e-9);
}
