//! `gjkd`: the distance server (`gjkd serve`), its demo (`gjkd demo`), its
//! measurements (`gjkd bench`) and a state-file tool (`gjkd objects`).
//!
//! A thin command line: the daemon's commands come from `gjkd-server`, the
//! demo and the measurements from `gjkd-bench` (the measurements only with
//! this package's `bench` feature, so that an installed daemon links no
//! test kit, plotting or progress crate).

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use gjkd_bench::demo::DemoArgs;
use gjkd_server::commands::{ObjectsArgs, ServeArgs};
use tracing::error;

#[derive(Parser, Debug)]
#[command(
    name = "gjkd",
    version,
    about = "Distance server for co-located processes"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Serve distance queries until SIGINT or SIGTERM.
    Serve(ServeArgs),
    /// Start a server, sweep the Section 8 scene through it and print the
    /// distances and the warm-start speed-up.
    Demo(DemoArgs),
    /// Measurements: `latency`, `tradeoff` (speed against accuracy),
    /// `paper` (Section 7), `robot`, `scene-robot` (a robot among 1 000
    /// obstacles, beside parry3d-f64) and `sweep` (Section 8 as a collision
    /// sweep). See docs/benchmarks.md. Built in with the `bench` feature
    /// (`cargo run --release -p gjkd --features bench -- bench ...`).
    Bench(gjkd_bench::BenchArgs),
    /// List the objects of a stopped server's state file, with whether each
    /// owner still runs; with --remove-departed, remove those whose
    /// registering client process is gone (a client can remove only its
    /// own objects, so no client can remove these).
    Objects(ObjectsArgs),
}

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_writer(std::io::stderr)
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info")),
        )
        .init();
    // iceoryx2 logs to the console by itself; keep it to real problems.
    iceoryx2::prelude::set_log_level(iceoryx2::prelude::LogLevel::Error);
    let cli = Cli::parse();
    match cli.command {
        Command::Serve(args) => match gjkd_server::commands::serve(args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                error!("{e}");
                ExitCode::FAILURE
            }
        },
        Command::Demo(args) => match gjkd_bench::demo::run(&args.steps, args.repeats.max(1)) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("gjkd demo: {e}");
                ExitCode::FAILURE
            }
        },
        Command::Bench(args) => match gjkd_bench::run(args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("gjkd bench: {e}");
                ExitCode::FAILURE
            }
        },
        Command::Objects(args) => match gjkd_server::commands::objects(&args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("gjkd objects: {e}");
                ExitCode::FAILURE
            }
        },
    }
}
