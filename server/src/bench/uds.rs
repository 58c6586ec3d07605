//! The Unix-domain-socket baseline of `gjkd bench latency`: the same
//! `#[repr(C)]` request bytes, the same handler ([`State::handle`]), carried
//! the way an ordinary socket server would carry them.
//!
//! A request is an 8-byte header (item count, zero) followed by the items as
//! they lie in memory; a reply is a [`ReplyHeader`] followed by the results.
//! The server is a thread doing blocking reads on a stream socket, one
//! connection at a time; the client writes a request with one `write` and
//! reads the reply with blocking reads. No polling, no artificial delays.

use std::io::{Read, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;

use gjkd_proto::{ErrorCode, Item, ItemResult, ReplyHeader};

use crate::state::State;

// The byte views below rely on these types having no padding (every byte is
// a field's) and accepting any bit pattern (every field is an integer or a
// float), which the wire format already promises for shared memory.
const _: () = assert!(std::mem::size_of::<Item>() == 160);
const _: () = assert!(std::mem::size_of::<ItemResult>() == 128);
const _: () = assert!(std::mem::size_of::<ReplyHeader>() == 8);

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

/// A Unix-socket gjkd server on its own thread.
pub struct UdsServer {
    path: PathBuf,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl UdsServer {
    /// Binds `path` (removing a stale socket file first) and serves `state`
    /// on a new thread, pinned to `cpu` if given, until dropped.
    ///
    /// # Errors
    /// When the socket cannot be bound.
    pub fn start(path: &Path, mut state: State, cpu: Option<usize>) -> std::io::Result<Self> {
        let _ = std::fs::remove_file(path);
        let listener = UnixListener::bind(path)?;
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let thread = std::thread::Builder::new()
            .name("gjkd-uds".into())
            .spawn(move || {
                if let Some(cpu) = cpu {
                    super::latency::pin(0, cpu);
                }
                for conn in listener.incoming() {
                    if flag.load(Ordering::Relaxed) {
                        break;
                    }
                    if let Ok(conn) = conn {
                        // A connection ends when the client hangs up.
                        let _ = serve_connection(conn, &mut state);
                    }
                }
            })?;
        Ok(UdsServer {
            path: path.to_owned(),
            stop,
            thread: Some(thread),
        })
    }

    /// The socket's path.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for UdsServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        // Wake the blocking accept so the thread sees the flag.
        let _ = UnixStream::connect(&self.path);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
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
                }
            }
            Err(code) => {
                reply.clear();
                ReplyHeader {
                    error: code as u32,
                    count: 0,
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
    use crate::state::Limits;
    use gjkd_proto::{AdminOp, AdminRequest, ObjectId, QueryOptions, Vertex, WaitMode, shape_kind};

    #[test]
    fn answers_over_the_socket_equal_the_handler() {
        let mut state = State::new(Limits::default(), WaitMode::Block, 3);
        let mut reg = AdminRequest::new(AdminOp::Register);
        reg.shape = shape_kind::CONVEX;
        reg.piece_count = 1;
        reg.pieces[0].vertex_count = 1;
        reg.pieces[0].radius = 0.5;
        let a = state.handle_admin(1, &reg, &[Vertex::default()]).id;
        let b = state
            .handle_admin(
                1,
                &reg,
                &[Vertex {
                    x: 3.0,
                    y: 0.0,
                    z: 0.0,
                }],
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
        let server = UdsServer::start(&path, state, None).expect("bind");
        let mut client = UdsClient::connect(server.path()).expect("connect");
        let mut out = [ItemResult::default(); 2];
        for _ in 0..3 {
            client.query(&items, &mut out).expect("round trip");
            assert_eq!(out[0].answer().expect("answer").distance, 2.0);
            assert_eq!(out[1].error_code(), ErrorCode::UnknownObject);
        }
        drop(client);
        drop(server);
        assert!(!path.exists());
    }
}
