//! The arm the robot tests share (a URDF written here, with box, sphere
//! and STL mesh links; revolute, prismatic and fixed joints), its hand-made
//! forward kinematics, and the small helpers every test of the C API here
//! uses.

use std::ffi::{CStr, CString};
use std::path::Path;
use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use gjkd_status::*;

pub(crate) const ARM_URDF: &str = r#"<?xml version="1.0"?>
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
pub(crate) fn box_stl(lo: [f32; 3], hi: [f32; 3]) -> Vec<u8> {
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
pub(crate) fn arm_dir(tag: &str) -> std::path::PathBuf {
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

pub(crate) fn last() -> (String, u32) {
    // SAFETY: never NULL, lives until the next call on this thread.
    let msg = unsafe { CStr::from_ptr(gjkd_last_error()) };
    (msg.to_string_lossy().into_owned(), gjkd_last_error_code())
}

#[track_caller]
pub(crate) fn ok(status: gjkd_status) {
    assert_eq!(status, GJKD_OK, "{:?}", last());
}

/// Asserts the status, the code and words of the message.
#[track_caller]
pub(crate) fn fails(status: gjkd_status, want: gjkd_status, code: u32, words: &str) {
    let (msg, got) = last();
    assert_eq!(status, want, "message: {msg}");
    assert_eq!(got, code, "message: {msg}");
    assert!(msg.contains(words), "`{words}` not in `{msg}`");
}

pub(crate) fn connect(server: &Server) -> *mut gjkd_client {
    let service = CString::new(server.service.clone()).unwrap();
    let mut client = null_mut();
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_connect(service.as_ptr(), 2.0, 10.0, &mut client) });
    client
}

pub(crate) fn cstr(p: &Path) -> CString {
    CString::new(p.to_str().unwrap()).unwrap()
}

pub(crate) fn at(x: f64, y: f64, z: f64) -> gjkd_pose {
    gjkd_pose {
        translation: [x, y, z],
        rotation: [0.0, 0.0, 0.0, 1.0],
    }
}

pub(crate) fn dist(c: *mut gjkd_client, a: gjkd_id, b: gjkd_id) -> f64 {
    let mut ans = gjkd_answer::default();
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_distance(c, a, b, null(), null(), null(), &mut ans) });
    ans.distance
}

pub(crate) fn ball(c: *mut gjkd_client, r: f64, p: &gjkd_pose) -> gjkd_id {
    let mut id = 0;
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_register_sphere(c, r, null(), p, &mut id) });
    id
}

/// The arm's links by hand: (upper, fore, tip) frames for `q` on `base`.
pub(crate) fn hand_fk(q: [f64; 3], base: Isometry3<f64>) -> [Isometry3<f64>; 4] {
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

pub(crate) fn register_arm(c: *mut gjkd_client, dir: &Path, name: &str) -> *mut gjkd_robot {
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

pub(crate) fn link_id(robot: *const gjkd_robot, name: &CStr) -> gjkd_id {
    let mut id = 0;
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_robot_link_id(robot, name.as_ptr(), &mut id) });
    id
}
