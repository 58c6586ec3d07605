//! Objects that end with their client: what a client registered with
//! [`ClientBuilder::remove_on_close`](crate::ClientBuilder::remove_on_close)
//! set is removed when the [`Client`] is dropped, so that test runs and
//! short-lived programs leave nothing behind on a server that persists
//! objects across restarts.

use gjkd_proto::ObjectId;

use crate::{Client, ConnectError, RemoveError, RobotError};

/// What this client registered to end with it.
#[derive(Debug, Default)]
pub(crate) struct EndWithClient {
    /// Whether registrations are noted (the builder's choice).
    on: bool,
    objects: Vec<ObjectId>,
    robots: Vec<String>,
}

impl EndWithClient {
    /// Nothing noted yet; registrations are noted if `on`.
    pub(crate) fn new(on: bool) -> Self {
        EndWithClient {
            on,
            ..Default::default()
        }
    }

    /// Notes an object this client registered.
    pub(crate) fn object(&mut self, id: ObjectId) {
        if self.on {
            self.objects.push(id);
        }
    }

    /// Notes a robot this client attached (by name: robots are removed
    /// by name, whole). Only a client with robots attaches them.
    #[cfg(feature = "robots")]
    pub(crate) fn robot(&mut self, name: &str) {
        if self.on && !self.robots.iter().any(|r| r == name) {
            self.robots.push(name.to_owned());
        }
    }

    /// Forgets an object removed by the caller.
    pub(crate) fn removed(&mut self, id: ObjectId) {
        self.objects.retain(|&o| o != id);
    }

    /// Forgets a robot removed by the caller.
    pub(crate) fn removed_robot(&mut self, name: &str) {
        self.robots.retain(|r| r != name);
    }
}

impl Drop for Client {
    /// Removes what was registered to end with the client: robots whole,
    /// then the other objects (a robot's links are gone with it already).
    /// Best effort within the call timeout: a server gone keeps them (and,
    /// with persistence, reloads them), so the first connection failure
    /// ends the clean-up rather than waiting a timeout per object.
    fn drop(&mut self) {
        let robots = std::mem::take(&mut self.ending.robots);
        let objects = std::mem::take(&mut self.ending.objects);
        let gone =
            |e: &ConnectError| matches!(e, ConnectError::ServerGone(_) | ConnectError::Timeout(_));
        for name in robots {
            if let Err(RobotError::Connection(e)) = self.remove_robot(&name)
                && gone(&e)
            {
                return;
            }
        }
        for id in objects {
            if let Err(RemoveError::Connection(e)) = self.remove(id)
                && gone(&e)
            {
                return;
            }
        }
    }
}
