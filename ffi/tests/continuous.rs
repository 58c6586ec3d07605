//! The C API's continuous paths: a thin plate that ten samples miss is
//! found, its first contact bracketed, and a bad bracket is refused.

use std::ffi::CStr;
use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;

use gjkd_status::*;

fn ok(status: gjkd_status) {
    assert_eq!(status, GJKD_OK, "{:?}", unsafe {
        CStr::from_ptr(gjkd_last_error())
    });
}

fn at(x: f64) -> gjkd_pose {
    gjkd_pose {
        translation: [x, 0.0, 0.0],
        rotation: [0.0, 0.0, 0.0, 1.0],
    }
}

#[test]
fn continuous_paths_bracket_the_first_contact() {
    let server = Server::start("ffi-continuous", &["--no-persist", "--wait", "spin"]);
    let service = std::ffi::CString::new(server.service.clone()).unwrap();
    let mut c = null_mut();
    // SAFETY: valid pointers throughout; the handle is live until closed.
    unsafe {
        ok(gjkd_connect(service.as_ptr(), 2.0, 10.0, &mut c));
        let (mut ball, mut plate) = (0, 0);
        ok(gjkd_register_sphere(c, 0.01, null(), null(), &mut ball));
        ok(gjkd_register_box(
            c,
            [0.5e-4, 1.0, 1.0].as_ptr(),
            0.0,
            null(),
            null(),
            &mut plate,
        ));
        let group = gjkd_group {
            id: ball,
            members: null(),
            member_count: 0,
            allowed: null(),
            allowed_count: 0,
        };
        let moving = [ball];
        let ends = [at(-3.0), at(3.3)];
        let mut options = gjkd_scene_options_default();
        options.bracket = 1e-9;
        let mut rows = [gjkd_scene_row::default(); 4];
        let mut s = gjkd_scene_summary::default();
        ok(gjkd_path(
            c,
            &group,
            gjkd_path_question::GJKD_PATH_CONTINUOUS as u32,
            0.0,
            moving.as_ptr(),
            1,
            ends.as_ptr(),
            2,
            &options,
            rows.as_mut_ptr(),
            4,
            &mut s,
        ));
        assert_eq!((s.written, s.first_hit), (1, 0));
        assert_eq!((rows[0].a, rows[0].b), (ball, plate));
        let exact = (3.0 - 0.01005) / 6.3;
        assert!(rows[0].s_lo <= exact && exact <= rows[0].s_hi);
        assert!(rows[0].s_hi - rows[0].s_lo <= 1e-9);
        // Sampled at ten steps, the plate slips between.
        let sampled: Vec<gjkd_pose> = (0..=10).map(|k| at(-3.0 + 0.63 * k as f64)).collect();
        ok(gjkd_path(
            c,
            &group,
            gjkd_path_question::GJKD_PATH_FIRST_HIT as u32,
            0.0,
            moving.as_ptr(),
            1,
            sampled.as_ptr(),
            11,
            &options,
            rows.as_mut_ptr(),
            4,
            &mut s,
        ));
        assert_eq!(s.first_hit, u32::MAX);
        // A bracket of 0 is refused, nothing written.
        options.bracket = 0.0;
        let status = gjkd_path(
            c,
            &group,
            gjkd_path_question::GJKD_PATH_CONTINUOUS as u32,
            0.0,
            moving.as_ptr(),
            1,
            ends.as_ptr(),
            2,
            &options,
            rows.as_mut_ptr(),
            4,
            &mut s,
        );
        assert_ne!(status, GJKD_OK);
        ok(gjkd_close(c));
    }
}
