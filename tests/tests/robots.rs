//! Robots and meshes through a real server: a robot registered from URDF
//! and mesh files, moved by joints in one round trip, its link distances
//! equal to those at poses the client computes; a robot from the scene
//! file; mesh hulls against a closed form; every bad input refused with
//! nothing changed.

use std::path::{Path, PathBuf};
use std::time::Duration;

use gjkd_client::{
    Client, ClientError, ErrorCode, Item, ItemResult, LimitMode, PackagePath, QueryOptions,
    RobotError,
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

fn rejected<T: std::fmt::Debug, E: Into<ClientError>>(r: Result<T, E>) -> ErrorCode {
    match r.map_err(Into::into) {
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
    assert_eq!(
        client.set_joints(&mut arm, &[0.3], None),
        Err(RobotError::WrongJointCount)
    );
    // Found here before sending, with the code the server gives an
    // unknown name (as Python's NotFound and C's last error code carry).
    let e = client
        .set_joints_by_name(&mut arm, &[("flange", 0.1)])
        .unwrap_err();
    assert_eq!(e, RobotError::UnknownJoint("flange".into()));
    assert_eq!(e.code(), Some(ErrorCode::UnknownName));
    assert_eq!(ClientError::from(e).code(), Some(ErrorCode::UnknownName));
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
        matches!(&e, RobotError::InvalidRobot(m) if m.contains("gone.stl")),
        "{e}"
    );
    // The code the server gives a robot it cannot attach.
    assert_eq!(e.code(), Some(ErrorCode::InvalidRobot));
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
        matches!(&e, RobotError::InvalidRobot(m) if m.contains("cylinder")),
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
    let e = client
        .attach_robot("arm", "<robot", None, &Isometry3::identity())
        .unwrap_err();
    assert!(matches!(e, RobotError::InvalidRobot(_)), "{e}");
    assert_eq!(e.code(), Some(ErrorCode::InvalidRobot));
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

/// The vendored real robots' package folder (example-robot-data's layout).
fn real_robots() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../model/tests/data")
}

/// A shape's convex pieces with their offsets, each piece's hull features
/// found once, for the brute-force reference.
fn reference_pieces(
    shape: &gjk::Shape,
) -> Vec<(Isometry3<f64>, gjkd_testkit::reference::Hull, f64)> {
    let pieces: Vec<(Isometry3<f64>, &gjk::Convex)> = match shape {
        gjk::Shape::Convex(c) => vec![(Isometry3::identity(), c)],
        gjk::Shape::Compound(c) => c.pieces().iter().map(|(o, p)| (*o, p)).collect(),
    };
    pieces
        .into_iter()
        .map(|(o, c)| {
            let hull = gjkd_testkit::reference::Hull::new(c.vertices());
            (o, hull, c.radius())
        })
        .collect()
}

/// A pose of k's (which has its own nalgebra) as ours.
fn from_k(pose: &k::Isometry3<f64>) -> Isometry3<f64> {
    let (t, q) = (pose.translation.vector, pose.rotation.quaternion());
    Isometry3::from_parts(
        nalgebra::Translation3::new(t.x, t.y, t.z),
        nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(q.w, q.i, q.j, q.k)),
    )
}

#[test]
fn a_real_panda_moved_by_joints_answers_as_the_exact_reference() {
    // Franka's panda as example-robot-data ships it (STL collision meshes
    // behind package:// URLs, a mimic finger), registered and moved through
    // the server; each link's distance to a box is judged against link
    // poses from the k crate and the brute-force distance between hulls.
    let urdf = real_robots().join("example-robot-data/robots/panda_description/urdf/panda.urdf");
    let server = Server::start("robot-panda", &["--no-persist"]);
    let mut client = server.client(TIMEOUT);
    let packages = PackagePath::new([real_robots()]);
    let base = Isometry3::from_parts(
        Vector3::new(0.1, -0.2, 0.05).into(),
        nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, 0.4),
    );
    let mut panda = client
        .register_robot("panda", &urdf, None, &packages, &base)
        .unwrap();
    assert_eq!(panda.kinematics.dof(), 8);
    let half = Vector3::new(0.1, 0.15, 0.2);
    let box_pose = Isometry3::from_parts(
        Vector3::new(0.5, 0.1, 0.5).into(),
        nalgebra::UnitQuaternion::from_euler_angles(0.2, 0.1, -0.3),
    );
    let obstacle = client
        .register_named(
            "box",
            &gjkd_client::Geometry::Cuboid {
                half_extents: half,
                radius: 0.0,
            },
            &box_pose,
        )
        .unwrap();
    let box_ref = reference_pieces(&gjk::Convex::cuboid(half, 0.0).unwrap().into());
    let model = gjkd_client::RobotModel::load(&urdf, &packages).unwrap();
    let link_refs: Vec<_> = model
        .links
        .iter()
        .map(|l| l.shape.as_ref().map(reference_pieces))
        .collect();
    let chain = k::Chain::<f64>::from_urdf_file(&urdf).unwrap();
    let options = QueryOptions::default();
    let (mut apart, mut touching) = (0, 0);
    for step in 0..6 {
        // Spread over the joints' ranges, a different phase per joint.
        let q: Vec<f64> = panda
            .kinematics
            .moving_joints()
            .enumerate()
            .map(|(j, joint)| {
                let s = (0.37 * f64::from(step) + 0.23 * j as f64).fract();
                joint.lower + s * (joint.upper - joint.lower)
            })
            .collect();
        let mut items = panda.joint_items(&q, None, false);
        let first = items.len();
        let links: Vec<(usize, gjkd_client::ObjectId)> = panda
            .links
            .iter()
            .enumerate()
            .filter_map(|(i, l)| l.map(|id| (i, id)))
            .collect();
        items.extend(
            links
                .iter()
                .map(|&(_, id)| Item::distance(id, obstacle, &options)),
        );
        let mut out = vec![ItemResult::default(); items.len()];
        client.query_batch(&items, &mut out).unwrap();
        for (j, &qj) in panda.kinematics.moving_joints().zip(&q) {
            chain.find(&j.name).unwrap().set_joint_position(qj).unwrap();
        }
        chain.update_transforms();
        for (&(i, _), got) in links.iter().zip(&out[first..]) {
            let name = &panda.kinematics.link_names()[i];
            let pose = match panda.kinematics.joints().iter().find(|j| j.child == i) {
                Some(j) => base * from_k(&chain.find(&j.name).unwrap().world_transform().unwrap()),
                None => base,
            };
            let pieces = link_refs[i].as_ref().unwrap();
            let want = pieces
                .iter()
                .flat_map(|(o, h, r)| {
                    box_ref.iter().map(move |(bo, bh, br)| {
                        gjkd_testkit::reference::distance(
                            h,
                            &(pose * o),
                            *r,
                            bh,
                            &(box_pose * bo),
                            *br,
                        )
                        .distance
                    })
                })
                .fold(f64::INFINITY, f64::min);
            let got = got.answer().unwrap();
            assert!(
                (got.distance - want).abs() <= 1e-9,
                "step {step}, {name}: {} vs {want}",
                got.distance
            );
            assert!(got.lower <= want + 1e-12 && want <= got.upper + 1e-12);
            if want > 0.0 {
                apart += 1;
            } else {
                touching += 1;
            }
        }
        panda.positions = q;
    }
    assert!(
        apart > 20 && touching > 0,
        "{apart} apart, {touching} touching"
    );
}
