//! Stored poses read back from the server.

use rust_client::{ErrorCode, ObjectId};

use crate::args::{slice, slice_mut};
use crate::handle::{gjkd_client, with_client};
use crate::status::{Failure, gjkd_status, guard};
use crate::types::{gjkd_id, gjkd_pose};

/// Reads the stored poses of `count` objects in one round trip:
/// `poses[i]` is the pose of `ids[i]` as the server holds it, bit for bit
/// (what `gjkd_set_pose()` or the registration stored; for a robot's link
/// object, the pose its robot's last joint update computed), and
/// `errors[i]` a `gjkd_error_code`: `GJKD_CODE_OK`, or
/// `GJKD_CODE_UNKNOWN_OBJECT` for an id the server does not hold (never
/// registered, removed, another server run's; a robot id from
/// `gjkd_robot_info()` is not an object id), whose pose is then the
/// identity. An unknown id fails its entry alone, as a pair of
/// `gjkd_query_pairs()` does: the call still returns `GJKD_OK`. Batches
/// larger than the server takes are split. A count of 0 does nothing (the
/// arrays may then be NULL).
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`client`, `ids`, `poses`, `errors`,
/// with a count above 0), `GJKD_ERR_BUSY`, `GJKD_ERR_SERVER_GONE`,
/// `GJKD_ERR_TIMEOUT`. On error the outputs are left alone.
///
/// # Safety
/// `client` is NULL or a live handle; `ids`, `poses` and `errors` NULL or
/// pointing to `count` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_get_poses(
    client: *mut gjkd_client,
    ids: *const gjkd_id,
    count: usize,
    poses: *mut gjkd_pose,
    errors: *mut u32,
) -> gjkd_status {
    guard("gjkd_get_poses", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                if count == 0 {
                    return Ok(());
                }
                let ids = slice(ids, count, "ids")?;
                let poses = slice_mut(poses, count, "poses")?.ok_or(Failure::null("poses"))?;
                let errors = slice_mut(errors, count, "errors")?.ok_or(Failure::null("errors"))?;
                let ids: Vec<ObjectId> = ids.iter().map(|&id| ObjectId::from_raw(id)).collect();
                let got = c.client.poses(&ids)?;
                for ((entry, pose), error) in got.iter().zip(poses).zip(errors) {
                    let wire = match entry {
                        Ok(iso) => gjkd_proto::Pose::from_isometry(iso),
                        Err(_) => gjkd_proto::Pose::IDENTITY,
                    };
                    *pose = gjkd_pose {
                        translation: wire.translation,
                        rotation: wire.rotation,
                    };
                    *error = match entry {
                        Ok(_) => ErrorCode::Ok as u32,
                        Err(code) => *code as u32,
                    };
                }
                Ok(())
            })
        }
    })
}
