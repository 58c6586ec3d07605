//! A leak check: `tests/c/leak_check.c` makes many calls of the C API
//! (mostly failing ones, each building and freeing a last-error message,
//! one in a hundred a round trip, and a few handles opened and closed)
//! under valgrind, which must find nothing lost and no memory error.
//!
//! `GJKD_LEAK_CALLS` sets the number of calls (default 100 000, about half
//! a minute under valgrind). Skipped, saying so, where valgrind is missing.
// The program registers and moves a robot: the library's `robots` feature.
#![cfg(feature = "robots")]

mod common;

use std::process::Command;

use gjkd_e2e::Server;

fn valgrind_present() -> bool {
    Command::new("valgrind")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
fn many_calls_leak_nothing_under_valgrind() {
    if !valgrind_present() {
        eprintln!("SKIPPED many_calls_leak_nothing_under_valgrind: valgrind is not installed");
        return;
    }
    let calls = std::env::var("GJKD_LEAK_CALLS").unwrap_or_else(|_| "100000".into());
    let exe = common::compile(&["tests/c/leak_check.c"], "leak_check", false);
    let server = Server::start("ffi-leaks", &["--no-persist"]);
    let out = Command::new("valgrind")
        .args([
            "--leak-check=full",
            "--error-exitcode=1",
            "--errors-for-leak-kinds=definite,indirect,possible",
        ])
        .arg(&exe)
        .args([server.service.as_str(), calls.as_str()])
        .env_remove("IOX2_LOG_LEVEL")
        // The program's rpath names this build's library (see common::run).
        .env_remove("LD_LIBRARY_PATH")
        .output()
        .expect("run valgrind");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "valgrind or the program failed ({}):\n{stdout}\n{stderr}",
        out.status
    );
    assert!(stdout.contains(&format!("calls {calls},")), "{stdout}");
    for kind in ["definitely lost", "indirectly lost", "possibly lost"] {
        // valgrind omits the summary when nothing at all is left in use.
        let line = stderr.lines().find(|l| l.contains(kind));
        if let Some(line) = line {
            assert!(line.contains(": 0 bytes in 0 blocks"), "{line}\n{stderr}");
        }
    }
    assert!(
        stderr.contains("ERROR SUMMARY: 0 errors"),
        "valgrind found errors:\n{stderr}"
    );
}
