//! The C API's scene queries answer as the Rust client's, row for row, and
//! each failure has its status, code and message: clearance, within,
//! nearest and paths into caller-owned row arrays.

use std::ffi::CStr;
use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;
use nalgebra::Isometry3;
use rust_client::{ObjectId, SceneRow, Steps};

use gjkd_status::*;

fn ok(status: gjkd_status) {
    assert_eq!(status, GJKD_OK, "{:?}", unsafe {
        CStr::from_ptr(gjkd_last_error())
    });
}

fn at(x: f64, y: f64) -> gjkd_pose {
    gjkd_pose {
        translation: [x, y, 0.0],
        rotation: [0.0, 0.0, 0.0, 1.0],
    }
}

fn last_error() -> String {
    // SAFETY: the library's own NUL-terminated message.
    unsafe { CStr::from_ptr(gjkd_last_error()) }
        .to_string_lossy()
        .into_owned()
}

fn members(ids: &[gjkd_id]) -> gjkd_group {
    gjkd_group {
        id: 0,
        members: ids.as_ptr(),
        member_count: ids.len(),
        allowed: null(),
        allowed_count: 0,
    }
}

fn same(c_row: &gjkd_scene_row, row: &SceneRow) {
    assert_eq!((c_row.a, c_row.b, c_row.step), (row.a, row.b, row.step));
    assert_eq!(c_row.error, row.result.error);
    assert_eq!(c_row.answer.lower, row.result.lower);
    assert_eq!(c_row.answer.upper, row.result.upper);
}

#[test]
fn scene_calls_answer_as_the_rust_client() {
    let server = Server::start("ffi-scene", &["--no-persist", "--wait", "spin"]);
    let service = std::ffi::CString::new(server.service.clone()).unwrap();
    let mut c = null_mut();
    // SAFETY: valid pointers throughout; the handle is live until closed.
    unsafe {
        ok(gjkd_connect(service.as_ptr(), 2.0, 10.0, &mut c));
        let mut ids = [0; 5];
        for (i, id) in ids.iter_mut().enumerate() {
            ok(gjkd_register_sphere(c, 0.5, null(), null(), id));
            ok(gjkd_set_pose(c, *id, &at(2.0 * i as f64, 0.1 * i as f64)));
        }
        let group = members(&ids[..2]);
        let mut rust = server.client(std::time::Duration::from_secs(2));
        let oids: Vec<ObjectId> = ids.iter().map(|&i| ObjectId::from_raw(i)).collect();
        let mut rows = [gjkd_scene_row::default(); 8];
        let mut want = [SceneRow::default(); 8];
        let mut s = gjkd_scene_summary::default();

        let cold = gjkd_scene_options {
            warm_start: false,
            ..gjkd_scene_options_default()
        };
        ok(gjkd_clearance(
            c,
            &group,
            &cold,
            rows.as_mut_ptr(),
            8,
            &mut s,
        ));
        let r = rust
            .clearance(&oids[..2])
            .warm(false)
            .into_rows(&mut want)
            .expect("rust clearance");
        assert_eq!((s.written, s.total), (r.written, r.total));
        assert_eq!(s.written, 2);
        rows[..2].iter().zip(&want).for_each(|(x, y)| same(x, y));
        // Balls 2 apart centre to centre, radius 0.5: the second member's
        // nearest outside the group is the third ball.
        assert_eq!(rows[1].b, ids[2]);

        ok(gjkd_within(
            c,
            &group,
            3.5,
            &cold,
            rows.as_mut_ptr(),
            8,
            &mut s,
        ));
        let r = rust
            .within(&oids[..2], 3.5)
            .warm(false)
            .into_rows(&mut want)
            .expect("rust within");
        assert_eq!(s.total, r.total);
        rows[..s.written]
            .iter()
            .zip(&want)
            .for_each(|(x, y)| same(x, y));
        // Truncated into a row array of one.
        ok(gjkd_within(
            c,
            &group,
            3.5,
            &cold,
            rows.as_mut_ptr(),
            1,
            &mut s,
        ));
        assert!(s.truncated && s.written == 1);

        ok(gjkd_nearest(
            c,
            ids[4],
            2,
            &cold,
            rows.as_mut_ptr(),
            8,
            &mut s,
        ));
        assert_eq!(s.written, 2);
        assert_eq!((rows[0].b, rows[1].b), (ids[3], ids[2]));

        let moving = [ids[0]];
        let poses: Vec<gjkd_pose> = (0..4).map(|k| at(-1.0 - k as f64, 0.0)).collect();
        ok(gjkd_path(
            c,
            &members(&moving),
            gjkd_path_question::GJKD_PATH_CLEARANCE as u32,
            0.0,
            moving.as_ptr(),
            1,
            poses.as_ptr(),
            4,
            &cold,
            rows.as_mut_ptr(),
            8,
            &mut s,
        ));
        let isos: Vec<Isometry3<f64>> = (0..4)
            .map(|k| Isometry3::translation(-1.0 - k as f64, 0.0, 0.0))
            .collect();
        let r = rust
            .path(
                &oids[..1],
                Steps::Poses {
                    objects: &oids[..1],
                    poses: &isos,
                },
            )
            .warm(false)
            .into_rows(&mut want)
            .expect("rust path");
        assert_eq!((s.steps, s.written), (4, 4));
        assert_eq!(r.written, 4);
        rows[..4].iter().zip(&want).for_each(|(x, y)| same(x, y));

        // Errors: each with its status, code and words.
        let unknown = gjkd_group {
            id: 0xdead_0000_0001,
            ..members(&[])
        };
        assert_eq!(
            gjkd_clearance(c, &unknown, null(), rows.as_mut_ptr(), 8, &mut s),
            GJKD_ERR_REJECTED
        );
        assert_eq!(
            gjkd_last_error_code(),
            gjkd_error_code::GJKD_CODE_UNKNOWN_OBJECT as u32
        );
        assert!(
            last_error().starts_with("gjkd_clearance: "),
            "{}",
            last_error()
        );
        assert_eq!(s, gjkd_scene_summary::default(), "zeroed on failure");
        assert_eq!(
            gjkd_within(c, &group, f64::NAN, null(), rows.as_mut_ptr(), 8, &mut s),
            GJKD_ERR_REJECTED
        );
        assert_eq!(
            gjkd_last_error_code(),
            gjkd_error_code::GJKD_CODE_INVALID_OPTIONS as u32
        );
        assert_eq!(
            gjkd_clearance(c, null(), null(), rows.as_mut_ptr(), 8, &mut s),
            GJKD_ERR_NULL_POINTER
        );
        assert_eq!(
            gjkd_clearance(c, &group, null(), null_mut(), 8, &mut s),
            GJKD_ERR_NULL_POINTER
        );
        assert_eq!(
            gjkd_clearance(c, &group, null(), rows.as_mut_ptr(), 8, null_mut()),
            GJKD_ERR_NULL_POINTER
        );
        let nan = [gjkd_pose {
            translation: [f64::NAN, 0.0, 0.0],
            ..at(0.0, 0.0)
        }];
        assert_eq!(
            gjkd_path(
                c,
                &group,
                0,
                0.0,
                moving.as_ptr(),
                1,
                nan.as_ptr(),
                1,
                null(),
                rows.as_mut_ptr(),
                8,
                &mut s
            ),
            GJKD_ERR_INVALID_ARGUMENT
        );
        assert!(last_error().contains("poses[0]"), "{}", last_error());
        assert_eq!(
            gjkd_path(
                c,
                &group,
                7,
                0.0,
                moving.as_ptr(),
                1,
                poses.as_ptr(),
                1,
                null(),
                rows.as_mut_ptr(),
                8,
                &mut s
            ),
            GJKD_ERR_INVALID_ARGUMENT
        );
        gjkd_close(c);
    }
}
