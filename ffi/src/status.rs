//! Status codes, the thread-local last error, and the guard every entry
//! point runs its body in (so that no panic crosses the C boundary).

use std::cell::{Cell, RefCell};
use std::ffi::{CStr, CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

use rust_client::{ClientError, ErrorCode};

/// What a call returns. `GJKD_OK` (0) is success; every other value is a
/// failure, described in words by `gjkd_last_error()`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(non_camel_case_types)]
pub enum gjkd_status {
    /// Success.
    GJKD_OK = 0,
    /// No server serves the service: it was never started, it stopped or it
    /// died. The next call on the same handle tries to reconnect.
    GJKD_ERR_SERVER_GONE = 1,
    /// The server is alive but did not answer within the handle's timeout.
    GJKD_ERR_TIMEOUT = 2,
    /// The server refused the request: `gjkd_last_error_code()` says why
    /// (a `gjkd_error_code`). Nothing was changed.
    GJKD_ERR_REJECTED = 3,
    /// An argument is out of its domain (a count too large, a timeout that
    /// is not positive, a pose that is not finite or not a unit quaternion,
    /// a name that is not UTF-8 or too long, bad query options). Nothing was
    /// sent.
    GJKD_ERR_INVALID_ARGUMENT = 4,
    /// A pointer that must not be NULL was NULL. Nothing was sent.
    GJKD_ERR_NULL_POINTER = 5,
    /// No longer returned: a handle may be used from any thread, one call
    /// at a time (see `GJKD_ERR_BUSY`). Kept so that code naming it
    /// still compiles.
    GJKD_ERR_WRONG_THREAD = 6,
    /// A server serves the name with another protocol version than this
    /// library's `GJKD_PROTOCOL_VERSION`.
    GJKD_ERR_VERSION_MISMATCH = 7,
    /// A service of this name exists but was made by another program or
    /// another build of gjkd.
    GJKD_ERR_INCOMPATIBLE = 8,
    /// The service belongs to another user.
    GJKD_ERR_PERMISSION_DENIED = 9,
    /// The server admits no more clients.
    GJKD_ERR_TOO_MANY_CLIENTS = 10,
    /// The server answered something this library does not understand.
    GJKD_ERR_PROTOCOL = 11,
    /// Shared memory or another local resource failed.
    GJKD_ERR_IPC = 12,
    /// A bug inside the library was caught before it reached the caller;
    /// the handle may be left in any state but is safe to close.
    GJKD_ERR_PANIC = 13,
    /// The handle was in a call on another thread at that moment: a handle
    /// serves one call at a time, from any thread. Nothing was sent; hold
    /// a mutex around the handle's calls, or use one handle per thread.
    GJKD_ERR_BUSY = 14,
}

use gjkd_status::*;

/// A failed call: its status, the server's code (for rejections) and the
/// words.
#[derive(Debug)]
pub struct Failure {
    /// The status returned.
    pub status: gjkd_status,
    /// The `gjkd_error_code` of a rejection, 0 otherwise.
    pub code: u32,
    /// What went wrong.
    pub message: String,
}

impl Failure {
    /// A failure with no server code.
    pub fn new(status: gjkd_status, message: impl Into<String>) -> Self {
        Failure {
            status,
            code: 0,
            message: message.into(),
        }
    }

    /// A NULL where a pointer is required.
    pub fn null(what: &str) -> Self {
        Failure::new(GJKD_ERR_NULL_POINTER, format!("{what} is NULL"))
    }

    /// An argument out of its domain.
    pub fn invalid(message: impl Into<String>) -> Self {
        Failure::new(GJKD_ERR_INVALID_ARGUMENT, message)
    }

    /// An argument out of its domain, found here before anything was
    /// sent, that the server refuses with `code`: the caller sees the
    /// same code whichever side finds the fault.
    pub fn invalid_code(code: ErrorCode, message: impl Into<String>) -> Self {
        Failure {
            code: code.raw(),
            ..Failure::invalid(message)
        }
    }

    /// A refusal by the server with `code`.
    pub fn rejected(code: ErrorCode, context: &str) -> Self {
        Failure {
            status: GJKD_ERR_REJECTED,
            code: code.raw(),
            message: format!("{context}refused: {} ({})", code, code_name(code.raw())),
        }
    }
}

impl<E: Into<ClientError>> From<E> for Failure {
    /// Every operation's error (`RegisterError`, `QueryError`, ...) read
    /// through the umbrella `ClientError`, so that one fault has one status
    /// and one code whichever call met it.
    fn from(e: E) -> Self {
        let e: ClientError = e.into();
        let status = match &e {
            ClientError::ServerGone(_) => GJKD_ERR_SERVER_GONE,
            ClientError::Timeout(_) => GJKD_ERR_TIMEOUT,
            ClientError::Rejected(code) => return Failure::rejected(*code, ""),
            ClientError::ResultBufferTooSmall { .. }
            | ClientError::InvalidArgument(_)
            | ClientError::InvalidRobot(_)
            | ClientError::UnknownJoint(_)
            | ClientError::InvalidMesh(_) => GJKD_ERR_INVALID_ARGUMENT,
            ClientError::Protocol(_) => GJKD_ERR_PROTOCOL,
            ClientError::VersionMismatch { .. } => GJKD_ERR_VERSION_MISMATCH,
            ClientError::Incompatible { .. } => GJKD_ERR_INCOMPATIBLE,
            ClientError::PermissionDenied(_) => GJKD_ERR_PERMISSION_DENIED,
            ClientError::TooManyClients(_) => GJKD_ERR_TOO_MANY_CLIENTS,
            ClientError::Ipc(_) => GJKD_ERR_IPC,
        };
        // A fault found before sending carries the code the server gives
        // it (an unreadable robot, an unknown joint), as in Rust and Python.
        Failure {
            code: e.code().map_or(0, ErrorCode::raw),
            ..Failure::new(status, e.to_string())
        }
    }
}

thread_local! {
    static LAST_MESSAGE: RefCell<CString> = RefCell::new(CString::default());
    static LAST_CODE: Cell<u32> = const { Cell::new(0) };
}

/// Records `failure` as this thread's last error and returns its status.
fn record(function: &str, failure: Failure) -> gjkd_status {
    // Interior NULs cannot come from our own messages, but a name a caller
    // passed could in principle be echoed: drop them rather than fail.
    let text = format!("{function}: {}", failure.message).replace('\0', "");
    let message = CString::new(text).unwrap_or_default();
    LAST_MESSAGE.with(|m| *m.borrow_mut() = message);
    LAST_CODE.with(|c| c.set(failure.code));
    failure.status
}

/// Runs the body of the entry point `function`: its failure becomes the
/// thread's last error, a panic becomes `GJKD_ERR_PANIC`.
pub fn guard(function: &str, body: impl FnOnce() -> Result<(), Failure>) -> gjkd_status {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => GJKD_OK,
        Ok(Err(failure)) => record(function, failure),
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            record(
                function,
                Failure::new(GJKD_ERR_PANIC, format!("internal error: {what}")),
            )
        }
    }
}

/// The message of the last failed call on this thread ("" if none).
pub fn last_message() -> *const c_char {
    LAST_MESSAGE.with(|m| m.borrow().as_ptr())
}

/// The server's code of the last failed call on this thread.
pub fn last_code() -> u32 {
    LAST_CODE.with(Cell::get)
}

/// The `GJKD_CODE_*` name of error code `raw`.
pub fn code_name(raw: u32) -> &'static str {
    const NAMES: [&str; 23] = [
        "GJKD_CODE_OK",
        "GJKD_CODE_UNKNOWN_OBJECT",
        "GJKD_CODE_NON_FINITE_POSE",
        "GJKD_CODE_BAD_QUATERNION",
        "GJKD_CODE_INVALID_OPTIONS",
        "GJKD_CODE_EMPTY_VERTICES",
        "GJKD_CODE_TOO_MANY_VERTICES",
        "GJKD_CODE_INVALID_RADIUS",
        "GJKD_CODE_BATCH_TOO_LARGE",
        "GJKD_CODE_EMPTY_BATCH",
        "GJKD_CODE_MALFORMED",
        "GJKD_CODE_NOT_OWNER",
        "GJKD_CODE_READ_ONLY",
        "GJKD_CODE_TOO_MANY_PIECES",
        "GJKD_CODE_EMPTY_COMPOUND",
        "GJKD_CODE_NON_FINITE_VERTEX",
        "GJKD_CODE_UNKNOWN_NAME",
        "GJKD_CODE_NAME_TAKEN",
        "GJKD_CODE_TOO_MANY_OBJECTS",
        "GJKD_CODE_INTERNAL",
        "GJKD_CODE_STORAGE_FULL",
        "GJKD_CODE_OUT_OF_LIMITS",
        "GJKD_CODE_INVALID_ROBOT",
    ];
    NAMES
        .get(raw as usize)
        .copied()
        .unwrap_or("GJKD_CODE_UNKNOWN")
}

/// The name of status value `raw` (`"GJKD_ERR_TIMEOUT"`, ...).
pub fn status_name(raw: i32) -> &'static CStr {
    const NAMES: [&CStr; 15] = [
        c"GJKD_OK",
        c"GJKD_ERR_SERVER_GONE",
        c"GJKD_ERR_TIMEOUT",
        c"GJKD_ERR_REJECTED",
        c"GJKD_ERR_INVALID_ARGUMENT",
        c"GJKD_ERR_NULL_POINTER",
        c"GJKD_ERR_WRONG_THREAD",
        c"GJKD_ERR_VERSION_MISMATCH",
        c"GJKD_ERR_INCOMPATIBLE",
        c"GJKD_ERR_PERMISSION_DENIED",
        c"GJKD_ERR_TOO_MANY_CLIENTS",
        c"GJKD_ERR_PROTOCOL",
        c"GJKD_ERR_IPC",
        c"GJKD_ERR_PANIC",
        c"GJKD_ERR_BUSY",
    ];
    usize::try_from(raw)
        .ok()
        .and_then(|i| NAMES.get(i).copied())
        .unwrap_or(c"GJKD_ERR_UNKNOWN")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn message() -> String {
        // SAFETY: last_message points to a live NUL-terminated string.
        unsafe { CStr::from_ptr(last_message()) }
            .to_string_lossy()
            .into_owned()
    }

    #[test]
    fn a_panic_is_caught_and_reported() {
        let status = guard("gjkd_test", || panic!("boom {}", 7));
        assert_eq!(status, GJKD_ERR_PANIC);
        assert_eq!(message(), "gjkd_test: internal error: boom 7");
        assert_eq!(last_code(), 0);
    }

    #[test]
    fn a_failure_sets_message_and_code_and_success_leaves_them() {
        let status = guard("gjkd_test", || {
            Err(Failure::rejected(ErrorCode::NameTaken, "row 3: "))
        });
        assert_eq!(status, GJKD_ERR_REJECTED);
        assert_eq!(
            message(),
            "gjkd_test: row 3: refused: name already taken (GJKD_CODE_NAME_TAKEN)"
        );
        assert_eq!(last_code(), ErrorCode::NameTaken.raw());
        assert_eq!(guard("gjkd_other", || Ok(())), GJKD_OK);
        assert_eq!(last_code(), ErrorCode::NameTaken.raw());
        // A NUL inside a message cannot end it early.
        guard("gjkd_test", || Err(Failure::invalid("a\0b")));
        assert_eq!(message(), "gjkd_test: ab");
        assert_eq!(last_code(), 0);
    }

    #[test]
    fn client_errors_map_to_their_statuses() {
        use std::time::Duration;
        let cases = [
            (ClientError::ServerGone("s".into()), GJKD_ERR_SERVER_GONE),
            (
                ClientError::Timeout(Duration::from_secs(1)),
                GJKD_ERR_TIMEOUT,
            ),
            (ClientError::InvalidArgument("x"), GJKD_ERR_INVALID_ARGUMENT),
            (ClientError::Protocol("p".into()), GJKD_ERR_PROTOCOL),
            (
                ClientError::VersionMismatch {
                    service: "s".into(),
                    server: 2,
                    client: 1,
                },
                GJKD_ERR_VERSION_MISMATCH,
            ),
            (
                ClientError::Incompatible {
                    service: "s".into(),
                    cause: "c".into(),
                },
                GJKD_ERR_INCOMPATIBLE,
            ),
            (
                ClientError::PermissionDenied("s".into()),
                GJKD_ERR_PERMISSION_DENIED,
            ),
            (
                ClientError::TooManyClients("s".into()),
                GJKD_ERR_TOO_MANY_CLIENTS,
            ),
            (ClientError::Ipc("i".into()), GJKD_ERR_IPC),
        ];
        for (e, want) in cases {
            let words = e.to_string();
            let f = Failure::from(e);
            assert_eq!(f.status, want);
            assert_eq!(f.message, words);
            assert_eq!(f.code, 0);
        }
        let f = Failure::from(ClientError::Rejected(ErrorCode::UnknownObject));
        assert_eq!((f.status, f.code), (GJKD_ERR_REJECTED, 1));
        // Faults the client finds carry the server's code for them, the
        // same as Rust's `ClientError::code` and Python's `code`.
        let cases = [
            (ClientError::InvalidRobot("bad".into()), 22),
            (ClientError::UnknownJoint("nope".into()), 16),
            (ClientError::InvalidMesh("gone.stl".into()), 0),
        ];
        for (e, code) in cases {
            let words = e.to_string();
            let f = Failure::from(e);
            assert_eq!((f.status, f.code), (GJKD_ERR_INVALID_ARGUMENT, code));
            assert_eq!(f.message, words);
        }
        assert_eq!(code_name(22), "GJKD_CODE_INVALID_ROBOT");
        assert_eq!(code_name(16), "GJKD_CODE_UNKNOWN_NAME");
    }

    #[test]
    fn operation_errors_have_the_status_and_code_of_the_same_client_error() {
        use rust_client::{
            ConnectError, LookupError, PoseError, QueryError, RegisterError, RobotError, SceneError,
        };
        /// The failure of `e` is that of its `ClientError`, word for word.
        fn same<E: Clone + Into<ClientError>>(e: E) -> Failure {
            let via = Failure::from(e.clone().into());
            let f = Failure::from(e);
            assert_eq!(
                (f.status, f.code, &f.message),
                (via.status, via.code, &via.message)
            );
            f
        }
        let f = same(RegisterError::NameTaken);
        assert_eq!((f.status, f.code), (GJKD_ERR_REJECTED, 17));
        let f = same(PoseError::NonFinitePose);
        assert_eq!((f.status, f.code), (GJKD_ERR_REJECTED, 2));
        let f = same(QueryError::ResultBufferTooSmall { needed: 2, got: 1 });
        assert_eq!((f.status, f.code), (GJKD_ERR_INVALID_ARGUMENT, 0));
        let f = same(LookupError::NameTooLong);
        assert_eq!((f.status, f.code), (GJKD_ERR_INVALID_ARGUMENT, 0));
        let f = same(RobotError::UnknownJoint("j".into()));
        assert_eq!((f.status, f.code), (GJKD_ERR_INVALID_ARGUMENT, 16));
        let f = same(RobotError::UnknownRobot);
        assert_eq!((f.status, f.code), (GJKD_ERR_REJECTED, 16));
        let f = same(SceneError::Connection(ConnectError::ServerGone("s".into())));
        assert_eq!((f.status, f.code), (GJKD_ERR_SERVER_GONE, 0));
    }
}
