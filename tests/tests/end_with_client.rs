//! Objects that end with their client (`ClientBuilder::remove_on_close`),
//! through a real server with persistence: what such a client registered,
//! robots whole, is gone once it is dropped, while another client's
//! objects, and those of a client without the option, stay.

use std::time::Duration;

use gjkd_client::{Client, ClientError, ErrorCode, Geometry, PackagePath, QueryOptions};
use gjkd_e2e::Server;
use nalgebra::Isometry3;

const TIMEOUT: Duration = Duration::from_secs(5);

/// A box base and a ball one along x from the joint.
const URDF: &str = r#"<robot name="arm">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="tip"><collision><origin xyz="1 0 0"/><geometry><sphere radius="0.1"/></geometry></collision></link>
  <joint name="turn" type="revolute"><parent link="base"/><child link="tip"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#;

fn rejected<T: std::fmt::Debug>(r: Result<T, ClientError>) -> ErrorCode {
    match r {
        Err(ClientError::Rejected(code)) => code,
        other => panic!("expected a refusal, got {other:?}"),
    }
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
