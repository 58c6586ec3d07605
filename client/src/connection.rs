//! One connection to a server: the ports of one server incarnation, the
//! round trip of an admin request, waiting for answers, noticing a server
//! that went away and reconnecting.

use std::time::{Duration, Instant};

use iceoryx2::node::Node;
use iceoryx2::port::client::Client as IoxClient;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::{event, request_response};

use crate::open_failure::{NameTakenBy, OpenFailure, name_taken_by};
use crate::path_split::{RequestLimits, SplitScratch};
use crate::{ClientError, ipc_err, scene};
use gjkd_proto::{
    AdminChunk, AdminOp, AdminReply, AdminRequest, ErrorCode, Item, ReplyEntry, ReplyHeader,
    ServerInfo, Vertex, WaitMode, admin_service_name, query_service_name, wake_service_name,
};

type QueryPort = IoxClient<ipc::Service, [Item], (), [ReplyEntry], ReplyHeader>;
type AdminPort = IoxClient<ipc::Service, [AdminChunk], AdminRequest, AdminReply, ()>;

/// Open ports to one server incarnation.
pub(crate) struct Connection {
    // Ports are declared before their services so they are dropped first.
    /// The scene service, opened at the first scene query.
    pub(crate) scene: Option<scene::ScenePorts>,
    /// The pose service, opened at the first pose read-back.
    pub(crate) poses: Option<crate::poses::PosesPorts>,
    pub(crate) query: QueryPort,
    pub(crate) admin: AdminPort,
    pub(crate) wake: Notifier<ipc::Service>,
    pub(crate) query_service:
        request_response::PortFactory<ipc::Service, [Item], (), [ReplyEntry], ReplyHeader>,
    pub(crate) admin_service:
        request_response::PortFactory<ipc::Service, [AdminChunk], AdminRequest, AdminReply, ()>,
    pub(crate) _wake_service: event::PortFactory<ipc::Service>,
    pub(crate) info: ServerInfo,
    /// The admin server port that answered hello, once it has. A server that
    /// is killed and restarted before this client notices is a different
    /// port; this client's old ports may never hear from the new one, so
    /// that counts as the server being gone (and the next call reconnects).
    pub(crate) server: Option<u128>,
    pub(crate) notify_queries: bool,
}

impl Connection {
    /// A failed send means the server is gone if it is; otherwise it is
    /// iceoryx2's error.
    pub(crate) fn send_failed<E: std::fmt::Debug>(
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
    pub(crate) fn server_alive(&self, node: &Node<ipc::Service>) -> bool {
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
    pub(crate) conn: Option<Connection>,
    pub(crate) node: Node<ipc::Service>,
    pub(crate) service: String,
    pub(crate) timeout: Duration,
    pub(crate) vertex_scratch: Vec<Vertex>,
    pub(crate) tokens: TokenSource,
    pub(crate) split_scratch: SplitScratch,
    /// What ends with this client ([`crate::ClientBuilder::remove_on_close`]).
    pub(crate) ending: crate::ending::EndWithClient,
}

/// Draws registration tokens: random (from the standard library's
/// randomly keyed hasher), never 0, never the same twice in a row.
pub(crate) struct TokenSource {
    keys: std::collections::hash_map::RandomState,
    count: u64,
}

impl TokenSource {
    pub(crate) fn new() -> Self {
        TokenSource {
            keys: std::collections::hash_map::RandomState::new(),
            count: 0,
        }
    }

    pub(crate) fn next(&mut self) -> u64 {
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
pub(crate) const RETRY_PAUSE: Duration = Duration::from_millis(5);
/// Hello is repeated this often while connecting.
const HELLO_RETRY: Duration = Duration::from_millis(250);
/// Yield (rather than sleep) this long before sleeping between polls.
const YIELD_FOR: Duration = Duration::from_millis(2);

impl Client {
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

    /// The item and row limits of one request, from the server's hello.
    pub(crate) fn request_limits(&self) -> Option<RequestLimits> {
        self.conn.as_ref().map(|c| RequestLimits {
            items: c.info.max_batch as usize,
            rows: usize::try_from(c.info.max_rows).unwrap_or(usize::MAX),
        })
    }

    /// Whether the client currently holds a connection (it may still find
    /// out at the next call that the server is gone).
    pub fn is_connected(&self) -> bool {
        self.conn.is_some()
    }

    pub(crate) fn gone(&self) -> ClientError {
        ClientError::ServerGone(self.service.clone())
    }

    /// The error for a service opened on first use (scene questions, pose
    /// read-back) that could not be opened: this client is connected, so a
    /// missing one is a server of a release without `feature`, the rest as
    /// [`Self::open_failed`]. `kind` names the service in the message.
    pub(crate) fn later_service_failed(
        &self,
        service: &str,
        kind: &str,
        feature: &str,
        error: iceoryx2::service::builder::request_response::RequestResponseOpenError,
    ) -> ClientError {
        match OpenFailure::from(error) {
            OpenFailure::Missing => ClientError::Protocol(format!(
                "the server has no {kind} service (a release older than {feature})"
            )),
            cause => self.open_failed(service, cause),
        }
    }

    /// The error for a service that could not be opened. A missing service
    /// is a server not (yet) there, unless a server of another protocol
    /// version serves the name: then waiting would never help.
    pub(crate) fn open_failed(&self, service: &str, cause: OpenFailure) -> ClientError {
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
    pub(crate) fn reconnect(
        &mut self,
        deadline: Instant,
        cleanup: bool,
    ) -> Result<(), ClientError> {
        self.conn = None;
        if cleanup {
            self.node.try_cleanup_dead_nodes();
        }
        let name = |s: String| ServiceName::new(&s).map_err(ipc_err("service name"));
        let query_service = self
            .node
            .service_builder(&name(query_service_name(&self.service))?)
            .request_response::<[Item], [ReplyEntry]>()
            .response_user_header::<ReplyHeader>()
            .open()
            .map_err(|e| self.open_failed(&query_service_name(&self.service), e.into()))?;
        let admin_service = self
            .node
            .service_builder(&name(admin_service_name(&self.service))?)
            .request_response::<[AdminChunk], AdminReply>()
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
            poses: None,
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

    pub(crate) fn ensure_connected(&mut self, deadline: Instant) -> Result<(), ClientError> {
        if self.conn.is_none() {
            self.reconnect(deadline, true)?;
        }
        Ok(())
    }

    /// Waits for `poll` to produce an answer until `deadline`, checking now
    /// and then that a server is still there.
    pub(crate) fn await_reply<R>(
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
    pub(crate) fn settle<R>(&mut self, outcome: Result<R, Waited>) -> Result<R, ClientError> {
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
    pub(crate) fn admin_call(
        &mut self,
        request: &AdminRequest,
        payload: &[AdminChunk],
        deadline: Instant,
    ) -> Result<(AdminReply, u128), ClientError> {
        let conn = self.conn.as_ref().ok_or_else(|| self.gone())?;
        let outcome = (|| {
            let mut loan = conn
                .admin
                .loan_slice_uninit(payload.len())
                .map_err(|e| Waited::Failed(ipc_err("admin loan")(e)))?;
            *loan.user_header_mut() = *request;
            let pending = loan
                .write_from_slice(payload)
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

    pub(crate) fn admin(
        &mut self,
        request: &AdminRequest,
        payload: &[AdminChunk],
    ) -> Result<AdminReply, ClientError> {
        self.admin_until(request, payload, Instant::now() + self.timeout)
    }

    pub(crate) fn admin_until(
        &mut self,
        request: &AdminRequest,
        payload: &[AdminChunk],
        deadline: Instant,
    ) -> Result<AdminReply, ClientError> {
        self.ensure_connected(deadline)?;
        let (reply, _) = self.admin_call(request, payload, deadline)?;
        match reply.error_code() {
            ErrorCode::Ok => Ok(reply),
            code => Err(ClientError::Rejected(code)),
        }
    }
}

/// How waiting for an answer ended, short of an answer.
pub(crate) enum Waited {
    /// No server is left on the service.
    Gone,
    /// Anything else, reported as is.
    Failed(ClientError),
}
