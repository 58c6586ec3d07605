//! Signed distances on scene rows (`SceneQuery::signed_distance`), and the
//! non-unique flag of overlapping pairs' gradients, through a real server:
//! every question (clearance, within, nearest, a path's rows) against
//! closed forms (a ball in a box: `r + ` the centre's distance to the
//! nearest face) and the brute-force Minkowski depth of two boxes; pairs
//! apart carry their distance; the default asks nothing; a continuous path
//! refuses the flag.

use gjkd_client::{
    Client, ClientError, Group, ObjectId, QueryOptions, SceneError, ScenePair, Status, Steps,
};
use gjkd_e2e::Server;
use gjkd_testkit::minkowski_depth::minkowski_depth;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// A box `[-1, 1]³` (the crate), a ball of radius 0.5 whose centre is 0.2
/// inside the crate's face x = 1 (0.7 deep), a ball 2.5 beyond the face
/// y = 1, and a tilted box of half extents 0.4 overlapping the crate's
/// face z = 1.
struct Scene {
    crate_: ObjectId,
    deep: ObjectId,
    apart: ObjectId,
    tilted: ObjectId,
    tilted_pose: Isometry3<f64>,
}

const TILTED_HALF: f64 = 0.4;

fn scene(client: &mut Client) -> Result<Scene, ClientError> {
    let crate_ = client.register_cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?;
    let deep = client.register_sphere(0.5)?;
    client.set_pose(deep, &Isometry3::translation(0.8, 0.1, 0.0))?;
    let apart = client.register_sphere(0.5)?;
    client.set_pose(apart, &Isometry3::translation(0.0, 4.0, 0.0))?;
    let tilted = client.register_cuboid(Vector3::repeat(TILTED_HALF), 0.0)?;
    let tilted_pose = Isometry3::from_parts(
        Translation3::new(0.2, -0.3, 1.25),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.3, 0.2, 0.1)),
    );
    client.set_pose(tilted, &tilted_pose)?;
    Ok(Scene {
        crate_,
        deep,
        apart,
        tilted,
        tilted_pose,
    })
}

/// The eight corners of a box of half extents `h` at `pose`.
fn corners(h: Vector3<f64>, pose: &Isometry3<f64>) -> Vec<Point3<f64>> {
    let mut out = Vec::new();
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                out.push(pose * Point3::new(sx * h.x, sy * h.y, sz * h.z));
            }
        }
    }
    out
}

/// The signed distance every row of the scene's pairs must carry, from
/// the crate: closed forms and the brute-force Minkowski depth.
fn expected(s: &Scene, b: ObjectId) -> f64 {
    if b == s.deep {
        -0.7
    } else if b == s.apart {
        2.5
    } else {
        assert_eq!(b, s.tilted);
        let crate_corners = corners(Vector3::repeat(1.0), &Isometry3::identity());
        let tilted = corners(Vector3::repeat(TILTED_HALF), &s.tilted_pose);
        let (depth, _) = minkowski_depth(&crate_corners, &tilted).expect("they overlap");
        -depth
    }
}

/// Checks a row's signed distance against the independent answer (its
/// value when the row converged: a row apart answered at a margin's early
/// exit carries the distance's estimate), and its witnesses against its
/// value.
fn check(s: &Scene, pair: &ScenePair) {
    let b = pair.b.expect("a pair");
    let answer = pair.answer.expect("answered");
    let signed = answer.signed.expect("asked for");
    let want = expected(s, b);
    let slack = 1e-9 * want.abs().max(1.0);
    if want <= 0.0 || answer.status == Some(Status::Converged) {
        assert!(
            (signed.value - want).abs() <= slack,
            "{b:?}: {signed:?} vs {want}"
        );
    }
    assert!(
        signed.lower <= want + slack && want - slack <= signed.upper,
        "{b:?}: {signed:?} vs {want}"
    );
    if want > 0.0 {
        // Apart: the distance itself, interval and all.
        assert_eq!(
            (signed.value, signed.lower, signed.upper),
            (answer.distance, answer.lower, answer.upper)
        );
    } else {
        assert_eq!(answer.distance, 0.0);
    }
    let gap = answer.point_b - answer.point_a - answer.normal * signed.value;
    assert!(gap.norm() < 1e-9, "{answer:?}");
}

#[test]
fn readme_signed_rows_example_runs() -> Result<(), ClientError> {
    let server = Server::start("doc-signed-rows", &[]);
    let service = server.service.as_str();
    // --- from README.md, "Signed distance in batches and scene rows" ---

    let mut client = Client::connect(service)?;
    let crate_ = client.register_cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?;
    let ball = client.register_sphere(0.5)?;
    client.set_pose(ball, &Isometry3::translation(0.8, 0.0, 0.0))?; // 0.7 deep
    let mut pairs = [ScenePair::default(); 8];
    let got = client
        .within(crate_, 0.0)
        .signed_distance()
        .into_pairs(&mut pairs)?;
    assert_eq!(got.written, 1); // overlapping: within any margin
    let signed = pairs[0]
        .answer
        .expect("answered")
        .signed
        .expect("asked for");
    assert!((signed.value + 0.7).abs() < 1e-9);
    assert!(signed.lower <= -0.7 && -0.7 <= signed.upper);
    Ok(())
}

#[test]
fn every_question_carries_the_signed_distance_when_asked() -> Result<(), ClientError> {
    let server = Server::start("signed-rows", &[]);
    let mut client = Client::connect(&server.service)?;
    let s = scene(&mut client)?;
    let mut pairs = [ScenePair::default(); 8];

    // Within a margin of 3: all three, the overlapping ones with their
    // depth, the one apart with its distance (exact with `exact`, else
    // the early exit's estimate and interval).
    for exact in [true, false] {
        let got = client
            .within(s.crate_, 3.0)
            .exact(exact)
            .signed_distance()
            .into_pairs(&mut pairs)?;
        assert_eq!(got.written, 3);
        for pair in &pairs[..3] {
            check(&s, pair);
            let converged = pair.answer.unwrap().status == Some(Status::Converged);
            assert!(converged || !exact, "{pair:?}");
        }
    }
    // Within a margin of 0: the overlapping pairs however deep, not the
    // one apart (the question compares the distance, 0 when overlapping).
    let got = client
        .within(s.crate_, 0.0)
        .signed_distance()
        .into_pairs(&mut pairs)?;
    let mut found: Vec<ObjectId> = pairs[..got.written].iter().filter_map(|p| p.b).collect();
    found.sort();
    let mut want = vec![s.deep, s.tilted];
    want.sort();
    assert_eq!(found, want);
    for pair in &pairs[..got.written] {
        check(&s, pair);
    }
    // Without the flag, no row carries one.
    let got = client.within(s.crate_, 3.0).into_pairs(&mut pairs)?;
    assert_eq!(got.written, 3);
    assert!(
        pairs[..3]
            .iter()
            .all(|p| p.answer.unwrap().signed.is_none())
    );

    // Nearest, 3 of them: each row with its own.
    let got = client
        .nearest(s.crate_, 3)
        .signed_distance()
        .into_pairs(&mut pairs)?;
    assert_eq!(got.written, 3);
    for pair in &pairs[..3] {
        check(&s, pair);
    }
    // Clearance of each ball: the crate, from the ball's side (the sign
    // is the pair's, whichever is `a`).
    let balls = [s.deep, s.apart];
    let got = client
        .clearance(Group::Members(&balls))
        .signed_distance()
        .into_pairs(&mut pairs)?;
    assert_eq!(got.written, 2);
    for pair in &pairs[..2] {
        assert_eq!(pair.b, Some(s.crate_));
        let signed = pair.answer.unwrap().signed.expect("asked for");
        let want = if pair.a == s.deep { -0.7 } else { 2.5 };
        assert!((signed.value - want).abs() < 1e-9, "{pair:?}");
        assert!(signed.lower <= want && want <= signed.upper, "{pair:?}");
    }
    Ok(())
}

#[test]
fn a_paths_rows_carry_each_steps_signed_distance() -> Result<(), ClientError> {
    let server = Server::start("signed-path", &[]);
    let mut client = Client::connect(&server.service)?;
    let s = scene(&mut client)?;
    // The deep ball at three steps: 0.2, 0.5 and 0.9 inside the face x = 1
    // (0.7, 1.0 and 1.4 deep: at 0.9 inside, the face x = 1 is still the
    // nearest), then 0.5 beyond it (apart by 0).
    let xs = [0.8, 0.5, 0.1, 2.0];
    let poses: Vec<Isometry3<f64>> = xs
        .iter()
        .map(|&x| Isometry3::translation(x, 0.0, 0.0))
        .collect();
    let moving = [s.deep];
    let mut pairs = [ScenePair::default(); 8];
    let got = client
        .path(
            Group::Members(&moving),
            Steps::Poses {
                objects: &moving,
                poses: &poses,
            },
        )
        .signed_distance()
        .into_pairs(&mut pairs)?;
    assert_eq!((got.steps, got.written), (4, 4));
    for (pair, x) in pairs.iter().zip(xs) {
        let want = if x <= 1.0 {
            -(0.5 + (1.0 - x).min(1.0))
        } else {
            x - 1.5
        };
        let signed = pair.answer.unwrap().signed.expect("asked for");
        assert!(
            (signed.value - want).abs() < 1e-9,
            "step {}: {signed:?} vs {want}",
            pair.step
        );
        assert!(signed.lower <= want + 1e-12 && want - 1e-12 <= signed.upper);
    }
    // The stored pose is the same after the path.
    let after = client.distance(
        s.crate_,
        s.deep,
        &QueryOptions {
            signed_distance: true,
            ..QueryOptions::default()
        },
    )?;
    assert!((after.signed.unwrap().value + 0.7).abs() < 1e-9);
    Ok(())
}

#[test]
fn a_continuous_path_refuses_signed_rows() -> Result<(), ClientError> {
    let server = Server::start("signed-continuous", &[]);
    let mut client = Client::connect(&server.service)?;
    let s = scene(&mut client)?;
    let moving = [s.apart];
    let poses = [
        Isometry3::translation(0.0, 4.0, 0.0),
        Isometry3::translation(0.0, 3.0, 0.0),
    ];
    let steps = Steps::Poses {
        objects: &moving,
        poses: &poses,
    };
    let mut contacts = [gjkd_client::Contact::default(); 4];
    let refused = client
        .within(Group::Members(&moving), 0.1)
        .signed_distance()
        .continuous(steps, 1e-6)
        .into_contacts(&mut contacts);
    assert!(matches!(refused, Err(SceneError::Malformed)), "{refused:?}");
    // The same path without the flag is answered.
    let clear = client
        .within(Group::Members(&moving), 0.1)
        .continuous(steps, 1e-6)
        .into_contacts(&mut contacts)?;
    assert_eq!(clear.written, 0);
    Ok(())
}

/// A ball of radius 0.5 centred at `c` inside the crate: the gradient of
/// the pair (crate, ball) with respect to the crate's twist, from a pair
/// query and from a scene row.
fn overlap_gradients(
    client: &mut Client,
    crate_: ObjectId,
    ball: ObjectId,
    c: Vector3<f64>,
) -> Result<[gjkd_client::Gradient; 2], ClientError> {
    client.set_pose(ball, &Isometry3::translation(c.x, c.y, c.z))?;
    let options = QueryOptions {
        signed_distance: true,
        warm_start: false,
        ..QueryOptions::default()
    };
    let item = gjkd_client::Item::distance(crate_, ball, &options).with_gradient(false);
    let mut out = [gjkd_client::ItemResult::default()];
    let mut gradient = [gjkd_client::Gradient::NONE];
    client.query_batch_gradients(&[item], &mut out, &mut gradient)?;
    let pair = out[0].answer_with(Some(&gradient[0])).expect("answered");
    let mut pairs = [ScenePair::default(); 2];
    let got = client
        .within(crate_, 0.0)
        .signed_distance()
        .gradients(false)
        .into_pairs(&mut pairs)?;
    assert_eq!(got.written, 1);
    let row = pairs[0].answer.expect("answered");
    // The ball's depth: 0.5 plus its centre's distance to the nearest face.
    let depth = 0.5 + (1.0 - c.x.abs()).min(1.0 - c.y.abs()).min(1.0 - c.z.abs());
    for answer in [&pair, &row] {
        let signed = answer.signed.expect("asked for");
        assert!((signed.value + depth).abs() < 1e-9, "{answer:?}");
    }
    Ok([
        pair.gradient.expect("asked for"),
        row.gradient.expect("asked for"),
    ])
}

#[test]
fn overlapping_pairs_flag_a_tied_depth_direction() -> Result<(), ClientError> {
    let server = Server::start("signed-ties", &[]);
    let mut client = Client::connect(&server.service)?;
    let crate_ = client.register_cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?;
    let ball = client.register_sphere(0.5)?;
    // On the medial axis between the faces x = 1 and y = 1: two shortest
    // ways out, no gradient.
    for g in overlap_gradients(&mut client, crate_, ball, Vector3::new(0.5, 0.5, 0.0))? {
        assert!(g.is_present() && g.is_not_unique(), "{g:?}");
        assert_eq!(g.columns, 6);
    }
    // Nearer the face x = 1: one way out, a gradient. In the crate's
    // frame the ball's centre is at x_c, its signed distance
    // x_c - 1.5: moving the crate along +x (v_x) takes x_c down at unit
    // rate; turning it about z (ω_z) turns the centre by -ω_z about z,
    // which takes x_c up at 0.1 (its y) per radian; nothing else moves it
    // across the face.
    for g in overlap_gradients(&mut client, crate_, ball, Vector3::new(0.8, 0.1, 0.0))? {
        assert!(g.is_present() && !g.is_not_unique(), "{g:?}");
        let want = [-1.0, 0.0, 0.0, 0.0, 0.0, 0.1];
        for (got, want) in g.as_slice().iter().zip(want) {
            assert!((got - want).abs() < 1e-9, "{g:?}");
        }
    }
    Ok(())
}
