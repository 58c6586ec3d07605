//! numpy inputs: ids, poses and vertices read as contiguous slices, with an
//! `InvalidInput` naming the argument for every wrong shape or dtype.
//!
//! Arrays must already have the right dtype (float64 for numbers, an
//! integer type for ids): converting a float32 or integer array silently
//! would hide a mistake in the caller's data. Python sequences (lists,
//! tuples) are converted, since they carry no dtype to be wrong about.

use nalgebra::{Matrix3, Point3, Rotation3, UnitQuaternion};
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyAnyMethods;

use gjkd_proto::Pose;

use crate::errors::invalid;

/// A contiguous numpy array of `T`.
pub type Array<'py, T> = Bound<'py, PyArrayDyn<T>>;

/// The elements of `a`, a C-contiguous array (as every function here
/// returns).
///
/// numpy's own borrow tracking (`PyReadonlyArray`) costs a few hundred
/// nanoseconds an array, which a batch of one pair pays several times over;
/// like any C extension, this one instead reads the buffer directly.
pub fn slice<'a, T: numpy::Element>(a: &'a Array<'_, T>) -> PyResult<&'a [T]> {
    // SAFETY: the slice lives no longer than the borrow of `a`, which keeps
    // the array alive; this crate holds no mutable view of input arrays.
    // Another Python thread may write the array while the GIL is released,
    // as with any extension that releases it: numpy leaves that to the
    // caller.
    Ok(unsafe { a.as_slice() }?)
}

/// A float64 array, contiguous.
pub fn f64_array<'py>(obj: &Bound<'py, PyAny>, field: &str) -> PyResult<Array<'py, f64>> {
    array_of::<f64>(obj, field, "float64")
}

/// An id array: uint64, or int64 with no negative entry.
pub fn id_array<'py>(obj: &Bound<'py, PyAny>, field: &str) -> PyResult<IdArray<'py>> {
    let py = obj.py();
    if let Ok(a) = obj.cast::<PyArrayDyn<i64>>() {
        let a = contiguous(a.clone().into_any(), field)?.cast_into::<PyArrayDyn<i64>>()?;
        if let Some(i) = slice(&a)?.iter().position(|&v| v < 0) {
            let row = i / a.shape().iter().skip(1).product::<usize>().max(1);
            return Err(invalid(
                py,
                field,
                Some(row),
                format!("{field}: negative id (row {row})"),
            ));
        }
        return Ok(IdArray::Signed(a));
    }
    array_of::<u64>(obj, field, "uint64 (or int64)").map(IdArray::Unsigned)
}

/// [`id_array`] of shape `(N,)`: `InvalidInput` naming `field` for any
/// other shape.
pub fn id_vector<'py>(obj: &Bound<'py, PyAny>, field: &str) -> PyResult<IdArray<'py>> {
    let ids = id_array(obj, field)?;
    if ids.shape().len() != 1 {
        return Err(invalid(
            obj.py(),
            field,
            None,
            format!("{field} must have shape (N,), got {:?}", ids.shape()),
        ));
    }
    Ok(ids)
}

/// Ids read either way.
pub enum IdArray<'py> {
    /// From an int64 array, none negative.
    Signed(Array<'py, i64>),
    /// From a uint64 array.
    Unsigned(Array<'py, u64>),
}

impl IdArray<'_> {
    /// The array's shape.
    pub fn shape(&self) -> &[usize] {
        match self {
            IdArray::Signed(a) => a.shape(),
            IdArray::Unsigned(a) => a.shape(),
        }
    }

    /// The ids, in order. An int64 id is never negative here, so the cast
    /// keeps its value.
    pub fn slice(&self) -> PyResult<Ids<'_>> {
        Ok(match self {
            IdArray::Signed(a) => Ids::Signed(slice(a)?),
            IdArray::Unsigned(a) => Ids::Unsigned(slice(a)?),
        })
    }
}

/// A view of ids that can cross into code that runs without the GIL.
#[derive(Clone, Copy)]
pub enum Ids<'a> {
    /// Non-negative int64 ids.
    Signed(&'a [i64]),
    /// uint64 ids.
    Unsigned(&'a [u64]),
}

impl Ids<'_> {
    /// Id `i`.
    #[inline]
    pub fn get(&self, i: usize) -> u64 {
        match self {
            Ids::Signed(s) => s[i] as u64,
            Ids::Unsigned(s) => s[i],
        }
    }

    /// How many.
    pub fn len(&self) -> usize {
        match self {
            Ids::Signed(s) => s.len(),
            Ids::Unsigned(s) => s.len(),
        }
    }
}

fn array_of<'py, T: numpy::Element>(
    obj: &Bound<'py, PyAny>,
    field: &str,
    want: &str,
) -> PyResult<Array<'py, T>> {
    let py = obj.py();
    let array = if let Ok(untyped) = obj.cast::<PyUntypedArray>() {
        if obj.cast::<PyArrayDyn<T>>().is_err() {
            let got = untyped.dtype().str()?.to_string();
            return Err(invalid(
                py,
                field,
                None,
                format!("{field} must be a {want} array, got dtype {got}"),
            ));
        }
        contiguous(obj.clone(), field)?
    } else {
        let numpy = py.import("numpy")?;
        let dtype = numpy.getattr(want.split(' ').next().unwrap_or(want))?;
        match numpy.call_method1("asarray", (obj, dtype)) {
            Ok(a) => a,
            Err(e) => {
                return Err(invalid(
                    py,
                    field,
                    None,
                    format!("{field} cannot be read as {want}: {e}"),
                ));
            }
        }
    };
    Ok(array.cast_into::<PyArrayDyn<T>>()?)
}

/// `obj` if C-contiguous, else a contiguous copy.
fn contiguous<'py>(obj: Bound<'py, PyAny>, field: &str) -> PyResult<Bound<'py, PyAny>> {
    let untyped = obj.cast::<PyUntypedArray>()?;
    if untyped.is_c_contiguous() {
        return Ok(obj);
    }
    let py = obj.py();
    py.import("numpy")?
        .call_method1("ascontiguousarray", (&obj,))
        .map_err(|e| invalid(py, field, None, format!("{field}: {e}")))
}

/// `(N, 3)` float64 vertices, as points.
pub fn points(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<Vec<Point3<f64>>> {
    let a = f64_array(obj, field)?;
    let shape = a.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(invalid(
            obj.py(),
            field,
            None,
            format!("{field} must have shape (N, 3), got {shape:?}"),
        ));
    }
    Ok(slice(&a)?
        .chunks_exact(3)
        .map(|c| Point3::new(c[0], c[1], c[2]))
        .collect())
}

/// One point of three floats.
pub fn point(obj: &Bound<'_, PyAny>, field: &str) -> PyResult<Point3<f64>> {
    let a = f64_array(obj, field)?;
    if a.shape() != [3] {
        return Err(invalid(
            obj.py(),
            field,
            None,
            format!("{field} must have shape (3,), got {:?}", a.shape()),
        ));
    }
    let s = slice(&a)?;
    Ok(Point3::new(s[0], s[1], s[2]))
}

/// How a pose array is laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Rows of `[x, y, z, qx, qy, qz, qw]`.
    Quaternion,
    /// Row-major 4 × 4 homogeneous matrices.
    Matrix,
}

impl Layout {
    fn width(self) -> usize {
        match self {
            Layout::Quaternion => 7,
            Layout::Matrix => 16,
        }
    }
}

/// Poses read from an array, without the GIL.
#[derive(Clone, Copy)]
pub struct Poses<'a> {
    data: &'a [f64],
    layout: Layout,
}

impl<'a> Poses<'a> {
    /// Rows of `[x, y, z, qx, qy, qz, qw]`.
    pub fn rows(data: &'a [f64]) -> Self {
        Poses {
            data,
            layout: Layout::Quaternion,
        }
    }

    /// Pose `i` on the wire.
    #[inline]
    pub fn get(&self, i: usize) -> Pose {
        let w = self.layout.width();
        let row = &self.data[i * w..(i + 1) * w];
        match self.layout {
            Layout::Quaternion => Pose {
                translation: [row[0], row[1], row[2]],
                rotation: [row[3], row[4], row[5], row[6]],
            },
            Layout::Matrix => pose_of_matrix(row),
        }
    }

    /// How many.
    pub fn len(&self) -> usize {
        self.data.len() / self.layout.width()
    }
}

/// A pose array and its layout, held while its slice is in use.
pub struct PoseArray<'py> {
    array: Array<'py, f64>,
    layout: Layout,
}

impl PoseArray<'_> {
    /// The poses.
    pub fn poses(&self) -> PyResult<Poses<'_>> {
        Ok(Poses {
            data: slice(&self.array)?,
            layout: self.layout,
        })
    }
}

/// `(N, 7)` or `(N, 4, 4)` poses.
pub fn pose_array<'py>(obj: &Bound<'py, PyAny>, field: &str) -> PyResult<PoseArray<'py>> {
    let array = f64_array(obj, field)?;
    let layout = match array.shape() {
        [_, 7] => Layout::Quaternion,
        [_, 4, 4] => Layout::Matrix,
        shape => {
            return Err(invalid(
                obj.py(),
                field,
                None,
                format!("{field} must have shape (N, 7) or (N, 4, 4), got {shape:?}"),
            ));
        }
    };
    Ok(PoseArray { array, layout })
}

/// One pose: `(7,)` or `(4, 4)`; `None` stands for no pose.
pub fn pose(obj: Option<&Bound<'_, PyAny>>, field: &str) -> PyResult<Option<Pose>> {
    let Some(obj) = obj else { return Ok(None) };
    if obj.is_none() {
        return Ok(None);
    }
    let a = f64_array(obj, field)?;
    let s = slice(&a)?;
    match a.shape() {
        [7] => Ok(Some(Pose {
            translation: [s[0], s[1], s[2]],
            rotation: [s[3], s[4], s[5], s[6]],
        })),
        [4, 4] => Ok(Some(pose_of_matrix(s))),
        shape => Err(invalid(
            obj.py(),
            field,
            None,
            format!("{field} must have shape (7,) or (4, 4), got {shape:?}"),
        )),
    }
}

/// How far a matrix's rotation block may be from orthonormal, entry by
/// entry, and its bottom row from `[0, 0, 0, 1]`: the server's tolerance on
/// a quaternion's length.
const RIGID_TOLERANCE: f64 = 1e-6;

/// The wire pose of a row-major 4 × 4 matrix. A matrix with a NaN or
/// infinite entry gets a NaN translation, one that is not a rigid motion a
/// zero quaternion, so that the server (or `gjkd.local`) answers
/// `NON_FINITE_POSE` or `BAD_QUATERNION` for it like for any other pose.
pub fn pose_of_matrix(m: &[f64]) -> Pose {
    if !m.iter().all(|v| v.is_finite()) {
        return Pose {
            translation: [f64::NAN; 3],
            rotation: [0.0, 0.0, 0.0, 1.0],
        };
    }
    let translation = [m[3], m[7], m[11]];
    let r = Matrix3::new(m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]);
    let off_identity = (r.transpose() * r - Matrix3::identity()).abs().max();
    let bottom = (m[12].abs())
        .max(m[13].abs())
        .max(m[14].abs())
        .max((m[15] - 1.0).abs());
    if off_identity > RIGID_TOLERANCE || bottom > RIGID_TOLERANCE || r.determinant() <= 0.0 {
        return Pose {
            translation,
            rotation: [0.0; 4],
        };
    }
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    let c = q.coords;
    Pose {
        translation,
        rotation: [c.x, c.y, c.z, c.w],
    }
}
