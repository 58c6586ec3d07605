//! Who holds the objects, a server or the Python process: the trait both
//! `gjkd.Client` and `gjkd.Local` implement, and the pose check every call
//! of either makes before anything changes.
//!
//! The robot and scene calls return the Rust client's [`ClientError`] (a
//! `Local` answers with the error a server's refusal gives the client), so
//! that one mapping (`errors::client`) raises the same exception, with the
//! same `code`, from either class.

use std::path::Path;

use pyo3::prelude::*;

use gjkd_client::{ClientError, LimitMode, PackagePath, RobotHandle, SceneSummary};
use gjkd_proto::{Item, Pose, SceneRequest, SceneRow};
use nalgebra::Isometry3;

use crate::arrays::pose;
use crate::errors;
use crate::runner::{Answerer, Buffers};
use crate::server_lib::check_pose;
use crate::shape::Registration;

/// Who holds the objects: a server (through the Rust client) or the
/// Python process.
pub trait Backend {
    /// The answerer of query items and the buffers kept for it.
    fn parts(&mut self, py: Python<'_>) -> PyResult<(&mut dyn Answerer, &mut Buffers)>;
    /// Registers `what`, returning its id.
    fn register(
        &mut self,
        py: Python<'_>,
        what: &Registration<'_>,
        name: Option<&str>,
        pose: Option<Pose>,
    ) -> PyResult<u64>;
    /// Removes object `id`.
    fn remove(&mut self, py: Python<'_>, id: u64) -> PyResult<()>;
    /// The id of the object named `name`.
    fn lookup(&mut self, py: Python<'_>, name: &str) -> PyResult<u64>;
    /// The stored pose of each of `ids`, or its error code
    /// (`UnknownObject`), in order.
    fn stored_poses(
        &mut self,
        py: Python<'_>,
        ids: &[u64],
    ) -> PyResult<Vec<Result<Pose, gjkd_proto::ErrorCode>>>;
    /// Registers a robot: its link objects, then its kinematics (as
    /// `gjkd_client::Client::register_robot_text`).
    fn register_robot(&mut self, py: Python<'_>, robot: &RobotText<'_>) -> Outcome<RobotHandle>;
    /// The robot named `name` already held, read with its URDF text (as
    /// `gjkd_client::Client::open_robot`).
    fn open_robot(&mut self, py: Python<'_>, name: &str, urdf: &str) -> Outcome<RobotHandle>;
    /// Removes the robot named `name` with every link.
    fn remove_robot(&mut self, py: Python<'_>, name: &str) -> Outcome<()>;
    /// Sets every joint of `robot` and, if given, its base (as
    /// `gjkd_client::Client::set_joints_with`).
    fn set_joints(
        &mut self,
        py: Python<'_>,
        robot: &mut RobotHandle,
        positions: &[f64],
        base: Option<&Isometry3<f64>>,
        mode: LimitMode,
    ) -> Outcome<()>;
    /// Answers the scene question `request` about the `count` items
    /// `item(i)`, its rows handed to `read` (as
    /// `gjkd_client::Client::scene_with`: a path comes back whole, however
    /// long).
    fn scene(
        &mut self,
        py: Python<'_>,
        request: &SceneRequest,
        count: usize,
        item: &mut dyn FnMut(usize) -> Item,
        read: &mut dyn FnMut(&[SceneRow]),
    ) -> Outcome<SceneSummary>;
}

/// A call's outcome: the outer error is the holder's own (a closed
/// client), the inner one the call's.
pub type Outcome<T> = PyResult<Result<T, ClientError>>;

/// A robot description, as `gjkd_client::Client::register_robot_text`
/// takes it.
pub struct RobotText<'a> {
    /// The robot's name: its links are the objects `<name>/<link>`.
    pub name: &'a str,
    /// URDF text.
    pub urdf: &'a str,
    /// SRDF text, for the allowed pairs.
    pub srdf: Option<&'a str>,
    /// The folder relative mesh paths start from (the working folder when
    /// `None`).
    pub mesh_base: Option<&'a Path>,
    /// Where `package://` URLs are searched.
    pub packages: &'a PackagePath,
    /// The base pose.
    pub base: &'a Isometry3<f64>,
}

/// A pose argument, checked as the server will check it, so that a bad one
/// raises before anything is registered or changed.
pub fn checked_pose(
    py: Python<'_>,
    obj: Option<&Bound<'_, PyAny>>,
    field: &str,
) -> PyResult<Option<Pose>> {
    let Some(p) = pose(obj, field)? else {
        return Ok(None);
    };
    check_pose(&p).map_err(|code| errors::refused(py, code, Some(field), None))?;
    Ok(Some(p))
}
