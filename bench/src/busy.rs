//! Competing load for `gjkd bench latency --competitors N`: busy processes
//! that keep a CPU's worth of work each, as a perception or planning
//! process beside a control loop would.
//!
//! Each is a child process of this executable (`gjkd bench busy`), started
//! and stopped by the bench by process id, and bounded in time twice over:
//! it ends by itself after `--seconds`, and with the bench (a parent-death
//! signal), so a bench that is killed leaves no busy process behind.

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use super::{BenchError, io};

/// Flags of the hidden `gjkd bench busy`: one busy process.
#[derive(clap::Args, Debug, Clone)]
pub struct BusyArgs {
    /// End after this many seconds, whatever happens to the bench.
    #[arg(long, default_value_t = 60.0)]
    seconds: f64,
}

/// Runs `gjkd bench busy`: computes without sleeping until `--seconds`
/// have passed.
pub fn run_busy(args: &BusyArgs) {
    // End with the bench if it dies without stopping us.
    // SAFETY: prctl(PR_SET_PDEATHSIG) takes a signal number and no pointers.
    unsafe {
        libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL);
    }
    let end = Instant::now() + Duration::from_secs_f64(args.seconds.clamp(0.0, 3600.0));
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    while Instant::now() < end {
        // Real work rather than a pause instruction: the CPU is as busy as
        // a computing neighbour keeps it.
        for _ in 0..10_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
        }
        std::hint::black_box(x);
    }
}

/// Running busy processes, killed (SIGKILL, by process id) and reaped when
/// dropped.
pub struct Competitors {
    children: Vec<Child>,
}

impl Competitors {
    /// Starts `n` busy processes, unpinned (the scheduler places them, as
    /// it would an unrelated program), each ending by itself after
    /// `seconds`.
    ///
    /// # Errors
    /// When a process cannot be spawned; those already started are killed.
    pub fn start(n: usize, seconds: f64) -> Result<Self, BenchError> {
        let mut competitors = Competitors {
            children: Vec::with_capacity(n),
        };
        let exe = io("find this executable", std::env::current_exe())?;
        for _ in 0..n {
            let child = io(
                "spawn gjkd bench busy",
                Command::new(&exe)
                    .args(["bench", "busy", "--seconds", &format!("{seconds:.1}")])
                    .stdin(Stdio::null())
                    .stdout(Stdio::null())
                    .spawn(),
            )?;
            competitors.children.push(child);
        }
        Ok(competitors)
    }

    /// The process ids, for the report.
    pub fn pids(&self) -> Vec<u32> {
        self.children.iter().map(Child::id).collect()
    }
}

impl Drop for Competitors {
    fn drop(&mut self) {
        for child in &mut self.children {
            // Child::kill sends SIGKILL to this child's own pid, which has
            // not been reaped yet, so it cannot name another process.
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}
