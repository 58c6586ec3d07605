//! The raw iceoryx2 floor of `gjkd bench latency` (transport `iceoryx2`):
//! the same request and reply sizes through a bare request-response
//! service, both sides busy-polling, no GJK, no checks, no wake event. A
//! gjkd round trip in spin mode is this floor plus the in-process handler's
//! time plus whatever gjkd's own layers add; the difference is what those
//! layers cost.
//!
//! The server is a child process (`gjkd bench raw-server`, [`RawServer`]),
//! pinned like the gjkd servers; it answers each request of `n` items with
//! `n` default results until SIGTERM, then removes its service.

use std::io::Write;
use std::process::{Child, ChildStdout};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use gjkd_proto::{Item, ItemResult};
use iceoryx2::port::client::Client as IoxClient;
use iceoryx2::prelude::*;

use super::{BenchError, io};

/// Flags of the hidden `gjkd bench raw-server`.
#[derive(clap::Args, Debug, Clone)]
pub struct RawServerArgs {
    /// iceoryx2 service name to serve.
    #[arg(long)]
    service: String,
    /// Pin the process to this CPU before serving.
    #[arg(long)]
    cpu: Option<usize>,
    /// The largest batch a request may carry.
    #[arg(long, default_value_t = 512)]
    max_batch: usize,
}

/// The line the child prints on stdout once its server port exists.
const READY: &str = "gjkd-raw serving";

fn ipc<E: std::fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> BenchError {
    move |e| BenchError::Other(format!("iceoryx2 {what}: {e:?}"))
}

/// The floor's request-response service.
type RawService = iceoryx2::service::port_factory::request_response::PortFactory<
    ipc::Service,
    [Item],
    (),
    [ItemResult],
    (),
>;

/// The request-response service of the floor, opened or created.
fn service(node: &Node<ipc::Service>, name: &str) -> Result<RawService, BenchError> {
    let name = ServiceName::new(name).map_err(ipc("service name"))?;
    node.service_builder(&name)
        .request_response::<[Item], [ItemResult]>()
        .max_clients(2)
        .max_servers(1)
        .max_active_requests_per_client(2)
        .max_response_buffer_size(2)
        .enable_fire_and_forget_requests(false)
        .open_or_create()
        .map_err(ipc("service"))
}

/// Runs `gjkd bench raw-server`: answers until SIGTERM.
///
/// # Errors
/// When iceoryx2 cannot set up the service or the CPU cannot be pinned.
pub fn run_server(args: &RawServerArgs) -> Result<(), BenchError> {
    // SAFETY: prctl(PR_SET_PDEATHSIG) takes a signal number and no pointers.
    unsafe {
        libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM);
    }
    let stop = Arc::new(AtomicBool::new(false));
    io(
        "install the SIGTERM handler",
        signal_hook::flag::register(signal_hook::consts::SIGTERM, Arc::clone(&stop)),
    )?;
    if let Some(cpu) = args.cpu {
        gjkd_rt::pin_current_thread(cpu)
            .map_err(|e| BenchError::Other(format!("raw-server --cpu {cpu}: {e}")))?;
    }
    let node = NodeBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(ipc("node"))?;
    let service = service(&node, &args.service)?;
    let server = service
        .server_builder()
        .initial_max_slice_len(args.max_batch.max(1))
        .allocation_strategy(AllocationStrategy::Static)
        .create()
        .map_err(ipc("server"))?;
    let mut stdout = std::io::stdout().lock();
    io(
        "write the ready line",
        writeln!(stdout, "{READY}").and_then(|()| stdout.flush()),
    )?;
    drop(stdout);
    while !stop.load(Ordering::Relaxed) {
        match server.receive() {
            Ok(Some(request)) => {
                let n = request.payload().len();
                if let Ok(reply) = request.loan_slice_uninit(n) {
                    let _ = reply.write_from_fn(|_| ItemResult::default()).send();
                }
            }
            Ok(None) => std::hint::spin_loop(),
            Err(e) => return Err(ipc("receive")(e)),
        }
    }
    Ok(())
}

/// A `gjkd bench raw-server` child process, stopped by SIGTERM (it then
/// removes its service) and reaped when dropped.
pub struct RawServer {
    child: Child,
    _stdout: ChildStdout,
}

impl RawServer {
    /// Starts `gjkd bench raw-server` on `service`, pinned to `cpu` if
    /// given, and waits until it serves.
    ///
    /// # Errors
    /// When the process cannot be spawned or exits before serving.
    pub fn spawn(service: &str, max_batch: usize, cpu: Option<usize>) -> std::io::Result<Self> {
        let max_batch = max_batch.to_string();
        let (mut child, stdout, line) = super::spawn_child(
            &[
                "raw-server".as_ref(),
                "--service".as_ref(),
                service.as_ref(),
                "--max-batch".as_ref(),
                max_batch.as_ref(),
            ],
            cpu,
        )?;
        if line != READY {
            let _ = child.kill();
            let _ = child.wait();
            return Err(std::io::Error::other(format!(
                "gjkd bench raw-server did not start (said {line:?})"
            )));
        }
        Ok(RawServer {
            child,
            _stdout: stdout,
        })
    }
}

impl Drop for RawServer {
    fn drop(&mut self) {
        if let Ok(pid) = libc::pid_t::try_from(self.child.id()) {
            // SAFETY: kill(2) with a pid we spawned and have not reaped.
            unsafe {
                libc::kill(pid, libc::SIGTERM);
            }
        }
        let deadline = Instant::now() + Duration::from_secs(5);
        while Instant::now() < deadline {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

type RawPort = IoxClient<ipc::Service, [Item], (), [ItemResult], ()>;

/// The client side of the floor: sends items, busy-polls for the reply.
pub struct RawClient {
    port: RawPort,
    _node: Node<ipc::Service>,
}

impl RawClient {
    /// Connects to the raw server of `service`.
    ///
    /// # Errors
    /// When iceoryx2 cannot open the service or create the port.
    pub fn connect(service: &str, max_batch: usize) -> Result<Self, BenchError> {
        let node = NodeBuilder::new()
            .create::<ipc::Service>()
            .map_err(ipc("node"))?;
        // Opened or created: the server created it already, and its limits
        // stick.
        let factory = self::service(&node, service)?;
        let port = factory
            .client_builder()
            .initial_max_slice_len(max_batch.max(1))
            .allocation_strategy(AllocationStrategy::Static)
            .create()
            .map_err(ipc("client"))?;
        Ok(RawClient { port, _node: node })
    }

    /// One round trip of `items`; the results are copied into `results`.
    ///
    /// # Errors
    /// When a send fails or no reply comes within five seconds.
    pub fn query(&self, items: &[Item], results: &mut [ItemResult]) -> Result<(), BenchError> {
        let pending = self
            .port
            .loan_slice_uninit(items.len())
            .map_err(ipc("loan"))?
            .write_from_slice(items)
            .send()
            .map_err(ipc("send"))?;
        let deadline = Instant::now() + Duration::from_secs(5);
        let mut turns = 0u32;
        loop {
            if let Some(reply) = pending.receive().map_err(ipc("receive"))? {
                let payload = reply.payload();
                let n = payload.len().min(results.len());
                results[..n].copy_from_slice(&payload[..n]);
                return Ok(());
            }
            turns = turns.wrapping_add(1);
            // The clock is read now and then, not every turn: the floor is
            // the transport's, not the clock's.
            if turns.is_multiple_of(1024) && Instant::now() > deadline {
                return Err(BenchError::Other(
                    "raw iceoryx2 server did not answer".into(),
                ));
            }
            std::hint::spin_loop();
        }
    }
}
