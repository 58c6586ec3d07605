//! The scene questions `gjkd.Client` and `gjkd.Local` share: the macro
//! that gives both classes the same `clearance`, `within`, `nearest`,
//! `path` and `path_joints`, written once over a
//! [`Backend`](crate::backend::Backend) (the work is in `scene.rs`).

/// The scene methods of `$class`, in a `#[pymethods]` block of their own.
macro_rules! scene_methods {
    ($class:ident) => {
        #[pymethods]
        impl $class {
            /// For each member of `group`, the nearest object outside the group:
            /// one row per member into `out` (a `gjkd.SceneRows`); returns a
            /// `gjkd.SceneSummary`.
            ///
            /// `group` is a robot id (its links, with its allowed pairs), an object
            /// id, or a 1-D array of object ids. `allow`: `(K, 2)` ids of pairs
            /// never to report. `cutoff`: ignore objects farther than this (a
            /// member with nothing that near may get `b == 0`). `warm_start`,
            /// `motion_bounds`, `accept_absolute`, `accept_relative`: see the
            /// README's "Scene queries"; `exact=True` runs every reported row to
            /// convergence (no `BOUNDED` or `CLOSER` row: `distance` exact for
            /// all). Raises `InvalidInput` (`UNKNOWN_OBJECT`,
            /// `INVALID_OPTIONS`, `MALFORMED`, ...) when the store (server or `Local`) refuses the
            /// whole request; nothing changes then.
            #[pyo3(signature = (group, *, out, allow=None, cutoff=None, tolerance=gjkd_proto::DEFAULT_TOLERANCE, max_iterations=gjkd_proto::DEFAULT_MAX_ITERATIONS, warm_start=true, motion_bounds=true, accept_absolute=0.0, accept_relative=0.0, exact=false))]
            #[allow(clippy::too_many_arguments)]
            fn clearance<'py>(
                &mut self,
                py: Python<'py>,
                group: &Bound<'py, PyAny>,
                out: &Bound<'py, crate::scene::SceneRows>,
                allow: Option<&Bound<'py, PyAny>>,
                cutoff: Option<f64>,
                tolerance: f64,
                max_iterations: u32,
                warm_start: bool,
                motion_bounds: bool,
                accept_absolute: f64,
                accept_relative: f64,
                exact: bool,
            ) -> PyResult<crate::scene::Summary> {
                let options = crate::scene::Options {
                    tolerance,
                    max_iterations,
                    warm_start,
                    motion_bounds,
                    accept_absolute,
                    accept_relative,
                    exact,
                    cutoff,
                    clamp: false,
                };
                crate::scene::ask(
                    py,
                    self,
                    gjkd_proto::SceneKind::Clearance,
                    group,
                    allow,
                    crate::scene::PathArg::None,
                    &options,
                    |_| {},
                    out,
                )
            }

            /// Every pair, `group` against the rest (or all against all with
            /// `all_pairs=True`), whose distance is at most `margin`, into `out`.
            /// With `self_pairs=True`, also the group's members against each other
            /// but the allowed pairs (a robot's self-collisions: not its adjacent
            /// links nor the SRDF's disabled pairs). Other arguments as `clearance`.
            #[pyo3(signature = (group, margin, *, out, all_pairs=false, self_pairs=false, allow=None, tolerance=gjkd_proto::DEFAULT_TOLERANCE, max_iterations=gjkd_proto::DEFAULT_MAX_ITERATIONS, warm_start=true, motion_bounds=true, accept_absolute=0.0, accept_relative=0.0, exact=false))]
            #[allow(clippy::too_many_arguments)]
            fn within<'py>(
                &mut self,
                py: Python<'py>,
                group: &Bound<'py, PyAny>,
                margin: f64,
                out: &Bound<'py, crate::scene::SceneRows>,
                all_pairs: bool,
                self_pairs: bool,
                allow: Option<&Bound<'py, PyAny>>,
                tolerance: f64,
                max_iterations: u32,
                warm_start: bool,
                motion_bounds: bool,
                accept_absolute: f64,
                accept_relative: f64,
                exact: bool,
            ) -> PyResult<crate::scene::Summary> {
                let options = crate::scene::Options {
                    tolerance,
                    max_iterations,
                    warm_start,
                    motion_bounds,
                    accept_absolute,
                    accept_relative,
                    exact,
                    cutoff: None,
                    clamp: false,
                };
                let edit = |r: &mut gjkd_proto::SceneRequest| {
                    r.margin = margin;
                    if all_pairs {
                        r.flags |= gjkd_proto::scene_flags::ALL_PAIRS;
                    }
                    if self_pairs {
                        r.flags |= gjkd_proto::scene_flags::SELF_PAIRS;
                    }
                };
                crate::scene::ask(
                    py,
                    self,
                    gjkd_proto::SceneKind::Within,
                    group,
                    allow,
                    crate::scene::PathArg::None,
                    &options,
                    edit,
                    out,
                )
            }

            /// The `k` objects nearest to `object`, nearest first, into `out`.
            /// Other arguments as `clearance`.
            #[pyo3(signature = (object, k, *, out, allow=None, cutoff=None, tolerance=gjkd_proto::DEFAULT_TOLERANCE, max_iterations=gjkd_proto::DEFAULT_MAX_ITERATIONS, warm_start=true, motion_bounds=true, accept_absolute=0.0, accept_relative=0.0, exact=false))]
            #[allow(clippy::too_many_arguments)]
            fn nearest<'py>(
                &mut self,
                py: Python<'py>,
                object: &Bound<'py, PyAny>,
                k: u32,
                out: &Bound<'py, crate::scene::SceneRows>,
                allow: Option<&Bound<'py, PyAny>>,
                cutoff: Option<f64>,
                tolerance: f64,
                max_iterations: u32,
                warm_start: bool,
                motion_bounds: bool,
                accept_absolute: f64,
                accept_relative: f64,
                exact: bool,
            ) -> PyResult<crate::scene::Summary> {
                if object.extract::<u64>().is_err() {
                    return Err(crate::errors::invalid(py, "object", None, "object must be an id".into()));
                }
                let options = crate::scene::Options {
                    tolerance,
                    max_iterations,
                    warm_start,
                    motion_bounds,
                    accept_absolute,
                    accept_relative,
                    exact,
                    cutoff,
                    clamp: false,
                };
                let edit = |r: &mut gjkd_proto::SceneRequest| r.k = k;
                crate::scene::ask(
                    py,
                    self,
                    gjkd_proto::SceneKind::Nearest,
                    object,
                    allow,
                    crate::scene::PathArg::None,
                    &options,
                    edit,
                    out,
                )
            }

            /// A question asked at every step of a candidate motion, nothing moved
            /// in the store: `poses` holds `S * len(objects)` poses (`(S*n, 7)`
            /// rows or `(S*n, 4, 4)` matrices), row `s * n + i` the pose of
            /// `objects[i]` at step `s`. `question` is `"clearance"` (each member's
            /// clearance at every step), `"within"` (the pairs within `margin` at
            /// every step) or `"first_hit"` (only the first step with a pair within
            /// `margin`, its index in the summary's `first_hit`) or `"continuous"`
            /// (every pose of the motion between consecutive steps, not samples:
            /// translations linear, rotations along the shortest arc, or with
            /// `linear_quaternions` the quaternions' components linear as the GJK
            /// paper's Section 8; a row per segment that comes within `margin`, its
            /// first contact bracketed in `[out.s_lo, out.s_hi]` at most `bracket`
            /// wide, everything before `s_lo` certified clear; no row for a segment
            /// certified clear; `out.step` is the segment). Rows carry their step in
            /// `out.step`. `self_pairs` as `within` (a clearance row's nearest
            /// object may then be another member). Other arguments as `clearance`.
            #[pyo3(signature = (group, objects, poses, *, out, question="clearance", margin=0.0, self_pairs=false, bracket=gjkd_proto::DEFAULT_BRACKET, linear_quaternions=false, allow=None, cutoff=None, tolerance=gjkd_proto::DEFAULT_TOLERANCE, max_iterations=gjkd_proto::DEFAULT_MAX_ITERATIONS, warm_start=true, motion_bounds=true, accept_absolute=0.0, accept_relative=0.0, exact=false))]
            #[allow(clippy::too_many_arguments)]
            fn path<'py>(
                &mut self,
                py: Python<'py>,
                group: &Bound<'py, PyAny>,
                objects: &Bound<'py, PyAny>,
                poses: &Bound<'py, PyAny>,
                out: &Bound<'py, crate::scene::SceneRows>,
                question: &str,
                margin: f64,
                self_pairs: bool,
                bracket: f64,
                linear_quaternions: bool,
                allow: Option<&Bound<'py, PyAny>>,
                cutoff: Option<f64>,
                tolerance: f64,
                max_iterations: u32,
                warm_start: bool,
                motion_bounds: bool,
                accept_absolute: f64,
                accept_relative: f64,
                exact: bool,
            ) -> PyResult<crate::scene::Summary> {
                let (kind, mode) = crate::scene::path_question(py, question)?;
                let moving = crate::arrays::id_array(objects, "objects")?;
                if moving.shape().len() != 1 {
                    return Err(crate::errors::invalid(
                        py,
                        "objects",
                        None,
                        "objects must be a 1-D array of ids".into(),
                    ));
                }
                let poses = crate::arrays::pose_array(poses, "poses")?;
                let options = crate::scene::Options {
                    tolerance,
                    max_iterations,
                    warm_start,
                    motion_bounds,
                    accept_absolute,
                    accept_relative,
                    exact,
                    cutoff,
                    clamp: false,
                };
                let edit = |r: &mut gjkd_proto::SceneRequest| {
                    if kind == gjkd_proto::SceneKind::Within {
                        r.margin = margin;
                    }
                    if self_pairs {
                        r.flags |= gjkd_proto::scene_flags::SELF_PAIRS;
                    }
                    r.bracket = bracket;
                    if linear_quaternions {
                        r.flags |= gjkd_proto::scene_flags::LINEAR_QUATERNION;
                    }
                };
                let path = crate::scene::PathArg::Poses(mode, moving, poses);
                crate::scene::ask(py, self, kind, group, allow, path, &options, edit, out)
            }

            /// `path` along a motion of `robot` given as joint positions: `positions`
            /// is `(S, dof)` float64 (or `(dof,)` for one step), row `s` the moving
            /// joints' positions (in `robot.joint_names` order) at step `s`. The
            /// server (or `Local`) places the links by forward kinematics at
            /// each step and answers there; nothing moves in the store (the robot keeps its
            /// joints). A position outside its limits raises `InvalidInput`
            /// (`OUT_OF_LIMITS`, `index` its step) unless `clamp`, which moves it
            /// to the nearest limit; a NaN raises (`NON_FINITE_POSE`). `group` is
            /// usually the robot (`robot.id`, or the `Robot` itself, so that its
            /// allowed pairs apply). `question="continuous"` checks every pose of
            /// the motion between consecutive steps, joints linear between them: a
            /// planner's edge check is two rows of `positions`. Other arguments as
            /// `path`.
            #[pyo3(signature = (group, robot, positions, *, out, question="clearance", margin=0.0, self_pairs=false, bracket=gjkd_proto::DEFAULT_BRACKET, clamp=false, allow=None, cutoff=None, tolerance=gjkd_proto::DEFAULT_TOLERANCE, max_iterations=gjkd_proto::DEFAULT_MAX_ITERATIONS, warm_start=true, motion_bounds=true, accept_absolute=0.0, accept_relative=0.0, exact=false))]
            #[allow(clippy::too_many_arguments)]
            fn path_joints<'py>(
                &mut self,
                py: Python<'py>,
                group: &Bound<'py, PyAny>,
                robot: PyRef<'py, crate::robots::Robot>,
                positions: &Bound<'py, PyAny>,
                out: &Bound<'py, crate::scene::SceneRows>,
                question: &str,
                margin: f64,
                self_pairs: bool,
                bracket: f64,
                clamp: bool,
                allow: Option<&Bound<'py, PyAny>>,
                cutoff: Option<f64>,
                tolerance: f64,
                max_iterations: u32,
                warm_start: bool,
                motion_bounds: bool,
                accept_absolute: f64,
                accept_relative: f64,
                exact: bool,
            ) -> PyResult<crate::scene::Summary> {
                let (kind, mode) = crate::scene::path_question(py, question)?;
                let array = crate::arrays::f64_array(positions, "positions")?;
                let dof = robot.handle.positions.len();
                use numpy::PyUntypedArrayMethods as _;
                let shape = array.shape().to_vec();
                if !matches!(shape.as_slice(), [d] | [_, d] if *d == dof) || shape.contains(&0) {
                    return Err(crate::errors::invalid(
                        py,
                        "positions",
                        None,
                        format!(
                            "positions must have shape (S, {dof}) (a row of the robot's {dof} moving \
                             joints per step, at least one step), got {:?}",
                            shape
                        ),
                    ));
                }
                let steps = crate::robots::path_steps(py, &robot, crate::arrays::slice(&array)?, clamp)?;
                let options = crate::scene::Options {
                    tolerance,
                    max_iterations,
                    warm_start,
                    motion_bounds,
                    accept_absolute,
                    accept_relative,
                    exact,
                    cutoff,
                    clamp,
                };
                let edit = |r: &mut gjkd_proto::SceneRequest| {
                    if kind == gjkd_proto::SceneKind::Within {
                        r.margin = margin;
                    }
                    if self_pairs {
                        r.flags |= gjkd_proto::scene_flags::SELF_PAIRS;
                    }
                    r.bracket = bracket;
                };
                let path = crate::scene::PathArg::Joints(mode, steps);
                crate::scene::ask(py, self, kind, group, allow, path, &options, edit, out)
            }
        }
    };
}

pub(crate) use scene_methods;
