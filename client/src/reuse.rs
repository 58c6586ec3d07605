//! Objects and robots found again by name, and robots removed whole: what
//! a node restarted under the same names needs, since objects outlive the
//! client that registered them (and, with persistence, the server).

#[cfg(feature = "robots")]
use std::path::Path;

use gjkd_proto::{AdminOp, AdminRequest, Geometry, ObjectId, lookup_kind};
use nalgebra::Isometry3;

#[cfg(feature = "robots")]
use crate::robots::{PackagePath, RobotHandle};
use crate::{Client, LookupError, RegisterError, RobotError, op_error};

impl Client {
    /// The object named `name`: registered as [`Client::register_named`]
    /// would, or, when an object of that name exists already (registered
    /// before by this program's previous run, or by anyone), that object's
    /// id, as it is: its shape is not compared and its pose not changed.
    /// So a node restarted under the same names gets its objects back
    /// instead of [`RegisterError::NameTaken`]. (An object found so keeps
    /// its owner: only the client that registered it may remove it.)
    ///
    /// # Errors
    /// As [`Client::register_named`], without [`RegisterError::NameTaken`].
    pub fn register_named_or_get(
        &mut self,
        name: &str,
        geometry: &Geometry<'_>,
        pose: &Isometry3<f64>,
    ) -> Result<ObjectId, RegisterError> {
        loop {
            match self.register_named(name, geometry, pose) {
                Err(RegisterError::NameTaken) => {}
                other => return other,
            }
            match self.lookup(name) {
                Ok(id) => return Ok(id),
                // Removed between the two calls: register again.
                Err(LookupError::UnknownName) => {}
                // The name fitted the registration, so only the server
                // can fail here.
                Err(LookupError::NameTooLong) => return Err(RegisterError::NameTooLong),
                Err(LookupError::Internal) => return Err(RegisterError::Internal),
                Err(LookupError::Connection(e)) => return Err(e.into()),
            }
        }
    }

    /// The robot named `name`: the one on the server if there is one
    /// ([`Client::open_robot`]); else its link objects, if they are there
    /// (a server restarted since, which keeps objects but not robots),
    /// with the robot attached to them again ([`Client::attach_robot`]);
    /// else registered from `urdf` as [`Client::register_robot_text`]
    /// does. So a node restarted under the same name gets its robot back
    /// instead of a link's [`RegisterError::NameTaken`]. A robot found is
    /// not moved; one attached or registered is put at `base`.
    ///
    /// # Errors
    /// As [`Client::register_robot_text`], without a link's
    /// [`RegisterError::NameTaken`] ([`RobotError::Link`]).
    #[cfg(feature = "robots")]
    pub fn register_robot_text_or_get(
        &mut self,
        name: &str,
        urdf: &str,
        srdf: Option<&str>,
        mesh_base: Option<&Path>,
        packages: &PackagePath,
        base: &Isometry3<f64>,
    ) -> Result<RobotHandle, RobotError> {
        match self.open_robot(name, urdf) {
            Err(RobotError::UnknownRobot) => {}
            other => return other,
        }
        match self.register_robot_text(name, urdf, srdf, mesh_base, packages, base) {
            Err(RobotError::Link(RegisterError::NameTaken)) => {
                self.attach_robot(name, urdf, srdf, base)
            }
            other => other,
        }
    }

    /// Removes the robot named `name` as a whole: its kinematics and every
    /// link object, in one step on the server (all or nothing). Removing
    /// one link with [`Client::remove`] would leave a robot with a hole.
    ///
    /// # Errors
    /// [`RobotError::UnknownRobot`] (no robot of that name: never
    /// registered, removed, or a server restarted since, which keeps the
    /// link objects but not the robot: attach it again first),
    /// [`RobotError::NotOwner`] (another client's robot or link),
    /// [`RobotError::ReadOnly`] (a robot of the server's scene file),
    /// [`RobotError::StorageFull`]; [`RobotError::NameTooLong`] for a name
    /// over [`MAX_NAME_LEN`](crate::MAX_NAME_LEN) bytes; the connection
    /// faults.
    pub fn remove_robot(&mut self, name: &str) -> Result<(), RobotError> {
        let mut request = AdminRequest::new(AdminOp::RemoveRobot);
        if !request.set_name(name) {
            return Err(RobotError::NameTooLong);
        }
        self.admin(&request, &[]).map_err(op_error::<RobotError>)?;
        self.ending.removed_robot(name);
        Ok(())
    }

    /// The id of the robot named `name` on the server (one the scene file
    /// loaded, or a client attached): the group id of scene questions
    /// about it ([`Group::Robot`](crate::Group::Robot)) and the robot of
    /// [`Item::set_joints`](crate::Item::set_joints). Needs no URDF, so it
    /// works without the `robots` feature; `Client::open_robot` (with the
    /// feature) gives a handle that also knows the joints and links.
    ///
    /// # Errors
    /// [`LookupError::UnknownName`] (no robot of that name);
    /// [`LookupError::NameTooLong`] for a name over
    /// [`MAX_NAME_LEN`](crate::MAX_NAME_LEN) bytes; the connection faults.
    pub fn robot_id(&mut self, name: &str) -> Result<ObjectId, LookupError> {
        let mut request = AdminRequest::new(AdminOp::Lookup);
        if !request.set_name(name) {
            return Err(LookupError::NameTooLong);
        }
        // A look-up of a robot, not of an object.
        request.lookup = lookup_kind::ROBOT;
        self.admin(&request, &[])
            .map(|r| ObjectId::from_raw(r.id))
            .map_err(op_error)
    }
}
