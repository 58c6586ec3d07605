//! The robot part of `gjkd demo`, and the robot arm `gjkd bench robot`
//! uses: a 7-joint arm from a URDF written for gjkd ([`ARM_URDF`]), moved
//! through a few obstacles by one joint request per step.

use std::io::Write;
use std::path::PathBuf;

use gjkd_client::{
    Client, ClientError, Geometry, Item, ItemResult, ObjectId, QueryOptions, RegisterError,
    RobotError, RobotHandle,
};
use nalgebra::{Isometry3, Vector3};

/// A 7-joint arm (a 7-DOF manipulator's layout, in boxes and balls): seven
/// revolute joints alternating about z and y, a base and eight links with
/// collision geometry, a fixed flange and a mimic-free hand.
pub const ARM_URDF: &str = r#"<?xml version="1.0"?>
<robot name="gjkd_arm">
  <link name="base"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.3 0.3 0.1"/></geometry></collision></link>
  <link name="link1"><collision><origin xyz="0 0 0.15"/><geometry><box size="0.12 0.12 0.3"/></geometry></collision></link>
  <link name="link2"><collision><geometry><sphere radius="0.08"/></geometry></collision></link>
  <link name="link3"><collision><origin xyz="0 0 0.15"/><geometry><box size="0.1 0.1 0.3"/></geometry></collision></link>
  <link name="link4"><collision><geometry><sphere radius="0.07"/></geometry></collision></link>
  <link name="link5"><collision><origin xyz="0 0 0.12"/><geometry><box size="0.08 0.08 0.24"/></geometry></collision></link>
  <link name="link6"><collision><geometry><sphere radius="0.06"/></geometry></collision></link>
  <link name="link7"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.06 0.06 0.1"/></geometry></collision></link>
  <link name="flange"/>
  <link name="hand">
    <collision><origin xyz="0 0 0.02"/><geometry><box size="0.16 0.04 0.04"/></geometry></collision>
    <collision><origin xyz="0.07 0 0.07"/><geometry><box size="0.02 0.02 0.08"/></geometry></collision>
    <collision><origin xyz="-0.07 0 0.07"/><geometry><box size="0.02 0.02 0.08"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="link1"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-2.9" upper="2.9" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="link1"/><child link="link2"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-1.8" upper="1.8" effort="1" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="link2"/><child link="link3"/><axis xyz="0 0 1"/><limit lower="-2.9" upper="2.9" effort="1" velocity="1"/></joint>
  <joint name="j4" type="revolute"><parent link="link3"/><child link="link4"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-3.0" upper="0.1" effort="1" velocity="1"/></joint>
  <joint name="j5" type="revolute"><parent link="link4"/><child link="link5"/><axis xyz="0 0 1"/><limit lower="-2.9" upper="2.9" effort="1" velocity="1"/></joint>
  <joint name="j6" type="revolute"><parent link="link5"/><child link="link6"/><origin xyz="0 0 0.24"/><axis xyz="0 1 0"/><limit lower="-0.1" upper="3.7" effort="1" velocity="1"/></joint>
  <joint name="j7" type="revolute"><parent link="link6"/><child link="link7"/><axis xyz="0 0 1"/><limit lower="-2.9" upper="2.9" effort="1" velocity="1"/></joint>
  <joint name="j8" type="fixed"><parent link="link7"/><child link="flange"/><origin xyz="0 0 0.1"/></joint>
  <joint name="j9" type="fixed"><parent link="flange"/><child link="hand"/></joint>
</robot>
"#;

/// The joint path of the demo and the benchmark at `t` in [0, 1]: the arm
/// swings round and reaches down past the obstacles.
pub fn joint_path(t: f64) -> [f64; 7] {
    let s = (t * std::f64::consts::PI).sin();
    [
        -1.5 + 3.0 * t,
        0.2 + 0.9 * s,
        0.4 * s,
        -1.2 - 0.8 * s,
        0.5 * t,
        1.0 + 0.6 * s,
        2.0 * t - 1.0,
    ]
}

/// Writes [`ARM_URDF`] to a fresh temporary folder and registers the arm
/// as `name`; the folder is removed again.
///
/// # Errors
/// The client's, or [`RobotError::InvalidRobot`] for the temporary file.
pub fn register_arm(client: &mut Client, name: &str) -> Result<RobotHandle, RobotError> {
    let dir: PathBuf = std::env::temp_dir().join(format!("gjkd-arm-{}-{name}", std::process::id()));
    let io = |e: std::io::Error| RobotError::InvalidRobot(format!("{}: {e}", dir.display()));
    std::fs::create_dir_all(&dir).map_err(io)?;
    let urdf = dir.join("gjkd_arm.urdf");
    std::fs::write(&urdf, ARM_URDF).map_err(io)?;
    let arm = client.register_robot(
        name,
        &urdf,
        None,
        &gjkd_client::PackagePath::default(),
        &Isometry3::identity(),
    );
    let _ = std::fs::remove_dir_all(&dir);
    arm
}

/// `count` obstacles around the arm's workspace (boxes and balls), named
/// `<prefix><i>`.
///
/// # Errors
/// The client's.
pub fn register_obstacles(
    client: &mut Client,
    prefix: &str,
    count: usize,
) -> Result<Vec<ObjectId>, RegisterError> {
    (0..count)
        .map(|i| {
            let angle = i as f64 * std::f64::consts::TAU / count as f64;
            let (s, c) = angle.sin_cos();
            let radius = 0.55 + 0.1 * (i % 3) as f64;
            let pose = Isometry3::translation(radius * c, radius * s, 0.2 + 0.15 * (i % 4) as f64);
            let geometry = if i % 2 == 0 {
                Geometry::Cuboid {
                    half_extents: Vector3::new(0.08, 0.08, 0.2),
                    radius: 0.0,
                }
            } else {
                Geometry::Sphere { radius: 0.1 }
            };
            client.register_named(&format!("{prefix}{i}"), &geometry, &pose)
        })
        .collect()
}

/// Runs the robot demo on a connected client: registers the arm and four
/// obstacles, sweeps the joint path in `steps` steps, one request per step
/// (the joints, then every link's distance to every obstacle), and prints
/// each link's clearance (its distance to the nearest obstacle).
///
/// # Errors
/// The client's, or a refused item.
pub fn run(client: &mut Client, out: &mut impl Write, steps: usize) -> Result<(), ClientError> {
    let mut arm = register_arm(client, "demo_arm")?;
    let obstacles = register_obstacles(client, "demo_obstacle", 4)?;
    let links: Vec<(String, ObjectId)> = arm
        .link_names()
        .iter()
        .zip(&arm.links)
        .filter_map(|(n, l)| l.map(|l| (n.clone(), l)))
        .collect();
    let _ = writeln!(
        out,
        "A robot: a 7-joint arm from a URDF written for gjkd (links of boxes and balls), among\n\
         4 obstacles. Each step is one request: the 7 joint positions (the server computes\n\
         every link's pose by forward kinematics), then the {} link-obstacle distances,\n\
         warm-started along the path. Clearance of each link (metres) along the path:\n",
        links.len() * obstacles.len()
    );
    let mut header = format!("{:>4} ", "step");
    for (name, _) in &links {
        header.push_str(&format!("{name:>7}"));
    }
    let _ = writeln!(out, "{header}");
    let options = QueryOptions::default();
    let mut results = Vec::new();
    let mut closest = (f64::INFINITY, 0, String::new());
    for step in 0..=steps {
        let q = joint_path(step as f64 / steps as f64);
        let mut items = arm.joint_items(&q, None, false);
        for (_, link) in &links {
            items.extend(
                obstacles
                    .iter()
                    .map(|&o| Item::distance(*link, o, &options)),
            );
        }
        results.clear();
        results.resize(items.len(), ItemResult::default());
        client.query_batch(&items, &mut results)?;
        let mut line = format!("{step:>4} ");
        for (k, (name, _)) in links.iter().enumerate() {
            let answers = &results[1 + k * obstacles.len()..1 + (k + 1) * obstacles.len()];
            let mut clearance = f64::INFINITY;
            for r in answers {
                clearance = clearance.min(r.answer().map_err(ClientError::Rejected)?.distance);
            }
            if clearance < closest.0 {
                closest = (clearance, step, name.clone());
            }
            line.push_str(&format!("{clearance:>7.3}"));
        }
        let _ = writeln!(out, "{line}");
        arm.positions.copy_from_slice(&q);
    }
    let _ = writeln!(
        out,
        "\nClosest approach: {} at {:.4} m, step {}.\n",
        closest.2, closest.0, closest.1
    );
    Ok(())
}
