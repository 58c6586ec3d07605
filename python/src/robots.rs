//! `gjkd.Robot`: a robot registered from URDF on a server or in a
//! `gjkd.Local`, its links and joints, and the calls that register, find
//! and move robots, written once over a [`Backend`] (the methods of both
//! classes, `robot_api.rs`, forward here).

use std::path::{Path, PathBuf};

use numpy::{PyArray1, PyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use gjkd_client::{ErrorCode, JointError, LimitMode, PackagePath, RobotHandle, Steps};
use nalgebra::Isometry3;

use crate::arrays::{f64_array, slice};
use crate::backend::{Backend, RobotText, checked_pose};
use crate::errors::{self, Kind, Raise, invalid};
use crate::shape::isometry;

/// A robot on a gjkd server or in a `gjkd.Local`, registered from URDF by
/// `register_robot` (or found by `open_robot`) of either.
///
/// Each link with collision geometry is an object of its own, named
/// `<robot>/<link>`: `link(name)` gives its id, to query like any other
/// object (`client.distance(robot.link("hand"), table)`). Move the robot
/// with `set_joints` of the `Client` or `Local` that holds it: one round
/// trip sets every joint (and optionally the base pose), and the server
/// (or `Local`) places every link by forward kinematics.
#[pyclass(unsendable, module = "gjkd", name = "Robot")]
pub struct Robot {
    pub(crate) handle: RobotHandle,
    /// The base pose last sent (identity at first).
    base: Isometry3<f64>,
}

impl Robot {
    fn new(handle: RobotHandle, base: Isometry3<f64>) -> Self {
        Robot { handle, base }
    }
}

/// An isometry as a `[x, y, z, qx, qy, qz, qw]` row.
fn row(p: &Isometry3<f64>) -> [f64; 7] {
    let t = p.translation.vector;
    let q = p.rotation.coords;
    [t.x, t.y, t.z, q.x, q.y, q.z, q.w]
}

#[pymethods]
impl Robot {
    /// The robot's id on the server: the group id of scene questions about
    /// it, no object id (its links are the objects).
    #[getter]
    fn id(&self) -> u64 {
        self.handle.id.raw()
    }

    /// The name it was registered under.
    #[getter]
    fn name(&self) -> &str {
        &self.handle.name
    }

    /// Every link's name, in the URDF's order (the rows of `link_ids` and
    /// `link_poses`).
    #[getter]
    fn link_names(&self) -> Vec<String> {
        self.handle.link_names().to_vec()
    }

    /// The moving joints' names (fixed and mimic joints take no position),
    /// in the order of a position array.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.handle
            .joint_names()
            .into_iter()
            .map(str::to_owned)
            .collect()
    }

    /// Number of moving joints.
    #[getter]
    fn dof(&self) -> usize {
        self.handle.positions.len()
    }

    /// `(L,)` uint64: each link's object id, in `link_names` order, 0 for
    /// a link without collision geometry.
    #[getter]
    fn link_ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        let ids: Vec<u64> = self
            .handle
            .links
            .iter()
            .map(|l| l.map_or(0, |id| id.raw()))
            .collect();
        PyArray1::from_vec(py, ids)
    }

    /// `(dof,)` float64: the joint positions last set (zero within the
    /// limits at first; clamped ones after `set_joints(..., clamp=True)`).
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.handle.positions)
    }

    /// `(dof,)` float64 lower limits of the moving joints (`-inf` for a
    /// continuous joint).
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .handle
            .kinematics
            .moving_joints()
            .map(|j| j.lower)
            .collect();
        PyArray1::from_vec(py, v)
    }

    /// `(dof,)` float64 upper limits of the moving joints (`inf` for a
    /// continuous joint).
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .handle
            .kinematics
            .moving_joints()
            .map(|j| j.upper)
            .collect();
        PyArray1::from_vec(py, v)
    }

    /// The object id of link `name`, or `None` for a link without
    /// collision geometry. Raises `NotFound` (`field="name"`) when the
    /// robot has no link of that name.
    fn link(&self, py: Python<'_>, name: &str) -> PyResult<Option<u64>> {
        if !self.handle.link_names().iter().any(|l| l == name) {
            return Err(not_found(py, "name", format!("robot has no link `{name}`")));
        }
        Ok(self.handle.link(name).map(|id| id.raw()))
    }

    /// `(L, 7)` float64 `[x, y, z, qx, qy, qz, qw]`: every link's pose (in
    /// `link_names` order) by forward kinematics, computed here as the
    /// server computes it, for `positions` (default: the last set) and
    /// `base` (default: the last sent, identity at first). Positions are
    /// checked as by `set_joints` (`clamp` as there).
    #[pyo3(signature = (positions = None, base = None, *, clamp = false))]
    fn link_poses<'py>(
        &self,
        py: Python<'py>,
        positions: Option<&Bound<'py, PyAny>>,
        base: Option<&Bound<'py, PyAny>>,
        clamp: bool,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let q = match positions.filter(|p| !p.is_none()) {
            Some(p) => self.positions_of(py, p)?,
            None => self.handle.positions.clone(),
        };
        let base = match checked_pose(py, base, "base")? {
            Some(p) => isometry(&p),
            None => self.base,
        };
        let mode = if clamp {
            LimitMode::Clamp
        } else {
            LimitMode::Reject
        };
        let poses = self
            .handle
            .kinematics
            .link_poses(&base, &q, mode)
            .map_err(|e| joint_error(py, &self.handle, e))?;
        let rows: Vec<Vec<f64>> = poses.iter().map(|p| row(p).to_vec()).collect();
        Ok(PyArray2::from_vec2(py, &rows)?)
    }

    /// `{joint name: (lower, upper)}` of the moving joints.
    fn limits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for j in self.handle.kinematics.moving_joints() {
            d.set_item(&j.name, (j.lower, j.upper))?;
        }
        Ok(d)
    }

    fn __len__(&self) -> usize {
        self.handle.link_names().len()
    }

    fn __repr__(&self) -> String {
        format!(
            "gjkd.Robot(name={:?}, id={}, links={}, dof={})",
            self.handle.name,
            self.handle.id.raw(),
            self.handle.link_names().len(),
            self.handle.positions.len()
        )
    }
}

impl Robot {
    /// A full position array from `(dof,)` floats or a `{name: value}`
    /// dict (joints not named keep their last positions).
    fn positions_of(&self, py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        if let Ok(d) = obj.cast::<PyDict>() {
            let mut named = Vec::with_capacity(d.len());
            for (k, v) in d.iter() {
                let name: String = k.extract().map_err(|_| {
                    invalid(py, "positions", None, "joint names must be str".into())
                })?;
                let value: f64 = v.extract().map_err(|_| {
                    invalid(
                        py,
                        "positions",
                        None,
                        format!("joint `{name}`: not a float"),
                    )
                })?;
                named.push((name, value));
            }
            let named: Vec<(&str, f64)> = named.iter().map(|(n, v)| (n.as_str(), *v)).collect();
            return self
                .handle
                .kinematics
                .positions_by_name(&named, &self.handle.positions)
                .map_err(|e| joint_error(py, &self.handle, e));
        }
        let a = f64_array(obj, "positions")?;
        let dof = self.handle.positions.len();
        if a.shape() != [dof] {
            return Err(invalid(
                py,
                "positions",
                None,
                format!(
                    "positions must have shape ({dof},) (one per moving joint), got {:?}",
                    a.shape()
                ),
            ));
        }
        Ok(slice(&a)?.to_vec())
    }
}

/// The steps of a path of `robot`'s joint positions, `dof` per step, each
/// checked as the server would (finite; within limits unless `clamp`), so
/// that a refusal names its step (`index`) and joint before anything is
/// sent.
pub fn path_steps<'a>(
    py: Python<'_>,
    robot: &Robot,
    positions: &'a [f64],
    clamp: bool,
) -> PyResult<Steps<'a>> {
    let dof = robot.handle.positions.len();
    if dof == 0 {
        return Err(invalid(
            py,
            "robot",
            None,
            "the robot has no moving joint".into(),
        ));
    }
    let mode = if clamp {
        LimitMode::Clamp
    } else {
        LimitMode::Reject
    };
    let mut checked = vec![0.0; dof];
    for (step, q) in positions.chunks_exact(dof).enumerate() {
        checked.copy_from_slice(q);
        if let Err(e) = robot.handle.kinematics.check_positions(&mut checked, mode) {
            let code = match e {
                JointError::OutOfLimits { .. } => Some(ErrorCode::OutOfLimits),
                JointError::NotFinite(_) => Some(ErrorCode::NonFinitePose),
                _ => None,
            };
            return Err(Raise {
                kind: Kind::InvalidInput,
                message: format!("positions of step {step}: {e}"),
                code,
                field: Some("positions"),
                index: Some(step),
            }
            .into_err(py));
        }
    }
    Ok(Steps::joints(&robot.handle, positions))
}

/// `gjkd.NotFound` about `field`, without a server code.
fn not_found(py: Python<'_>, field: &str, message: String) -> PyErr {
    Raise {
        kind: Kind::NotFound,
        message,
        code: None,
        field: Some(field),
        index: None,
    }
    .into_err(py)
}

/// The exception of a joint request refused before it was sent, with the
/// server's code where it has one and the joint's index.
fn joint_error(py: Python<'_>, handle: &RobotHandle, e: JointError) -> PyErr {
    let index_of = |joint: &str| handle.joint_names().iter().position(|n| *n == joint);
    let (kind, code, index) = match &e {
        // The code a name that names nothing carries everywhere.
        JointError::UnknownJoint(_) => (Kind::NotFound, Some(ErrorCode::UnknownName), None),
        JointError::NotFinite(j) => (
            Kind::InvalidInput,
            Some(ErrorCode::NonFinitePose),
            index_of(j),
        ),
        JointError::OutOfLimits { joint, .. } => (
            Kind::InvalidInput,
            Some(ErrorCode::OutOfLimits),
            index_of(joint),
        ),
        JointError::BadBase => {
            return errors::refused(py, ErrorCode::NonFinitePose, Some("base"), None);
        }
        JointError::WrongCount { .. } => (Kind::InvalidInput, None, None),
    };
    Raise {
        kind,
        message: e.to_string(),
        code,
        field: Some("positions"),
        index,
    }
    .into_err(py)
}

/// What `Client.register_robot` reads.
pub struct RobotSource {
    /// URDF: a file, or text.
    pub urdf: Text,
    /// SRDF: a file, or text, or none.
    pub srdf: Option<Text>,
    /// `package://` search folders (the environment's after them).
    pub package_path: Vec<PathBuf>,
}

/// A description given as a file or as text.
pub enum Text {
    /// A file to read.
    File(PathBuf),
    /// The text itself.
    Inline(String),
}

impl Text {
    fn read(&self, py: Python<'_>, field: &str) -> PyResult<String> {
        match self {
            Text::Inline(s) => Ok(s.clone()),
            Text::File(p) => std::fs::read_to_string(p)
                .map_err(|e| invalid(py, field, None, format!("{}: {e}", p.display()))),
        }
    }
}

/// Registers a robot on `client` (GIL released while its meshes load and
/// its links register).
pub fn register_robot(
    client: &mut dyn Backend,
    py: Python<'_>,
    name: &str,
    source: &RobotSource,
    base: Option<&Bound<'_, PyAny>>,
) -> PyResult<Robot> {
    let base = checked_pose(py, base, "base")?.map_or_else(Isometry3::identity, |p| isometry(&p));
    let urdf = source.urdf.read(py, "urdf")?;
    let srdf = source
        .srdf
        .as_ref()
        .map(|s| s.read(py, "srdf"))
        .transpose()?;
    let mesh_base: Option<PathBuf> = match &source.urdf {
        Text::File(p) => p.parent().map(Path::to_path_buf),
        Text::Inline(_) => None,
    };
    let packages = PackagePath::with_env(source.package_path.clone());
    let text = RobotText {
        name,
        urdf: &urdf,
        srdf: srdf.as_deref(),
        mesh_base: mesh_base.as_deref(),
        packages: &packages,
        base: &base,
    };
    let handle = client
        .register_robot(py, &text)?
        // A robot the client cannot read carries the code the server gives
        // a robot it cannot attach (docs/errors.md): `ClientError::code`.
        .map_err(|e| errors::client(py, e, Some("urdf")))?;
    Ok(Robot::new(handle, base))
}

/// Finds a robot on the server by name, given its URDF text.
pub fn open_robot(
    client: &mut dyn Backend,
    py: Python<'_>,
    name: &str,
    urdf: &str,
) -> PyResult<Robot> {
    let handle = client.open_robot(py, name, urdf)?.map_err(|e| {
        let field = match e {
            gjkd_client::ClientError::InvalidRobot(_) => "urdf",
            _ => "name",
        };
        errors::client(py, e, Some(field))
    })?;
    Ok(Robot::new(handle, Isometry3::identity()))
}

/// Sets `robot`'s joints (and base) in one round trip.
pub fn set_joints(
    client: &mut dyn Backend,
    py: Python<'_>,
    robot: &mut Robot,
    positions: &Bound<'_, PyAny>,
    base: Option<&Bound<'_, PyAny>>,
    clamp: bool,
) -> PyResult<()> {
    // No positions for a robot without moving joints: only its base moves.
    let q = robot.positions_of(py, positions)?;
    let base = checked_pose(py, base, "base")?.map(|p| isometry(&p));
    let mode = if clamp {
        LimitMode::Clamp
    } else {
        LimitMode::Reject
    };
    // Checked here too, so that a refusal names its joint.
    let mut checked = q.clone();
    robot
        .handle
        .kinematics
        .check_positions(&mut checked, mode)
        .map_err(|e| joint_error(py, &robot.handle, e))?;
    let handle = &mut robot.handle;
    let outcome = client.set_joints(py, handle, &q, base.as_ref(), mode)?;
    outcome.map_err(|e| match e {
        gjkd_client::ClientError::Rejected(ErrorCode::UnknownObject) => {
            errors::refused(py, ErrorCode::UnknownObject, Some("robot"), None)
        }
        e => errors::client(py, e, Some("positions")),
    })?;
    if let Some(b) = base {
        robot.base = b;
    }
    Ok(())
}
