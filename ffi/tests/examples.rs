//! The C and C++ examples, built with the system compiler against the
//! static library, run against a real server and check their own answers
//! (analytic distances to 1e-9); this test checks what they printed.

mod common;

use gjkd_e2e::Server;

/// The lines every example prints about its answers.
fn assert_answers(stdout: &str) {
    for line in [
        "box-sphere             1.500000000000",
        "box-capsule            2.750000000000",
        "box-polytope           2.500000000000",
        "sphere-capsule         4.250000000000",
        "box-compound           3.700000000000",
        "box-sphere above       2.500000000000",
        "unknown pair           GJKD_CODE_UNKNOWN_OBJECT",
        "lookup of a missing name: GJKD_ERR_REJECTED, GJKD_CODE_UNKNOWN_NAME",
    ] {
        assert!(stdout.contains(line), "missing `{line}` in:\n{stdout}");
    }
    assert!(!stdout.contains("WRONG"), "{stdout}");
    assert_eq!(stdout.lines().last(), Some("ok"), "{stdout}");
}

#[test]
fn c_example_answers_match_the_analytic_distances() {
    // Built as against a lean install (robots hidden by GJKD_NO_ROBOTS):
    // the example of plain shapes needs none of the robot declarations, so
    // it builds and runs with or without the library's `robots` feature.
    let exe = common::compile_with(
        &["examples/basic.c"],
        "basic",
        false,
        &["-std=c99", "-DGJKD_NO_ROBOTS"],
    );
    let server = Server::start("ffi-c", &["--no-persist"]);
    let stdout = common::run_ok(&exe, &[&server.service]);
    assert_answers(&stdout);
    assert!(stdout.contains("found by name: yes"), "{stdout}");
}

// The C++ example registers a robot: the library's `robots` feature.
#[cfg(feature = "robots")]
#[test]
fn cpp_example_answers_match_the_analytic_distances() {
    let exe = common::compile(&["examples/basic.cpp"], "basic_cpp", true);
    let server = Server::start("ffi-cpp", &["--no-persist"]);
    let stdout = common::run_ok(&exe, &[&server.service]);
    assert_answers(&stdout);
    assert!(stdout.contains("lookup gives the id    1.0"), "{stdout}");
    for line in [
        "rows box-sphere below  3.500000000000",
        "path: hanging          1.500000000000",
        "rod still level        2.400000000000",
    ] {
        assert!(stdout.contains(line), "missing `{line}` in:\n{stdout}");
    }
}

#[test]
fn pair_rows_example_answers_match_the_analytic_distances() {
    let exe = common::compile(&["examples/pair_rows.c"], "pair_rows", false);
    let server = Server::start("ffi-rows", &["--no-persist"]);
    let stdout = common::run_ok(&exe, &[&server.service]);
    for line in [
        "box-sphere             1.500000000000",
        "box lifted-sphere      8.500000000000",
        "box-capsule            2.750000000000",
        "sphere-capsule         3.250000000000",
        "box-sphere point_b.x   2.500000000000",
        "ball at x = 6          4.500000000000",
        "unknown pair           GJKD_CODE_UNKNOWN_OBJECT",
        "undefined pose bit: GJKD_ERR_INVALID_ARGUMENT: gjkd_query_pairs: queries[0]: flags 0x2a",
    ] {
        assert!(stdout.contains(line), "missing `{line}` in:\n{stdout}");
    }
    assert!(!stdout.contains("WRONG"), "{stdout}");
    assert_eq!(stdout.lines().last(), Some("ok"), "{stdout}");
}

#[test]
fn examples_fail_when_no_server_runs() {
    // An example that cannot connect says so and exits non-zero, rather
    // than printing answers.
    let exe = common::compile(&["examples/basic.c"], "basic_noserver", false);
    let out = common::run(&exe, &[&gjkd_e2e::unique_service("ffi-none")]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("gjkd_connect failed: GJKD_ERR_SERVER_GONE"),
        "{stderr}"
    );
}

// The example moves a robot: the library's `robots` feature.
#[cfg(feature = "robots")]
#[test]
fn gradient_example_answers_match_the_analytic_gradient() {
    let exe = common::compile(&["examples/gradient.c"], "gradient", false);
    let server = Server::start("ffi-gradient", &["--no-persist"]);
    let stdout = common::run_ok(&exe, &[&server.service]);
    for line in [
        "rod-ball distance      0.350000000000",
        "d distance / d j       -0.800000000000",
        "row d distance / d j   -0.800000000000",
        "pair columns           1",
        "rows                   1",
    ] {
        assert!(stdout.contains(line), "missing `{line}` in:\n{stdout}");
    }
    assert_eq!(stdout.lines().last(), Some("ok"), "{stdout}");
}
