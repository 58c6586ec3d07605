//! Meshes and robots: register a mesh (its hull or a convex decomposition)
//! and a robot from URDF, find a robot the scene file loaded, and move a
//! robot by its joints in one round trip.
//!
//! ```no_run
//! use gjkd_client::{Client, MeshMode, PackagePath, QueryOptions};
//! use nalgebra::Isometry3;
//! use std::path::Path;
//!
//! # fn main() -> Result<(), gjkd_client::ClientError> {
//! let mut client = Client::connect("gjkd")?;
//! let table = client.register_mesh_file(
//!     "table", Path::new("table.stl"), [1.0; 3], MeshMode::Hull,
//!     &Isometry3::translation(1.0, 0.0, 0.0))?;
//! let mut arm = client.register_robot(
//!     "arm", Path::new("arm.urdf"), None, &PackagePath::with_env([]),
//!     &Isometry3::identity())?;
//! // One round trip: every link moves by forward kinematics.
//! client.set_joints(&mut arm, &[0.1, -0.5, 0.3, 0.0, 1.0, 0.0, 0.2], None)?;
//! let hand = arm.link("hand").expect("the hand has collision geometry");
//! let answer = client.distance(hand, table.id, &QueryOptions::default())?;
//! # Ok(())
//! # }
//! ```

use std::path::Path;

use gjk::Shape;
pub use gjkd_model::{JointError, Kinematics, LimitMode, Mesh, MeshError, PackagePath, RobotModel};
use gjkd_proto::{
    AdminChunk, AdminOp, AdminRequest, Item, ItemResult, JOINTS_PER_ITEM, ObjectId, Pose,
};
use nalgebra::Isometry3;

#[cfg(doc)]
use crate::ErrorCode;
use crate::{
    Client, ClientError, Geometry, LookupError, Piece, RegisterError, RobotError, op_error,
};

/// How a mesh becomes a shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshMode {
    /// Its convex hull: one piece; never reports more distance than the
    /// mesh.
    Hull,
    /// A V-HACD convex decomposition at this resolution (voxels along the
    /// longest side; 64 is a fair start): a compound that follows a
    /// non-convex mesh, within the reported deviation.
    Decompose(u32),
}

/// A registered mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct RegisteredMesh {
    /// The object.
    pub id: ObjectId,
    /// Number of convex pieces.
    pub pieces: usize,
    /// For a decomposition, the largest deviation found from the mesh (see
    /// `gjkd_model::Decomposition::deviation`); 0 for a hull, which never
    /// reaches closer than the mesh's own convex hull.
    pub deviation: f64,
}

/// A robot on the server, with what a client needs to move it and query
/// its links.
#[derive(Clone, Debug)]
pub struct RobotHandle {
    /// The robot's id, for [`Item::set_joints`].
    pub id: ObjectId,
    /// Its name.
    pub name: String,
    /// Its kinematics: joint order, limits, link names.
    pub kinematics: Kinematics,
    /// Each link's object (in [`Kinematics::link_names`] order), `None` for
    /// a link without collision geometry.
    pub links: Vec<Option<ObjectId>>,
    /// The joint positions last sent by [`Client::set_joints`] (zero, within
    /// the limits, at first).
    pub positions: Vec<f64>,
}

impl RobotHandle {
    /// The object of link `name`.
    pub fn link(&self, name: &str) -> Option<ObjectId> {
        let i = self
            .kinematics
            .link_names()
            .iter()
            .position(|l| l == name)?;
        self.links[i]
    }

    /// The moving joints' names, in the order of a position array.
    pub fn joint_names(&self) -> Vec<&str> {
        self.kinematics.joint_names()
    }

    /// Every link's name.
    pub fn link_names(&self) -> &[String] {
        self.kinematics.link_names()
    }

    /// The items that set `positions` (all joints, in joint order) and
    /// `base`, to put in a batch before queries: one item per
    /// [`JOINTS_PER_ITEM`] joints. [`RobotHandle::positions`] is not
    /// updated (the batch may fail): [`Client::set_joints_by_name`] starts
    /// from the positions last sent by [`Client::set_joints`].
    pub fn joint_items(
        &self,
        positions: &[f64],
        base: Option<&Isometry3<f64>>,
        clamp: bool,
    ) -> Vec<Item> {
        if positions.is_empty() {
            // A robot without moving joints: only its base moves (or,
            // without a base, nothing; the server still checks the robot).
            return vec![Item::set_joints(self.id, 0, &[], base, clamp)];
        }
        positions
            .chunks(JOINTS_PER_ITEM)
            .enumerate()
            .map(|(k, chunk)| {
                let first = (k * JOINTS_PER_ITEM) as u32;
                Item::set_joints(self.id, first, chunk, base.filter(|_| k == 0), clamp)
            })
            .collect()
    }
}

/// A robot that cannot be read, with the model's words.
fn robot_err(e: impl std::fmt::Display) -> RobotError {
    RobotError::InvalidRobot(e.to_string())
}

/// A mesh that cannot be used, with the model's words.
fn mesh_err(e: impl std::fmt::Display) -> RegisterError {
    RegisterError::InvalidMesh(e.to_string())
}

/// Positions by name refused before sending: an unknown joint carries the
/// code of an unknown name, as in Python and C.
fn named_joint_err(e: JointError) -> RobotError {
    match e {
        JointError::UnknownJoint(name) => RobotError::UnknownJoint(name),
        _ => RobotError::WrongJointCount,
    }
}

impl Client {
    /// Registers a mesh file (binary or ASCII STL, OBJ, COLLADA), scaled per
    /// axis, as its hull or decomposed, named and at `pose`.
    ///
    /// # Errors
    /// [`RegisterError::InvalidMesh`] for a file that is missing or not a
    /// mesh, or a bad scale; as [`Client::register_named`] otherwise.
    pub fn register_mesh_file(
        &mut self,
        name: &str,
        path: &Path,
        scale: [f64; 3],
        mode: MeshMode,
        pose: &Isometry3<f64>,
    ) -> Result<RegisteredMesh, RegisterError> {
        let mesh = Mesh::load(path, scale).map_err(mesh_err)?;
        self.register_mesh(name, &mesh, mode, pose)
    }

    /// Registers a mesh given as arrays ([`Mesh::from_arrays`]), as its hull
    /// or decomposed, named and at `pose`.
    ///
    /// # Errors
    /// [`RegisterError::InvalidMesh`] when the decomposition finds no
    /// pieces; as [`Client::register_named`] otherwise.
    pub fn register_mesh(
        &mut self,
        name: &str,
        mesh: &Mesh,
        mode: MeshMode,
        pose: &Isometry3<f64>,
    ) -> Result<RegisteredMesh, RegisterError> {
        match mode {
            MeshMode::Hull => {
                let hull = mesh.hull();
                let geometry = Geometry::Polytope {
                    vertices: &hull,
                    radius: 0.0,
                };
                let id = self.register_named(name, &geometry, pose)?;
                Ok(RegisteredMesh {
                    id,
                    pieces: 1,
                    deviation: 0.0,
                })
            }
            MeshMode::Decompose(resolution) => {
                let parts = mesh.decompose(resolution).map_err(mesh_err)?;
                let pieces: Vec<Piece<'_>> = parts
                    .pieces
                    .iter()
                    .map(|p| Piece {
                        offset: Isometry3::identity(),
                        geometry: Geometry::Polytope {
                            vertices: p,
                            radius: 0.0,
                        },
                    })
                    .collect();
                let id = self.register_named(name, &Geometry::Compound(&pieces), pose)?;
                Ok(RegisteredMesh {
                    id,
                    pieces: pieces.len(),
                    deviation: parts.deviation,
                })
            }
        }
    }

    /// Registers a robot from a URDF file (and optionally an SRDF for its
    /// allowed pairs): each link with collision geometry becomes an object
    /// named `<name>/<link>`, then the server gets the kinematics and puts
    /// the robot at `base` with every joint at zero (clamped into its
    /// limits). Mesh paths are resolved here, through `packages` and
    /// relative to the URDF's folder.
    ///
    /// # Errors
    /// [`RobotError::InvalidRobot`] (code [`ErrorCode::InvalidRobot`]) for
    /// a URDF, SRDF or mesh that cannot be loaded (the message names the
    /// file, link or joint); [`RobotError::Link`] with the
    /// [`RegisterError`] of a link object ([`RegisterError::NameTaken`]: a
    /// link object of that name exists; after a server restart, use
    /// [`Client::attach_robot`]); [`RobotError::RobotRefused`] and the
    /// faults of [`Client::attach_robot`]. Link objects registered before a
    /// failure are removed again.
    pub fn register_robot(
        &mut self,
        name: &str,
        urdf: &Path,
        srdf: Option<&Path>,
        packages: &PackagePath,
        base: &Isometry3<f64>,
    ) -> Result<RobotHandle, RobotError> {
        let text = std::fs::read_to_string(urdf)
            .map_err(|e| RobotError::InvalidRobot(format!("{}: {e}", urdf.display())))?;
        let srdf = srdf
            .map(|p| {
                std::fs::read_to_string(p)
                    .map_err(|e| RobotError::InvalidRobot(format!("{}: {e}", p.display())))
            })
            .transpose()?;
        self.register_robot_text(name, &text, srdf.as_deref(), urdf.parent(), packages, base)
    }

    /// [`Client::register_robot`] from URDF (and SRDF) text in memory, for
    /// callers that generate it (xacro, a robot description topic):
    /// relative mesh paths are resolved against `mesh_base` (the working
    /// folder when `None`), `package://` ones through `packages`.
    ///
    /// # Errors
    /// As [`Client::register_robot`].
    pub fn register_robot_text(
        &mut self,
        name: &str,
        urdf: &str,
        srdf: Option<&str>,
        mesh_base: Option<&Path>,
        packages: &PackagePath,
        base: &Isometry3<f64>,
    ) -> Result<RobotHandle, RobotError> {
        let model = RobotModel::from_urdf_str(urdf, mesh_base, packages).map_err(robot_err)?;
        gjkd_model::disabled_pairs(srdf, &model.kinematics, true).map_err(robot_err)?;
        let mut registered = Vec::new();
        let outcome = self
            .register_links(name, &model, &mut registered)
            .map_err(RobotError::from);
        let outcome = outcome.and_then(|()| self.attach_robot(name, urdf, srdf, base));
        if outcome.is_err() {
            for id in registered {
                let _ = self.remove(id);
            }
        }
        outcome
    }

    fn register_links(
        &mut self,
        name: &str,
        model: &RobotModel,
        registered: &mut Vec<ObjectId>,
    ) -> Result<(), RegisterError> {
        for link in &model.links {
            let Some(shape) = &link.shape else { continue };
            let object = format!("{name}/{}", link.name);
            let id = match shape {
                Shape::Convex(c) => {
                    self.register_named(&object, &Geometry::of_convex(c), &Isometry3::identity())?
                }
                Shape::Compound(c) => {
                    let pieces: Vec<Piece<'_>> = c
                        .pieces()
                        .iter()
                        .map(|(offset, p)| Piece {
                            offset: *offset,
                            geometry: Geometry::of_convex(p),
                        })
                        .collect();
                    self.register_named(
                        &object,
                        &Geometry::Compound(&pieces),
                        &Isometry3::identity(),
                    )?
                }
            };
            registered.push(id);
        }
        Ok(())
    }

    /// Attaches a robot's kinematics (URDF text, optional SRDF text) to
    /// link objects already on the server (named `<name>/<link>`): after a
    /// server restart, the restored links of a robot registered before. The
    /// robot is put at `base`, joints at zero within their limits.
    ///
    /// # Errors
    /// [`RobotError::InvalidRobot`] for URDF text this client cannot read;
    /// [`RobotError::NameTooLong`], [`RobotError::TextTooLong`];
    /// [`RobotError::RobotRefused`] (the server cannot use the URDF or
    /// SRDF), [`RobotError::NotOwner`] (another client's robot has that
    /// name), [`RobotError::NonFinitePose`] or
    /// [`RobotError::BadQuaternion`] (the base), [`RobotError::OutOfLimits`];
    /// the connection faults.
    pub fn attach_robot(
        &mut self,
        name: &str,
        urdf: &str,
        srdf: Option<&str>,
        base: &Isometry3<f64>,
    ) -> Result<RobotHandle, RobotError> {
        let kinematics = Kinematics::from_urdf_str(urdf).map_err(robot_err)?;
        let text = match srdf {
            Some(srdf) => format!("{urdf}\0{srdf}"),
            None => urdf.to_owned(),
        };
        let mut request = AdminRequest::new(AdminOp::AttachRobot);
        if !request.set_name(name) {
            return Err(RobotError::NameTooLong);
        }
        request.text_len = u32::try_from(text.len()).map_err(|_| RobotError::TextTooLong)?;
        request.pose = Pose::from_isometry(base);
        let reply = self
            .admin(&request, &AdminChunk::pack_text(&text))
            .map_err(op_error::<RobotError>)?;
        self.ending.robot(name);
        self.handle(ObjectId::from_raw(reply.id), name, kinematics)
    }

    /// Finds a robot on the server by name (one the scene file loaded, or
    /// another client attached), given its URDF text for the joint order
    /// and link names.
    ///
    /// # Errors
    /// [`RobotError::InvalidRobot`] for URDF text this client cannot read;
    /// [`RobotError::UnknownRobot`]; [`RobotError::NameTooLong`]; the
    /// connection faults.
    pub fn open_robot(&mut self, name: &str, urdf: &str) -> Result<RobotHandle, RobotError> {
        let kinematics = Kinematics::from_urdf_str(urdf).map_err(robot_err)?;
        let id = self.robot_id(name)?;
        self.handle(id, name, kinematics)
    }

    fn handle(
        &mut self,
        id: ObjectId,
        name: &str,
        kinematics: Kinematics,
    ) -> Result<RobotHandle, RobotError> {
        let mut links = Vec::with_capacity(kinematics.link_names().len());
        for link in kinematics.link_names() {
            links.push(match self.lookup(&format!("{name}/{link}")) {
                Ok(id) => Some(id),
                // A link without collision geometry has no object.
                Err(LookupError::UnknownName) => None,
                Err(e) => return Err(e.into()),
            });
        }
        let mut positions = vec![0.0; kinematics.dof()];
        kinematics
            .check_positions(&mut positions, LimitMode::Clamp)
            .map_err(robot_err)?;
        Ok(RobotHandle {
            id,
            name: name.to_owned(),
            kinematics,
            links,
            positions,
        })
    }

    /// Sets every joint of `robot` (an array in [`RobotHandle::joint_names`]
    /// order) and, if given, its base pose, in one round trip: the server
    /// computes and stores every link's pose. Positions outside their
    /// limits are refused. A robot without moving joints takes no
    /// positions: `set_joints(robot, &[], Some(&base))` moves it by its base
    /// alone.
    ///
    /// # Errors
    /// [`RobotError::WrongJointCount`] for the wrong number of positions;
    /// [`RobotError::OutOfLimits`], [`RobotError::NonFinitePose`] (a NaN
    /// position or base), [`RobotError::BadQuaternion`] (the base),
    /// [`RobotError::UnknownObject`] (robot or link gone); the connection
    /// faults. Nothing moves then.
    pub fn set_joints(
        &mut self,
        robot: &mut RobotHandle,
        positions: &[f64],
        base: Option<&Isometry3<f64>>,
    ) -> Result<(), RobotError> {
        self.set_joints_with(robot, positions, base, LimitMode::Reject)
    }

    /// [`Client::set_joints`], with positions outside their limits refused
    /// or moved to the nearest limit as `mode` says; with
    /// [`LimitMode::Clamp`], [`RobotHandle::positions`] holds the clamped
    /// positions afterwards.
    ///
    /// # Errors
    /// As [`Client::set_joints`] ([`RobotError::OutOfLimits`] only with
    /// [`LimitMode::Reject`]).
    pub fn set_joints_with(
        &mut self,
        robot: &mut RobotHandle,
        positions: &[f64],
        base: Option<&Isometry3<f64>>,
        mode: LimitMode,
    ) -> Result<(), RobotError> {
        if positions.len() != robot.positions.len() {
            return Err(RobotError::WrongJointCount);
        }
        let items = robot.joint_items(positions, base, mode == LimitMode::Clamp);
        let mut results = vec![ItemResult::default(); items.len()];
        self.batch(&items, &mut results)
            .map_err(op_error::<RobotError>)?;
        if let Some(r) = results.iter().find(|r| r.error != 0) {
            return Err(op_error(ClientError::Rejected(r.error_code())));
        }
        robot.positions.copy_from_slice(positions);
        // The server accepted them, so they are finite: clamping cannot
        // fail.
        let _ = robot
            .kinematics
            .check_positions(&mut robot.positions, LimitMode::Clamp);
        Ok(())
    }

    /// [`Client::set_joints`] by joint name; joints not named keep their
    /// last positions.
    ///
    /// # Errors
    /// [`RobotError::UnknownJoint`] (code [`ErrorCode::UnknownName`]) for
    /// a name that is no moving joint, before anything is sent; as
    /// [`Client::set_joints`].
    pub fn set_joints_by_name(
        &mut self,
        robot: &mut RobotHandle,
        named: &[(&str, f64)],
    ) -> Result<(), RobotError> {
        let q = robot
            .kinematics
            .positions_by_name(named, &robot.positions)
            .map_err(named_joint_err)?;
        self.set_joints(robot, &q, None)
    }
}
