//! Opening and closing a handle, what the server says about itself, and
//! the thread's last error.

use std::ffi::{CString, c_char};
use std::sync::OnceLock;
use std::time::Duration;

use rust_client::{Client, ErrorCode};

use crate::args::{opt_str, out};
use crate::handle::{gjkd_client, with_client};
use crate::status::{self, Failure, gjkd_status, guard};
use crate::types::{gjkd_info, gjkd_query_options, gjkd_server_stats};

/// A positive, finite number of seconds.
fn seconds(s: f64, what: &str) -> Result<Duration, Failure> {
    Duration::try_from_secs_f64(s)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or_else(|| Failure::invalid(format!("{what} must be a positive number of seconds")))
}

/// Connects to the gjkd server of `service` and returns a new handle in
/// `*out_client`.
///
/// - `service`: the server's `--service` name; NULL means `"gjkd"`, the
///   default of `gjkd serve`. Copied; not kept.
/// - `timeout_s`: seconds every later call waits for an answer (positive;
///   1.0 is the usual choice).
/// - `connect_timeout_s`: seconds this call waits for a server to come up;
///   0 means `timeout_s`.
/// - `out_client`: receives the handle, owned by the caller, to be freed
///   with `gjkd_close()`; set to NULL on failure.
///
/// The handle may be used from any thread, one call at a time: a call
/// made while another thread's call is using it returns `GJKD_ERR_BUSY`
/// and sends nothing. So a handle may be created on one thread, used on
/// others (a ROS 2 `MultiThreadedExecutor` runs one callback group's
/// callbacks on any of its threads) and closed on yet another. Share one
/// handle between callbacks that may run at once only behind a mutex (or
/// a `MutuallyExclusive` callback group), or give each its own handle.
///
/// Errors: `GJKD_ERR_NULL_POINTER` (`out_client`),
/// `GJKD_ERR_INVALID_ARGUMENT` (a timeout, a service name not UTF-8),
/// `GJKD_ERR_SERVER_GONE` (no server within the connect timeout),
/// `GJKD_ERR_VERSION_MISMATCH`, `GJKD_ERR_INCOMPATIBLE`,
/// `GJKD_ERR_PERMISSION_DENIED`, `GJKD_ERR_TOO_MANY_CLIENTS`,
/// `GJKD_ERR_IPC`.
///
/// # Safety
/// `service` is NULL or a NUL-terminated string; `out_client` is NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_connect(
    service: *const c_char,
    timeout_s: f64,
    connect_timeout_s: f64,
    out_client: *mut *mut gjkd_client,
) -> gjkd_status {
    guard("gjkd_connect", || {
        // SAFETY: the caller's promises.
        let slot = unsafe { out(out_client, "out_client") }?;
        *slot = std::ptr::null_mut();
        // SAFETY: the caller's promise.
        let service = unsafe { opt_str(service, "service") }?.unwrap_or("gjkd");
        let timeout = seconds(timeout_s, "timeout_s")?;
        let connect_timeout = if connect_timeout_s == 0.0 {
            timeout
        } else {
            seconds(connect_timeout_s, "connect_timeout_s")?
        };
        let client = Client::builder(service)
            .timeout(timeout)
            .connect_timeout(connect_timeout)
            .connect()?;
        *slot = Box::into_raw(Box::new(gjkd_client::new(client)));
        Ok(())
    })
}

/// Closes the connection and frees the handle, from any thread. NULL is
/// accepted and does nothing. Objects the handle registered stay on the
/// server until removed (and, under a server with persistence, the
/// default, across server restarts too), except those registered while
/// `gjkd_registration_options::remove_on_close` was set, which are removed
/// now.
///
/// Errors: `GJKD_ERR_BUSY` (a call on another thread is using the handle:
/// it is then not freed).
///
/// # Safety
/// `client` is NULL or a handle from `gjkd_connect()` not yet closed; it
/// must not be used after this call returns `GJKD_OK`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_close(client: *mut gjkd_client) -> gjkd_status {
    guard("gjkd_close", || {
        if client.is_null() {
            return Ok(());
        }
        // SAFETY: the caller's promise; the busy flag is checked first.
        unsafe {
            with_client(client, |c| {
                c.remove_doomed();
                Ok(())
            })
        }?;
        // SAFETY: created by Box::into_raw in gjkd_connect, not yet freed.
        drop(unsafe { Box::from_raw(client) });
        Ok(())
    })
}

/// What the server said about itself at the last (re)connection, into
/// `*out_info`.
///
/// Errors: `GJKD_ERR_NULL_POINTER`, `GJKD_ERR_BUSY`,
/// `GJKD_ERR_SERVER_GONE` while disconnected (the next call reconnects).
///
/// # Safety
/// `client` is NULL or a live handle; `out_info` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_server_info(
    client: *mut gjkd_client,
    out_info: *mut gjkd_info,
) -> gjkd_status {
    guard("gjkd_server_info", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let slot = out(out_info, "out_info")?;
                let info = c.client.server_info().ok_or_else(|| {
                    Failure::new(
                        gjkd_status::GJKD_ERR_SERVER_GONE,
                        "not connected (the next call reconnects)",
                    )
                })?;
                *slot = info.into();
                Ok(())
            })
        }
    })
}

/// The server's counters, into `*out_stats` (one round trip).
///
/// Errors: `GJKD_ERR_NULL_POINTER`, `GJKD_ERR_BUSY`,
/// `GJKD_ERR_SERVER_GONE`, `GJKD_ERR_TIMEOUT`.
///
/// # Safety
/// `client` is NULL or a live handle; `out_stats` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn gjkd_stats(
    client: *mut gjkd_client,
    out_stats: *mut gjkd_server_stats,
) -> gjkd_status {
    guard("gjkd_stats", || {
        // SAFETY: the caller's promises.
        unsafe {
            with_client(client, |c| {
                let slot = out(out_stats, "out_stats")?;
                *slot = c.client.stats()?.into();
                Ok(())
            })
        }
    })
}

/// The message of the last call on this thread that failed, in English
/// (`""` if none failed yet). Owned by the library: valid until the next
/// gjkd call on this thread; copy it to keep it. Never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn gjkd_last_error() -> *const c_char {
    status::last_message()
}

/// The `gjkd_error_code` of the last call on this thread that failed: the
/// server's refusal for `GJKD_ERR_REJECTED`; for
/// `GJKD_ERR_INVALID_ARGUMENT`, the code the server gives the same fault,
/// when the library found it before sending (`GJKD_CODE_NON_FINITE_POSE`,
/// `GJKD_CODE_BAD_QUATERNION`, `GJKD_CODE_INVALID_OPTIONS`,
/// `GJKD_CODE_OUT_OF_LIMITS`, `GJKD_CODE_UNKNOWN_NAME`, ...);
/// `GJKD_CODE_OK` (0) when no code applies (a NULL pointer, a count, a
/// connection failure). So one fault has one status and one code whichever
/// call meets it: a NaN pose given to `gjkd_set_pose()`, `gjkd_distance()`
/// or `gjkd_register()`, or a NaN joint position, is
/// `GJKD_ERR_INVALID_ARGUMENT` with `GJKD_CODE_NON_FINITE_POSE`.
#[unsafe(no_mangle)]
pub extern "C" fn gjkd_last_error_code() -> u32 {
    status::last_code()
}

/// The name of a `gjkd_status` value, such as `"GJKD_ERR_TIMEOUT"`
/// (`"GJKD_ERR_UNKNOWN"` for a value that is none). A static string.
#[unsafe(no_mangle)]
pub extern "C" fn gjkd_status_name(status: i32) -> *const c_char {
    status::status_name(status).as_ptr()
}

/// A description of a `gjkd_error_code` value in words, such as
/// `"unknown object id"` (`"unknown error code"` for a value that is
/// none). A static string.
#[unsafe(no_mangle)]
pub extern "C" fn gjkd_error_code_describe(code: u32) -> *const c_char {
    static TEXTS: OnceLock<Vec<CString>> = OnceLock::new();
    let texts = TEXTS.get_or_init(|| {
        ErrorCode::ALL
            .iter()
            .map(|c| CString::new(c.describe()).unwrap_or_default())
            .collect()
    });
    texts
        .get(code as usize)
        .map_or(c"unknown error code".as_ptr(), |t| t.as_ptr())
}

/// The `GJKD_CODE_*` name of a `gjkd_error_code` value, such as
/// `"GJKD_CODE_UNKNOWN_OBJECT"` (`"GJKD_CODE_UNKNOWN"` for a value that is
/// none). A static string.
#[unsafe(no_mangle)]
pub extern "C" fn gjkd_error_code_name(code: u32) -> *const c_char {
    static NAMES: OnceLock<Vec<CString>> = OnceLock::new();
    let names = NAMES.get_or_init(|| {
        (0..=ErrorCode::ALL.len() as u32)
            .map(|c| CString::new(status::code_name(c)).unwrap_or_default())
            .collect()
    });
    let last = names.len() - 1;
    names[(code as usize).min(last)].as_ptr()
}

/// The protocol version this library speaks, equal to
/// `GJKD_PROTOCOL_VERSION` of the header it was built with.
#[unsafe(no_mangle)]
pub extern "C" fn gjkd_protocol_version() -> u32 {
    gjkd_proto::PROTOCOL_VERSION
}

/// The default query options: tolerance `GJKD_DEFAULT_TOLERANCE`,
/// `GJKD_DEFAULT_MAX_ITERATIONS` iterations, no margin, warm start on,
/// double precision.
#[unsafe(no_mangle)]
pub extern "C" fn gjkd_query_options_default() -> gjkd_query_options {
    gjkd_query_options::default()
}
