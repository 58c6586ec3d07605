//! What `gjkd.Client` and `gjkd.Local` have in common: the calls of their
//! Python API written once over a [`Backend`], and the macro that gives
//! both classes the same methods.

use pyo3::prelude::*;

use gjkd_client::{ClientError, ErrorCode, Gradient, Item, ItemResult, ObjectId};

use nalgebra::Isometry3;

use crate::arrays::{Ids, Poses, id_vector, pose, pose_array};
use crate::batch::{Answer, Distances, RequestArrays, options, set_pose_a, set_pose_b};
use crate::errors::{self, invalid};
use crate::runner::{run_gradient, run_items, run_pairs};
use crate::server_lib::check_pose;
use crate::shape::{Pieces, Registration, Shape};

pub use crate::backend::{Backend, checked_pose};

/// Registers one convex shape.
pub fn register_shape(
    backend: &mut dyn Backend,
    py: Python<'_>,
    shape: &Shape,
    name: Option<&str>,
    pose: Option<&Bound<'_, PyAny>>,
) -> PyResult<u64> {
    let pose = checked_pose(py, pose, "pose")?;
    backend.register(py, &Registration::Convex(shape), name, pose)
}

/// Registers a compound of `[(pose, Shape), ...]`.
pub fn register_compound(
    backend: &mut dyn Backend,
    py: Python<'_>,
    pieces: &Bound<'_, PyAny>,
    name: Option<&str>,
    pose: Option<&Bound<'_, PyAny>>,
) -> PyResult<u64> {
    let pieces = Pieces::read(pieces)?;
    for (i, offset) in pieces.offsets.iter().enumerate() {
        check_pose(offset).map_err(|code| errors::refused(py, code, Some("pieces"), Some(i)))?;
    }
    let pose = checked_pose(py, pose, "pose")?;
    backend.register(py, &Registration::Compound(&pieces), name, pose)
}

/// Stores `poses[i]` for `ids[i]` (arrays as Python gives them).
pub fn set_poses(
    backend: &mut dyn Backend,
    py: Python<'_>,
    ids: &Bound<'_, PyAny>,
    poses: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let id_arr = id_vector(ids, "ids")?;
    let pose_arr = pose_array(poses, "poses")?;
    store_poses(backend, py, id_arr.slice()?, pose_arr.poses()?, "poses")
}

/// The stored poses of `ids` as an `(N, 7)` array
/// `[x, y, z, qx, qy, qz, qw]`, bit for bit as the store holds them; an
/// unknown id raises `NotFound` (`UNKNOWN_OBJECT`, with its row), as
/// `set_poses` does.
pub fn poses<'py>(
    backend: &mut dyn Backend,
    py: Python<'py>,
    ids: &Bound<'_, PyAny>,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let id_arr = id_vector(ids, "ids")?;
    let slice = id_arr.slice()?;
    let ids: Vec<u64> = (0..slice.len()).map(|i| slice.get(i)).collect();
    let got = if ids.is_empty() {
        Vec::new()
    } else {
        backend.stored_poses(py, &ids)?
    };
    let mut rows = Vec::with_capacity(got.len());
    for (i, entry) in got.iter().enumerate() {
        let p = entry.map_err(|code| errors::refused(py, code, Some("ids"), Some(i)))?;
        let [x, y, z] = p.translation;
        let [qx, qy, qz, qw] = p.rotation;
        rows.push(vec![x, y, z, qx, qy, qz, qw]);
    }
    if rows.is_empty() {
        return Ok(numpy::PyArray2::zeros(py, [0, 7], false));
    }
    numpy::PyArray2::from_vec2(py, &rows).map_err(|e| invalid(py, "ids", None, e.to_string()))
}

/// Stores one pose.
pub fn set_pose(
    backend: &mut dyn Backend,
    py: Python<'_>,
    id: u64,
    pose_obj: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let p = pose(Some(pose_obj), "pose")?
        .ok_or_else(|| invalid(py, "pose", None, "pose must not be None".into()))?;
    let row = [
        p.translation[0],
        p.translation[1],
        p.translation[2],
        p.rotation[0],
        p.rotation[1],
        p.rotation[2],
        p.rotation[3],
    ];
    let ids = [id];
    store_poses(backend, py, Ids::Unsigned(&ids), Poses::rows(&row), "pose")
}

/// Every pose is checked first (a bad one raises `InvalidInput` with its
/// row and changes nothing); an unknown id raises `NotFound` with its row
/// after the other rows were stored.
fn store_poses(
    backend: &mut dyn Backend,
    py: Python<'_>,
    ids: Ids<'_>,
    poses: Poses<'_>,
    field: &str,
) -> PyResult<()> {
    let n = ids.len();
    if poses.len() != n {
        return Err(invalid(
            py,
            field,
            None,
            format!("{field} has {} rows for {n} ids", poses.len()),
        ));
    }
    // A single pose (`set_pose`) has no row to name.
    let row = |i: usize| (field != "pose").then_some(i);
    for i in 0..n {
        check_pose(&poses.get(i)).map_err(|c| errors::refused(py, c, Some(field), row(i)))?;
    }
    if n == 0 {
        return Ok(());
    }
    let make = move |i: usize| -> Item {
        let mut item = Item::set_pose(ObjectId::from_raw(ids.get(i)), &Isometry3::identity());
        item.pose_a = poses.get(i);
        item
    };
    let mut failed: Option<(usize, ErrorCode)> = None;
    let mut check = |i: usize, r: &ItemResult| -> Result<(), ClientError> {
        if r.error != 0 && failed.is_none() {
            failed = Some((i, r.error_code()));
        }
        Ok(())
    };
    let (answerer, buffers) = backend.parts(py)?;
    run_items(py, answerer, buffers, n, &make, &mut check)
        .map_err(|e| errors::client(py, e, None))?;
    match failed {
        Some((i, code)) => {
            let field = if code == ErrorCode::UnknownObject {
                "ids"
            } else {
                field
            };
            Err(errors::refused(py, code, Some(field), row(i)))
        }
        None => Ok(()),
    }
}

/// Keyword options of a query, as Python passes them.
pub struct QueryArgs {
    /// Relative tolerance.
    pub tolerance: f64,
    /// Iteration cap.
    pub max_iterations: u32,
    /// Early-exit margin.
    pub margin: Option<f64>,
    /// Start from the pair's last simplex.
    pub warm_start: bool,
    /// Also answer the signed distance.
    pub signed_distance: bool,
    /// Also the distance's gradient: `None`, or `Some(base)` with the base
    /// twist's columns when `base`.
    pub gradient: Option<bool>,
}

/// One pair query.
pub fn distance(
    backend: &mut dyn Backend,
    py: Python<'_>,
    a: u64,
    b: u64,
    pose_a: Option<&Bound<'_, PyAny>>,
    pose_b: Option<&Bound<'_, PyAny>>,
    args: &QueryArgs,
) -> PyResult<Answer> {
    let opts = options(
        py,
        args.tolerance,
        args.max_iterations,
        args.margin,
        args.warm_start,
        args.signed_distance,
    )?;
    let mut item = Item::distance(ObjectId::from_raw(a), ObjectId::from_raw(b), &opts);
    if let Some(base) = args.gradient {
        item = item.with_gradient(base);
    }
    if let Some(p) = pose(pose_a, "pose_a")? {
        set_pose_a(&mut item, p);
    }
    if let Some(p) = pose(pose_b, "pose_b")? {
        set_pose_b(&mut item, p);
    }
    let (answerer, buffers) = backend.parts(py)?;
    let (out, gradient) = if args.gradient.is_some() {
        // The gradient travels apart from the result, into room of its
        // own for this one item.
        run_gradient(py, answerer, item).map_err(|e| errors::client(py, e, None))?
    } else {
        let mut out = ItemResult::default();
        let mut check = |_: usize, r: &ItemResult| -> Result<(), ClientError> {
            out = *r;
            Ok(())
        };
        run_items(py, answerer, buffers, 1, &move |_| item, &mut check)
            .map_err(|e| errors::client(py, e, None))?;
        (out, Gradient::NONE)
    };
    match out.error_code() {
        ErrorCode::Ok if args.gradient.is_some() => Ok(Answer::with_gradient(out, gradient)),
        ErrorCode::Ok => Ok(Answer::new(out)),
        code => {
            let field = match code {
                ErrorCode::UnknownObject => Some("id"),
                ErrorCode::NonFinitePose | ErrorCode::BadQuaternion => Some("pose"),
                _ => None,
            };
            Err(errors::refused(py, code, field, None))
        }
    }
}

/// `N` pair queries in as few round trips as the answerer's limit allows.
pub fn distances(
    backend: &mut dyn Backend,
    py: Python<'_>,
    pairs: &Bound<'_, PyAny>,
    poses_a: Option<&Bound<'_, PyAny>>,
    poses_b: Option<&Bound<'_, PyAny>>,
    args: &QueryArgs,
    out: Option<Bound<'_, Distances>>,
) -> PyResult<Py<Distances>> {
    let opts = options(
        py,
        args.tolerance,
        args.max_iterations,
        args.margin,
        args.warm_start,
        args.signed_distance,
    )?;
    let arrays = RequestArrays::read(pairs, poses_a, poses_b)?;
    let result = Distances::reuse_or_new(py, out, arrays.len())?;
    let request = arrays.request(opts, result.borrow(py).gradient_request())?;
    let (answerer, buffers) = backend.parts(py)?;
    run_pairs(py, answerer, buffers, request, &result.borrow(py))?
        .map_err(|e| errors::client(py, e, None))?;
    Ok(result)
}

/// The Python methods `gjkd.Client` and `gjkd.Local` share, plus the
/// class's own (`$extra`), in the one `#[pymethods]` block a class may
/// have.
macro_rules! backend_methods {
    ($class:ident, { $($extra:tt)* }) => {
        #[pymethods]
        impl $class {
            $($extra)*

            /// Registers `shape` (a `gjkd.Shape`), optionally with a unique
            /// `name` (see `lookup`) and an initial `pose` (`(7,)`
            /// `[x, y, z, qx, qy, qz, qw]` or `(4, 4)`; default identity).
            /// Returns the new object's id (an int).
            #[pyo3(signature = (shape, *, name = None, pose = None))]
            fn register(
                &mut self,
                py: Python<'_>,
                shape: &Bound<'_, crate::shape::Shape>,
                name: Option<&str>,
                pose: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<u64> {
                crate::api::register_shape(self, py, shape.get(), name, pose)
            }

            /// Registers a ball of `radius` about the body origin; `name`
            /// and `pose` as for `register`. Returns its id.
            #[pyo3(signature = (radius, *, name = None, pose = None))]
            fn register_sphere(
                &mut self,
                py: Python<'_>,
                radius: f64,
                name: Option<&str>,
                pose: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<u64> {
                let shape = crate::shape::Shape::sphere(radius);
                crate::api::register_shape(self, py, &shape, name, pose)
            }

            /// Registers the segment `a`–`b` (three floats each) grown by
            /// `radius`; `name` and `pose` as for `register`. Returns its id.
            #[pyo3(signature = (a, b, radius, *, name = None, pose = None))]
            fn register_capsule(
                &mut self,
                py: Python<'_>,
                a: &Bound<'_, PyAny>,
                b: &Bound<'_, PyAny>,
                radius: f64,
                name: Option<&str>,
                pose: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<u64> {
                let shape = crate::shape::Shape::capsule(a, b, radius)?;
                crate::api::register_shape(self, py, &shape, name, pose)
            }

            /// Registers a box of these half extents (three floats, each
            /// `>= 0`) centred on the body origin, its edges rounded by
            /// `radius`; `name` and `pose` as for `register`. Returns its id.
            #[pyo3(signature = (half_extents, radius = 0.0, *, name = None, pose = None))]
            fn register_box(
                &mut self,
                py: Python<'_>,
                half_extents: &Bound<'_, PyAny>,
                radius: f64,
                name: Option<&str>,
                pose: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<u64> {
                let shape = crate::shape::Shape::cuboid(py, half_extents, radius)?;
                crate::api::register_shape(self, py, &shape, name, pose)
            }

            /// Registers an exact cylinder about the body z axis, centred on
            /// the body origin: the disk of `radius` swept from
            /// `z = -half_height` to `z = +half_height`, its rims rounded by
            /// `rounding` (each finite and `>= 0`); `name` and `pose` as for
            /// `register`. Returns its id.
            #[pyo3(signature = (radius, half_height, rounding = 0.0, *, name = None, pose = None))]
            fn register_cylinder(
                &mut self,
                py: Python<'_>,
                radius: f64,
                half_height: f64,
                rounding: f64,
                name: Option<&str>,
                pose: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<u64> {
                let shape = crate::shape::Shape::cylinder(radius, half_height, rounding);
                crate::api::register_shape(self, py, &shape, name, pose)
            }

            /// Registers the convex hull of `vertices` (`(N, 3)` float64,
            /// N >= 1) grown by `radius`; `name` and `pose` as for
            /// `register`. Returns its id.
            #[pyo3(signature = (vertices, radius = 0.0, *, name = None, pose = None))]
            fn register_polytope(
                &mut self,
                py: Python<'_>,
                vertices: &Bound<'_, PyAny>,
                radius: f64,
                name: Option<&str>,
                pose: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<u64> {
                let shape = crate::shape::Shape::polytope(vertices, radius)?;
                crate::api::register_shape(self, py, &shape, name, pose)
            }

            /// Registers a union of convex pieces, `[(offset, Shape), ...]`
            /// (at most 64), each placed in the compound's body frame by its
            /// offset (`(7,)` or `(4, 4)`). Answers name the pieces that
            /// realise the distance by position in this list. `name` and
            /// `pose` as for `register`. Returns its id.
            #[pyo3(signature = (pieces, *, name = None, pose = None))]
            fn register_compound(
                &mut self,
                py: Python<'_>,
                pieces: &Bound<'_, PyAny>,
                name: Option<&str>,
                pose: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<u64> {
                crate::api::register_compound(self, py, pieces, name, pose)
            }

            /// Registers a triangle mesh given as arrays: `vertices`
            /// `(N, 3)` float64, `triangles` `(M, 3)` vertex indices (any
            /// integer dtype; optional for a hull), scaled by `scale` (a
            /// float or three). By default the object is the mesh's convex
            /// hull, which never reports more distance than the mesh;
            /// `decompose=R` makes it a compound of convex pieces instead
            /// (V-HACD at resolution `R`, 64 is a fair start; at most
            /// `MAX_PIECES` pieces). `name` and `pose` as for `register`.
            /// `info`: a `gjkd.MeshInfo`, filled with the pieces made and,
            /// for a decomposition, its largest deviation found from the
            /// mesh. Returns its id.
            #[pyo3(signature = (vertices, triangles = None, *, scale = None,
                decompose = None, name = None, pose = None, info = None))]
            #[allow(clippy::too_many_arguments)]
            fn register_mesh(
                &mut self,
                py: Python<'_>,
                vertices: &Bound<'_, PyAny>,
                triangles: Option<&Bound<'_, PyAny>>,
                scale: Option<&Bound<'_, PyAny>>,
                decompose: Option<u32>,
                name: Option<&str>,
                pose: Option<&Bound<'_, PyAny>>,
                info: Option<&Bound<'_, crate::meshes::MeshInfo>>,
            ) -> PyResult<u64> {
                let args = crate::meshes::MeshArgs { scale, decompose, name, pose, info };
                crate::meshes::register_mesh(self, py, vertices, triangles, &args)
            }

            /// Registers the mesh in the file at `path` (binary or ASCII
            /// STL, OBJ, COLLADA `.dae`); `scale`, `decompose`, `name`,
            /// `pose` and `info` as for `register_mesh`. A file that is missing or not
            /// a mesh raises `InvalidInput` (`field="path"`). Returns its id.
            #[pyo3(signature = (path, *, scale = None, decompose = None, name = None,
                pose = None, info = None))]
            #[allow(clippy::too_many_arguments)]
            fn register_mesh_file(
                &mut self,
                py: Python<'_>,
                path: std::path::PathBuf,
                scale: Option<&Bound<'_, PyAny>>,
                decompose: Option<u32>,
                name: Option<&str>,
                pose: Option<&Bound<'_, PyAny>>,
                info: Option<&Bound<'_, crate::meshes::MeshInfo>>,
            ) -> PyResult<u64> {
                let args = crate::meshes::MeshArgs { scale, decompose, name, pose, info };
                crate::meshes::register_mesh_file(self, py, path, &args)
            }

            /// Removes object `id`. Its id is never reused.
            fn remove(&mut self, py: Python<'_>, id: u64) -> PyResult<()> {
                crate::api::Backend::remove(self, py, id)
            }

            /// The id of the object named `name`.
            fn lookup(&mut self, py: Python<'_>, name: &str) -> PyResult<u64> {
                crate::api::Backend::lookup(self, py, name)
            }

            /// Stores `pose` (`(7,)` or `(4, 4)`) as the pose of object `id`,
            /// used by every later query that gives no pose of its own.
            fn set_pose(
                &mut self,
                py: Python<'_>,
                id: u64,
                pose: &Bound<'_, PyAny>,
            ) -> PyResult<()> {
                crate::api::set_pose(self, py, id, pose)
            }

            /// Stores many poses in one round trip: `ids` `(N,)` integers
            /// and `poses` `(N, 7)` `[x, y, z, qx, qy, qz, qw]` or
            /// `(N, 4, 4)` float64. Every pose is checked first: a bad one
            /// raises `InvalidInput` (with `index` its row) and stores
            /// nothing. An unknown id raises `NotFound` (with its row) after
            /// the other rows were stored.
            fn set_poses(
                &mut self,
                py: Python<'_>,
                ids: &Bound<'_, PyAny>,
                poses: &Bound<'_, PyAny>,
            ) -> PyResult<()> {
                crate::api::set_poses(self, py, ids, poses)
            }

            /// The stored poses of `ids` (`(N,)` integers) as an `(N, 7)`
            /// float64 array `[x, y, z, qx, qy, qz, qw]`, bit for bit as
            /// stored: what `set_pose`/`set_poses` or the registration
            /// stored, and for a robot's link the pose its joints put it
            /// at. One round trip for any `N` (split when larger than a
            /// request takes). An unknown id raises `NotFound`
            /// (`UNKNOWN_OBJECT`, with `index` its row), as `set_poses`
            /// does; no id gives a `(0, 7)` array.
            fn poses<'py>(
                &mut self,
                py: Python<'py>,
                ids: &Bound<'_, PyAny>,
            ) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
                crate::api::poses(self, py, ids)
            }

            /// The distance between objects `a` and `b`, at their stored
            /// poses or at `pose_a` / `pose_b` (`(7,)` or `(4, 4)`) for this
            /// query only. `tolerance` is the relative tolerance of the
            /// stopping rule (default `gjkd.DEFAULT_TOLERANCE`, 100 × machine
            /// epsilon), `max_iterations` the iteration cap, `margin`
            /// an early exit (stop once the distance is proved above or at
            /// most it), `warm_start` starts from the pair's last simplex.
            /// `signed_distance` also answers the signed distance (negative
            /// inside: minus the penetration depth) with its certified
            /// interval, in `Answer.signed_distance` and
            /// `Answer.signed_interval`; it costs nothing for a pair proved
            /// apart.
            /// `gradient=True` also asks the distance's gradient with
            /// respect to the coordinates that move `a` (its robot's
            /// joints, or its pose's twist; `Answer.gradient`), and
            /// `gradient_base=True` the robot base's twist too
            /// (`gradient_base=True` alone raises `InvalidInput`).
            /// Returns an `Answer`; a refused query raises (`NotFound` for
            /// an unknown id, `InvalidInput` for a bad pose).
            #[pyo3(signature = (a, b, pose_a = None, pose_b = None, *,
                tolerance = gjkd_client::DEFAULT_TOLERANCE, max_iterations = 128,
                margin = None, warm_start = true, signed_distance = false, gradient = false, gradient_base = false),
                text_signature = "($self, a, b, pose_a=None, pose_b=None, *, tolerance=2.220446049250313e-14, max_iterations=128, margin=None, warm_start=True, signed_distance=False, gradient=False, gradient_base=False)")]
            #[allow(clippy::too_many_arguments)]
            fn distance(
                &mut self,
                py: Python<'_>,
                a: u64,
                b: u64,
                pose_a: Option<&Bound<'_, PyAny>>,
                pose_b: Option<&Bound<'_, PyAny>>,
                tolerance: f64,
                max_iterations: u32,
                margin: Option<f64>,
                warm_start: bool,
                signed_distance: bool,
                gradient: bool,
                gradient_base: bool,
            ) -> PyResult<crate::batch::Answer> {
                let gradient = crate::batch::gradient_asked(py, gradient, gradient_base)?;
                let args = crate::api::QueryArgs {
                    tolerance, max_iterations, margin, warm_start, signed_distance, gradient,
                };
                crate::api::distance(self, py, a, b, pose_a, pose_b, &args)
            }

            /// The distances of `N` pairs at once: `pairs` `(N, 2)` integer
            /// ids; `poses_a`, `poses_b` `(N, 7)` or `(N, 4, 4)` float64
            /// poses for these queries only (default: the stored poses);
            /// options as for `distance`, the same for every pair. Batches
            /// larger than the server takes are split transparently.
            /// Returns a `Distances` (arrays, one row per pair); a pair
            /// that fails has its `ErrorCode` in `error` and the other
            /// pairs are still answered. `out`, a `Distances` of `N` rows
            /// from an earlier call, is filled instead of new arrays.
            /// `signed_distance=True` also answers each pair's signed
            /// distance with its certified interval, in the result's
            /// `signed_distance`, `signed_lower` and `signed_upper` arrays
            /// (NaN otherwise), and an overlapping pair's depth witnesses
            /// in `point_a`, `point_b`, `normal`.
            /// Gradients are asked by the room they go into, as for scene
            /// rows: `out=gjkd.Distances(N, gradient_columns=c)` (with
            /// `gradient_base=True` the base twist too) fills its
            /// `gradient` `(N, c)`, `gradient_flags` and `gradient_error`
            /// with each pair's gradient, bit for bit what
            /// `distance(gradient=True)` answers.
            #[pyo3(signature = (pairs, poses_a = None, poses_b = None, *,
                tolerance = gjkd_client::DEFAULT_TOLERANCE, max_iterations = 128,
                margin = None, warm_start = true, signed_distance = false, out = None),
                text_signature = "($self, pairs, poses_a=None, poses_b=None, *, tolerance=2.220446049250313e-14, max_iterations=128, margin=None, warm_start=True, signed_distance=False, out=None)")]
            #[allow(clippy::too_many_arguments)]
            fn distances(
                &mut self,
                py: Python<'_>,
                pairs: &Bound<'_, PyAny>,
                poses_a: Option<&Bound<'_, PyAny>>,
                poses_b: Option<&Bound<'_, PyAny>>,
                tolerance: f64,
                max_iterations: u32,
                margin: Option<f64>,
                warm_start: bool,
                signed_distance: bool,
                out: Option<Bound<'_, crate::batch::Distances>>,
            ) -> PyResult<Py<crate::batch::Distances>> {
                let args = crate::api::QueryArgs {
                    tolerance, max_iterations, margin, warm_start, signed_distance, gradient: None,
                };
                crate::api::distances(self, py, pairs, poses_a, poses_b, &args, out)
            }

            /// Returns itself: `with ... as x:`.
            fn __enter__(slf: Py<Self>) -> Py<Self> {
                slf
            }

            /// Closes (see `close`); exceptions pass through.
            #[pyo3(signature = (*_args))]
            fn __exit__(&mut self, _args: &Bound<'_, pyo3::types::PyTuple>) -> bool {
                self.close();
                false
            }
        }
    };
}

pub(crate) use backend_methods;
