//! Cylinders through the C API against closed forms.

use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;

use gjkd_status::*;

use crate::arm::*;

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
