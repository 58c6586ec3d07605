//! Meshes from Python: a triangle mesh given as numpy arrays or read from a
//! file (STL, OBJ, COLLADA), registered as its convex hull or, on request,
//! as a convex decomposition, on a `gjkd.Client` and a `gjkd.Local` alike.

use std::path::PathBuf;

use numpy::{PyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;

use gjkd_client::{MAX_PIECES, Mesh};
use gjkd_proto::Pose;
use nalgebra::Point3;

use crate::arrays::{points, slice};
use crate::backend::{Backend, checked_pose};
use crate::errors::invalid;
use crate::shape::{Pieces, Registration, Shape, ShapeKind};

/// How a registered mesh is shaped: its hull, or a decomposition at a
/// resolution.
pub struct MeshArgs<'a, 'py> {
    /// Per-axis scale: a float or three.
    pub scale: Option<&'a Bound<'py, PyAny>>,
    /// V-HACD resolution, or `None` for the hull.
    pub decompose: Option<u32>,
    /// Unique name.
    pub name: Option<&'a str>,
    /// Initial pose.
    pub pose: Option<&'a Bound<'py, PyAny>>,
    /// Where to write what the registration made, if anywhere.
    pub info: Option<&'a Bound<'py, MeshInfo>>,
}

/// What a mesh registration made: pass one as `info=` to `register_mesh`
/// or `register_mesh_file`, and read it after the call (it is written only
/// when the registration succeeds).
///
/// - `pieces`: convex pieces, 1 for a hull;
/// - `deviation`: for a decomposition, the largest distance found by which
///   the pieces reach beyond the mesh (so how much less distance they may
///   report than the mesh itself); 0 for a hull, which never reports more
///   distance than the mesh and never less than its convex hull.
#[pyclass(module = "gjkd", name = "MeshInfo")]
#[derive(Default)]
pub struct MeshInfo {
    pieces: usize,
    deviation: f64,
}

#[pymethods]
impl MeshInfo {
    /// Zeroed, to be filled by a registration.
    #[new]
    fn new() -> Self {
        MeshInfo::default()
    }

    /// Convex pieces: 1 for a hull.
    #[getter]
    fn pieces(&self) -> usize {
        self.pieces
    }

    /// The largest deviation found of a decomposition from the mesh; 0 for
    /// a hull.
    #[getter]
    fn deviation(&self) -> f64 {
        self.deviation
    }

    fn __repr__(&self) -> String {
        format!(
            "gjkd.MeshInfo(pieces={}, deviation={:e})",
            self.pieces, self.deviation
        )
    }
}

/// The scale argument: `None` (1), one float, or three.
fn scale(py: Python<'_>, obj: Option<&Bound<'_, PyAny>>) -> PyResult<[f64; 3]> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok([1.0; 3]);
    };
    if let Ok(s) = obj.extract::<f64>() {
        return Ok([s; 3]);
    }
    obj.extract::<[f64; 3]>().map_err(|_| {
        invalid(
            py,
            "scale",
            None,
            "scale must be a float or three floats".into(),
        )
    })
}

/// Triangles `(M, 3)` of any integer dtype, as vertex indices.
fn triangles(obj: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 3]>> {
    let py = obj.py();
    let bad = |why: String| invalid(py, "triangles", None, why);
    let np = py.import("numpy")?;
    let array = np.call_method1("asarray", (obj,))?;
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    if kind != "i" && kind != "u" {
        return Err(bad(format!(
            "triangles must be an integer array, got dtype kind {kind:?}"
        )));
    }
    let array = np
        .call_method1("ascontiguousarray", (array, "int64"))?
        .cast_into::<PyArrayDyn<i64>>()?;
    let shape = array.shape().to_vec();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(bad(format!(
            "triangles must have shape (M, 3), got {shape:?}"
        )));
    }
    slice(&array)?
        .chunks_exact(3)
        .enumerate()
        .map(|(row, t)| {
            let index = |v: i64| u32::try_from(v).ok();
            match (index(t[0]), index(t[1]), index(t[2])) {
                (Some(a), Some(b), Some(c)) => Ok([a, b, c]),
                _ => Err(invalid(
                    py,
                    "triangles",
                    Some(row),
                    format!("triangle {row} has an index outside 0..2^32"),
                )),
            }
        })
        .collect()
}

/// `mesh` as a shape to register: its hull, or its decomposition's pieces.
fn shaped(py: Python<'_>, mesh: &Mesh, decompose: Option<u32>) -> PyResult<Shaped> {
    let polytope = |vertices: Vec<Point3<f64>>| Shape {
        kind: ShapeKind::Polytope {
            vertices,
            radius: 0.0,
        },
    };
    let Some(resolution) = decompose else {
        let hull = py.detach(|| mesh.hull());
        return Ok(Shaped::Hull(polytope(hull)));
    };
    if resolution == 0 {
        return Err(invalid(
            py,
            "decompose",
            None,
            "decompose must be a resolution of at least 1 (64 is a fair start)".into(),
        ));
    }
    let parts = py
        .detach(|| mesh.decompose(resolution))
        .map_err(|e| invalid(py, "decompose", None, e.to_string()))?;
    if parts.pieces.len() > MAX_PIECES {
        return Err(invalid(
            py,
            "decompose",
            None,
            format!(
                "the decomposition has {} pieces, more than the {MAX_PIECES} a compound takes: \
                 use a coarser resolution",
                parts.pieces.len()
            ),
        ));
    }
    Ok(Shaped::Pieces(
        Pieces {
            offsets: vec![Pose::IDENTITY; parts.pieces.len()],
            shapes: parts.pieces.into_iter().map(polytope).collect(),
        },
        parts.deviation,
    ))
}

impl MeshInfo {
    /// What a hull registration made.
    fn default_hull() -> Self {
        MeshInfo {
            pieces: 1,
            deviation: 0.0,
        }
    }
}

/// A mesh made ready to register.
enum Shaped {
    Hull(Shape),
    /// The pieces and their largest deviation found from the mesh.
    Pieces(Pieces, f64),
}

/// Registers `mesh` with `args`; returns its id.
fn register(
    backend: &mut dyn Backend,
    py: Python<'_>,
    mesh: Mesh,
    args: &MeshArgs<'_, '_>,
) -> PyResult<u64> {
    let pose = checked_pose(py, args.pose, "pose")?;
    let factors = scale(py, args.scale)?;
    let mesh = mesh
        .scaled(factors)
        .map_err(|e| invalid(py, "scale", None, e.to_string()))?;
    let (id, made) = match shaped(py, &mesh, args.decompose)? {
        Shaped::Hull(shape) => {
            let id = backend.register(py, &Registration::Convex(&shape), args.name, pose)?;
            (id, MeshInfo::default_hull())
        }
        Shaped::Pieces(pieces, deviation) => {
            let made = MeshInfo {
                pieces: pieces.shapes.len(),
                deviation,
            };
            let id = backend.register(py, &Registration::Compound(&pieces), args.name, pose)?;
            (id, made)
        }
    };
    if let Some(info) = args.info {
        *info.borrow_mut() = made;
    }
    Ok(id)
}

/// Registers the mesh of `vertices` (`(N, 3)` float64) and `triangles`
/// (`(M, 3)` integers, optional for a hull).
pub fn register_mesh(
    backend: &mut dyn Backend,
    py: Python<'_>,
    vertices: &Bound<'_, PyAny>,
    triangle_obj: Option<&Bound<'_, PyAny>>,
    args: &MeshArgs<'_, '_>,
) -> PyResult<u64> {
    let vertices = points(vertices, "vertices")?;
    let tris = match triangle_obj.filter(|t| !t.is_none()) {
        Some(t) => triangles(t)?,
        None => Vec::new(),
    };
    if args.decompose.is_some() && tris.is_empty() {
        return Err(invalid(
            py,
            "triangles",
            None,
            "a decomposition needs the mesh's triangles".into(),
        ));
    }
    let mesh = Mesh::from_arrays(vertices, tris).map_err(|e| {
        let field = match e {
            gjkd_client::MeshError::BadIndex { .. } => "triangles",
            _ => "vertices",
        };
        let row = match e {
            gjkd_client::MeshError::BadIndex { triangle, .. } => Some(triangle),
            _ => None,
        };
        invalid(py, field, row, e.to_string())
    })?;
    register(backend, py, mesh, args)
}

/// Registers the mesh in the file at `path`.
pub fn register_mesh_file(
    backend: &mut dyn Backend,
    py: Python<'_>,
    path: PathBuf,
    args: &MeshArgs<'_, '_>,
) -> PyResult<u64> {
    let mesh = py
        .detach(|| Mesh::load(&path, [1.0; 3]))
        .map_err(|e| invalid(py, "path", None, e.to_string()))?;
    register(backend, py, mesh, args)
}
