//! What a node restarted under the same names meets, through a real
//! server with persistence: objects and robots found again by name instead
//! of `NameTaken` (also after a server restart, which keeps the link
//! objects but not the robot), and a robot removed whole; and objects that
//! end with their client (`ClientBuilder::remove_on_close`) instead of
//! piling up.

use std::time::Duration;

use gjkd_client::{Client, ClientError, ErrorCode, Geometry, PackagePath, QueryOptions};
use gjkd_e2e::Server;
use nalgebra::Isometry3;

const TIMEOUT: Duration = Duration::from_secs(5);

/// A 0.2 box base, and a ball of radius 0.1 one along x from the joint.
const URDF: &str = r#"<robot name="arm">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="tip"><collision><origin xyz="1 0 0"/><geometry><sphere radius="0.1"/></geometry></collision></link>
  <joint name="turn" type="revolute"><parent link="base"/><child link="tip"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#;

fn rejected<T: std::fmt::Debug, E: Into<ClientError>>(r: Result<T, E>) -> ErrorCode {
    match r.map_err(Into::into) {
        Err(ClientError::Rejected(code)) => code,
        other => panic!("expected a refusal, got {other:?}"),
    }
}

#[test]
fn a_restarted_node_gets_its_objects_and_robot_back_and_removes_the_robot_whole() {
    let mut server = Server::start("reuse", &[]);
    let mut first = server.client(TIMEOUT);
    let ball = Geometry::Sphere { radius: 0.5 };
    let here = Isometry3::translation(0.0, 3.0, 0.0);
    let id = first
        .register_named_or_get("reuse-ball", &ball, &here)
        .unwrap();
    let packages = PackagePath::default();
    let base = Isometry3::identity();
    let arm = first
        .register_robot_text_or_get("reuse-arm", URDF, None, None, &packages, &base)
        .unwrap();
    let tip = arm.link("tip").unwrap();
    drop(first);

    // A new process: the names are taken, and found.
    let mut second = server.client(TIMEOUT);
    assert_eq!(
        rejected(second.register_named("reuse-ball", &ball, &here)),
        ErrorCode::NameTaken
    );
    assert_eq!(
        second
            .register_named_or_get("reuse-ball", &ball, &here)
            .unwrap(),
        id
    );
    let found = second
        .register_robot_text_or_get("reuse-arm", URDF, None, None, &packages, &base)
        .unwrap();
    assert_eq!((found.id, found.link("tip")), (arm.id, Some(tip)));
    drop(second);

    // The server restarts: it keeps the objects, not the robot, which is
    // attached to its old links again.
    server.terminate();
    server.restart();
    let mut third = server.client(TIMEOUT);
    let mut back = third
        .register_robot_text_or_get("reuse-arm", URDF, None, None, &packages, &base)
        .unwrap();
    assert_eq!(back.link("tip"), Some(tip));
    third
        .set_joints(&mut back, &[std::f64::consts::FRAC_PI_2], None)
        .unwrap();
    let d = third.distance(tip, id, &QueryOptions::default()).unwrap();
    assert!((d.distance - (2.0 - 0.6)).abs() < 1e-9, "{}", d.distance);

    // Removed whole, by the client that attached it; the links were the
    // first process's, so they are another client's: refused, nothing
    // removed.
    assert_eq!(
        rejected(third.remove_robot("reuse-arm")),
        ErrorCode::NotOwner
    );
    assert!(third.distance(tip, id, &QueryOptions::default()).is_ok());
    assert_eq!(
        rejected(third.remove_robot("no-such-arm")),
        ErrorCode::UnknownName
    );

    // A robot this client registered goes with every link.
    let own = third
        .register_robot_text_or_get("reuse-own", URDF, None, None, &packages, &base)
        .unwrap();
    let own_tip = own.link("tip").unwrap();
    third.remove_robot("reuse-own").unwrap();
    assert_eq!(
        rejected(third.distance(own_tip, id, &QueryOptions::default())),
        ErrorCode::UnknownObject
    );
    assert_eq!(
        rejected(third.lookup("reuse-own/base")),
        ErrorCode::UnknownName
    );
}

#[test]
fn what_a_client_registers_to_end_with_it_is_gone_after_it_and_nothing_else() {
    let server = Server::start("end-with-client", &[]);
    let mut keeper = server.client(TIMEOUT);
    let kept = keeper
        .register_named(
            "ewc-kept",
            &Geometry::Sphere { radius: 0.5 },
            &Isometry3::identity(),
        )
        .unwrap();
    let objects_before = keeper.stats().unwrap().objects;

    let mut passing = Client::builder(&server.service)
        .timeout(TIMEOUT)
        .remove_on_close(true)
        .connect()
        .unwrap();
    let here = Isometry3::translation(3.0, 0.0, 0.0);
    let named = passing
        .register_named("ewc-ball", &Geometry::Sphere { radius: 0.25 }, &here)
        .unwrap();
    let unnamed = passing.register_cylinder(0.5, 1.0, 0.0).unwrap();
    let removed_early = passing.register_sphere(1.0).unwrap();
    passing.remove(removed_early).unwrap();
    let arm = passing
        .register_robot_text(
            "ewc-arm",
            URDF,
            None,
            None,
            &PackagePath::default(),
            &Isometry3::identity(),
        )
        .unwrap();
    let tip = arm.link("tip").unwrap();
    // The other client's object is found by name, not registered: it is
    // not this client's to end.
    let found = passing
        .register_named_or_get(
            "ewc-kept",
            &Geometry::Sphere { radius: 0.5 },
            &Isometry3::identity(),
        )
        .unwrap();
    assert_eq!(found, kept);
    // Ball, cylinder and two links.
    assert_eq!(keeper.stats().unwrap().objects, objects_before + 4);
    // The ball is 3 from the kept sphere's centre: 3 - 0.5 - 0.25.
    let d = keeper
        .distance(kept, named, &QueryOptions::default())
        .unwrap()
        .distance;
    assert!((d - 2.25).abs() < 1e-12, "{d}");
    drop(passing);

    assert_eq!(keeper.stats().unwrap().objects, objects_before);
    for id in [named, unnamed, tip] {
        assert_eq!(
            rejected(keeper.distance(kept, id, &QueryOptions::default())),
            ErrorCode::UnknownObject
        );
    }
    assert_eq!(rejected(keeper.lookup("ewc-ball")), ErrorCode::UnknownName);
    assert_eq!(rejected(keeper.robot_id("ewc-arm")), ErrorCode::UnknownName);
    assert_eq!(keeper.lookup("ewc-kept").unwrap(), kept);

    // Without the option (the default), objects outlive their client.
    let mut lasting = server.client(TIMEOUT);
    let stays = lasting
        .register_named("ewc-stays", &Geometry::Sphere { radius: 0.1 }, &here)
        .unwrap();
    drop(lasting);
    assert_eq!(keeper.lookup("ewc-stays").unwrap(), stays);
}
