//! What can go wrong with a call, and how replies and iceoryx2 failures
//! become [`ClientError`]s.

use std::time::Duration;

#[cfg(doc)]
use crate::{Client, PROTOCOL_VERSION};
use gjkd_proto::ErrorCode;

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

/// `Ok` for a reply header's [`ErrorCode::Ok`], the request's rejection
/// for another code, a protocol error for a value this version does not
/// know: how the query and scene services say a whole request failed.
pub(crate) fn reply_accepted(raw: u32) -> Result<(), ClientError> {
    match ErrorCode::from_raw(raw) {
        Some(ErrorCode::Ok) => Ok(()),
        Some(code) => Err(ClientError::Rejected(code)),
        None => Err(ClientError::Protocol(format!("unknown error code {raw}"))),
    }
}

pub(crate) fn ipc_err<E: std::fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> ClientError {
    move |e| ClientError::Ipc(format!("{what}: {e:?}"))
}
