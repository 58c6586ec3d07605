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
//!   wait mode, beside a Unix-socket server process and a plain function call, with
//!   HdrHistogram percentiles.
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

#![warn(missing_docs)]

use std::path::PathBuf;

pub mod collision_sweep;
pub mod demo;
pub mod extremes;
pub mod latency;
pub mod paper;
pub mod plot;
pub mod robot;
pub mod robot_demo;
pub mod scene_call;
pub mod scene_inprocess;
pub mod scene_parry;
pub mod scene_robot;
pub mod scene_world;
pub mod served_sweep;
pub mod server_process;
pub mod stats;
pub mod tradeoff;
mod tradeoff_by_size;
pub mod uds;

/// `gjkd bench` and its subcommands.
#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    #[command(subcommand)]
    command: BenchCommand,
}

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
    /// The paper's Section 7: time per query and per vertex against M.
    Paper(paper::PaperArgs),
    /// A 7-joint robot moved by one joint request with 70 link-obstacle
    /// queries, against the same queries at link poses the client computed.
    Robot(robot::RobotArgs),
    /// A 7-link arm among 1 000 obstacles: per step each link's clearance
    /// and the pairs within 5 % of the arm's size, by parry3d-f64 in
    /// process, gjkd per-pair queries and gjkd scene requests.
    SceneRobot(scene_robot::SceneRobotArgs),
    /// The paper's Section 8 as a collision sweep: one path request against
    /// cold per-pair queries in batches.
    Sweep(collision_sweep::SweepArgs),
    /// The socket server `latency` starts as a child process.
    #[command(hide = true)]
    UdsServer(uds::UdsServerArgs),
}

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

impl BenchError {
    /// An item's or a scene request's error code.
    pub(crate) fn from_code(code: gjkd_client::ErrorCode) -> Self {
        BenchError::Client(gjkd_client::ClientError::Rejected(code))
    }
}

/// `Result::map_err` helper naming what was being done.
pub(crate) fn io<T>(what: impl Into<String>, r: std::io::Result<T>) -> Result<T, BenchError> {
    r.map_err(|e| BenchError::Io(what.into(), e))
}

/// Runs one `gjkd bench` subcommand.
///
/// # Errors
/// What stopped it.
pub fn run(args: BenchArgs) -> Result<(), BenchError> {
    if let BenchCommand::UdsServer(a) = &args.command {
        // A child of `latency`: it serves until killed and prints nothing
        // but its ready line.
        return uds::run_server(a);
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
        BenchCommand::Sweep(a) => {
            collision_sweep::run(&a)?;
            "sweep"
        }
        BenchCommand::UdsServer(_) => unreachable!("handled above"),
    };
    println!(
        "\ngjkd bench {what}: finished in {:.1} s (wall time of the whole command)",
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Creates the output directory.
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
