//! Register a robot from URDF and a mesh from an STL file, move the robot by
//! its joints in one round trip, and ask how far its gripper is from the
//! mesh. The example writes its own URDF and STL into a temporary folder.
//!
//! Start a server first (`cargo run --release -p gjkd -- serve`), then:
//!
//! ```sh
//! cargo run -p gjkd-client --example robot_arm [SERVICE]
//! ```

use std::path::Path;

use gjkd_client::{Client, DEFAULT_SERVICE, MeshMode, PackagePath, QueryOptions, RobotError};
use nalgebra::Isometry3;

/// A two-joint arm: a post turning about z, an arm on an elbow about y,
/// a gripper ball at the end of a prismatic joint. Its mesh comes through a
/// `package://` URL.
const URDF: &str = r#"<robot name="pointer">
  <link name="post"><collision><origin xyz="0 0 0.5"/>
    <geometry><mesh filename="package://pointer/post.stl"/></geometry></collision></link>
  <link name="arm"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.1 0.1"/></geometry></collision></link>
  <link name="gripper"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
  <joint name="turn" type="continuous"><parent link="post"/><child link="arm"/>
    <origin xyz="0 0 1"/><axis xyz="0 0 1"/></joint>
  <joint name="reach" type="prismatic"><parent link="arm"/><child link="gripper"/>
    <origin xyz="1 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.5" effort="1" velocity="1"/></joint>
</robot>"#;

/// Writes a binary STL of the box `[-h, h]`.
fn write_box_stl(path: &Path, h: [f32; 3]) -> std::io::Result<()> {
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
    for face in faces {
        out.extend([0u8; 12]);
        for i in face {
            corner(i).iter().for_each(|c| out.extend(c.to_le_bytes()));
        }
        out.extend([0u8; 2]);
    }
    std::fs::write(path, out)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let service = std::env::args().nth(1);
    let mut client = Client::connect(service.as_deref().unwrap_or(DEFAULT_SERVICE))?;
    let dir = std::env::temp_dir().join(format!("gjkd-robot-arm-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("pkg/pointer"))?;
    write_box_stl(&dir.join("pkg/pointer/post.stl"), [0.05, 0.05, 0.5])?;
    write_box_stl(&dir.join("crate.stl"), [0.5, 0.5, 0.5])?;
    std::fs::write(dir.join("pointer.urdf"), URDF)?;

    // A crate, from its STL: the mesh's convex hull. Its near face is at
    // y = 1.5.
    let crate_ = client.register_mesh_file(
        "crate",
        &dir.join("crate.stl"),
        [1.0; 3],
        MeshMode::Hull,
        &Isometry3::translation(0.0, 2.0, 1.0),
    )?;
    // The robot: its links become the objects "pointer/post", ...
    let packages = PackagePath::with_env([dir.join("pkg")]);
    let mut robot = client.register_robot(
        "pointer",
        &dir.join("pointer.urdf"),
        None,
        &packages,
        &Isometry3::identity(),
    )?;
    println!("joints, in order: {:?}", robot.joint_names());
    let gripper = robot.link("gripper").expect("the gripper has a shape");

    // One round trip per step: turn towards the crate and reach out.
    for (turn, reach) in [(0.0, 0.0), (0.8, 0.2), (std::f64::consts::FRAC_PI_2, 0.25)] {
        client.set_joints(&mut robot, &[turn, reach], None)?;
        let d = client.distance(gripper, crate_.id, &QueryOptions::default())?;
        println!(
            "turn {turn:.3} reach {reach:.2}: gripper to crate {:.12}",
            d.distance
        );
    }
    // Facing the crate, the gripper's centre is at y = 1.25, its surface at
    // 1.35: 0.15 from the crate's face.
    let d = client.distance(gripper, crate_.id, &QueryOptions::default())?;
    assert!((d.distance - 0.15).abs() < 1e-9, "{}", d.distance);

    // Out of its limits: refused, and nothing moves.
    match client.set_joints(&mut robot, &[0.0, 0.9], None) {
        Err(e @ RobotError::OutOfLimits) => println!("reach 0.9 refused: {e}"),
        other => panic!("expected a refusal, got {other:?}"),
    }
    std::fs::remove_dir_all(&dir)?;
    Ok(())
}
