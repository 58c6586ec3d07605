//! How long what a handle registers lives: found again by name, ended
//! with the handle, or removed, a robot as a whole.

use std::ffi::c_char;

use crate::args::req_str;
#[cfg(feature = "robots")]
use crate::args::required;
use crate::handle::{gjkd_client, with_client};
#[cfg(feature = "robots")]
use crate::robots::gjkd_robot;
use crate::status::{Failure, gjkd_status, guard};
use crate::types::gjkd_registration_options;

/// Sets how the handle's later registrations treat names and the handle's
/// end (see `gjkd_registration_options`); registrations made before keep
/// what was set then. NULL `options` means both off, the default.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`), `GJKD_ERR_BUSY`.
///
/// # Safety
/// `client` is NULL or a live handle; `options` NULL or readable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_set_registration_options(
    client: *mut gjkd_client,
    options: *const gjkd_registration_options,
) -> gjkd_status {
    guard("gjkd_set_registration_options", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                c.registration = options.as_ref().copied().unwrap_or_default();
                Ok(())
            })
        }
    })
}

/// Removes `robot` from the server as a whole: its kinematics and every
/// link object, in one step (all or nothing; removing one link with
/// `gjkd_remove()` would leave a robot with a hole). `robot` stays to be
/// freed with `gjkd_robot_free()`; it names nothing on the server then.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `robot`), `GJKD_ERR_BUSY`,
/// `GJKD_ERR_REJECTED` with `GJKD_CODE_UNKNOWN_NAME` (no robot of that
/// name: removed already, or a server restarted since, which keeps link
/// objects but not robots), `GJKD_CODE_NOT_OWNER` (another client's robot
/// or link), `GJKD_CODE_READ_ONLY` (a robot of the server's scene file),
/// `GJKD_CODE_STORAGE_FULL`; `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT`.
///
/// # Safety
/// `client` and `robot` are NULL or live.
#[cfg(feature = "robots")]
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_remove_robot(
    client: *mut gjkd_client,
    robot: *const gjkd_robot,
) -> gjkd_status {
    guard("gjkd_remove_robot", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let r = required(robot, "robot")?;
                let name = r.handle.name.clone();
                c.client.remove_robot(&name)?;
                c.doomed_robots.retain(|n| *n != name);
                Ok(())
            })
        }
    })
}

/// Removes the robot named `name` as a whole, as `gjkd_remove_robot()`
/// does, for a program that holds no `gjkd_robot` of it (one restarted,
/// cleaning up after its previous run; that run's robot is another
/// client's unless this handle attached it again).
///
/// Errors: as `gjkd_remove_robot()`, `GJKD_ERR_NULL_POINTER` for `name`,
/// `GJKD_ERR_INVALID_ARGUMENT` for a name not UTF-8 or longer than
/// `GJKD_MAX_NAME_LEN`.
///
/// # Safety
/// `client` is NULL or live; `name` NULL or NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_remove_robot_named(
    client: *mut gjkd_client,
    name: *const c_char,
) -> gjkd_status {
    guard("gjkd_remove_robot_named", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let name = req_str(name, "name")?;
                if name.len() > gjkd_proto::MAX_NAME_LEN {
                    return Err(Failure::invalid("name is longer than GJKD_MAX_NAME_LEN"));
                }
                c.client.remove_robot(name)?;
                c.doomed_robots.retain(|n| n != name);
                Ok(())
            })
        }
    })
}
