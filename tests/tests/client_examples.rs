//! The client's examples (`client/examples/`) run as a user would run them,
//! against a real server, and succeed: each checks its own answers against
//! the analytic distance and exits non-zero if they are off.

use std::path::PathBuf;
use std::process::Command;
use std::sync::OnceLock;

use gjkd_e2e::{Server, gjkd_binary};

/// Builds the client's examples once per test process, in this run's
/// profile and target dir (cargo builds another package's examples only
/// when asked), and returns the folder that holds them.
fn examples_dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let profile_dir = gjkd_binary()
            .parent()
            .expect("the binary lives in target/<profile>")
            .to_path_buf();
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let mut build = Command::new(cargo);
        build
            // As `cargo test --workspace` builds them (it builds every
            // example), so that this is a no-op after it.
            .args(["build", "--quiet", "--workspace", "--examples"])
            .current_dir(env!("CARGO_MANIFEST_DIR"));
        if profile_dir.file_name().is_some_and(|n| n == "release") {
            build.arg("--release");
        }
        if let Some(target) = profile_dir.parent() {
            build.env("CARGO_TARGET_DIR", target);
        }
        let status = build.status().expect("run cargo build for the examples");
        assert!(
            status.success(),
            "building the client examples failed: {status}"
        );
        profile_dir.join("examples")
    })
}

/// Runs one example against `server` and returns its stdout, after checking
/// that iceoryx2's notice about its missing config file stayed quiet.
fn run(example: &str, server: &Server) -> String {
    let output = Command::new(examples_dir().join(example))
        .arg(&server.service)
        .env_remove("IOX2_LOG_LEVEL")
        .output()
        .unwrap_or_else(|e| panic!("start example {example}: {e}"));
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        output.status.success(),
        "example {example} failed ({}):\n{stdout}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stderr)
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !stderr.contains("No config file"),
        "iceoryx2's notice reached the example's stderr:\n{stderr}"
    );
    stdout
}

#[test]
fn register_and_query_runs() {
    let server = Server::start("ex-query", &["--no-persist"]);
    let out = run("register_and_query", &server);
    assert!(out.contains("distance 1.500000000000"), "{out}");
}

#[test]
fn batch_along_motion_runs() {
    let server = Server::start("ex-batch", &["--no-persist"]);
    let out = run("batch_along_motion", &server);
    assert!(
        out.contains("closest approach over 100 steps: 0.700000000000"),
        "{out}"
    );
}

#[test]
fn two_processes_run() {
    let server = Server::start("ex-two", &["--no-persist"]);
    let out = run("two_processes", &server);
    assert!(out.contains("owner: the watcher saw the door"), "{out}");
}

#[test]
fn robot_arm_runs() {
    let server = Server::start("ex-robot", &["--no-persist"]);
    let out = run("robot_arm", &server);
    assert!(
        out.contains("joints, in order: [\"turn\", \"reach\"]"),
        "{out}"
    );
    assert!(out.contains("gripper to crate 0.150000000000"), "{out}");
    assert!(
        out.contains("reach 0.9 refused: a joint position is outside its limits"),
        "{out}"
    );
}

#[test]
fn scene_clearance_runs() {
    let server = Server::start("ex-scene", &["--no-persist"]);
    let out = run("scene_clearance", &server);
    assert!(out.contains("4 pairs within 1.6"), "{out}");
    assert!(out.contains("first step within 0.2: Some(4)"), "{out}");
}
