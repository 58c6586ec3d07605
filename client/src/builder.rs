//! Configuring and opening a [`Client`].

use std::time::{Duration, Instant};

use iceoryx2::prelude::*;

use crate::connection::TokenSource;
use crate::{Client, ClientError, ConnectError, ipc_err};
#[cfg(doc)]
use gjkd_proto::DEFAULT_SERVICE;

/// Timeout of every call unless set with [`ClientBuilder::timeout`]: one
/// second.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(1);

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

/// Configures and opens a [`Client`].
#[derive(Clone, Debug)]
pub struct ClientBuilder {
    service: String,
    timeout: Duration,
    connect_timeout: Option<Duration>,
    remove_on_close: bool,
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

    /// Whether what the client registers ends with it (default `false`):
    /// objects it registers and robots it attaches are removed (robots
    /// whole) when the [`Client`] is dropped. Without it objects outlive
    /// their client, and a server with persistence keeps them across
    /// restarts: right for a scene that must stay, wrong for tests and
    /// short-lived programs, whose objects pile up. Best effort: a server
    /// that is gone when the client ends keeps them. Objects found again
    /// by name ([`Client::register_named_or_get`]) are not the client's to
    /// end. (C: `gjkd_set_registration_options`'s `remove_on_close`.)
    pub fn remove_on_close(mut self, yes: bool) -> Self {
        self.remove_on_close = yes;
        self
    }

    /// Connects, waiting up to the connect timeout for a server to come up.
    ///
    /// # Errors
    /// [`ConnectError::ServerGone`] if no server serves the name within the
    /// timeout; [`ConnectError::VersionMismatch`],
    /// [`ConnectError::Incompatible`], [`ConnectError::PermissionDenied`] or
    /// [`ConnectError::TooManyClients`] at once if a service of that name
    /// exists but this client cannot use it; [`ConnectError::Ipc`] if
    /// iceoryx2 cannot set up this process.
    pub fn connect(self) -> Result<Client, ConnectError> {
        quiet_iceoryx2_notices();
        let node = NodeBuilder::new()
            .name(
                &NodeName::new("gjkd-client")
                    .map_err(ipc_err("node name"))
                    .map_err(ConnectError::from_client)?,
            )
            .create::<ipc::Service>()
            .map_err(ipc_err("node"))
            .map_err(ConnectError::from_client)?;
        let mut client = Client {
            service: self.service,
            timeout: self.timeout,
            node,
            conn: None,
            vertex_scratch: Vec::new(),
            tokens: TokenSource::new(),
            split_scratch: Default::default(),
            ending: crate::ending::EndWithClient::new(self.remove_on_close),
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
                Err(e) => return Err(ConnectError::from_client(e)),
            }
        }
    }
}

impl Client {
    /// A builder for a client of the deployment named `service` (the server's
    /// `--service`, default [`DEFAULT_SERVICE`]).
    pub fn builder(service: &str) -> ClientBuilder {
        ClientBuilder {
            service: service.to_owned(),
            timeout: DEFAULT_TIMEOUT,
            connect_timeout: None,
            remove_on_close: false,
        }
    }

    /// Connects to the server of `service` with the default timeout, waiting
    /// up to that long for it to come up.
    ///
    /// # Errors
    /// As [`ClientBuilder::connect`].
    pub fn connect(service: &str) -> Result<Self, ConnectError> {
        Self::builder(service).connect()
    }
}
