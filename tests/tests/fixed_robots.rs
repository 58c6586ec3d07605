//! A robot without moving joints moves by its base alone: `set_joints`
//! with no positions places its links where the base puts them, as the
//! distances to a ball show against their closed form.

use std::time::Duration;

use gjkd_client::{PackagePath, QueryOptions, RobotError};
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Vector3};

/// A table: one box link of half extents (0.5, 0.25, 0.1), no joint.
const TABLE: &str = r#"<robot name="table">
  <link name="top"><collision><geometry><box size="1.0 0.5 0.2"/></geometry></collision></link>
</robot>"#;

#[test]
fn a_robot_without_moving_joints_moves_by_its_base() {
    let server = Server::start("fixed-robot", &["--no-persist"]);
    let mut client = server.client(Duration::from_secs(10));
    let mut table = client
        .register_robot_text(
            "table",
            TABLE,
            None,
            None,
            &PackagePath::new(Vec::new()),
            &Isometry3::identity(),
        )
        .expect("table");
    assert!(table.positions.is_empty());
    let top = table.link("top").expect("the top link");
    let ball = client.register_sphere(0.1).expect("ball");
    client
        .set_pose(ball, &Isometry3::translation(0.0, 0.0, 1.0))
        .expect("ball pose");
    let d = |c: &mut gjkd_client::Client| c.distance(top, ball, &QueryOptions::cold()).unwrap();
    // At the identity: 1.0 - 0.1 (half height) - 0.1 (radius).
    assert!((d(&mut client).distance - 0.8).abs() < 1e-9);

    // Raised by 0.5 and turned a quarter about x: the half extent along z
    // is now 0.25.
    let base = Isometry3::new(
        Vector3::new(0.0, 0.0, 0.5),
        Vector3::new(std::f64::consts::FRAC_PI_2, 0.0, 0.0),
    );
    client
        .set_joints(&mut table, &[], Some(&base))
        .expect("base only");
    assert!((d(&mut client).distance - (0.5 - 0.25 - 0.1)).abs() < 1e-9);

    // No base and no positions: nothing to do, nothing moves.
    client.set_joints(&mut table, &[], None).expect("nothing");
    assert!((d(&mut client).distance - 0.15).abs() < 1e-9);

    // Positions for joints it does not have are still refused.
    assert_eq!(
        client.set_joints(&mut table, &[0.0], Some(&base)),
        Err(RobotError::WrongJointCount)
    );
    // A NaN base is refused and changes nothing.
    let nan = Isometry3::translation(f64::NAN, 0.0, 0.0);
    assert_eq!(
        client.set_joints(&mut table, &[], Some(&nan)),
        Err(RobotError::NonFinitePose)
    );
    assert!((d(&mut client).distance - 0.15).abs() < 1e-9);
}
