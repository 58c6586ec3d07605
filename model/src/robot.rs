//! A robot from URDF: its kinematic tree and one shape per link.
//!
//! A link's shape is made of its `<collision>` elements, each at its
//! `<origin>` in the link frame: `<box>`, `<sphere>`, `<cylinder>` (an
//! exact cylinder of `length` along the element's z axis, see [`cylinder`];
//! never a polytope), `<capsule>` (a non-standard element some tools write:
//! a cylinder of `length` between two half balls, along z) and `<mesh>`
//! (its convex hull, scaled). One element at the link origin is a convex
//! shape, several a compound. A link without collision elements has no
//! shape.

use std::path::{Path, PathBuf};

use gjk::{Compound, Convex, Shape};
use nalgebra::{Isometry3, Point3, Vector3};

use crate::kinematics::{Kinematics, KinematicsError, urdf_pose};
use crate::mesh::{Mesh, MeshError};
use crate::paths::PackagePath;

/// What can go wrong loading a robot.
#[derive(Debug, thiserror::Error)]
pub enum RobotError {
    /// The URDF file could not be read.
    #[error("cannot read URDF file {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The URDF is malformed or its tree is not one gjkd can move.
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// A mesh's `package://` URL was found in no package folder.
    #[error("link `{link}`: {message}")]
    MeshPath {
        /// The link.
        link: String,
        /// Where it was looked for.
        message: String,
    },
    /// A mesh file is missing or not a mesh.
    #[error("link `{link}`: {source}")]
    Mesh {
        /// The link.
        link: String,
        /// What is wrong with the mesh.
        source: MeshError,
    },
    /// A collision element's size or origin is not valid (negative, NaN).
    #[error("link `{link}`: {reason}")]
    Geometry {
        /// The link.
        link: String,
        /// Why.
        reason: String,
    },
}

/// One link: its name and shape.
#[derive(Clone, Debug)]
pub struct LinkModel {
    /// The link's name.
    pub name: String,
    /// Its collision shape in the link frame; `None` for a link without
    /// collision elements.
    pub shape: Option<Shape>,
}

/// A robot: its name, kinematic tree and link shapes.
#[derive(Clone, Debug)]
pub struct RobotModel {
    /// The kinematic tree.
    pub kinematics: Kinematics,
    /// The links, in [`Kinematics::link_names`] order.
    pub links: Vec<LinkModel>,
}

impl RobotModel {
    /// Reads a URDF file; relative mesh paths are relative to its folder.
    ///
    /// # Errors
    /// A [`RobotError`] naming the file, link or joint at fault.
    pub fn load(path: &Path, packages: &PackagePath) -> Result<Self, RobotError> {
        let text = std::fs::read_to_string(path).map_err(|source| RobotError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_urdf_str(&text, path.parent(), packages)
    }

    /// Parses URDF text; relative mesh paths are relative to `base` (or to
    /// the working folder).
    ///
    /// # Errors
    /// A [`RobotError`] naming the link or joint at fault.
    pub fn from_urdf_str(
        text: &str,
        base: Option<&Path>,
        packages: &PackagePath,
    ) -> Result<Self, RobotError> {
        let urdf = crate::urdf::parse_urdf(text)?;
        let kinematics = Kinematics::from_urdf(&urdf)?;
        let links = urdf
            .links
            .iter()
            .map(|link| {
                Ok(LinkModel {
                    name: link.name.clone(),
                    shape: link_shape(link, base, packages)?,
                })
            })
            .collect::<Result<Vec<_>, RobotError>>()?;
        Ok(RobotModel { kinematics, links })
    }

    /// The robot's name in the URDF.
    pub fn name(&self) -> &str {
        self.kinematics.robot_name()
    }
}

fn link_shape(
    link: &urdf_rs::Link,
    base: Option<&Path>,
    packages: &PackagePath,
) -> Result<Option<Shape>, RobotError> {
    let mut pieces = Vec::with_capacity(link.collision.len());
    for element in &link.collision {
        let o = &element.origin;
        if !o.xyz.0.iter().chain(&o.rpy.0).all(|c| c.is_finite()) {
            return Err(RobotError::Geometry {
                link: link.name.clone(),
                reason: "a collision origin is not finite".into(),
            });
        }
        let convex = element_convex(&link.name, &element.geometry, base, packages)?;
        pieces.push((urdf_pose(o), convex));
    }
    let shape = match pieces.len() {
        0 => return Ok(None),
        1 if pieces[0].0 == Isometry3::identity() => Shape::Convex(pieces.remove(0).1),
        _ => Shape::Compound(Compound::new(pieces).map_err(|e| RobotError::Geometry {
            link: link.name.clone(),
            reason: e.to_string(),
        })?),
    };
    Ok(Some(shape))
}

/// Why a cylinder could not be made: a size is negative, not finite, or
/// the cylinder would reach beyond 2^999 (about 5e300) from its centre.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct CylinderError(pub String);

/// The farthest gjk lets a shape reach from its origin, 2^999.
const MAX_REACH: f64 = 5.357543035931337e300;

/// An exact cylinder along z, centred on its frame's origin: the disk of
/// `radius` swept from `z = -half_height` to `z = +half_height`, edges
/// rounded by `rounding` (gjk's [`Convex::cylinder`], a support function,
/// never a polytope). The one place where URDF `<cylinder>` elements (along
/// their frame's z axis, as gjk's) and scene-file cylinders become a shape.
///
/// ```
/// let can = gjkd_model::cylinder(0.05, 0.2, 0.0)?;
/// assert_eq!(can.cylinder_dimensions(), Some((0.05, 0.2)));
/// # Ok::<(), gjkd_model::CylinderError>(())
/// ```
///
/// # Errors
/// [`CylinderError`] for a negative or non-finite size, or one reaching
/// beyond 2^999.
pub fn cylinder(radius: f64, half_height: f64, rounding: f64) -> Result<Convex, CylinderError> {
    let sizes = [radius, half_height, rounding];
    if !sizes.iter().all(|x| x.is_finite() && *x >= 0.0)
        || radius.hypot(half_height) + rounding > MAX_REACH
    {
        return Err(CylinderError(format!(
            "cylinder radius {radius}, half height {half_height} and rounding {rounding} must be finite, >= 0 and at most 5e300"
        )));
    }
    Convex::cylinder(radius, half_height, rounding).map_err(|e| CylinderError(e.to_string()))
}

/// One collision element as a convex shape in its own frame.
fn element_convex(
    link: &str,
    geometry: &urdf_rs::Geometry,
    base: Option<&Path>,
    packages: &PackagePath,
) -> Result<Convex, RobotError> {
    use urdf_rs::Geometry as G;
    let bad = |reason: String| RobotError::Geometry {
        link: link.to_owned(),
        reason,
    };
    let made = match geometry {
        G::Box { size } => {
            if !size.0.iter().all(|s| s.is_finite() && *s >= 0.0) {
                return Err(bad(format!(
                    "box size {:?} must be finite and >= 0",
                    size.0
                )));
            }
            Convex::cuboid(Vector3::from(size.0) / 2.0, 0.0)
        }
        G::Sphere { radius } => Convex::sphere(*radius),
        G::Capsule { radius, length } => {
            if !(length.is_finite() && *length >= 0.0) {
                return Err(bad(format!(
                    "capsule length {length} must be finite and >= 0"
                )));
            }
            let h = length / 2.0;
            Convex::capsule(Point3::new(0.0, 0.0, -h), Point3::new(0.0, 0.0, h), *radius)
        }
        G::Cylinder { radius, length } => {
            return cylinder(*radius, length / 2.0, 0.0).map_err(|e| bad(e.0));
        }
        G::Mesh { filename, scale } => {
            let path =
                packages
                    .resolve(filename, base)
                    .map_err(|message| RobotError::MeshPath {
                        link: link.to_owned(),
                        message,
                    })?;
            let scale = scale.as_ref().map_or([1.0; 3], |s| s.0);
            let mesh_error = |source| RobotError::Mesh {
                link: link.to_owned(),
                source,
            };
            return Mesh::load(&path, scale)
                .and_then(|m| m.to_convex())
                .map_err(mesh_error);
        }
    };
    made.map_err(|e| bad(e.to_string()))
}
