//! `gjkd_query_pairs`, the batch of rows: analytic distances and points,
//! rows equal to the Rust client's items and answers equal to its answers,
//! bit for bit, over several chunks; per-row failures (poses, options);
//! every whole-call error path changing nothing.

use std::ffi::CStr;
use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;
use rust_client::{Item, ItemResult, ObjectId, QueryOptions};

use gjkd_error_code::*;
use gjkd_status::*;

const MAX_BATCH: usize = 5;

fn message() -> String {
    // SAFETY: never NULL, alive until the next call on this thread.
    unsafe { CStr::from_ptr(gjkd_last_error()) }
        .to_string_lossy()
        .into_owned()
}

#[track_caller]
fn ok(status: gjkd_status) {
    assert_eq!(status, GJKD_OK, "{}", message());
}

#[track_caller]
fn assert_fails(status: gjkd_status, want: gjkd_status, words: &str) {
    let msg = message();
    assert_eq!(status, want, "message: {msg}");
    assert!(msg.contains(words), "`{words}` not in `{msg}`");
}

fn at(x: f64, y: f64, z: f64) -> gjkd_pose {
    gjkd_pose {
        translation: [x, y, z],
        rotation: [0.0, 0.0, 0.0, 1.0],
    }
}

/// A pose turned by `angle` about z, at `(x, y, z)`.
fn turned(x: f64, y: f64, z: f64, angle: f64) -> gjkd_pose {
    let h = 0.5 * angle;
    gjkd_pose {
        translation: [x, y, z],
        rotation: [0.0, 0.0, h.sin(), h.cos()],
    }
}

fn connect(server: &Server) -> *mut gjkd_client {
    let service = std::ffi::CString::new(server.service.clone()).unwrap();
    let mut c = null_mut();
    // SAFETY: valid pointers.
    ok(unsafe { gjkd_connect(service.as_ptr(), 2.0, 10.0, &mut c) });
    c
}

/// A unit box (half extents 1) at the origin and a ball of radius 0.5 at
/// x = 3, both stored.
fn box_and_ball(c: *mut gjkd_client) -> (gjkd_id, gjkd_id) {
    let (mut b, mut s) = (0, 0);
    // SAFETY: valid pointers, a live handle.
    unsafe {
        ok(gjkd_register_box(
            c,
            [1.0; 3].as_ptr(),
            0.0,
            null(),
            null(),
            &mut b,
        ));
        ok(gjkd_register_sphere(
            c,
            0.5,
            null(),
            &at(3.0, 0.0, 0.0),
            &mut s,
        ));
    }
    (b, s)
}

/// A row of `a` and `b` at their stored poses, default options.
fn base(a: gjkd_id, b: gjkd_id) -> gjkd_pair_query {
    // SAFETY: NULL options.
    unsafe { gjkd_pair_query_of(a, b, null()) }
}

/// A row of `a` and `b` with `options`.
fn with_options(a: gjkd_id, b: gjkd_id, options: &gjkd_query_options) -> gjkd_pair_query {
    // SAFETY: readable options.
    unsafe { gjkd_pair_query_of(a, b, options) }
}

fn query(c: *mut gjkd_client, rows: &[gjkd_pair_query], out: &mut [gjkd_result]) -> gjkd_status {
    assert!(out.len() >= rows.len());
    // SAFETY: `out` has a row per query.
    unsafe { gjkd_query_pairs(c, rows.as_ptr(), rows.len(), out.as_mut_ptr()) }
}

#[test]
fn rows_answer_the_analytic_distances_and_points() {
    let server = Server::start("ffi-rows-analytic", &["--no-persist"]);
    let c = connect(&server);
    let (cube, ball) = box_and_ball(c);
    let mut rows = vec![base(cube, ball)];
    // Ball given at y = 4: 4 - 1 - 0.5 apart, along +y.
    rows.push(gjkd_pair_query {
        pose_b: at(0.0, 4.0, 0.0),
        flags: base(cube, ball).flags | GJKD_POSE_B,
        ..base(cube, ball)
    });
    // Box given turned by 45 degrees about z: its corner reaches sqrt(2)
    // along x, the stored ball is 3 - sqrt(2) - 0.5 away.
    rows.push(gjkd_pair_query {
        pose_a: turned(0.0, 0.0, 0.0, std::f64::consts::FRAC_PI_4),
        flags: base(cube, ball).flags | GJKD_POSE_A,
        ..base(cube, ball)
    });
    // Both given: box at z = -10, ball at z = 2 (-10 + 1 .. 2 - 0.5).
    rows.push(gjkd_pair_query {
        pose_a: at(0.0, 0.0, -10.0),
        pose_b: at(0.0, 0.0, 2.0),
        flags: base(cube, ball).flags | GJKD_POSE_A | GJKD_POSE_B,
        ..base(cube, ball)
    });
    // Ball given inside the box: they overlap, the distance is 0.
    rows.push(gjkd_pair_query {
        pose_b: at(0.25, 0.0, 0.0),
        flags: base(cube, ball).flags | GJKD_POSE_B,
        ..base(cube, ball)
    });
    let mut out = vec![gjkd_result::default(); rows.len()];
    ok(query(c, &rows, &mut out));
    let want = [1.5, 2.5, 2.5 - 2f64.sqrt(), 10.5, 0.0];
    for (i, (r, w)) in out.iter().zip(want).enumerate() {
        assert_eq!(r.error, GJKD_CODE_OK as u32, "row {i}");
        assert!((r.distance - w).abs() <= 1e-9, "row {i}: {r:?}, want {w}");
        assert!(r.lower <= r.distance && r.distance <= r.upper, "row {i}");
    }
    let close = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-9);
    assert!(close(out[0].point_a, [1.0, 0.0, 0.0]), "{:?}", out[0]);
    assert!(close(out[0].point_b, [2.5, 0.0, 0.0]), "{:?}", out[0]);
    assert!(close(out[0].normal, [1.0, 0.0, 0.0]), "{:?}", out[0]);
    assert!(close(out[1].point_b, [0.0, 3.5, 0.0]), "{:?}", out[1]);
    let s2 = 2f64.sqrt();
    assert!(close(out[2].point_a, [s2, 0.0, 0.0]), "{:?}", out[2]);
    assert!((out[3].point_a[2] + 9.0).abs() <= 1e-9, "{:?}", out[3]);
    assert!((out[3].point_b[2] - 1.5).abs() <= 1e-9, "{:?}", out[3]);
    assert!(out[4].penetration > 0.0, "{:?}", out[4]);
    for r in &out[..4] {
        assert_eq!(r.status, gjkd_query_status::GJKD_QUERY_CONVERGED as u32);
    }
    // The stored poses were not changed by the rows' own.
    let mut again = [gjkd_result::default()];
    ok(query(c, &rows[..1], &mut again));
    assert!((again[0].distance - 1.5).abs() <= 1e-9);
    assert_ne!(
        again[0].flags & GJKD_RESULT_WARM_STARTED,
        0,
        "the pair's second query starts warm"
    );
    // SAFETY: a live handle.
    ok(unsafe { gjkd_close(c) });
}

#[test]
fn rows_equal_the_rust_clients_answers_over_several_chunks() {
    let max = MAX_BATCH.to_string();
    let server = Server::start("ffi-rows-rust", &["--no-persist", "--max-batch", &max]);
    let c = connect(&server);
    let (cube, ball) = box_and_ball(c);
    let mut rust = server.client(std::time::Duration::from_secs(2));
    let cold = QueryOptions::cold();
    let mut options = gjkd_query_options_default();
    options.warm_start = false;
    let (mut rows, mut items) = (Vec::new(), Vec::new());
    let (oc, ob) = (ObjectId::from_raw(cube), ObjectId::from_raw(ball));
    for i in 0..4 * MAX_BATCH + 2 {
        let f = i as f64;
        let pa = turned(0.1 * f, -0.2 * f, 0.05 * f, 0.3 * f);
        let pb = turned(3.0 + 0.2 * f, 0.4 * f, -0.1 * f, -0.2 * f);
        // Rows alternate between given and stored poses.
        let poses = (i % 4) as u32;
        let row = with_options(cube, ball, &options);
        rows.push(gjkd_pair_query {
            pose_a: pa,
            pose_b: pb,
            flags: row.flags | poses,
            ..row
        });
        let mut item = Item::distance(oc, ob, &cold);
        if poses & GJKD_POSE_A != 0 {
            item.flags |= gjkd_proto::item_flags::POSE_A;
            item.pose_a = pa.wire();
        }
        if poses & GJKD_POSE_B != 0 {
            item.flags |= gjkd_proto::item_flags::POSE_B;
            item.pair_mut().pose_b = pb.wire();
        }
        items.push(item);
    }
    // An id no server gave out fails alone, in its row.
    rows.push(with_options(cube, 0xdead, &options));
    items.push(Item::distance(oc, ObjectId::from_raw(0xdead), &cold));
    let n = rows.len();
    let mut want = vec![ItemResult::default(); n];
    for chunk in (0..n).step_by(MAX_BATCH) {
        let end = n.min(chunk + MAX_BATCH);
        rust.query_batch(&items[chunk..end], &mut want[chunk..end])
            .expect("the Rust client answers");
    }
    // The rows are the Rust items, bit for bit (a pose whose bit is not
    // set is not read).
    for (row, item) in rows.iter().zip(&items) {
        assert_eq!(
            (row.kind, row.flags, row.a, row.b),
            (item.kind, item.flags, item.a, item.b)
        );
        if row.flags & GJKD_POSE_A != 0 {
            assert_eq!(row.pose_a.wire(), item.pose_a);
        }
        if row.flags & GJKD_POSE_B != 0 {
            assert_eq!(row.pose_b.wire(), item.pair().pose_b);
        }
        assert_eq!(
            (
                row.tolerance.to_bits(),
                row.margin.to_bits(),
                row.max_iterations
            ),
            (
                item.pair().tolerance.to_bits(),
                item.pair().margin.to_bits(),
                item.pair().max_iterations
            )
        );
    }
    let mut out = vec![gjkd_result::default(); n];
    ok(query(c, &rows, &mut out));
    for (i, (got, want)) in out.iter().zip(&want).enumerate() {
        let bits = |r: &gjkd_result| {
            let mut v = vec![r.distance, r.lower, r.upper, r.penetration];
            v.extend(r.point_a.iter().chain(&r.point_b).chain(&r.normal));
            v.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        };
        let want_row = gjkd_result {
            distance: want.distance,
            lower: want.lower,
            upper: want.upper,
            penetration: want.penetration,
            point_a: want.point_a,
            point_b: want.point_b,
            normal: want.normal,
            error: want.error,
            status: want.status,
            iterations: want.iterations,
            flags: want.flags,
            pieces: want.pieces,
            signed_distance: want.signed_distance,
            signed_lower: want.signed_lower,
            signed_upper: want.signed_upper,
        };
        assert_eq!(bits(got), bits(&want_row), "row {i}");
        assert_eq!(
            (got.error, got.status, got.iterations, got.flags, got.pieces),
            (
                want.error,
                want.status,
                want.iterations,
                want.flags,
                want.pieces
            ),
            "row {i}"
        );
    }
    assert_eq!(out[n - 1].error, GJKD_CODE_UNKNOWN_OBJECT as u32);
    assert_eq!(out[n - 1].distance, 0.0);
    // SAFETY: a live handle.
    ok(unsafe { gjkd_close(c) });
}

#[test]
fn bad_poses_in_a_row_fail_that_row_alone() {
    let server = Server::start("ffi-rows-poses", &["--no-persist"]);
    let c = connect(&server);
    let (cube, ball) = box_and_ball(c);
    let mut crooked = at(3.0, 0.0, 0.0);
    crooked.rotation = [0.0, 0.0, 0.5, 1.0];
    let mut nan = at(3.0, 0.0, 0.0);
    nan.translation[1] = f64::NAN;
    let rows = [
        gjkd_pair_query {
            pose_b: crooked,
            flags: base(cube, ball).flags | GJKD_POSE_B,
            ..base(cube, ball)
        },
        gjkd_pair_query {
            pose_a: nan,
            flags: base(cube, ball).flags | GJKD_POSE_A,
            ..base(cube, ball)
        },
        // A bad pose whose bit is not set is not used.
        gjkd_pair_query {
            pose_a: nan,
            ..base(cube, ball)
        },
    ];
    let mut out = [gjkd_result::default(); 3];
    ok(query(c, &rows, &mut out));
    assert_eq!(out[0].error, GJKD_CODE_BAD_QUATERNION as u32);
    assert_eq!(out[1].error, GJKD_CODE_NON_FINITE_POSE as u32);
    assert_eq!(out[2].error, GJKD_CODE_OK as u32);
    assert!((out[2].distance - 1.5).abs() <= 1e-9);
    // Bad options fail their rows alone too.
    let mut no_iterations = gjkd_query_options_default();
    no_iterations.max_iterations = 0;
    let mut no_precision = gjkd_query_options_default();
    no_precision.precision = 7;
    let mut nan_tolerance = gjkd_query_options_default();
    nan_tolerance.tolerance = f64::NAN;
    let rows = [
        with_options(cube, ball, &no_iterations),
        with_options(cube, ball, &no_precision),
        with_options(cube, ball, &nan_tolerance),
        base(cube, ball),
    ];
    let mut out = [gjkd_result::default(); 4];
    ok(query(c, &rows, &mut out));
    for r in &out[..3] {
        assert_eq!(r.error, GJKD_CODE_INVALID_OPTIONS as u32, "{r:?}");
    }
    assert!((out[3].distance - 1.5).abs() <= 1e-9);
    // SAFETY: a live handle.
    ok(unsafe { gjkd_close(c) });
}

#[test]
fn whole_call_errors_are_reported_and_send_nothing() {
    let server = Server::start("ffi-rows-errors", &["--no-persist"]);
    let c = connect(&server);
    let (cube, ball) = box_and_ball(c);
    let good = [base(cube, ball)];
    let mut out = [gjkd_result::default(); 2];
    let stats = |c| {
        let mut s = gjkd_server_stats::default();
        // SAFETY: valid pointers.
        ok(unsafe { gjkd_stats(c, &mut s) });
        s.items
    };
    let before = stats(c);
    // SAFETY (every call below): the pointers are NULL or valid for the
    // counts given, except where a count is impossible on purpose (the
    // call refuses it before reading).
    unsafe {
        let o = out.as_mut_ptr();
        assert_fails(
            gjkd_query_pairs(null_mut(), good.as_ptr(), 1, o),
            GJKD_ERR_NULL_POINTER,
            "client is NULL",
        );
        assert_fails(
            gjkd_query_pairs(c, null(), 1, o),
            GJKD_ERR_NULL_POINTER,
            "queries is NULL",
        );
        assert_fails(
            gjkd_query_pairs(c, good.as_ptr(), 1, null_mut()),
            GJKD_ERR_NULL_POINTER,
            "out is NULL",
        );
        assert_fails(
            gjkd_query_pairs(c, good.as_ptr(), usize::MAX / 8, o),
            GJKD_ERR_INVALID_ARGUMENT,
            "larger than any array",
        );
        // A row that would store a pose, a zeroed row, a row with a bit
        // this call does not define.
        let set_pose = [good[0], gjkd_pair_query { kind: 1, ..good[0] }];
        assert_fails(
            gjkd_query_pairs(c, set_pose.as_ptr(), 2, o),
            GJKD_ERR_INVALID_ARGUMENT,
            "queries[1]: kind 1 is not a distance query",
        );
        let zeroed: [gjkd_pair_query; 1] = std::mem::zeroed();
        assert_fails(
            gjkd_query_pairs(c, zeroed.as_ptr(), 1, o),
            GJKD_ERR_INVALID_ARGUMENT,
            "queries[0]: kind 0",
        );
        let stray = [
            good[0],
            gjkd_pair_query {
                flags: good[0].flags | gjkd_proto::item_flags::CLAMP,
                ..good[0]
            },
        ];
        assert_fails(
            gjkd_query_pairs(c, stray.as_ptr(), 2, o),
            GJKD_ERR_INVALID_ARGUMENT,
            "queries[1]: flags 0x28",
        );
        let reserved = [gjkd_pair_query {
            reserved: 1,
            ..good[0]
        }];
        assert_fails(
            gjkd_query_pairs(c, reserved.as_ptr(), 1, o),
            GJKD_ERR_INVALID_ARGUMENT,
            "reserved 1 is not 0",
        );
        // A row asking for a gradient needs the gradient call, and room
        // for every gradient asked.
        let asks = [
            good[0],
            gjkd_pair_query {
                flags: good[0].flags | GJKD_PAIR_GRADIENT,
                ..good[0]
            },
        ];
        assert_fails(
            gjkd_query_pairs(c, asks.as_ptr(), 2, o),
            GJKD_ERR_INVALID_ARGUMENT,
            "queries[1]: asks for a gradient",
        );
        let mut written = 7;
        assert_fails(
            gjkd_query_pairs_gradients(c, asks.as_ptr(), 2, o, null_mut(), 0, &mut written),
            GJKD_ERR_NULL_POINTER,
            "gradients is NULL",
        );
        let mut room: [gjkd_gradient; 0] = [];
        assert_fails(
            gjkd_query_pairs_gradients(c, asks.as_ptr(), 2, o, room.as_mut_ptr(), 0, &mut written),
            GJKD_ERR_INVALID_ARGUMENT,
            "gradient_count 0: 1 rows ask for a gradient",
        );
        assert_eq!(written, 0);
        // A count of 0 does nothing, whatever the arrays.
        ok(gjkd_query_pairs(c, null(), 0, null_mut()));
    }
    assert_eq!(out, [gjkd_result::default(); 2], "nothing written");
    assert_eq!(stats(c), before, "nothing sent");
    // Another thread may use the handle (one call at a time).
    let handle = c as usize;
    let (status, row) = std::thread::spawn(move || {
        let mut out = [gjkd_result::default()];
        let row = [base(cube, ball)];
        // SAFETY: the handle is live and idle.
        let status = unsafe {
            gjkd_query_pairs(
                handle as *mut gjkd_client,
                row.as_ptr(),
                1,
                out.as_mut_ptr(),
            )
        };
        (status, out[0])
    })
    .join()
    .unwrap();
    assert_eq!(status, GJKD_OK);
    assert_eq!((row.error, row.status), (0, 1), "{row:?}");
    // SAFETY: a live handle.
    ok(unsafe { gjkd_close(c) });
}
