//! `gjkd.pin_thread` and `gjkd.set_realtime_priority`: where and how
//! urgently the calling thread runs (`gjkd_client::rt`), for the thread
//! that sends queries. docs/deployment.md says when each pays.

use gjkd_client::rt::{self, PinError, PriorityError};
use pyo3::prelude::*;

use crate::errors::{Kind, Raise};

/// Pins the calling thread to CPU `cpu` (an int): from now on it runs there
/// and nowhere else. Put the thread that sends queries on a CPU other than
/// the server's (``gjkd.Server(cpu=...)``) and away from busy processes.
///
/// Raises :class:`gjkd.InvalidInput` (``field`` ``"cpu"``) for a CPU that
/// does not exist or is outside this process's cpuset (the message lists
/// the allowed ones), :class:`gjkd.IpcError` for any other refusal. On
/// error the thread's affinity is unchanged.
#[pyfunction]
pub fn pin_thread(py: Python<'_>, cpu: usize) -> PyResult<()> {
    rt::pin_current_thread(cpu).map_err(|e| {
        let kind = match e {
            PinError::NoSuchCpu { .. } | PinError::NotAllowed { .. } => Kind::InvalidInput,
            PinError::Os { .. } => Kind::Ipc,
        };
        Raise {
            kind,
            message: e.to_string(),
            code: None,
            field: Some("cpu"),
            index: None,
        }
        .into_err(py)
    })
}

/// Runs the calling thread under ``SCHED_FIFO`` at ``priority`` (1 to 99):
/// when the server's answer wakes it, it preempts any ordinary process on
/// its CPU at once.
///
/// Raises :class:`gjkd.InvalidInput` (``field`` ``"priority"``) outside 1
/// to 99, :class:`gjkd.AccessDenied` when the process has neither the
/// capability ``CAP_SYS_NICE`` nor an ``RLIMIT_RTPRIO`` of at least
/// ``priority`` (the message says how to grant either),
/// :class:`gjkd.IpcError` for any other refusal. On error nothing changed.
#[pyfunction]
pub fn set_realtime_priority(py: Python<'_>, priority: i32) -> PyResult<()> {
    rt::set_realtime_priority(priority).map_err(|e| {
        let kind = match e {
            PriorityError::OutOfRange { .. } => Kind::InvalidInput,
            PriorityError::NotPermitted { .. } => Kind::AccessDenied,
            PriorityError::Os { .. } => Kind::Ipc,
        };
        Raise {
            kind,
            message: e.to_string(),
            code: None,
            field: Some("priority"),
            index: None,
        }
        .into_err(py)
    })
}
