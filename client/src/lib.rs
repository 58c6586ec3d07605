//! # gjkd-client
//!
//! Client of the gjkd distance server. A [`Client`] talks to a `gjkd serve`
//! process on the same host through iceoryx2 shared memory: register convex
//! objects once, then ask for distances between them at changing poses, one
//! pair at a time or in batches. The server keeps each pair's last simplex
//! per client, so a sequence of queries along a motion starts warm.
//!
//! Start a server first (`gjkd serve`, or `gjkd serve --service NAME` to run
//! several side by side), then:
//!
//! ```no_run
//! use gjkd_client::{Client, QueryOptions};
//! use nalgebra::{Isometry3, Point3, Vector3};
//!
//! # fn main() -> Result<(), gjkd_client::ClientError> {
//! let mut client = Client::connect("gjkd")?;
//! let ball = client.register_sphere(0.5)?;
//! let crate_ = client.register_cuboid(Vector3::new(1.0, 1.0, 1.0), 0.0)?;
//!
//! // Poses are stored by the server until changed...
//! client.set_pose(ball, &Isometry3::translation(3.0, 0.0, 0.0))?;
//! let answer = client.distance(crate_, ball, &QueryOptions::default())?;
//! assert!((answer.distance - 1.5).abs() < 1e-9);
//! println!("nearest points {} and {}", answer.point_a, answer.point_b);
//!
//! // ...or given per query, leaving the stored ones alone.
//! let answer = client.distance_at(
//!     crate_, &Isometry3::identity(),
//!     ball, &Isometry3::translation(0.0, 4.0, 0.0),
//!     &QueryOptions::default(),
//! )?;
//! assert!((answer.distance - 2.5).abs() < 1e-9);
//! # Ok(())
//! # }
//! ```
//!
//! ## Batches
//!
//! [`Client::query_batch`] sends any mix of pose updates and pair queries as
//! one request and writes the results, in order, into a buffer you own: no
//! buffers are allocated per call. Each result carries its own error code.
//!
//! ```no_run
//! use gjkd_client::{Client, ErrorCode, Item, ItemResult, QueryOptions};
//! use nalgebra::{Isometry3, Vector3};
//!
//! # fn main() -> Result<(), gjkd_client::ClientError> {
//! let mut client = Client::connect("gjkd")?;
//! let robot = client.register_cuboid(Vector3::new(0.5, 0.5, 1.0), 0.05)?;
//! let obstacles: Vec<_> = (0..8)
//!     .map(|_| client.register_sphere(0.3))
//!     .collect::<Result<_, _>>()?;
//! for (i, &o) in obstacles.iter().enumerate() {
//!     client.set_pose(o, &Isometry3::translation(2.0 + i as f64, 0.0, 0.0))?;
//! }
//!
//! let mut items = Vec::new();
//! let mut results = vec![ItemResult::default(); obstacles.len() + 1];
//! for step in 0..100 {
//!     items.clear();
//!     let pose = Isometry3::translation(0.05 * step as f64, 0.0, 0.0);
//!     items.push(Item::set_pose(robot, &pose));
//!     for &o in &obstacles {
//!         items.push(Item::distance(robot, o, &QueryOptions::default()));
//!     }
//!     client.query_batch(&items, &mut results)?;
//!     for r in &results[1..] {
//!         match r.answer() {
//!             Ok(a) => println!("{:.3}", a.distance),
//!             Err(ErrorCode::UnknownObject) => println!("removed meanwhile"),
//!             Err(e) => println!("error: {e}"),
//!         }
//!     }
//! }
//! # Ok(())
//! # }
//! ```
//!
//! ## Scene queries
//!
//! [`Client::clearance`], [`Client::within`], [`Client::nearest`] and
//! [`Client::path`] ask about a group of objects against the whole scene in
//! one round trip (the nearest obstacle of each robot link, every pair
//! within a margin, the k nearest objects, all of it along a candidate
//! motion), into a buffer of rows you own; see [`SceneQuery`].
//!
//! ## Errors, timeouts and a server that goes away
//!
//! Every call returns within the client's timeout (default one second, see
//! [`ClientBuilder::timeout`]). If the server has died or stopped, the call
//! fails with [`ClientError::ServerGone`]; later calls reconnect by themselves
//! once a server serves the name again. A server started with persistence
//! (the default of `gjkd serve`) reloads every object whose registration it
//! acknowledged, with the same id, geometry, name, owner and latest stored
//! pose, so after a restart the same ids go on working and this `Client`
//! can still remove what it registered. A server started with
//! `--no-persist` starts empty: old ids then get
//! [`ErrorCode::UnknownObject`], never some other object. A registration
//! is the one call that retries by itself, safely (see [`Client::register`]):
//! a server restarted within its timeout answers it with the object it
//! stored, never a second one. Warm starts are
//! not kept across a restart (the first query of each pair is cold).
//!
//! ## Bad input
//!
//! Every field of every request is checked by the server; each bad value has
//! its own [`ErrorCode`] (the full table is in `docs/errors.md`), a bad item
//! fails alone while the rest of its batch is answered, and nothing a client
//! sends can make the server panic or lose an object.
//!
//! A `Client` is not `Send` (iceoryx2 ports are bound to their thread): create
//! one per thread. Each holds one iceoryx2 node and two client ports (three
//! after its first scene query).
//!
//! iceoryx2 runs with its built-in defaults when no config file exists, as
//! gjkd expects, and says so on stderr in every process. The first connect
//! sets iceoryx2's log level to errors only, unless `IOX2_LOG_LEVEL` is set
//! (`IOX2_LOG_LEVEL=warn` brings its warnings back) or the program set
//! another level through iceoryx2 before.

#![warn(missing_docs)]

mod open_failure;
mod robots;
mod scene;

pub use robots::{
    JointError, Kinematics, LimitMode, Mesh, MeshError, MeshMode, PackagePath, RegisteredMesh,
    RobotHandle, RobotModel,
};
pub use scene::{Contact, Group, ScenePair, SceneQuery, SceneSummary, Steps};

/// Where and how urgently the calling thread runs: pin the thread that
/// sends queries to a CPU of its own (`rt::pin_current_thread`) and, where
/// permitted, give it a real-time priority (`rt::set_realtime_priority`),
/// as `gjkd serve --cpu N --priority P` does for the server. Which to use
/// when, with measured figures: `docs/deployment.md`.
pub use gjkd_rt as rt;

use std::time::{Duration, Instant};

use iceoryx2::node::Node;
use iceoryx2::port::client::Client as IoxClient;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::{event, request_response};
use nalgebra::{Isometry3, Point3, Vector3};
use open_failure::{NameTakenBy, OpenFailure, name_taken_by};

use gjkd_proto::{
    AdminOp, AdminReply, AdminRequest, ReplyHeader, Vertex, admin_service_name, query_service_name,
    wake_service_name,
};
pub use gjkd_proto::{
    Answer, DEFAULT_MAX_ITERATIONS, DEFAULT_SERVICE, DEFAULT_TOLERANCE, ErrorCode, Geometry, Item,
    ItemKind, ItemResult, MAX_NAME_LEN, MAX_PIECES, ObjectId, PROTOCOL_VERSION, Piece, Pose,
    Precision, QueryOptions, SceneReply, SceneRequest, SceneRow, ServerInfo, ServerStats,
    ShapeError, Status, WaitMode, item_flags, result_flags, scene_flags, scene_reply_flags,
};

/// Timeout of every call unless set with [`ClientBuilder::timeout`]: one
/// second.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(1);

/// What can go wrong with a call.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ClientError {
    /// No server answers on this service: it was never started, it stopped,
    /// or it died. The next call tries to reconnect.
    #[error("no gjkd server is serving `{0}`")]
    ServerGone(String),
    /// The server is alive but did not answer within the timeout.
    #[error("no answer within {0:?}")]
    Timeout(Duration),
    /// The server refused the request (or, for single-item calls, the item):
    /// the code says why.
    #[error("request refused: {0}")]
    Rejected(ErrorCode),
    /// The result buffer of [`Client::query_batch`] is shorter than the batch.
    #[error("result buffer holds {got} results but the batch has {needed} items")]
    ResultBufferTooSmall {
        /// Items in the batch.
        needed: usize,
        /// Length of the buffer.
        got: usize,
    },
    /// An argument cannot be sent (a name too long, a compound nested in a
    /// compound, too many pieces).
    #[error("invalid argument: {0}")]
    InvalidArgument(&'static str),
    /// The server answered something this client does not understand
    /// (different protocol version or a broken server).
    #[error("protocol error: {0}")]
    Protocol(String),
    /// A server serves this name, but with another protocol version than
    /// this client's ([`PROTOCOL_VERSION`]):
    /// client and server come from different gjkd releases. Retrying does not
    /// help; use a client of the server's release, or start a server of
    /// this one's.
    #[error(
        "the server on `{service}` speaks protocol version {server}, this client speaks {client}"
    )]
    VersionMismatch {
        /// The service name asked for.
        service: String,
        /// The protocol version of the server found on that name.
        server: u32,
        /// This client's protocol version.
        client: u32,
    },
    /// A service of this name exists but cannot be opened by this client:
    /// it was made by another program, another build of gjkd (other message
    /// types or limits), or another iceoryx2 version. The cause names which.
    #[error("the service `{service}` is incompatible with this client: {cause}")]
    Incompatible {
        /// The iceoryx2 service that could not be opened.
        service: String,
        /// What iceoryx2 found different.
        cause: String,
    },
    /// The service belongs to another user and this process may not open
    /// it: run client and server as the same user, or see the README's
    /// "Access" section for sharing a server across users.
    #[error("no permission to open the service `{0}` (it belongs to another user)")]
    PermissionDenied(String),
    /// The server already has as many client processes as it admits.
    #[error("the service `{0}` admits no more clients")]
    TooManyClients(String),
    /// iceoryx2 failed locally (shared memory, permissions, limits).
    #[error("iceoryx2: {0}")]
    Ipc(String),
    /// A mesh, URDF or SRDF could not be loaded, or joint positions named
    /// a joint the robot does not move; the message says which and why.
    #[error("{0}")]
    Model(String),
}

/// iceoryx2 warns on stderr, in every process, that it found no config
/// file and uses its defaults, which is what gjkd wants. Unless the user
/// chose a level (the `IOX2_LOG_LEVEL` variable, or iceoryx2's
/// `set_log_level` to anything but its default before the first connect),
/// the client lets through iceoryx2's errors only.
fn quiet_iceoryx2_notices() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        if std::env::var_os("IOX2_LOG_LEVEL").is_none()
            && iceoryx2_log::get_log_level() == LogLevel::Info as u8
        {
            set_log_level(LogLevel::Error);
        }
    });
}

/// `Ok` for a reply header's [`ErrorCode::Ok`], the request's rejection
/// for another code, a protocol error for a value this version does not
/// know: how the query and scene services say a whole request failed.
fn reply_accepted(raw: u32) -> Result<(), ClientError> {
    match ErrorCode::from_raw(raw) {
        Some(ErrorCode::Ok) => Ok(()),
        Some(code) => Err(ClientError::Rejected(code)),
        None => Err(ClientError::Protocol(format!("unknown error code {raw}"))),
    }
}

fn ipc_err<E: std::fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> ClientError {
    move |e| ClientError::Ipc(format!("{what}: {e:?}"))
}

/// Configures and opens a [`Client`].
#[derive(Clone, Debug)]
pub struct ClientBuilder {
    service: String,
    timeout: Duration,
    connect_timeout: Option<Duration>,
}

impl ClientBuilder {
    /// Timeout of every call (default [`DEFAULT_TIMEOUT`]), and of
    /// [`ClientBuilder::connect`] unless [`ClientBuilder::connect_timeout`]
    /// is set.
    pub fn timeout(mut self, timeout: Duration) -> Self {
        self.timeout = timeout;
        self
    }

    /// How long [`ClientBuilder::connect`] waits for a server to come up
    /// (default: the call timeout). Useful when the server is started just
    /// before the client.
    pub fn connect_timeout(mut self, timeout: Duration) -> Self {
        self.connect_timeout = Some(timeout);
        self
    }

    /// Connects, waiting up to the connect timeout for a server to come up.
    ///
    /// # Errors
    /// [`ClientError::ServerGone`] if no server serves the name within the
    /// timeout; [`ClientError::VersionMismatch`],
    /// [`ClientError::Incompatible`], [`ClientError::PermissionDenied`] or
    /// [`ClientError::TooManyClients`] at once if a service of that name
    /// exists but this client cannot use it; [`ClientError::Ipc`] if
    /// iceoryx2 cannot set up this process.
    pub fn connect(self) -> Result<Client, ClientError> {
        quiet_iceoryx2_notices();
        let node = NodeBuilder::new()
            .name(&NodeName::new("gjkd-client").map_err(ipc_err("node name"))?)
            .create::<ipc::Service>()
            .map_err(ipc_err("node"))?;
        let mut client = Client {
            service: self.service,
            timeout: self.timeout,
            node,
            conn: None,
            vertex_scratch: Vec::new(),
            tokens: TokenSource::new(),
        };
        let deadline = Instant::now() + self.connect_timeout.unwrap_or(client.timeout);
        let mut first = true;
        loop {
            match client.reconnect(deadline, !first) {
                Ok(()) => return Ok(client),
                Err(ClientError::ServerGone(_)) if Instant::now() < deadline => {
                    first = false;
                    std::thread::sleep(Duration::from_millis(5));
                }
                Err(e) => return Err(e),
            }
        }
    }
}

type QueryPort = IoxClient<ipc::Service, [Item], (), [ItemResult], ReplyHeader>;
type AdminPort = IoxClient<ipc::Service, [Vertex], AdminRequest, AdminReply, ()>;

/// Open ports to one server incarnation.
struct Connection {
    // Ports are declared before their services so they are dropped first.
    /// The scene service, opened at the first scene query.
    scene: Option<scene::ScenePorts>,
    query: QueryPort,
    admin: AdminPort,
    wake: Notifier<ipc::Service>,
    query_service:
        request_response::PortFactory<ipc::Service, [Item], (), [ItemResult], ReplyHeader>,
    admin_service:
        request_response::PortFactory<ipc::Service, [Vertex], AdminRequest, AdminReply, ()>,
    _wake_service: event::PortFactory<ipc::Service>,
    info: ServerInfo,
    /// The admin server port that answered hello, once it has. A server that
    /// is killed and restarted before this client notices is a different
    /// port; this client's old ports may never hear from the new one, so
    /// that counts as the server being gone (and the next call reconnects).
    server: Option<u128>,
    notify_queries: bool,
}

impl Connection {
    /// A failed send means the server is gone if it is; otherwise it is
    /// iceoryx2's error.
    fn send_failed<E: std::fmt::Debug>(
        &self,
        node: &Node<ipc::Service>,
        what: &'static str,
        e: E,
    ) -> Waited {
        if self.server_alive(node) {
            Waited::Failed(ipc_err(what)(e))
        } else {
            Waited::Gone
        }
    }

    /// Whether the server this connection said hello to is still there,
    /// after removing what dead processes left behind (which takes up to a
    /// few milliseconds: keep it off the fast path).
    fn server_alive(&self, node: &Node<ipc::Service>) -> bool {
        node.try_cleanup_dead_nodes();
        if self.query_service.dynamic_config().number_of_servers() == 0 {
            return false;
        }
        let Some(id) = self.server else {
            return self.admin_service.dynamic_config().number_of_servers() > 0;
        };
        let mut found = false;
        self.admin_service.dynamic_config().list_servers(|d| {
            found = d.server_id.value() == id;
            if found {
                CallbackProgression::Stop
            } else {
                CallbackProgression::Continue
            }
        });
        found
    }
}

/// A connection to a gjkd server. See the [crate documentation](crate).
pub struct Client {
    // The connection holds ports of the node's services: drop it first.
    conn: Option<Connection>,
    node: Node<ipc::Service>,
    service: String,
    timeout: Duration,
    vertex_scratch: Vec<Vertex>,
    tokens: TokenSource,
}

/// Draws registration tokens: random (from the standard library's
/// randomly keyed hasher), never 0, never the same twice in a row.
struct TokenSource {
    keys: std::collections::hash_map::RandomState,
    count: u64,
}

impl TokenSource {
    fn new() -> Self {
        TokenSource {
            keys: std::collections::hash_map::RandomState::new(),
            count: 0,
        }
    }

    fn next(&mut self) -> u64 {
        use std::hash::{BuildHasher, Hasher};
        self.count += 1;
        let mut h = self.keys.build_hasher();
        h.write_u64(self.count);
        h.write_u32(std::process::id());
        h.finish().max(1)
    }
}

impl std::fmt::Debug for Client {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Client")
            .field("service", &self.service)
            .field("timeout", &self.timeout)
            .field("connected", &self.conn.is_some())
            .finish()
    }
}

/// After this long without an answer, the client starts checking that the
/// server is still alive (a killed server's requests are never answered and
/// iceoryx2 does not report its death by itself).
const LIVENESS_AFTER: Duration = Duration::from_millis(20);
/// How often it checks after that: a check cleans up dead nodes, which takes
/// up to a couple of milliseconds.
const LIVENESS_EVERY: Duration = Duration::from_millis(100);
/// Busy-poll this long for an answer before yielding the CPU: a spinning
/// server answers a query in a few microseconds.
const SPIN_FOR: Duration = Duration::from_micros(100);
/// Pause between two attempts of a registration while the server is gone.
const RETRY_PAUSE: Duration = Duration::from_millis(5);
/// Hello is repeated this often while connecting.
const HELLO_RETRY: Duration = Duration::from_millis(250);
/// Yield (rather than sleep) this long before sleeping between polls.
const YIELD_FOR: Duration = Duration::from_millis(2);

impl Client {
    /// A builder for a client of the deployment named `service` (the server's
    /// `--service`, default [`DEFAULT_SERVICE`]).
    pub fn builder(service: &str) -> ClientBuilder {
        ClientBuilder {
            service: service.to_owned(),
            timeout: DEFAULT_TIMEOUT,
            connect_timeout: None,
        }
    }

    /// Connects to the server of `service` with the default timeout, waiting
    /// up to that long for it to come up.
    ///
    /// # Errors
    /// As [`ClientBuilder::connect`].
    pub fn connect(service: &str) -> Result<Self, ClientError> {
        Self::builder(service).connect()
    }

    /// The service name.
    pub fn service(&self) -> &str {
        &self.service
    }

    /// The timeout of every call.
    pub fn timeout(&self) -> Duration {
        self.timeout
    }

    /// What the server said about itself when this client (re)connected:
    /// limits, wait strategy, pid. `None` while disconnected.
    pub fn server_info(&self) -> Option<ServerInfo> {
        self.conn.as_ref().map(|c| c.info)
    }

    /// Whether the client currently holds a connection (it may still find
    /// out at the next call that the server is gone).
    pub fn is_connected(&self) -> bool {
        self.conn.is_some()
    }

    fn gone(&self) -> ClientError {
        ClientError::ServerGone(self.service.clone())
    }

    /// The error for a service that could not be opened. A missing service
    /// is a server not (yet) there, unless a server of another protocol
    /// version serves the name: then waiting would never help.
    fn open_failed(&self, service: &str, cause: OpenFailure) -> ClientError {
        match cause {
            OpenFailure::Missing => {
                let (query, admin, wake) = (
                    query_service_name(&self.service),
                    admin_service_name(&self.service),
                    wake_service_name(&self.service),
                );
                let ours = [
                    (query.as_str(), false),
                    (admin.as_str(), false),
                    (wake.as_str(), true),
                ];
                match name_taken_by(&self.service, ours) {
                    Some(NameTakenBy::Version(server)) => ClientError::VersionMismatch {
                        service: self.service.clone(),
                        server,
                        client: gjkd_proto::PROTOCOL_VERSION,
                    },
                    Some(NameTakenBy::OtherPattern { name, pattern }) => {
                        ClientError::Incompatible {
                            service: name,
                            cause: format!(
                                "a {pattern} service, not gjkd's (another program uses the name?)"
                            ),
                        }
                    }
                    None => self.gone(),
                }
            }
            OpenFailure::Incompatible(cause) => ClientError::Incompatible {
                service: service.to_owned(),
                cause,
            },
            OpenFailure::Permission => ClientError::PermissionDenied(service.to_owned()),
            OpenFailure::Full => ClientError::TooManyClients(service.to_owned()),
            OpenFailure::Other(cause) => ClientError::Ipc(format!("open `{service}`: {cause}")),
        }
    }

    /// Opens the services and says hello. Drops any previous connection.
    /// `cleanup` first removes what dead processes left behind: a killed
    /// server's services linger until someone does, and a restarted server
    /// is then found at once. (Creating the node did it already, so the first
    /// attempt skips it: it scans every node on the host.)
    fn reconnect(&mut self, deadline: Instant, cleanup: bool) -> Result<(), ClientError> {
        self.conn = None;
        if cleanup {
            self.node.try_cleanup_dead_nodes();
        }
        let name = |s: String| ServiceName::new(&s).map_err(ipc_err("service name"));
        let query_service = self
            .node
            .service_builder(&name(query_service_name(&self.service))?)
            .request_response::<[Item], [ItemResult]>()
            .response_user_header::<ReplyHeader>()
            .open()
            .map_err(|e| self.open_failed(&query_service_name(&self.service), e.into()))?;
        let admin_service = self
            .node
            .service_builder(&name(admin_service_name(&self.service))?)
            .request_response::<[Vertex], AdminReply>()
            .request_user_header::<AdminRequest>()
            .open()
            .map_err(|e| self.open_failed(&admin_service_name(&self.service), e.into()))?;
        let wake_service = self
            .node
            .service_builder(&name(wake_service_name(&self.service))?)
            .event()
            .open()
            .map_err(|e| self.open_failed(&wake_service_name(&self.service), e.into()))?;
        if query_service.dynamic_config().number_of_servers() == 0
            || admin_service.dynamic_config().number_of_servers() == 0
        {
            return Err(self.gone());
        }
        let query = query_service
            .client_builder()
            .initial_max_slice_len(64)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(ipc_err("query client port"))?;
        let admin = admin_service
            .client_builder()
            .initial_max_slice_len(64)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(ipc_err("admin client port"))?;
        let wake = wake_service
            .notifier_builder()
            .create()
            .map_err(ipc_err("wake notifier"))?;
        self.conn = Some(Connection {
            scene: None,
            query,
            admin,
            wake,
            query_service,
            admin_service,
            _wake_service: wake_service,
            info: ServerInfo::default(),
            server: None,
            notify_queries: true,
        });
        // A request sent while a server is still setting up its ports may
        // never be answered; hello is harmless to repeat.
        let hello = AdminRequest::new(AdminOp::Hello);
        let (reply, server) = loop {
            let attempt = (Instant::now() + HELLO_RETRY).min(deadline);
            match self.admin_call(&hello, &[], attempt) {
                Ok(r) => break r,
                Err(ClientError::Timeout(_)) if Instant::now() < deadline => {}
                Err(e) => {
                    self.conn = None;
                    return Err(e);
                }
            }
        };
        if reply.info.protocol != gjkd_proto::PROTOCOL_VERSION {
            self.conn = None;
            return Err(ClientError::Protocol(format!(
                "server speaks protocol {}, this client {}",
                reply.info.protocol,
                gjkd_proto::PROTOCOL_VERSION
            )));
        }
        if let Some(conn) = &mut self.conn {
            conn.info = reply.info;
            conn.server = Some(server);
            // A spinning server needs no wake-up: skip the notify syscall.
            conn.notify_queries =
                WaitMode::from_raw(reply.info.wait).is_none_or(|m| m.needs_wake());
        }
        Ok(())
    }

    fn ensure_connected(&mut self, deadline: Instant) -> Result<(), ClientError> {
        if self.conn.is_none() {
            self.reconnect(deadline, true)?;
        }
        Ok(())
    }

    /// Waits for `poll` to produce an answer until `deadline`, checking now
    /// and then that a server is still there.
    fn await_reply<R>(
        node: &Node<ipc::Service>,
        conn: &Connection,
        deadline: Instant,
        timeout: Duration,
        mut poll: impl FnMut() -> Result<Option<R>, ClientError>,
    ) -> Result<R, Waited> {
        let start = Instant::now();
        let mut next_check = start + LIVENESS_AFTER;
        loop {
            match poll() {
                Ok(Some(r)) => return Ok(r),
                Ok(None) => {}
                Err(e) => return Err(Waited::Failed(e)),
            }
            let now = Instant::now();
            let waited = now - start;
            if now >= next_check || now >= deadline {
                if !conn.server_alive(node) {
                    return Err(Waited::Gone);
                }
                // The answer may have come while we were cleaning up.
                if let Ok(Some(r)) = poll() {
                    return Ok(r);
                }
                if Instant::now() >= deadline {
                    return Err(Waited::Failed(ClientError::Timeout(timeout)));
                }
                next_check = Instant::now() + LIVENESS_EVERY;
            }
            if waited < SPIN_FOR {
                // No yield while spinning: beside a busy process, a yield
                // hands it the CPU until its time slice ends, milliseconds
                // later; a server woken onto this CPU preempts the spin by
                // itself (it asks for short slices; docs/deployment.md).
                std::hint::spin_loop();
            } else if waited < YIELD_FOR {
                std::thread::yield_now();
            } else {
                std::thread::sleep(Duration::from_micros(200));
            }
        }
    }

    /// Turns the outcome of a call into the caller's result, dropping the
    /// connection when the server is gone so the next call reconnects.
    fn settle<R>(&mut self, outcome: Result<R, Waited>) -> Result<R, ClientError> {
        match outcome {
            Ok(r) => Ok(r),
            Err(Waited::Gone) => {
                self.conn = None;
                Err(self.gone())
            }
            Err(Waited::Failed(e)) => Err(e),
        }
    }

    /// One admin round trip; the reply and the id of the server port that
    /// sent it.
    fn admin_call(
        &mut self,
        request: &AdminRequest,
        vertices: &[Vertex],
        deadline: Instant,
    ) -> Result<(AdminReply, u128), ClientError> {
        let conn = self.conn.as_ref().ok_or_else(|| self.gone())?;
        let outcome = (|| {
            let mut loan = conn
                .admin
                .loan_slice_uninit(vertices.len())
                .map_err(|e| Waited::Failed(ipc_err("admin loan")(e)))?;
            *loan.user_header_mut() = *request;
            let pending = loan
                .write_from_slice(vertices)
                .send()
                .map_err(|e| conn.send_failed(&self.node, "admin send", e))?;
            // Admin requests are rare: always wake the server, whatever its
            // mode (it is not known before the first hello).
            let _ = conn.wake.notify();
            Self::await_reply(&self.node, conn, deadline, self.timeout, || {
                pending
                    .receive()
                    .map(|r| r.map(|r| (*r.payload(), r.header().server_id().value())))
                    .map_err(ipc_err("admin receive"))
            })
        })();
        let (reply, server) = self.settle(outcome)?;
        if reply.op != request.op {
            return Err(ClientError::Protocol(format!(
                "reply to operation {} answers operation {}",
                request.op, reply.op
            )));
        }
        Ok((reply, server))
    }

    fn admin(
        &mut self,
        request: &AdminRequest,
        vertices: &[Vertex],
    ) -> Result<AdminReply, ClientError> {
        self.admin_until(request, vertices, Instant::now() + self.timeout)
    }

    fn admin_until(
        &mut self,
        request: &AdminRequest,
        vertices: &[Vertex],
        deadline: Instant,
    ) -> Result<AdminReply, ClientError> {
        self.ensure_connected(deadline)?;
        let (reply, _) = self.admin_call(request, vertices, deadline)?;
        match reply.error_code() {
            ErrorCode::Ok => Ok(reply),
            code => Err(ClientError::Rejected(code)),
        }
    }

    /// Registers an object at the identity pose, without a name.
    ///
    /// # Errors
    /// - [`ClientError::InvalidArgument`], before anything is sent: a
    ///   negative half extent, a compound inside a compound, more than
    ///   [`MAX_PIECES`] pieces, more than `u32::MAX` vertices.
    /// - [`ClientError::Rejected`], and nothing is stored:
    ///   [`ErrorCode::EmptyVertices`], [`ErrorCode::InvalidRadius`] (negative,
    ///   NaN, infinite, or above 2^999, about 5e300),
    ///   [`ErrorCode::NonFiniteVertex`] (NaN, infinite, or the shape, its
    ///   vertices plus its radius, reaching beyond 2^999 from its body
    ///   origin),
    ///   [`ErrorCode::TooManyVertices`] (over the server's `--max-vertices`),
    ///   [`ErrorCode::EmptyCompound`], [`ErrorCode::TooManyPieces`],
    ///   [`ErrorCode::NonFinitePose`] or [`ErrorCode::BadQuaternion`] (a
    ///   piece offset), [`ErrorCode::TooManyObjects`] (the server's
    ///   `--max-objects`), [`ErrorCode::StorageFull`] (the server's disk
    ///   has no room to store the object; the same call succeeds once there
    ///   is room), [`ErrorCode::Internal`] (the store failed otherwise).
    /// - [`ClientError::ServerGone`] or [`ClientError::Timeout`], after
    ///   the retries below. **The registration may then have happened**:
    ///   the request may have reached the server and been stored before
    ///   the server died or the answer came too late, and no retry reached
    ///   a server within the timeout. An object registered under a name can be
    ///   found again with [`Client::lookup`]; an unnamed one cannot be named
    ///   by anyone, so register what must not be orphaned with a name.
    ///
    /// # Retries
    /// Each registration carries a random token. When the server turns out
    /// to be gone (it died, or was restarted), this call reconnects and
    /// sends the same registration again, with the same token, until its
    /// timeout has passed: a server that stored the object before it died
    /// answers the retry with that object's id (it keeps the tokens of each
    /// client's last 64 registrations with the objects, across restarts),
    /// so a retry never stores a second object. So a server restarted
    /// within the timeout costs no orphan. A [`ClientError::Timeout`] from
    /// a server that is alive is not retried (the deadline has passed). No
    /// other call retries by itself: a pose update or query that failed is
    /// simply sent again by the caller, and [`Client::remove`] retried
    /// after a lost reply answers [`ErrorCode::UnknownObject`] if the first
    /// attempt removed the object.
    pub fn register(&mut self, geometry: &Geometry<'_>) -> Result<ObjectId, ClientError> {
        self.register_with(geometry, None, &Isometry3::identity())
    }

    /// Registers an object with a unique `name` (so that other clients can
    /// [`lookup`](Client::lookup) it) and an initial pose.
    ///
    /// # Errors
    /// As [`Client::register`], plus [`ErrorCode::NameTaken`] and
    /// [`ClientError::InvalidArgument`] for a name over [`MAX_NAME_LEN`]
    /// bytes.
    pub fn register_named(
        &mut self,
        name: &str,
        geometry: &Geometry<'_>,
        pose: &Isometry3<f64>,
    ) -> Result<ObjectId, ClientError> {
        self.register_with(geometry, Some(name), pose)
    }

    fn register_with(
        &mut self,
        geometry: &Geometry<'_>,
        name: Option<&str>,
        pose: &Isometry3<f64>,
    ) -> Result<ObjectId, ClientError> {
        let mut request = AdminRequest::new(AdminOp::Register);
        request.pose = Pose::from_isometry(pose);
        if let Some(name) = name
            && !request.set_name(name)
        {
            return Err(ClientError::InvalidArgument(
                "name longer than MAX_NAME_LEN",
            ));
        }
        request.token = self.tokens.next();
        let mut vertices = std::mem::take(&mut self.vertex_scratch);
        vertices.clear();
        let built = Self::encode(geometry, &mut request, &mut vertices);
        let result = built.and_then(|()| self.register_retrying(&request, &vertices));
        self.vertex_scratch = vertices;
        result.map(|r| ObjectId::from_raw(r.id))
    }

    /// Sends a registration and, while the server is gone, sends it again
    /// with the same token (reconnecting) until the call's deadline: the
    /// server answers a repeated token with the object it stored, so this
    /// never registers twice.
    fn register_retrying(
        &mut self,
        request: &AdminRequest,
        vertices: &[Vertex],
    ) -> Result<AdminReply, ClientError> {
        let deadline = Instant::now() + self.timeout;
        loop {
            match self.admin_until(request, vertices, deadline) {
                Err(ClientError::ServerGone(_)) if Instant::now() + RETRY_PAUSE < deadline => {
                    std::thread::sleep(RETRY_PAUSE);
                }
                outcome => return outcome,
            }
        }
    }

    /// The wire form of `geometry` into `request` and `vertices`.
    fn encode(
        geometry: &Geometry<'_>,
        request: &mut AdminRequest,
        vertices: &mut Vec<Vertex>,
    ) -> Result<(), ClientError> {
        geometry
            .encode(request, vertices)
            .map_err(|e| ClientError::InvalidArgument(e.describe()))
    }

    /// Registers a ball of `radius` about the body origin.
    ///
    /// # Errors
    /// As [`Client::register`].
    pub fn register_sphere(&mut self, radius: f64) -> Result<ObjectId, ClientError> {
        self.register(&Geometry::Sphere { radius })
    }

    /// Registers the segment `a`–`b` grown by `radius`.
    ///
    /// # Errors
    /// As [`Client::register`].
    pub fn register_capsule(
        &mut self,
        a: Point3<f64>,
        b: Point3<f64>,
        radius: f64,
    ) -> Result<ObjectId, ClientError> {
        self.register(&Geometry::Capsule { a, b, radius })
    }

    /// Registers a box with these half extents, centred on the body origin,
    /// its edges rounded by `radius` (0 for a sharp box).
    ///
    /// # Errors
    /// As [`Client::register`].
    pub fn register_cuboid(
        &mut self,
        half_extents: Vector3<f64>,
        radius: f64,
    ) -> Result<ObjectId, ClientError> {
        self.register(&Geometry::Cuboid {
            half_extents,
            radius,
        })
    }

    /// Registers an exact cylinder about the body z axis, centred on the
    /// body origin, of `radius` and `half_height` (half its length), its
    /// edges rounded by `rounding` (0 for sharp rims): see
    /// [`Geometry::Cylinder`]. For a name and an initial pose, pass that
    /// geometry to [`Client::register_named`]; a compound takes cylinder
    /// pieces too.
    ///
    /// ```no_run
    /// use gjkd_client::{Client, Geometry, QueryOptions};
    /// use nalgebra::Isometry3;
    ///
    /// # fn main() -> Result<(), gjkd_client::ClientError> {
    /// let mut client = Client::connect("gjkd")?;
    /// let can = client.register_cylinder(0.5, 1.0, 0.0)?;
    /// let ball = client.register_named(
    ///     "ball", &Geometry::Sphere { radius: 0.25 }, &Isometry3::translation(2.0, 0.0, 0.3))?;
    /// // Beside the curved face: 2 - 0.5 - 0.25.
    /// let d = client.distance(can, ball, &QueryOptions::default())?.distance;
    /// assert!((d - 1.25).abs() < 1e-12);
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// # Errors
    /// As [`Client::register`]: [`ErrorCode::InvalidRadius`] for a
    /// negative, NaN or infinite radius, half-height or rounding (or a
    /// cylinder reaching beyond 2^999), and [`ErrorCode::Malformed`] from
    /// a server older than cylinders.
    pub fn register_cylinder(
        &mut self,
        radius: f64,
        half_height: f64,
        rounding: f64,
    ) -> Result<ObjectId, ClientError> {
        self.register(&Geometry::Cylinder {
            radius,
            half_height,
            rounding,
        })
    }

    /// Registers the convex hull of `vertices` grown by `radius`.
    ///
    /// # Errors
    /// As [`Client::register`].
    pub fn register_polytope(
        &mut self,
        vertices: &[Point3<f64>],
        radius: f64,
    ) -> Result<ObjectId, ClientError> {
        self.register(&Geometry::Polytope { vertices, radius })
    }

    /// Registers a union of convex pieces.
    ///
    /// ```no_run
    /// use gjkd_client::{Client, Geometry, Piece};
    /// use nalgebra::{Isometry3, Point3};
    ///
    /// # fn main() -> Result<(), gjkd_client::ClientError> {
    /// let mut client = Client::connect("gjkd")?;
    /// let ball = Geometry::Sphere { radius: 0.3 };
    /// let bar = Geometry::Capsule {
    ///     a: Point3::new(-1.0, 0.0, 0.0),
    ///     b: Point3::new(1.0, 0.0, 0.0),
    ///     radius: 0.05,
    /// };
    /// let dumbbell = client.register_compound(&[
    ///     Piece { offset: Isometry3::translation(-1.0, 0.0, 0.0), geometry: ball },
    ///     Piece { offset: Isometry3::identity(), geometry: bar },
    ///     Piece { offset: Isometry3::translation(1.0, 0.0, 0.0), geometry: ball },
    /// ])?;
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// # Errors
    /// As [`Client::register`], plus [`ErrorCode::EmptyCompound`] and
    /// [`ClientError::InvalidArgument`] for a nested compound or more than
    /// [`MAX_PIECES`] pieces.
    pub fn register_compound(&mut self, pieces: &[Piece<'_>]) -> Result<ObjectId, ClientError> {
        self.register(&Geometry::Compound(pieces))
    }

    /// Removes an object this client registered. Its id is never reused.
    ///
    /// # Errors
    /// [`ErrorCode::UnknownObject`], [`ErrorCode::NotOwner`] for another
    /// client's object, [`ErrorCode::ReadOnly`] for a scene object,
    /// [`ErrorCode::StorageFull`] when the server's disk has no room to
    /// store the removal (the object stays; the same call succeeds once
    /// there is room).
    pub fn remove(&mut self, id: ObjectId) -> Result<(), ClientError> {
        let mut request = AdminRequest::new(AdminOp::Remove);
        request.object = id.raw();
        self.admin(&request, &[]).map(|_| ())
    }

    /// The id of the object named `name` (scene objects, or objects
    /// registered with [`Client::register_named`]).
    ///
    /// # Errors
    /// [`ErrorCode::UnknownName`], [`ClientError::InvalidArgument`] for a name
    /// over [`MAX_NAME_LEN`] bytes.
    pub fn lookup(&mut self, name: &str) -> Result<ObjectId, ClientError> {
        let mut request = AdminRequest::new(AdminOp::Lookup);
        if !request.set_name(name) {
            return Err(ClientError::InvalidArgument(
                "name longer than MAX_NAME_LEN",
            ));
        }
        self.admin(&request, &[]).map(|r| ObjectId::from_raw(r.id))
    }

    /// The server's counters: objects, requests, warm-start cache use.
    ///
    /// # Errors
    /// The connection errors of every call.
    pub fn stats(&mut self) -> Result<ServerStats, ClientError> {
        self.admin(&AdminRequest::new(AdminOp::Stats), &[])
            .map(|r| r.stats)
    }

    /// Stores a new pose for `id`, used by every later query (of any client)
    /// that does not give its own.
    ///
    /// # Errors
    /// [`ErrorCode::UnknownObject`], [`ErrorCode::NonFinitePose`],
    /// [`ErrorCode::BadQuaternion`], and the connection errors.
    pub fn set_pose(&mut self, id: ObjectId, pose: &Isometry3<f64>) -> Result<(), ClientError> {
        self.single(Item::set_pose(id, pose)).map(|_| ())
    }

    /// Distance between `a` and `b` at their stored poses.
    ///
    /// # Errors
    /// [`ClientError::Rejected`] with [`ErrorCode::UnknownObject`] or
    /// [`ErrorCode::InvalidOptions`], and the connection errors.
    pub fn distance(
        &mut self,
        a: ObjectId,
        b: ObjectId,
        options: &QueryOptions,
    ) -> Result<Answer, ClientError> {
        self.single(Item::distance(a, b, options))
    }

    /// Distance between `a` at `pose_a` and `b` at `pose_b`; the stored poses
    /// are neither used nor changed.
    ///
    /// # Errors
    /// As [`Client::distance`], plus [`ErrorCode::NonFinitePose`] and
    /// [`ErrorCode::BadQuaternion`].
    pub fn distance_at(
        &mut self,
        a: ObjectId,
        pose_a: &Isometry3<f64>,
        b: ObjectId,
        pose_b: &Isometry3<f64>,
        options: &QueryOptions,
    ) -> Result<Answer, ClientError> {
        self.single(Item::distance_at(a, pose_a, b, pose_b, options))
    }

    fn single(&mut self, item: Item) -> Result<Answer, ClientError> {
        let mut out = [ItemResult::error(ErrorCode::Internal)];
        self.query_batch(&[item], &mut out)?;
        out[0].answer().map_err(ClientError::Rejected)
    }

    /// Sends `items` as one request and writes the answer to `items[i]` into
    /// `results[i]`. Items are applied in order, so a pose update affects the
    /// queries after it. Each result has its own error code (see
    /// [`ItemResult::answer`]); the call itself fails only if the whole
    /// request does. Allocates nothing of its own (iceoryx2 0.10 makes one
    /// small allocation per request for its loan bookkeeping).
    ///
    /// # Errors
    /// [`ClientError::ResultBufferTooSmall`];
    /// [`ClientError::Rejected`] with [`ErrorCode::EmptyBatch`] or
    /// [`ErrorCode::BatchTooLarge`] (more than [`ServerInfo::max_batch`]
    /// items); and the connection errors.
    pub fn query_batch(
        &mut self,
        items: &[Item],
        results: &mut [ItemResult],
    ) -> Result<(), ClientError> {
        if results.len() < items.len() {
            return Err(ClientError::ResultBufferTooSmall {
                needed: items.len(),
                got: results.len(),
            });
        }
        self.round_trip(
            items.len(),
            Source::<fn(usize) -> Item>::Slice(items),
            |payload| results[..payload.len()].copy_from_slice(payload),
        )
    }

    /// As [`Client::query_batch`], but the results are handed to `read`
    /// straight from the response's shared memory (`read` is called once,
    /// with `items.len()` results, if the request succeeds): for bindings
    /// that keep results in layouts of their own but can make their items
    /// as a slice first, which is copied into the request in one piece.
    ///
    /// # Errors
    /// As [`Client::query_batch`].
    pub fn query_batch_read(
        &mut self,
        items: &[Item],
        read: impl FnOnce(&[ItemResult]),
    ) -> Result<(), ClientError> {
        self.round_trip(items.len(), Source::<fn(usize) -> Item>::Slice(items), read)
    }

    /// As [`Client::query_batch`], but item `i` of the `count` items is
    /// made by `item(i)` and written straight into the request's shared
    /// memory, and the results are handed to `read` straight from the
    /// response's (`read` is called once, with `count` results, if the
    /// request succeeds). For bindings whose callers keep items and
    /// results in layouts of their own: neither needs a buffer in between.
    ///
    /// # Errors
    /// As [`Client::query_batch`].
    pub fn query_batch_with(
        &mut self,
        count: usize,
        item: impl FnMut(usize) -> Item,
        read: impl FnOnce(&[ItemResult]),
    ) -> Result<(), ClientError> {
        self.round_trip(count, Source::Fn(item), read)
    }

    /// Sends `count` items from `source` as one request and hands the
    /// results to `read`.
    fn round_trip<F: FnMut(usize) -> Item>(
        &mut self,
        count: usize,
        source: Source<'_, F>,
        read: impl FnOnce(&[ItemResult]),
    ) -> Result<(), ClientError> {
        let deadline = Instant::now() + self.timeout;
        self.ensure_connected(deadline)?;
        let conn = self.conn.as_ref().ok_or_else(|| self.gone())?;
        let mut read = Some(read);
        let outcome = (|| {
            if conn.query_service.dynamic_config().number_of_servers() == 0 {
                return Err(Waited::Gone);
            }
            let loan = conn
                .query
                .loan_slice_uninit(count)
                .map_err(|e| Waited::Failed(ipc_err("query loan")(e)))?;
            let request = match source {
                Source::Slice(items) => loan.write_from_slice(items),
                Source::Fn(item) => loan.write_from_fn(item),
            };
            let pending = request
                .send()
                .map_err(|e| conn.send_failed(&self.node, "query send", e))?;
            if conn.notify_queries {
                let _ = conn.wake.notify();
            }
            Self::await_reply(&self.node, conn, deadline, self.timeout, || {
                let Some(response) = pending.receive().map_err(ipc_err("query receive"))? else {
                    return Ok(None);
                };
                let header = *response.user_header();
                reply_accepted(header.error)?;
                let payload = response.payload();
                if payload.len() != count {
                    return Err(ClientError::Protocol(format!(
                        "{} results for {} items",
                        payload.len(),
                        count
                    )));
                }
                if let Some(read) = read.take() {
                    read(payload);
                }
                Ok(Some(()))
            })
        })();
        self.settle(outcome)
    }
}

/// Where the items of a request come from.
enum Source<'a, F> {
    /// A caller's slice, copied as it is.
    Slice(&'a [Item]),
    /// Made one by one into the request.
    Fn(F),
}

/// How waiting for an answer ended, short of an answer.
enum Waited {
    /// No server is left on the service.
    Gone,
    /// Anything else, reported as is.
    Failed(ClientError),
}

#[cfg(test)]
mod tests {
    use super::*;
    use gjkd_proto::{piece_kind, shape_kind};

    /// Vertices, radius and piece kind of a convex geometry's wire form.
    fn push_convex(g: &Geometry<'_>, v: &mut Vec<Vertex>) -> Result<(f64, u32), ClientError> {
        let mut req = AdminRequest::new(AdminOp::Register);
        Client::encode(g, &mut req, v)?;
        Ok((req.pieces[0].rounding, req.pieces[0].kind))
    }

    #[test]
    fn a_negative_half_extent_is_refused_before_sending() {
        for h in [
            Vector3::new(-1.0, 1.0, 1.0),
            Vector3::new(1.0, -0.0001, 1.0),
            Vector3::new(1.0, 1.0, -f64::MIN_POSITIVE),
        ] {
            let mut v = Vec::new();
            let g = Geometry::Cuboid {
                half_extents: h,
                radius: 0.0,
            };
            assert_eq!(
                push_convex(&g, &mut v),
                Err(ClientError::InvalidArgument("a half extent is negative")),
                "{h:?}"
            );
            assert!(v.is_empty(), "nothing encoded for {h:?}");
        }
        // Zero (a flat box) and -0.0 are documented as valid.
        let mut v = Vec::new();
        let flat = Geometry::Cuboid {
            half_extents: Vector3::new(1.0, 0.0, -0.0),
            radius: 0.0,
        };
        assert_eq!(push_convex(&flat, &mut v), Ok((0.0, piece_kind::HULL)));
    }

    #[test]
    fn cuboid_vertices_follow_gjk_order() {
        let mut v = Vec::new();
        let g = Geometry::Cuboid {
            half_extents: Vector3::new(1.0, 2.0, 3.0),
            radius: 0.0,
        };
        assert_eq!(push_convex(&g, &mut v), Ok((0.0, piece_kind::HULL)));
        assert_eq!(v.len(), 8);
        assert_eq!(
            v[0],
            Vertex {
                x: -1.0,
                y: -2.0,
                z: -3.0
            }
        );
        assert_eq!(
            v[5],
            Vertex {
                x: 1.0,
                y: -2.0,
                z: 3.0
            }
        );
    }

    #[test]
    fn compounds_encode_their_piece_table() {
        let pts = [Point3::new(1.0, 0.0, 0.0), Point3::new(0.0, 1.0, 0.0)];
        let pieces = [
            Piece {
                offset: Isometry3::translation(1.0, 0.0, 0.0),
                geometry: Geometry::Sphere { radius: 0.5 },
            },
            Piece {
                offset: Isometry3::identity(),
                geometry: Geometry::Polytope {
                    vertices: &pts,
                    radius: 0.1,
                },
            },
        ];
        let mut req = AdminRequest::new(AdminOp::Register);
        let mut v = Vec::new();
        Client::encode(&Geometry::Compound(&pieces), &mut req, &mut v).expect("valid");
        assert_eq!(req.shape, shape_kind::COMPOUND);
        assert_eq!(req.piece_count, 2);
        assert_eq!(req.pieces[0].vertex_count, 1);
        assert_eq!(req.pieces[1].vertex_count, 2);
        assert_eq!(req.pieces[1].rounding, 0.1);
        assert_eq!(req.pieces[0].offset.translation, [1.0, 0.0, 0.0]);
        assert_eq!(v.len(), 3);

        let nested = [Piece {
            offset: Isometry3::identity(),
            geometry: Geometry::Compound(&pieces),
        }];
        assert!(matches!(
            Client::encode(&Geometry::Compound(&nested), &mut req, &mut v),
            Err(ClientError::InvalidArgument(_))
        ));
    }

    #[test]
    fn cylinders_travel_with_named_dimensions() {
        let can = Geometry::Cylinder {
            radius: 0.5,
            half_height: 2.0,
            rounding: 0.125,
        };
        let mut req = AdminRequest::new(AdminOp::Register);
        let mut v = Vec::new();
        Client::encode(&can, &mut req, &mut v).expect("valid");
        assert_eq!((req.shape, req.piece_count), (shape_kind::CONVEX, 1));
        let desc = req.pieces[0];
        assert_eq!((desc.kind, desc.vertex_count), (piece_kind::CYLINDER, 0));
        assert_eq!(desc.rounding, 0.125);
        assert_eq!((desc.cylinder_radius, desc.half_height), (0.5, 2.0));
        assert!(v.is_empty(), "a cylinder sends no vertices");

        let pieces = [
            Piece {
                offset: Isometry3::translation(0.0, 0.0, 1.0),
                geometry: Geometry::Sphere { radius: 0.5 },
            },
            Piece {
                offset: Isometry3::identity(),
                geometry: can,
            },
        ];
        let mut v = Vec::new();
        Client::encode(&Geometry::Compound(&pieces), &mut req, &mut v).expect("valid");
        assert_eq!(req.pieces[0].kind, piece_kind::HULL);
        assert_eq!(req.pieces[1].kind, piece_kind::CYLINDER);
        assert_eq!(v.len(), 1);

        // A gjk cylinder maps back to the same geometry, a polytope to its
        // vertices.
        let c = gjk::Convex::cylinder(0.5, 2.0, 0.125).expect("valid");
        assert_eq!(Geometry::of_convex(&c), can);
        let b = gjk::Convex::sphere(0.3).expect("valid");
        assert!(matches!(
            Geometry::of_convex(&b),
            Geometry::Polytope { vertices, radius } if vertices.len() == 1 && radius == 0.3
        ));
    }
}
