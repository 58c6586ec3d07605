//! The iceoryx2 side of the server: services, ports, the wait loop.
//!
//! One thread answers everything. iceoryx2's `ipc::Service` ports are not
//! `Send`, and one thread that owns the whole [`State`] needs no locks: a query
//! is a few microseconds, far below what a lock hand-off would cost.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use gjkd_proto::{
    AdminChunk, AdminOp, AdminReply, AdminRequest, ErrorCode, Item, ItemResult, PosesReply,
    ReplyEntry, ReplyHeader, SceneReply, SceneRequest, SceneRow, StoredPose, WaitMode,
    admin_service_name, poses_service_name, query_service_name, scene_service_name,
    wake_service_name,
};
use iceoryx2::active_request::ActiveRequest;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::server::Server as IoxServer;
use iceoryx2::prelude::*;
use iceoryx2::service::builder::request_response::Builder as RequestResponseBuilder;
use tracing::{debug, error, info, warn};

use crate::engine::{Limits, State};
use crate::wait::{Idle, WaitPolicy};

type QueryServer = IoxServer<ipc::Service, [Item], (), [ReplyEntry], ReplyHeader>;
type AdminServer = IoxServer<ipc::Service, [AdminChunk], AdminRequest, AdminReply, ()>;
type PosesServer = IoxServer<ipc::Service, [u64], (), [StoredPose], PosesReply>;
type PosesService = iceoryx2::service::port_factory::request_response::PortFactory<
    ipc::Service,
    [u64],
    (),
    [StoredPose],
    PosesReply,
>;
type SceneServer = IoxServer<ipc::Service, [Item], SceneRequest, [SceneRow], SceneReply>;
type SceneService = iceoryx2::service::port_factory::request_response::PortFactory<
    ipc::Service,
    [Item],
    SceneRequest,
    [SceneRow],
    SceneReply,
>;
type QueryService = iceoryx2::service::port_factory::request_response::PortFactory<
    ipc::Service,
    [Item],
    (),
    [ReplyEntry],
    ReplyHeader,
>;
type AdminService = iceoryx2::service::port_factory::request_response::PortFactory<
    ipc::Service,
    [AdminChunk],
    AdminRequest,
    AdminReply,
    (),
>;

/// Why the server could not start or stopped.
#[derive(Debug, thiserror::Error)]
pub enum ServerError {
    /// The service name is not a valid iceoryx2 service name.
    #[error("invalid service name `{0}`")]
    InvalidName(String),
    /// iceoryx2 refused to create or open something.
    #[error("iceoryx2: {0}")]
    Ipc(String),
    /// Another server already serves this service.
    #[error("another gjkd server already serves `{0}`")]
    AlreadyRunning(String),
}

/// The error of creating a server port on a service of `service`: a
/// second server of the same service is [`ServerError::AlreadyRunning`].
fn server_port_error<'a>(
    service: &'a str,
    what: &'static str,
) -> impl FnOnce(iceoryx2::service::port_factory::server::ServerCreateError) -> ServerError + 'a {
    move |e| match e {
        iceoryx2::service::port_factory::server::ServerCreateError::ExceedsMaxSupportedServers => {
            ServerError::AlreadyRunning(service.to_owned())
        }
        e => ServerError::Ipc(format!("{what}: {e:?}")),
    }
}

fn ipc<E: std::fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> ServerError {
    move |e| ServerError::Ipc(format!("{what}: {e:?}"))
}

/// Longest sleep in `block` mode: the loop wakes this often to look at the
/// shutdown flag (signal handlers cannot wake an iceoryx2 wait) and do
/// housekeeping.
const BLOCK_SLICE: Duration = Duration::from_millis(50);

/// Dead clients are looked for at most this often, and only when the server
/// has been idle for [`IDLE_BEFORE_HOUSEKEEPING`]: cleaning up takes
/// milliseconds that must not land in the middle of a burst of queries.
const HOUSEKEEPING_PERIOD: Duration = Duration::from_secs(2);
const IDLE_BEFORE_HOUSEKEEPING: Duration = Duration::from_millis(20);
/// A server that is never idle still looks for dead clients this often, or
/// the state of a client killed while others keep it busy would never be
/// freed.
const HOUSEKEEPING_FORCED: Duration = Duration::from_secs(5);
/// After a removal of departed clients' objects could not be committed, how
/// long before the next attempt.
const REAP_BACKOFF: Duration = Duration::from_secs(60);

/// In spin mode, the admin service is polled once per this many idle loop
/// turns: each poll scans every connected client, and registrations are rare.
const ADMIN_POLL_EVERY: u32 = 64;

/// Most requests a client may have in flight on one service.
const ACTIVE_REQUESTS_PER_CLIENT: usize = 2;

/// The settings every request-response service of a deployment shares: one
/// server (this one), `limits`' clients and nodes, a request at a time in
/// flight per client and answered once, no request without an answer.
fn one_server<Request, RequestHeader, Response, ResponseHeader>(
    builder: RequestResponseBuilder<Request, RequestHeader, Response, ResponseHeader, ipc::Service>,
    limits: &Limits,
) -> RequestResponseBuilder<Request, RequestHeader, Response, ResponseHeader, ipc::Service>
where
    Request: std::fmt::Debug + IceoryxSend + ?Sized,
    RequestHeader: std::fmt::Debug + ZeroCopySend,
    Response: std::fmt::Debug + IceoryxSend + ?Sized,
    ResponseHeader: std::fmt::Debug + ZeroCopySend,
{
    builder
        .max_clients(limits.max_clients)
        .max_servers(1)
        .max_nodes(limits.max_nodes)
        .max_active_requests_per_client(ACTIVE_REQUESTS_PER_CLIENT)
        .max_response_buffer_size(2)
        .max_borrowed_responses_per_pending_response(1)
        .enable_fire_and_forget_requests(false)
}

/// Response chunks the query and scene servers preallocate for `clients`
/// clients.
pub fn response_chunks(clients: usize) -> usize {
    clients
        .saturating_mul(ACTIVE_REQUESTS_PER_CLIENT)
        .saturating_mul(2)
        .saturating_add(16)
}

/// Everything needed to start a server.
#[derive(Clone, Debug)]
pub struct ServeOptions {
    /// Deployment name; the services are `{service}/v4/...`.
    pub service: String,
    /// Wait strategy.
    pub wait: WaitMode,
    /// Remove, while serving, the objects of clients whose process has
    /// ended (checked at housekeeping, as `gjkd objects --remove-departed`
    /// does offline). Off, they stay until the operator removes them.
    pub remove_departed: bool,
}

/// The iceoryx2 side of a running server. Fields drop in declaration
/// order: ports first, then services, then the node, the reverse of their
/// creation, which removes the services' shared memory.
struct Endpoints {
    query: QueryServer,
    scene: SceneServer,
    poses: PosesServer,
    admin: AdminServer,
    listener: Listener<ipc::Service>,
    _wake_service: iceoryx2::service::port_factory::event::PortFactory<ipc::Service>,
    admin_service: AdminService,
    scene_service: SceneService,
    poses_service: PosesService,
    query_service: QueryService,
    node: Node<ipc::Service>,
}

/// Creates the node, the services and the ports of a server for
/// `options.service`, sized by `limits`.
fn open_endpoints(options: &ServeOptions, limits: &Limits) -> Result<Endpoints, ServerError> {
    let name = |s: String| {
        ServiceName::new(&s).map_err(|_| ServerError::InvalidName(options.service.clone()))
    };
    let query_name = name(query_service_name(&options.service))?;
    let admin_name = name(admin_service_name(&options.service))?;
    let scene_name = name(scene_service_name(&options.service))?;
    let wake_name = name(wake_service_name(&options.service))?;
    let poses_name = name(poses_service_name(&options.service))?;

    let node = NodeBuilder::new()
        .name(&NodeName::new("gjkd").map_err(ipc("node name"))?)
        // Signals are handled by the caller's flag: iceoryx2 only looks at
        // them inside its own waits, and a spinning server never waits.
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(ipc("node"))?;
    // A server killed with -9 leaves its port registered; clearing dead nodes
    // first lets a restarted server take its place.
    let cleaned = node.try_cleanup_dead_nodes();
    if cleaned.cleanups > 0 {
        info!(
            count = cleaned.cleanups,
            "cleaned up resources of dead processes"
        );
    }

    let clients = limits.max_clients;
    let query_service = one_server(
        node.service_builder(&query_name)
            .request_response::<[Item], [ReplyEntry]>()
            .response_user_header::<ReplyHeader>(),
        limits,
    )
    .open_or_create()
    .map_err(ipc("query service"))?;
    let admin_service = one_server(
        node.service_builder(&admin_name)
            .request_response::<[AdminChunk], AdminReply>()
            .request_user_header::<AdminRequest>(),
        limits,
    )
    .open_or_create()
    .map_err(ipc("admin service"))?;
    let scene_service = one_server(
        node.service_builder(&scene_name)
            .request_response::<[Item], [SceneRow]>()
            .request_user_header::<SceneRequest>()
            .response_user_header::<SceneReply>(),
        limits,
    )
    .open_or_create()
    .map_err(ipc("scene service"))?;
    let poses_service = one_server(
        node.service_builder(&poses_name)
            .request_response::<[u64], [StoredPose]>()
            .response_user_header::<PosesReply>(),
        limits,
    )
    .open_or_create()
    .map_err(ipc("poses service"))?;
    let wake_service = node
        .service_builder(&wake_name)
        .event()
        .max_notifiers(clients)
        .max_listeners(2)
        .max_nodes(limits.max_nodes)
        .open_or_create()
        .map_err(ipc("wake service"))?;

    let listener = wake_service
        .listener_builder()
        .create()
        .map_err(ipc("wake listener"))?;
    let admin: AdminServer = admin_service
        .server_builder()
        .create()
        .map_err(server_port_error(&options.service, "admin server"))?;
    // Sized as the query server (below), for `max_rows` rows a reply.
    let scene: SceneServer = scene_service
        .server_builder()
        .initial_max_slice_len(limits.max_rows)
        .allocation_strategy(AllocationStrategy::Static)
        .override_response_preallocation(move |_| response_chunks(clients))
        .create()
        .map_err(server_port_error(&options.service, "scene server"))?;
    // Sized as the query server, for `max_batch` poses a reply.
    let poses: PosesServer = poses_service
        .server_builder()
        .initial_max_slice_len(limits.max_batch)
        .allocation_strategy(AllocationStrategy::Static)
        .override_response_preallocation(move |_| response_chunks(clients))
        .create()
        .map_err(server_port_error(&options.service, "poses server"))?;
    // The query server port comes last: clients take it as the sign that
    // the server is ready, and a request sent to a service before its server
    // port exists is never answered.
    let query: QueryServer = query_service
        .server_builder()
        // A static segment: a growing one makes iceoryx2 size every client's
        // connection for all the segments it might grow into, which makes
        // connecting slow (hundreds of ms for 128 clients in a debug build).
        // Room for `max_batch` results and as many gradients.
        .initial_max_slice_len(limits.max_batch.saturating_mul(2))
        .allocation_strategy(AllocationStrategy::Static)
        // iceoryx2 reserves for streams of responses per request; gjkd sends
        // exactly one, so each client needs one chunk per active request, and
        // as many again for replies to requests it gave up on.
        .override_response_preallocation(move |_| response_chunks(clients))
        .create()
        .map_err(server_port_error(&options.service, "query server"))?;

    Ok(Endpoints {
        query,
        scene,
        poses,
        admin,
        listener,
        _wake_service: wake_service,
        admin_service,
        scene_service,
        poses_service,
        query_service,
        node,
    })
}

/// Runs a server until `shutdown` becomes true, then removes its services and
/// returns. `state` comes filled (scene objects) and its limits size the
/// services.
///
/// # Errors
/// [`ServerError`] when the services or ports cannot be set up; once running,
/// errors of single requests are logged and the loop goes on.
pub fn run(
    options: &ServeOptions,
    mut state: State,
    shutdown: &AtomicBool,
    ready: impl FnOnce(),
) -> Result<(), ServerError> {
    let limits = *state.limits();
    let endpoints = open_endpoints(options, &limits)?;
    let waitset = WaitSetBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(ipc("waitset"))?;
    let _guard = waitset
        .attach_notification(&endpoints.listener)
        .map_err(ipc("waitset attach"))?;
    info!(
        service = %options.service,
        wait = ?options.wait,
        max_clients = limits.max_clients,
        max_nodes = limits.max_nodes,
        max_batch = limits.max_batch,
        max_vertices = limits.max_vertices,
        cache_capacity = limits.cache_capacity,
        objects = state.len(),
        "gjkd serving"
    );
    ready();
    serve_until(options, &mut state, &endpoints, &waitset, shutdown);
    info!(service = %options.service, "shutting down");
    if let Err(e) = state.flush() {
        error!("cannot sync the pose journal: {e}");
    }
    // The current poses into the database, so that the next start needs
    // no journal; if it fails, nothing is lost: the journal has them.
    if let Err(e) = state.persist() {
        error!("cannot write the current poses into the database: {e}");
    }
    Ok(())
}

/// When housekeeping last ran and when removing departed clients' objects
/// may be tried again.
struct Housekeeping {
    last: Instant,
    reap_after: Instant,
}

/// The serving loop: answers requests, sleeps or spins as `options.wait`
/// says, and keeps house when idle, until `shutdown` becomes true.
fn serve_until(
    options: &ServeOptions,
    state: &mut State,
    endpoints: &Endpoints,
    waitset: &WaitSet<ipc::Service>,
    shutdown: &AtomicBool,
) {
    let mut wait = WaitPolicy::new(options.wait, Instant::now());
    let mut house = Housekeeping {
        last: Instant::now(),
        reap_after: Instant::now(),
    };
    let mut turns: u32 = 0;
    let mut scene_rows = Vec::new();
    while !shutdown.load(Ordering::Relaxed) {
        turns = turns.wrapping_add(1);
        let mut served = serve_queries(&endpoints.query, state);
        // Looked at only while a scene client is connected (an atomic load):
        // receiving takes a lock, which servers whose clients never ask a
        // scene question should not pay on every turn.
        if endpoints.scene_service.dynamic_config().number_of_clients() > 0 {
            served += serve_scenes(&endpoints.scene, state, &mut scene_rows);
        }
        // Likewise: poses are read back rarely, and only by some clients.
        if endpoints.poses_service.dynamic_config().number_of_clients() > 0 {
            served += serve_poses(&endpoints.poses, state);
        }
        // Counted over all turns, busy or not, so that a stream of queries
        // cannot starve registrations.
        if options.wait != WaitMode::Spin || turns.is_multiple_of(ADMIN_POLL_EVERY) {
            served += serve_admin(&endpoints.admin, &endpoints.admin_service, state);
        }
        let now = Instant::now();
        if served > 0 {
            wait.served(now);
        }
        let since = now.duration_since(house.last);
        if (now.duration_since(wait.last_request()) > IDLE_BEFORE_HOUSEKEEPING
            && since > HOUSEKEEPING_PERIOD)
            || since > HOUSEKEEPING_FORCED
        {
            keep_house(options, state, endpoints, &mut house, now);
        }
        if served > 0 {
            continue;
        }
        wait_step(&mut wait, now, waitset, endpoints);
    }
}

/// What the loop does on a turn that found no request, as the wait policy
/// says: sleeps until a client notifies, or spins, never yielding (see
/// [`crate::wait`] for why).
fn wait_step(
    wait: &mut WaitPolicy,
    now: Instant,
    waitset: &WaitSet<ipc::Service>,
    endpoints: &Endpoints,
) {
    match wait.idle(now) {
        Idle::Sleep => {
            block(waitset, endpoints);
            wait.woke(Instant::now());
        }
        Idle::Spin => std::hint::spin_loop(),
    }
}

/// Cleans up after dead processes, forgets departed clients (and, when
/// asked for, removes their objects), and puts the pose journal on disk.
fn keep_house(
    options: &ServeOptions,
    state: &mut State,
    endpoints: &Endpoints,
    house: &mut Housekeeping,
    now: Instant,
) {
    house.last = now;
    let cleaned = endpoints.node.try_cleanup_dead_nodes();
    if cleaned.cleanups > 0 {
        info!(
            count = cleaned.cleanups,
            "cleaned up resources of dead clients"
        );
    }
    // Always compared with the live list, not the count: a client that died
    // while another connected leaves the count unchanged.
    forget_departed_clients(endpoints, state);
    // A store that cannot be written is not retried at every housekeeping.
    if options.remove_departed && now >= house.reap_after && !remove_departed_objects(state) {
        house.reap_after = now + REAP_BACKOFF;
    }
    state.set_clients(endpoints.query_service.dynamic_config().number_of_clients());
    if let Err(e) = state.flush() {
        error!("cannot sync the pose journal: {e}");
    }
}

/// Drops the warm starts of query and scene clients that are no longer
/// connected (each port keys its own warm starts).
fn forget_departed_clients(endpoints: &Endpoints, state: &mut State) {
    let mut alive = std::collections::HashSet::new();
    let mut insert = |id: u128| {
        alive.insert(id);
        CallbackProgression::Continue
    };
    endpoints
        .query_service
        .dynamic_config()
        .list_clients(|c| insert(c.client_id.value()));
    endpoints
        .scene_service
        .dynamic_config()
        .list_clients(|c| insert(c.client_id.value()));
    let before = state.stats().cache_entries;
    state.retain_clients(|c| alive.contains(&c));
    let dropped = before - state.stats().cache_entries;
    if dropped > 0 {
        debug!(dropped, "forgot warm starts of departed clients");
    }
}

/// Removes the objects of clients whose iceoryx2 node no longer runs. A
/// node whose state cannot be read counts as running, and when the nodes
/// cannot be listed at all nothing is removed. False when a removal could
/// not be committed.
fn remove_departed_objects(state: &mut State) -> bool {
    let alive = match crate::offline::alive_nodes() {
        Ok(alive) => alive,
        Err(e) => {
            warn!("cannot list the running clients, no object removed: {e}");
            return true;
        }
    };
    let (removed, failed) = state.remove_departed(alive);
    if !removed.is_empty() {
        // A crashed process may leave thousands: the first few name them.
        let first: Vec<String> = removed
            .iter()
            .take(16)
            .map(|id| format!("{id:#x}"))
            .collect();
        info!(
            count = removed.len(),
            first = ?first,
            "removed the objects of departed clients"
        );
    }
    if let Some(e) = failed {
        error!(
            "cannot remove the objects of departed clients ({e:?}); next try in {} s",
            REAP_BACKOFF.as_secs()
        );
        return false;
    }
    true
}

/// Sleeps until a client notifies or [`BLOCK_SLICE`] passes. The listener is
/// drained and the servers looked at once more before sleeping, so that a
/// request that arrived after the last poll but whose notification was
/// consumed cannot be missed.
fn block(waitset: &WaitSet<ipc::Service>, endpoints: &Endpoints) {
    let listener = &endpoints.listener;
    let _ = listener.try_wait(|_| {});
    let pending = endpoints.query.has_requests().unwrap_or(false)
        || endpoints.scene.has_requests().unwrap_or(false)
        || endpoints.poses.has_requests().unwrap_or(false)
        || endpoints.admin.has_requests().unwrap_or(false);
    if pending {
        return;
    }
    let on_event = |_id: WaitSetAttachmentId<ipc::Service>| {
        let _ = listener.try_wait(|_| {});
        CallbackProgression::Stop
    };
    if let Err(e) = waitset.wait_and_process_once_with_timeout(on_event, BLOCK_SLICE) {
        warn!(error = ?e, "waitset wait failed");
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// The one path every service's requests take: receives each request
/// waiting (`receive`, the service's port) and hands it to `answer`, the
/// service's part; returns how many. A failed receive is logged and ends
/// the turn.
fn serve_waiting<R, E: std::fmt::Debug>(
    service: &'static str,
    mut receive: impl FnMut() -> Result<Option<R>, E>,
    mut answer: impl FnMut(R),
) -> usize {
    let mut served = 0;
    loop {
        match receive() {
            Ok(Some(request)) => {
                served += 1;
                answer(request);
            }
            Ok(None) => return served,
            Err(e) => {
                warn!(service, error = ?e, "receive failed");
                return served;
            }
        }
    }
}

/// Runs a service's handler. A panic is a bug of ours, not the client's:
/// it is logged, the request is answered with `fallback()`, and serving
/// goes on.
fn guarded<T>(
    service: &'static str,
    handler: impl FnOnce() -> T,
    fallback: impl FnOnce() -> T,
) -> T {
    catch_unwind(AssertUnwindSafe(handler)).unwrap_or_else(|_| {
        error!(service, "handler panicked");
        fallback()
    })
}

/// Logs a reply that could not be delivered (its client gone, usually).
fn delivered<E: std::fmt::Debug>(service: &'static str, sent: Result<(), E>) {
    if let Err(e) = sent {
        debug!(service, error = ?e, "reply not delivered (client gone?)");
    }
}

/// Refuses a request of a service whose replies are rows: no row, and
/// `header` saying why.
fn refuse<Req, ReqHeader, Row, Header>(
    service: &'static str,
    request: &ActiveRequest<ipc::Service, Req, ReqHeader, [Row], Header>,
    header: Header,
) where
    Req: std::fmt::Debug + IceoryxSend + ?Sized,
    ReqHeader: std::fmt::Debug + ZeroCopySend,
    Row: std::fmt::Debug + ZeroCopySend + Default + 'static,
    Header: std::fmt::Debug + ZeroCopySend + Default,
{
    match request.loan_slice_uninit(0) {
        Ok(reply) => {
            let mut reply = reply.write_from_fn(|_| Row::default());
            *reply.user_header_mut() = header;
            delivered(service, reply.send());
        }
        Err(e) => warn!(service, error = ?e, "cannot loan reply"),
    }
}

/// Answers every query request waiting; returns how many.
fn serve_queries(query: &QueryServer, state: &mut State) -> usize {
    serve_waiting(
        "query",
        || query.receive(),
        |request| {
            let items = request.payload();
            let client = request.origin().value();
            if let Err(code) = state.check_batch(items.len()) {
                debug!(len = items.len(), ?code, "batch rejected");
                let header = ReplyHeader {
                    error: code as u32,
                    ..ReplyHeader::default()
                };
                refuse("query", &request, header);
                return;
            }
            // The results, then a gradient for each item that asks: a
            // pair that asks none carries none.
            let gradients = ReplyEntry::gradients_asked(items);
            let reply = match request.loan_slice_uninit(items.len() + gradients) {
                Ok(r) => r,
                Err(e) => {
                    warn!(error = ?e, len = items.len(), "cannot loan reply");
                    return;
                }
            };
            // Filled first, then answered: the fill takes every line of the
            // reply from the client's cache in one sweep whose misses overlap.
            // Writing each result straight in after its GJK run measured slower
            // on batches, each write then missing alone.
            let mut reply = reply.write_from_fn(|_| ReplyEntry::default());
            *reply.user_header_mut() = ReplyHeader {
                error: ErrorCode::Ok as u32,
                count: items.len() as u32,
                gradients: gradients as u32,
                reserved: 0,
            };
            let answered = guarded(
                "query",
                || {
                    if let Some((results, rows)) =
                        ReplyEntry::split_mut(reply.payload_mut(), items.len())
                    {
                        state.handle_with_gradients(client, items, results, rows);
                    }
                    true
                },
                || false,
            );
            if !answered
                && let Some((results, rows)) =
                    ReplyEntry::split_mut(reply.payload_mut(), items.len())
            {
                results.fill(ItemResult::error(ErrorCode::Internal));
                rows.fill(gjkd_proto::GradientRow::default());
            }
            delivered("query", reply.send());
        },
    )
}

/// Answers every scene request waiting; returns how many.
///
/// The engine writes into `scratch`, kept from one request to the next,
/// and only the rows written go into shared memory: a reply slice as
/// large as the caller's capacity would be initialised and sent whole,
/// which cost more than the question for a handful of rows in a buffer
/// of a thousand.
fn serve_scenes(scene: &SceneServer, state: &mut State, scratch: &mut Vec<SceneRow>) -> usize {
    serve_waiting(
        "scene",
        || scene.receive(),
        |request| {
            let header = *request.user_header();
            let items = request.payload();
            // The client port keys the warm starts and motion bounds, as the
            // query service's does: two clients never share them.
            let client = request.origin().value();
            let max_batch = state.limits().max_batch;
            if items.len() > max_batch {
                refuse(
                    "scene",
                    &request,
                    SceneReply::error(ErrorCode::BatchTooLarge),
                );
                return;
            }
            let rows = (header.max_rows as usize).min(state.limits().max_rows);
            if scratch.len() < rows {
                scratch.resize(rows, SceneRow::default());
            }
            let answer = guarded(
                "scene",
                || state.scene(client, &header, items, &mut scratch[..rows]),
                || SceneReply::error(ErrorCode::Internal),
            );
            if answer.error_code() != ErrorCode::Ok {
                debug!(kind = header.kind, code = ?answer.error_code(), "scene request refused");
                refuse("scene", &request, answer);
                return;
            }
            let written = usize::try_from(answer.total).map_or(rows, |t| t.min(rows));
            match request.loan_slice_uninit(written) {
                Ok(reply) => {
                    let mut reply = reply.write_from_slice(&scratch[..written]);
                    *reply.user_header_mut() = answer;
                    delivered("scene", reply.send());
                }
                Err(e) => warn!(error = ?e, written, "cannot loan scene reply"),
            }
        },
    )
}

/// Answers every pose request waiting; returns how many.
fn serve_poses(poses: &PosesServer, state: &mut State) -> usize {
    serve_waiting(
        "poses",
        || poses.receive(),
        |request| {
            let ids = request.payload();
            if let Err(code) = state.check_batch(ids.len()) {
                debug!(len = ids.len(), ?code, "pose request refused");
                let header = PosesReply {
                    error: code as u32,
                    count: 0,
                };
                refuse("poses", &request, header);
                return;
            }
            let reply = match request.loan_slice_uninit(ids.len()) {
                Ok(r) => r,
                Err(e) => {
                    warn!(error = ?e, len = ids.len(), "cannot loan pose reply");
                    return;
                }
            };
            let mut reply = reply.write_from_fn(|_| StoredPose::default());
            *reply.user_header_mut() = PosesReply {
                error: ErrorCode::Ok as u32,
                count: ids.len() as u32,
            };
            let out = reply.payload_mut();
            let answered = guarded(
                "poses",
                || {
                    state.poses(ids, out);
                    true
                },
                || false,
            );
            if !answered {
                *reply.user_header_mut() = PosesReply {
                    error: ErrorCode::Internal as u32,
                    count: 0,
                };
            }
            delivered("poses", reply.send());
        },
    )
}

/// The owner identity of admin client port `port`: the id of the iceoryx2
/// node that created it. A `gjkd-client` `Client` keeps its node for its
/// whole life, so the identity survives its reconnections and a server
/// restart, where port ids do not. A port that is already gone (its
/// process died after sending) keeps its port id, which owns nothing.
fn owner_of(service: &AdminService, port: u128) -> u128 {
    let mut owner = port;
    service.dynamic_config().list_clients(|c| {
        if c.client_id.value() == port {
            owner = c.node_id.value();
            CallbackProgression::Stop
        } else {
            CallbackProgression::Continue
        }
    });
    owner
}

/// Answers every admin request waiting; returns how many.
fn serve_admin(admin: &AdminServer, service: &AdminService, state: &mut State) -> usize {
    serve_waiting(
        "admin",
        || admin.receive(),
        |request| {
            let header = request.user_header();
            let client = owner_of(service, request.origin().value());
            let vertices = request.payload();
            let reply = guarded(
                "admin",
                || state.handle_admin(client, header, vertices),
                || AdminReply::error(header.op, ErrorCode::Internal),
            );
            match reply.error_code() {
                ErrorCode::Ok => debug!(op = header.op, id = reply.id, "admin ok"),
                code => info!(op = header.op, ?code, "admin request refused"),
            }
            if header.op == AdminOp::Register as u32
                && reply.error_code() == ErrorCode::Ok
                && fault_kill_after_register()
            {
                // Fault injection for the tests: a crash between the commit
                // and the reply, as `kill -9` would make it.
                error!(
                    id = reply.id,
                    "{KILL_AFTER_REGISTER} is set: killing this server before the reply"
                );
                // SAFETY: kill(2) on our own pid; no memory is involved.
                unsafe { libc::kill(libc::getpid(), libc::SIGKILL) };
            }
            delivered("admin", request.send_copy(reply));
        },
    )
}

/// Fault-injection hook for the tests, not for production: when this
/// environment variable is `1` at start, the server kills itself with
/// `SIGKILL` right after committing a registration and before replying,
/// as a `kill -9` between the store and the reply would.
pub const KILL_AFTER_REGISTER: &str = "GJKD_FAULT_KILL_AFTER_REGISTER";

/// Whether [`KILL_AFTER_REGISTER`] is set (read once).
fn fault_kill_after_register() -> bool {
    static SET: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *SET.get_or_init(|| std::env::var(KILL_AFTER_REGISTER).is_ok_and(|v| v == "1"))
}
