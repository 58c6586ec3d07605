//! Everything this module takes from the server library, in one place: the
//! pose check and the request handlers (`gjkd.Local` answers with the very
//! code a server runs, so the answers are the same bit for bit), and the
//! serving command (`python -m gjkd serve`).

use gjkd_proto::{AdminRequest, ErrorCode, Item, ItemResult, Pose, Vertex, WaitMode};
use nalgebra::Isometry3;

/// The server's check of a wire pose (finite, unit quaternion within its
/// tolerance) and the isometry it then uses.
///
/// # Errors
/// `NonFinitePose` or `BadQuaternion`.
pub fn check_pose(p: &Pose) -> Result<Isometry3<f64>, ErrorCode> {
    gjkd::state::check_pose(p)
}

/// The server's limits, with defaults.
pub use gjkd::state::Limits;

/// The server's object store and request handlers, without any IPC.
pub struct Store {
    state: gjkd::state::State,
}

/// The client identity `gjkd.Local` uses with the handlers: the owner of
/// every object and the key of every warm start.
const LOCAL_CLIENT: u128 = 1;

impl Store {
    /// An empty store.
    pub fn new(limits: Limits) -> Self {
        Store {
            state: gjkd::state::State::new(limits, WaitMode::Spin, 1),
        }
    }

    /// The limits.
    pub fn limits(&self) -> &Limits {
        self.state.limits()
    }

    /// Answers a registration, removal or look-up: the id, or the error.
    pub fn admin(&mut self, request: &AdminRequest, vertices: &[Vertex]) -> Result<u64, ErrorCode> {
        let reply = self.state.handle_admin(LOCAL_CLIENT, request, vertices);
        match reply.error_code() {
            ErrorCode::Ok => Ok(reply.id),
            code => Err(code),
        }
    }

    /// Answers query items as a server answers one request.
    pub fn handle(&mut self, items: &[Item], results: &mut [ItemResult]) {
        self.state.handle(LOCAL_CLIENT, items, results);
    }

    /// Objects held.
    pub fn len(&self) -> usize {
        self.state.len()
    }

    /// Forgets every warm start.
    pub fn forget_warm_starts(&mut self) {
        self.state.forget_client(LOCAL_CLIENT);
    }
}

/// `gjkd serve` with `args` (no program name); the exit status.
///
/// Interim, until the server library has the serve command: in-memory
/// objects only, and the flags `--service`, `--wait`, `--max-batch`,
/// `--cache-capacity`, `--no-persist`.
pub fn serve(args: &[String]) -> i32 {
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;
    let mut limits = Limits::default();
    let mut options = gjkd::server::ServeOptions {
        service: gjkd_proto::DEFAULT_SERVICE.to_owned(),
        wait: WaitMode::Adaptive,
        remove_departed: false,
    };
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let mut value = || it.next().cloned().unwrap_or_default();
        match flag.as_str() {
            "--service" => options.service = value(),
            "--wait" => {
                options.wait = match value().as_str() {
                    "spin" => WaitMode::Spin,
                    "block" => WaitMode::Block,
                    _ => WaitMode::Adaptive,
                }
            }
            "--max-batch" => limits.max_batch = value().parse().unwrap_or(limits.max_batch),
            "--cache-capacity" => {
                limits.cache_capacity = value().parse().unwrap_or(limits.cache_capacity)
            }
            "--no-persist" => {}
            other => {
                eprintln!("gjkd serve: unknown flag {other}");
                return 2;
            }
        }
    }
    let state = gjkd::state::State::new(limits, options.wait, std::process::id().max(1));
    let shutdown = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        if signal_hook::flag::register(signal, Arc::clone(&shutdown)).is_err() {
            return 1;
        }
    }
    match gjkd::server::run(&options, state, &shutdown, || {}) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("gjkd serve: {e}");
            1
        }
    }
}
