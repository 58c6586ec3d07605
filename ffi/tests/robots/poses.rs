//! `gjkd_get_poses`: stored poses read back bit for bit, robot links where
//! the hand-computed kinematics puts them, unknown ids failing alone, and
//! the NULL and empty cases.

use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use gjkd_status::*;

use crate::arm::*;

fn isometry(p: &gjkd_pose) -> Isometry3<f64> {
    let [x, y, z] = p.translation;
    let [qx, qy, qz, qw] = p.rotation;
    Isometry3::from_parts(
        Vector3::new(x, y, z).into(),
        UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(qw, qx, qy, qz)),
    )
}

#[test]
fn poses_are_read_back_bit_for_bit_and_unknown_ids_fail_alone() {
    let server = Server::start("ffi-poses", &["--no-persist"]);
    let dir = arm_dir("poses");
    let c = connect(&server);
    // Every bit of the mantissas in use.
    let moved = gjkd_pose {
        translation: [0.1, -2.0 / 3.0, 1e-7],
        rotation: [0.36, -0.48, 0.0, 0.8],
    };
    let a = ball(c, 0.5, &at(1.0, 2.0, 3.0));
    let b = ball(c, 0.5, &at(0.0, 0.0, 0.0));
    // SAFETY: valid pointers or NULLs where tested.
    unsafe {
        ok(gjkd_set_pose(c, b, &moved));
        let ids = [a, 0, b, a + 1_000_000];
        let mut poses = [at(9.0, 9.0, 9.0); 4];
        let mut errors = [77u32; 4];
        ok(gjkd_get_poses(
            c,
            ids.as_ptr(),
            4,
            poses.as_mut_ptr(),
            errors.as_mut_ptr(),
        ));
        let ok_code = gjkd_error_code::GJKD_CODE_OK as u32;
        let unknown = gjkd_error_code::GJKD_CODE_UNKNOWN_OBJECT as u32;
        assert_eq!(errors, [ok_code, unknown, ok_code, unknown]);
        assert_eq!(poses[0], at(1.0, 2.0, 3.0));
        let bits = |p: &gjkd_pose| {
            let mut v = Vec::new();
            v.extend(p.translation.iter().chain(&p.rotation).map(|c| c.to_bits()));
            v
        };
        assert_eq!(bits(&poses[2]), bits(&moved));
        assert_eq!(
            poses[1],
            at(0.0, 0.0, 0.0),
            "an unknown id reads the identity"
        );

        // A robot's links, where its joints put them.
        let robot = register_arm(c, &dir, "arm");
        let base = Isometry3::new(Vector3::new(0.3, -0.2, 0.1), Vector3::new(0.0, 0.0, 0.5));
        let q = [0.4, -0.7, 0.05];
        let b_pose = gjkd_pose {
            translation: base.translation.vector.into(),
            rotation: base.rotation.coords.into(),
        };
        ok(gjkd_set_joints(c, robot, q.as_ptr(), 3, &b_pose, false));
        let frames = hand_fk(q, base);
        let links = [
            link_id(robot, c"base"),
            link_id(robot, c"upper"),
            link_id(robot, c"fore"),
            link_id(robot, c"tip"),
        ];
        let mut poses = [at(0.0, 0.0, 0.0); 4];
        let mut errors = [77u32; 4];
        ok(gjkd_get_poses(
            c,
            links.as_ptr(),
            4,
            poses.as_mut_ptr(),
            errors.as_mut_ptr(),
        ));
        assert_eq!(errors, [ok_code; 4]);
        for (got, want) in poses.iter().zip(&frames) {
            let got = isometry(got);
            let off = (got.translation.vector - want.translation.vector).norm()
                + got.rotation.angle_to(&want.rotation);
            assert!(off < 1e-12, "{got} vs {want}");
        }

        // A count of 0 does nothing, NULL arrays and all.
        ok(gjkd_get_poses(c, null(), 0, null_mut(), null_mut()));
        // NULL pointers with a count: refused, outputs left alone.
        let mut one = [at(5.0, 5.0, 5.0)];
        let mut err = [77u32];
        let null_p = GJKD_ERR_NULL_POINTER;
        assert_eq!(
            gjkd_get_poses(c, null(), 1, one.as_mut_ptr(), err.as_mut_ptr()),
            null_p
        );
        assert!(gjkd_last_error_message_has("ids"));
        assert_eq!(
            gjkd_get_poses(c, &a, 1, null_mut(), err.as_mut_ptr()),
            null_p
        );
        assert!(gjkd_last_error_message_has("poses"));
        assert_eq!(
            gjkd_get_poses(c, &a, 1, one.as_mut_ptr(), null_mut()),
            null_p
        );
        assert!(gjkd_last_error_message_has("errors"));
        assert_eq!((one[0], err[0]), (at(5.0, 5.0, 5.0), 77));
        assert_eq!(
            gjkd_get_poses(null_mut(), &a, 1, one.as_mut_ptr(), err.as_mut_ptr()),
            null_p
        );
        ok(gjkd_robot_free(robot));
        ok(gjkd_close(c));
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// Whether the calling thread's last error message names `word`.
fn gjkd_last_error_message_has(word: &str) -> bool {
    // SAFETY: never NULL, lives until the next call on this thread.
    let msg = unsafe { std::ffi::CStr::from_ptr(gjkd_last_error()) };
    msg.to_string_lossy().contains(word)
}
