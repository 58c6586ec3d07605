//! A robot listed, moved and answering, against transforms computed by
//! hand and analytic distances.

use std::ffi::{CStr, CString, c_char};
use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use crate::arm::*;

#[test]
fn a_robot_lists_moves_and_answers() {
    let server = Server::start("ffi-robot", &["--no-persist"]);
    let dir = arm_dir("answers");
    let c = connect(&server);
    let robot = register_arm(c, &dir, "arm");
    // SAFETY: valid pointers throughout.
    unsafe {
        let (mut id, mut links, mut joints) = (0, 0, 0);
        ok(gjkd_robot_info(robot, &mut id, &mut links, &mut joints));
        assert!(id != 0);
        assert_eq!((links, joints), (5, 3));
        let mut names = vec![];
        for i in 0..links {
            let (mut name, mut link): (*const c_char, gjkd_id) = (null(), 0);
            ok(gjkd_robot_link(robot, i, &mut name, &mut link));
            names.push(CStr::from_ptr(name).to_str().unwrap().to_owned());
            assert_eq!(link == 0, i == 4, "only the tool has no geometry");
        }
        assert_eq!(names, ["base", "upper", "fore", "tip", "tool"]);
        let (mut name, mut lo, mut hi, mut q) = (null(), 0.0, 0.0, 1.0);
        ok(gjkd_robot_joint(
            robot, 2, &mut name, &mut lo, &mut hi, &mut q,
        ));
        assert_eq!(CStr::from_ptr(name).to_str().unwrap(), "slide");
        assert_eq!((lo, hi, q), (0.0, 0.2, 0.0));
        assert_eq!(link_id(robot, c"tool"), 0);

        // Forward kinematics against the hand-written transforms.
        let base = Isometry3::from_parts(
            Translation3::new(1.0, 2.0, 0.0),
            UnitQuaternion::from_scaled_axis(Vector3::z() * -0.4),
        );
        let wire_base = {
            let (t, r) = (base.translation.vector, base.rotation.coords);
            gjkd_pose {
                translation: [t.x, t.y, t.z],
                rotation: [r.x, r.y, r.z, r.w],
            }
        };
        let ball = ball(c, 0.05, &at(0.0, 0.0, 0.0));
        let tip = link_id(robot, c"tip");
        let upper = link_id(robot, c"upper");
        for (k, q) in [[0.3, -1.0, 0.05], [-2.5, 1.9, 0.2], [1.0, 0.0, 0.0]]
            .into_iter()
            .enumerate()
        {
            let b = if k == 0 {
                &wire_base as *const _
            } else {
                null()
            };
            ok(gjkd_set_joints(c, robot, q.as_ptr(), 3, b, false));
            let frames = hand_fk(q, base);
            let mut poses = [at(0.0, 0.0, 0.0); 5];
            ok(gjkd_robot_link_poses(
                robot,
                null(),
                0,
                null(),
                false,
                poses.as_mut_ptr(),
                5,
            ));
            for (i, f) in frames.iter().enumerate() {
                let got = poses[i].isometry().to_homogeneous();
                assert!((got - f.to_homogeneous()).abs().max() < 1e-12, "link {i}");
            }
            // A ball 0.3 along a link's local z is 0.2 from it (both 0.05).
            for (link, frame, centre) in [
                (tip, frames[3], [0.05, 0.0, 0.0]),
                (upper, frames[1], [0.0; 3]),
            ] {
                let p =
                    frame * nalgebra::Point3::from(centre) + frame.rotation * Vector3::z() * 0.3;
                ok(gjkd_set_pose(c, ball, &at(p.x, p.y, p.z)));
                let d = dist(c, link, ball);
                assert!((d - 0.2).abs() < 1e-9, "step {k}: {d}");
            }
        }
        // By name, then clamped.
        let names = [c"elbow".as_ptr()];
        ok(gjkd_set_joints_by_name(
            c,
            robot,
            names.as_ptr(),
            [0.5].as_ptr(),
            1,
            false,
        ));
        let mut q = 0.0;
        ok(gjkd_robot_joint(
            robot,
            1,
            null_mut(),
            null_mut(),
            null_mut(),
            &mut q,
        ));
        assert_eq!(q, 0.5);
        ok(gjkd_set_joints(
            c,
            robot,
            [0.0, 9.0, -1.0].as_ptr(),
            3,
            null(),
            true,
        ));
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
        assert_eq!(got, [0.0, 2.0, 0.0]);

        // Another handle opens it by name.
        let mut other = null_mut();
        let urdf = CString::new(ARM_URDF).unwrap();
        ok(gjkd_open_robot(
            c,
            c"arm".as_ptr(),
            urdf.as_ptr(),
            &mut other,
        ));
        let mut other_id = 0;
        ok(gjkd_robot_info(
            other,
            &mut other_id,
            null_mut(),
            null_mut(),
        ));
        assert_eq!(other_id, id);
        ok(gjkd_robot_free(other));
        ok(gjkd_robot_free(robot));
        ok(gjkd_robot_free(null_mut()));
        ok(gjkd_close(c));
    }
    let _ = std::fs::remove_dir_all(dir);
}
