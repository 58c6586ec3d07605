//! A short time slice for an ordinary (`SCHED_OTHER`) thread: how a thread
//! that sleeps between requests gets woken at once on a busy CPU without
//! any privilege.
//!
//! Linux's fair scheduler (EEVDF, since 6.6) lets the running thread finish
//! its slice before a woken one runs, unless the woken one asked for a
//! shorter slice (since 6.12, `sched_attr.sched_runtime` of a `SCHED_OTHER`
//! thread): then its earlier deadline preempts the neighbour at the wake-up.
//! Without it, a server woken on a CPU where a busy process runs waits for
//! that process's slice to end, which the timer tick (4 ms at the common
//! 250 Hz) rounds up. The request changes no share of the CPU, only how it
//! is cut: the thread runs as often, in shorter pieces. Older kernels
//! accept the call and ignore the slice.

use std::time::Duration;

/// The shortest slice the kernel accepts (100 µs); shorter requests are
/// raised to it.
pub const MIN_SLICE: Duration = Duration::from_micros(100);

/// The kernel's `struct sched_attr` (version 1, 56 bytes).
#[repr(C)]
struct SchedAttr {
    size: u32,
    sched_policy: u32,
    sched_flags: u64,
    sched_nice: i32,
    sched_priority: u32,
    sched_runtime: u64,
    sched_deadline: u64,
    sched_period: u64,
    sched_util_min: u32,
    sched_util_max: u32,
}

/// Asks for time slices of `slice` (at least [`MIN_SLICE`]) for the calling
/// thread, keeping it an ordinary `SCHED_OTHER` thread at its nice value.
/// Threads it starts later inherit the request.
///
/// # Errors
/// What the kernel said: a thread under a real-time policy is left alone
/// (`EPERM` would not be the cause; this call only asks for `SCHED_OTHER`),
/// and a kernel without `sched_setattr` says `ENOSYS`.
pub fn request_short_slice(slice: Duration) -> std::io::Result<()> {
    let slice = slice.max(MIN_SLICE);
    // SAFETY: getpriority takes plain integers; errno is cleared first
    // because -1 is a valid nice value.
    let nice = unsafe {
        *libc::__errno_location() = 0;
        libc::getpriority(libc::PRIO_PROCESS, 0)
    };
    let attr = SchedAttr {
        size: std::mem::size_of::<SchedAttr>() as u32,
        sched_policy: libc::SCHED_OTHER as u32,
        sched_flags: 0,
        sched_nice: nice,
        sched_priority: 0,
        sched_runtime: u64::try_from(slice.as_nanos()).unwrap_or(u64::MAX),
        sched_deadline: 0,
        sched_period: 0,
        sched_util_min: 0,
        sched_util_max: 0,
    };
    // SAFETY: sched_setattr(pid 0 = calling thread, a valid sched_attr of
    // the size it says, flags 0) reads the struct and nothing else.
    let rc = unsafe { libc::syscall(libc::SYS_sched_setattr, 0, &attr, 0u32) };
    if rc == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

/// The slice the calling thread asked for, if any (`sched_runtime` as
/// `sched_getattr` reports it; 0 when it never asked or the kernel has no
/// custom slices).
///
/// # Errors
/// What the kernel said.
pub fn current_slice() -> std::io::Result<Duration> {
    let mut attr = SchedAttr {
        size: 0,
        sched_policy: 0,
        sched_flags: 0,
        sched_nice: 0,
        sched_priority: 0,
        sched_runtime: 0,
        sched_deadline: 0,
        sched_period: 0,
        sched_util_min: 0,
        sched_util_max: 0,
    };
    // SAFETY: sched_getattr writes at most `size` bytes into `attr`.
    let rc = unsafe {
        libc::syscall(
            libc::SYS_sched_getattr,
            0,
            &mut attr,
            std::mem::size_of::<SchedAttr>() as u32,
            0u32,
        )
    };
    if rc == 0 {
        Ok(Duration::from_nanos(attr.sched_runtime))
    } else {
        Err(std::io::Error::last_os_error())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_requested_slice_is_what_the_kernel_reports_and_stays_ordinary() {
        std::thread::spawn(|| {
            request_short_slice(Duration::from_micros(300)).expect("sched_setattr");
            // SAFETY: pid 0 is the calling thread.
            assert_eq!(unsafe { libc::sched_getscheduler(0) }, libc::SCHED_OTHER);
            let slice = current_slice().expect("sched_getattr");
            // Kernels before 6.12 keep no custom slice and report their
            // default; those after report the request.
            if slice == Duration::from_micros(300) {
                request_short_slice(Duration::from_micros(1)).expect("raised to the minimum");
                assert_eq!(current_slice().expect("sched_getattr"), MIN_SLICE);
            }
        })
        .join()
        .expect("thread");
    }
}
