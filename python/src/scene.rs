//! Scene queries on `gjkd.Client`: a group of objects against the whole
//! scene in one round trip (`clearance`, `within`, `nearest`, `path`), the
//! rows written into a caller-owned `gjkd.SceneRows`.

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyAnyMethods;

use gjkd_client::{ClientError, Item, ObjectId, SceneRow, Steps};
use gjkd_proto::{PathMode, SceneKind, SceneRequest, scene_flags};

use crate::arrays::{IdArray, Ids, PoseArray, Poses, id_array};
use crate::backend::Backend;
use crate::batch::{Distances, check_gradient_room};
use crate::errors::{self, invalid};
use crate::robots::Robot;

/// Room for the rows of scene answers (`clearance`, `within`,
/// `nearest`, `path`): `SceneRows(n)` holds `n` rows, reused from call to
/// call (nothing is allocated per call). A call writes its rows from the
/// start and returns a `SceneSummary` whose `written` says how many.
///
/// Attributes (numpy arrays of `n` rows; rows past `written` keep what an
/// earlier call left):
///
/// - `a` `(n,)` uint64: the group's object (the object asked about, for
///   `nearest`);
/// - `b` `(n,)` uint64: the other object, 0 when none qualifies;
/// - `step` `(n,)` uint32: the path step (0 when not a path; the segment
///   of a continuous path);
/// - `s_lo`, `s_hi` `(n,)` float64: a continuous path's first-contact
///   bracket in the segment's `s` (0 otherwise);
/// - `answers`: a `gjkd.Distances` of `n` rows with each pair's
///   `distance`, `lower`, `upper`, `point_a` (on `a`), `point_b`,
///   `normal`, `status` (`gjkd.Status`, `BOUNDED` for rows answered from
///   motion bounds), `error`, ...; `distance`, `lower`, `upper`, `status`
///   and `error` are also attributes of the rows themselves.
///
/// Which fields are exact depends on the row's `status`: `lower` and
/// `upper` always bound the true distance. `CONVERGED` (and
/// `ITERATION_CAP`, `TOLERANCE_NOT_MET`, within their bounds): `distance`
/// and the points are the answer. `CLOSER` (a `within` pair proved inside
/// the margin by an early exit) and `BOUNDED` (answered from motion
/// bounds, without GJK): `distance` and the points are an estimate inside
/// `[lower, upper]`, which may be wide. Pass `exact=True` for exact
/// distances on every reported row.
///
/// `SceneRows(n, gradient_columns=c)` with `c > 0` also asks every call
/// for each row's distance gradient (with `gradient_base=True`, a robot's
/// base twist too), written into:
///
/// - `gradient` `(n, c)` float64: row `i` holds `∂d/∂x` with respect to
///   the coordinates that move its `a` (a robot link: the robot's moving
///   joints in `Robot.joint_names` order, then the base twist `[v, ω]`
///   when asked; any other object: its pose's twist), zero beyond the
///   columns in use; for overlapping pairs, the signed distance's
///   (`distance - answers.penetration`). A gradient of more than `c`
///   columns keeps its first `c`: size `c` for the widest row (a robot's
///   `dof`, plus 6 with `gradient_base`; 6 for a free object);
/// - `gradient_flags` `(n,)` uint32: `1` computed, `2` nearest points not
///   unique (a one-sided gradient), `4` base twist included, `8` no
///   direction (zeros);
/// - `gradient_error` `(n,)` float64: a bound on each entry's error from
///   the distance's certified interval.
///
/// These are `answers`' arrays of the same names (`gjkd.Distances(n,
/// gradient_columns=c)` asks pair queries for gradients the same way).
/// `gradient_base=True` without gradient columns raises `InvalidInput`.
///
/// `SceneRows(n, signed_distance=True)` also asks every call for each
/// row's signed distance with its certified interval, in
/// `signed_distance`, `signed_lower`, `signed_upper` (`answers`' arrays):
/// a pair apart carries its distance (the same interval), a pair that
/// overlaps minus its penetration depth, with the depth's witnesses in
/// `answers.point_a`, `point_b`, `normal`. Which rows are reported does not
/// change: every overlapping pair has distance 0, so `within` reports it
/// whatever the margin. A continuous path refuses it (`gjkd.InvalidInput`,
/// code `MALFORMED`).
#[pyclass(module = "gjkd", name = "SceneRows")]
pub struct SceneRows {
    a: Py<PyArray1<u64>>,
    b: Py<PyArray1<u64>>,
    step: Py<PyArray1<u32>>,
    s_lo: Py<PyArray1<f64>>,
    s_hi: Py<PyArray1<f64>>,
    answers: Py<Distances>,
    signed_distance: bool,
    busy: std::sync::atomic::AtomicBool,
}

#[pymethods]
impl SceneRows {
    /// Zeroed room for `n` rows, and for `gradient_columns` gradient
    /// entries per row (0: no gradients asked); `signed_distance` asks
    /// every call for each row's signed distance.
    #[new]
    #[pyo3(signature = (n, gradient_columns = 0, gradient_base = false, signed_distance = false))]
    fn new(
        py: Python<'_>,
        n: usize,
        gradient_columns: usize,
        gradient_base: bool,
        signed_distance: bool,
    ) -> PyResult<Self> {
        check_gradient_room(py, gradient_columns, gradient_base)?;
        Ok(SceneRows {
            a: PyArray1::zeros(py, n, false).unbind(),
            b: PyArray1::zeros(py, n, false).unbind(),
            step: PyArray1::zeros(py, n, false).unbind(),
            s_lo: PyArray1::zeros(py, n, false).unbind(),
            s_hi: PyArray1::zeros(py, n, false).unbind(),
            answers: Py::new(
                py,
                Distances::with_room(py, n, gradient_columns, gradient_base),
            )?,
            signed_distance,
            busy: std::sync::atomic::AtomicBool::new(false),
        })
    }

    /// `(n, gradient_columns)` float64: each row's distance gradient
    /// (`answers.gradient`).
    #[getter]
    fn gradient<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.answers.bind(py).borrow().gradient(py)
    }

    /// `(n,)` uint32: each row's gradient flags (`answers.gradient_flags`).
    #[getter]
    fn gradient_flags<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.answers.bind(py).borrow().gradient_flags(py)
    }

    /// `(n,)` float64: a bound on each row's gradient entries' error
    /// (`answers.gradient_error`).
    #[getter]
    fn gradient_error<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.answers.bind(py).borrow().gradient_error(py)
    }

    fn __len__(&self, py: Python<'_>) -> usize {
        self.rows(py)
    }

    /// `(n,)` uint64: the group's objects.
    #[getter]
    fn a<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        self.a.bind(py).clone()
    }

    /// `(n,)` uint64: the other objects, 0 for none.
    #[getter]
    fn b<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        self.b.bind(py).clone()
    }

    /// `(n,)` uint32: the path steps.
    #[getter]
    fn step<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.step.bind(py).clone()
    }

    /// `(n,)` float64: a continuous path's first contact: every pose of
    /// the segment before this `s` is certified clear.
    #[getter]
    fn s_lo<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.s_lo.bind(py).clone()
    }

    /// `(n,)` float64: a continuous path's first contact: the pose at this
    /// `s` is within the margin (the row's answer is there).
    #[getter]
    fn s_hi<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.s_hi.bind(py).clone()
    }

    /// The pairs' answers, a `gjkd.Distances` of `n` rows.
    #[getter]
    fn answers<'py>(&self, py: Python<'py>) -> Bound<'py, Distances> {
        self.answers.bind(py).clone()
    }

    /// `(n,)` float64: the distances (`answers.distance`).
    #[getter]
    fn distance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.answers.bind(py).getattr("distance")
    }

    /// `(n,)` float64: certified lower bounds (`answers.lower`).
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.answers.bind(py).getattr("lower")
    }

    /// `(n,)` float64: certified upper bounds (`answers.upper`).
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.answers.bind(py).getattr("upper")
    }

    /// `(n,)` float64: the signed distances (`answers.signed_distance`),
    /// NaN in rows without one.
    #[getter]
    fn signed_distance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.answers.bind(py).getattr("signed_distance")
    }

    /// `(n,)` float64: certified lower bounds on the signed distances.
    #[getter]
    fn signed_lower<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.answers.bind(py).getattr("signed_lower")
    }

    /// `(n,)` float64: certified upper bounds on the signed distances.
    #[getter]
    fn signed_upper<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.answers.bind(py).getattr("signed_upper")
    }

    /// `(n,)` uint32: `gjkd.Status` values (`answers.status`).
    #[getter]
    fn status<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.answers.bind(py).getattr("status")
    }

    /// `(n,)` uint32: `gjkd.ErrorCode` values (`answers.error`).
    #[getter]
    fn error<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.answers.bind(py).getattr("error")
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!("<gjkd.SceneRows of {} rows>", self.rows(py))
    }
}

/// What a scene answer held besides its rows.
#[pyclass(frozen, module = "gjkd", name = "SceneSummary")]
#[derive(Clone, Copy)]
pub struct Summary {
    inner: gjkd_client::SceneSummary,
}

#[pymethods]
impl Summary {
    /// Rows written, from the start of the `SceneRows`.
    #[getter]
    fn written(&self) -> usize {
        self.inner.written
    }
    /// Rows that qualified, also those that did not fit.
    #[getter]
    fn total(&self) -> u64 {
        self.inner.total
    }
    /// More rows qualified than the `SceneRows` holds: the rows written
    /// are a prefix of the answer.
    #[getter]
    fn truncated(&self) -> bool {
        self.inner.truncated
    }
    /// Steps answered (1 when not a path).
    #[getter]
    fn steps(&self) -> u32 {
        self.inner.steps
    }
    /// `path(..., question="first_hit")`: the first step with a pair within
    /// the margin, `None` when the whole path is clear.
    #[getter]
    fn first_hit(&self) -> Option<u32> {
        self.inner.first_hit
    }
    /// Pair queries that ran GJK.
    #[getter]
    fn gjk_runs(&self) -> u64 {
        self.inner.gjk_runs
    }
    /// Pairs answered from motion bounds alone.
    #[getter]
    fn bounded(&self) -> u64 {
        self.inner.bounded
    }
    /// Pairs the broadphase could not rule out.
    #[getter]
    fn candidates(&self) -> u64 {
        self.inner.candidates
    }

    fn __repr__(&self) -> String {
        let s = &self.inner;
        format!(
            "SceneSummary(written={}, total={}, truncated={}, steps={}, first_hit={:?})",
            s.written, s.total, s.truncated, s.steps, s.first_hit
        )
    }
}

/// The keyword options every scene call takes.
pub(crate) struct Options {
    pub(crate) tolerance: f64,
    pub(crate) max_iterations: u32,
    pub(crate) warm_start: bool,
    pub(crate) motion_bounds: bool,
    pub(crate) accept_absolute: f64,
    pub(crate) accept_relative: f64,
    /// Exact distances on every reported row.
    pub(crate) exact: bool,
    pub(crate) cutoff: Option<f64>,
    /// Clamp a path's joint positions to their limits.
    pub(crate) clamp: bool,
}

impl Options {
    /// The request of `kind` about `group` (0 for listed members).
    fn request(&self, kind: SceneKind, group: u64) -> SceneRequest {
        let mut r = SceneRequest::new(kind, group);
        r.tolerance = self.tolerance;
        r.max_iterations = self.max_iterations;
        r.accept_absolute = self.accept_absolute;
        r.accept_relative = self.accept_relative;
        r.flags = 0;
        if self.warm_start {
            r.flags |= scene_flags::WARM_START;
        }
        if self.motion_bounds {
            r.flags |= scene_flags::MOTION_BOUNDS;
        }
        if self.exact {
            r.flags |= scene_flags::EXACT;
        }
        if let Some(c) = self.cutoff {
            r.flags |= scene_flags::CUTOFF;
            r.margin = c;
        }
        if self.clamp {
            r.flags |= scene_flags::CLAMP;
        }
        r
    }
}

/// The group argument: an int (a robot or an object) or ids.
enum GroupArg<'py> {
    Id(u64),
    Members(IdArray<'py>),
}

fn group_arg<'py>(obj: &Bound<'py, PyAny>) -> PyResult<GroupArg<'py>> {
    if let Ok(id) = obj.extract::<u64>() {
        return Ok(GroupArg::Id(id));
    }
    if let Ok(robot) = obj.cast::<Robot>() {
        return Ok(GroupArg::Id(robot.borrow().handle.id.raw()));
    }
    let ids = id_array(obj, "group")?;
    if ids.shape().len() != 1 {
        return Err(invalid(
            obj.py(),
            "group",
            None,
            format!(
                "group must be an id or a 1-D array of ids, got shape {:?}",
                ids.shape()
            ),
        ));
    }
    Ok(GroupArg::Members(ids))
}

/// The pairs argument `(K, 2)`, or none.
fn allow_arg<'py>(obj: Option<&Bound<'py, PyAny>>) -> PyResult<Option<IdArray<'py>>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let ids = id_array(obj, "allow")?;
    if !matches!(ids.shape(), [_, 2]) {
        return Err(invalid(
            obj.py(),
            "allow",
            None,
            format!("allow must have shape (K, 2), got {:?}", ids.shape()),
        ));
    }
    Ok(Some(ids))
}

/// The items of a scene request, readable without the GIL.
#[derive(Clone, Copy)]
struct Inputs<'a> {
    members: Option<Ids<'a>>,
    allowed: Option<Ids<'a>>,
    moving: Option<Ids<'a>>,
    poses: Option<Poses<'a>>,
    /// A path of joint positions, instead of `moving` and `poses`.
    joints: Option<Steps<'a>>,
}

impl Inputs<'_> {
    fn counts(&self) -> (usize, usize, usize, usize) {
        let members = self.members.map_or(0, |m| m.len());
        let allowed = self.allowed.map_or(0, |a| a.len() / 2);
        let moving = self.moving.map_or(0, |m| m.len());
        let poses = self.poses.map_or(0, |p| p.len());
        (members, allowed, moving, poses)
    }

    /// Number of items.
    fn len(&self) -> usize {
        let (m, a, n, p) = self.counts();
        if let Some(j) = self.joints {
            return m + a + j.count().unwrap_or(0) * j.items_per_step();
        }
        let steps = p.checked_div(n).unwrap_or(0);
        m + a + steps * n
    }

    fn item(&self, i: usize) -> Item {
        let (m, a, n, _) = self.counts();
        if i < m {
            let members = self.members.expect("counted");
            return Item::member(ObjectId::from_raw(members.get(i)));
        }
        let i = i - m;
        if i < a {
            let allowed = self.allowed.expect("counted");
            return Item::allow(
                ObjectId::from_raw(allowed.get(2 * i)),
                ObjectId::from_raw(allowed.get(2 * i + 1)),
            );
        }
        let i = i - a;
        if let Some(j) = self.joints {
            let per = j.items_per_step();
            return j.item(i / per, i % per);
        }
        // Each step is its poses, the last flagged to end it.
        let (s, k) = (i / n.max(1), i % n.max(1));
        match (self.moving, self.poses) {
            (Some(moving), Some(poses)) if k < n => {
                let id = moving.get(k);
                let item = Item {
                    a: id,
                    pose_a: poses.get(s * n + k),
                    ..Item::set_pose(ObjectId::from_raw(id), &Default::default())
                };
                if k + 1 == n { item.ending_step() } else { item }
            }
            _ => Item::step(),
        }
    }
}

impl SceneRows {
    /// The request flags this room asks for.
    fn gradient_request_flags(&self, py: Python<'_>) -> u32 {
        let signed = if self.signed_distance {
            scene_flags::SIGNED_DISTANCE
        } else {
            0
        };
        signed
            | match self.answers.bind(py).borrow().gradient_request() {
                None => 0,
                Some(false) => scene_flags::GRADIENTS,
                Some(true) => scene_flags::GRADIENTS | scene_flags::GRADIENT_BASE,
            }
    }

    /// Number of rows (the answers' arrays are as long as the others).
    fn rows(&self, py: Python<'_>) -> usize {
        self.answers.bind(py).borrow().len()
    }

    /// Runs `call` with the arrays' storage to write rows into.
    fn with_rows<R>(
        &self,
        py: Python<'_>,
        call: impl FnOnce(&mut dyn FnMut(&[SceneRow])) -> PyResult<R>,
    ) -> PyResult<R> {
        use std::sync::atomic::Ordering;
        if self.busy.swap(true, Ordering::Acquire) {
            return Err(invalid(
                py,
                "out",
                None,
                "out is being written by another call".into(),
            ));
        }
        let (a, b, step) = (self.a.bind(py), self.b.bind(py), self.step.bind(py));
        let (s_lo, s_hi) = (self.s_lo.bind(py), self.s_hi.bind(py));
        let answers = self.answers.bind(py).borrow();
        let result = (|| {
            // SAFETY: created contiguous by `SceneRows::new`, owned by their
            // arrays, lent once per call (`busy` keeps two calls apart), as
            // `Distances` does with its own.
            let (a, b, step) =
                unsafe { (a.as_slice_mut()?, b.as_slice_mut()?, step.as_slice_mut()?) };
            // SAFETY: as above.
            let (s_lo, s_hi) = unsafe { (s_lo.as_slice_mut()?, s_hi.as_slice_mut()?) };
            answers.with_writer(py, |mut writer| {
                let mut write = |rows: &[SceneRow]| {
                    for (i, row) in rows.iter().enumerate() {
                        a[i] = row.a;
                        b[i] = row.b;
                        step[i] = row.step;
                        s_lo[i] = row.s_lo;
                        s_hi[i] = row.s_hi;
                        writer.write(i, std::slice::from_ref(&row.result));
                        writer.write_gradients(i, std::slice::from_ref(&row.gradient));
                    }
                };
                call(&mut write)
            })
        })();
        self.busy.store(false, Ordering::Release);
        result
    }
}

/// Sends `request` with `inputs` from `client`, rows into `out`.
fn run(
    py: Python<'_>,
    client: &mut dyn Backend,
    mut request: SceneRequest,
    inputs: Inputs<'_>,
    out: &Bound<'_, SceneRows>,
) -> PyResult<Summary> {
    let rows = out.borrow();
    request.max_rows = u32::try_from(rows.rows(py)).unwrap_or(u32::MAX);
    request.flags |= rows.gradient_request_flags(py);
    let count = inputs.len();
    let outcome = rows.with_rows(py, |write| {
        client.scene(py, &request, count, &mut |i| inputs.item(i), write)
    })?;
    outcome
        .map(|inner| Summary { inner })
        .map_err(|e: ClientError| errors::client(py, e, None))
}

/// The scene question and path mode of a path's `question` argument.
pub(crate) fn path_question(py: Python<'_>, question: &str) -> PyResult<(SceneKind, PathMode)> {
    match question {
        "clearance" => Ok((SceneKind::Clearance, PathMode::EveryStep)),
        "within" => Ok((SceneKind::Within, PathMode::EveryStep)),
        "first_hit" => Ok((SceneKind::Within, PathMode::FirstHit)),
        "continuous" => Ok((SceneKind::Within, PathMode::Continuous)),
        other => Err(invalid(
            py,
            "question",
            None,
            format!(
                "question must be 'clearance', 'within', 'first_hit' or 'continuous', not {other:?}"
            ),
        )),
    }
}

/// The motion of a path question, if any.
pub(crate) enum PathArg<'a, 'py> {
    /// Not a path.
    None,
    /// Poses of the moving objects, step after step.
    Poses(PathMode, IdArray<'py>, PoseArray<'py>),
    /// A robot's joint positions, step after step, checked.
    Joints(PathMode, Steps<'a>),
}

/// Reads the group and allowed pairs, then runs.
#[allow(clippy::too_many_arguments)]
pub(crate) fn ask<'py>(
    py: Python<'py>,
    client: &mut dyn Backend,
    kind: SceneKind,
    group: &Bound<'py, PyAny>,
    allow: Option<&Bound<'py, PyAny>>,
    path: PathArg<'_, 'py>,
    options: &Options,
    edit: impl FnOnce(&mut SceneRequest),
    out: &Bound<'py, SceneRows>,
) -> PyResult<Summary> {
    let group = group_arg(group)?;
    let allow = allow_arg(allow)?;
    let (id, members) = match &group {
        GroupArg::Id(id) => (*id, None),
        GroupArg::Members(m) => (0, Some(m.slice()?)),
    };
    let mut request = options.request(kind, id);
    edit(&mut request);
    let mut joints = None;
    let (moving, poses) = match &path {
        PathArg::Poses(mode, moving, poses) => {
            request.path = *mode as u32;
            let (moving, poses) = (moving.slice()?, poses.poses()?);
            if moving.len() == 0 || poses.len() == 0 || poses.len() % moving.len() != 0 {
                return Err(invalid(
                    py,
                    "poses",
                    None,
                    format!(
                        "poses holds {} poses, not a whole number of steps of {} objects",
                        poses.len(),
                        moving.len()
                    ),
                ));
            }
            (Some(moving), Some(poses))
        }
        PathArg::Joints(mode, steps) => {
            request.path = *mode as u32;
            joints = Some(*steps);
            (None, None)
        }
        PathArg::None => (None, None),
    };
    let inputs = Inputs {
        members,
        allowed: allow.as_ref().map(|a| a.slice()).transpose()?,
        moving,
        poses,
        joints,
    };
    run(py, client, request, inputs, out)
}
