//! Meshes and robots through the C API, against a real server: a URDF arm
//! written here (box, sphere and STL mesh links; revolute, prismatic and
//! fixed joints), its link poses against transforms computed here by hand,
//! link distances against analytic answers, and every error path with its
//! status, code and message.
// Robots and meshes are in the library with its `robots` feature only.
#![cfg(feature = "robots")]

use std::ffi::{CStr, CString, c_char};
use std::path::Path;
use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use gjkd_status::*;

const ARM_URDF: &str = r#"<?xml version="1.0"?>
<robot name="testarm">
  <link name="base">
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <collision><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <link name="fore">
    <collision><geometry><mesh filename="meshes/fore.stl"/></geometry></collision>
  </link>
  <link name="tip">
    <collision>
      <origin xyz="0.05 0 0" rpy="0 0 0"/>
      <geometry><box size="0.1 0.1 0.1"/></geometry>
    </collision>
  </link>
  <link name="tool"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/>
    <origin xyz="0.5 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="fore"/><child link="tip"/>
    <origin xyz="0.4 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.2" effort="1" velocity="1"/>
  </joint>
  <joint name="flange" type="fixed">
    <parent link="tip"/><child link="tool"/>
    <origin xyz="0.1 0 0" rpy="0 0 0"/>
  </joint>
</robot>
"#;

/// A binary STL of the box `[lo, hi]`.
fn box_stl(lo: [f32; 3], hi: [f32; 3]) -> Vec<u8> {
    let corner = |i: usize| {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut out = vec![b' '; 80];
    out.extend_from_slice(&12u32.to_le_bytes());
    for [a, b, c, d] in quads {
        for tri in [[a, b, c], [a, c, d]] {
            out.extend_from_slice(&[0u8; 12]);
            for i in tri {
                for v in corner(i) {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
            out.extend_from_slice(&[0, 0]);
        }
    }
    out
}

/// A folder with `arm.urdf` and `meshes/fore.stl`.
fn arm_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("gjkd-c-robots-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("meshes")).unwrap();
    std::fs::write(
        dir.join("meshes/fore.stl"),
        box_stl([0.0, -0.05, -0.05], [0.4, 0.05, 0.05]),
    )
    .unwrap();
    std::fs::write(dir.join("arm.urdf"), ARM_URDF).unwrap();
    dir
}

fn last() -> (String, u32) {
    // SAFETY: never NULL, lives until the next call on this thread.
    let msg = unsafe { CStr::from_ptr(gjkd_last_error()) };
    (msg.to_string_lossy().into_owned(), gjkd_last_error_code())
}

#[track_caller]
fn ok(status: gjkd_status) {
    assert_eq!(status, GJKD_OK, "{:?}", last());
}

/// Asserts the status, the code and words of the message.
#[track_caller]
fn fails(status: gjkd_status, want: gjkd_status, code: u32, words: &str) {
    let (msg, got) = last();
    assert_eq!(status, want, "message: {msg}");
    assert_eq!(got, code, "message: {msg}");
    assert!(msg.contains(words), "`{words}` not in `{msg}`");
}

fn connect(server: &Server) -> *mut gjkd_client {
    let service = CString::new(server.service.clone()).unwrap();
    let mut client = null_mut();
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_connect(service.as_ptr(), 2.0, 10.0, &mut client) });
    client
}

fn cstr(p: &Path) -> CString {
    CString::new(p.to_str().unwrap()).unwrap()
}

fn at(x: f64, y: f64, z: f64) -> gjkd_pose {
    gjkd_pose {
        translation: [x, y, z],
        rotation: [0.0, 0.0, 0.0, 1.0],
    }
}

fn dist(c: *mut gjkd_client, a: gjkd_id, b: gjkd_id) -> f64 {
    let mut ans = gjkd_answer::default();
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_distance(c, a, b, null(), null(), null(), &mut ans) });
    ans.distance
}

fn ball(c: *mut gjkd_client, r: f64, p: &gjkd_pose) -> gjkd_id {
    let mut id = 0;
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_register_sphere(c, r, null(), p, &mut id) });
    id
}

/// The arm's links by hand: (upper, fore, tip) frames for `q` on `base`.
fn hand_fk(q: [f64; 3], base: Isometry3<f64>) -> [Isometry3<f64>; 4] {
    let t = |x, y, z| Isometry3::from_parts(Translation3::new(x, y, z), UnitQuaternion::identity());
    let r = |axis: Vector3<f64>, a: f64| {
        Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_scaled_axis(axis * a),
        )
    };
    let upper = base * t(0.0, 0.0, 0.1) * r(Vector3::z(), q[0]);
    let fore = upper * t(0.5, 0.0, 0.0) * r(Vector3::y(), q[1]);
    let tip = fore * t(0.4 + q[2], 0.0, 0.0);
    [base, upper, fore, tip]
}

fn register_arm(c: *mut gjkd_client, dir: &Path, name: &str) -> *mut gjkd_robot {
    let (name, urdf) = (CString::new(name).unwrap(), cstr(&dir.join("arm.urdf")));
    let mut robot = null_mut();
    // SAFETY: valid pointers.
    ok(unsafe {
        gjkd_register_robot(
            c,
            name.as_ptr(),
            urdf.as_ptr(),
            null(),
            null(),
            null(),
            &mut robot,
        )
    });
    assert!(!robot.is_null());
    robot
}

fn link_id(robot: *const gjkd_robot, name: &CStr) -> gjkd_id {
    let mut id = 0;
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_robot_link_id(robot, name.as_ptr(), &mut id) });
    id
}

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

#[test]
fn meshes_register_from_files_and_arrays() {
    let server = Server::start("ffi-mesh", &["--no-persist"]);
    let dir = arm_dir("mesh");
    let c = connect(&server);
    // SAFETY: valid pointers throughout.
    unsafe {
        let path = cstr(&dir.join("meshes/fore.stl"));
        let (mut id, mut info) = (0, gjkd_mesh_info::default());
        let scale = [2.0, 1.0, 1.0];
        ok(gjkd_register_mesh_file(
            c,
            path.as_ptr(),
            scale.as_ptr(),
            0,
            c"fore".as_ptr(),
            null(),
            &mut id,
            &mut info,
        ));
        assert_eq!((info.pieces, info.deviation), (1, 0.0));
        // Spans x in [0, 0.8] once scaled (0.4 in single precision, as STL
        // holds it).
        let b = ball(c, 0.1, &at(1.5, 0.0, 0.0));
        let end = 2.0 * f64::from(0.4f32);
        assert!((dist(c, id, b) - (1.4 - end)).abs() < 1e-9);
        // The same box from arrays, as a hull and decomposed.
        let v: Vec<f64> = (0..8)
            .flat_map(|i| {
                [
                    if i & 1 == 0 { -1.0 } else { 1.0 },
                    if i & 2 == 0 { -1.0 } else { 1.0 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                ]
            })
            .collect();
        let t: [u32; 36] = [
            0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6,
            2, 1, 3, 7, 1, 7, 5,
        ];
        let pose = at(0.0, 5.0, 0.0);
        ok(gjkd_register_mesh(
            c,
            v.as_ptr(),
            8,
            t.as_ptr(),
            12,
            null(),
            0,
            null(),
            &pose,
            &mut id,
            null_mut(),
        ));
        ok(gjkd_set_pose(c, b, &at(0.0, 8.0, 0.0)));
        assert!((dist(c, id, b) - 1.9).abs() < 1e-9);
        ok(gjkd_register_mesh(
            c,
            v.as_ptr(),
            8,
            t.as_ptr(),
            12,
            null(),
            16,
            null(),
            &pose,
            &mut id,
            &mut info,
        ));
        assert!(info.pieces >= 1 && info.deviation >= 0.0);
        assert!((dist(c, id, b) - 1.9).abs() < 1e-3, "{}", dist(c, id, b));
        ok(gjkd_close(c));
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn every_mesh_and_robot_error_has_its_status() {
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
        // Meshes.
        let missing = cstr(&dir.join("none.stl"));
        fails(
            gjkd_register_mesh_file(
                c,
                missing.as_ptr(),
                null(),
                0,
                null(),
                null(),
                &mut id,
                null_mut(),
            ),
            inv,
            0,
            "none.stl",
        );
        let junk = dir.join("junk.stl");
        std::fs::write(&junk, "not a mesh").unwrap();
        let junk = cstr(&junk);
        fails(
            gjkd_register_mesh_file(
                c,
                junk.as_ptr(),
                null(),
                0,
                null(),
                null(),
                &mut id,
                null_mut(),
            ),
            inv,
            0,
            "junk.stl",
        );
        fails(
            gjkd_register_mesh_file(c, null(), null(), 0, null(), null(), &mut id, null_mut()),
            null_p,
            0,
            "path is NULL",
        );
        let mesh = cstr(&dir.join("meshes/fore.stl"));
        fails(
            gjkd_register_mesh_file(
                c,
                mesh.as_ptr(),
                null(),
                0,
                null(),
                null(),
                null_mut(),
                null_mut(),
            ),
            null_p,
            0,
            "out_id",
        );
        let zero = [1.0, 0.0, 1.0];
        fails(
            gjkd_register_mesh_file(
                c,
                mesh.as_ptr(),
                zero.as_ptr(),
                0,
                null(),
                null(),
                &mut id,
                null_mut(),
            ),
            inv,
            0,
            "scale",
        );
        fails(
            gjkd_register_mesh_file(
                c,
                mesh.as_ptr(),
                null(),
                0,
                null(),
                &nan,
                &mut id,
                null_mut(),
            ),
            inv,
            gjkd_error_code::GJKD_CODE_NON_FINITE_POSE as u32,
            "pose",
        );
        fails(
            gjkd_register_mesh_file(
                c,
                mesh.as_ptr(),
                null(),
                0,
                c"".as_ptr(),
                null(),
                &mut id,
                null_mut(),
            ),
            inv,
            0,
            "name is empty",
        );
        let v = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, f64::NAN, 0.0];
        let t = [0u32, 1, 2];
        fails(
            gjkd_register_mesh(
                c,
                v.as_ptr(),
                3,
                t.as_ptr(),
                1,
                null(),
                0,
                null(),
                null(),
                &mut id,
                null_mut(),
            ),
            inv,
            0,
            "vertex 2",
        );
        fails(
            gjkd_register_mesh(
                c,
                v.as_ptr(),
                0,
                null(),
                0,
                null(),
                0,
                null(),
                null(),
                &mut id,
                null_mut(),
            ),
            inv,
            0,
            "no vertices",
        );
        fails(
            gjkd_register_mesh(
                c,
                null(),
                3,
                null(),
                0,
                null(),
                0,
                null(),
                null(),
                &mut id,
                null_mut(),
            ),
            null_p,
            0,
            "vertices is NULL",
        );
        fails(
            gjkd_register_mesh(
                c,
                v.as_ptr(),
                2,
                null(),
                1,
                null(),
                0,
                null(),
                null(),
                &mut id,
                null_mut(),
            ),
            null_p,
            0,
            "triangles is NULL",
        );
        let bad_t = [0u32, 1, 7];
        fails(
            gjkd_register_mesh(
                c,
                v.as_ptr(),
                2,
                bad_t.as_ptr(),
                1,
                null(),
                0,
                null(),
                null(),
                &mut id,
                null_mut(),
            ),
            inv,
            0,
            "names vertex 7",
        );
        fails(
            gjkd_register_mesh(
                c,
                v.as_ptr(),
                2,
                null(),
                0,
                null(),
                8,
                null(),
                null(),
                &mut id,
                null_mut(),
            ),
            inv,
            0,
            "needs the mesh's triangles",
        );
        fails(
            gjkd_register_mesh(
                c,
                v.as_ptr(),
                usize::MAX,
                null(),
                0,
                null(),
                0,
                null(),
                null(),
                &mut id,
                null_mut(),
            ),
            inv,
            0,
            "larger than any array",
        );
        assert_eq!(id, 0, "a failed registration writes 0");

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

#[test]
fn cylinders_match_closed_forms() {
    let server = Server::start("ffi-cylinder", &["--no-persist"]);
    let c = connect(&server);
    // SAFETY: valid pointers throughout.
    unsafe {
        let mut cyl = 0;
        ok(gjkd_register_cylinder(
            c,
            0.5,
            1.0,
            0.0,
            null(),
            null(),
            &mut cyl,
        ));
        let shape = gjkd_shape {
            kind: gjkd_shape_kind::GJKD_SHAPE_CYLINDER as u32,
            radius: 0.1,
            a: [0.5, 1.0, 0.0],
            b: [0.0; 3],
            vertices: null(),
            vertex_count: 0,
        };
        let mut rounded = 0;
        ok(gjkd_register(
            c,
            &shape,
            null(),
            &at(10.0, 0.0, 0.0),
            &mut rounded,
        ));
        let piece = gjkd_piece {
            offset: at(0.0, 0.0, 0.0),
            shape: gjkd_shape {
                radius: 0.0,
                ..shape
            },
        };
        let mut comp = 0;
        ok(gjkd_register_compound(
            c,
            &piece,
            1,
            null(),
            &at(20.0, 0.0, 0.0),
            &mut comp,
        ));
        let b = ball(c, 0.25, &at(0.0, 0.0, 0.0));
        for (p, want) in [
            ([2.0, 0.0, 0.3], 1.25),
            ([0.2, 0.1, -3.0], 1.75),
            ([2.0, 0.0, 2.0], 1.5f64.hypot(1.0) - 0.25),
        ] {
            for (id, dx, less) in [(cyl, 0.0, 0.0), (rounded, 10.0, 0.1), (comp, 20.0, 0.0)] {
                ok(gjkd_set_pose(c, b, &at(p[0] + dx, p[1], p[2])));
                let d = dist(c, id, b);
                assert!((d - (want - less)).abs() < 1e-9, "{p:?} {dx}: {d}");
            }
        }
        let code = gjkd_error_code::GJKD_CODE_INVALID_RADIUS as u32;
        for (r, h, round) in [(-0.5, 1.0, 0.0), (0.5, f64::NAN, 0.0), (0.5, 1.0, -1.0)] {
            let mut id = 7;
            let s = gjkd_register_cylinder(c, r, h, round, null(), null(), &mut id);
            fails(s, GJKD_ERR_REJECTED, code, "INVALID_RADIUS");
            assert_eq!(id, 0);
        }
        fails(
            gjkd_register_cylinder(null_mut(), 0.5, 1.0, 0.0, null(), null(), &mut cyl),
            GJKD_ERR_NULL_POINTER,
            0,
            "client is NULL",
        );
        ok(gjkd_close(c));
    }
}
