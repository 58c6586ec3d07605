//! `gjkd bench` smoke tests: the commands run end to end on the real binary
//! (`--quick`, few requests) and write their tables and plots. Nothing here
//! looks at a time: only that the outputs exist and hold every row.

use std::path::PathBuf;
use std::process::Command;

use gjkd_e2e::gjkd_binary;

fn out_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gjkd-bench-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn run(args: &[&str]) -> String {
    let out = Command::new(gjkd_binary())
        .args(args)
        .env("RUST_LOG", "warn")
        .output()
        .expect("run gjkd bench");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "gjkd {args:?} failed: {}\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

#[test]
fn latency_quick_writes_table_csv_and_plots() {
    let dir = out_dir("latency");
    let d = dir.to_str().expect("utf-8 temp dir");
    let stdout = run(&[
        "bench",
        "latency",
        "--quick",
        "--out",
        d,
        "--requests",
        "60",
        "--min-requests",
        "20",
        "--batches",
        "1,8",
        "--gap-us",
        "20",
    ]);
    assert!(
        stdout.contains("Single pair, back to back: p50 spin"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(dir.join("latency.csv")).expect("latency.csv");
    // Header + 6 transports x 3 request shapes x 2 pacings.
    assert_eq!(csv.lines().count(), 1 + 6 * 3 * 2, "{csv}");
    for t in ["spin", "adaptive", "block", "iceoryx2", "uds", "in-process"] {
        assert!(
            csv.lines()
                .any(|l| l.starts_with(&format!("{t},single,back-to-back")))
        );
    }
    for f in [
        "latency-back-to-back.svg",
        "latency-gaps.svg",
        "latency-p50.svg",
    ] {
        let svg = std::fs::read_to_string(dir.join(f)).expect(f);
        assert!(svg.starts_with("<svg"), "{f}");
    }
    // The socket server ran as a child process (`gjkd bench uds-server`)
    // with its socket in the output directory: the bench removed it.
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .expect("read the output directory")
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().ends_with(".sock"))
        .map(|e| e.path())
        .collect();
    assert!(leftovers.is_empty(), "socket files left: {leftovers:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn latency_contention_runs_beside_busy_processes_and_kills_them() {
    let dir = out_dir("contention");
    let d = dir.to_str().expect("utf-8 temp dir");
    let out = Command::new(gjkd_binary())
        .args([
            "bench",
            "latency",
            "--contention",
            "--quick",
            "--out",
            d,
            "--requests",
            "40",
            "--min-requests",
            "20",
            "--gap-us",
            "20,100",
            "--competitors",
            "0,2",
            "--pinning",
            "unpinned",
            "--transports",
            "adaptive,iceoryx2,in-process",
        ])
        .env("RUST_LOG", "warn")
        .output()
        .expect("run gjkd bench latency --contention");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    // One table per condition, each with its summary against the floor.
    assert!(stdout.contains("### quiet, unpinned"), "{stdout}");
    assert!(
        stdout.contains("### 2 competing busy processes, unpinned"),
        "{stdout}"
    );
    assert!(
        stdout.contains("Single pair, gap 100 µs: p50 spin"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(dir.join("latency.csv")).expect("latency.csv");
    // Header + 2 conditions x 3 transports x 3 pacings, single pairs only.
    assert_eq!(csv.lines().count(), 1 + 2 * 3 * 3, "{csv}");
    assert!(
        csv.lines()
            .any(|l| l.starts_with("iceoryx2,single,gap 20 µs,") && l.ends_with(",2,false,0")),
        "{csv}"
    );
    // The busy processes were named by pid, and none outlived the run.
    let line = stderr
        .lines()
        .find(|l| l.contains("busy processes ["))
        .unwrap_or_else(|| panic!("no busy process reported: {stderr}"));
    let pids: Vec<u32> = line[line.find('[').expect("[") + 1..line.find(']').expect("]")]
        .split(", ")
        .map(|p| p.parse().expect("pid"))
        .collect();
    assert_eq!(pids.len(), 2, "{line}");
    for pid in pids {
        let cmdline = std::fs::read(format!("/proc/{pid}/cmdline")).unwrap_or_default();
        assert!(
            !String::from_utf8_lossy(&cmdline).contains("busy"),
            "busy process {pid} still runs"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn paper_quick_states_whether_the_cost_is_linear() {
    let dir = out_dir("paper");
    let d = dir.to_str().expect("utf-8 temp dir");
    let stdout = run(&["bench", "paper", "--quick", "--out", d]);
    assert!(stdout.contains("Is the cost linear in M?"), "{stdout}");
    let csv = std::fs::read_to_string(dir.join("paper.csv")).expect("paper.csv");
    // Header + 20 pairs x 3 situations.
    assert_eq!(csv.lines().count(), 1 + 60);
    assert!(dir.join("paper-figure2.svg").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
