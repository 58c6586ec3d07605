//! Every error path of the C API returns its status, its server code and a
//! message naming the problem, and changes nothing: NULL handles and
//! arrays, zero and impossible counts, NaN poses and radii, unknown ids,
//! bad options, the wrong thread, and a server that went away.

use std::ffi::{CStr, c_char};
use std::ptr::{null, null_mut};

use gjkd_c::*;
use gjkd_e2e::Server;

use gjkd_status::*;

/// The thread's last error: message and server code.
fn last() -> (String, u32) {
    // SAFETY: gjkd_last_error never returns NULL, and the string lives until
    // the next call on this thread.
    let msg = unsafe { CStr::from_ptr(gjkd_last_error()) };
    (msg.to_string_lossy().into_owned(), gjkd_last_error_code())
}

/// Asserts success.
#[track_caller]
fn ok(status: gjkd_status) {
    assert_eq!(status, GJKD_OK, "{:?}", last());
}

/// Asserts that `status` is `want` and the message contains `words`.
#[track_caller]
fn assert_fails(status: gjkd_status, want: gjkd_status, words: &str) {
    let (msg, _) = last();
    assert_eq!(status, want, "message: {msg}");
    assert!(msg.contains(words), "`{words}` not in `{msg}`");
}

/// Asserts an argument refused before sending, with the server's `code`
/// for the same fault and `words` in the message.
#[track_caller]
fn assert_invalid(status: gjkd_status, code: gjkd_error_code, words: &str) {
    let (msg, got) = last();
    assert_eq!(status, GJKD_ERR_INVALID_ARGUMENT, "message: {msg}");
    assert_eq!(got, code as u32, "message: {msg}");
    assert!(msg.contains(words), "`{words}` not in `{msg}`");
}

/// Asserts a refusal by the server with `code`.
#[track_caller]
fn assert_rejected(status: gjkd_status, code: gjkd_error_code) {
    let (msg, got) = last();
    assert_eq!(status, GJKD_ERR_REJECTED, "message: {msg}");
    assert_eq!(got, code as u32, "message: {msg}");
    // SAFETY: a static string.
    let name = unsafe { CStr::from_ptr(gjkd_error_code_name(code as u32)) };
    assert!(msg.contains(name.to_str().unwrap()), "{msg}");
}

fn at(x: f64, y: f64, z: f64) -> gjkd_pose {
    gjkd_pose {
        translation: [x, y, z],
        rotation: [0.0, 0.0, 0.0, 1.0],
    }
}

fn connect(server: &Server) -> *mut gjkd_client {
    let service = std::ffi::CString::new(server.service.clone()).unwrap();
    let mut client = null_mut();
    // SAFETY: valid pointers.
    let s = unsafe { gjkd_connect(service.as_ptr(), 1.0, 10.0, &mut client) };
    assert_eq!(s, GJKD_OK, "{:?}", last());
    assert!(!client.is_null());
    client
}

fn sphere(c: *mut gjkd_client, r: f64, pose: &gjkd_pose) -> gjkd_id {
    let mut id = 0;
    // SAFETY: valid pointers.
    let s = unsafe { gjkd_register_sphere(c, r, null(), pose, &mut id) };
    assert_eq!(s, GJKD_OK, "{:?}", last());
    id
}

/// Distance of a pair at stored poses.
fn dist(c: *mut gjkd_client, a: gjkd_id, b: gjkd_id) -> f64 {
    let mut ans = gjkd_answer::default();
    // SAFETY: valid pointers.
    let s = unsafe { gjkd_distance(c, a, b, null(), null(), null(), &mut ans) };
    assert_eq!(s, GJKD_OK, "{:?}", last());
    ans.distance
}

#[test]
fn a_null_handle_is_refused_by_every_call() {
    let c = null_mut();
    let mut id = 0;
    let mut ans = gjkd_answer::default();
    let p = at(0.0, 0.0, 0.0);
    let v = [0.0; 3];
    let mut info = gjkd_info::default();
    let mut stats = gjkd_server_stats::default();
    // SAFETY: only NULL handles and valid pointers are passed.
    let statuses = unsafe {
        [
            gjkd_register_sphere(c, 1.0, null(), null(), &mut id),
            gjkd_register_box(c, v.as_ptr(), 0.0, null(), null(), &mut id),
            gjkd_register_capsule(c, v.as_ptr(), v.as_ptr(), 0.1, null(), null(), &mut id),
            gjkd_register_polytope(c, v.as_ptr(), 1, 0.0, null(), null(), &mut id),
            gjkd_register_compound(c, null(), 0, null(), null(), &mut id),
            gjkd_lookup(c, c"x".as_ptr(), &mut id),
            gjkd_remove(c, 1),
            gjkd_set_pose(c, 1, &p),
            gjkd_set_poses(c, &1, &p, 1),
            gjkd_distance(c, 1, 2, null(), null(), null(), &mut ans),
            gjkd_server_info(c, &mut info),
            gjkd_stats(c, &mut stats),
        ]
    };
    for (i, s) in statuses.into_iter().enumerate() {
        assert_eq!(s, GJKD_ERR_NULL_POINTER, "call {i}");
    }
    assert_fails(
        statuses[11],
        GJKD_ERR_NULL_POINTER,
        "gjkd_stats: client is NULL",
    );
    // Closing NULL is allowed, like free(NULL).
    // SAFETY: NULL.
    assert_eq!(unsafe { gjkd_close(null_mut()) }, GJKD_OK);
}

#[test]
fn connect_checks_its_arguments_and_reports_a_missing_server() {
    let mut client = null_mut();
    // SAFETY: valid pointers or NULL where tested.
    unsafe {
        assert_fails(
            gjkd_connect(null(), 1.0, 0.0, null_mut()),
            GJKD_ERR_NULL_POINTER,
            "out_client is NULL",
        );
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_fails(
                gjkd_connect(null(), bad, 0.0, &mut client),
                GJKD_ERR_INVALID_ARGUMENT,
                "timeout_s must be a positive number of seconds",
            );
            assert!(client.is_null());
        }
        assert_fails(
            gjkd_connect(null(), 1.0, -2.0, &mut client),
            GJKD_ERR_INVALID_ARGUMENT,
            "connect_timeout_s",
        );
        let not_utf8 = [0xffu8, 0xfe, 0];
        assert_fails(
            gjkd_connect(not_utf8.as_ptr().cast::<c_char>(), 1.0, 0.0, &mut client),
            GJKD_ERR_INVALID_ARGUMENT,
            "service is not valid UTF-8",
        );
        let nobody = std::ffi::CString::new(gjkd_e2e::unique_service("ffi-nobody")).unwrap();
        assert_fails(
            gjkd_connect(nobody.as_ptr(), 0.05, 0.0, &mut client),
            GJKD_ERR_SERVER_GONE,
            "no gjkd server is serving",
        );
        assert!(client.is_null());
    }
}

#[test]
fn null_arrays_and_outputs_are_refused_before_sending() {
    let server = Server::start("ffi-null", &["--no-persist"]);
    let c = connect(&server);
    let a = sphere(c, 1.0, &at(0.0, 0.0, 0.0));
    let b = sphere(c, 1.0, &at(5.0, 0.0, 0.0));
    let mut id = 0;
    let mut d = [0.0];
    let mut e = [0u32];
    let pairs = [a, b];
    // SAFETY: NULL where tested, valid pointers elsewhere.
    unsafe {
        assert_fails(
            gjkd_set_poses(c, null(), &at(0.0, 0.0, 0.0), 1),
            GJKD_ERR_NULL_POINTER,
            "gjkd_set_poses: ids is NULL",
        );
        assert_fails(
            gjkd_set_poses(c, &a, null(), 1),
            GJKD_ERR_NULL_POINTER,
            "poses is NULL",
        );
        assert_fails(
            gjkd_set_pose(c, a, null()),
            GJKD_ERR_NULL_POINTER,
            "pose is NULL",
        );
        let full = gjkd_results {
            distance: d.as_mut_ptr(),
            error: e.as_mut_ptr(),
            ..results_none()
        };
        assert_fails(
            gjkd_distances(c, null(), 1, null(), null(), null(), &full),
            GJKD_ERR_NULL_POINTER,
            "pairs is NULL",
        );
        assert_fails(
            gjkd_distances(c, pairs.as_ptr(), 1, null(), null(), null(), null()),
            GJKD_ERR_NULL_POINTER,
            "out is NULL",
        );
        let no_error = gjkd_results {
            distance: d.as_mut_ptr(),
            ..results_none()
        };
        assert_fails(
            gjkd_distances(c, pairs.as_ptr(), 1, null(), null(), null(), &no_error),
            GJKD_ERR_NULL_POINTER,
            "out.error is NULL",
        );
        let no_distance = gjkd_results {
            error: e.as_mut_ptr(),
            ..results_none()
        };
        assert_fails(
            gjkd_distances(c, pairs.as_ptr(), 1, null(), null(), null(), &no_distance),
            GJKD_ERR_NULL_POINTER,
            "out.distance is NULL",
        );
        assert_fails(
            gjkd_distance(c, a, b, null(), null(), null(), null_mut()),
            GJKD_ERR_NULL_POINTER,
            "out_answer is NULL",
        );
        assert_fails(
            gjkd_register_sphere(c, 1.0, null(), null(), null_mut()),
            GJKD_ERR_NULL_POINTER,
            "out_id is NULL",
        );
        assert_fails(
            gjkd_register_box(c, null(), 0.0, null(), null(), &mut id),
            GJKD_ERR_NULL_POINTER,
            "half_extents is NULL",
        );
        assert_fails(
            gjkd_register_capsule(c, [0.0; 3].as_ptr(), null(), 0.1, null(), null(), &mut id),
            GJKD_ERR_NULL_POINTER,
            "b is NULL",
        );
        assert_fails(
            gjkd_register_polytope(c, null(), 3, 0.0, null(), null(), &mut id),
            GJKD_ERR_NULL_POINTER,
            "shape.vertices is NULL",
        );
        assert_fails(
            gjkd_register(c, null(), null(), null(), &mut id),
            GJKD_ERR_NULL_POINTER,
            "shape is NULL",
        );
        assert_fails(
            gjkd_lookup(c, null(), &mut id),
            GJKD_ERR_NULL_POINTER,
            "name is NULL",
        );
        assert_eq!(id, 0, "a failed call leaves 0 in out_id");
    }
    // Nothing was stored by any of them.
    assert_eq!(dist(c, a, b), 3.0);
    let mut stats = gjkd_server_stats::default();
    // SAFETY: valid pointers.
    assert_eq!(unsafe { gjkd_stats(c, &mut stats) }, GJKD_OK);
    assert_eq!(stats.objects, 2);
    // SAFETY: a live handle, closed once.
    assert_eq!(unsafe { gjkd_close(c) }, GJKD_OK);
}

fn results_none() -> gjkd_results {
    gjkd_results {
        distance: null_mut(),
        lower: null_mut(),
        upper: null_mut(),
        penetration: null_mut(),
        point_a: null_mut(),
        point_b: null_mut(),
        normal: null_mut(),
        status: null_mut(),
        iterations: null_mut(),
        pieces: null_mut(),
        error: null_mut(),
        warm_started: null_mut(),
    }
}

#[test]
fn zero_and_impossible_counts_get_their_errors() {
    let server = Server::start("ffi-counts", &["--no-persist"]);
    let c = connect(&server);
    let a = sphere(c, 1.0, &at(0.0, 0.0, 0.0));
    let mut id = 0;
    let out = results_none();
    // SAFETY: NULL only with a count of 0, or with the impossible counts
    // that are refused before any dereference.
    unsafe {
        // Nothing to do is not an error.
        assert_eq!(gjkd_set_poses(c, null(), null(), 0), GJKD_OK);
        assert_eq!(
            gjkd_distances(c, null(), 0, null(), null(), null(), &out),
            GJKD_OK
        );
        // The server refuses an empty shape or compound.
        assert_rejected(
            gjkd_register_polytope(c, null(), 0, 0.0, null(), null(), &mut id),
            gjkd_error_code::GJKD_CODE_EMPTY_VERTICES,
        );
        assert_rejected(
            gjkd_register_compound(c, null(), 0, null(), null(), &mut id),
            gjkd_error_code::GJKD_CODE_EMPTY_COMPOUND,
        );
        let p = at(0.0, 0.0, 0.0);
        assert_fails(
            gjkd_set_poses(c, &a, &p, usize::MAX),
            GJKD_ERR_INVALID_ARGUMENT,
            "ids: count 18446744073709551615 is larger than any array",
        );
        let mut d = [0.0];
        let mut e = [0u32];
        let tiny = gjkd_results {
            distance: d.as_mut_ptr(),
            error: e.as_mut_ptr(),
            ..results_none()
        };
        assert_fails(
            gjkd_distances(
                c,
                [a, a].as_ptr(),
                usize::MAX / 8,
                null(),
                null(),
                null(),
                &tiny,
            ),
            GJKD_ERR_INVALID_ARGUMENT,
            "pairs: count",
        );
        let bead = gjkd_piece {
            offset: at(0.0, 0.0, 0.0),
            shape: shape(gjkd_shape_kind::GJKD_SHAPE_SPHERE, 0.1),
        };
        let many = vec![bead; GJKD_MAX_PIECES + 1];
        assert_fails(
            gjkd_register_compound(c, many.as_ptr(), many.len(), null(), null(), &mut id),
            GJKD_ERR_INVALID_ARGUMENT,
            "65 pieces, more than GJKD_MAX_PIECES (64)",
        );
        // GJKD_MAX_PIECES itself is fine.
        let id_max = {
            let s =
                gjkd_register_compound(c, many.as_ptr(), GJKD_MAX_PIECES, null(), null(), &mut id);
            assert_eq!(s, GJKD_OK, "{:?}", last());
            id
        };
        assert_ne!(id_max, 0);
    }
    // SAFETY: a live handle.
    assert_eq!(unsafe { gjkd_close(c) }, GJKD_OK);
}

fn shape(kind: gjkd_shape_kind, radius: f64) -> gjkd_shape {
    gjkd_shape {
        kind: kind as u32,
        radius,
        a: [0.0; 3],
        b: [0.0; 3],
        vertices: null(),
        vertex_count: 0,
    }
}

#[test]
fn nan_poses_radii_vertices_and_options_get_their_errors() {
    let server = Server::start("ffi-nan", &["--no-persist"]);
    let c = connect(&server);
    let a = sphere(c, 1.0, &at(0.0, 0.0, 0.0));
    let b = sphere(c, 1.0, &at(5.0, 0.0, 0.0));
    let nan = at(f64::NAN, 0.0, 0.0);
    let skew = gjkd_pose {
        translation: [0.0; 3],
        rotation: [0.0, 0.0, 0.0, 2.0],
    };
    let mut id = 0;
    let mut ans = gjkd_answer::default();
    // SAFETY: valid pointers throughout.
    unsafe {
        // One fault, one status and one code, whichever call meets it.
        let non_finite = gjkd_error_code::GJKD_CODE_NON_FINITE_POSE;
        assert_invalid(
            gjkd_set_pose(c, a, &nan),
            non_finite,
            "gjkd_set_pose: pose has a NaN or infinite component",
        );
        assert_invalid(
            gjkd_set_pose(c, a, &skew),
            gjkd_error_code::GJKD_CODE_BAD_QUATERNION,
            "not of unit length",
        );
        // A translation the server could store but no query could use is
        // refused when set, not at the next query.
        for x in [1e305, -2.7e300, f64::MAX] {
            assert_invalid(gjkd_set_pose(c, a, &at(0.0, x, 0.0)), non_finite, "beyond");
            assert_invalid(
                gjkd_distance(c, a, b, &at(x, 0.0, 0.0), null(), null(), &mut ans),
                non_finite,
                "pose_a",
            );
        }
        assert_eq!(dist(c, a, b), 3.0, "nothing stored");
        // At the limit, two objects on opposite corners are still answered.
        let m = GJKD_MAX_TRANSLATION;
        ok(gjkd_set_pose(c, a, &at(m, m, m)));
        ok(gjkd_set_pose(c, b, &at(-m, -m, -m)));
        let far = dist(c, a, b);
        assert!(far > 9.2e300 && far.is_finite(), "{far}");
        ok(gjkd_set_pose(c, a, &at(0.0, 0.0, 0.0)));
        ok(gjkd_set_pose(c, b, &at(5.0, 0.0, 0.0)));
        // A bad row fails the whole call before anything is sent: row 0,
        // good, is not stored either.
        let ids = [a, b];
        let poses = [at(1.0, 0.0, 0.0), nan];
        assert_invalid(
            gjkd_set_poses(c, ids.as_ptr(), poses.as_ptr(), 2),
            non_finite,
            "poses[1] has a NaN",
        );
        assert_eq!(dist(c, a, b), 3.0, "row 0 was not stored");
        // A pose given for one query: refused as gjkd_set_pose refuses it.
        assert_invalid(
            gjkd_distance(c, a, b, null(), &nan, null(), &mut ans),
            non_finite,
            "pose_b has a NaN",
        );
        assert_eq!(ans, gjkd_answer::default(), "a failed answer is zeroed");
        // In a batch, the bad row fails alone.
        let pairs = [a, b, a, b];
        let poses_b = [at(5.0, 0.0, 0.0), at(f64::INFINITY, 0.0, 0.0)];
        let mut d = [-1.0; 2];
        let mut e = [99u32; 2];
        let mut st = [99u32; 2];
        let out = gjkd_results {
            distance: d.as_mut_ptr(),
            error: e.as_mut_ptr(),
            status: st.as_mut_ptr(),
            ..results_none()
        };
        let s = gjkd_distances(c, pairs.as_ptr(), 2, null(), poses_b.as_ptr(), null(), &out);
        assert_eq!(s, GJKD_OK, "{:?}", last());
        assert_eq!(e, [0, gjkd_error_code::GJKD_CODE_NON_FINITE_POSE as u32]);
        assert_eq!(d, [3.0, 0.0]);
        assert_eq!(st, [gjkd_query_status::GJKD_QUERY_CONVERGED as u32, 0]);
        // Shapes.
        assert_rejected(
            gjkd_register_sphere(c, f64::NAN, null(), null(), &mut id),
            gjkd_error_code::GJKD_CODE_INVALID_RADIUS,
        );
        assert_rejected(
            gjkd_register_sphere(c, -1.0, null(), null(), &mut id),
            gjkd_error_code::GJKD_CODE_INVALID_RADIUS,
        );
        let bad = [0.0, f64::NAN, 0.0, 1.0, 1.0, 1.0];
        assert_rejected(
            gjkd_register_polytope(c, bad.as_ptr(), 2, 0.0, null(), null(), &mut id),
            gjkd_error_code::GJKD_CODE_NON_FINITE_VERTEX,
        );
        assert_fails(
            gjkd_register_box(c, [1.0, -1.0, 1.0].as_ptr(), 0.0, null(), null(), &mut id),
            GJKD_ERR_INVALID_ARGUMENT,
            "a half extent is negative",
        );
        assert_fails(
            gjkd_register_sphere(c, 1.0, null(), &nan, &mut id),
            GJKD_ERR_INVALID_ARGUMENT,
            "pose has a NaN",
        );
        let piece = gjkd_piece {
            offset: skew,
            shape: shape(gjkd_shape_kind::GJKD_SHAPE_SPHERE, 0.1),
        };
        assert_fails(
            gjkd_register_compound(c, &piece, 1, null(), null(), &mut id),
            GJKD_ERR_INVALID_ARGUMENT,
            "pieces[0].offset has a rotation quaternion",
        );
        let mut odd = shape(gjkd_shape_kind::GJKD_SHAPE_SPHERE, 0.1);
        odd.kind = 42;
        assert_fails(
            gjkd_register(c, &odd, null(), null(), &mut id),
            GJKD_ERR_INVALID_ARGUMENT,
            "shape.kind 42 is not a gjkd_shape_kind",
        );
        // Options.
        let mut o = gjkd_query_options_default();
        o.tolerance = f64::NAN;
        assert_fails(
            gjkd_distance(c, a, b, null(), null(), &o, &mut ans),
            GJKD_ERR_INVALID_ARGUMENT,
            "tolerance must be finite and >= 0",
        );
        let mut o = gjkd_query_options_default();
        o.max_iterations = 0;
        assert_fails(
            gjkd_distances(c, pairs.as_ptr(), 2, null(), null(), &o, &out),
            GJKD_ERR_INVALID_ARGUMENT,
            "max_iterations must be at least 1",
        );
        let mut o = gjkd_query_options_default();
        o.use_margin = true;
        o.margin = f64::NAN;
        assert_fails(
            gjkd_distance(c, a, b, null(), null(), &o, &mut ans),
            GJKD_ERR_INVALID_ARGUMENT,
            "margin must be finite",
        );
        let mut o = gjkd_query_options_default();
        o.precision = 7;
        assert_fails(
            gjkd_distance(c, a, b, null(), null(), &o, &mut ans),
            GJKD_ERR_INVALID_ARGUMENT,
            "precision 7 is not a gjkd_precision",
        );
    }
    let mut stats = gjkd_server_stats::default();
    // SAFETY: valid pointers.
    assert_eq!(unsafe { gjkd_stats(c, &mut stats) }, GJKD_OK);
    assert_eq!(stats.objects, 2, "no bad registration was stored");
    // SAFETY: a live handle.
    assert_eq!(unsafe { gjkd_close(c) }, GJKD_OK);
}

#[test]
fn unknown_ids_and_names_are_rejected_with_their_codes() {
    let server = Server::start("ffi-unknown", &["--no-persist"]);
    let c = connect(&server);
    let a = sphere(c, 1.0, &at(0.0, 0.0, 0.0));
    let b = sphere(c, 1.0, &at(5.0, 0.0, 0.0));
    let ghost = 0x7777;
    let mut id = 0;
    let mut ans = gjkd_answer::default();
    // SAFETY: valid pointers.
    unsafe {
        assert_rejected(
            gjkd_distance(c, a, ghost, null(), null(), null(), &mut ans),
            gjkd_error_code::GJKD_CODE_UNKNOWN_OBJECT,
        );
        assert_rejected(
            gjkd_remove(c, ghost),
            gjkd_error_code::GJKD_CODE_UNKNOWN_OBJECT,
        );
        assert_rejected(
            gjkd_set_pose(c, ghost, &at(0.0, 0.0, 0.0)),
            gjkd_error_code::GJKD_CODE_UNKNOWN_OBJECT,
        );
        // The unknown row is named; the known rows are stored.
        let ids = [b, ghost];
        let poses = [at(7.0, 0.0, 0.0), at(0.0, 0.0, 0.0)];
        let s = gjkd_set_poses(c, ids.as_ptr(), poses.as_ptr(), 2);
        assert_rejected(s, gjkd_error_code::GJKD_CODE_UNKNOWN_OBJECT);
        assert!(last().0.contains("ids[1]"), "{:?}", last());
        assert_eq!(dist(c, a, b), 5.0, "row 0 was stored");
        assert_rejected(
            gjkd_lookup(c, c"nobody".as_ptr(), &mut id),
            gjkd_error_code::GJKD_CODE_UNKNOWN_NAME,
        );
        let long = std::ffi::CString::new("n".repeat(GJKD_MAX_NAME_LEN + 1)).unwrap();
        assert_fails(
            gjkd_lookup(c, long.as_ptr(), &mut id),
            GJKD_ERR_INVALID_ARGUMENT,
            "name longer than MAX_NAME_LEN",
        );
        assert_fails(
            gjkd_register_sphere(c, 1.0, c"".as_ptr(), null(), &mut id),
            GJKD_ERR_INVALID_ARGUMENT,
            "name is empty",
        );
        // A name taken is refused; the first object keeps it.
        let s = gjkd_register_sphere(c, 1.0, c"taken".as_ptr(), null(), &mut id);
        assert_eq!(s, GJKD_OK);
        let first = id;
        assert_rejected(
            gjkd_register_sphere(c, 2.0, c"taken".as_ptr(), null(), &mut id),
            gjkd_error_code::GJKD_CODE_NAME_TAKEN,
        );
        assert_eq!(gjkd_lookup(c, c"taken".as_ptr(), &mut id), GJKD_OK);
        assert_eq!(id, first);
        // A removed id is unknown afterwards.
        assert_eq!(gjkd_remove(c, a), GJKD_OK);
        assert_rejected(gjkd_remove(c, a), gjkd_error_code::GJKD_CODE_UNKNOWN_OBJECT);
        assert_eq!(gjkd_close(c), GJKD_OK);
    }
}

#[test]
fn a_handle_serves_any_thread_one_call_at_a_time_and_errors_stay_on_their_thread() {
    let server = Server::start("ffi-thread", &["--no-persist"]);
    let c = connect(&server);
    let a = sphere(c, 1.0, &at(0.0, 0.0, 0.0));
    let b = sphere(c, 1.0, &at(5.0, 0.0, 0.0));
    // SAFETY: valid pointers.
    unsafe {
        assert_rejected(
            gjkd_remove(c, 0x99),
            gjkd_error_code::GJKD_CODE_UNKNOWN_OBJECT,
        );
    }
    let mine = last();
    let addr = c as usize;
    // Another thread uses the handle, then this one again: each call in
    // turn, on whatever thread.
    let other = std::thread::spawn(move || {
        let c = addr as *mut gjkd_client;
        let mut ans = gjkd_answer::default();
        // SAFETY: a live handle, used by no other call meanwhile.
        let s = unsafe { gjkd_distance(c, a, b, null(), null(), null(), &mut ans) };
        // SAFETY: as above.
        let refused = unsafe { gjkd_remove(c, 0x98) };
        (s, ans.distance, refused, last())
    })
    .join()
    .expect("the thread ends");
    assert_eq!((other.0, other.1), (GJKD_OK, 3.0));
    assert_eq!(other.2, GJKD_ERR_REJECTED);
    assert!(other.3.0.starts_with("gjkd_remove:"), "{:?}", other.3);
    // This thread's last error is its own, and the handle still works.
    assert_eq!(last(), mine);
    assert_eq!(dist(c, a, b), 3.0);
    // A call while another thread's call holds the handle is refused, not
    // run beside it: with the server paused, a call waits its timeout
    // (one second) for the answer, holding the handle meanwhile.
    let pid = server.pid().expect("the server runs") as i32;
    // SAFETY: signals to the test's own child.
    unsafe { libc::kill(pid, libc::SIGSTOP) };
    let waiting = std::thread::spawn(move || {
        let mut ans = gjkd_answer::default();
        // SAFETY: a live handle.
        unsafe {
            gjkd_distance(
                addr as *mut gjkd_client,
                a,
                b,
                null(),
                null(),
                null(),
                &mut ans,
            )
        }
    });
    std::thread::sleep(std::time::Duration::from_millis(300));
    let mut ans = gjkd_answer::default();
    // SAFETY: a live handle, busy on the other thread.
    let busy = unsafe { gjkd_distance(c, a, b, null(), null(), null(), &mut ans) };
    assert_eq!(busy, GJKD_ERR_BUSY);
    assert!(last().0.contains("another thread"), "{:?}", last());
    assert_eq!(waiting.join().unwrap(), GJKD_ERR_TIMEOUT);
    // SAFETY: as above.
    unsafe { libc::kill(pid, libc::SIGCONT) };
    // Closed on yet another thread: freed there (valgrind checks no leak
    // in leak_check.c, which does the same).
    let closed = std::thread::spawn(move || {
        // SAFETY: a live handle, idle.
        unsafe { gjkd_close(addr as *mut gjkd_client) }
    });
    assert_eq!(closed.join().unwrap(), GJKD_OK);
}

#[test]
fn a_server_that_goes_away_is_reported_and_found_again() {
    let mut server = Server::start("ffi-gone", &["--no-persist"]);
    let c = connect(&server);
    let a = sphere(c, 1.0, &at(0.0, 0.0, 0.0));
    server.terminate();
    let mut ans = gjkd_answer::default();
    let pairs = [a, a];
    let mut d = [0.0];
    let mut e = [0u32];
    let out = gjkd_results {
        distance: d.as_mut_ptr(),
        error: e.as_mut_ptr(),
        ..results_none()
    };
    let mut id = 0;
    // SAFETY: valid pointers.
    unsafe {
        assert_fails(
            gjkd_distance(c, a, a, null(), null(), null(), &mut ans),
            GJKD_ERR_SERVER_GONE,
            "gjkd_distance: no gjkd server is serving",
        );
        assert_fails(
            gjkd_distances(c, pairs.as_ptr(), 1, null(), null(), null(), &out),
            GJKD_ERR_SERVER_GONE,
            "no gjkd server",
        );
        assert_fails(
            gjkd_register_sphere(c, 1.0, null(), null(), &mut id),
            GJKD_ERR_SERVER_GONE,
            "no gjkd server",
        );
        let mut info = gjkd_info::default();
        assert_fails(
            gjkd_server_info(c, &mut info),
            GJKD_ERR_SERVER_GONE,
            "not connected",
        );
    }
    // A new server on the name: the same handle reconnects by itself. It
    // started empty (no persistence), so the old id is unknown there.
    server.restart();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
    let status = loop {
        // SAFETY: valid pointers.
        let s = unsafe { gjkd_distance(c, a, a, null(), null(), null(), &mut ans) };
        if s != GJKD_ERR_SERVER_GONE || std::time::Instant::now() > deadline {
            break s;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    assert_rejected(status, gjkd_error_code::GJKD_CODE_UNKNOWN_OBJECT);
    // SAFETY: a live handle.
    assert_eq!(unsafe { gjkd_close(c) }, GJKD_OK);
}

#[test]
fn status_and_code_names_cover_every_value() {
    let name = |s: i32| {
        unsafe { CStr::from_ptr(gjkd_status_name(s)) }
            .to_str()
            .unwrap()
    };
    assert_eq!(name(GJKD_OK as i32), "GJKD_OK");
    assert_eq!(name(GJKD_ERR_TIMEOUT as i32), "GJKD_ERR_TIMEOUT");
    assert_eq!(name(GJKD_ERR_PANIC as i32), "GJKD_ERR_PANIC");
    assert_eq!(name(GJKD_ERR_BUSY as i32), "GJKD_ERR_BUSY");
    assert_eq!(name(15), "GJKD_ERR_UNKNOWN");
    assert_eq!(name(-1), "GJKD_ERR_UNKNOWN");
    let words = unsafe { CStr::from_ptr(gjkd_error_code_describe(1000)) };
    assert_eq!(words.to_str().unwrap(), "unknown error code");
}
