//! Signed distances in the C API's batches and scene rows:
//! `gjkd_signed_distances()` (the optional output, NULL = not asked) and
//! `gjkd_scene_options.signed_distance`, against closed forms (a ball of
//! radius 0.5 in the box `[-1, 1]³` is `0.5 + ` its centre's distance to
//! the nearest face deep), through a real server whose batch limit splits
//! the batch; the failure paths (a NULL required array, a failed row).

use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;

use gjkd_status::{GJKD_ERR_NULL_POINTER, GJKD_OK};

fn at(x: f64, y: f64, z: f64) -> gjkd_pose {
    gjkd_pose {
        translation: [x, y, z],
        rotation: [0.0, 0.0, 0.0, 1.0],
    }
}

fn ok(status: gjkd_status) {
    assert_eq!(status, GJKD_OK, "{:?}", unsafe {
        std::ffi::CStr::from_ptr(gjkd_last_error())
    });
}

/// The box and `xs.len()` balls at `(x, 0.1, 0)`; returns their ids.
fn scene(c: *mut gjkd_client, xs: &[f64]) -> (gjkd_id, Vec<gjkd_id>) {
    let mut crate_ = 0;
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_register_box(c, [1.0; 3].as_ptr(), 0.0, null(), null(), &mut crate_) });
    let balls = xs
        .iter()
        .map(|&x| {
            let mut id = 0;
            // SAFETY: valid pointers.
            ok(unsafe { gjkd_register_sphere(c, 0.5, null(), &at(x, 0.1, 0.0), &mut id) });
            id
        })
        .collect();
    (crate_, balls)
}

/// The ball at `(x, 0.1, 0)`'s signed distance to the box.
fn want(x: f64) -> f64 {
    if x <= 1.0 {
        -(0.5 + (1.0 - x.abs()).min(0.9))
    } else {
        x - 1.5
    }
}

#[test]
fn batches_answer_the_signed_distance_into_the_optional_arrays() {
    let server = Server::start("ffi-signed-batch", &["--no-persist", "--max-batch", "3"]);
    let service = std::ffi::CString::new(server.service.clone()).unwrap();
    let mut c = null_mut();
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_connect(service.as_ptr(), 2.0, 10.0, &mut c) });
    let xs = [0.8, 0.5, -0.3, 2.0, 3.25, 0.95, 1.2];
    let (crate_, balls) = scene(c, &xs);
    let mut pairs: Vec<gjkd_id> = balls.iter().flat_map(|&b| [crate_, b]).collect();
    // The last pair names an object that does not exist: a failed row.
    let n = xs.len() + 1;
    pairs.extend([crate_, 999_999]);
    let mut distance = vec![f64::NAN; n];
    let mut error = vec![99u32; n];
    let mut normal = vec![f64::NAN; 3 * n];
    let out = gjkd_results {
        distance: distance.as_mut_ptr(),
        error: error.as_mut_ptr(),
        normal: normal.as_mut_ptr(),
        lower: null_mut(),
        upper: null_mut(),
        penetration: null_mut(),
        point_a: null_mut(),
        point_b: null_mut(),
        status: null_mut(),
        iterations: null_mut(),
        pieces: null_mut(),
        warm_started: null_mut(),
    };
    let (mut value, mut lower, mut upper) =
        (vec![f64::NAN; n], vec![f64::NAN; n], vec![f64::NAN; n]);
    let signed = gjkd_signed_results {
        value: value.as_mut_ptr(),
        lower: lower.as_mut_ptr(),
        upper: upper.as_mut_ptr(),
    };
    // SAFETY: every pointer has room for `n` rows.
    ok(unsafe {
        gjkd_signed_distances(c, pairs.as_ptr(), n, null(), null(), null(), &out, &signed)
    });
    for (i, &x) in xs.iter().enumerate() {
        let w = want(x);
        assert_eq!(error[i], 0, "row {i}");
        assert!((value[i] - w).abs() < 1e-9, "row {i}: {} vs {w}", value[i]);
        assert!(lower[i] <= w && w <= upper[i], "row {i}");
        // The distance: the signed one apart, 0 overlapping.
        assert!((distance[i] - w.max(0.0)).abs() < 1e-9, "row {i}");
        if w < 0.0 {
            // Overlapping: B leaves A through the face x = ±1 nearest it.
            let out = x.signum();
            assert!((normal[3 * i] - out).abs() < 1e-9, "row {i}: {normal:?}");
        }
    }
    assert_ne!(error[n - 1], 0);
    assert_eq!((value[n - 1], lower[n - 1], upper[n - 1]), (0.0, 0.0, 0.0));

    // Only the value wanted: the bounds stay as they were.
    let only_value = gjkd_signed_results {
        value: value.as_mut_ptr(),
        lower: null_mut(),
        upper: null_mut(),
    };
    lower.fill(f64::NAN);
    value.fill(f64::NAN);
    // SAFETY: as above.
    ok(unsafe {
        gjkd_signed_distances(
            c,
            pairs.as_ptr(),
            n,
            null(),
            null(),
            null(),
            &out,
            &only_value,
        )
    });
    assert!((value[0] - want(xs[0])).abs() < 1e-9);
    assert!(lower.iter().all(|l| l.is_nan()));

    // NULL `signed_out`: exactly `gjkd_distances()`, the distance only
    // (0 when overlapping) and the distance's normal (zero inside).
    normal.fill(f64::NAN);
    // SAFETY: as above.
    ok(unsafe {
        gjkd_signed_distances(c, pairs.as_ptr(), n, null(), null(), null(), &out, null())
    });
    assert_eq!(distance[0], 0.0);
    assert_eq!(&normal[..3], &[0.0; 3]);

    // A missing required array refuses the call before sending.
    let no_value = gjkd_signed_results {
        value: null_mut(),
        lower: lower.as_mut_ptr(),
        upper: null_mut(),
    };
    // SAFETY: as above.
    let status = unsafe {
        gjkd_signed_distances(
            c,
            pairs.as_ptr(),
            n,
            null(),
            null(),
            null(),
            &out,
            &no_value,
        )
    };
    assert_eq!(status, GJKD_ERR_NULL_POINTER);

    // Scene rows: the flag fills every row's signed fields.
    let options = gjkd_scene_options {
        signed_distance: true,
        exact: true,
        ..gjkd_scene_options_default()
    };
    let group = gjkd_group {
        id: crate_,
        members: null(),
        member_count: 0,
        allowed: null(),
        allowed_count: 0,
    };
    let mut rows = [gjkd_scene_row::default(); 8];
    let mut summary = gjkd_scene_summary::default();
    // SAFETY: valid pointers, room for 8 rows.
    ok(unsafe {
        gjkd_within(
            c,
            &group,
            10.0,
            &options,
            rows.as_mut_ptr(),
            8,
            &mut summary,
        )
    });
    assert_eq!(summary.written, xs.len());
    for row in &rows[..summary.written] {
        let i = balls.iter().position(|&b| b == row.b).expect("a ball");
        let w = want(xs[i]);
        assert!(row.answer.has_signed_distance, "{row:?}");
        assert!(
            (row.answer.signed_distance - w).abs() < 1e-9,
            "{row:?} vs {w}"
        );
        assert!(row.answer.signed_lower <= w && w <= row.answer.signed_upper);
    }
    // Without it, none.
    // SAFETY: as above.
    ok(unsafe { gjkd_within(c, &group, 10.0, null(), rows.as_mut_ptr(), 8, &mut summary) });
    assert!(
        rows[..summary.written]
            .iter()
            .all(|r| !r.answer.has_signed_distance)
    );
    // SAFETY: the handle from `gjkd_connect`.
    ok(unsafe { gjkd_close(c) });
}
