//! Batched queries: the request read from numpy arrays (`Request`), the
//! answers written into numpy arrays (`Distances`), and the single answer
//! (`Answer`). Shared by `gjkd.Client` and `gjkd.Local`, which differ only
//! in who answers the items.

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyAnyMethods, PyDict};

use gjkd_client::{Gradient, Item, ItemResult, ObjectId, Precision, QueryOptions};
use gjkd_proto::{GRADIENT_COLUMNS, Pose, result_flags};

use crate::arrays::{IdArray, Ids, PoseArray, Poses, id_array, pose_array};
use crate::errors::invalid;

/// Query options from keyword arguments, checked so that a bad one raises
/// `InvalidInput` naming it (the server would only say `INVALID_OPTIONS`).
pub fn options(
    py: Python<'_>,
    tolerance: f64,
    max_iterations: u32,
    margin: Option<f64>,
    warm_start: bool,
    signed_distance: bool,
) -> PyResult<QueryOptions> {
    if !(tolerance.is_finite() && tolerance >= 0.0) {
        return Err(invalid(
            py,
            "tolerance",
            None,
            "tolerance must be finite and >= 0".into(),
        ));
    }
    if max_iterations == 0 {
        return Err(invalid(
            py,
            "max_iterations",
            None,
            "max_iterations must be at least 1".into(),
        ));
    }
    if margin.is_some_and(|m| !m.is_finite()) {
        return Err(invalid(py, "margin", None, "margin must be finite".into()));
    }
    Ok(QueryOptions {
        tolerance,
        max_iterations,
        margin,
        warm_start,
        precision: Precision::Double,
        signed_distance,
    })
}

/// What `gradient=` and `gradient_base=` of a single query ask: `None`
/// (no gradient) or `Some(base)`. The base twist alone is not a gradient
/// asked: refused rather than ignored, so that a forgotten `gradient=True`
/// does not pass unnoticed.
pub fn gradient_asked(py: Python<'_>, gradient: bool, base: bool) -> PyResult<Option<bool>> {
    if base && !gradient {
        return Err(invalid(
            py,
            "gradient_base",
            None,
            "gradient_base=True adds the base twist to a gradient: pass gradient=True too".into(),
        ));
    }
    Ok(gradient.then_some(base))
}

/// Checks the gradient room of a `Distances` or `SceneRows`: at most
/// [`GRADIENT_COLUMNS`] columns, and `gradient_base` only with columns
/// (without them no gradient is asked, so a base twist would be dropped
/// without a word).
pub fn check_gradient_room(py: Python<'_>, columns: usize, base: bool) -> PyResult<()> {
    if columns > GRADIENT_COLUMNS {
        return Err(invalid(
            py,
            "gradient_columns",
            None,
            format!("a row carries at most {GRADIENT_COLUMNS} gradient entries, not {columns}"),
        ));
    }
    if base && columns == 0 {
        return Err(invalid(
            py,
            "gradient_base",
            None,
            "gradient_base=True adds the base twist to a gradient: give gradient_columns > 0 too"
                .into(),
        ));
    }
    Ok(())
}

/// The arrays of a `distances` call, read and checked, held while their
/// slices are in use.
pub struct RequestArrays<'py> {
    pairs: IdArray<'py>,
    poses_a: Option<PoseArray<'py>>,
    poses_b: Option<PoseArray<'py>>,
    n: usize,
}

impl<'py> RequestArrays<'py> {
    /// Reads `pairs` `(N, 2)` and the optional `(N, 7)` / `(N, 4, 4)` poses.
    pub fn read(
        pairs: &Bound<'py, PyAny>,
        poses_a: Option<&Bound<'py, PyAny>>,
        poses_b: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        let py = pairs.py();
        let ids = id_array(pairs, "pairs")?;
        let n = match ids.shape() {
            [n, 2] => *n,
            shape => {
                return Err(invalid(
                    py,
                    "pairs",
                    None,
                    format!("pairs must have shape (N, 2), got {shape:?}"),
                ));
            }
        };
        let read = |obj: Option<&Bound<'py, PyAny>>, field: &str| -> PyResult<_> {
            let Some(obj) = obj.filter(|o| !o.is_none()) else {
                return Ok(None);
            };
            let a = pose_array(obj, field)?;
            let len = a.poses()?.len();
            if len != n {
                return Err(invalid(
                    py,
                    field,
                    None,
                    format!("{field} has {len} poses for {n} pairs"),
                ));
            }
            Ok(Some(a))
        };
        Ok(RequestArrays {
            poses_a: read(poses_a, "poses_a")?,
            poses_b: read(poses_b, "poses_b")?,
            pairs: ids,
            n,
        })
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.n
    }

    /// The request, as slices that can be used without the GIL; with
    /// `gradient` `Some(base)`, every pair also asks its gradient (and
    /// with `base` the base twist's columns).
    pub fn request(&self, options: QueryOptions, gradient: Option<bool>) -> PyResult<Request<'_>> {
        Ok(Request {
            pairs: self.pairs.slice()?,
            poses_a: self.poses_a.as_ref().map(|p| p.poses()).transpose()?,
            poses_b: self.poses_b.as_ref().map(|p| p.poses()).transpose()?,
            options,
            gradient,
        })
    }
}

/// A batch of pair queries, readable without the GIL.
#[derive(Clone, Copy)]
pub struct Request<'a> {
    pairs: Ids<'a>,
    poses_a: Option<Poses<'a>>,
    poses_b: Option<Poses<'a>>,
    options: QueryOptions,
    /// `Some(base)`: every pair asks its gradient.
    gradient: Option<bool>,
}

impl Request<'_> {
    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.pairs.len() / 2
    }

    /// Whether every pair asks its gradient.
    pub fn asks_gradients(&self) -> bool {
        self.gradient.is_some()
    }

    /// Appends the items of pairs `range` to `items`.
    pub fn push_items(&self, range: std::ops::Range<usize>, items: &mut Vec<Item>) {
        items.extend(range.map(|i| self.item(i)));
    }

    #[inline]
    fn item(&self, i: usize) -> Item {
        let a = ObjectId::from_raw(self.pairs.get(2 * i));
        let b = ObjectId::from_raw(self.pairs.get(2 * i + 1));
        let mut item = Item::distance(a, b, &self.options);
        if let Some(base) = self.gradient {
            item = item.with_gradient(base);
        }
        if let Some(p) = &self.poses_a {
            set_pose_a(&mut item, p.get(i));
        }
        if let Some(p) = &self.poses_b {
            set_pose_b(&mut item, p.get(i));
        }
        item
    }
}

/// `item` with its own pose for A, the wire pose as given.
pub fn set_pose_a(item: &mut Item, pose: Pose) {
    item.flags |= gjkd_proto::item_flags::POSE_A;
    item.pose_a = pose;
}

/// `item` with its own pose for B, the wire pose as given.
pub fn set_pose_b(item: &mut Item, pose: Pose) {
    item.flags |= gjkd_proto::item_flags::POSE_B;
    item.pair_mut().pose_b = pose;
}

/// The answers of a batch of `N` pair queries, one numpy array per field;
/// row `i` answers pair `i`.
///
/// Attributes (all numpy arrays):
///
/// - `distance` `(N,)` float64: the distance between the (rounded) shapes;
/// - `lower`, `upper` `(N,)` float64: certified bounds on it;
/// - `penetration` `(N,)` float64: a lower bound on the penetration depth,
///   0 when separated;
/// - `point_a`, `point_b` `(N, 3)` float64: nearest points, world frame;
/// - `normal` `(N, 3)` float64: unit vector from `point_a` towards
///   `point_b`, zero when the cores touch or intersect;
/// - `status` `(N,)` uint32: a `gjkd.Status` value, 0 for failed rows;
/// - `iterations` `(N,)` uint32: subalgorithm iterations;
/// - `pieces` `(N, 2)` uint32: the pieces of A and B realising the
///   distance (0 for convex objects);
/// - `error` `(N,)` uint32: a `gjkd.ErrorCode` value, 0 (`OK`) when the
///   row was answered; the other fields of a failed row are 0;
/// - `warm_started` `(N,)` bool: the query started from the pair's last
///   simplex;
/// - `signed_distance`, `signed_lower`, `signed_upper` `(N,)` float64: the
///   signed distance (the distance apart, minus the penetration depth
///   overlapping) and its certified bounds, for rows that asked for it
///   (`signed_distance=True`, `SceneRows(n, signed_distance=True)`); NaN
///   in rows without one (not asked, or failed). A row that has one holds
///   its witnesses in `point_a`, `point_b` and `normal` (`point_b - point_a
///   = signed_distance * normal`), also when overlapping.
///
/// Pass it back as `out=` to a later call of the same `N` to reuse its
/// arrays instead of allocating new ones.
///
/// `Distances(n, gradient_columns=c)` with `c > 0` also asks every call
/// given it as `out=` for each pair's distance gradient (with
/// `gradient_base=True`, a robot's base twist too), as `SceneRows(n,
/// gradient_columns=c)` does for scene rows, written into:
///
/// - `gradient` `(N, c)` float64: row `i` holds `∂d/∂x` with respect to
///   the coordinates that move its `a` (a robot link: the robot's moving
///   joints in `Robot.joint_names` order, then the base twist `[v, ω]`
///   when asked; any other object: its pose's twist), zero beyond the
///   columns in use; for overlapping pairs, the signed distance's
///   (`distance - penetration`). A gradient of more than `c` columns keeps
///   its first `c`: size `c` for the widest pair (a robot's `dof`, plus 6
///   with `gradient_base`; 6 for a free object). Failed rows hold zeros;
/// - `gradient_flags` `(N,)` uint32: `1` computed, `2` nearest points not
///   unique (a one-sided gradient), `4` base twist included, `8` no
///   direction (zeros); 0 in failed rows;
/// - `gradient_error` `(N,)` float64: a bound on each entry's error from
///   the distance's certified interval.
///
/// The room asks, not a keyword of `distances`, as with `SceneRows`: the
/// arrays are sized once for the gradient's columns and reused from call
/// to call, so a call never asks for a gradient it has no room for, and
/// nothing is allocated per call. Without gradient columns, `gradient` is
/// `(N, 0)` and the flags and errors stay 0.
#[pyclass(module = "gjkd", name = "Distances")]
pub struct Distances {
    distance: Py<PyArray1<f64>>,
    lower: Py<PyArray1<f64>>,
    upper: Py<PyArray1<f64>>,
    penetration: Py<PyArray1<f64>>,
    point_a: Py<PyArray2<f64>>,
    point_b: Py<PyArray2<f64>>,
    normal: Py<PyArray2<f64>>,
    status: Py<PyArray1<u32>>,
    iterations: Py<PyArray1<u32>>,
    pieces: Py<PyArray2<u32>>,
    error: Py<PyArray1<u32>>,
    warm_started: Py<PyArray1<bool>>,
    signed_distance: Py<PyArray1<f64>>,
    signed_lower: Py<PyArray1<f64>>,
    signed_upper: Py<PyArray1<f64>>,
    gradient: Py<PyArray2<f64>>,
    gradient_flags: Py<PyArray1<u32>>,
    gradient_error: Py<PyArray1<f64>>,
    /// Entries per row of `gradient` (0: no gradients asked).
    gradient_columns: usize,
    /// Gradients also carry a robot base's twist.
    gradient_base: bool,
    len: usize,
    /// Set while a call writes the arrays: a second call given the same
    /// `out` meanwhile (from another thread) is refused.
    busy: std::sync::atomic::AtomicBool,
}

/// The field names of [`Distances`], in [`Distances::as_dict`]'s order.
const FIELDS: [&str; 18] = [
    "distance",
    "lower",
    "upper",
    "penetration",
    "point_a",
    "point_b",
    "normal",
    "status",
    "iterations",
    "pieces",
    "error",
    "warm_started",
    "signed_distance",
    "signed_lower",
    "signed_upper",
    "gradient",
    "gradient_flags",
    "gradient_error",
];

#[pymethods]
impl Distances {
    /// Zeroed arrays for `n` pairs, to pass as `out=`, and room for
    /// `gradient_columns` gradient entries per pair (0: no gradients
    /// asked); `gradient_base` asks a robot base's twist too.
    #[new]
    #[pyo3(signature = (n, gradient_columns = 0, gradient_base = false))]
    fn py_new(
        py: Python<'_>,
        n: usize,
        gradient_columns: usize,
        gradient_base: bool,
    ) -> PyResult<Self> {
        check_gradient_room(py, gradient_columns, gradient_base)?;
        Ok(Distances::with_room(py, n, gradient_columns, gradient_base))
    }

    /// `(N, gradient_columns)` float64: each pair's distance gradient.
    #[getter]
    pub(crate) fn gradient<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.gradient.bind(py).clone()
    }

    /// `(N,)` uint32: each pair's gradient flags.
    #[getter]
    pub(crate) fn gradient_flags<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.gradient_flags.bind(py).clone()
    }

    /// `(N,)` float64: a bound on each pair's gradient entries' error.
    #[getter]
    pub(crate) fn gradient_error<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.gradient_error.bind(py).clone()
    }

    fn __len__(&self) -> usize {
        self.len
    }

    /// `(N,)` float64: the distances.
    #[getter]
    fn distance<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.distance.bind(py).clone()
    }

    /// `(N,)` float64: certified lower bounds.
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.lower.bind(py).clone()
    }

    /// `(N,)` float64: certified upper bounds.
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.upper.bind(py).clone()
    }

    /// `(N,)` float64: lower bounds on the penetration depth.
    #[getter]
    fn penetration<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.penetration.bind(py).clone()
    }

    /// `(N, 3)` float64: nearest points on A, world frame.
    #[getter]
    fn point_a<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.point_a.bind(py).clone()
    }

    /// `(N, 3)` float64: nearest points on B, world frame.
    #[getter]
    fn point_b<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.point_b.bind(py).clone()
    }

    /// `(N, 3)` float64: unit normals from A towards B.
    #[getter]
    fn normal<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        self.normal.bind(py).clone()
    }

    /// `(N,)` uint32: `gjkd.Status` values, 0 for failed rows.
    #[getter]
    fn status<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.status.bind(py).clone()
    }

    /// `(N,)` uint32: subalgorithm iterations.
    #[getter]
    fn iterations<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.iterations.bind(py).clone()
    }

    /// `(N, 2)` uint32: the pieces of A and B realising the distance.
    #[getter]
    fn pieces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        self.pieces.bind(py).clone()
    }

    /// `(N,)` uint32: `gjkd.ErrorCode` values, 0 when answered.
    #[getter]
    fn error<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.error.bind(py).clone()
    }

    /// `(N,)` bool: the query started from the pair's last simplex.
    #[getter]
    fn warm_started<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        self.warm_started.bind(py).clone()
    }

    /// `(N,)` float64: the signed distances, NaN in rows without one.
    #[getter]
    fn signed_distance<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.signed_distance.bind(py).clone()
    }

    /// `(N,)` float64: certified lower bounds on the signed distances.
    #[getter]
    fn signed_lower<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.signed_lower.bind(py).clone()
    }

    /// `(N,)` float64: certified upper bounds on the signed distances.
    #[getter]
    fn signed_upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.signed_upper.bind(py).clone()
    }

    /// `(N,)` bool: the rows that were answered (`error == 0`).
    #[getter]
    fn ok<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.error.bind(py).call_method1("__eq__", (0u32,))
    }

    /// The arrays in a dict keyed by field name.
    fn as_dict<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(slf.py());
        for f in FIELDS {
            d.set_item(f, slf.getattr(f)?)?;
        }
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!("<gjkd.Distances of {} pairs>", self.len)
    }
}

impl Distances {
    /// Zeroed arrays for `n` pairs, without gradients.
    pub fn new(py: Python<'_>, n: usize) -> Self {
        Distances::with_room(py, n, 0, false)
    }

    /// Zeroed arrays for `n` pairs and `gradient_columns` gradient entries
    /// per pair (checked by [`check_gradient_room`]).
    pub fn with_room(
        py: Python<'_>,
        n: usize,
        gradient_columns: usize,
        gradient_base: bool,
    ) -> Self {
        Distances {
            distance: PyArray1::zeros(py, n, false).unbind(),
            lower: PyArray1::zeros(py, n, false).unbind(),
            upper: PyArray1::zeros(py, n, false).unbind(),
            penetration: PyArray1::zeros(py, n, false).unbind(),
            point_a: PyArray2::zeros(py, [n, 3], false).unbind(),
            point_b: PyArray2::zeros(py, [n, 3], false).unbind(),
            normal: PyArray2::zeros(py, [n, 3], false).unbind(),
            status: PyArray1::zeros(py, n, false).unbind(),
            iterations: PyArray1::zeros(py, n, false).unbind(),
            pieces: PyArray2::zeros(py, [n, 2], false).unbind(),
            error: PyArray1::zeros(py, n, false).unbind(),
            warm_started: PyArray1::zeros(py, n, false).unbind(),
            signed_distance: PyArray1::from_vec(py, vec![f64::NAN; n]).unbind(),
            signed_lower: PyArray1::from_vec(py, vec![f64::NAN; n]).unbind(),
            signed_upper: PyArray1::from_vec(py, vec![f64::NAN; n]).unbind(),
            gradient: PyArray2::zeros(py, [n, gradient_columns], false).unbind(),
            gradient_flags: PyArray1::zeros(py, n, false).unbind(),
            gradient_error: PyArray1::zeros(py, n, false).unbind(),
            gradient_columns,
            gradient_base,
            len: n,
            busy: std::sync::atomic::AtomicBool::new(false),
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.len
    }

    /// The gradient every call filling these arrays asks: `None`, or
    /// `Some(base)` (with the base twist when `base`).
    pub fn gradient_request(&self) -> Option<bool> {
        (self.gradient_columns > 0).then_some(self.gradient_base)
    }

    /// Runs `fill` with the arrays' storage to write into.
    pub fn with_writer<R>(
        &self,
        py: Python<'_>,
        fill: impl FnOnce(Writer<'_>) -> PyResult<R>,
    ) -> PyResult<R> {
        /// The storage of `a`, an array this object created (C-contiguous).
        /// The storage is numpy's, not the handle's: hence a mutable slice
        /// from a shared handle.
        #[allow(clippy::mut_from_ref)]
        fn storage<'a, T: numpy::Element, D: numpy::ndarray::Dimension>(
            a: &'a Bound<'_, numpy::PyArray<T, D>>,
        ) -> PyResult<&'a mut [T]> {
            // SAFETY: the arrays were created contiguous by `Distances::new`
            // and numpy arrays that own their data cannot be resized while
            // this object references them. No other Rust view of them
            // exists: each field is lent once per call, and `busy` keeps two
            // calls from writing one `Distances` at once. Python code
            // holding a view may read them,
            // also from another thread while the GIL is released, as with
            // any extension that releases it; numpy's borrow tracking,
            // which would catch that, costs more than a one-pair batch.
            Ok(unsafe { a.as_slice_mut() }?)
        }
        let (d, lo, up, pen) = (
            self.distance.bind(py),
            self.lower.bind(py),
            self.upper.bind(py),
            self.penetration.bind(py),
        );
        let (pa, pb, nrm) = (
            self.point_a.bind(py),
            self.point_b.bind(py),
            self.normal.bind(py),
        );
        let (st, it, pc, er, wm) = (
            self.status.bind(py),
            self.iterations.bind(py),
            self.pieces.bind(py),
            self.error.bind(py),
            self.warm_started.bind(py),
        );
        let (sd, slo, sup) = (
            self.signed_distance.bind(py),
            self.signed_lower.bind(py),
            self.signed_upper.bind(py),
        );
        let (gr, gf, ge) = (
            self.gradient.bind(py),
            self.gradient_flags.bind(py),
            self.gradient_error.bind(py),
        );
        use std::sync::atomic::Ordering;
        if self.busy.swap(true, Ordering::Acquire) {
            return Err(invalid(
                py,
                "out",
                None,
                "out is being written by another call".into(),
            ));
        }
        let result = (|| {
            fill(Writer {
                distance: storage(d)?,
                lower: storage(lo)?,
                upper: storage(up)?,
                penetration: storage(pen)?,
                point_a: storage(pa)?,
                point_b: storage(pb)?,
                normal: storage(nrm)?,
                status: storage(st)?,
                iterations: storage(it)?,
                pieces: storage(pc)?,
                error: storage(er)?,
                warm: storage(wm)?,
                signed_distance: storage(sd)?,
                signed_lower: storage(slo)?,
                signed_upper: storage(sup)?,
                gradient: storage(gr)?,
                gradient_flags: storage(gf)?,
                gradient_error: storage(ge)?,
                gradient_columns: self.gradient_columns,
            })
        })();
        self.busy.store(false, Ordering::Release);
        result
    }

    /// `out` if it has `n` rows and is not referenced elsewhere in a way
    /// that stops writing, else new arrays.
    pub fn reuse_or_new(
        py: Python<'_>,
        out: Option<Bound<'_, Distances>>,
        n: usize,
    ) -> PyResult<Py<Distances>> {
        match out {
            Some(o) if o.borrow().len == n => Ok(o.unbind()),
            Some(o) => Err(invalid(
                py,
                "out",
                None,
                format!("out holds {} rows, the call has {n}", o.borrow().len),
            )),
            None => Py::new(py, Distances::new(py, n)),
        }
    }
}

/// The storage of a [`Distances`], writable without the GIL.
pub struct Writer<'a> {
    distance: &'a mut [f64],
    lower: &'a mut [f64],
    upper: &'a mut [f64],
    penetration: &'a mut [f64],
    point_a: &'a mut [f64],
    point_b: &'a mut [f64],
    normal: &'a mut [f64],
    status: &'a mut [u32],
    iterations: &'a mut [u32],
    pieces: &'a mut [u32],
    error: &'a mut [u32],
    warm: &'a mut [bool],
    signed_distance: &'a mut [f64],
    signed_lower: &'a mut [f64],
    signed_upper: &'a mut [f64],
    gradient: &'a mut [f64],
    gradient_flags: &'a mut [u32],
    gradient_error: &'a mut [f64],
    gradient_columns: usize,
}

impl Writer<'_> {
    /// Writes `results` into rows `start..start + results.len()`.
    pub fn write(&mut self, start: usize, results: &[ItemResult]) {
        for (k, r) in results.iter().enumerate() {
            let i = start + k;
            self.distance[i] = r.distance;
            self.lower[i] = r.lower;
            self.upper[i] = r.upper;
            self.penetration[i] = r.penetration;
            self.point_a[3 * i..3 * i + 3].copy_from_slice(&r.point_a);
            self.point_b[3 * i..3 * i + 3].copy_from_slice(&r.point_b);
            self.normal[3 * i..3 * i + 3].copy_from_slice(&r.normal);
            self.status[i] = r.status;
            self.iterations[i] = r.iterations;
            self.pieces[2 * i..2 * i + 2].copy_from_slice(&r.pieces);
            self.error[i] = r.error;
            self.warm[i] = r.flags & result_flags::WARM_STARTED != 0;
            let (v, lo, up) = if r.flags & result_flags::SIGNED_DISTANCE != 0 {
                (r.signed_distance, r.signed_lower, r.signed_upper)
            } else {
                (f64::NAN, f64::NAN, f64::NAN)
            };
            self.signed_distance[i] = v;
            self.signed_lower[i] = lo;
            self.signed_upper[i] = up;
        }
    }

    /// Writes `gradients` into rows `start..start + gradients.len()`,
    /// each cut to the room's columns; nothing when the room has no
    /// gradient columns (none was asked).
    pub fn write_gradients(&mut self, start: usize, gradients: &[Gradient]) {
        let c = self.gradient_columns;
        if c == 0 {
            return;
        }
        for (k, g) in gradients.iter().enumerate() {
            let i = start + k;
            let out = &mut self.gradient[i * c..(i + 1) * c];
            let got = g.as_slice();
            let n = got.len().min(c);
            out[..n].copy_from_slice(&got[..n]);
            out[n..].fill(0.0);
            self.gradient_flags[i] = g.flags;
            self.gradient_error[i] = g.error;
        }
    }
}

/// The answer to one pair query (`Client.distance`, `Local.distance`).
///
/// Distances are after radii; points are in world coordinates.
#[pyclass(frozen, module = "gjkd", name = "Answer")]
#[derive(Clone, Copy)]
pub struct Answer {
    r: ItemResult,
    /// The gradient, [`Gradient::NONE`] when not asked.
    g: Gradient,
}

impl Answer {
    /// The answer in `r`, which holds no error.
    pub fn new(r: ItemResult) -> Self {
        Answer::with_gradient(r, Gradient::NONE)
    }

    /// The answer in `r`, which holds no error, with its gradient `g`
    /// (which travels apart from the result).
    pub fn with_gradient(r: ItemResult, g: Gradient) -> Self {
        Answer { r, g }
    }

    /// Whether the signed-distance fields hold an answer.
    fn signed(&self) -> bool {
        self.r.flags & result_flags::SIGNED_DISTANCE != 0
    }
}

#[pymethods]
impl Answer {
    /// Distance between the (rounded) shapes, `>= 0`.
    #[getter]
    fn distance(&self) -> f64 {
        self.r.distance
    }
    /// Certified lower bound on the distance.
    #[getter]
    fn lower(&self) -> f64 {
        self.r.lower
    }
    /// Certified upper bound on the distance.
    #[getter]
    fn upper(&self) -> f64 {
        self.r.upper
    }
    /// Lower bound on the penetration depth; 0 when separated.
    #[getter]
    fn penetration(&self) -> f64 {
        self.r.penetration
    }
    /// Nearest point on A, world frame, `(x, y, z)`.
    #[getter]
    fn point_a(&self) -> (f64, f64, f64) {
        let [x, y, z] = self.r.point_a;
        (x, y, z)
    }
    /// Nearest point on B, world frame, `(x, y, z)`.
    #[getter]
    fn point_b(&self) -> (f64, f64, f64) {
        let [x, y, z] = self.r.point_b;
        (x, y, z)
    }
    /// Unit vector from A's nearest point towards B's; zero when the cores
    /// touch or intersect.
    #[getter]
    fn normal(&self) -> (f64, f64, f64) {
        let [x, y, z] = self.r.normal;
        (x, y, z)
    }
    /// How the query ended, a `gjkd.Status` value.
    #[getter]
    fn status(&self) -> u32 {
        self.r.status
    }
    /// Subalgorithm iterations (summed over piece pairs for compounds).
    #[getter]
    fn iterations(&self) -> u32 {
        self.r.iterations
    }
    /// Pieces of A and B that realise the distance (0 for convex objects).
    #[getter]
    fn pieces(&self) -> (u32, u32) {
        (self.r.pieces[0], self.r.pieces[1])
    }
    /// The signed distance, when the query asked for it
    /// (`signed_distance=True`), else `None`: the distance apart, minus
    /// the penetration depth (the shortest translation that separates the
    /// shapes) overlapping. `point_a`, `point_b` and `normal` are then its
    /// witnesses and direction, `point_b - point_a = signed_distance *
    /// normal`, also when the shapes overlap.
    #[getter]
    fn signed_distance(&self) -> Option<f64> {
        self.signed().then_some(self.r.signed_distance)
    }
    /// The certified `(lower, upper)` interval of the signed distance,
    /// when the query asked for it, else `None`.
    #[getter]
    fn signed_interval(&self) -> Option<(f64, f64)> {
        self.signed()
            .then_some((self.r.signed_lower, self.r.signed_upper))
    }
    /// The query started from the pair's last simplex.
    #[getter]
    fn warm_started(&self) -> bool {
        self.r.flags & result_flags::WARM_STARTED != 0
    }
    /// The Backup Procedure ran (a numerically hard case).
    #[getter]
    fn backup_used(&self) -> bool {
        self.r.flags & result_flags::BACKUP_USED != 0
    }
    /// With `gradient=True`: `(columns,)` float64, the distance's gradient
    /// with respect to the coordinates that move `a` (its robot's moving
    /// joints in `Robot.joint_names` order, then with `gradient_base` the
    /// base twist `[v, ω]`; any other object, its pose's twist); `None`
    /// when not asked. For overlapping objects, the signed distance's.
    #[getter]
    fn gradient<'py>(&self, py: Python<'py>) -> Option<Bound<'py, numpy::PyArray1<f64>>> {
        let g = &self.g;
        g.is_present()
            .then(|| numpy::PyArray1::from_slice(py, g.as_slice()))
    }
    /// The nearest points are not unique (parallel faces or edges): the
    /// gradient is a one-sided one.
    #[getter]
    fn gradient_not_unique(&self) -> bool {
        self.g.is_not_unique()
    }
    /// A bound on each gradient entry's error from the distance's
    /// certified interval.
    #[getter]
    fn gradient_error(&self) -> f64 {
        self.g.error
    }

    fn __repr__(&self) -> String {
        format!(
            "Answer(distance={}, lower={}, upper={}, status={})",
            self.r.distance, self.r.lower, self.r.upper, self.r.status
        )
    }
}
