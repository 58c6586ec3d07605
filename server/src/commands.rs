//! The daemon's two commands, flags and all: `gjkd serve` ([`ServeArgs`],
//! [`serve`]) and the offline `gjkd objects` ([`ObjectsArgs`], [`objects`]).
//! They live in the library rather than in the binary so that every front
//! end that starts a server (the `gjkd` command line, language bindings)
//! takes the same flags and starts it the same way.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use clap::{Args, ValueEnum};
use gjkd_proto::{DEFAULT_SERVICE, MAX_PIECES, WaitMode};
use tracing::info;

use crate::engine::state::{Limits, State};
use crate::scene::Scene;
use crate::server::{ServeOptions, run};

/// How the server waits for requests (`--wait`).
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Wait {
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

/// The flags of `gjkd serve`.
#[derive(Args, Debug)]
pub struct ServeArgs {
    /// Deployment name: the services are NAME/v4/query, NAME/v4/admin,
    /// NAME/v4/scene and NAME/v4/wake.
    #[arg(long, default_value = DEFAULT_SERVICE)]
    pub service: String,
    /// Scene file (TOML) of read-only named objects to load at start.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// A folder searched for the scene robots' `package://` mesh URLs
    /// (repeatable; searched before `GJKD_PACKAGE_PATH`).
    #[arg(long, value_name = "DIR")]
    pub package_path: Vec<PathBuf>,
    /// Wait strategy.
    #[arg(long, value_enum, default_value_t = Wait::Adaptive)]
    pub wait: Wait,
    /// Pin the serving thread to this CPU (docs/deployment.md: best a CPU
    /// no busy process shares, and not the client's).
    #[arg(long, value_name = "N")]
    pub cpu: Option<usize>,
    /// Run the serving thread at this SCHED_FIFO real-time priority (1 to
    /// 99): a woken server then preempts any ordinary process at once.
    /// Needs CAP_SYS_NICE or RLIMIT_RTPRIO; with `--wait spin`, only on a
    /// CPU of its own.
    #[arg(long, value_name = "P")]
    pub priority: Option<i32>,
    /// Most clients at once (one per `gjkd-client` `Client`; the limit holds
    /// for each of the query and admin services).
    #[arg(long, default_value_t = Limits::default().max_clients)]
    pub max_clients: usize,
    /// Most processes (iceoryx2 nodes) per service.
    #[arg(long, default_value_t = Limits::default().max_nodes)]
    pub max_nodes: usize,
    /// Most items per query or scene request.
    #[arg(long, default_value_t = Limits::default().max_batch)]
    pub max_batch: usize,
    /// Most rows per scene answer. Its shared memory is reserved for four
    /// answers a client (152 bytes a row; sparse: resident only as answers
    /// fill it). Clients split a longer path into several requests by
    /// themselves.
    #[arg(long, default_value_t = Limits::default().max_rows)]
    pub max_rows: usize,
    /// Most vertices per registered object.
    #[arg(long, default_value_t = Limits::default().max_vertices)]
    pub max_vertices: usize,
    /// Most objects held at once.
    #[arg(long, default_value_t = Limits::default().max_objects)]
    pub max_objects: usize,
    /// Most warm-start cache entries (one per client and ordered pair).
    #[arg(long, default_value_t = Limits::default().cache_capacity)]
    pub cache_capacity: usize,
    /// State file: registered objects are written here before each
    /// registration or removal is acknowledged, and reloaded at start with
    /// the same ids. Default
    /// `${XDG_STATE_HOME:-$HOME/.local/state}/gjkd/<service>.objects`
    /// (directory created 0700, file 0600).
    #[arg(long, value_name = "PATH", conflicts_with = "no_persist")]
    pub state_file: Option<PathBuf>,
    /// Keep objects in memory only: they are lost when the server stops.
    #[arg(long)]
    pub no_persist: bool,
    /// Remove, while serving, the objects of clients whose process has
    /// ended, within seconds of it (scene objects and those of running
    /// clients stay; ids are never reused). Off by default: such objects
    /// keep being served, and `gjkd objects --remove-departed` removes
    /// them with the server stopped.
    #[arg(long)]
    pub remove_departed: bool,
}

/// The flags of `gjkd objects`.
#[derive(Args, Debug)]
pub struct ObjectsArgs {
    /// Deployment name, for the default state file.
    #[arg(long, default_value = DEFAULT_SERVICE)]
    pub service: String,
    /// State file (default as for `gjkd serve`). The server using it must
    /// be stopped: its lock on the file is checked.
    #[arg(long, value_name = "PATH")]
    pub state_file: Option<PathBuf>,
    /// Remove the objects whose owner (an iceoryx2 node) no longer runs.
    /// Scene objects and those of running clients stay; ids are never
    /// reused.
    #[arg(long)]
    pub remove_departed: bool,
}

/// Runs `gjkd objects`: prints the table, and removes the departed owners'
/// objects when asked. Loading does to a damaged change log what a server
/// start would (see `open_state`).
///
/// # Errors
/// A message saying what stopped it.
pub fn objects(args: &ObjectsArgs) -> Result<(), String> {
    let path = args
        .state_file
        .clone()
        .or_else(|| crate::persist::default_path(&args.service))
        .ok_or("neither XDG_STATE_HOME nor HOME is set: give --state-file")?;
    crate::offline::run(&path, args.remove_departed)
}

/// Runs `gjkd serve` until SIGINT or SIGTERM.
///
/// # Errors
/// A message saying what stopped it: the state file, the scene or the
/// service could not be opened, or serving failed.
pub fn serve(args: ServeArgs) -> Result<(), String> {
    let shutdown = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(signal, Arc::clone(&shutdown))
            .map_err(|e| format!("cannot install the handler of signal {signal}: {e}"))?;
    }
    serve_until(args, &shutdown, || {})
}

/// Runs `gjkd serve` until `shutdown` is set, calling `ready` once the
/// services are open; for a front end that handles signals itself or stops
/// the server on its own terms.
///
/// # Errors
/// As [`serve`].
pub fn serve_until(
    args: ServeArgs,
    shutdown: &AtomicBool,
    ready: impl FnOnce(),
) -> Result<(), String> {
    place_thread(args.cpu, args.priority)?;
    if args.priority.is_none() && !matches!(args.wait, Wait::Spin) {
        // A server that sleeps must be woken at once on a busy CPU: see
        // `wait`. Asked for, not required: an old kernel ignores it.
        if let Err(e) = gjkd_rt::request_short_slice(gjkd_rt::MIN_SLICE) {
            tracing::warn!(
                "cannot ask for short time slices ({e}): wake-ups beside busy processes may wait a slice"
            );
        }
    }
    let limits = Limits {
        max_clients: args.max_clients.max(1),
        max_nodes: args.max_nodes.max(2),
        max_batch: args.max_batch.max(1),
        max_rows: args.max_rows.max(1),
        max_vertices: args.max_vertices.max(1),
        max_pieces: MAX_PIECES,
        max_objects: args.max_objects,
        cache_capacity: args.cache_capacity,
    };
    let mut state = if args.no_persist {
        State::new(limits, args.wait.into(), epoch())
    } else {
        open_state(&args, limits)?
    };
    if let Some(path) = &args.scene {
        let ids = Scene::load(path)
            .and_then(|mut s| {
                s.package_path.clone_from(&args.package_path);
                s.install(&mut state)
            })
            .map_err(|e| e.to_string())?;
        info!(scene = %path.display(), objects = ids.len(), "scene loaded");
    }
    // Written once at start: a read-only directory fails now rather than at
    // the first registration, and the scene's ids become durable.
    state.persist().map_err(|e| e.to_string())?;
    let options = ServeOptions {
        service: args.service,
        wait: args.wait.into(),
        remove_departed: args.remove_departed,
    };
    run(&options, state, shutdown, ready).map_err(|e| e.to_string())
}

/// Pins the calling thread, which is about to serve, to `cpu` and gives it
/// real-time `priority`, each when asked for; before anything is opened,
/// so that a bad flag stops the start with nothing done.
///
/// # Errors
/// The flag and why the kernel refused it.
pub fn place_thread(cpu: Option<usize>, priority: Option<i32>) -> Result<(), String> {
    if let Some(cpu) = cpu {
        gjkd_rt::pin_current_thread(cpu).map_err(|e| format!("--cpu {cpu}: {e}"))?;
    }
    if let Some(priority) = priority {
        gjkd_rt::set_realtime_priority(priority)
            .map_err(|e| format!("--priority {priority}: {e}"))?;
    }
    Ok(())
}

/// The state of a persisting server (see `State::open`).
fn open_state(args: &ServeArgs, limits: Limits) -> Result<State, String> {
    let path = args
        .state_file
        .clone()
        .or_else(|| crate::persist::default_path(&args.service))
        .ok_or("neither XDG_STATE_HOME nor HOME is set: give --state-file or --no-persist")?;
    crate::persist::open_state(limits, args.wait.into(), &path, epoch())
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
