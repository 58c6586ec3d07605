//! `gjkd serve --cpu N --priority P`: a pinned server serves from its CPU,
//! and a flag the kernel refuses stops the start with a message that says
//! what to fix, before anything is opened.

use std::process::{Command, Output};
use std::time::Duration;

use gjkd_e2e::{Server, gjkd_binary, unique_service};

/// Runs `gjkd serve` with `args` on a fresh service, to its exit.
fn serve_refused(prefix: &[&str], args: &[&str]) -> Output {
    let service = unique_service("refused");
    let gjkd = gjkd_binary();
    let mut command = match prefix.split_first() {
        Some((program, rest)) => {
            let mut c = Command::new(program);
            c.args(rest).arg(&gjkd);
            c
        }
        None => Command::new(&gjkd),
    };
    command
        .args(["serve", "--no-persist", "--service", &service])
        .args(args)
        .env("RUST_LOG", "warn")
        .output()
        .expect("run gjkd serve")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The CPUs `pid`'s main thread may run on, from /proc.
fn cpus_of(pid: u32) -> String {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).expect("proc status");
    status
        .lines()
        .find_map(|l| l.strip_prefix("Cpus_allowed_list:"))
        .expect("Cpus_allowed_list")
        .trim()
        .to_owned()
}

#[test]
fn a_pinned_server_serves_from_its_cpu() {
    let cpu = *gjkd_client::rt::allowed_cpus()
        .expect("affinity")
        .last()
        .expect("a CPU");
    let server = Server::start("cpu", &["--cpu", &cpu.to_string()]);
    let mut client = server.client(Duration::from_secs(5));
    // The serving loop runs on the main thread, whose id is the pid.
    assert_eq!(cpus_of(server.pid().expect("running")), cpu.to_string());
    let a = client.register_sphere(1.0).expect("register");
    let b = client.register_sphere(1.0).expect("register");
    client
        .set_pose(b, &nalgebra::Isometry3::translation(5.0, 0.0, 0.0))
        .expect("pose");
    let d = client
        .distance(a, b, &gjkd_client::QueryOptions::default())
        .expect("distance");
    assert!((d.distance - 3.0).abs() < 1e-9, "{d:?}");
}

#[test]
fn a_cpu_that_does_not_exist_is_refused_by_number() {
    let out = serve_refused(&[], &["--cpu", "4000000"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.contains("--cpu 4000000: CPU 4000000 does not exist"),
        "{err}"
    );
}

#[test]
fn a_cpu_outside_the_allowed_set_is_refused_listing_the_allowed_ones() {
    // The last CPU a set can name: no test machine has it online.
    let out = serve_refused(&[], &["--cpu", "1023"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.contains("--cpu 1023: CPU 1023 is not one this thread may run on (allowed: "),
        "{err}"
    );
}

#[test]
fn a_priority_out_of_range_is_refused() {
    let out = serve_refused(&[], &["--priority", "0"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.contains("--priority 0: SCHED_FIFO priority 0 is out of range: 1 to 99"),
        "{err}"
    );
}

#[test]
fn a_priority_without_the_capability_names_it_and_the_limit() {
    // Without CAP_SYS_NICE (dropped from every set by setpriv when this
    // runs as root) and with RLIMIT_RTPRIO 0, the kernel refuses.
    // SAFETY: geteuid has no arguments.
    let root = unsafe { libc::geteuid() } == 0;
    let setpriv = [
        "setpriv",
        "--inh-caps=-sys_nice",
        "--ambient-caps=-sys_nice",
        "--bounding-set=-sys_nice",
        "prlimit",
        "--rtprio=0",
        "--",
    ];
    let unprivileged = ["prlimit", "--rtprio=0", "--"];
    let prefix: &[&str] = if root { &setpriv } else { &unprivileged };
    let out = serve_refused(prefix, &["--priority", "10"]);
    assert!(!out.status.success(), "started: {}", stderr(&out));
    let err = stderr(&out);
    assert!(
        err.contains("--priority 10: SCHED_FIFO priority 10 is not permitted"),
        "{err}"
    );
    assert!(err.contains("CAP_SYS_NICE"), "{err}");
    assert!(err.contains("RLIMIT_RTPRIO of at least 10 (now 0"), "{err}");
}
