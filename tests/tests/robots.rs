//! Robots and meshes through a real server: a robot registered from URDF
//! and mesh files, moved by joints in one round trip, its link distances
//! equal to those at poses the client computes; a robot from the scene
//! file; mesh hulls against a closed form; every bad input refused with
//! nothing changed.

use std::path::{Path, PathBuf};
use std::time::Duration;

use gjkd_client::{
    Client, ClientError, ErrorCode, Item, ItemResult, LimitMode, PackagePath, QueryOptions,
};
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Vector3};

const TIMEOUT: Duration = Duration::from_secs(5);

const URDF: &str = r#"<robot name="arm">
  <link name="base"><collision><geometry><box size="0.3 0.3 0.1"/></geometry></collision></link>
  <link name="upper"><collision><origin xyz="0 0 0.25"/><geometry><mesh filename="package://arm/upper.stl"/></geometry></collision></link>
  <link name="fore"><collision><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.05 0.05"/></geometry></collision></link>
  <link name="tool"/>
  <link name="tip"><collision><geometry><sphere radius="0.03"/></geometry></collision></link>
  <joint name="yaw" type="continuous"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.05"/><axis xyz="0 0 1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="fore"/><child link="tool"/><origin xyz="0.4 0 0" rpy="0 0 0.3"/></joint>
  <joint name="reach" type="prismatic"><parent link="tool"/><child link="tip"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.1" effort="1" velocity="1"/></joint>
</robot>"#;

/// A binary STL of the box `[-h, h]`.
fn write_box_stl(path: &Path, h: [f32; 3]) {
    let corner = |i: usize| [0, 1, 2].map(|k| if i >> k & 1 == 1 { h[k] } else { -h[k] });
    let faces: [[usize; 3]; 12] = [
        [0, 2, 3],
        [0, 3, 1],
        [4, 5, 7],
        [4, 7, 6],
        [0, 1, 5],
        [0, 5, 4],
        [2, 6, 7],
        [2, 7, 3],
        [0, 4, 6],
        [0, 6, 2],
        [1, 3, 7],
        [1, 7, 5],
    ];
    let mut out = vec![0u8; 80];
    out.extend(12u32.to_le_bytes());
    for f in faces {
        out.extend([0u8; 12]);
        for i in f {
            for c in corner(i) {
                out.extend(c.to_le_bytes());
            }
        }
        out.extend([0u8; 2]);
    }
    std::fs::write(path, out).unwrap();
}

fn folder(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gjkd-e2e-robots-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("pkg/arm")).unwrap();
    write_box_stl(&dir.join("pkg/arm/upper.stl"), [0.05, 0.05, 0.25]);
    std::fs::write(dir.join("arm.urdf"), URDF).unwrap();
    dir
}

fn rejected<T: std::fmt::Debug>(r: Result<T, ClientError>) -> ErrorCode {
    match r {
        Err(ClientError::Rejected(code)) => code,
        other => panic!("expected a rejection, got {other:?}"),
    }
}

#[test]
fn a_robot_moves_by_joints_and_its_links_answer_as_at_client_poses() {
    let dir = folder("moves");
    let server = Server::start("robot-moves", &["--no-persist"]);
    let mut client = server.client(TIMEOUT);
    let packages = PackagePath::new([dir.join("pkg")]);
    let base = Isometry3::translation(0.5, -0.5, 0.0);
    let mut arm = client
        .register_robot("arm", &dir.join("arm.urdf"), None, &packages, &base)
        .unwrap();
    assert_eq!(arm.joint_names(), ["yaw", "elbow", "reach"]);
    assert_eq!(arm.link("tool"), None);
    let wall = client
        .register_named(
            "wall",
            &gjkd_client::Geometry::Cuboid {
                half_extents: Vector3::new(0.05, 1.0, 1.0),
                radius: 0.0,
            },
            &Isometry3::translation(1.2, 0.0, 0.5),
        )
        .unwrap();
    let options = QueryOptions::default();
    let links: Vec<_> = arm.links.iter().flatten().copied().collect();
    for step in 0..15 {
        let t = f64::from(step) / 14.0;
        let q = [3.0 * t - 1.0, 1.8 * t - 0.9, 0.1 * t];
        // One request: the joints, then every link's distance to the wall.
        let mut items = arm.joint_items(&q, None, false);
        items.extend(links.iter().map(|&l| Item::distance(l, wall, &options)));
        let mut out = vec![ItemResult::default(); items.len()];
        client.query_batch(&items, &mut out).unwrap();
        let poses = arm
            .kinematics
            .link_poses(&base, &q, LimitMode::Reject)
            .unwrap();
        let with_pose: Vec<_> = arm
            .links
            .iter()
            .zip(&poses)
            .filter_map(|(l, p)| l.map(|_| *p))
            .collect();
        for ((link, pose), got) in links.iter().zip(&with_pose).zip(&out[1..]) {
            let reference = client
                .distance_at(
                    *link,
                    pose,
                    wall,
                    &Isometry3::translation(1.2, 0.0, 0.5),
                    &QueryOptions::cold(),
                )
                .unwrap();
            let got = got.answer().unwrap();
            assert!(
                (got.distance - reference.distance).abs() <= 1e-9,
                "step {step}: {} vs {}",
                got.distance,
                reference.distance
            );
        }
    }
    // By name, one round trip; the others keep their positions.
    client.set_joints(&mut arm, &[2.0, 0.5, 0.1], None).unwrap();
    client
        .set_joints_by_name(&mut arm, &[("elbow", 0.0)])
        .unwrap();
    assert_eq!(arm.positions, [2.0, 0.0, 0.1]);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn bad_joints_and_robots_are_refused_and_change_nothing() {
    let dir = folder("bad");
    let server = Server::start("robot-bad", &["--no-persist"]);
    let mut client = server.client(TIMEOUT);
    let packages = PackagePath::new([dir.join("pkg")]);
    let mut arm = client
        .register_robot(
            "arm",
            &dir.join("arm.urdf"),
            None,
            &packages,
            &Isometry3::identity(),
        )
        .unwrap();
    let ball = client.register_sphere(0.1).unwrap();
    client
        .set_pose(ball, &Isometry3::translation(0.0, 2.0, 0.5))
        .unwrap();
    client
        .set_joints(&mut arm, &[0.3, 0.4, 0.05], None)
        .unwrap();
    let tip = arm.link("tip").unwrap();
    let o = QueryOptions::cold();
    let before = client.distance(tip, ball, &o).unwrap().distance;
    assert_eq!(
        rejected(client.set_joints(&mut arm, &[0.3, 2.5, 0.05], None)),
        ErrorCode::OutOfLimits
    );
    assert_eq!(
        rejected(client.set_joints(&mut arm, &[0.3, f64::NAN, 0.05], None)),
        ErrorCode::NonFinitePose
    );
    assert!(matches!(
        client.set_joints(&mut arm, &[0.3], None),
        Err(ClientError::InvalidArgument(_))
    ));
    assert!(matches!(
        client.set_joints_by_name(&mut arm, &[("flange", 0.1)]),
        Err(ClientError::Model(m)) if m.contains("flange")
    ));
    assert_eq!(client.distance(tip, ball, &o).unwrap().distance, before);
    assert_eq!(arm.positions, [0.3, 0.4, 0.05]);
    // Clamping, asked for, moves the elbow to its limit.
    let mut out = [ItemResult::default()];
    client
        .query_batch(&arm.joint_items(&[0.3, 2.5, 0.05], None, true), &mut out)
        .unwrap();
    assert_eq!(out[0].error, 0);

    let objects = client.stats().unwrap().objects;
    let missing = URDF.replace("package://arm/upper.stl", "package://arm/gone.stl");
    std::fs::write(dir.join("missing.urdf"), missing).unwrap();
    let e = client
        .register_robot(
            "arm2",
            &dir.join("missing.urdf"),
            None,
            &packages,
            &Isometry3::identity(),
        )
        .unwrap_err();
    assert!(
        matches!(&e, ClientError::Model(m) if m.contains("gone.stl")),
        "{e}"
    );
    // A cylinder is exact, but its sizes are checked like any other.
    let cylinder = URDF.replace(
        r#"<sphere radius="0.03"/>"#,
        r#"<cylinder radius="-0.03" length="0.1"/>"#,
    );
    std::fs::write(dir.join("cylinder.urdf"), cylinder).unwrap();
    let e = client
        .register_robot(
            "arm3",
            &dir.join("cylinder.urdf"),
            None,
            &packages,
            &Isometry3::identity(),
        )
        .unwrap_err();
    assert!(
        matches!(&e, ClientError::Model(m) if m.contains("cylinder")),
        "{e}"
    );
    // The same name again: its links are taken, and what was registered
    // before the refusal is removed again.
    assert_eq!(
        rejected(client.register_robot(
            "arm",
            &dir.join("arm.urdf"),
            None,
            &packages,
            &Isometry3::identity()
        )),
        ErrorCode::NameTaken
    );
    assert!(matches!(
        client.attach_robot("arm", "<robot", None, &Isometry3::identity()),
        Err(ClientError::Model(_))
    ));
    assert_eq!(client.stats().unwrap().objects, objects);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_robot_and_a_mesh_from_the_scene_file_are_served() {
    let dir = folder("scene");
    write_box_stl(&dir.join("block.stl"), [0.5, 0.25, 0.125]);
    let scene = r#"
[[object]]
name = "block"
type = "mesh"
file = "block.stl"
pose = { translation = [3.0, 0.0, 0.0] }

[[robot]]
name = "arm"
urdf = "arm.urdf"
pose = { translation = [0.0, 0.0, 1.0] }
joints = { elbow = 0.5 }
"#;
    std::fs::write(dir.join("scene.toml"), scene).unwrap();
    let scene_path = dir.join("scene.toml");
    let pkg = dir.join("pkg");
    let server = Server::start(
        "robot-scene",
        &[
            "--no-persist",
            "--scene",
            scene_path.to_str().unwrap(),
            "--package-path",
            pkg.to_str().unwrap(),
        ],
    );
    let mut client: Client = server.client(TIMEOUT);
    let mut arm = client.open_robot("arm", URDF).unwrap();
    let block = client.lookup("block").unwrap();
    let probe = client.register_sphere(0.0).unwrap();
    // The block's hull against the box closed form.
    for (p, want) in [
        ([4.0, 0.0, 0.0], 0.5),
        ([3.0, 1.25, 1.125], 2f64.sqrt()),
        ([3.2, 0.1, 0.0], 0.0),
    ] {
        client
            .set_pose(probe, &Isometry3::translation(p[0], p[1], p[2]))
            .unwrap();
        let d = client
            .distance(probe, block, &QueryOptions::default())
            .unwrap()
            .distance;
        assert!((d - want).abs() <= 1e-12, "{p:?}: {d}");
    }
    // The scene's robot moves by joints like any other.
    client.set_joints(&mut arm, &[0.0, 0.0, 0.0], None).unwrap();
    let tip = arm.link("tip").unwrap();
    client
        .set_pose(probe, &Isometry3::translation(0.4, 0.0, 1.55 + 0.03 + 1.0))
        .unwrap();
    let d = client
        .distance(tip, probe, &QueryOptions::default())
        .unwrap()
        .distance;
    // Tip at (0.4, 0, 1.55) with radius 0.03: the probe is 1 above its top.
    assert!((d - 1.0).abs() <= 1e-12, "{d}");
    assert_eq!(
        rejected(client.open_robot("nobody", URDF)),
        ErrorCode::UnknownName
    );
    std::fs::remove_dir_all(dir).unwrap();
}
