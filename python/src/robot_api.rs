//! The robot calls `gjkd.Client` and `gjkd.Local` share: the macro that
//! gives both classes the same `register_robot`, `open_robot`,
//! `remove_robot` and `set_joints`, written once over a
//! [`Backend`](crate::backend::Backend) (the work is in `robots.rs`).

/// The robot methods of `$class`, in a `#[pymethods]` block of their own.
macro_rules! robot_methods {
    ($class:ident) => {
        #[pymethods]
        impl $class {
            /// Registers a robot from URDF: each link with collision geometry
            /// (boxes, spheres, cylinders, meshes; several elements make a
            /// compound) becomes an object named `<name>/<link>`, then the server
            /// (for `Local`, this process) holds the robot's kinematics and puts it at `base` (`(7,)` or
            /// `(4, 4)`, default identity) with every joint at zero (within its
            /// limits). `urdf` is a file path, `srdf` an optional SRDF file (its
            /// `disable_collisions` pairs); `urdf_text` / `srdf_text` give the
            /// text instead (then relative mesh paths are relative to the working
            /// folder). `package://NAME/...` mesh URLs are searched in
            /// `package_path`, then `$GJKD_PACKAGE_PATH`, `$ROS_PACKAGE_PATH` and
            /// the `share` folder of each `$AMENT_PREFIX_PATH` prefix, as ROS
            /// searches them (`DIR/NAME/...` or a `DIR` named `NAME` first, then
            /// the shallowest folder below a `DIR` whose `package.xml` names
            /// `NAME`, up to six levels down). Returns a
            /// `gjkd.Robot`. Raises `InvalidInput` (`INVALID_ROBOT`,
            /// `field="urdf"`) for a URDF, SRDF or mesh that cannot be read (the
            /// message names the file, link or joint), `Refused` (`NAME_TAKEN`) when a link object of that name
            /// exists; links registered before a failure are removed again.
            #[pyo3(signature = (name, urdf = None, *, srdf = None, urdf_text = None,
                                        srdf_text = None, package_path = Vec::new(), base = None))]
            #[allow(clippy::too_many_arguments)]
            fn register_robot(
                &mut self,
                py: Python<'_>,
                name: &str,
                urdf: Option<std::path::PathBuf>,
                srdf: Option<std::path::PathBuf>,
                urdf_text: Option<String>,
                srdf_text: Option<String>,
                package_path: Vec<std::path::PathBuf>,
                base: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<crate::robots::Robot> {
                use crate::robots::{RobotSource, Text};
                let urdf = match (urdf, urdf_text) {
                    (Some(p), None) => Text::File(p),
                    (None, Some(t)) => Text::Inline(t),
                    _ => {
                        return Err(crate::errors::invalid(
                            py,
                            "urdf",
                            None,
                            "give urdf (a path) or urdf_text".into(),
                        ));
                    }
                };
                let srdf = match (srdf, srdf_text) {
                    (Some(p), None) => Some(Text::File(p)),
                    (None, Some(t)) => Some(Text::Inline(t)),
                    (None, None) => None,
                    _ => {
                        return Err(crate::errors::invalid(
                            py,
                            "srdf",
                            None,
                            "give srdf or srdf_text, not both".into(),
                        ));
                    }
                };
                let source = RobotSource {
                    urdf,
                    srdf,
                    package_path,
                };
                crate::robots::register_robot(self, py, name, &source, base)
            }

            /// The robot named `name` already held (on a server: one its scene
            /// file loaded, or another client registered; in a `Local`: one
            /// registered on it before), given its URDF
            /// text for the joint order and link names. Returns a `gjkd.Robot`;
            /// raises `NotFound` (`UNKNOWN_NAME`) when there is none.
            fn open_robot(
                &mut self,
                py: Python<'_>,
                name: &str,
                urdf_text: &str,
            ) -> PyResult<crate::robots::Robot> {
                crate::robots::open_robot(self, py, name, urdf_text)
            }

            /// Removes the robot named `name` (or the `gjkd.Robot` given) as a
            /// whole: its kinematics and every link object, all or nothing
            /// (`remove` of one link would leave the robot with a hole; the
            /// robot's `id` is no object id). Raises `NotFound` (`UNKNOWN_NAME`)
            /// when there is no such robot, and the store's refusals
            /// (`NOT_OWNER`, `READ_ONLY`) as `remove` does.
            fn remove_robot(&mut self, py: Python<'_>, robot: &Bound<'_, PyAny>) -> PyResult<()> {
                let name = match robot.cast::<crate::robots::Robot>() {
                    Ok(r) => r.borrow().handle.name.clone(),
                    Err(_) => robot.extract::<String>()?,
                };
                crate::backend::Backend::remove_robot(self, py, &name)?
                    .map_err(|e| crate::errors::client(py, e, Some("robot")))
            }

            /// Sets every joint of `robot` in one round trip, and its base pose
            /// when `base` is given: the server (or `Local`) places every link by forward
            /// kinematics. `positions` is a `(dof,)` float64 array in
            /// `robot.joint_names` order, or a `{joint name: position}` dict
            /// (joints not named keep their last positions); a robot without
            /// moving joints takes `[]` and moves by `base` alone. A position outside
            /// its limits raises `InvalidInput` (`OUT_OF_LIMITS`, `index` the
            /// joint) unless `clamp=True` moves it to the nearest limit; NaN
            /// raises `InvalidInput` (`NON_FINITE_POSE`); an unknown joint name
            /// `NotFound` (`UNKNOWN_NAME`). Nothing moves on error.
            #[pyo3(signature = (robot, positions, *, base = None, clamp = false))]
            fn set_joints(
                &mut self,
                py: Python<'_>,
                mut robot: PyRefMut<'_, crate::robots::Robot>,
                positions: &Bound<'_, PyAny>,
                base: Option<&Bound<'_, PyAny>>,
                clamp: bool,
            ) -> PyResult<()> {
                crate::robots::set_joints(self, py, &mut robot, positions, base, clamp)
            }
        }
    };
}

pub(crate) use robot_methods;
