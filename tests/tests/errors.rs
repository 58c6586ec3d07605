//! Bad requests get their specific error, and the server keeps serving.

use std::time::Duration;

use gjkd_client::{
    Client, ClientError, ErrorCode, Geometry, Item, ItemResult, ObjectId, Piece, QueryError,
    QueryOptions, RegisterError, ShapeError,
};
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Point3, Vector3};

const TIMEOUT: Duration = Duration::from_secs(5);

fn rejected<E: Into<ClientError>>(r: Result<impl std::fmt::Debug, E>) -> ErrorCode {
    match r.map_err(Into::into) {
        Err(ClientError::Rejected(code)) => code,
        other => panic!("expected a rejection, got {other:?}"),
    }
}

/// Two spheres 3 apart: the query every test repeats to show the server is
/// still serving after a bad request.
struct Probe {
    a: ObjectId,
    b: ObjectId,
}

impl Probe {
    fn new(client: &mut Client) -> Self {
        let a = client.register_sphere(0.5).expect("a");
        let b = client.register_sphere(0.5).expect("b");
        client
            .set_pose(b, &Isometry3::translation(3.0, 0.0, 0.0))
            .expect("pose");
        Probe { a, b }
    }

    fn check(&self, client: &mut Client) {
        let d = client
            .distance(self.a, self.b, &QueryOptions::default())
            .expect("server still serving")
            .distance;
        assert!((d - 2.0).abs() < 1e-12, "{d}");
    }
}

#[test]
fn unknown_and_removed_ids() {
    let server = Server::start("ids", &[]);
    let mut client = server.client(TIMEOUT);
    let probe = Probe::new(&mut client);
    let ghost = ObjectId::from_raw(0xdead_beef);
    let o = QueryOptions::default();

    assert_eq!(
        rejected(client.distance(probe.a, ghost, &o)),
        ErrorCode::UnknownObject
    );
    assert_eq!(
        rejected(client.distance(ghost, probe.a, &o)),
        ErrorCode::UnknownObject
    );
    assert_eq!(
        rejected(client.set_pose(ghost, &Isometry3::identity())),
        ErrorCode::UnknownObject
    );
    assert_eq!(rejected(client.remove(ghost)), ErrorCode::UnknownObject);
    probe.check(&mut client);

    let doomed = client.register_sphere(1.0).expect("doomed");
    client.distance(probe.a, doomed, &o).expect("alive");
    client.remove(doomed).expect("removed");
    assert_eq!(
        rejected(client.distance(probe.a, doomed, &o)),
        ErrorCode::UnknownObject
    );
    assert_eq!(
        rejected(client.set_pose(doomed, &Isometry3::identity())),
        ErrorCode::UnknownObject
    );
    assert_eq!(rejected(client.remove(doomed)), ErrorCode::UnknownObject);
    // Ids are not reused: the next object gets a new one.
    let next = client.register_sphere(1.0).expect("next");
    assert_ne!(next, doomed);
    assert_eq!(
        rejected(client.distance(probe.a, doomed, &o)),
        ErrorCode::UnknownObject
    );
    probe.check(&mut client);

    assert_eq!(rejected(client.lookup("nobody")), ErrorCode::UnknownName);
    probe.check(&mut client);
}

#[test]
fn non_finite_and_non_unit_poses() {
    let server = Server::start("poses", &[]);
    let mut client = server.client(TIMEOUT);
    let probe = Probe::new(&mut client);
    let o = QueryOptions::default();
    let nan = Isometry3::translation(f64::NAN, 0.0, 0.0);
    let inf = Isometry3::translation(0.0, f64::INFINITY, 0.0);

    assert_eq!(
        rejected(client.set_pose(probe.a, &nan)),
        ErrorCode::NonFinitePose
    );
    assert_eq!(
        rejected(client.set_pose(probe.a, &inf)),
        ErrorCode::NonFinitePose
    );
    assert_eq!(
        rejected(client.distance_at(probe.a, &nan, probe.b, &Isometry3::identity(), &o)),
        ErrorCode::NonFinitePose
    );
    assert_eq!(
        rejected(client.distance_at(probe.a, &Isometry3::identity(), probe.b, &nan, &o)),
        ErrorCode::NonFinitePose
    );
    // The rejected update left the stored pose alone.
    probe.check(&mut client);

    let mut stretched = Item::set_pose(probe.a, &Isometry3::identity());
    stretched.pose_a.rotation = [0.0, 0.0, 0.0, 1.5];
    let mut nearly = stretched;
    nearly.pose_a.rotation = [0.0, 0.0, 0.0, 1.0 + 5e-7];
    let mut results = [ItemResult::default(); 2];
    client
        .query_batch(&[stretched, nearly], &mut results)
        .expect("request");
    assert_eq!(results[0].answer().unwrap_err(), ErrorCode::BadQuaternion);
    assert!(results[1].answer().is_ok(), "within 1e-6 is normalised");
    probe.check(&mut client);
}

#[test]
fn invalid_options() {
    let server = Server::start("options", &[]);
    let mut client = server.client(TIMEOUT);
    let probe = Probe::new(&mut client);
    let base = QueryOptions::default();
    for bad in [
        QueryOptions {
            tolerance: -1.0,
            ..base
        },
        QueryOptions {
            tolerance: f64::NAN,
            ..base
        },
        QueryOptions {
            max_iterations: 0,
            ..base
        },
        QueryOptions {
            margin: Some(f64::NAN),
            ..base
        },
    ] {
        assert_eq!(
            rejected(client.distance(probe.a, probe.b, &bad)),
            ErrorCode::InvalidOptions,
            "{bad:?}"
        );
    }
    let mut unknown = Item::distance(probe.a, probe.b, &base);
    unknown.kind = 99;
    let mut flags = Item::distance(probe.a, probe.b, &base);
    flags.flags = u32::MAX;
    let mut results = [ItemResult::default(); 2];
    // Every bit asks a gradient too: refused by the client without room
    // for it, answered Malformed by the server with room.
    assert_eq!(
        client.query_batch(&[unknown, flags], &mut results),
        Err(QueryError::NoRoomForGradient)
    );
    let mut gradient = [gjkd_client::Gradient::NONE];
    client
        .query_batch_gradients(&[unknown, flags], &mut results, &mut gradient)
        .expect("request");
    assert_eq!(gradient[0], gjkd_client::Gradient::NONE);
    assert_eq!(results[0].answer().unwrap_err(), ErrorCode::Malformed);
    assert_eq!(results[1].answer().unwrap_err(), ErrorCode::Malformed);
    probe.check(&mut client);
}

#[test]
fn invalid_geometry() {
    let server = Server::start("geometry", &["--max-vertices", "100"]);
    let mut client = server.client(TIMEOUT);
    let probe = Probe::new(&mut client);
    let p = Point3::new(1.0, 2.0, 3.0);

    assert_eq!(
        rejected(client.register_polytope(&[], 0.0)),
        ErrorCode::EmptyVertices
    );
    assert_eq!(
        rejected(client.register_sphere(-1.0)),
        ErrorCode::InvalidRadius
    );
    assert_eq!(
        rejected(client.register_sphere(f64::NAN)),
        ErrorCode::InvalidRadius
    );
    assert_eq!(
        rejected(client.register_polytope(&[p, Point3::new(f64::NAN, 0.0, 0.0)], 0.0)),
        ErrorCode::NonFiniteVertex
    );
    assert_eq!(
        rejected(client.register_polytope(&vec![p; 101], 0.0)),
        ErrorCode::TooManyVertices
    );
    assert!(client.register_polytope(&vec![p; 100], 0.0).is_ok());
    assert_eq!(
        rejected(client.register_compound(&[])),
        ErrorCode::EmptyCompound
    );
    let empty_piece = [Piece {
        offset: Isometry3::identity(),
        geometry: Geometry::Polytope {
            vertices: &[],
            radius: 0.0,
        },
    }];
    assert_eq!(
        rejected(client.register_compound(&empty_piece)),
        ErrorCode::EmptyVertices
    );
    let bad_offset = [Piece {
        offset: Isometry3::translation(f64::NAN, 0.0, 0.0),
        geometry: Geometry::Sphere { radius: 1.0 },
    }];
    assert_eq!(
        rejected(client.register_compound(&bad_offset)),
        ErrorCode::NonFinitePose
    );
    let nested = [Piece {
        offset: Isometry3::identity(),
        geometry: Geometry::Compound(&bad_offset),
    }];
    assert_eq!(
        client.register_compound(&nested),
        Err(RegisterError::InvalidShape(ShapeError::CompoundIsNested))
    );
    assert_eq!(
        client.register_named(
            &"n".repeat(65),
            &Geometry::Sphere { radius: 1.0 },
            &Isometry3::identity()
        ),
        Err(RegisterError::NameTooLong)
    );
    let named = client
        .register_named(
            "twin",
            &Geometry::Sphere { radius: 1.0 },
            &Isometry3::identity(),
        )
        .expect("first");
    assert_eq!(
        rejected(client.register_named(
            "twin",
            &Geometry::Cuboid {
                half_extents: Vector3::new(1.0, 1.0, 1.0),
                radius: 0.0
            },
            &Isometry3::identity()
        )),
        ErrorCode::NameTaken
    );
    assert_eq!(client.lookup("twin").expect("found"), named);
    probe.check(&mut client);
}

#[test]
fn bad_batches() {
    let server = Server::start("batches", &["--max-batch", "64"]);
    let mut client = server.client(TIMEOUT);
    let probe = Probe::new(&mut client);
    let item = Item::distance(probe.a, probe.b, &QueryOptions::default());

    let mut results = vec![ItemResult::default(); 100];
    assert_eq!(
        rejected(client.query_batch(&[item; 65], &mut results)),
        ErrorCode::BatchTooLarge
    );
    assert_eq!(
        rejected(client.query_batch(&[], &mut results)),
        ErrorCode::EmptyBatch
    );
    assert_eq!(
        client.query_batch(&[item; 3], &mut results[..2]),
        Err(QueryError::ResultBufferTooSmall { needed: 3, got: 2 })
    );
    client
        .query_batch(&[item; 64], &mut results)
        .expect("at the limit");
    assert!(results[..64].iter().all(|r| r.answer().is_ok()));

    // One bad item fails alone; the others are answered.
    let ghost = ObjectId::from_raw(7);
    let mixed = [
        item,
        Item::distance(probe.a, ghost, &QueryOptions::default()),
        item,
    ];
    client.query_batch(&mixed, &mut results).expect("request");
    assert!((results[0].answer().expect("ok").distance - 2.0).abs() < 1e-12);
    assert_eq!(results[1].answer().unwrap_err(), ErrorCode::UnknownObject);
    assert!((results[2].answer().expect("ok").distance - 2.0).abs() < 1e-12);
    let stats = client.stats().expect("stats");
    assert!(stats.item_errors >= 1);
    probe.check(&mut client);
}

#[test]
fn only_owners_remove() {
    let server = Server::start("owners", &[]);
    let mut alice = server.client(TIMEOUT);
    let mut bob = server.client(TIMEOUT);
    let probe = Probe::new(&mut alice);
    let hers = alice.register_sphere(1.0).expect("hers");
    assert_eq!(rejected(bob.remove(hers)), ErrorCode::NotOwner);
    // Bob may still query it and move it.
    bob.distance(hers, probe.a, &QueryOptions::default())
        .expect("query");
    alice.remove(hers).expect("owner removes");
    probe.check(&mut bob);
}
