//! Scene files: named objects in TOML, loaded by `gjkd serve --scene FILE`
//! and looked up by clients by name.
//!
//! ```toml
//! [[object]]
//! name = "ball"
//! type = "sphere"
//! radius = 0.5
//! pose = { translation = [0.0, 0.0, 1.0] }
//!
//! [[object]]
//! name = "pill"
//! type = "capsule"
//! a = [0.0, 0.0, -1.0]
//! b = [0.0, 0.0, 1.0]
//! radius = 0.2
//!
//! [[object]]
//! name = "crate"
//! type = "box"
//! half_extents = [1.0, 2.0, 0.5]
//! radius = 0.05            # rounding, optional (default 0)
//! pose = { translation = [4.0, 0.0, 0.0], axis_angle = [0.0, 0.0, 0.7] }
//!
//! [[object]]
//! name = "wedge"
//! type = "polytope"
//! vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
//!
//! [[object]]
//! name = "dumbbell"
//! type = "compound"
//! [[object.pieces]]
//! type = "sphere"
//! radius = 0.3
//! offset = { translation = [-1.0, 0.0, 0.0] }
//! [[object.pieces]]
//! type = "sphere"
//! radius = 0.3
//! offset = { translation = [1.0, 0.0, 0.0] }
//! ```
//!
//! A cylinder is exact (gjk's support function, never a polytope), along
//! its body z axis, centred on its origin: `radius`, and `half_height` or
//! `length` (one of the two), optionally `rounding`; a compound takes
//! cylinder pieces too:
//!
//! ```toml
//! [[object]]
//! name = "can"
//! type = "cylinder"
//! radius = 0.5
//! half_height = 1.0        # or length = 2.0
//! rounding = 0.01          # optional (default 0)
//! pose = { translation = [0.0, 3.0, 0.0], axis_angle = [1.5707963267948966, 0.0, 0.0] }
//! ```
//!
//! Meshes (`type = "mesh"`) and robots (`[[robot]]`) are described in
//! [`crate::scene::robots`].
//!
//! A pose has an optional `translation` and at most one of `quaternion`
//! (`[i, j, k, w]`, normalised on load) and `axis_angle` (the rotation axis
//! scaled by the angle in radians).

use std::path::Path;

use gjk::{Compound, Convex, Shape};
use nalgebra::{Point3, Vector3};
use serde::Deserialize;

use crate::engine::state::{NewObject, State};

mod error;
mod pose;
pub mod robots;

pub use error::SceneError;
pub use pose::PoseSpec;
use robots::{ROBOT_KEYS, RobotSpec, mesh_shape};

/// A scene: a list of named objects.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// The objects, in file order.
    #[serde(default, rename = "object")]
    pub objects: Vec<ObjectSpec>,
    /// The robots, in file order, added after the objects.
    #[serde(default, rename = "robot")]
    pub robots: Vec<RobotSpec>,
    /// The folder relative paths (mesh files, URDF) are relative to: the
    /// scene file's, when loaded from a file.
    #[serde(skip)]
    pub base: Option<std::path::PathBuf>,
    /// Folders searched for `package://` URLs after each robot's own
    /// (`gjkd serve --package-path`).
    #[serde(skip)]
    pub package_path: Vec<std::path::PathBuf>,
}

/// One named object.
#[derive(Clone, Debug, Deserialize, PartialEq)]
pub struct ObjectSpec {
    /// Unique name.
    pub name: String,
    /// Initial pose.
    #[serde(default)]
    pub pose: PoseSpec,
    /// The geometry.
    #[serde(flatten)]
    pub shape: ShapeSpec,
}

/// A shape, tagged by `type`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum ShapeSpec {
    /// A ball.
    Sphere {
        /// Radius.
        radius: f64,
    },
    /// A segment grown by a radius.
    Capsule {
        /// One end.
        a: [f64; 3],
        /// The other end.
        b: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// A box centred on the body origin, optionally with rounded edges.
    Box {
        /// Half extents.
        half_extents: [f64; 3],
        /// Rounding radius.
        #[serde(default)]
        radius: f64,
    },
    /// The convex hull of vertices, optionally grown by a radius.
    Polytope {
        /// Vertices.
        vertices: Vec<[f64; 3]>,
        /// Rounding radius.
        #[serde(default)]
        radius: f64,
    },
    /// A mesh file's convex hull, or its convex decomposition.
    Mesh {
        /// STL, OBJ or COLLADA file, relative to the scene file.
        file: std::path::PathBuf,
        /// Scale per axis.
        #[serde(default = "unit_scale")]
        scale: [f64; 3],
        /// V-HACD resolution to decompose at, instead of taking the hull.
        decompose: Option<u32>,
    },
    /// An exact cylinder along z, centred on the origin.
    Cylinder {
        /// Radius of the disk.
        radius: f64,
        /// Half its length along z (or give `length`).
        half_height: Option<f64>,
        /// Its whole length along z (or give `half_height`).
        length: Option<f64>,
        /// Rounding radius of its edges.
        #[serde(default)]
        rounding: f64,
    },
    /// A union of convex pieces.
    Compound {
        /// The pieces.
        pieces: Vec<PieceSpec>,
    },
}

fn unit_scale() -> [f64; 3] {
    [1.0; 3]
}

/// A convex piece of a compound.
#[derive(Clone, Debug, Deserialize, PartialEq)]
pub struct PieceSpec {
    /// Offset in the compound's body frame.
    #[serde(default)]
    pub offset: PoseSpec,
    /// The piece's geometry (not itself a compound).
    #[serde(flatten)]
    pub shape: ShapeSpec,
}

impl ShapeSpec {
    fn convex(&self) -> Result<Convex, String> {
        let p = |v: [f64; 3]| Point3::from(v);
        let made = match self {
            ShapeSpec::Sphere { radius } => Convex::sphere(*radius),
            ShapeSpec::Capsule { a, b, radius } => Convex::capsule(p(*a), p(*b), *radius),
            ShapeSpec::Box {
                half_extents,
                radius,
            } => Convex::cuboid(Vector3::from(*half_extents), *radius),
            ShapeSpec::Polytope { vertices, radius } => {
                Convex::new(vertices.iter().map(|&v| p(v)).collect::<Vec<_>>(), *radius)
            }
            ShapeSpec::Mesh {
                file,
                scale,
                decompose: None,
            } => {
                let shape = mesh_shape(file, *scale, None)?;
                return match shape {
                    Shape::Convex(c) => Ok(c),
                    Shape::Compound(_) => Err("a mesh hull is one piece".into()),
                };
            }
            ShapeSpec::Mesh { .. } => return Err("a decomposed mesh cannot be a piece".into()),
            ShapeSpec::Cylinder {
                radius,
                half_height,
                length,
                rounding,
            } => {
                let half_height = match (half_height, length) {
                    (Some(h), None) => *h,
                    (None, Some(l)) => l / 2.0,
                    _ => {
                        return Err(
                            "a cylinder takes `half_height` or `length`, one of them".into()
                        );
                    }
                };
                return gjkd_model::cylinder(*radius, half_height, *rounding)
                    .map_err(|e| e.to_string());
            }
            ShapeSpec::Compound { .. } => return Err("a compound cannot be a piece".into()),
        };
        made.map_err(|e| e.to_string())
    }

    /// The gjk shape.
    ///
    /// # Errors
    /// A message saying what is wrong.
    pub fn build(&self) -> Result<Shape, String> {
        match self {
            ShapeSpec::Compound { pieces } => {
                let mut built = Vec::with_capacity(pieces.len());
                for (i, piece) in pieces.iter().enumerate() {
                    let offset = piece
                        .offset
                        .to_isometry()
                        .map_err(|e| format!("piece {i}: {e}"))?;
                    let convex = piece
                        .shape
                        .convex()
                        .map_err(|e| format!("piece {i}: {e}"))?;
                    built.push((offset, convex));
                }
                Ok(Compound::new(built).map_err(|e| e.to_string())?.into())
            }
            ShapeSpec::Mesh {
                file,
                scale,
                decompose: Some(resolution),
            } => mesh_shape(file, *scale, Some(*resolution)),
            _ => Ok(self.convex()?.into()),
        }
    }
}

impl Scene {
    /// Parses a scene from TOML text.
    ///
    /// # Errors
    /// [`SceneError::Parse`], [`SceneError::UnknownKey`].
    pub fn from_toml(text: &str) -> Result<Self, SceneError> {
        let table: toml::Table = toml::from_str(text)?;
        check_keys(&table)?;
        Ok(Scene::deserialize(table)?)
    }

    /// Reads and parses a scene file.
    ///
    /// # Errors
    /// [`SceneError::Io`], [`SceneError::Parse`], [`SceneError::UnknownKey`].
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
            path: path.display().to_string(),
            source,
        })?;
        let mut scene = Self::from_toml(&text)?;
        scene.base = path.parent().map(Path::to_path_buf);
        scene.rebase_mesh_files();
        Ok(scene)
    }

    /// Makes the mesh files' relative paths relative to [`Scene::base`].
    fn rebase_mesh_files(&mut self) {
        let Some(base) = &self.base else { return };
        let pieces = self.objects.iter_mut().flat_map(|o| match &mut o.shape {
            ShapeSpec::Compound { pieces } => pieces.iter_mut().map(|p| &mut p.shape).collect(),
            shape => vec![shape],
        });
        for shape in pieces {
            if let ShapeSpec::Mesh { file, .. } = shape
                && file.is_relative()
            {
                *file = base.join(&*file);
            }
        }
    }

    /// Adds every object to `state` as a read-only scene object, in file
    /// order, returning their ids. A scene object restored from the state
    /// file with the same name and geometry keeps its id, so clients that
    /// looked it up before a crash can go on using the id; restored scene
    /// objects the file no longer has are dropped.
    ///
    /// # Errors
    /// [`SceneError::Object`] for an invalid shape or pose, a duplicate name
    /// (within the file, or taken by a client's object restored from the
    /// state file) or too many objects; objects before it stay added.
    pub fn install(&self, state: &mut State) -> Result<Vec<u64>, SceneError> {
        let mut ids = Vec::with_capacity(self.objects.len());
        let mut seen = std::collections::HashSet::new();
        for spec in &self.objects {
            let fail = |reason: String| SceneError::Object {
                name: spec.name.clone(),
                reason,
            };
            if !seen.insert(spec.name.as_str()) {
                return Err(fail(gjkd_proto::ErrorCode::NameTaken.to_string()));
            }
            if spec.name.is_empty() || spec.name.len() > gjkd_proto::MAX_NAME_LEN {
                return Err(fail(format!(
                    "names must be 1 to {} bytes long",
                    gjkd_proto::MAX_NAME_LEN
                )));
            }
            let shape = spec.shape.build().map_err(fail)?;
            let pose = spec.pose.to_isometry().map_err(fail)?;
            let new = NewObject {
                shape,
                pose,
                name: Some(spec.name.clone()),
            };
            let id = state
                .adopt_scene_object(new)
                .map_err(|e| fail(e.to_string()))?;
            ids.push(id);
        }
        for robot in &self.robots {
            if !seen.insert(robot.name.as_str()) {
                return Err(SceneError::Object {
                    name: robot.name.clone(),
                    reason: "a robot and another robot or object share this name".into(),
                });
            }
            ids.extend(robot.install(state, self.base.as_deref(), &self.package_path)?);
        }
        state.drop_scene_objects_except(&ids);
        Ok(ids)
    }
}

/// The keys a shape of `kind` takes besides `type`; `None` for an unknown
/// type, which serde reports with the list of types.
fn shape_keys(kind: &str) -> Option<&'static [&'static str]> {
    Some(match kind {
        "sphere" => &["radius"],
        "capsule" => &["a", "b", "radius"],
        "box" => &["half_extents", "radius"],
        "polytope" => &["vertices", "radius"],
        "compound" => &["pieces"],
        "mesh" => &["file", "scale", "decompose"],
        "cylinder" => &["radius", "half_height", "length", "rounding"],
        _ => return None,
    })
}

/// Refuses any key the format does not have, naming it and its place.
/// serde cannot do this for objects and pieces: their shape keys are
/// flattened in beside the common ones, and flattening turns
/// `deny_unknown_fields` off.
fn check_keys(scene: &toml::Table) -> Result<(), SceneError> {
    check_table(scene, &["object", "robot"], "the scene")?;
    if let Some(toml::Value::Array(robots)) = scene.get("robot") {
        for (i, robot) in robots.iter().enumerate() {
            if let Some(robot) = robot.as_table() {
                let place = match robot.get("name").and_then(|n| n.as_str()) {
                    Some(name) => format!("robot `{name}`"),
                    None => format!("robot {i}"),
                };
                check_table(robot, ROBOT_KEYS, &place)?;
            }
        }
    }
    let Some(toml::Value::Array(objects)) = scene.get("object") else {
        return Ok(());
    };
    for (i, object) in objects.iter().enumerate() {
        let Some(object) = object.as_table() else {
            continue;
        };
        let place = match object.get("name").and_then(|n| n.as_str()) {
            Some(name) => format!("object `{name}`"),
            None => format!("object {i}"),
        };
        check_shape(object, &["name", "pose", "type"], &place)?;
        let Some(toml::Value::Array(pieces)) = object.get("pieces") else {
            continue;
        };
        for (j, piece) in pieces.iter().enumerate() {
            if let Some(piece) = piece.as_table() {
                check_shape(piece, &["offset", "type"], &format!("{place}, piece {j}"))?;
            }
        }
    }
    Ok(())
}

fn check_shape(table: &toml::Table, common: &[&str], place: &str) -> Result<(), SceneError> {
    let Some(keys) = table
        .get("type")
        .and_then(|t| t.as_str())
        .and_then(shape_keys)
    else {
        return Ok(());
    };
    let allowed: Vec<&str> = common.iter().chain(keys).copied().collect();
    check_table(table, &allowed, place)
}

fn check_table(table: &toml::Table, allowed: &[&str], place: &str) -> Result<(), SceneError> {
    match table.keys().find(|k| !allowed.contains(&k.as_str())) {
        Some(key) => Err(SceneError::UnknownKey {
            place: place.to_owned(),
            key: key.clone(),
            allowed: allowed.join(", "),
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::state::Limits;
    use gjkd_proto::WaitMode;
    use nalgebra::Isometry3;

    const EXAMPLE: &str = r#"
[[object]]
name = "ball"
type = "sphere"
radius = 0.5
pose = { translation = [0, 0, 1] }

[[object]]
name = "pill"
type = "capsule"
a = [0.0, 0.0, -1.0]
b = [0.0, 0.0, 1.0]
radius = 0.2

[[object]]
name = "crate"
type = "box"
half_extents = [1.0, 2.0, 0.5]
radius = 0.05
pose = { translation = [4.0, 0.0, 0.0], axis_angle = [0.0, 0.0, 0.7] }

[[object]]
name = "wedge"
type = "polytope"
vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]

[[object]]
name = "dumbbell"
type = "compound"
[[object.pieces]]
type = "sphere"
radius = 0.3
offset = { translation = [-1.0, 0.0, 0.0] }
[[object.pieces]]
type = "box"
half_extents = [0.2, 0.2, 0.2]
offset = { translation = [1.0, 0.0, 0.0], quaternion = [0.0, 0.0, 0.0, 2.0] }
"#;

    /// After a restart the same scene keeps its ids; a changed scene gets
    /// new ids for what changed and loses what it dropped; a duplicate name
    /// in one file is an error.
    #[test]
    fn scene_ids_survive_a_restart_and_follow_changes() {
        let scene = Scene::from_toml(EXAMPLE).expect("parses");
        let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
        let ids = scene.install(&mut state).expect("valid");
        let mut again =
            State::restore(Limits::default(), WaitMode::Spin, &state.snapshot()).expect("restores");
        assert_eq!(scene.install(&mut again).expect("valid"), ids);
        assert_eq!(again.len(), ids.len());

        let changed = EXAMPLE
            .replace("radius = 0.5", "radius = 0.6")
            .replace("name = \"wedge\"", "name = \"prism\"");
        let changed = Scene::from_toml(&changed).expect("parses");
        let mut third =
            State::restore(Limits::default(), WaitMode::Spin, &again.snapshot()).expect("restores");
        let new_ids = changed.install(&mut third).expect("valid");
        assert_ne!(new_ids[0], ids[0], "the ball changed");
        assert_eq!(new_ids[1..3], ids[1..3]);
        assert_ne!(new_ids[3], ids[3], "the wedge became a prism");
        assert_eq!(third.lookup("wedge"), None);
        assert_eq!(third.len(), 5);

        let twice =
            format!("{EXAMPLE}\n[[object]]\nname = \"ball\"\ntype = \"sphere\"\nradius = 0.5\n");
        let twice = Scene::from_toml(&twice).expect("parses");
        let mut fresh = State::new(Limits::default(), WaitMode::Spin, 1);
        assert!(twice.install(&mut fresh).is_err());
    }

    #[test]
    fn the_documented_example_loads() {
        let scene = Scene::from_toml(EXAMPLE).expect("parses");
        assert_eq!(scene.objects.len(), 5);
        let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
        let ids = scene.install(&mut state).expect("valid");
        assert_eq!(state.lookup("crate"), Some(ids[2]));
        let ball = state.object(ids[0]).expect("there");
        assert_eq!(ball.pose.translation.vector.z, 1.0);
        match &state.object(ids[4]).expect("there").shape {
            Shape::Compound(c) => {
                assert_eq!(c.pieces().len(), 2);
                assert!((c.pieces()[1].0.rotation.norm() - 1.0).abs() < 1e-15);
            }
            other => panic!("not a compound: {other:?}"),
        }
        let crate_pose = state.object(ids[2]).expect("there").pose;
        assert!((crate_pose.rotation.angle() - 0.7).abs() < 1e-12);
    }

    /// Every TOML block of this module's documentation, one after the
    /// other.
    #[test]
    fn the_module_doc_examples_load() {
        let mut doc = String::new();
        let mut inside = false;
        for line in include_str!("mod.rs").lines() {
            match (inside, line.trim_start().strip_prefix("//!")) {
                (false, Some(l)) if l.trim() == "```toml" => inside = true,
                (true, Some(l)) if l.trim() == "```" => inside = false,
                (true, Some(l)) => doc.extend([l.strip_prefix(' ').unwrap_or(l), "\n"]),
                _ => {}
            }
        }
        let scene = Scene::from_toml(&doc).expect("parses");
        let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
        assert_eq!(scene.install(&mut state).expect("valid").len(), 6);
        let can = state.lookup("can").expect("the cylinder is there");
        let can = state.object(can).expect("there");
        let Shape::Convex(c) = &can.shape else {
            panic!("a cylinder is one piece");
        };
        assert_eq!(c.cylinder_dimensions(), Some((0.5, 1.0)));
        assert_eq!(c.radius(), 0.01);
    }

    /// A scene cylinder, alone (given by `length`) or as a compound's piece
    /// (by `half_height`), answers exactly: beside the curved face
    /// `|centre_xy| - r - r_ball`, beyond a cap `|z| - h - r_ball`.
    #[test]
    fn scene_cylinders_are_exact() {
        let text = r#"
[[object]]
name = "can"
type = "cylinder"
radius = 0.5
length = 2.0

[[object]]
name = "pair"
type = "compound"
[[object.pieces]]
type = "cylinder"
radius = 0.5
half_height = 1.0
offset = { translation = [0.0, 0.0, 10.0] }
[[object.pieces]]
type = "sphere"
radius = 0.1
"#;
        let scene = Scene::from_toml(text).expect("parses");
        let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
        let ids = scene.install(&mut state).expect("valid");
        let ball: Shape = Convex::sphere(0.25).expect("ball").into();
        let options = gjk::Options::default();
        let cases = [
            (ids[0], Vector3::new(1.2, -1.6, 0.3), 2.0 - 0.5 - 0.25),
            (ids[0], Vector3::new(0.1, 0.2, -3.0), 3.0 - 1.0 - 0.25),
            (ids[1], Vector3::new(0.0, 3.0, 10.5), 3.0 - 0.5 - 0.25),
            (ids[1], Vector3::new(0.3, 0.0, 12.0), 2.0 - 1.0 - 0.25),
        ];
        for (id, at, want) in cases {
            let o = state.object(id).expect("there");
            let pose = Isometry3::translation(at.x, at.y, at.z);
            let a = gjk::distance(&o.shape, &o.pose, &ball, &pose, &options, None).expect("ok");
            assert!((a.distance - want).abs() < 1e-12, "{at:?}: {}", a.distance);
            assert!(a.lower <= want && want <= a.upper);
        }
    }

    /// Scene cylinders come back from the store as the very shapes the
    /// scene builds, so a restart keeps their ids.
    #[test]
    fn scene_cylinders_keep_their_ids_across_a_restart() {
        let text = "[[object]]\nname='can'\ntype='cylinder'\nradius=0.5\nlength=2\nrounding=0.1\n\
            [[object]]\nname='pair'\ntype='compound'\n\
            [[object.pieces]]\ntype='cylinder'\nradius=0.5\nhalf_height=1\n\
            [[object.pieces]]\ntype='sphere'\nradius=1\n";
        let scene = Scene::from_toml(text).expect("parses");
        let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
        let ids = scene.install(&mut state).expect("valid");
        let mut again =
            State::restore(Limits::default(), WaitMode::Spin, &state.snapshot()).expect("restores");
        assert_eq!(scene.install(&mut again).expect("valid"), ids);
        assert_eq!(again.len(), 2);
    }

    /// Every bad cylinder is refused with a message naming the problem.
    #[test]
    fn bad_scene_cylinders_are_reported() {
        let can = "[[object]]\nname='c'\ntype='cylinder'\n";
        let cases = [
            ("radius=1\nhalf_height=1\nlength=2\n", "one of them"),
            ("radius=1\n", "one of them"),
            ("radius=-1\nhalf_height=1\n", "must be finite"),
            ("radius=1\nlength=-2\n", "must be finite"),
            ("radius=1\nhalf_height=nan\n", "must be finite"),
            ("radius=1\nhalf_height=1\nrounding=-0.5\n", "must be finite"),
            ("radius=4e300\nhalf_height=4e300\n", "at most 5e300"),
        ];
        for (keys, message) in cases {
            let text = format!("{can}{keys}");
            let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
            let err = Scene::from_toml(&text)
                .expect("parses")
                .install(&mut state)
                .expect_err(keys);
            assert!(err.to_string().contains(message), "{keys}: {err}");
            assert_eq!(state.len(), 0, "nothing loaded");
        }
        let typo = format!("{can}radius=1\nhalf_height=1\nrounded=0.1\n");
        match Scene::from_toml(&typo) {
            Err(SceneError::UnknownKey { key, .. }) => assert_eq!(key, "rounded"),
            other => panic!("expected UnknownKey, got {other:?}"),
        }
    }

    #[test]
    fn unknown_keys_are_refused_by_name() {
        let cases = [
            (
                "[[object]]\nname='a'\ntype='sphere'\nradious=1\n",
                "object `a`",
                "radious",
            ),
            (
                "[[object]]\nname='b'\ntype='box'\nhalf_extents=[1,1,1]\nradius=0\ncolor='red'\n",
                "object `b`",
                "color",
            ),
            (
                "[[object]]\ntype='sphere'\nradius=1\nnmae='c'\n",
                "object 0",
                "nmae",
            ),
            ("objects = []\n", "the scene", "objects"),
            (
                "[[object]]\nname='d'\ntype='compound'\n[[object.pieces]]\ntype='sphere'\nradius=1\npose={}\n",
                "object `d`, piece 0",
                "pose",
            ),
        ];
        for (text, place, key) in cases {
            match Scene::from_toml(text) {
                Err(SceneError::UnknownKey {
                    place: p, key: k, ..
                }) => {
                    assert_eq!((p.as_str(), k.as_str()), (place, key), "{text}");
                }
                other => panic!("{text}: expected UnknownKey, got {other:?}"),
            }
        }
        // Inside a pose, serde itself refuses, naming the key.
        let pose = "[[object]]\nname='e'\ntype='sphere'\nradius=1\npose={translaton=[1,0,0]}\n";
        let err = Scene::from_toml(pose).expect_err("misspelt pose key");
        assert!(err.to_string().contains("translaton"), "{err}");
    }

    #[test]
    fn the_scene_file_doc_example_loads() {
        let doc: String = include_str!("../../../docs/scene-files.md")
            .lines()
            .skip_while(|l| !l.starts_with("```toml"))
            .skip(1)
            .take_while(|l| !l.starts_with("```"))
            .map(|l| format!("{l}\n"))
            .collect();
        let scene = Scene::from_toml(&doc).expect("parses");
        let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
        let ids = scene.install(&mut state).expect("valid");
        assert_eq!(ids.len(), scene.objects.len());
        assert!(ids.len() >= 7, "the example shows every shape type");
        let bottle = state.object(state.lookup("bottle").expect("there"));
        let Some(Shape::Convex(bottle)) = bottle.map(|o| &o.shape) else {
            panic!("a cylinder is one piece");
        };
        assert_eq!(bottle.cylinder_dimensions(), Some((0.04, 0.125)));
        let rack = state.object(state.lookup("rack").expect("there"));
        let Some(Shape::Compound(rack)) = rack.map(|o| &o.shape) else {
            panic!("the rack is a compound");
        };
        for (_, piece) in rack.pieces() {
            assert_eq!(piece.cylinder_dimensions(), Some((0.01, 0.3)));
            assert_eq!(piece.radius(), 0.002);
        }
    }

    /// The README's scene-file example (its one TOML block), with the
    /// closed form of a ball's distance to its pillar.
    #[test]
    fn the_readme_example_loads() {
        let doc: String = include_str!("../../../README.md")
            .lines()
            .skip_while(|l| !l.starts_with("```toml"))
            .skip(1)
            .take_while(|l| !l.starts_with("```"))
            .map(|l| format!("{l}\n"))
            .collect();
        let scene = Scene::from_toml(&doc).expect("parses");
        let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
        assert_eq!(scene.install(&mut state).expect("valid").len(), 2);
        let pillar = state
            .object(state.lookup("pillar").expect("there"))
            .expect("there");
        let ball: Shape = Convex::sphere(0.1).expect("ball").into();
        let at = Isometry3::translation(1.0, 1.5, 0.5);
        let options = gjk::Options::default();
        let a = gjk::distance(&pillar.shape, &pillar.pose, &ball, &at, &options, None).expect("ok");
        assert!(
            (a.distance - (1.0 - 0.15 - 0.1)).abs() < 1e-12,
            "{}",
            a.distance
        );
    }

    #[test]
    fn bad_scenes_are_reported() {
        let dup = "[[object]]\nname='a'\ntype='sphere'\nradius=1\n[[object]]\nname='a'\ntype='sphere'\nradius=1\n";
        let mut state = State::new(Limits::default(), WaitMode::Spin, 1);
        let err = Scene::from_toml(dup)
            .expect("parses")
            .install(&mut state)
            .expect_err("duplicate");
        assert!(err.to_string().contains("name"), "{err}");
        assert!(Scene::from_toml("[[object]]\nname='a'\ntype='cone'\n").is_err());
        let neg = "[[object]]\nname='n'\ntype='sphere'\nradius=-1\n";
        assert!(
            Scene::from_toml(neg)
                .expect("parses")
                .install(&mut state)
                .is_err()
        );
        let both = "[[object]]\nname='q'\ntype='sphere'\nradius=1\npose={quaternion=[0,0,0,1], axis_angle=[0,0,1]}\n";
        assert!(
            Scene::from_toml(both)
                .expect("parses")
                .install(&mut state)
                .is_err()
        );
    }
}
