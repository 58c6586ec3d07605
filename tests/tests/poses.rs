//! Stored poses read back through a real server (`Client::poses`): bit for
//! bit what was set, robot links where `gjkd-model`'s forward kinematics
//! puts them, unknown ids failing alone.

use std::time::Duration;

use gjkd_client::{ErrorCode, LimitMode, ObjectId, PackagePath, Pose};
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Vector3};

const TIMEOUT: Duration = Duration::from_secs(5);

const URDF: &str = r#"<robot name="arm">
  <link name="base"><collision><geometry><box size="0.3 0.3 0.1"/></geometry></collision></link>
  <link name="upper"><collision><origin xyz="0 0 0.25"/><geometry><box size="0.1 0.1 0.5"/></geometry></collision></link>
  <link name="fore"><collision><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.05 0.05"/></geometry></collision></link>
  <link name="tip"><collision><geometry><sphere radius="0.03"/></geometry></collision></link>
  <joint name="yaw" type="continuous"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.05"/><axis xyz="0 0 1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="reach" type="prismatic"><parent link="fore"/><child link="tip"/><origin xyz="0.4 0 0" rpy="0 0 0.3"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/></joint>
</robot>"#;

/// The seven components, as bits: equality is bit for bit.
fn bits(pose: &Isometry3<f64>) -> [u64; 7] {
    let p = Pose::from_isometry(pose);
    let mut out = [0; 7];
    for (o, c) in out.iter_mut().zip(p.translation.iter().chain(&p.rotation)) {
        *o = c.to_bits();
    }
    out
}

#[test]
fn poses_come_back_as_set_and_unknown_ids_fail_alone() {
    let server = Server::start("poses-read-back", &["--no-persist"]);
    let mut client = server.client(TIMEOUT);
    let start = Isometry3::translation(1.0, 2.0, 3.0);
    let mut ball_at = |pose: &Isometry3<f64>| {
        let id = client.register_sphere(0.5).unwrap();
        client.set_pose(id, pose).unwrap();
        id
    };
    let a = ball_at(&start);
    let b = ball_at(&Isometry3::identity());
    let removed = ball_at(&start);
    // Every bit of the mantissas in use.
    let moved = Isometry3::new(
        Vector3::new(0.1, -2.0 / 3.0, 1e-7),
        Vector3::new(0.3, -1.1, 0.7),
    );
    client.set_pose(b, &moved).unwrap();
    client.remove(removed).unwrap();
    let never = ObjectId::from_raw(0);
    let got = client.poses(&[a, removed, b, never, a]).unwrap();
    assert_eq!(got.len(), 5);
    assert_eq!(bits(got[0].as_ref().unwrap()), bits(&start));
    assert_eq!(got[1], Err(ErrorCode::UnknownObject));
    assert_eq!(bits(got[2].as_ref().unwrap()), bits(&moved));
    assert_eq!(got[3], Err(ErrorCode::UnknownObject));
    assert_eq!(bits(got[4].as_ref().unwrap()), bits(&start));
    // No id: nothing asked, nothing answered.
    assert!(client.poses(&[]).unwrap().is_empty());
    // More ids than one request takes: split, answered in order.
    let max = client.server_info().unwrap().max_batch as usize;
    let many: Vec<ObjectId> = (0..max + 3)
        .map(|i| if i % 2 == 0 { a } else { b })
        .collect();
    let got = client.poses(&many).unwrap();
    assert_eq!(got.len(), many.len());
    for (id, pose) in many.iter().zip(&got) {
        let want = if *id == a { start } else { moved };
        assert_eq!(bits(pose.as_ref().unwrap()), bits(&want));
    }
}

#[test]
fn link_poses_come_back_where_the_joints_put_them() {
    let dir = std::env::temp_dir().join(format!("gjkd-e2e-poses-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("arm.urdf"), URDF).unwrap();
    let server = Server::start("poses-links", &["--no-persist"]);
    let mut client = server.client(TIMEOUT);
    let base = Isometry3::translation(0.5, -0.5, 0.0);
    let mut arm = client
        .register_robot(
            "arm",
            &dir.join("arm.urdf"),
            None,
            &PackagePath::new([dir.clone()]),
            &base,
        )
        .unwrap();
    let q = [0.7, -1.3, 0.05];
    let new_base = Isometry3::new(Vector3::new(0.2, 0.1, 0.3), Vector3::new(0.0, 0.0, 0.4));
    client.set_joints(&mut arm, &q, Some(&new_base)).unwrap();
    let want = arm
        .kinematics
        .link_poses(&new_base, &q, LimitMode::Reject)
        .unwrap();
    let (ids, expected): (Vec<ObjectId>, Vec<Isometry3<f64>>) = arm
        .links
        .iter()
        .zip(&want)
        .filter_map(|(l, p)| l.map(|id| (id, *p)))
        .unzip();
    assert_eq!(ids.len(), 4, "every link has a shape");
    let got = client.poses(&ids).unwrap();
    for ((id, got), want) in ids.iter().zip(&got).zip(&expected) {
        let got = got.as_ref().unwrap();
        let off = (got.translation.vector - want.translation.vector).norm()
            + got.rotation.angle_to(&want.rotation);
        assert!(off <= 1e-12, "link {id}: {got} vs {want}");
    }
    // The robot's own id is not an object's.
    assert_eq!(
        client.poses(&[arm.id]).unwrap()[0],
        Err(ErrorCode::UnknownObject)
    );
    std::fs::remove_dir_all(dir).unwrap();
}
