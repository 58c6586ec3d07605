//! Meshes registered from files and from arrays.

use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;

use crate::arm::*;

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
