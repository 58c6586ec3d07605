//! Each operation's error, met for real: a fault of every operation
//! provoked against a running server comes back as its own variant, with
//! the code the umbrella `ClientError` (what Python and C read) gives the
//! same fault.

use std::time::Duration;

use gjkd_client::{
    Client, ClientError, ConnectError, ErrorCode, Geometry, Item, ItemResult, LookupError,
    ObjectId, PackagePath, PoseError, PoseReadError, QueryError, QueryOptions, RegisterError,
    RemoveError, RobotError, SceneError, SceneRow, StatsError, Steps,
};
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};

const TIMEOUT: Duration = Duration::from_secs(5);

/// A one-joint arm: a base box and a ball on a revolute joint limited to
/// [-1, 1].
const ARM: &str = r#"<robot name="arm">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="hand"><collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="hand"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"#;

/// `e` has `code`, and so has the umbrella error of the same fault.
fn has_code<E: Clone + Into<ClientError> + std::fmt::Debug>(e: &E, own: Option<ErrorCode>) {
    let umbrella: ClientError = e.clone().into();
    assert_eq!(umbrella.code(), own, "{e:?} as {umbrella:?}");
}

/// A pose whose rotation is far off unit length.
fn skewed() -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::new_unchecked(Quaternion::new(2.0, 0.0, 0.0, 0.0)),
    )
}

#[test]
fn registrations_removals_and_look_ups_fail_with_their_own_errors() {
    let server = Server::start("op-admin", &["--no-persist"]);
    let mut alice = server.client(TIMEOUT);
    let mut bob = server.client(TIMEOUT);
    let ball = Geometry::Sphere { radius: 0.5 };

    let e = alice.register_sphere(-1.0).unwrap_err();
    assert_eq!(e, RegisterError::InvalidRadius);
    assert_eq!(e.code(), Some(ErrorCode::InvalidRadius));
    has_code(&e, e.code());
    let hers = alice
        .register_named("hers", &ball, &Isometry3::identity())
        .expect("registered");
    let e = bob
        .register_named("hers", &ball, &Isometry3::identity())
        .unwrap_err();
    assert_eq!(e, RegisterError::NameTaken);
    assert_eq!(e.code(), Some(ErrorCode::NameTaken));
    has_code(&e, e.code());
    let e = alice.register_named("x", &ball, &skewed()).unwrap_err();
    assert_eq!(e, RegisterError::BadQuaternion);
    has_code(&e, Some(ErrorCode::BadQuaternion));

    let e = bob.remove(hers).unwrap_err();
    assert_eq!(e, RemoveError::NotOwner);
    assert_eq!(e.code(), Some(ErrorCode::NotOwner));
    has_code(&e, e.code());
    alice.remove(hers).expect("hers to remove");
    let e = alice.remove(hers).unwrap_err();
    assert_eq!(e, RemoveError::UnknownObject);
    has_code(&e, Some(ErrorCode::UnknownObject));

    let e = alice.lookup("hers").unwrap_err();
    assert_eq!(e, LookupError::UnknownName);
    assert_eq!(e.code(), Some(ErrorCode::UnknownName));
    has_code(&e, e.code());
    let e = alice.robot_id("nobody").unwrap_err();
    assert_eq!(e, LookupError::UnknownName);
    let e = alice.lookup(&"n".repeat(65)).unwrap_err();
    assert_eq!(e, LookupError::NameTooLong);
    assert_eq!(e.code(), None);
    has_code(&e, None);
}

#[test]
fn poses_and_pair_queries_fail_with_their_own_errors() {
    let server = Server::start("op-query", &["--no-persist", "--max-batch", "4"]);
    let mut client = server.client(TIMEOUT);
    let a = client.register_sphere(0.5).expect("a");
    let b = client.register_sphere(0.5).expect("b");
    let ghost = ObjectId::from_raw(0xdead_beef);

    let e = client.set_pose(ghost, &Isometry3::identity()).unwrap_err();
    assert_eq!(e, PoseError::UnknownObject);
    assert_eq!(e.code(), Some(ErrorCode::UnknownObject));
    has_code(&e, e.code());
    let e = client
        .set_pose(a, &Isometry3::translation(f64::NAN, 0.0, 0.0))
        .unwrap_err();
    assert_eq!(e, PoseError::NonFinitePose);
    has_code(&e, Some(ErrorCode::NonFinitePose));
    let e = client.set_pose(a, &skewed()).unwrap_err();
    assert_eq!(e, PoseError::BadQuaternion);
    has_code(&e, Some(ErrorCode::BadQuaternion));

    let e = client
        .distance(a, ghost, &QueryOptions::default())
        .unwrap_err();
    assert_eq!(e, QueryError::UnknownObject);
    has_code(&e, Some(ErrorCode::UnknownObject));
    let negative = QueryOptions {
        tolerance: -1.0,
        ..QueryOptions::default()
    };
    let e = client.distance(a, b, &negative).unwrap_err();
    assert_eq!(e, QueryError::InvalidOptions);
    assert_eq!(e.code(), Some(ErrorCode::InvalidOptions));
    has_code(&e, e.code());
    let item = Item::distance(a, b, &QueryOptions::default());
    let mut results = [ItemResult::default(); 5];
    let e = client.query_batch(&[item; 5], &mut results).unwrap_err();
    assert_eq!(e, QueryError::BatchTooLarge);
    has_code(&e, Some(ErrorCode::BatchTooLarge));
    let e = client.query_batch(&[], &mut results).unwrap_err();
    assert_eq!(e, QueryError::EmptyBatch);
    has_code(&e, Some(ErrorCode::EmptyBatch));
    let e = client
        .query_batch(&[item; 2], &mut results[..1])
        .unwrap_err();
    assert_eq!(e, QueryError::ResultBufferTooSmall { needed: 2, got: 1 });
    assert_eq!(e.code(), None);
    has_code(&e, None);
}

#[test]
fn scene_questions_fail_with_their_own_errors() {
    let server = Server::start("op-scene", &["--no-persist"]);
    let mut client = server.client(TIMEOUT);
    let a = client.register_sphere(0.5).expect("a");
    let ghost = ObjectId::from_raw(0xdead_beef);
    let mut rows = [SceneRow::default(); 4];

    let e = client.clearance(ghost).into_rows(&mut rows).unwrap_err();
    assert_eq!(e, SceneError::UnknownObject);
    assert_eq!(e.code(), Some(ErrorCode::UnknownObject));
    has_code(&e, e.code());
    let e = client.nearest(a, 0).into_rows(&mut rows).unwrap_err();
    assert_eq!(e, SceneError::InvalidOptions);
    has_code(&e, Some(ErrorCode::InvalidOptions));
    let e = client
        .clearance(&[a][..])
        .until_hit(Steps::Poses {
            objects: &[a],
            poses: &[Isometry3::identity()],
        })
        .into_rows(&mut rows)
        .unwrap_err();
    assert_eq!(e, SceneError::Malformed);
    has_code(&e, Some(ErrorCode::Malformed));
    let e = client
        .path(
            &[a][..],
            Steps::Poses {
                objects: &[a],
                poses: &[Isometry3::translation(f64::INFINITY, 0.0, 0.0)],
            },
        )
        .into_rows(&mut rows)
        .unwrap_err();
    assert_eq!(e, SceneError::NonFinitePose);
    has_code(&e, Some(ErrorCode::NonFinitePose));
    let e = client
        .path(
            &[a][..],
            Steps::Poses {
                objects: &[],
                poses: &[],
            },
        )
        .into_rows(&mut rows)
        .unwrap_err();
    assert_eq!(e, SceneError::PartialSteps);
    has_code(&e, None);
}

#[test]
fn robot_calls_fail_with_their_own_errors() {
    let server = Server::start("op-robot", &["--no-persist"]);
    let mut alice = server.client(TIMEOUT);
    let mut bob = server.client(TIMEOUT);
    let packages = PackagePath::new(Vec::new());
    let at = Isometry3::identity();
    let mut arm = alice
        .register_robot_text("arm", ARM, None, None, &packages, &at)
        .expect("arm");

    let e = alice.set_joints(&mut arm, &[1.5], None).unwrap_err();
    assert_eq!(e, RobotError::OutOfLimits);
    assert_eq!(e.code(), Some(ErrorCode::OutOfLimits));
    has_code(&e, e.code());
    let e = alice
        .set_joints(&mut arm, &[0.5], Some(&skewed()))
        .unwrap_err();
    assert_eq!(e, RobotError::BadQuaternion);
    has_code(&e, Some(ErrorCode::BadQuaternion));
    let e = alice
        .set_joints_by_name(&mut arm, &[("elbow", 0.1)])
        .unwrap_err();
    assert_eq!(e, RobotError::UnknownJoint("elbow".into()));
    assert_eq!(e.code(), Some(ErrorCode::UnknownName));
    has_code(&e, e.code());
    assert_eq!(arm.positions, [0.0], "nothing moved");

    let e = alice.open_robot("nobody", ARM).unwrap_err();
    assert_eq!(e, RobotError::UnknownRobot);
    assert_eq!(e.code(), Some(ErrorCode::UnknownName));
    has_code(&e, e.code());
    let e = alice.remove_robot("nobody").unwrap_err();
    assert_eq!(e, RobotError::UnknownRobot);
    let e = bob.remove_robot("arm").unwrap_err();
    assert_eq!(e, RobotError::NotOwner);
    has_code(&e, Some(ErrorCode::NotOwner));
    // The client reads the URDF but leaves the SRDF to the server.
    let e = alice
        .attach_robot("arm", ARM, Some("<robot"), &at)
        .unwrap_err();
    assert_eq!(e, RobotError::RobotRefused);
    assert_eq!(e.code(), Some(ErrorCode::InvalidRobot));
    has_code(&e, e.code());
    let e = alice.attach_robot("arm", "<robot", None, &at).unwrap_err();
    assert!(matches!(e, RobotError::InvalidRobot(_)), "{e:?}");
    has_code(&e, Some(ErrorCode::InvalidRobot));
    // Its link objects are taken: the registration's own error, inside.
    let e = bob
        .register_robot_text("arm", ARM, None, None, &packages, &at)
        .unwrap_err();
    assert_eq!(e, RobotError::Link(RegisterError::NameTaken));
    assert_eq!(e.code(), Some(ErrorCode::NameTaken));
    has_code(&e, e.code());
    alice.remove_robot("arm").expect("removed whole");
}

#[test]
fn a_server_gone_is_every_operations_connection_fault() {
    let mut server = Server::start("op-gone", &["--no-persist"]);
    let mut client = server.client(Duration::from_millis(500));
    let a = client.register_sphere(0.5).expect("a");
    server.kill9();
    let gone = |e: &ConnectError| matches!(e, ConnectError::ServerGone(_));

    let e = client.stats().unwrap_err();
    assert!(matches!(&e, StatsError::Connection(c) if gone(c)), "{e:?}");
    assert_eq!(e.code(), None);
    has_code(&e, None);
    let e = client.poses(&[a]).unwrap_err();
    assert!(
        matches!(&e, PoseReadError::Connection(c) if gone(c)),
        "{e:?}"
    );
    let e = client.set_pose(a, &Isometry3::identity()).unwrap_err();
    assert!(matches!(&e, PoseError::Connection(c) if gone(c)), "{e:?}");
    let e = client.register_sphere(0.5).unwrap_err();
    assert!(
        matches!(&e, RegisterError::Connection(c) if gone(c)),
        "{e:?}"
    );
    // The umbrella error is the one every call returned before.
    assert!(matches!(ClientError::from(e), ClientError::ServerGone(_)));
    let e = client.remove(a).unwrap_err();
    assert!(matches!(&e, RemoveError::Connection(c) if gone(c)), "{e:?}");
    let e = client
        .clearance(a)
        .into_rows(&mut [SceneRow::default()])
        .unwrap_err();
    assert!(matches!(&e, SceneError::Connection(c) if gone(c)), "{e:?}");
    let e = client.remove_robot("arm").unwrap_err();
    assert!(matches!(&e, RobotError::Connection(c) if gone(c)), "{e:?}");
    let _: Client = client;
}
