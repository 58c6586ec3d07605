//! What a C and a C++ developer meet, each a program written against the
//! header (`tests/c/api_checks.c`) or the wrapper
//! (`tests/cpp/wrapper_check.cpp`) that checks its own answers against
//! analytic values and documented errors, run against a real server, then
//! again under valgrind (no leak, no memory error) where it is installed.
//! The C++ program is built as C++17, with Eigen's conversions when Eigen
//! is installed, and as C++20 (the `std::span` overloads).
// Both programs register robots: the library's `robots` feature.
#![cfg(feature = "robots")]

mod common;

use std::path::Path;
use std::process::Command;

use gjkd_e2e::Server;

fn valgrind_present() -> bool {
    Command::new("valgrind")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Runs `exe SERVICE` and checks it ended with "ok"; then under valgrind,
/// which must find no error and nothing lost.
fn run_checked(exe: &Path, service: &str) -> String {
    let stdout = common::run_ok(exe, &[service]);
    assert!(!stdout.contains("WRONG"), "{stdout}");
    assert_eq!(stdout.lines().last(), Some("ok"), "{stdout}");
    if !valgrind_present() {
        eprintln!(
            "valgrind is not installed: {} not checked for leaks",
            exe.display()
        );
        return stdout;
    }
    let out = Command::new("valgrind")
        .args([
            "--leak-check=full",
            "--error-exitcode=1",
            "--errors-for-leak-kinds=definite,indirect,possible",
        ])
        .arg(exe)
        .arg(service)
        .env_remove("IOX2_LOG_LEVEL")
        .env_remove("LD_LIBRARY_PATH")
        .output()
        .expect("run valgrind");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "valgrind or the program failed ({}):\n{}\n{stderr}",
        out.status,
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(stderr.contains("ERROR SUMMARY: 0 errors"), "{stderr}");
    stdout
}

#[test]
fn the_c_api_holds_what_its_header_says() {
    let exe = common::compile(&["tests/c/api_checks.c"], "api_checks", false);
    let server = Server::start("ffi-api-checks", &["--no-persist"]);
    let stdout = run_checked(&exe, &server.service);
    for line in [
        "set_pose 1e305                           GJKD_ERR_INVALID_ARGUMENT GJKD_CODE_NON_FINITE_POSE",
        "distance at NaN                          GJKD_ERR_INVALID_ARGUMENT GJKD_CODE_NON_FINITE_POSE",
        "NaN joint                                GJKD_ERR_INVALID_ARGUMENT GJKD_CODE_NON_FINITE_POSE",
    ] {
        assert!(stdout.contains(line), "missing `{line}` in:\n{stdout}");
    }
}

#[test]
fn the_cpp_wrapper_offers_what_the_c_api_has() {
    let eigen = Path::new("/usr/include/eigen3/Eigen/Geometry").exists();
    let mut flags = vec!["-std=c++17"];
    if eigen {
        flags.extend(["-DGJKD_WITH_EIGEN", "-I/usr/include/eigen3"]);
    } else {
        eprintln!("Eigen is not installed: to_eigen()/from_eigen() not checked");
    }
    let exe17 = common::compile_with(
        &["tests/cpp/wrapper_check.cpp"],
        "wrapper_check17",
        true,
        &flags,
    );
    let exe20 = common::compile_with(
        &["tests/cpp/wrapper_check.cpp"],
        "wrapper_check20",
        true,
        &["-std=c++20"],
    );
    let server = Server::start("ffi-wrapper", &["--no-persist"]);
    let stdout = run_checked(&exe17, &server.service);
    assert_eq!(stdout.contains("eigen round trip"), eigen, "{stdout}");
    let stdout = common::run_ok(&exe20, &[&server.service]);
    assert!(stdout.contains("tip turned (span)"), "{stdout}");
    assert_eq!(stdout.lines().last(), Some("ok"), "{stdout}");
}
