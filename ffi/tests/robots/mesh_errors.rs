//! Every mesh registration error through the C API, with its status,
//! code and message.

use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;

use gjkd_status::*;

use crate::arm::*;

#[test]
fn every_mesh_error_has_its_status() {
    let server = Server::start("ffi-mesh-errors", &["--no-persist"]);
    let dir = arm_dir("mesh-errors");
    let c = connect(&server);
    let nan = at(f64::NAN, 0.0, 0.0);
    let (inv, null_p) = (GJKD_ERR_INVALID_ARGUMENT, GJKD_ERR_NULL_POINTER);
    // SAFETY: valid pointers or NULLs where tested.
    unsafe {
        let mut id = 0;
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
        ok(gjkd_close(c));
    }
    let _ = std::fs::remove_dir_all(dir);
}
