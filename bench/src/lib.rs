//! # gjkd-bench
//!
//! The tools that use a gjkd server rather than make one: the built-in demo
//! (`gjkd demo`, [`demo`]) and the measurements of `gjkd bench`, behind
//! `docs/benchmarks.md` and `docs/speed-accuracy.md`, one command each.
//! They start real `gjkd serve` processes and talk to them through
//! `gjkd-client`, which is why they sit in a crate of their own above the
//! server library instead of inside it.
//!
//! - [`latency`]: round trips through real `gjkd serve` processes in each
//!   wait mode, beside a Unix-socket server process, a bare iceoryx2 server
//!   ([`raw_ipc`]) and a plain function call, with HdrHistogram percentiles;
//!   quiet or beside competing busy processes ([`busy`]), pinned or not.
//! - [`tradeoff`]: time against error over tolerances, iteration caps, warm
//!   and cold starts and early-exit margins, judged by an exact reference
//!   ([`gjkd_testkit::reference`](mod@gjkd_testkit::reference)) that owes nothing to GJK.
//! - [`paper`]: the paper's Section 7, time per query against the number of
//!   vertices `M`.
//! - [`robot`]: a 7-joint robot moved by one joint request, against link
//!   poses computed by the client.
//! - [`scene_robot`]: a 7-link arm among 1 000 obstacles, clearance and
//!   pairs within a margin per step, by parry3d-f64 in process, gjkd
//!   per-pair queries and gjkd scene requests.
//! - [`collision_sweep`]: the paper's Section 8 as a collision sweep, one
//!   path request against cold per-pair queries.
//!
//! Each writes a table to stdout, CSV and SVG plots to `--out`, and shows a
//! progress bar while it runs. Timing is never asserted anywhere: the tests
//! cover only the logic (percentiles, fits, the Pareto front).
//!
//! The measurements are behind the default feature `measure`; without it
//! (as the `gjkd` daemon links this crate unless built with its `bench`
//! feature) only the demo is here, and `gjkd bench` says how to get them.

#![warn(missing_docs)]

#[cfg(feature = "measure")]
use std::path::PathBuf;

#[cfg(feature = "measure")]
pub mod busy;
#[cfg(feature = "measure")]
pub mod collision_sweep;
pub mod contact_intervals;
pub mod demo;
#[cfg(feature = "measure")]
pub mod depth;
#[cfg(feature = "measure")]
pub mod edges;
#[cfg(feature = "measure")]
pub mod extremes;
#[cfg(feature = "measure")]
pub mod latency;
#[cfg(feature = "measure")]
pub mod latency_objects;
#[cfg(feature = "measure")]
pub mod paper;
#[cfg(feature = "measure")]
pub mod plot;
#[cfg(feature = "measure")]
pub mod raw_ipc;
#[cfg(feature = "measure")]
pub mod robot;
pub mod robot_demo;
pub mod scene_call;
#[cfg(feature = "measure")]
pub mod scene_inprocess;
#[cfg(feature = "measure")]
pub mod scene_parry;
#[cfg(feature = "measure")]
pub mod scene_robot;
#[cfg(feature = "measure")]
pub mod scene_world;
pub mod served_sweep;
pub mod server_process;
#[cfg(feature = "measure")]
pub mod stats;
#[cfg(feature = "measure")]
pub mod tradeoff;
#[cfg(feature = "measure")]
pub mod uds;

#[cfg(feature = "measure")]
/// `gjkd bench` and its subcommands.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    #[command(subcommand)]
    command: BenchCommand,
}

#[cfg(feature = "measure")]
#[derive(clap::Subcommand, Debug)]
enum BenchCommand {
    /// Round-trip latency: spin, block and adaptive servers, a Unix-socket
    /// server and an in-process call, single pairs and batches, back to back
    /// and with gaps.
    Latency(latency::LatencyArgs),
    /// Speed against accuracy: tolerance, iteration caps, warm/cold starts,
    /// margins and f32 support search on the paper's family and an extremes
    /// family, and the f32 search on box clouds of 16 to 16 384 points.
    Tradeoff(tradeoff::TradeoffArgs),
    /// The penetration depth's tolerance: time, error against the
    /// brute-force depth and interval width on overlapping polytopes and
    /// cylinders.
    Depth(depth::DepthArgs),
    /// The paper's Section 7: time per query and per vertex against M.
    Paper(paper::PaperArgs),
    /// A 7-joint robot moved by one joint request with 70 link-obstacle
    /// queries, against the same queries at link poses the client computed.
    Robot(robot::RobotArgs),
    /// A 7-link arm among 1 000 obstacles: per step each link's clearance
    /// and the pairs within 5 % of the arm's size, by parry3d-f64 in
    /// process, gjkd per-pair queries and gjkd scene requests.
    SceneRobot(scene_robot::SceneRobotArgs),
    /// A planner's edge check for the 7-link arm among 1 000 obstacles:
    /// gjkd's certified continuous check (one request per edge) against
    /// sampled checks at OMPL's resolution, gjkd's and parry3d-f64's, with
    /// the collisions each misses.
    Edges(edges::EdgesArgs),
    /// The paper's Section 8 as a collision sweep: one path request against
    /// cold per-pair queries in batches.
    Sweep(collision_sweep::SweepArgs),
    /// The socket server `latency` starts as a child process.
    #[command(hide = true)]
    UdsServer(uds::UdsServerArgs),
    /// The bare iceoryx2 server `latency` starts as a child process.
    #[command(hide = true)]
    RawServer(raw_ipc::RawServerArgs),
    /// A busy process `latency --competitors` starts.
    #[command(hide = true)]
    Busy(busy::BusyArgs),
}

#[cfg(feature = "measure")]
/// Flags every bench command has.
#[derive(clap::Args, Clone, Debug)]
pub struct CommonArgs {
    /// Directory for CSV, SVG and Markdown output (`--out docs/img` to
    /// refresh the documentation's plots).
    #[arg(long, default_value = "target/gjkd-bench")]
    pub out: PathBuf,
    /// A smoke test: a small fraction of the work, same outputs.
    #[arg(long)]
    pub quick: bool,
}

/// What can stop a bench command.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// Reading or writing a file, or a socket.
    #[error("{0}: {1}")]
    Io(String, std::io::Error),
    /// A gjkd client call.
    #[error("client: {0}")]
    Client(#[from] gjkd_client::ClientError),
    /// Connecting to the server.
    #[error("connect: {0}")]
    Connect(#[from] gjkd_client::ConnectError),
    /// The algorithm refused an input (a bug in the bench's inputs).
    #[error("gjk: {0}")]
    Gjk(#[from] gjk::Error),
    /// Drawing a plot.
    #[error("plot {0}: {1}")]
    Plot(String, String),
    /// Anything else.
    #[error("{0}")]
    Other(String),
}

/// `From` each client operation's error (`RegisterError`, `QueryError`,
/// ...) for an error that takes a [`gjkd_client::ClientError`], read as
/// that umbrella, so that `?` on any client call converts.
macro_rules! from_client_operations {
    ($target:ty) => {
        $crate::from_client_operations!($target: RegisterError, RemoveError, LookupError,
            PoseError, QueryError, PoseReadError, StatsError, SceneError, RobotError);
    };
    ($target:ty: $($op:ident),*) => {
        $(impl From<gjkd_client::$op> for $target {
            fn from(e: gjkd_client::$op) -> Self {
                Self::from(gjkd_client::ClientError::from(e))
            }
        })*
    };
}
pub(crate) use from_client_operations;

from_client_operations!(BenchError);

#[cfg(feature = "measure")]
impl BenchError {
    /// An item's or a scene request's error code.
    pub(crate) fn from_code(code: gjkd_client::ErrorCode) -> Self {
        BenchError::Client(gjkd_client::ClientError::Rejected(code))
    }
}

#[cfg(feature = "measure")]
/// `Result::map_err` helper naming what was being done.
pub(crate) fn io<T>(what: impl Into<String>, r: std::io::Result<T>) -> Result<T, BenchError> {
    r.map_err(|e| BenchError::Io(what.into(), e))
}

#[cfg(feature = "measure")]
/// Runs one `gjkd bench` subcommand.
///
/// # Errors
/// What stopped it.
pub fn run(args: BenchArgs) -> Result<(), BenchError> {
    // Children of `latency`: they serve or compute until stopped and print
    // nothing but a ready line.
    match &args.command {
        BenchCommand::UdsServer(a) => return uds::run_server(a),
        BenchCommand::RawServer(a) => return raw_ipc::run_server(a),
        BenchCommand::Busy(a) => {
            busy::run_busy(a);
            return Ok(());
        }
        _ => {}
    }
    let start = std::time::Instant::now();
    let what = match args.command {
        BenchCommand::Latency(a) => {
            latency::run(&a)?;
            "latency"
        }
        BenchCommand::Tradeoff(a) => {
            tradeoff::run(&a)?;
            "tradeoff"
        }
        BenchCommand::Depth(a) => {
            depth::run(&a)?;
            "depth"
        }
        BenchCommand::Paper(a) => {
            paper::run(&a)?;
            "paper"
        }
        BenchCommand::Robot(a) => {
            robot::run(&a)?;
            "robot"
        }
        BenchCommand::SceneRobot(a) => {
            scene_robot::run(&a)?;
            "scene-robot"
        }
        BenchCommand::Edges(a) => {
            edges::run(&a)?;
            "edges"
        }
        BenchCommand::Sweep(a) => {
            collision_sweep::run(&a)?;
            "sweep"
        }
        BenchCommand::UdsServer(_) | BenchCommand::RawServer(_) | BenchCommand::Busy(_) => {
            unreachable!("handled above")
        }
    };
    println!(
        "\ngjkd bench {what}: finished in {:.1} s (wall time of the whole command)",
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(feature = "measure")]
/// Starts this executable as `gjkd bench SUBCOMMAND ARGS [--cpu N]` (a
/// child server of `latency`), with its stdout piped, and returns it with
/// the first line it printed (its ready line, or what it said instead).
pub(crate) fn spawn_child(
    args: &[&std::ffi::OsStr],
    cpu: Option<usize>,
) -> std::io::Result<(std::process::Child, std::process::ChildStdout, String)> {
    use std::io::Read;
    let mut cmd = std::process::Command::new(std::env::current_exe()?);
    cmd.arg("bench")
        .args(args)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped());
    if let Some(cpu) = cpu {
        cmd.args(["--cpu", &cpu.to_string()]);
    }
    let mut child = cmd.spawn()?;
    let Some(mut stdout) = child.stdout.take() else {
        let _ = child.kill();
        let _ = child.wait();
        return Err(std::io::Error::other("no stdout pipe"));
    };
    // The child writes nothing but this line, so an unbuffered read of it
    // leaves nothing behind in the pipe.
    let mut line = String::new();
    let mut byte = [0u8; 1];
    while stdout.read(&mut byte)? == 1 && byte[0] != b'\n' {
        line.push(char::from(byte[0]));
    }
    Ok((child, stdout, line))
}

/// Creates the output directory.
#[cfg(feature = "measure")]
pub(crate) fn out_dir(common: &CommonArgs) -> Result<PathBuf, BenchError> {
    io(
        format!("create {}", common.out.display()),
        std::fs::create_dir_all(&common.out),
    )?;
    Ok(common.out.clone())
}

/// A one-line description of the machine, for the tables: CPU model, core
/// count, kernel.
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_owned())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let kernel = std::fs::read_to_string("/proc/sys/kernel/osrelease")
        .map(|s| s.trim().to_owned())
        .unwrap_or_default();
    format!("{cpu}, {cores} cores, Linux {kernel}")
}

/// The 1-, 5- and 15-minute load averages, as `/proc/loadavg` gives them.
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

/// `gjkd bench` in a build without the measurements: takes any arguments.
#[cfg(not(feature = "measure"))]
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    /// The measurement and its flags.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    args: Vec<String>,
}

/// `gjkd bench` in a build without the measurements.
///
/// # Errors
/// Always: says how to build them in.
#[cfg(not(feature = "measure"))]
pub fn run(args: BenchArgs) -> Result<(), BenchError> {
    Err(BenchError::Other(format!(
        "`bench {}`: this gjkd was built without the measurements; run them with `cargo run --release -p gjkd --features bench -- bench ...`",
        args.args.join(" ")
    )))
}
