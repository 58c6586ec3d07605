//! The Unix-domain-socket baseline of `gjkd bench latency`: the same
//! `#[repr(C)]` request bytes, the same handler ([`State::handle`]), carried
//! the way an ordinary socket server would carry them.
//!
//! A request is an 8-byte header (item count, zero) followed by the items as
//! they lie in memory; a reply is the error and count of a [`ReplyHeader`]
//! (8 bytes) followed by the results (pairs only: no gradients).
//! The server is a separate process, like the iceoryx2 servers it is
//! compared with: `gjkd bench latency` starts this executable as
//! `gjkd bench uds-server --socket PATH [--cpu N]` ([`UdsServer`]), pinned
//! as the others are, and kills it and removes the socket file when done.
//! It does blocking reads on a stream socket, one connection at a time; the
//! client writes a request with one `write` and reads the reply with
//! blocking reads. No polling, no artificial delays.
//!
//! The child registers the bench's objects itself, through the same admin
//! handler and in the same order as the in-process baseline
//! (`latency_objects::local_state`), so the ids the client sends name the same
//! objects on both sides; `gjkd bench latency` checks the first answer.

use std::io::{Read, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout};

use gjkd_proto::{ErrorCode, Item, ItemResult, ReplyHeader};

use super::{BenchError, io};
use gjkd_server::engine::state::State;

// The byte views below rely on these types having no padding (every byte is
// a field's) and accepting any bit pattern (every field is an integer or a
// float), which the wire format already promises for shared memory.
const _: () = assert!(std::mem::size_of::<Item>() == 160);
const _: () = assert!(std::mem::size_of::<ItemResult>() == 152);
const _: () = assert!(std::mem::size_of::<ReplyHeader>() == 16);

fn items_bytes(items: &[Item]) -> &[u8] {
    // SAFETY: `Item` is `repr(C)` plain data without padding (asserted above),
    // so its bytes are initialised; the length is the slice's size in bytes.
    unsafe { std::slice::from_raw_parts(items.as_ptr().cast::<u8>(), size_of_val(items)) }
}

fn items_bytes_mut(items: &mut [Item]) -> &mut [u8] {
    // SAFETY: as above, and every bit pattern is a valid `Item` (integers and
    // floats only), so writing arbitrary bytes cannot make an invalid value.
    unsafe { std::slice::from_raw_parts_mut(items.as_mut_ptr().cast::<u8>(), size_of_val(items)) }
}

fn results_bytes(results: &[ItemResult]) -> &[u8] {
    // SAFETY: `ItemResult` is `repr(C)` plain data without padding.
    unsafe { std::slice::from_raw_parts(results.as_ptr().cast::<u8>(), size_of_val(results)) }
}

fn results_bytes_mut(results: &mut [ItemResult]) -> &mut [u8] {
    // SAFETY: as above; every bit pattern is a valid `ItemResult`.
    unsafe {
        std::slice::from_raw_parts_mut(results.as_mut_ptr().cast::<u8>(), size_of_val(results))
    }
}

/// Flags of the hidden `gjkd bench uds-server`: the socket server that
/// `gjkd bench latency` starts as a child process.
#[derive(clap::Args, Debug, Clone)]
pub struct UdsServerArgs {
    /// Socket file to bind (a stale one is removed first).
    #[arg(long)]
    socket: PathBuf,
    /// Pin the process to this CPU before serving.
    #[arg(long)]
    cpu: Option<usize>,
    /// The largest batch the client will send: the server registers the
    /// bench's objects for it (`latency_objects::local_state`).
    #[arg(long, default_value_t = 512)]
    max_batch: usize,
}

/// The line the child prints on stdout once the socket is bound.
const READY: &str = "gjkd-uds listening";

/// Runs `gjkd bench uds-server`: pins itself if asked, builds the bench's
/// state, binds the socket, says so on stdout, and serves connections one
/// at a time, with blocking reads, until killed.
///
/// # Errors
/// When the socket cannot be bound or the ready line cannot be written.
pub fn run_server(args: &UdsServerArgs) -> Result<(), BenchError> {
    // End with the bench if it dies without stopping us.
    // SAFETY: prctl(PR_SET_PDEATHSIG) takes a signal number and no pointers.
    unsafe {
        libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM);
    }
    if let Some(cpu) = args.cpu {
        gjkd_rt::pin_current_thread(cpu)
            .map_err(|e| BenchError::Other(format!("uds-server --cpu {cpu}: {e}")))?;
    }
    let (state, ..) = super::latency_objects::local_state(args.max_batch.max(1));
    let _ = std::fs::remove_file(&args.socket);
    let listener = io(
        format!("bind {}", args.socket.display()),
        UnixListener::bind(&args.socket),
    )?;
    let mut stdout = std::io::stdout().lock();
    io(
        "write the ready line",
        writeln!(stdout, "{READY}").and_then(|()| stdout.flush()),
    )?;
    drop(stdout);
    serve(&listener, state);
    Ok(())
}

/// Serves the connections of `listener` one at a time, each until its client
/// hangs up; returns when accepting fails.
fn serve(listener: &UnixListener, mut state: State) {
    for conn in listener.incoming() {
        match conn {
            // A connection ends when the client hangs up.
            Ok(conn) => {
                let _ = serve_connection(conn, &mut state);
            }
            Err(_) => return,
        }
    }
}

/// A `gjkd bench uds-server` child process (this executable), killed and its
/// socket file removed when dropped.
pub struct UdsServer {
    path: PathBuf,
    child: Child,
    /// Kept open: closing it would make the child's writes fail.
    _stdout: ChildStdout,
}

impl UdsServer {
    /// Starts `gjkd bench uds-server` on `path`, for batches of up to
    /// `max_batch`, pinned to `cpu` if given, and waits until it listens.
    ///
    /// # Errors
    /// When the process cannot be spawned or exits before listening.
    pub fn spawn(path: &Path, max_batch: usize, cpu: Option<usize>) -> std::io::Result<Self> {
        let max_batch = max_batch.to_string();
        let (child, stdout, line) = super::spawn_child(
            &[
                "uds-server".as_ref(),
                "--socket".as_ref(),
                path.as_ref(),
                "--max-batch".as_ref(),
                max_batch.as_ref(),
            ],
            cpu,
        )?;
        let server = UdsServer {
            path: path.to_owned(),
            _stdout: stdout,
            child,
        };
        if line != READY {
            return Err(std::io::Error::other(format!(
                "gjkd bench uds-server did not start (said {line:?})"
            )));
        }
        Ok(server)
    }

    /// The socket's path.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for UdsServer {
    fn drop(&mut self) {
        // The server holds no state worth a clean exit: kill and reap it.
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_file(&self.path);
    }
}

/// Answers requests on one connection until the client hangs up. Buffers
/// grow to the largest batch seen and are reused.
fn serve_connection(mut conn: UnixStream, state: &mut State) -> std::io::Result<()> {
    let mut items: Vec<Item> = Vec::new();
    let mut reply: Vec<ItemResult> = Vec::new();
    let mut out: Vec<u8> = Vec::new();
    loop {
        let mut header = [0u8; 8];
        conn.read_exact(&mut header)?;
        let count = u32::from_ne_bytes([header[0], header[1], header[2], header[3]]) as usize;
        let check = state.check_batch(count);
        // Refused batches carry no items worth reading past the limit; the
        // connection is dropped rather than resynchronised.
        if check == Err(ErrorCode::BatchTooLarge) {
            return Ok(());
        }
        items.resize(
            count,
            Item::set_pose(
                gjkd_proto::ObjectId::from_raw(0),
                &nalgebra::Isometry3::identity(),
            ),
        );
        conn.read_exact(items_bytes_mut(&mut items))?;
        reply.clear();
        reply.resize(count, ItemResult::default());
        let head = match check {
            Ok(()) => {
                state.handle(0, &items, &mut reply);
                ReplyHeader {
                    error: ErrorCode::Ok as u32,
                    count: count as u32,
                    ..ReplyHeader::default()
                }
            }
            Err(code) => {
                reply.clear();
                ReplyHeader {
                    error: code as u32,
                    ..ReplyHeader::default()
                }
            }
        };
        out.clear();
        out.extend_from_slice(&head.error.to_ne_bytes());
        out.extend_from_slice(&head.count.to_ne_bytes());
        out.extend_from_slice(results_bytes(&reply));
        conn.write_all(&out)?;
    }
}

/// A client of [`UdsServer`].
pub struct UdsClient {
    stream: UnixStream,
    out: Vec<u8>,
}

impl UdsClient {
    /// Connects to the server at `path`.
    ///
    /// # Errors
    /// When the socket cannot be reached.
    pub fn connect(path: &Path) -> std::io::Result<Self> {
        Ok(UdsClient {
            stream: UnixStream::connect(path)?,
            out: Vec::new(),
        })
    }

    /// One round trip: sends `items`, fills `results[..items.len()]`.
    ///
    /// # Errors
    /// Socket errors, and `InvalidData` when the server refused the batch.
    pub fn query(&mut self, items: &[Item], results: &mut [ItemResult]) -> std::io::Result<()> {
        self.out.clear();
        self.out
            .extend_from_slice(&(items.len() as u32).to_ne_bytes());
        self.out.extend_from_slice(&0u32.to_ne_bytes());
        self.out.extend_from_slice(items_bytes(items));
        self.stream.write_all(&self.out)?;
        let mut header = [0u8; 8];
        self.stream.read_exact(&mut header)?;
        let error = u32::from_ne_bytes([header[0], header[1], header[2], header[3]]);
        let count = u32::from_ne_bytes([header[4], header[5], header[6], header[7]]) as usize;
        if error != ErrorCode::Ok as u32 || count != items.len() || results.len() < count {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "reply error {error}, {count} results for {} items",
                    items.len()
                ),
            ));
        }
        self.stream
            .read_exact(results_bytes_mut(&mut results[..count]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gjkd_proto::{
        AdminChunk, AdminOp, AdminRequest, ObjectId, QueryOptions, Vertex, WaitMode, shape_kind,
    };
    use gjkd_server::engine::state::Limits;

    #[test]
    fn answers_over_the_socket_equal_the_handler() {
        let mut state = State::new(Limits::default(), WaitMode::Block, 3);
        let mut reg = AdminRequest::new(AdminOp::Register);
        reg.shape = shape_kind::CONVEX;
        reg.piece_count = 1;
        reg.pieces[0].vertex_count = 1;
        reg.pieces[0].rounding = 0.5;
        let a = state
            .handle_admin(1, &reg, AdminChunk::from_vertices(&[Vertex::default()]))
            .id;
        let b = state
            .handle_admin(
                1,
                &reg,
                &[Vertex {
                    x: 3.0,
                    y: 0.0,
                    z: 0.0,
                }
                .into()],
            )
            .id;
        let items = [
            Item::distance(
                ObjectId::from_raw(a),
                ObjectId::from_raw(b),
                &QueryOptions::cold(),
            ),
            Item::distance(
                ObjectId::from_raw(a),
                ObjectId::from_raw(7),
                &QueryOptions::cold(),
            ),
        ];
        let path = std::env::temp_dir().join(format!("gjkd-uds-test-{}.sock", std::process::id()));
        let _ = std::fs::remove_file(&path);
        // The server loop of the child process, on a thread here: a unit
        // test's executable is not `gjkd` (the e2e tests run the child).
        let listener = UnixListener::bind(&path).expect("bind");
        let server = std::thread::spawn(move || serve(&listener, state));
        let mut client = UdsClient::connect(&path).expect("connect");
        let mut out = [ItemResult::default(); 2];
        for _ in 0..3 {
            client.query(&items, &mut out).expect("round trip");
            assert_eq!(out[0].answer().expect("answer").distance, 2.0);
            assert_eq!(out[1].error_code(), ErrorCode::UnknownObject);
        }
        drop(client);
        std::fs::remove_file(&path).expect("remove the socket");
        // The serving thread stays blocked in `accept`; it ends with the
        // test process.
        drop(server);
    }
}
