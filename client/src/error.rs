//! The umbrella of every call's faults, [`ClientError`], the connection
//! faults every call shares, [`ConnectError`], and how replies and
//! iceoryx2 failures become them (each operation's own error is in
//! `op_error.rs`).

use std::time::Duration;

#[cfg(doc)]
use crate::{Client, PROTOCOL_VERSION};
use gjkd_proto::ErrorCode;

/// What can go wrong with any call: the umbrella of the errors per
/// operation ([`RegisterError`](crate::RegisterError),
/// [`QueryError`](crate::QueryError), ...), each of which converts into it,
/// so that `?` into one type works on every call. A refusal by the server
/// is [`ClientError::Rejected`] with its code; Python and C report every
/// fault as its `ClientError` (`docs/errors.md`).
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
    /// A robot's URDF or SRDF, or a mesh it names, cannot be read (missing,
    /// malformed, a `package://` URL found in no folder, a collision
    /// element of a bad size): the fault the server refuses as
    /// [`ErrorCode::InvalidRobot`], found here before anything is sent
    /// (or with the link objects registered so far removed again). The
    /// message names the file, link or joint.
    #[error("the robot cannot be read: {0}")]
    InvalidRobot(String),
    /// Joint positions named a joint the robot does not move (no such
    /// joint, or a fixed or mimic one): the fault a name lookup refuses as
    /// [`ErrorCode::UnknownName`], found here before anything is sent.
    #[error("the robot has no moving joint named `{0}`")]
    UnknownJoint(String),
    /// A mesh cannot be made a shape: its file is missing or no mesh, its
    /// scale is bad, or its decomposition found no pieces. The server never
    /// sees meshes, so no [`ErrorCode`] names this; the message says why.
    #[error("the mesh cannot be used: {0}")]
    InvalidMesh(String),
}

impl ClientError {
    /// The [`ErrorCode`] of this fault: the server's for a refusal, and
    /// for a fault this client finds before sending, the code the server
    /// gives the same fault ([`ClientError::InvalidRobot`] is
    /// [`ErrorCode::InvalidRobot`], [`ClientError::UnknownJoint`]
    /// [`ErrorCode::UnknownName`]), so that Rust, Python and C report one
    /// fault with one code (`docs/errors.md`). `None` for faults no code
    /// names (a server gone, a timeout, an argument that cannot be sent).
    pub fn code(&self) -> Option<ErrorCode> {
        match self {
            ClientError::Rejected(code) => Some(*code),
            ClientError::InvalidRobot(_) => Some(ErrorCode::InvalidRobot),
            ClientError::UnknownJoint(_) => Some(ErrorCode::UnknownName),
            _ => None,
        }
    }
}

/// Why a call found no server it can use: the error of
/// [`ClientBuilder::connect`](crate::ClientBuilder::connect) (and
/// [`Client::connect`]), and the `Connection` variant of every other
/// operation's error ([`RegisterError`](crate::RegisterError),
/// [`QueryError`](crate::QueryError), ...), since every call reconnects to
/// a server that went away and so can meet every fault of a connect. Each
/// converts into [`ClientError`], the same fault there.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConnectError {
    /// No gjkd server serves the name (within the connect timeout, for a
    /// connect): none was started, it stopped, or it died. The next call
    /// tries to reconnect.
    #[error("no gjkd server is serving `{0}`")]
    ServerGone(String),
    /// A server serves the name but did not answer (the greeting, or the
    /// call) within the timeout.
    #[error("the server did not answer within {0:?}")]
    Timeout(Duration),
    /// A server serves this name with another protocol version than this
    /// client's ([`PROTOCOL_VERSION`]): client and server come from
    /// different gjkd releases. Retrying does not help.
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
    /// A service of this name was made by another program, another build of
    /// gjkd or another iceoryx2 version; the cause names which.
    #[error("the service `{service}` is incompatible with this client: {cause}")]
    Incompatible {
        /// The iceoryx2 service that could not be opened.
        service: String,
        /// What iceoryx2 found different.
        cause: String,
    },
    /// The service belongs to another user (see the README's "Access").
    #[error("no permission to open the service `{0}` (it belongs to another user)")]
    PermissionDenied(String),
    /// The server already has as many client processes as it admits.
    #[error("the service `{0}` admits no more clients")]
    TooManyClients(String),
    /// The server answered something this client does not understand (a
    /// broken server, or a refusal the operation never gets).
    #[error("the server's answer is not understood: {0}")]
    Protocol(String),
    /// iceoryx2 could not set up this process (shared memory, limits).
    #[error("iceoryx2: {0}")]
    Ipc(String),
}

impl ConnectError {
    /// The connect error of what reconnecting met; a refusal of the
    /// greeting (which a gjkd server never sends) reads as a protocol
    /// fault, an argument fault cannot happen here and reads the same.
    pub(crate) fn from_client(e: ClientError) -> Self {
        match e {
            ClientError::ServerGone(s) => ConnectError::ServerGone(s),
            ClientError::Timeout(t) => ConnectError::Timeout(t),
            ClientError::VersionMismatch {
                service,
                server,
                client,
            } => ConnectError::VersionMismatch {
                service,
                server,
                client,
            },
            ClientError::Incompatible { service, cause } => {
                ConnectError::Incompatible { service, cause }
            }
            ClientError::PermissionDenied(s) => ConnectError::PermissionDenied(s),
            ClientError::TooManyClients(s) => ConnectError::TooManyClients(s),
            ClientError::Ipc(s) => ConnectError::Ipc(s),
            ClientError::Protocol(s) => ConnectError::Protocol(s),
            other => ConnectError::Protocol(other.to_string()),
        }
    }
}

impl From<ConnectError> for ClientError {
    /// The same fault in the error every call can return.
    fn from(e: ConnectError) -> Self {
        match e {
            ConnectError::ServerGone(s) => ClientError::ServerGone(s),
            ConnectError::Timeout(t) => ClientError::Timeout(t),
            ConnectError::VersionMismatch {
                service,
                server,
                client,
            } => ClientError::VersionMismatch {
                service,
                server,
                client,
            },
            ConnectError::Incompatible { service, cause } => {
                ClientError::Incompatible { service, cause }
            }
            ConnectError::PermissionDenied(s) => ClientError::PermissionDenied(s),
            ConnectError::TooManyClients(s) => ClientError::TooManyClients(s),
            ConnectError::Protocol(s) => ClientError::Protocol(s),
            ConnectError::Ipc(s) => ClientError::Ipc(s),
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn connect_errors_become_the_same_client_errors_and_back() {
        let cases = [
            ConnectError::ServerGone("s".into()),
            ConnectError::Timeout(Duration::from_millis(5)),
            ConnectError::VersionMismatch {
                service: "s".into(),
                server: 3,
                client: 2,
            },
            ConnectError::Incompatible {
                service: "s".into(),
                cause: "c".into(),
            },
            ConnectError::PermissionDenied("s".into()),
            ConnectError::TooManyClients("s".into()),
            ConnectError::Protocol("p".into()),
            ConnectError::Ipc("i".into()),
        ];
        for e in cases {
            let client = ClientError::from(e.clone());
            assert_eq!(ConnectError::from_client(client.clone()), e);
            // Python and C read the `ClientError`: same words where the
            // fault is the same, no code (none names a connection fault).
            assert_eq!(client.code(), None);
        }
        assert_eq!(
            ClientError::from(ConnectError::ServerGone("gjkd".into())).to_string(),
            ConnectError::ServerGone("gjkd".into()).to_string()
        );
        // What no server sends to a greeting reads as a protocol fault.
        assert_eq!(
            ConnectError::from_client(ClientError::Rejected(ErrorCode::Malformed)),
            ConnectError::Protocol("request refused: malformed request".into())
        );
    }

    #[test]
    fn faults_found_before_sending_carry_the_servers_codes() {
        assert_eq!(
            ClientError::InvalidRobot("x".into()).code(),
            Some(ErrorCode::InvalidRobot)
        );
        assert_eq!(
            ClientError::UnknownJoint("x".into()).code(),
            Some(ErrorCode::UnknownName)
        );
        assert_eq!(ClientError::InvalidMesh("x".into()).code(), None);
        assert_eq!(
            ClientError::Rejected(ErrorCode::NotOwner).code(),
            Some(ErrorCode::NotOwner)
        );
        assert_eq!(ClientError::InvalidArgument("x").code(), None);
    }
}
