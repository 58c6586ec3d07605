//! Every robot registration, listing and joint error through the C API,
//! with its status, code and message.

use std::ffi::CString;
use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Vector3};

use gjkd_status::*;

use crate::arm::*;

#[test]
fn every_robot_error_has_its_status() {
    let server = Server::start("ffi-robot-errors", &["--no-persist"]);
    let dir = arm_dir("errors");
    let c = connect(&server);
    let robot = register_arm(c, &dir, "arm");
    let urdf = cstr(&dir.join("arm.urdf"));
    let text = CString::new(ARM_URDF).unwrap();
    let nan = at(f64::NAN, 0.0, 0.0);
    let (inv, null_p, rej) = (
        GJKD_ERR_INVALID_ARGUMENT,
        GJKD_ERR_NULL_POINTER,
        GJKD_ERR_REJECTED,
    );
    let code = |c: gjkd_error_code| c as u32;
    // SAFETY: valid pointers or NULLs where tested.
    unsafe {
        let (mut id, mut r) = (0, null_mut());
        // Robot registration: a robot that cannot be read carries the code
        // the server gives a robot it cannot attach, as in Rust and Python.
        let robot_code = code(gjkd_error_code::GJKD_CODE_INVALID_ROBOT);
        let missing = cstr(&dir.join("none.urdf"));
        fails(
            gjkd_register_robot(
                c,
                c"r".as_ptr(),
                missing.as_ptr(),
                null(),
                null(),
                null(),
                &mut r,
            ),
            inv,
            robot_code,
            "none.urdf",
        );
        fails(
            gjkd_register_robot(c, null(), urdf.as_ptr(), null(), null(), null(), &mut r),
            null_p,
            0,
            "name is NULL",
        );
        fails(
            gjkd_register_robot(c, c"r".as_ptr(), null(), null(), null(), null(), &mut r),
            null_p,
            0,
            "urdf_path is NULL",
        );
        fails(
            gjkd_register_robot(
                c,
                c"r".as_ptr(),
                urdf.as_ptr(),
                null(),
                null(),
                null(),
                null_mut(),
            ),
            null_p,
            0,
            "out_robot",
        );
        fails(
            gjkd_register_robot(
                null_mut(),
                c"r".as_ptr(),
                urdf.as_ptr(),
                null(),
                null(),
                null(),
                &mut r,
            ),
            null_p,
            0,
            "client is NULL",
        );
        let srdf = cstr(&dir.join("none.srdf"));
        fails(
            gjkd_register_robot(
                c,
                c"r".as_ptr(),
                urdf.as_ptr(),
                srdf.as_ptr(),
                null(),
                null(),
                &mut r,
            ),
            inv,
            robot_code,
            "none.srdf",
        );
        fails(
            gjkd_register_robot(
                c,
                c"r".as_ptr(),
                urdf.as_ptr(),
                null(),
                null(),
                &nan,
                &mut r,
            ),
            inv,
            gjkd_error_code::GJKD_CODE_NON_FINITE_POSE as u32,
            "base",
        );
        fails(
            gjkd_register_robot(
                c,
                c"arm".as_ptr(),
                urdf.as_ptr(),
                null(),
                null(),
                null(),
                &mut r,
            ),
            rej,
            code(gjkd_error_code::GJKD_CODE_NAME_TAKEN),
            "NAME_TAKEN",
        );
        fails(
            gjkd_register_robot_text(
                c,
                c"r".as_ptr(),
                c"<robot".as_ptr(),
                null(),
                null(),
                null(),
                null(),
                &mut r,
            ),
            inv,
            robot_code,
            "",
        );
        // Text: the relative mesh path resolves against mesh_dir only.
        fails(
            gjkd_register_robot_text(
                c,
                c"r".as_ptr(),
                text.as_ptr(),
                null(),
                null(),
                null(),
                null(),
                &mut r,
            ),
            inv,
            robot_code,
            "fore.stl",
        );
        let bad_srdf = c"<robot name=\"testarm\"><disable_collisions link1=\"base\" link2=\"nolink\"/></robot>";
        let d = cstr(&dir);
        fails(
            gjkd_register_robot_text(
                c,
                c"r".as_ptr(),
                text.as_ptr(),
                bad_srdf.as_ptr(),
                d.as_ptr(),
                null(),
                null(),
                &mut r,
            ),
            inv,
            robot_code,
            "nolink",
        );
        assert!(r.is_null(), "a failed registration writes NULL");
        // Nothing was left behind: the name is free, and text with a mesh
        // folder registers.
        ok(gjkd_register_robot_text(
            c,
            c"r".as_ptr(),
            text.as_ptr(),
            null(),
            d.as_ptr(),
            null(),
            null(),
            &mut r,
        ));
        ok(gjkd_robot_free(r));
        fails(
            gjkd_open_robot(c, c"nobody".as_ptr(), text.as_ptr(), &mut r),
            rej,
            code(gjkd_error_code::GJKD_CODE_UNKNOWN_NAME),
            "UNKNOWN_NAME",
        );
        fails(
            gjkd_open_robot(c, c"arm".as_ptr(), c"<robot".as_ptr(), &mut r),
            inv,
            robot_code,
            "the robot cannot be read",
        );

        // Listing.
        fails(
            gjkd_robot_info(null(), &mut id, null_mut(), null_mut()),
            null_p,
            0,
            "robot is NULL",
        );
        fails(
            gjkd_robot_link(robot, 5, null_mut(), &mut id),
            inv,
            0,
            "index 5: the robot has 5 links",
        );
        fails(
            gjkd_robot_joint(robot, 3, null_mut(), null_mut(), null_mut(), null_mut()),
            inv,
            0,
            "3 moving joints",
        );
        fails(
            // Looked up in the handle: no refusal by the server.
            gjkd_robot_link_id(robot, c"elbow".as_ptr(), &mut id),
            inv,
            code(gjkd_error_code::GJKD_CODE_UNKNOWN_NAME),
            "link `elbow`",
        );
        fails(
            gjkd_robot_link_id(robot, null(), &mut id),
            null_p,
            0,
            "name is NULL",
        );

        // Joints: nothing moves on any of these.
        ok(gjkd_set_joints(
            c,
            robot,
            [0.1, 0.2, 0.05].as_ptr(),
            3,
            null(),
            false,
        ));
        let lim = code(gjkd_error_code::GJKD_CODE_OUT_OF_LIMITS);
        let nonfinite = code(gjkd_error_code::GJKD_CODE_NON_FINITE_POSE);
        fails(
            gjkd_set_joints(c, robot, [0.0, 2.5, 0.0].as_ptr(), 3, null(), false),
            inv,
            lim,
            "joint `elbow`",
        );
        fails(
            gjkd_set_joints(c, robot, [0.0, 0.0, f64::NAN].as_ptr(), 3, null(), false),
            inv,
            nonfinite,
            "joint `slide`",
        );
        fails(
            gjkd_set_joints(c, robot, [0.0; 2].as_ptr(), 2, null(), false),
            inv,
            0,
            "count 2: the robot has 3 moving joints",
        );
        fails(
            gjkd_set_joints(c, robot, null(), 3, null(), false),
            null_p,
            0,
            "positions is NULL",
        );
        fails(
            gjkd_set_joints(c, null_mut(), [0.0; 3].as_ptr(), 3, null(), false),
            null_p,
            0,
            "robot is NULL",
        );
        fails(
            gjkd_set_joints(null_mut(), robot, [0.0; 3].as_ptr(), 3, null(), false),
            null_p,
            0,
            "client is NULL",
        );
        fails(
            gjkd_set_joints(c, robot, [0.0; 3].as_ptr(), 3, &nan, false),
            inv,
            gjkd_error_code::GJKD_CODE_NON_FINITE_POSE as u32,
            "base",
        );
        let names = [c"wrist".as_ptr()];
        fails(
            gjkd_set_joints_by_name(c, robot, names.as_ptr(), [0.0].as_ptr(), 1, false),
            inv,
            gjkd_error_code::GJKD_CODE_UNKNOWN_NAME as u32,
            "wrist",
        );
        let names = [null()];
        fails(
            gjkd_set_joints_by_name(c, robot, names.as_ptr(), [0.0].as_ptr(), 1, false),
            null_p,
            0,
            "names[0] is NULL",
        );
        let mut poses = [at(0.0, 0.0, 0.0); 5];
        fails(
            gjkd_robot_link_poses(robot, null(), 0, null(), false, poses.as_mut_ptr(), 4),
            inv,
            0,
            "out_count 4",
        );
        fails(
            gjkd_robot_link_poses(robot, null(), 0, null(), false, null_mut(), 5),
            null_p,
            0,
            "out_poses",
        );
        fails(
            gjkd_robot_link_poses(
                robot,
                [0.0, 3.0, 0.0].as_ptr(),
                3,
                null(),
                false,
                poses.as_mut_ptr(),
                5,
            ),
            inv,
            lim,
            "elbow",
        );
        let mut got = [0.0; 3];
        for (i, g) in got.iter_mut().enumerate() {
            ok(gjkd_robot_joint(
                robot,
                i,
                null_mut(),
                null_mut(),
                null_mut(),
                g,
            ));
        }
        assert_eq!(got, [0.1, 0.2, 0.05]);
        // The server kept them too: the tip where [0.1, 0.2, 0.05] puts it.
        let tip = link_id(robot, c"tip");
        let frames = hand_fk([0.1, 0.2, 0.05], Isometry3::identity());
        let p = frames[3] * nalgebra::Point3::new(0.05, 0.0, 0.0)
            + frames[3].rotation * Vector3::z() * 0.3;
        let b = ball(c, 0.05, &at(p.x, p.y, p.z));
        assert!((dist(c, tip, b) - 0.2).abs() < 1e-9);
        // The client and the robot serve any thread, one call at a time.
        let (c_addr, robot_addr) = (c as usize, robot as usize);
        let other = std::thread::spawn(move || {
            let (c, r) = (c_addr as *mut gjkd_client, robot_addr as *mut gjkd_robot);
            gjkd_set_joints(c, r, [0.1, 0.2, 0.05].as_ptr(), 3, null(), false)
        });
        assert_eq!(other.join().unwrap(), GJKD_OK);
        assert!((dist(c, tip, b) - 0.2).abs() < 1e-9);
        ok(gjkd_robot_free(robot));
        ok(gjkd_close(c));
    }
    let _ = std::fs::remove_dir_all(dir);
}
