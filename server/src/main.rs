//! `gjkd`: the distance server (`gjkd serve`), its demo (`gjkd demo`), its
//! measurements (`gjkd bench`) and a state-file tool (`gjkd objects`).

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use clap::{Args, Parser, Subcommand, ValueEnum};
use gjkd::scene::Scene;
use gjkd::server::{ServeOptions, run};
use gjkd::state::{Limits, State};
use gjkd_proto::{DEFAULT_SERVICE, MAX_PIECES, WaitMode};
use tracing::{error, info};

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
    /// Measurements: `latency`, `tradeoff` (speed against accuracy) and
    /// `paper` (Section 7). See docs/benchmarks.md.
    Bench(gjkd::bench::BenchArgs),
    /// List the objects of a stopped server's state file, with whether each
    /// owner still runs; with --remove-departed, remove those whose
    /// registering client process is gone (a client can remove only its
    /// own objects, so no client can remove these).
    Objects(ObjectsArgs),
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum Wait {
    /// Busy-poll: lowest latency, burns a core.
    Spin,
    /// Sleep until a client notifies: no busy CPU.
    Block,
    /// Spin briefly after each request, then sleep.
    Adaptive,
}

impl From<Wait> for WaitMode {
    fn from(w: Wait) -> Self {
        match w {
            Wait::Spin => WaitMode::Spin,
            Wait::Block => WaitMode::Block,
            Wait::Adaptive => WaitMode::Adaptive,
        }
    }
}

#[derive(Args, Debug)]
struct ServeArgs {
    /// Deployment name: the services are NAME/v1/query, NAME/v1/admin and
    /// NAME/v1/wake.
    #[arg(long, default_value = DEFAULT_SERVICE)]
    service: String,
    /// Scene file (TOML) of read-only named objects to load at start.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Wait strategy.
    #[arg(long, value_enum, default_value_t = Wait::Adaptive)]
    wait: Wait,
    /// Most clients at once (one per `gjkd-client` `Client`; the limit holds
    /// for each of the query and admin services).
    #[arg(long, default_value_t = Limits::default().max_clients)]
    max_clients: usize,
    /// Most processes (iceoryx2 nodes) per service.
    #[arg(long, default_value_t = Limits::default().max_nodes)]
    max_nodes: usize,
    /// Most items per query request.
    #[arg(long, default_value_t = Limits::default().max_batch)]
    max_batch: usize,
    /// Most vertices per registered object.
    #[arg(long, default_value_t = Limits::default().max_vertices)]
    max_vertices: usize,
    /// Most objects held at once.
    #[arg(long, default_value_t = Limits::default().max_objects)]
    max_objects: usize,
    /// Most warm-start cache entries (one per client and ordered pair).
    #[arg(long, default_value_t = Limits::default().cache_capacity)]
    cache_capacity: usize,
    /// State file: registered objects are written here before each
    /// registration or removal is acknowledged, and reloaded at start with
    /// the same ids. Default
    /// `${XDG_STATE_HOME:-$HOME/.local/state}/gjkd/<service>.objects`
    /// (directory created 0700, file 0600).
    #[arg(long, value_name = "PATH", conflicts_with = "no_persist")]
    state_file: Option<PathBuf>,
    /// Keep objects in memory only: they are lost when the server stops.
    #[arg(long)]
    no_persist: bool,
    /// Remove, while serving, the objects of clients whose process has
    /// ended, within seconds of it (scene objects and those of running
    /// clients stay; ids are never reused). Off by default: such objects
    /// keep being served, and `gjkd objects --remove-departed` removes
    /// them with the server stopped.
    #[arg(long)]
    remove_departed: bool,
}

#[derive(Args, Debug)]
struct ObjectsArgs {
    /// Deployment name, for the default state file.
    #[arg(long, default_value = DEFAULT_SERVICE)]
    service: String,
    /// State file (default as for `gjkd serve`). The server using it must
    /// be stopped: its lock on the file is checked.
    #[arg(long, value_name = "PATH")]
    state_file: Option<PathBuf>,
    /// Remove the objects whose owner (an iceoryx2 node) no longer runs.
    /// Scene objects and those of running clients stay; ids are never
    /// reused.
    #[arg(long)]
    remove_departed: bool,
}

#[derive(Args, Debug)]
struct DemoArgs {
    /// Sweep steps to time, besides the paper's 10, 100 and 1000.
    #[arg(long, value_delimiter = ',', default_values_t = [10usize, 100, 1000])]
    steps: Vec<usize>,
    /// Repetitions of each timed sweep (the median is reported).
    #[arg(long, default_value_t = 7)]
    repeats: usize,
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
        Command::Serve(args) => serve(args),
        Command::Demo(args) => match gjkd::demo::run(&args.steps, args.repeats.max(1)) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("gjkd demo: {e}");
                ExitCode::FAILURE
            }
        },
        Command::Bench(args) => match gjkd::bench::run(args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("gjkd bench: {e}");
                ExitCode::FAILURE
            }
        },
        Command::Objects(args) => match objects(&args) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("gjkd objects: {e}");
                ExitCode::FAILURE
            }
        },
    }
}

/// `gjkd objects`: the table, and the removal when asked for.
fn objects(args: &ObjectsArgs) -> Result<(), String> {
    let path = args
        .state_file
        .clone()
        .or_else(|| gjkd::stored::default_path(&args.service))
        .ok_or("neither XDG_STATE_HOME nor HOME is set: give --state-file")?;
    gjkd::offline::run(&path, args.remove_departed)
}

fn serve(args: ServeArgs) -> ExitCode {
    let limits = Limits {
        max_clients: args.max_clients.max(1),
        max_nodes: args.max_nodes.max(2),
        max_batch: args.max_batch.max(1),
        max_vertices: args.max_vertices.max(1),
        max_pieces: MAX_PIECES,
        max_objects: args.max_objects,
        cache_capacity: args.cache_capacity,
    };
    let mut state = if args.no_persist {
        State::new(limits, args.wait.into(), epoch())
    } else {
        match open_state(&args, limits) {
            Ok(state) => state,
            Err(message) => {
                error!("{message}");
                return ExitCode::FAILURE;
            }
        }
    };
    if let Some(path) = &args.scene {
        match Scene::load(path).and_then(|s| s.install(&mut state)) {
            Ok(ids) => info!(scene = %path.display(), objects = ids.len(), "scene loaded"),
            Err(e) => {
                error!("{e}");
                return ExitCode::FAILURE;
            }
        }
    }
    // Written once at start: a read-only directory fails now rather than at
    // the first registration, and the scene's ids become durable.
    if let Err(e) = state.persist() {
        error!("{e}");
        return ExitCode::FAILURE;
    }
    let shutdown = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        if let Err(e) = signal_hook::flag::register(signal, Arc::clone(&shutdown)) {
            error!("cannot install the handler of signal {signal}: {e}");
            return ExitCode::FAILURE;
        }
    }
    let options = ServeOptions {
        service: args.service,
        wait: args.wait.into(),
        remove_departed: args.remove_departed,
    };
    match run(&options, state, &shutdown, || {}) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            error!("{e}");
            ExitCode::FAILURE
        }
    }
}

/// The state of a persisting server (see `State::open`).
fn open_state(args: &ServeArgs, limits: Limits) -> Result<State, String> {
    let path = args
        .state_file
        .clone()
        .or_else(|| gjkd::stored::default_path(&args.service))
        .ok_or("neither XDG_STATE_HOME nor HOME is set: give --state-file or --no-persist")?;
    State::open(limits, args.wait.into(), &path, epoch())
}

/// Upper half of every object id of this run: differs between runs so that a
/// client's ids from before a restart are unknown, not aliases.
fn epoch() -> u32 {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos() as u64)
        .unwrap_or(0);
    let mixed = (nanos ^ (u64::from(std::process::id()) << 20)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    ((mixed >> 32) as u32).max(1)
}
