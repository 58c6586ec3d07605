//! Everything this module takes from the server library, in one place: the
//! pose check and the request handlers (`gjkd.Local` answers with the very
//! code a server runs, so the answers are the same bit for bit), and the
//! serving command (`python -m gjkd serve`).

use gjkd_proto::{
    AdminChunk, AdminRequest, ErrorCode, Gradient, GradientRow, Item, ItemResult, Pose, SceneReply,
    SceneRequest, SceneRow, WaitMode,
};
use nalgebra::Isometry3;

/// The server's check of a wire pose (finite, unit quaternion within its
/// tolerance) and the isometry it then uses.
///
/// # Errors
/// `NonFinitePose` or `BadQuaternion`.
pub fn check_pose(p: &Pose) -> Result<Isometry3<f64>, ErrorCode> {
    gjkd_server::engine::checks::check_pose(p)
}

/// The server's limits, with defaults.
pub use gjkd_server::engine::state::Limits;

/// The server's object store and request handlers, without any IPC.
pub struct Store {
    state: gjkd_server::engine::state::State,
    /// The gradient section of the last request with gradients, kept so
    /// that a request allocates nothing once it has grown.
    gradient_rows: Vec<GradientRow>,
}

/// The client identity `gjkd.Local` uses with the handlers: the owner of
/// every object and the key of the pair queries' warm starts.
const LOCAL_CLIENT: u128 = 1;

/// The key of the scene questions' warm starts and motion bounds: apart
/// from the pair queries', as a server keeps a client's scene port apart
/// from its query port, so that a `Local` starts each pair as warm as a
/// `Client` does.
const LOCAL_SCENES: u128 = 2;

impl Store {
    /// An empty store.
    pub fn new(limits: Limits) -> Self {
        Store {
            state: gjkd_server::engine::state::State::new(limits, WaitMode::Spin, 1),
            gradient_rows: Vec::new(),
        }
    }

    /// The limits.
    pub fn limits(&self) -> &Limits {
        self.state.limits()
    }

    /// Answers an admin request (a registration, removal, look-up or
    /// robot) with its payload (vertices or robot text): the id, or the
    /// error.
    pub fn admin(
        &mut self,
        request: &AdminRequest,
        payload: &[AdminChunk],
    ) -> Result<u64, ErrorCode> {
        let reply = self.state.handle_admin(LOCAL_CLIENT, request, payload);
        match reply.error_code() {
            ErrorCode::Ok => Ok(reply.id),
            code => Err(code),
        }
    }

    /// The stored pose of each of `ids` (see `State::poses`).
    pub fn poses(&self, ids: &[u64], out: &mut [gjkd_proto::StoredPose]) {
        self.state.poses(ids, out);
    }

    /// Answers query items as a server answers one request.
    pub fn handle(&mut self, items: &[Item], results: &mut [ItemResult]) {
        self.state.handle(LOCAL_CLIENT, items, results);
    }

    /// Answers a scene request as a server does, rows into `rows` (its
    /// length is the most rows written).
    pub fn scene(
        &mut self,
        request: &SceneRequest,
        items: &[Item],
        rows: &mut [SceneRow],
    ) -> SceneReply {
        self.state.scene(LOCAL_SCENES, request, items, rows)
    }

    /// The id of the object named `name`.
    pub fn lookup(&self, name: &str) -> Option<u64> {
        self.state.lookup(name)
    }

    /// As [`Store::handle`], and the gradient of the `k`-th item that asks
    /// for one into `gradients[k]` (room for all of them), as a server's
    /// reply carries them.
    pub fn handle_gradients(
        &mut self,
        items: &[Item],
        results: &mut [ItemResult],
        gradients: &mut [Gradient],
    ) {
        let rows = &mut self.gradient_rows;
        rows.clear();
        rows.resize(gradients.len(), GradientRow::default());
        self.state
            .handle_with_gradients(LOCAL_CLIENT, items, results, rows);
        for (out, row) in gradients.iter_mut().zip(rows.iter()) {
            *out = row.gradient;
        }
    }

    /// Objects held.
    pub fn len(&self) -> usize {
        self.state.len()
    }

    /// Forgets every warm start.
    pub fn forget_warm_starts(&mut self) {
        // The scene questions' motion bounds too: every client is gone.
        self.state.retain_clients(|_| false);
    }
}

/// `python -m gjkd serve`: the flags of `gjkd serve`, parsed by the
/// server library's own definition.
#[derive(clap::Parser, Debug)]
#[command(
    name = "python -m gjkd serve",
    about = "Serve distance queries until SIGINT or SIGTERM."
)]
struct ServeCommand {
    #[command(flatten)]
    args: gjkd_server::commands::ServeArgs,
}

/// Runs `gjkd serve` with `args` (without the program name) until SIGINT
/// or SIGTERM, logging to stderr as the `gjkd` binary does; the exit
/// status.
pub fn serve(args: &[String]) -> i32 {
    use clap::Parser;
    let program = std::iter::once("python -m gjkd serve".to_owned());
    let command = match ServeCommand::try_parse_from(program.chain(args.iter().cloned())) {
        Ok(c) => c,
        Err(e) => {
            // Help and version go to stdout with status 0, mistakes to
            // stderr with status 2, as clap does on its own.
            let _ = e.print();
            return e.exit_code();
        }
    };
    let _ = tracing_subscriber::fmt()
        .with_writer(std::io::stderr)
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info")),
        )
        .try_init();
    match gjkd_server::commands::serve(command.args) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("gjkd serve: {e}");
            1
        }
    }
}
