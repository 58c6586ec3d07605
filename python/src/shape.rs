//! `gjkd.Shape`: a convex shape described in Python, as the protocol's
//! shape table (`Geometry`) for the Rust client, and in its wire form
//! (written by that same table) for `gjkd.Local`.

use nalgebra::{Isometry3, Point3, Vector3};
use numpy::PyArray2;
use pyo3::PyTypeInfo;
use pyo3::prelude::*;
use pyo3::types::{PyAnyMethods, PyList};

use gjkd_client::{Geometry, MAX_NAME_LEN, MAX_PIECES, Piece};
use gjkd_proto::{AdminOp, AdminRequest, Pose, Vertex, cuboid_corners};

use crate::arrays::{point, points, pose};
use crate::errors::invalid;

/// A convex shape to register: build one with `Shape.sphere`,
/// `Shape.capsule`, `Shape.box`, `Shape.cylinder` or `Shape.polytope`, then pass it to
/// `register` or, as a piece, to `register_compound`.
///
/// Every shape is the convex hull of its vertices grown by a radius
/// ("rounding"); distances are between the grown shapes.
#[pyclass(frozen, module = "gjkd", name = "Shape")]
#[derive(Clone, Debug)]
pub struct Shape {
    pub(crate) kind: ShapeKind,
}

/// What a [`Shape`] is.
#[derive(Clone, Debug)]
pub enum ShapeKind {
    /// A ball about the body origin.
    Sphere { radius: f64 },
    /// A segment grown by a radius.
    Capsule {
        a: Point3<f64>,
        b: Point3<f64>,
        radius: f64,
    },
    /// A box centred on the body origin.
    Box { half: Vector3<f64>, radius: f64 },
    /// An exact cylinder about the body z axis, its rims rounded by
    /// `radius`.
    Cylinder {
        disk: f64,
        half_height: f64,
        radius: f64,
    },
    /// A convex hull.
    Polytope {
        vertices: Vec<Point3<f64>>,
        radius: f64,
    },
}

#[pymethods]
impl Shape {
    /// A ball of `radius` about the body origin.
    #[staticmethod]
    pub(crate) fn sphere(radius: f64) -> Self {
        Shape {
            kind: ShapeKind::Sphere { radius },
        }
    }

    /// The segment from `a` to `b` (each three floats, body frame) grown by
    /// `radius`.
    #[staticmethod]
    pub(crate) fn capsule(
        a: &Bound<'_, PyAny>,
        b: &Bound<'_, PyAny>,
        radius: f64,
    ) -> PyResult<Self> {
        Ok(Shape {
            kind: ShapeKind::Capsule {
                a: point(a, "a")?,
                b: point(b, "b")?,
                radius,
            },
        })
    }

    /// A box centred on the body origin with these half extents (three
    /// floats, each finite and `>= 0`), its edges rounded by `radius`.
    #[staticmethod]
    #[pyo3(name = "box", signature = (half_extents, radius = 0.0))]
    pub(crate) fn cuboid(
        py: Python<'_>,
        half_extents: &Bound<'_, PyAny>,
        radius: f64,
    ) -> PyResult<Self> {
        let h = point(half_extents, "half_extents")?.coords;
        if !h.iter().all(|v| v.is_finite() && *v >= 0.0) {
            return Err(invalid(
                py,
                "half_extents",
                None,
                "half_extents must be finite and >= 0".into(),
            ));
        }
        Ok(Shape {
            kind: ShapeKind::Box { half: h, radius },
        })
    }

    /// An exact cylinder about the body z axis, centred on the body origin:
    /// the disk of `radius` swept from `z = -half_height` to
    /// `z = +half_height`, its rims rounded by `rounding` (the shape's
    /// `radius` attribute). Never approximated by a polytope.
    #[staticmethod]
    #[pyo3(signature = (radius, half_height, rounding = 0.0))]
    pub(crate) fn cylinder(radius: f64, half_height: f64, rounding: f64) -> Self {
        Shape {
            kind: ShapeKind::Cylinder {
                disk: radius,
                half_height,
                radius: rounding,
            },
        }
    }

    /// The convex hull of `vertices`, an `(N, 3)` float64 array (N >= 1;
    /// they need not be hull vertices), grown by `radius`.
    #[staticmethod]
    #[pyo3(signature = (vertices, radius = 0.0))]
    pub(crate) fn polytope(vertices: &Bound<'_, PyAny>, radius: f64) -> PyResult<Self> {
        Ok(Shape {
            kind: ShapeKind::Polytope {
                vertices: points(vertices, "vertices")?,
                radius,
            },
        })
    }

    /// `"sphere"`, `"capsule"`, `"box"`, `"cylinder"` or `"polytope"`.
    #[getter]
    fn kind(&self) -> &'static str {
        match self.kind {
            ShapeKind::Sphere { .. } => "sphere",
            ShapeKind::Capsule { .. } => "capsule",
            ShapeKind::Box { .. } => "box",
            ShapeKind::Cylinder { .. } => "cylinder",
            ShapeKind::Polytope { .. } => "polytope",
        }
    }

    /// The rounding radius (a cylinder's `rounding`).
    #[getter]
    fn radius(&self) -> f64 {
        match self.kind {
            ShapeKind::Sphere { radius }
            | ShapeKind::Capsule { radius, .. }
            | ShapeKind::Box { radius, .. }
            | ShapeKind::Cylinder { radius, .. }
            | ShapeKind::Polytope { radius, .. } => radius,
        }
    }

    /// The vertices the shape is the hull of, `(N, 3)` float64, in the
    /// order the server stores them (a sphere is its centre, a box its 8
    /// corners; a cylinder, which is no hull, has none).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let mut v = Vec::new();
        self.push_vertices(&mut v);
        if v.is_empty() {
            return PyArray2::zeros(py, [0, 3], false);
        }
        let rows: Vec<Vec<f64>> = v.iter().map(|p| vec![p.x, p.y, p.z]).collect();
        PyArray2::from_vec2(py, &rows).unwrap_or_else(|_| PyArray2::zeros(py, [0, 3], false))
    }

    fn __repr__(&self) -> String {
        match &self.kind {
            ShapeKind::Sphere { radius } => format!("Shape.sphere({radius})"),
            ShapeKind::Capsule { a, b, radius } => format!(
                "Shape.capsule(({}, {}, {}), ({}, {}, {}), {radius})",
                a.x, a.y, a.z, b.x, b.y, b.z
            ),
            ShapeKind::Box { half, radius } => {
                format!("Shape.box(({}, {}, {}), {radius})", half.x, half.y, half.z)
            }
            ShapeKind::Cylinder {
                disk,
                half_height,
                radius,
            } => format!("Shape.cylinder({disk}, {half_height}, {radius})"),
            ShapeKind::Polytope { vertices, radius } => {
                format!("Shape.polytope(<{} vertices>, {radius})", vertices.len())
            }
        }
    }
}

impl Shape {
    /// The shape as the Rust client's geometry.
    pub fn geometry(&self) -> Geometry<'_> {
        match &self.kind {
            ShapeKind::Sphere { radius } => Geometry::Sphere { radius: *radius },
            ShapeKind::Capsule { a, b, radius } => Geometry::Capsule {
                a: *a,
                b: *b,
                radius: *radius,
            },
            ShapeKind::Box { half, radius } => Geometry::Cuboid {
                half_extents: *half,
                radius: *radius,
            },
            ShapeKind::Cylinder {
                disk,
                half_height,
                radius,
            } => Geometry::Cylinder {
                radius: *disk,
                half_height: *half_height,
                rounding: *radius,
            },
            ShapeKind::Polytope { vertices, radius } => Geometry::Polytope {
                vertices,
                radius: *radius,
            },
        }
    }

    /// Appends the vertices the shape is the hull of, in the order the
    /// wire carries them (the `gjk` constructors' order).
    fn push_vertices(&self, out: &mut Vec<Point3<f64>>) {
        match &self.kind {
            ShapeKind::Sphere { .. } => out.push(Point3::origin()),
            ShapeKind::Capsule { a, b, .. } => out.extend([*a, *b]),
            ShapeKind::Box { half, .. } => out.extend(cuboid_corners(half)),
            ShapeKind::Cylinder { .. } => {}
            ShapeKind::Polytope { vertices, .. } => out.extend_from_slice(vertices),
        }
    }
}

/// A compound's pieces read from Python: `(pose, Shape)` pairs.
pub struct Pieces {
    /// Offsets, as given (wire form).
    pub offsets: Vec<Pose>,
    /// Shapes.
    pub shapes: Vec<Shape>,
}

impl Pieces {
    /// Reads `[(pose, shape), ...]`; a pose is `(7,)` or `(4, 4)`.
    pub fn read(pieces: &Bound<'_, PyAny>) -> PyResult<Self> {
        let py = pieces.py();
        let list = PyList::type_object(py).call1((pieces,)).map_err(|_| {
            invalid(
                py,
                "pieces",
                None,
                "pieces must be a sequence of (pose, Shape)".into(),
            )
        })?;
        let list = list.cast::<PyList>()?;
        if list.len() > MAX_PIECES {
            return Err(invalid(
                py,
                "pieces",
                None,
                format!("at most {MAX_PIECES} pieces"),
            ));
        }
        let mut out = Pieces {
            offsets: Vec::with_capacity(list.len()),
            shapes: Vec::with_capacity(list.len()),
        };
        for (i, item) in list.iter().enumerate() {
            let bad = || {
                invalid(
                    py,
                    "pieces",
                    Some(i),
                    format!("piece {i} is not a (pose, Shape) pair"),
                )
            };
            let (p, s): (Bound<'_, PyAny>, Bound<'_, PyAny>) = item.extract().map_err(|_| bad())?;
            let shape = s.cast::<Shape>().map_err(|_| bad())?.get().clone();
            let offset = pose(Some(&p), "pieces")?.unwrap_or(Pose::IDENTITY);
            out.offsets.push(offset);
            out.shapes.push(shape);
        }
        Ok(out)
    }

    /// The pieces as the Rust client's, with offsets taken as they are
    /// (the server checks them).
    pub fn client_pieces(&self) -> Vec<Piece<'_>> {
        self.offsets
            .iter()
            .zip(&self.shapes)
            .map(|(o, s)| Piece {
                offset: o.to_isometry_unchecked(),
                geometry: s.geometry(),
            })
            .collect()
    }
}

/// What to register: one convex shape or a compound.
pub enum Registration<'a> {
    /// One convex shape.
    Convex(&'a Shape),
    /// A union of pieces.
    Compound(&'a Pieces),
}

/// The wire registration the Rust client would send for `what`, named
/// `name`, at `pose`: the request header and the vertices.
pub fn wire_registration(
    py: Python<'_>,
    what: &Registration<'_>,
    name: Option<&str>,
    pose: Pose,
) -> PyResult<(AdminRequest, Vec<Vertex>)> {
    let mut request = AdminRequest::new(AdminOp::Register);
    request.pose = pose;
    if let Some(name) = name
        && !request.set_name(name)
    {
        return Err(invalid(
            py,
            "name",
            None,
            format!("name longer than {MAX_NAME_LEN} bytes"),
        ));
    }
    let mut vertices = Vec::new();
    let pieces;
    let geometry = match what {
        Registration::Convex(shape) => shape.geometry(),
        Registration::Compound(list) => {
            pieces = list.client_pieces();
            Geometry::Compound(&pieces)
        }
    };
    geometry
        .encode(&mut request, &mut vertices)
        .map_err(|e| invalid(py, "shape", None, e.to_string()))?;
    Ok((request, vertices))
}

/// `pose` as an isometry taken as it is, for the Rust client (the server
/// checks it).
pub fn isometry(pose: &Pose) -> Isometry3<f64> {
    pose.to_isometry_unchecked()
}
