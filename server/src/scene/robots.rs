//! The robots and meshes of a scene file (see [`crate::scene`]).
//!
//! ```toml
//! [[object]]
//! name = "table"
//! type = "mesh"
//! file = "meshes/table.stl"   # STL, OBJ or COLLADA; relative to the scene file
//! scale = [0.001, 0.001, 0.001]  # optional, per axis (default 1)
//! decompose = 64              # optional: V-HACD resolution; default: the hull
//!
//! [[robot]]
//! name = "arm"                # its links are the objects "arm/<link>"
//! urdf = "arm.urdf"           # relative to the scene file
//! srdf = "arm.srdf"           # optional: disable_collisions pairs
//! package_path = ["pkgs"]     # optional: package:// folders
//! pose = { translation = [0.0, 0.0, 0.5] }   # base pose
//! joints = { shoulder = 0.3, elbow = -1.0 }  # or an array in joint order
//! ```
//!
//! `package://` URLs are searched in the robot's `package_path`, then the
//! folders given to `gjkd serve --package-path`, then those of
//! `GJKD_PACKAGE_PATH` and `ROS_PACKAGE_PATH`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use gjkd_model::{Kinematics, LimitMode, Mesh, PackagePath, RobotModel};
use serde::Deserialize;

use super::error::SceneError;
use super::pose::PoseSpec;
use crate::engine::robots::NewRobot;
use crate::engine::state::{NewObject, Owner, State};

/// A robot of a scene file.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// The robot's name: its links are the objects `<name>/<link>`.
    pub name: String,
    /// The URDF file.
    pub urdf: PathBuf,
    /// An SRDF file, for the robot's allowed pairs.
    pub srdf: Option<PathBuf>,
    /// Folders to search for `package://` URLs.
    #[serde(default)]
    pub package_path: Vec<PathBuf>,
    /// Base pose.
    #[serde(default)]
    pub pose: PoseSpec,
    /// Initial joint positions (default zero, clamped into the limits).
    pub joints: Option<JointsSpec>,
}

/// Joint positions: an array in the robot's joint order, or by name.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum JointsSpec {
    /// In joint order.
    Array(Vec<f64>),
    /// By name; joints not named are at zero.
    Named(BTreeMap<String, f64>),
}

/// The keys of a `[[robot]]` table.
pub const ROBOT_KEYS: &[&str] = &["name", "urdf", "srdf", "package_path", "pose", "joints"];

/// A mesh object's shape: its hull, or its V-HACD decomposition at
/// `decompose` resolution (whose largest deviation is logged).
///
/// # Errors
/// A message naming the file and the problem.
pub fn mesh_shape(
    file: &Path,
    scale: [f64; 3],
    decompose: Option<u32>,
) -> Result<gjk::Shape, String> {
    let mesh = Mesh::load(file, scale).map_err(|e| e.to_string())?;
    match decompose {
        None => Ok(mesh.to_convex().map_err(|e| e.to_string())?.into()),
        Some(resolution) => {
            let parts = mesh.decompose(resolution).map_err(|e| e.to_string())?;
            tracing::info!(
                file = %file.display(),
                pieces = parts.pieces.len(),
                deviation = parts.deviation,
                "mesh decomposed"
            );
            Ok(parts.to_compound().map_err(|e| e.to_string())?.into())
        }
    }
}

impl RobotSpec {
    /// Loads the robot (paths relative to `base`), adds its link objects to
    /// `state` as scene objects at its initial configuration, attaches its
    /// kinematics, and returns the link objects' ids.
    ///
    /// # Errors
    /// [`SceneError::Object`] naming the robot and the problem.
    pub fn install(
        &self,
        state: &mut State,
        base: Option<&Path>,
        extra_packages: &[PathBuf],
    ) -> Result<Vec<u64>, SceneError> {
        let fail = |reason: String| SceneError::Object {
            name: self.name.clone(),
            reason,
        };
        let at = |p: &Path| base.map_or_else(|| p.to_path_buf(), |b| b.join(p));
        let dirs = self
            .package_path
            .iter()
            .map(|p| at(p))
            .chain(extra_packages.iter().cloned());
        let packages = PackagePath::with_env(dirs);
        let urdf_path = at(&self.urdf);
        let model = RobotModel::load(&urdf_path, &packages).map_err(|e| fail(e.to_string()))?;
        let urdf = std::fs::read_to_string(&urdf_path).map_err(|e| fail(e.to_string()))?;
        let srdf = match &self.srdf {
            Some(p) => Some(
                std::fs::read_to_string(at(p))
                    .map_err(|e| fail(format!("{}: {e}", p.display())))?,
            ),
            None => None,
        };
        let pose = self.pose.to_isometry().map_err(fail)?;
        let positions = self.positions(&model.kinematics).map_err(fail)?;
        let poses = model
            .kinematics
            .link_poses(&pose, &positions, LimitMode::Reject)
            .map_err(|e| fail(e.to_string()))?;
        let mut ids = Vec::new();
        for (link, link_pose) in model.links.iter().zip(&poses) {
            let Some(shape) = &link.shape else { continue };
            let name = format!("{}/{}", self.name, link.name);
            if name.len() > gjkd_proto::MAX_NAME_LEN {
                return Err(fail(format!(
                    "object name `{name}` is longer than {} bytes",
                    gjkd_proto::MAX_NAME_LEN
                )));
            }
            let new = NewObject {
                shape: shape.clone(),
                pose: *link_pose,
                name: Some(name.clone()),
            };
            let id = state
                .adopt_scene_object(new)
                .map_err(|e| fail(format!("{name}: {e}")))?;
            ids.push(id);
        }
        let new = NewRobot {
            name: &self.name,
            urdf: &urdf,
            srdf: srdf.as_deref(),
            base: pose,
            positions: Some(positions),
            owner: Owner::Scene,
        };
        state.attach_robot(new).map_err(|e| fail(e.to_string()))?;
        Ok(ids)
    }

    fn positions(&self, kinematics: &Kinematics) -> Result<Vec<f64>, String> {
        match &self.joints {
            None => {
                let mut q = vec![0.0; kinematics.dof()];
                kinematics
                    .check_positions(&mut q, LimitMode::Clamp)
                    .map_err(|e| e.to_string())?;
                Ok(q)
            }
            Some(JointsSpec::Array(q)) => Ok(q.clone()),
            Some(JointsSpec::Named(named)) => {
                let named: Vec<(&str, f64)> = named.iter().map(|(k, v)| (k.as_str(), *v)).collect();
                kinematics
                    .positions_by_name(&named, &vec![0.0; kinematics.dof()])
                    .map_err(|e| e.to_string())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::engine::state::{Limits, State};
    use crate::scene::{Scene, SceneError};
    use gjkd_proto::WaitMode;
    use nalgebra::{Isometry3, Vector3};

    const CUBE_OBJ: &str = "v -1 -1 -1\nv 1 -1 -1\nv -1 1 -1\nv 1 1 -1\n\
        v -1 -1 1\nv 1 -1 1\nv -1 1 1\nv 1 1 1\n\
        f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\n\
        f 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\n";

    const URDF: &str = r#"<robot name="pointer">
      <link name="post"><collision><geometry><cylinder radius="0.1" length="1"/></geometry></collision></link>
      <link name="hand"><collision><geometry>
        <mesh filename="package://pointer/cube.obj" scale="0.1 0.1 0.1"/></geometry></collision></link>
      <joint name="turn" type="revolute"><parent link="post"/><child link="hand"/>
        <origin xyz="0 0 1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
    </robot>"#;

    fn folder(tag: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("gjkd-scene-robots-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("pkgs/pointer")).unwrap();
        std::fs::write(dir.join("pkgs/pointer/cube.obj"), CUBE_OBJ).unwrap();
        std::fs::write(dir.join("pointer.urdf"), URDF).unwrap();
        std::fs::write(dir.join("cube.obj"), CUBE_OBJ).unwrap();
        dir
    }

    fn load(dir: &std::path::Path, toml: &str) -> Result<(State, Vec<u64>), SceneError> {
        std::fs::write(dir.join("scene.toml"), toml).unwrap();
        let scene = Scene::load(&dir.join("scene.toml"))?;
        let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
        let ids = scene.install(&mut state)?;
        Ok((state, ids))
    }

    const SCENE: &str = r#"
[[object]]
name = "crate"
type = "mesh"
file = "cube.obj"
scale = [2.0, 1.0, 1.0]
pose = { translation = [5.0, 0.0, 0.0] }

[[robot]]
name = "pointer"
urdf = "pointer.urdf"
package_path = ["pkgs"]
pose = { translation = [1.0, 0.0, 0.0] }
joints = { turn = 0.5 }
"#;

    #[test]
    fn a_robot_and_a_mesh_in_a_scene_file_load() {
        let dir = folder("ok");
        let (state, ids) = load(&dir, SCENE).unwrap();
        assert_eq!(ids.len(), 3);
        let hand = state.object(state.lookup("pointer/hand").unwrap()).unwrap();
        let want = Isometry3::translation(1.0, 0.0, 1.0) * Isometry3::rotation(Vector3::z() * 0.5);
        assert!((hand.pose.to_homogeneous() - want.to_homogeneous()).norm() < 1e-12);
        let crate_ = state.object(state.lookup("crate").unwrap()).unwrap();
        let gjk::Shape::Convex(c) = &crate_.shape else {
            panic!("a hull is convex")
        };
        let max_x = c.vertices().iter().map(|p| p.x).fold(f64::MIN, f64::max);
        assert_eq!(max_x, 2.0);
        // The post is an exact cylinder at the base pose: a ball beside it
        // is `2 - 0.1 - 0.25` away, one above its top `0.8 - 0.5 - 0.25`.
        let post = state.object(state.lookup("pointer/post").unwrap()).unwrap();
        let gjk::Shape::Convex(c) = &post.shape else {
            panic!("one element at the link origin is convex")
        };
        assert_eq!(c.cylinder_dimensions(), Some((0.1, 0.5)));
        let ball: gjk::Shape = gjk::Convex::sphere(0.25).unwrap().into();
        for (at, want) in [
            (Vector3::new(1.0, 2.0, 0.2), 2.0 - 0.1 - 0.25),
            (Vector3::new(1.05, 0.0, -0.8), 0.8 - 0.5 - 0.25),
        ] {
            let at = Isometry3::translation(at.x, at.y, at.z);
            let options = gjk::Options::default();
            let a = gjk::distance(&post.shape, &post.pose, &ball, &at, &options, None).unwrap();
            assert!((a.distance - want).abs() < 1e-12, "{}", a.distance);
        }
        let robot = state
            .robots
            .get(state.robots.lookup("pointer").unwrap())
            .unwrap();
        assert_eq!(robot.positions, [0.5]);
        // Array positions are in joint order.
        let (state, _) = load(&dir, &SCENE.replace("{ turn = 0.5 }", "[-0.25]")).unwrap();
        let id = state.robots.lookup("pointer").unwrap();
        assert_eq!(state.robots.get(id).unwrap().positions, [-0.25]);
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn bad_robots_and_meshes_in_a_scene_are_reported() {
        let dir = folder("bad");
        let err = |toml: &str| load(&dir, toml).expect_err("refused").to_string();
        let e = err(&SCENE.replace("joints = { turn = 0.5 }", "joints = { turn = 5.0 }"));
        assert!(e.contains("outside its limits"), "{e}");
        let e = err(&SCENE.replace("joints = { turn = 0.5 }", "joints = { twist = 0.5 }"));
        assert!(e.contains("twist"), "{e}");
        let e = err(&SCENE.replace("package_path = [\"pkgs\"]", ""));
        assert!(e.contains("package://pointer/cube.obj"), "{e}");
        let e = err(&SCENE.replace("urdf = \"pointer.urdf\"", "urdf = \"none.urdf\""));
        assert!(e.contains("none.urdf"), "{e}");
        let e = err(&SCENE.replace("joints =", "joint ="));
        assert!(e.contains("unknown key `joint`"), "{e}");
        let e = err(&SCENE.replace("file = \"cube.obj\"", "file = \"gone.obj\""));
        assert!(e.contains("gone.obj"), "{e}");
        let e = err(&format!(
            "{SCENE}\n[[object]]\nname = \"pointer\"\ntype = \"sphere\"\nradius = 1.0\n"
        ));
        assert!(e.contains("pointer"), "{e}");
        std::fs::remove_dir_all(dir).unwrap();
    }
}

#[cfg(test)]
mod doc_tests {
    use crate::engine::state::{Limits, State};
    use crate::scene::Scene;
    use gjkd_proto::WaitMode;

    const ARM: &str = r#"<robot name="arm">
      <link name="base"><collision><geometry><mesh filename="package://arm/base.obj"/></geometry></collision></link>
      <link name="upper"><collision><geometry><box size="0.1 0.1 0.4"/></geometry></collision></link>
      <link name="fore"><collision><geometry><sphere radius="0.05"/></geometry></collision></link>
      <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
        <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
      <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
        <origin xyz="0 0 0.4"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
    </robot>"#;

    const TETRA_OBJ: &str =
        "v 0 0 0\nv 1000 0 0\nv 0 1000 0\nv 0 0 1000\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

    #[test]
    fn the_robot_doc_example_loads() {
        let doc = include_str!("../../../docs/scene-files.md");
        let section = &doc[doc.find("## Robots and meshes").expect("the section")..];
        let toml: String = section
            .lines()
            .skip_while(|l| !l.starts_with("```toml"))
            .skip(1)
            .take_while(|l| !l.starts_with("```"))
            .map(|l| format!("{l}\n"))
            .collect();
        let dir = std::env::temp_dir().join(format!("gjkd-scene-doc-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("meshes")).unwrap();
        std::fs::create_dir_all(dir.join("packages/arm")).unwrap();
        std::fs::write(dir.join("meshes/shelf.stl"), "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1000 0 0\nvertex 0 1000 0\nendloop\nendfacet\nendsolid s\n").unwrap();
        std::fs::write(dir.join("packages/arm/base.obj"), TETRA_OBJ).unwrap();
        std::fs::write(dir.join("arm.urdf"), ARM).unwrap();
        std::fs::write(
            dir.join("arm.srdf"),
            r#"<robot name="arm"><disable_collisions link1="base" link2="fore" reason="Never"/></robot>"#,
        )
        .unwrap();
        std::fs::write(dir.join("scene.toml"), toml).unwrap();
        let scene = Scene::load(&dir.join("scene.toml")).expect("parses");
        let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
        let ids = scene.install(&mut state).expect("valid");
        assert_eq!(ids.len(), 4, "the shelf and three links");
        let robot = state
            .robots
            .get(state.robots.lookup("arm").unwrap())
            .unwrap();
        assert_eq!(robot.positions, [0.3, -1.0]);
        assert_eq!(robot.allowed, [(0, 1), (0, 2), (1, 2)]);
        std::fs::remove_dir_all(dir).unwrap();
    }
}
