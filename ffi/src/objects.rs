//! Registering, looking up and removing objects.

use std::ffi::c_char;
use std::ops::Range;

use nalgebra::{Point3, Vector3};
use rust_client::{Geometry, ObjectId, Piece};

use crate::args::{checked_pose, opt_str, out, req_str, required, slice, vec3};
use crate::handle::{gjkd_client, with_client};
use crate::status::{Failure, gjkd_status, guard};
use crate::types::{gjkd_id, gjkd_piece, gjkd_pose, gjkd_shape, gjkd_shape_kind};

/// A shape read from C, its polytope vertices as a range of a shared
/// point buffer (so that the pieces of a compound can borrow from one
/// buffer filled first).
enum Convex {
    Sphere(f64),
    Capsule([f64; 3], [f64; 3], f64),
    Box([f64; 3], f64),
    /// Radius, half-height, rounding.
    Cylinder(f64, f64, f64),
    Polytope(Range<usize>, f64),
}

impl Convex {
    /// Reads `shape`, appending its vertices to `points`.
    ///
    /// # Safety
    /// `shape.vertices` is NULL or points to `3 * shape.vertex_count`
    /// doubles.
    unsafe fn read(
        shape: &gjkd_shape,
        points: &mut Vec<Point3<f64>>,
        what: &str,
    ) -> Result<Self, Failure> {
        use gjkd_shape_kind::*;
        Ok(match shape.kind {
            k if k == GJKD_SHAPE_SPHERE as u32 => Convex::Sphere(shape.radius),
            k if k == GJKD_SHAPE_CAPSULE as u32 => Convex::Capsule(shape.a, shape.b, shape.radius),
            k if k == GJKD_SHAPE_BOX as u32 => Convex::Box(shape.a, shape.radius),
            k if k == GJKD_SHAPE_CYLINDER as u32 => {
                Convex::Cylinder(shape.a[0], shape.a[1], shape.radius)
            }
            k if k == GJKD_SHAPE_POLYTOPE as u32 => {
                let name = format!("{what}.vertices");
                // SAFETY: the caller's promise.
                let vertices =
                    unsafe { slice(shape.vertices.cast::<[f64; 3]>(), shape.vertex_count, &name) }?;
                let start = points.len();
                points.extend(vertices.iter().map(|&v| Point3::from(v)));
                Convex::Polytope(start..points.len(), shape.radius)
            }
            k => {
                return Err(Failure::invalid(format!(
                    "{what}.kind {k} is not a gjkd_shape_kind"
                )));
            }
        })
    }

    /// The client's geometry, its vertices borrowed from `points`.
    fn geometry<'a>(&self, points: &'a [Point3<f64>]) -> Geometry<'a> {
        match *self {
            Convex::Sphere(radius) => Geometry::Sphere { radius },
            Convex::Capsule(a, b, radius) => Geometry::Capsule {
                a: Point3::from(a),
                b: Point3::from(b),
                radius,
            },
            Convex::Box(h, radius) => Geometry::Cuboid {
                half_extents: Vector3::from(h),
                radius,
            },
            Convex::Cylinder(radius, half_height, rounding) => Geometry::Cylinder {
                radius,
                half_height,
                rounding,
            },
            Convex::Polytope(ref range, radius) => Geometry::Polytope {
                vertices: &points[range.clone()],
                radius,
            },
        }
    }
}

/// What a registration reads from its arguments.
enum Built {
    /// One convex shape.
    Convex(Convex),
    /// Pieces and their offsets.
    Compound(Vec<(gjkd_pose, Convex)>),
}

/// Registers `geometry` with an optional name and pose, writing its id.
fn register(
    c: &mut gjkd_client,
    geometry: &Geometry<'_>,
    name: Option<&str>,
    pose: Option<&gjkd_pose>,
    out_id: &mut gjkd_id,
) -> Result<(), Failure> {
    if let Some(p) = pose {
        checked_pose(p, "pose")?;
    }
    if name == Some("") {
        return Err(Failure::invalid("name is empty (pass NULL for no name)"));
    }
    let pose = pose.map_or_else(nalgebra::Isometry3::identity, gjkd_pose::isometry);
    // On the wire an empty name means none: one request registers an
    // unnamed object at its pose too, with nothing to undo if a second
    // request (a set_pose) failed.
    let id = match name {
        Some(name) if c.registration.reuse_names => {
            c.client.register_named_or_get(name, geometry, &pose)?
        }
        _ => c
            .client
            .register_named(name.unwrap_or(""), geometry, &pose)?,
    };
    c.registered(id);
    *out_id = id.raw();
    Ok(())
}

/// The common arguments of every registration, read and checked, then
/// `build` gives the geometry.
///
/// # Safety
/// The pointers follow the rules of the `gjkd_register_*` functions.
unsafe fn register_entry(
    function: &str,
    client: *mut gjkd_client,
    name: *const c_char,
    pose: *const gjkd_pose,
    out_id: *mut gjkd_id,
    build: impl FnOnce(&mut Vec<Point3<f64>>) -> Result<Built, Failure>,
) -> gjkd_status {
    guard(function, || {
        // SAFETY: the caller's promises, for every pointer.
        unsafe {
            with_client(client, |c| {
                let slot = out(out_id, "out_id")?;
                *slot = 0;
                let name = opt_str(name, "name")?;
                let pose = pose.as_ref();
                let mut points = Vec::new();
                let geometry = build(&mut points)?;
                match geometry {
                    Built::Convex(shape) => register(c, &shape.geometry(&points), name, pose, slot),
                    Built::Compound(shapes) => {
                        let pieces: Vec<Piece<'_>> = shapes
                            .iter()
                            .map(|(offset, s)| Piece {
                                offset: offset.isometry(),
                                geometry: s.geometry(&points),
                            })
                            .collect();
                        register(c, &Geometry::Compound(&pieces), name, pose, slot)
                    }
                }
            })
        }
    })
}

/// Registers a convex `shape` and writes its id to `*out_id`.
///
/// - `shape`: read during the call only (its vertices too).
/// - `name`: NULL for none, or a unique NUL-terminated UTF-8 name of at
///   most `GJKD_MAX_NAME_LEN` bytes, so that other clients can
///   `gjkd_lookup()` it. Copied.
/// - `pose`: NULL for the identity, or the initial stored pose (checked as
///   by `gjkd_set_pose()`).
/// - `out_id`: receives the id (0 on failure).
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `shape`, `out_id`, or a
/// polytope's `vertices` with a non-zero count), `GJKD_ERR_BUSY`,
/// `GJKD_ERR_INVALID_ARGUMENT` (an unknown kind, a negative half extent, a
/// bad pose, a name empty, too long or not UTF-8),
/// `GJKD_ERR_REJECTED` with `GJKD_CODE_INVALID_RADIUS`,
/// `GJKD_CODE_EMPTY_VERTICES`, `GJKD_CODE_NON_FINITE_VERTEX`,
/// `GJKD_CODE_TOO_MANY_VERTICES`, `GJKD_CODE_NAME_TAKEN`,
/// `GJKD_CODE_TOO_MANY_OBJECTS`, `GJKD_CODE_STORAGE_FULL`,
/// `GJKD_CODE_INTERNAL` (nothing stored);
/// `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT` (the registration may then
/// have happened: register what must not be orphaned with a name and look
/// it up).
///
/// # Safety
/// Every non-NULL pointer points to what its parameter says.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_register(
    client: *mut gjkd_client,
    shape: *const gjkd_shape,
    name: *const c_char,
    pose: *const gjkd_pose,
    out_id: *mut gjkd_id,
) -> gjkd_status {
    // SAFETY: forwarded.
    unsafe {
        register_entry("gjkd_register", client, name, pose, out_id, |points| {
            let shape = required(shape, "shape")?;
            Ok(Built::Convex(Convex::read(shape, points, "shape")?))
        })
    }
}

/// Registers a ball of `radius` about the body origin. Arguments and
/// errors as `gjkd_register()`.
///
/// # Safety
/// As `gjkd_register()`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_register_sphere(
    client: *mut gjkd_client,
    radius: f64,
    name: *const c_char,
    pose: *const gjkd_pose,
    out_id: *mut gjkd_id,
) -> gjkd_status {
    // SAFETY: forwarded.
    unsafe {
        register_entry("gjkd_register_sphere", client, name, pose, out_id, |_| {
            Ok(Built::Convex(Convex::Sphere(radius)))
        })
    }
}

/// Registers an exact cylinder about the body z axis, centred on the body
/// origin: the disk of `radius` swept from `z = -half_height` to
/// `z = +half_height`, grown by `rounding` (radius and half-height each
/// grow by it, the rims become round; 0 for sharp rims).
/// Arguments and errors as `gjkd_register()` (a negative, NaN or infinite
/// size is `GJKD_ERR_REJECTED` with `GJKD_CODE_INVALID_RADIUS`).
///
/// # Safety
/// As `gjkd_register()`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_register_cylinder(
    client: *mut gjkd_client,
    radius: f64,
    half_height: f64,
    rounding: f64,
    name: *const c_char,
    pose: *const gjkd_pose,
    out_id: *mut gjkd_id,
) -> gjkd_status {
    // SAFETY: forwarded.
    unsafe {
        register_entry("gjkd_register_cylinder", client, name, pose, out_id, |_| {
            Ok(Built::Convex(Convex::Cylinder(
                radius,
                half_height,
                rounding,
            )))
        })
    }
}

/// Registers the segment from `a` to `b` (three doubles each) grown by
/// `radius`. Arguments and errors as `gjkd_register()`, plus
/// `GJKD_ERR_NULL_POINTER` for `a` or `b`.
///
/// # Safety
/// As `gjkd_register()`; `a` and `b` point to three doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_register_capsule(
    client: *mut gjkd_client,
    a: *const f64,
    b: *const f64,
    radius: f64,
    name: *const c_char,
    pose: *const gjkd_pose,
    out_id: *mut gjkd_id,
) -> gjkd_status {
    // SAFETY: forwarded.
    unsafe {
        register_entry("gjkd_register_capsule", client, name, pose, out_id, |_| {
            Ok(Built::Convex(Convex::Capsule(
                vec3(a, "a")?,
                vec3(b, "b")?,
                radius,
            )))
        })
    }
}

/// Registers a box of `half_extents` (three doubles, each `>= 0`) centred
/// on the body origin, grown by `radius` (each half extent grows by it,
/// edges and corners become round; 0 for a sharp box).
/// Arguments and errors as `gjkd_register()`, plus `GJKD_ERR_NULL_POINTER`
/// for `half_extents`.
///
/// # Safety
/// As `gjkd_register()`; `half_extents` points to three doubles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_register_box(
    client: *mut gjkd_client,
    half_extents: *const f64,
    radius: f64,
    name: *const c_char,
    pose: *const gjkd_pose,
    out_id: *mut gjkd_id,
) -> gjkd_status {
    // SAFETY: forwarded.
    unsafe {
        register_entry("gjkd_register_box", client, name, pose, out_id, |_| {
            Ok(Built::Convex(Convex::Box(
                vec3(half_extents, "half_extents")?,
                radius,
            )))
        })
    }
}

/// Registers the convex hull of `vertex_count` points (`x, y, z` each, so
/// `3 * vertex_count` doubles at `vertices`) grown by `radius`. The points
/// need not be hull vertices. Arguments and errors as `gjkd_register()`.
///
/// # Safety
/// As `gjkd_register()`; `vertices` points to `3 * vertex_count` doubles
/// (or is NULL with a count of 0).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_register_polytope(
    client: *mut gjkd_client,
    vertices: *const f64,
    vertex_count: usize,
    radius: f64,
    name: *const c_char,
    pose: *const gjkd_pose,
    out_id: *mut gjkd_id,
) -> gjkd_status {
    let shape = gjkd_shape {
        kind: gjkd_shape_kind::GJKD_SHAPE_POLYTOPE as u32,
        radius,
        a: [0.0; 3],
        b: [0.0; 3],
        vertices,
        vertex_count,
    };
    // SAFETY: forwarded; `shape` lives through the call.
    unsafe {
        gjkd_register_entry_named("gjkd_register_polytope", client, &shape, name, pose, out_id)
    }
}

/// `gjkd_register` under another function's name in its errors.
///
/// # Safety
/// As `gjkd_register()`.
unsafe fn gjkd_register_entry_named(
    function: &str,
    client: *mut gjkd_client,
    shape: &gjkd_shape,
    name: *const c_char,
    pose: *const gjkd_pose,
    out_id: *mut gjkd_id,
) -> gjkd_status {
    // SAFETY: forwarded.
    unsafe {
        register_entry(function, client, name, pose, out_id, |points| {
            Ok(Built::Convex(Convex::read(shape, points, "shape")?))
        })
    }
}

/// Registers a union of `piece_count` convex pieces, each placed in the
/// compound's body frame by its offset. Answers name the pieces realising
/// the distance by their index in `pieces`. Arguments and errors as
/// `gjkd_register()`, plus `GJKD_ERR_INVALID_ARGUMENT` for more than
/// `GJKD_MAX_PIECES` pieces or a bad offset, and `GJKD_ERR_REJECTED` with
/// `GJKD_CODE_EMPTY_COMPOUND` for none.
///
/// # Safety
/// As `gjkd_register()`; `pieces` points to `piece_count` pieces (or is
/// NULL with a count of 0), each shape's vertices as for a polytope.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_register_compound(
    client: *mut gjkd_client,
    pieces: *const gjkd_piece,
    piece_count: usize,
    name: *const c_char,
    pose: *const gjkd_pose,
    out_id: *mut gjkd_id,
) -> gjkd_status {
    // SAFETY: forwarded.
    unsafe {
        register_entry(
            "gjkd_register_compound",
            client,
            name,
            pose,
            out_id,
            |points| {
                let pieces = slice(pieces, piece_count, "pieces")?;
                if pieces.len() > gjkd_proto::MAX_PIECES {
                    return Err(Failure::invalid(format!(
                        "{} pieces, more than GJKD_MAX_PIECES ({})",
                        pieces.len(),
                        gjkd_proto::MAX_PIECES
                    )));
                }
                let mut shapes = Vec::with_capacity(pieces.len());
                for (i, p) in pieces.iter().enumerate() {
                    let what = format!("pieces[{i}]");
                    checked_pose(&p.offset, &format!("{what}.offset"))?;
                    shapes.push((p.offset, Convex::read(&p.shape, points, &what)?));
                }
                Ok(Built::Compound(shapes))
            },
        )
    }
}

/// Removes an object this client registered. Its id is never reused. A
/// robot's link removed so leaves the robot with a hole: remove a robot
/// whole with `gjkd_remove_robot()`. A robot's id (`gjkd_robot_info()`) is
/// no object id: given here, it is `GJKD_CODE_UNKNOWN_OBJECT`.
///
/// Errors: `GJKD_ERR_NULL_POINTER`, `GJKD_ERR_BUSY`,
/// `GJKD_ERR_REJECTED` with `GJKD_CODE_UNKNOWN_OBJECT`,
/// `GJKD_CODE_NOT_OWNER` (another client's object) or
/// `GJKD_CODE_READ_ONLY` (a scene object); `GJKD_ERR_SERVER_GONE`,
/// `GJKD_ERR_TIMEOUT`.
///
/// # Safety
/// `client` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_remove(client: *mut gjkd_client, id: gjkd_id) -> gjkd_status {
    guard("gjkd_remove", || {
        // SAFETY: the caller's promise.
        unsafe { with_client(client, |c| Ok(c.client.remove(ObjectId::from_raw(id))?)) }
    })
}

/// The id of the object named `name` (a scene object, or one registered
/// with a name by any client), into `*out_id` (0 on failure).
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `name`, `out_id`),
/// `GJKD_ERR_BUSY`, `GJKD_ERR_INVALID_ARGUMENT` (not UTF-8, longer
/// than `GJKD_MAX_NAME_LEN`), `GJKD_ERR_REJECTED` with
/// `GJKD_CODE_UNKNOWN_NAME`; `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT`.
///
/// # Safety
/// `client` is NULL or a live handle; `name` NULL or NUL-terminated;
/// `out_id` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_lookup(
    client: *mut gjkd_client,
    name: *const c_char,
    out_id: *mut gjkd_id,
) -> gjkd_status {
    guard("gjkd_lookup", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let slot = out(out_id, "out_id")?;
                *slot = 0;
                let name = req_str(name, "name")?;
                *slot = c.client.lookup(name)?.raw();
                Ok(())
            })
        }
    })
}
