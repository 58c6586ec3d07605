//! Meshes: registered from a file (STL, OBJ, COLLADA) or from arrays, as
//! their convex hull or as a convex decomposition.

use std::ffi::c_char;
use std::path::Path;

use nalgebra::{Isometry3, Point3};
use rust_client::{Mesh, MeshMode, RegisterError};

use crate::args::{checked_pose, opt_str, out, req_str, slice};
use crate::handle::{gjkd_client, with_client};
use crate::status::{Failure, gjkd_status, guard};
use crate::types::{gjkd_id, gjkd_pose};

/// What a mesh registration made (`out_info` of `gjkd_register_mesh()`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct gjkd_mesh_info {
    /// Convex pieces: 1 for a hull.
    pub pieces: usize,
    /// For a decomposition, the largest distance found by which the
    /// pieces reach beyond the mesh (so how much less distance they may
    /// report); 0 for a hull, which never reaches closer than the mesh's
    /// own convex hull.
    pub deviation: f64,
}

/// The per-axis scale at `scale` (NULL: 1, 1, 1).
///
/// # Safety
/// A non-NULL `scale` points to three doubles.
unsafe fn scale_of(scale: *const f64) -> [f64; 3] {
    if scale.is_null() {
        [1.0; 3]
    } else {
        // SAFETY: the caller's promise.
        unsafe { [*scale, *scale.add(1), *scale.add(2)] }
    }
}

/// Registers `mesh`, scaled, with the common arguments.
#[allow(clippy::too_many_arguments)]
fn register(
    c: &mut gjkd_client,
    mesh: Mesh,
    scale: [f64; 3],
    decompose: u32,
    name: Option<&str>,
    pose: Option<&gjkd_pose>,
    out_id: &mut gjkd_id,
    out_info: Option<&mut gjkd_mesh_info>,
) -> Result<(), Failure> {
    if let Some(p) = pose {
        checked_pose(p, "pose")?;
    }
    if name == Some("") {
        return Err(Failure::invalid("name is empty (pass NULL for no name)"));
    }
    let mesh = mesh
        .scaled(scale)
        .map_err(|e| Failure::invalid(format!("scale: {e}")))?;
    let mode = match decompose {
        0 => MeshMode::Hull,
        r => MeshMode::Decompose(r),
    };
    let pose = pose.map_or_else(Isometry3::identity, gjkd_pose::isometry);
    let made = match c
        .client
        .register_mesh(name.unwrap_or(""), &mesh, mode, &pose)
    {
        Err(RegisterError::NameTaken) if c.registration.reuse_names => {
            // The object of that name, as it is: what it was made of is
            // not known here.
            let id = c.client.lookup(name.unwrap_or(""))?;
            (id, gjkd_mesh_info::default())
        }
        made => {
            let made = made?;
            let info = gjkd_mesh_info {
                pieces: made.pieces,
                deviation: made.deviation,
            };
            (made.id, info)
        }
    };
    c.registered(made.0);
    *out_id = made.0.raw();
    if let Some(info) = out_info {
        *info = made.1;
    }
    Ok(())
}

/// Registers the triangle mesh in the file at `path` (binary or ASCII STL,
/// OBJ, COLLADA `.dae`) and writes its id to `*out_id`.
///
/// - `scale`: NULL for none, or three doubles (per axis; finite, non-zero).
/// - `decompose`: 0 for the mesh's convex hull (one convex object, which
///   never reports more distance than the mesh), or a V-HACD resolution
///   (64 is a fair start): a compound of convex pieces that follows a
///   non-convex mesh.
/// - `name`, `pose`, `out_id`: as for `gjkd_register()`.
/// - `out_info`: NULL, or receives the pieces and the deviation.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `path`, `out_id`),
/// `GJKD_ERR_BUSY`, `GJKD_ERR_INVALID_ARGUMENT` (a file missing or
/// not a mesh, a bad scale, a decomposition that finds no pieces, a bad
/// pose or name; the message says which), `GJKD_ERR_REJECTED` with the
/// codes of `gjkd_register()` (`GJKD_CODE_TOO_MANY_PIECES` for a
/// decomposition of more than `GJKD_MAX_PIECES` pieces: use a coarser
/// resolution); `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT`.
///
/// # Safety
/// Every non-NULL pointer points to what its parameter says.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gjkd_register_mesh_file(
    client: *mut gjkd_client,
    path: *const c_char,
    scale: *const f64,
    decompose: u32,
    name: *const c_char,
    pose: *const gjkd_pose,
    out_id: *mut gjkd_id,
    out_info: *mut gjkd_mesh_info,
) -> gjkd_status {
    guard("gjkd_register_mesh_file", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let slot = out(out_id, "out_id")?;
                *slot = 0;
                let path = req_str(path, "path")?;
                let name = opt_str(name, "name")?;
                let mesh = Mesh::load(Path::new(path), [1.0; 3])
                    .map_err(|e| Failure::invalid(e.to_string()))?;
                let info = out_info.as_mut();
                register(
                    c,
                    mesh,
                    scale_of(scale),
                    decompose,
                    name,
                    pose.as_ref(),
                    slot,
                    info,
                )
            })
        }
    })
}

/// Registers the triangle mesh of `vertex_count` vertices (`3 *
/// vertex_count` doubles, `x, y, z` each) and `triangle_count` triangles
/// (`3 * triangle_count` vertex indices; may be NULL with a count of 0 for
/// a hull, a decomposition needs them). Other arguments and errors as
/// `gjkd_register_mesh_file()`; an index out of range, a NaN vertex or no
/// vertices are `GJKD_ERR_INVALID_ARGUMENT`.
///
/// # Safety
/// Every non-NULL pointer points to what its parameter says.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gjkd_register_mesh(
    client: *mut gjkd_client,
    vertices: *const f64,
    vertex_count: usize,
    triangles: *const u32,
    triangle_count: usize,
    scale: *const f64,
    decompose: u32,
    name: *const c_char,
    pose: *const gjkd_pose,
    out_id: *mut gjkd_id,
    out_info: *mut gjkd_mesh_info,
) -> gjkd_status {
    guard("gjkd_register_mesh", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let slot = out(out_id, "out_id")?;
                *slot = 0;
                let name = opt_str(name, "name")?;
                let v = slice(vertices.cast::<[f64; 3]>(), vertex_count, "vertices")?;
                let t = slice(triangles.cast::<[u32; 3]>(), triangle_count, "triangles")?;
                if decompose != 0 && t.is_empty() {
                    return Err(Failure::invalid(
                        "a decomposition needs the mesh's triangles",
                    ));
                }
                let mesh =
                    Mesh::from_arrays(v.iter().map(|&p| Point3::from(p)).collect(), t.to_vec())
                        .map_err(|e| Failure::invalid(e.to_string()))?;
                let info = out_info.as_mut();
                register(
                    c,
                    mesh,
                    scale_of(scale),
                    decompose,
                    name,
                    pose.as_ref(),
                    slot,
                    info,
                )
            })
        }
    })
}
