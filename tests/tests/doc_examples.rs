//! The examples of the client's rustdoc, run against a real server: they are
//! `no_run` there (a doctest cannot start a server), so they are run here, as
//! written, with only the service name changed.

use gjkd_e2e::Server;

#[test]
fn crate_example_runs() -> Result<(), gjkd_client::ClientError> {
    let server = Server::start("doc-crate", &[]);
    let service = server.service.as_str();
    // --- from client/src/lib.rs, crate docs ---
    use gjkd_client::{Client, QueryOptions};
    use nalgebra::{Isometry3, Vector3};

    let mut client = Client::connect(service)?;
    let ball = client.register_sphere(0.5)?;
    let crate_ = client.register_cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?;

    // Poses are stored by the server until changed...
    client.set_pose(ball, &Isometry3::translation(3.0, 0.0, 0.0))?;
    let answer = client.distance(crate_, ball, &QueryOptions::default())?;
    assert!((answer.distance - 1.5).abs() < 1e-9);
    println!("nearest points {} and {}", answer.point_a, answer.point_b);

    // ...or given per query, leaving the stored ones alone.
    let answer = client.distance_at(
        crate_,
        &Isometry3::identity(),
        ball,
        &Isometry3::translation(0.0, 4.0, 0.0),
        &QueryOptions::default(),
    )?;
    assert!((answer.distance - 2.5).abs() < 1e-9);
    Ok(())
}

#[test]
fn batch_example_runs() -> Result<(), gjkd_client::ClientError> {
    let server = Server::start("doc-batch", &[]);
    let service = server.service.as_str();
    // --- from client/src/lib.rs, "Batches" ---
    use gjkd_client::{Client, ErrorCode, Item, ItemResult, QueryOptions};
    use nalgebra::{Isometry3, Vector3};

    let mut client = Client::connect(service)?;
    let robot = client.register_cuboid(Vector3::new(0.5, 0.5, 1.0), 0.05)?;
    let obstacles: Vec<_> = (0..8)
        .map(|_| client.register_sphere(0.3))
        .collect::<Result<_, _>>()?;
    for (i, &o) in obstacles.iter().enumerate() {
        client.set_pose(o, &Isometry3::translation(2.0 + i as f64, 0.0, 0.0))?;
    }

    let mut items = Vec::new();
    let mut results = vec![ItemResult::default(); obstacles.len() + 1];
    let mut answered = 0;
    for step in 0..100 {
        items.clear();
        let pose = Isometry3::translation(0.05 * step as f64, 0.0, 0.0);
        items.push(Item::set_pose(robot, &pose));
        for &o in &obstacles {
            items.push(Item::distance(robot, o, &QueryOptions::default()));
        }
        client.query_batch(&items, &mut results)?;
        for r in &results[1..] {
            match r.answer() {
                Ok(a) => {
                    answered += 1;
                    let _ = a.distance;
                }
                Err(ErrorCode::UnknownObject) => println!("removed meanwhile"),
                Err(e) => println!("error: {e}"),
            }
        }
    }
    // Checks of our own: every query answered, and at the last step the
    // robot (rounded box, left face at 4.95 - 0.5 - 0.05) has passed the
    // first obstacle (ball at 2 of radius 0.3).
    assert_eq!(answered, 800);
    let last = results[1].answer().expect("ok").distance;
    let expect: f64 = (0.05 * 99.0 - 0.5 - 0.05) - (2.0 + 0.3);
    assert!((last - expect).abs() < 1e-9, "{last} vs {expect}");
    Ok(())
}

#[test]
fn compound_example_runs() -> Result<(), gjkd_client::ClientError> {
    let server = Server::start("doc-compound", &[]);
    let service = server.service.as_str();
    // --- from client/src/lib.rs, Client::register_compound ---
    use gjkd_client::{Client, Geometry, Piece};
    use nalgebra::{Isometry3, Point3};

    let mut client = Client::connect(service)?;
    let ball = Geometry::Sphere { radius: 0.3 };
    let bar = Geometry::Capsule {
        a: Point3::new(-1.0, 0.0, 0.0),
        b: Point3::new(1.0, 0.0, 0.0),
        radius: 0.05,
    };
    let dumbbell = client.register_compound(&[
        Piece {
            offset: Isometry3::translation(-1.0, 0.0, 0.0),
            geometry: ball,
        },
        Piece {
            offset: Isometry3::identity(),
            geometry: bar,
        },
        Piece {
            offset: Isometry3::translation(1.0, 0.0, 0.0),
            geometry: ball,
        },
    ])?;
    // Ours: the far ball is the nearest piece to something on its side.
    let probe = client.register_sphere(0.2)?;
    let a = client.distance_at(
        dumbbell,
        &Isometry3::identity(),
        probe,
        &Isometry3::translation(3.0, 0.0, 0.0),
        &gjkd_client::QueryOptions::default(),
    )?;
    assert!((a.distance - 1.5).abs() < 1e-9, "{}", a.distance);
    assert_eq!(a.pieces, [2, 0]);
    Ok(())
}

#[test]
fn cylinder_example_runs() -> Result<(), gjkd_client::ClientError> {
    let server = Server::start("doc-cylinder", &["--no-persist"]);
    let service = server.service.as_str();
    // --- from client/src/lib.rs, Client::register_cylinder ---
    use gjkd_client::{Client, Geometry, QueryOptions};
    use nalgebra::Isometry3;

    let mut client = Client::connect(service)?;
    let can = client.register_cylinder(0.5, 1.0, 0.0)?;
    let ball = client.register_named(
        "ball",
        &Geometry::Sphere { radius: 0.25 },
        &Isometry3::translation(2.0, 0.0, 0.3),
    )?;
    // Beside the curved face: 2 - 0.5 - 0.25.
    let d = client
        .distance(can, ball, &QueryOptions::default())?
        .distance;
    assert!((d - 1.25).abs() < 1e-12);
    Ok(())
}

#[test]
fn readme_scene_example_runs() -> Result<(), gjkd_client::ClientError> {
    let server = Server::start("doc-scene", &["--no-persist"]);
    let service = server.service.as_str();
    // --- from README.md, "Scene queries" ---
    use gjkd_client::{Client, SceneRow, Steps};
    use nalgebra::{Isometry3, Vector3};

    let mut client = Client::connect(service)?;
    let arm = [client.register_sphere(0.2)?, client.register_sphere(0.2)?];
    client.set_pose(arm[1], &Isometry3::translation(0.0, 1.0, 0.0))?;
    let wall = client.register_cuboid(Vector3::new(0.1, 3.0, 1.0), 0.0)?;
    client.set_pose(wall, &Isometry3::translation(1.0, 0.0, 0.0))?;

    let mut rows = [SceneRow::default(); 16];
    // Each member's nearest object outside the group: here the wall, 0.7 away.
    let s = client.clearance(&arm).into_rows(&mut rows)?;
    assert_eq!((s.written, rows[0].b), (2, wall.raw()));
    assert!((rows[0].result.distance - 0.7).abs() < 1e-9);
    // Every pair (group against the rest) within a margin.
    let s = client.within(&arm, 1.0).into_rows(&mut rows)?;
    assert_eq!(s.total, 2);
    // The k objects nearest to one object, nearest first.
    client.nearest(arm[0], 2).into_rows(&mut rows)?;
    // A candidate motion, checked step by step; nothing moves on the server.
    let poses: Vec<Isometry3<f64>> = (0..5)
        .flat_map(|k| (0..2).map(move |i| Isometry3::translation(0.15 * k as f64, i as f64, 0.0)))
        .collect();
    let steps = Steps::Poses {
        objects: &arm,
        poses: &poses,
    };
    let s = client
        .within(&arm, 0.2)
        .until_hit(steps)
        .into_rows(&mut rows)?;
    assert_eq!(s.first_hit, Some(4));
    Ok(())
}

#[test]
fn readme_gradients_example_runs() -> Result<(), gjkd_client::ClientError> {
    let server = Server::start("doc-gradients", &["--no-persist"]);
    let service = server.service.as_str();
    // --- from README.md, "Gradients" ---
    use gjkd_client::{
        Client, Gradient, Item, ItemResult, PackagePath, QueryOptions, SceneRow, gradient_matrix,
    };
    use nalgebra::Isometry3;

    let mut client = Client::connect(service)?;
    // A 1 m rod turning about z, and a ball beside it.
    let urdf = r#"<robot name="arm"><link name="base"/>
  <link name="rod"><collision><origin xyz="0.5 0 0"/>
    <geometry><box size="1 0.1 0.1"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="rod"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#;
    let identity = Isometry3::identity();
    let arm =
        client.register_robot_text("arm", urdf, None, None, &PackagePath::default(), &identity)?;
    let rod = arm.link("rod").expect("the rod has geometry");
    let ball = client.register_sphere(0.1)?;
    client.set_pose(ball, &Isometry3::translation(0.8, 0.5, 0.0))?;

    // One pair: 0.35 apart; turning the joint towards the ball closes the gap
    // at 0.8 m per radian.
    let answer = client.distance_gradient(rod, ball, &QueryOptions::default(), false)?;
    let gradient = answer.gradient.expect("asked");
    assert!((answer.distance - 0.35).abs() < 1e-9);
    assert!((gradient.as_slice()[0] + 0.8).abs() < 1e-9 && !gradient.is_not_unique());

    // A batch: only the items that ask carry a gradient, the k-th that asks
    // into gradients[k] (buffers of yours, kept from call to call).
    let plain = Item::distance(rod, ball, &QueryOptions::default());
    let items = [plain, plain.with_gradient(false)];
    let mut results = [ItemResult::default(); 2];
    let mut gradients = [Gradient::NONE; 1];
    assert_eq!(
        client.query_batch_gradients(&items, &mut results, &mut gradients)?,
        1
    );
    assert!((gradients[0].as_slice()[0] + 0.8).abs() < 1e-9);

    // Every pair within 1 m, each row with its gradient, copied into one
    // (rows, dof) array.
    let mut rows = [SceneRow::default(); 8];
    let s = client
        .within(&arm, 1.0)
        .gradients(false)
        .into_rows(&mut rows)?;
    let mut matrix = [0.0; 8];
    gradient_matrix(&rows[..s.written], 1, &mut matrix);
    assert!((matrix[0] + 0.8).abs() < 1e-9);
    Ok(())
}

#[test]
fn readme_errors_example_runs() -> Result<(), gjkd_client::ClientError> {
    let server = Server::start("doc-errors", &["--no-persist"]);
    let service = server.service.as_str();
    // --- from README.md, "Every call has a timeout", twice: the second
    // registration of the name meets its own variant ---
    use gjkd_client::{Client, ConnectError, Geometry, RegisterError};
    use nalgebra::Isometry3;

    let mut client = Client::connect(service)?;
    let mut said = Vec::new();
    for _ in 0..2 {
        let ball = Geometry::Sphere { radius: 0.1 };
        match client.register_named("ball", &ball, &Isometry3::identity()) {
            Ok(id) => said.push(format!("registered {id}")),
            Err(RegisterError::NameTaken) => said.push("someone else's ball".to_owned()),
            Err(RegisterError::Connection(ConnectError::ServerGone(s))) => {
                said.push(format!("no server on {s}"))
            }
            Err(e) => return Err(e.into()),
        }
    }
    assert!(said[0].starts_with("registered "), "{said:?}");
    assert_eq!(said[1], "someone else's ball");
    Ok(())
}

#[test]
fn crate_errors_example_runs() -> Result<(), gjkd_client::ClientError> {
    let server = Server::start("doc-crate-errors", &["--no-persist"]);
    let service = server.service.as_str();
    // --- from client/src/lib.rs, crate docs, "Errors", twice: the second
    // time the name is taken and the object found by it ---
    use gjkd_client::{Client, Geometry, QueryError, QueryOptions, RegisterError};
    use nalgebra::Isometry3;

    let mut client = Client::connect(service)?;
    let mut ids = Vec::new();
    for _ in 0..2 {
        let ball = Geometry::Sphere { radius: 0.5 };
        let id = match client.register_named("ball", &ball, &Isometry3::identity()) {
            Err(RegisterError::NameTaken) => client.lookup("ball")?,
            other => other?,
        };
        match client.distance(id, id, &QueryOptions::default()) {
            Err(QueryError::UnknownObject) => println!("removed meanwhile"),
            other => println!("{:?}", other?.distance),
        }
        ids.push(id);
    }
    assert_eq!(ids[0], ids[1]);
    Ok(())
}
