//! Robots: registered from URDF (a file or text) with an optional SRDF,
//! their links and joints listed, moved by joint positions in one round
//! trip, and their link poses by forward kinematics.

#![allow(non_camel_case_types)]

use std::ffi::{CString, c_char};
use std::path::{Path, PathBuf};

use nalgebra::Isometry3;
use rust_client::{ErrorCode, JointError, LimitMode, PackagePath, RobotHandle, Steps};

use crate::args::{checked_pose, opt_str, out, req_str, required, slice, slice_mut};
use crate::handle::{gjkd_client, with_client};
use crate::status::{Failure, gjkd_status, guard};
use crate::types::{gjkd_id, gjkd_pose};

/// A robot registered on a server: its links (objects) and moving joints.
/// Opaque: made by `gjkd_register_robot()`, `gjkd_register_robot_text()`
/// or `gjkd_open_robot()`, freed with `gjkd_robot_free()`. It holds no
/// connection: any handle to the same server may move it, from any thread
/// (one call at a time).
pub struct gjkd_robot {
    pub(crate) handle: RobotHandle,
    /// The base pose last sent (identity at first).
    base: Isometry3<f64>,
    /// NUL-terminated link names, for `gjkd_robot_link()`.
    link_names: Vec<CString>,
    /// NUL-terminated moving-joint names, for `gjkd_robot_joint()`.
    joint_names: Vec<CString>,
}

impl gjkd_robot {
    fn new(handle: RobotHandle, base: Isometry3<f64>) -> Self {
        let c = |s: &str| CString::new(s.replace('\0', "")).unwrap_or_default();
        gjkd_robot {
            link_names: handle.link_names().iter().map(|s| c(s)).collect(),
            joint_names: handle.joint_names().into_iter().map(c).collect(),
            handle,
            base,
        }
    }

    /// Number of moving joints.
    pub(crate) fn dof(&self) -> usize {
        self.handle.positions.len()
    }
}

/// Writes a new robot to `*out_robot`.
fn hand_out(slot: &mut *mut gjkd_robot, handle: RobotHandle, base: Isometry3<f64>) {
    *slot = Box::into_raw(Box::new(gjkd_robot::new(handle, base)));
}

/// The base pose at `base` (NULL: identity), checked.
fn base_of(base: Option<&gjkd_pose>) -> Result<Isometry3<f64>, Failure> {
    match base {
        None => Ok(Isometry3::identity()),
        Some(p) => {
            checked_pose(p, "base")?;
            Ok(p.isometry())
        }
    }
}

/// A `:`-separated list of folders (NULL or empty: none), then the
/// environment's.
fn packages(list: Option<&str>) -> PackagePath {
    let dirs: Vec<PathBuf> = list
        .map(|l| {
            std::env::split_paths(l)
                .filter(|d| !d.as_os_str().is_empty())
                .collect()
        })
        .unwrap_or_default();
    PackagePath::with_env(dirs)
}

/// Registers a robot from the URDF file at `urdf_path`: each link with
/// collision geometry (boxes, spheres, cylinders, meshes; several elements
/// make a compound) becomes an object named `<name>/<link>`, then the
/// server holds the robot's kinematics and puts it at `base` (NULL:
/// identity) with every joint at zero (within its limits). Writes a new
/// robot to `*out_robot` (free it with `gjkd_robot_free()`; NULL on
/// failure).
///
/// - `srdf_path`: NULL, or an SRDF file whose `disable_collisions` pairs
///   the server keeps for the robot.
/// - `package_path`: NULL, or folders separated by `:` where `package://`
///   mesh URLs are searched (then `$GJKD_PACKAGE_PATH`,
///   `$ROS_PACKAGE_PATH`). Relative mesh paths are relative to the URDF's
///   folder.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `name`, `urdf_path`,
/// `out_robot`), `GJKD_ERR_BUSY`, `GJKD_ERR_INVALID_ARGUMENT` (a
/// URDF, SRDF or mesh that cannot be read: the message names the file,
/// link or joint; a bad base pose), `GJKD_ERR_REJECTED` with
/// `GJKD_CODE_NAME_TAKEN` (an object `<name>/<link>` exists),
/// `GJKD_CODE_INVALID_ROBOT` and the codes of `gjkd_register()`;
/// `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT`. Link objects registered
/// before a failure are removed again.
///
/// # Safety
/// Every non-NULL pointer points to what its parameter says; strings are
/// NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_register_robot(
    client: *mut gjkd_client,
    name: *const c_char,
    urdf_path: *const c_char,
    srdf_path: *const c_char,
    package_path: *const c_char,
    base: *const gjkd_pose,
    out_robot: *mut *mut gjkd_robot,
) -> gjkd_status {
    guard("gjkd_register_robot", || {
        // SAFETY: the caller's promises.
        unsafe {
            let slot = out(out_robot, "out_robot")?;
            *slot = std::ptr::null_mut();
            with_client(client, |c| {
                let name = req_str(name, "name")?;
                let urdf = Path::new(req_str(urdf_path, "urdf_path")?);
                let srdf = opt_str(srdf_path, "srdf_path")?.map(Path::new);
                let packages = packages(opt_str(package_path, "package_path")?);
                let base = base_of(base.as_ref())?;
                let handle = if c.registration.reuse_names {
                    let read = |p: &Path| {
                        std::fs::read_to_string(p).map_err(|e| {
                            // The code Rust's `ClientError::InvalidRobot` carries.
                            Failure::invalid_code(
                                ErrorCode::InvalidRobot,
                                format!("{}: {e}", p.display()),
                            )
                        })
                    };
                    let text = read(urdf)?;
                    let srdf = srdf.map(read).transpose()?;
                    c.client.register_robot_text_or_get(
                        name,
                        &text,
                        srdf.as_deref(),
                        urdf.parent(),
                        &packages,
                        &base,
                    )?
                } else {
                    c.client
                        .register_robot(name, urdf, srdf, &packages, &base)?
                };
                c.registered_robot(name);
                hand_out(slot, handle, base);
                Ok(())
            })
        }
    })
}

/// `gjkd_register_robot()` from URDF text (and SRDF text, or NULL) in
/// memory; relative mesh paths are relative to `mesh_dir` (NULL: the
/// working folder). Errors as `gjkd_register_robot()` (`urdf_text`
/// instead of `urdf_path`).
///
/// # Safety
/// As `gjkd_register_robot()`.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn gjkd_register_robot_text(
    client: *mut gjkd_client,
    name: *const c_char,
    urdf_text: *const c_char,
    srdf_text: *const c_char,
    mesh_dir: *const c_char,
    package_path: *const c_char,
    base: *const gjkd_pose,
    out_robot: *mut *mut gjkd_robot,
) -> gjkd_status {
    guard("gjkd_register_robot_text", || {
        // SAFETY: the caller's promises.
        unsafe {
            let slot = out(out_robot, "out_robot")?;
            *slot = std::ptr::null_mut();
            with_client(client, |c| {
                let name = req_str(name, "name")?;
                let urdf = req_str(urdf_text, "urdf_text")?;
                let srdf = opt_str(srdf_text, "srdf_text")?;
                let dir = opt_str(mesh_dir, "mesh_dir")?.map(Path::new);
                let packages = packages(opt_str(package_path, "package_path")?);
                let base = base_of(base.as_ref())?;
                let handle = if c.registration.reuse_names {
                    c.client
                        .register_robot_text_or_get(name, urdf, srdf, dir, &packages, &base)?
                } else {
                    c.client
                        .register_robot_text(name, urdf, srdf, dir, &packages, &base)?
                };
                c.registered_robot(name);
                hand_out(slot, handle, base);
                Ok(())
            })
        }
    })
}

/// The robot named `name` already on the server (one the server's scene
/// file loaded, or another client registered), given its URDF text for
/// the joint order and link names. Writes a new robot to `*out_robot`.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `name`, `urdf_text`,
/// `out_robot`), `GJKD_ERR_BUSY`, `GJKD_ERR_INVALID_ARGUMENT`
/// (URDF text that cannot be read), `GJKD_ERR_REJECTED` with
/// `GJKD_CODE_UNKNOWN_NAME`; `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT`.
///
/// # Safety
/// As `gjkd_register_robot()`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_open_robot(
    client: *mut gjkd_client,
    name: *const c_char,
    urdf_text: *const c_char,
    out_robot: *mut *mut gjkd_robot,
) -> gjkd_status {
    guard("gjkd_open_robot", || {
        // SAFETY: the caller's promises.
        unsafe {
            let slot = out(out_robot, "out_robot")?;
            *slot = std::ptr::null_mut();
            with_client(client, |c| {
                let name = req_str(name, "name")?;
                let urdf = req_str(urdf_text, "urdf_text")?;
                let handle = c.client.open_robot(name, urdf)?;
                hand_out(slot, handle, Isometry3::identity());
                Ok(())
            })
        }
    })
}

/// Frees a robot (the robot stays on the server). NULL is allowed.
///
/// # Safety
/// `robot` is NULL or from this library, not yet freed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_robot_free(robot: *mut gjkd_robot) -> gjkd_status {
    guard("gjkd_robot_free", || {
        if !robot.is_null() {
            // SAFETY: made by Box::into_raw in hand_out, not yet freed.
            drop(unsafe { Box::from_raw(robot) });
        }
        Ok(())
    })
}

/// The robot's id and its numbers of links and moving joints (each
/// output may be NULL). The robot's id is the group id of scene questions
/// about the robot (`gjkd_group::id`); it is no object id (robot ids are
/// their own namespace): its links are the objects, see
/// `gjkd_robot_link()`. Remove the robot with `gjkd_remove_robot()`.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`robot`).
///
/// # Safety
/// `robot` is NULL or live; the outputs NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_robot_info(
    robot: *const gjkd_robot,
    out_id: *mut gjkd_id,
    out_links: *mut usize,
    out_joints: *mut usize,
) -> gjkd_status {
    guard("gjkd_robot_info", || {
        // SAFETY: the caller's promises.
        unsafe {
            let r = required(robot, "robot")?;
            if let Some(id) = out_id.as_mut() {
                *id = r.handle.id.raw();
            }
            if let Some(n) = out_links.as_mut() {
                *n = r.link_names.len();
            }
            if let Some(n) = out_joints.as_mut() {
                *n = r.joint_names.len();
            }
            Ok(())
        }
    })
}

/// Link `index` (in the URDF's order, `0 <= index < links`): its name
/// (owned by the robot, valid until `gjkd_robot_free()`) and its object id
/// (0 for a link without collision geometry). Either output may be NULL.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`robot`), `GJKD_ERR_INVALID_ARGUMENT`
/// (`index` out of range).
///
/// # Safety
/// `robot` is NULL or live; the outputs NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_robot_link(
    robot: *const gjkd_robot,
    index: usize,
    out_name: *mut *const c_char,
    out_id: *mut gjkd_id,
) -> gjkd_status {
    guard("gjkd_robot_link", || {
        // SAFETY: the caller's promises.
        unsafe {
            let r = required(robot, "robot")?;
            let name = r.link_names.get(index).ok_or_else(|| {
                Failure::invalid(format!(
                    "index {index}: the robot has {} links",
                    r.link_names.len()
                ))
            })?;
            if let Some(n) = out_name.as_mut() {
                *n = name.as_ptr();
            }
            if let Some(id) = out_id.as_mut() {
                *id = r.handle.links[index].map_or(0, |l| l.raw());
            }
            Ok(())
        }
    })
}

/// The object id of the link named `name` (0 for a link without collision
/// geometry).
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`robot`, `name`, `out_id`),
/// `GJKD_ERR_INVALID_ARGUMENT` with last error code
/// `GJKD_CODE_UNKNOWN_NAME` (no link of that name: looked up in the
/// handle, nothing is asked of the server).
///
/// # Safety
/// `robot` is NULL or live; `name` NULL or NUL-terminated; `out_id` NULL
/// or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_robot_link_id(
    robot: *const gjkd_robot,
    name: *const c_char,
    out_id: *mut gjkd_id,
) -> gjkd_status {
    guard("gjkd_robot_link_id", || {
        // SAFETY: the caller's promises.
        unsafe {
            let slot = out(out_id, "out_id")?;
            *slot = 0;
            let r = required(robot, "robot")?;
            let name = req_str(name, "name")?;
            // Looked up here, in the robot's own list: a caller's mistake,
            // not a refusal by the server.
            if !r.handle.link_names().iter().any(|l| l == name) {
                return Err(Failure::invalid_code(
                    ErrorCode::UnknownName,
                    format!("the robot has no link `{name}`"),
                ));
            }
            *slot = r.handle.link(name).map_or(0, |l| l.raw());
            Ok(())
        }
    })
}

/// Moving joint `index` (in position-array order): its name (owned by the
/// robot, valid until `gjkd_robot_free()`), its limits (`-inf`, `inf` for
/// a continuous joint) and its position last set. Any output may be NULL.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`robot`), `GJKD_ERR_INVALID_ARGUMENT`
/// (`index` out of range).
///
/// # Safety
/// `robot` is NULL or live; the outputs NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_robot_joint(
    robot: *const gjkd_robot,
    index: usize,
    out_name: *mut *const c_char,
    out_lower: *mut f64,
    out_upper: *mut f64,
    out_position: *mut f64,
) -> gjkd_status {
    guard("gjkd_robot_joint", || {
        // SAFETY: the caller's promises.
        unsafe {
            let r = required(robot, "robot")?;
            let name = r.joint_names.get(index).ok_or_else(|| {
                Failure::invalid(format!(
                    "index {index}: the robot has {} moving joints",
                    r.joint_names.len()
                ))
            })?;
            let joint = r
                .handle
                .kinematics
                .moving_joints()
                .nth(index)
                .ok_or_else(|| Failure::invalid("joint index"))?;
            if let Some(n) = out_name.as_mut() {
                *n = name.as_ptr();
            }
            if let Some(v) = out_lower.as_mut() {
                *v = joint.lower;
            }
            if let Some(v) = out_upper.as_mut() {
                *v = joint.upper;
            }
            if let Some(v) = out_position.as_mut() {
                *v = r.handle.positions[index];
            }
            Ok(())
        }
    })
}

/// The steps of a path of `r`'s joint positions, `dof` per step, each
/// checked as the server would (finite; within limits unless `clamp`), so
/// that a refusal names its step and joint before anything is sent.
pub(crate) fn path_steps<'a>(
    r: &gjkd_robot,
    positions: &'a [f64],
    clamp: bool,
) -> Result<Steps<'a>, Failure> {
    let dof = r.handle.positions.len();
    if dof == 0 {
        return Err(Failure::invalid("the robot has no moving joint"));
    }
    let mode = if clamp {
        LimitMode::Clamp
    } else {
        LimitMode::Reject
    };
    let mut checked = vec![0.0; dof];
    for (s, step) in positions.chunks_exact(dof).enumerate() {
        checked.copy_from_slice(step);
        r.handle
            .kinematics
            .check_positions(&mut checked, mode)
            .map_err(|e| {
                let f = joint_failure(e);
                Failure {
                    message: format!("positions of step {s}: {}", f.message),
                    ..f
                }
            })?;
    }
    Ok(Steps::joints(&r.handle, positions))
}

/// The failure of positions refused before anything is sent.
fn joint_failure(e: JointError) -> Failure {
    let code = match e {
        JointError::OutOfLimits { .. } => ErrorCode::OutOfLimits.raw(),
        JointError::NotFinite(_) | JointError::BadBase => ErrorCode::NonFinitePose.raw(),
        JointError::UnknownJoint(_) => ErrorCode::UnknownName.raw(),
        JointError::WrongCount { .. } => 0,
    };
    Failure {
        code,
        ..Failure::invalid(e.to_string())
    }
}

/// Sets every moving joint of `robot` (`count` positions in joint order,
/// see `gjkd_robot_joint()`) and, if `base` is not NULL, its base pose, in
/// one round trip: the server places every link by forward kinematics. A
/// position outside its limits is refused, or moved to the nearest limit
/// when `clamp` is true. A robot without moving joints takes `count` 0
/// (`positions` may then be NULL): only its base moves.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `robot`, `positions`),
/// `GJKD_ERR_BUSY`, `GJKD_ERR_INVALID_ARGUMENT` (`count` not the
/// number of moving joints; a position NaN or infinite, last error code
/// `GJKD_CODE_NON_FINITE_POSE`; outside its limits without `clamp`,
/// `GJKD_CODE_OUT_OF_LIMITS`; the message names the joint; a bad base
/// pose), `GJKD_ERR_REJECTED` with `GJKD_CODE_UNKNOWN_OBJECT` (the robot
/// or a link is gone); `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT`.
/// Nothing moves on error.
///
/// # Safety
/// `client` and `robot` are NULL or live; `positions` NULL or `count`
/// doubles; `base` NULL or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_set_joints(
    client: *mut gjkd_client,
    robot: *mut gjkd_robot,
    positions: *const f64,
    count: usize,
    base: *const gjkd_pose,
    clamp: bool,
) -> gjkd_status {
    guard("gjkd_set_joints", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let r = robot.as_mut().ok_or_else(|| Failure::null("robot"))?;
                let dof = r.handle.positions.len();
                if count != dof {
                    return Err(Failure::invalid(format!(
                        "count {count}: the robot has {dof} moving joints"
                    )));
                }
                let q = if count == 0 {
                    &[][..]
                } else {
                    slice(positions, count, "positions")?
                };
                set_joints(c, r, q, base.as_ref(), clamp)
            })
        }
    })
}

/// Checks, then sends.
fn set_joints(
    c: &mut gjkd_client,
    r: &mut gjkd_robot,
    q: &[f64],
    base: Option<&gjkd_pose>,
    clamp: bool,
) -> Result<(), Failure> {
    // No positions for a robot without moving joints: only its base moves.
    let base = match base {
        Some(p) => Some(base_of(Some(p))?),
        None => None,
    };
    let mode = if clamp {
        LimitMode::Clamp
    } else {
        LimitMode::Reject
    };
    let mut checked = q.to_vec();
    r.handle
        .kinematics
        .check_positions(&mut checked, mode)
        .map_err(joint_failure)?;
    c.client
        .set_joints_with(&mut r.handle, q, base.as_ref(), mode)?;
    if let Some(b) = base {
        r.base = b;
    }
    Ok(())
}

/// `gjkd_set_joints()` by joint name: `names[i]` gets `values[i]`, joints
/// not named keep their positions last set.
///
/// Errors: as `gjkd_set_joints()`, plus `GJKD_ERR_NULL_POINTER` (`names`,
/// a name, `values`) and `GJKD_ERR_INVALID_ARGUMENT` for a name that is no
/// moving joint (last error code `GJKD_CODE_UNKNOWN_NAME`).
///
/// # Safety
/// `names` NULL or `count` pointers to NUL-terminated strings, `values`
/// NULL or `count` doubles; others as `gjkd_set_joints()`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_set_joints_by_name(
    client: *mut gjkd_client,
    robot: *mut gjkd_robot,
    names: *const *const c_char,
    values: *const f64,
    count: usize,
    clamp: bool,
) -> gjkd_status {
    guard("gjkd_set_joints_by_name", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let r = robot.as_mut().ok_or_else(|| Failure::null("robot"))?;
                let names = slice(names, count, "names")?;
                let values = slice(values, count, "values")?;
                let mut named = Vec::with_capacity(count);
                for (i, (&n, &v)) in names.iter().zip(values).enumerate() {
                    named.push((req_str(n, &format!("names[{i}]"))?, v));
                }
                let q = r
                    .handle
                    .kinematics
                    .positions_by_name(&named, &r.handle.positions)
                    .map_err(joint_failure)?;
                set_joints(c, r, &q, None, clamp)
            })
        }
    })
}

/// Every link's pose by forward kinematics, computed here as the server
/// computes it, into `out_poses` (`out_count` must be the number of
/// links; URDF order): for `count` positions (NULL with 0: the positions
/// last set) and `base` (NULL: the base last sent, identity at first).
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`robot`, `out_poses`),
/// `GJKD_ERR_INVALID_ARGUMENT` (wrong counts; positions refused as by
/// `gjkd_set_joints()`, same codes).
///
/// # Safety
/// `robot` NULL or live; `positions` NULL or `count` doubles; `base` NULL
/// or readable; `out_poses` NULL or room for `out_count` poses.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_robot_link_poses(
    robot: *const gjkd_robot,
    positions: *const f64,
    count: usize,
    base: *const gjkd_pose,
    clamp: bool,
    out_poses: *mut gjkd_pose,
    out_count: usize,
) -> gjkd_status {
    guard("gjkd_robot_link_poses", || {
        // SAFETY: the caller's promises.
        unsafe {
            let r = required(robot, "robot")?;
            let links = r.link_names.len();
            if out_count != links {
                return Err(Failure::invalid(format!(
                    "out_count {out_count}: the robot has {links} links"
                )));
            }
            let dst = slice_mut(out_poses, out_count, "out_poses")?
                .ok_or_else(|| Failure::null("out_poses"))?;
            let q = if positions.is_null() && count == 0 {
                r.handle.positions.clone()
            } else {
                slice(positions, count, "positions")?.to_vec()
            };
            let base = match base.as_ref() {
                Some(p) => base_of(Some(p))?,
                None => r.base,
            };
            let mode = if clamp {
                LimitMode::Clamp
            } else {
                LimitMode::Reject
            };
            let poses = r
                .handle
                .kinematics
                .link_poses(&base, &q, mode)
                .map_err(joint_failure)?;
            for (d, p) in dst.iter_mut().zip(&poses) {
                let t = p.translation.vector;
                let q = p.rotation.coords;
                *d = gjkd_pose {
                    translation: [t.x, t.y, t.z],
                    rotation: [q.x, q.y, q.z, q.w],
                };
            }
            Ok(())
        }
    })
}
