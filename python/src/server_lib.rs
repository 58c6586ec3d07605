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
pub fn serve(args: &[String]) -> i32 {
    let _ = args;
    eprintln!("gjkd serve: not available in this build yet");
    2
}
