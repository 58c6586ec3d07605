//! Calls on the Rust client with the GIL released: what the robot calls
//! need of `gjkd.Client`, so that they do not depend on the class itself.

use gjkd_client::ClientError;
use pyo3::prelude::*;

/// A holder of a Rust client that runs calls on it with the GIL released.
pub trait RustCall {
    /// Runs `call` on the Rust client; the outer error is the holder's
    /// own (a closed client), the inner one the call's, whichever
    /// operation's error it was (`RegisterError`, `QueryError`, ...), read
    /// as the umbrella [`ClientError`]: one fault, one Python exception
    /// and code (`errors::client`).
    fn call<R, E: Into<ClientError>>(
        &mut self,
        py: Python<'_>,
        call: impl FnOnce(&mut gjkd_client::Client) -> Result<R, E>,
    ) -> PyResult<Result<R, ClientError>>;
}
