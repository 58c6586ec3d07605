//! Who holds the objects, a server or the Python process: the trait both
//! `gjkd.Client` and `gjkd.Local` implement, and the pose check every call
//! of either makes before anything changes.

use pyo3::prelude::*;

use gjkd_proto::Pose;

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
