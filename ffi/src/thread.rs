//! Where and how urgently the calling thread runs: the C face of
//! `gjkd_client::rt` (docs/deployment.md says when each pays).

use rust_client::rt::{self, PinError, PriorityError};

use crate::status::{Failure, gjkd_status, guard};

/// Pins the calling thread to CPU `cpu`: from now on it runs there and
/// nowhere else (threads it starts later inherit the pin). Pin the thread
/// that sends queries to a CPU other than the server's (`gjkd serve --cpu
/// N`) and away from busy processes.
///
/// Errors: `GJKD_ERR_INVALID_ARGUMENT` (no such CPU, or one outside this
/// process's cpuset: `gjkd_last_error()` lists the allowed ones),
/// `GJKD_ERR_IPC` (any other refusal by the kernel). On error the thread's
/// affinity is unchanged.
#[unsafe(no_mangle)]
pub extern "C" fn gjkd_pin_thread(cpu: u32) -> gjkd_status {
    guard("gjkd_pin_thread", || {
        rt::pin_current_thread(cpu as usize).map_err(|e| {
            let status = match e {
                PinError::NoSuchCpu { .. } | PinError::NotAllowed { .. } => {
                    gjkd_status::GJKD_ERR_INVALID_ARGUMENT
                }
                PinError::Os { .. } => gjkd_status::GJKD_ERR_IPC,
            };
            Failure::new(status, e.to_string())
        })
    })
}

/// Runs the calling thread under `SCHED_FIFO` at `priority` (1 to 99): when
/// the server's answer wakes it, it preempts any ordinary process on its
/// CPU at once. Threads it starts later inherit it.
///
/// Errors: `GJKD_ERR_INVALID_ARGUMENT` (outside 1 to 99),
/// `GJKD_ERR_PERMISSION_DENIED` (the process has neither the capability
/// `CAP_SYS_NICE` nor an `RLIMIT_RTPRIO` of at least `priority`;
/// `gjkd_last_error()` says how to grant either), `GJKD_ERR_IPC` (any
/// other refusal). On error nothing changed.
#[unsafe(no_mangle)]
pub extern "C" fn gjkd_set_realtime_priority(priority: i32) -> gjkd_status {
    guard("gjkd_set_realtime_priority", || {
        rt::set_realtime_priority(priority).map_err(|e| {
            let status = match e {
                PriorityError::OutOfRange { .. } => gjkd_status::GJKD_ERR_INVALID_ARGUMENT,
                PriorityError::NotPermitted { .. } => gjkd_status::GJKD_ERR_PERMISSION_DENIED,
                PriorityError::Os { .. } => gjkd_status::GJKD_ERR_IPC,
            };
            Failure::new(status, e.to_string())
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::CStr;

    fn last_error() -> String {
        // SAFETY: the library's own thread-local message.
        unsafe { CStr::from_ptr(crate::gjkd_last_error()) }
            .to_string_lossy()
            .into_owned()
    }

    #[test]
    fn a_bad_cpu_is_an_invalid_argument_naming_it() {
        std::thread::spawn(|| {
            assert_eq!(
                gjkd_pin_thread(1 << 20),
                gjkd_status::GJKD_ERR_INVALID_ARGUMENT
            );
            assert!(last_error().contains("gjkd_pin_thread: CPU 1048576 does not exist"));
            let cpu = rt::allowed_cpus().expect("affinity")[0];
            assert_eq!(gjkd_pin_thread(cpu as u32), gjkd_status::GJKD_OK);
            assert_eq!(rt::allowed_cpus().expect("affinity"), vec![cpu]);
        })
        .join()
        .expect("thread");
    }

    #[test]
    fn a_priority_out_of_range_is_an_invalid_argument() {
        assert_eq!(
            gjkd_set_realtime_priority(0),
            gjkd_status::GJKD_ERR_INVALID_ARGUMENT
        );
        assert!(
            last_error().contains("out of range: 1 to 99"),
            "{}",
            last_error()
        );
    }
}
