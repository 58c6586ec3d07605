//! Real-time priority: `SCHED_FIFO`.
//!
//! A `SCHED_FIFO` thread that becomes runnable preempts every ordinary
//! (`SCHED_OTHER`) thread on its CPU at once and keeps the CPU until it
//! sleeps, so a woken server or client never waits behind a busy
//! neighbour's time slice. The price: while it runs, nothing ordinary runs
//! on that CPU (the kernel's real-time throttling, 95 % by default, is the
//! only backstop), so it suits threads that sleep between requests, not a
//! busy-polling one on a shared CPU.

/// Why a real-time priority could not be set.
#[derive(Debug, thiserror::Error)]
pub enum PriorityError {
    /// The priority is outside `SCHED_FIFO`'s range.
    #[error("SCHED_FIFO priority {priority} is out of range: {min} to {max}")]
    OutOfRange {
        /// The priority asked for.
        priority: i32,
        /// The lowest `SCHED_FIFO` priority.
        min: i32,
        /// The highest.
        max: i32,
    },
    /// The kernel refused (EPERM): the process has neither the capability
    /// nor a high enough resource limit.
    #[error(
        "SCHED_FIFO priority {priority} is not permitted: the process needs the capability \
         CAP_SYS_NICE (`setcap cap_sys_nice+ep` on the binary, `--cap-add SYS_NICE` for a \
         container, `AmbientCapabilities=CAP_SYS_NICE` in a systemd unit) or an RLIMIT_RTPRIO \
         of at least {priority} (now {rlimit}: `ulimit -r`, `LimitRTPRIO=` in a systemd unit, \
         `rtprio` in /etc/security/limits.conf); a cgroup with no real-time budget refuses it \
         whatever the capability"
    )]
    NotPermitted {
        /// The priority asked for.
        priority: i32,
        /// The process's RLIMIT_RTPRIO (soft limit).
        rlimit: u64,
    },
    /// Any other refusal by the kernel.
    #[error("cannot set SCHED_FIFO priority {priority}: {source}")]
    Os {
        /// The priority asked for.
        priority: i32,
        /// What the kernel said.
        source: std::io::Error,
    },
}

/// The lowest and highest `SCHED_FIFO` priority (1 and 99 on Linux).
pub fn realtime_priority_range() -> (i32, i32) {
    // SAFETY: plain queries with a valid policy constant.
    unsafe {
        (
            libc::sched_get_priority_min(libc::SCHED_FIFO),
            libc::sched_get_priority_max(libc::SCHED_FIFO),
        )
    }
}

/// The soft RLIMIT_RTPRIO of this process.
fn rtprio_limit() -> u64 {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes one rlimit into `limit`.
    if unsafe { libc::getrlimit(libc::RLIMIT_RTPRIO, &mut limit) } == 0 {
        limit.rlim_cur
    } else {
        0
    }
}

/// Runs the calling thread under `SCHED_FIFO` at `priority` (1 to 99; a
/// handful above the default 0 of ordinary threads is enough, and below the
/// kernel's own threads at 50 is wise). Threads it starts later inherit it.
///
/// # Errors
/// [`PriorityError::OutOfRange`] outside 1 to 99;
/// [`PriorityError::NotPermitted`] without `CAP_SYS_NICE` or a large enough
/// `RLIMIT_RTPRIO` (the message says how to grant either);
/// [`PriorityError::Os`] otherwise. On error nothing changed.
pub fn set_realtime_priority(priority: i32) -> Result<(), PriorityError> {
    let (min, max) = realtime_priority_range();
    if !(min..=max).contains(&priority) {
        return Err(PriorityError::OutOfRange { priority, min, max });
    }
    let param = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: pid 0 is the calling thread; `param` is a valid sched_param.
    if unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) } == 0 {
        return Ok(());
    }
    let source = std::io::Error::last_os_error();
    match source.raw_os_error() {
        Some(libc::EPERM) => Err(PriorityError::NotPermitted {
            priority,
            rlimit: rtprio_limit(),
        }),
        _ => Err(PriorityError::Os { priority, source }),
    }
}

/// Puts the calling thread back under ordinary scheduling (`SCHED_OTHER`),
/// as it was before [`set_realtime_priority`].
///
/// # Errors
/// What the kernel said (leaving a real-time class needs no privilege, so
/// this fails only on a bad thread).
pub fn reset_priority() -> std::io::Result<()> {
    let param = libc::sched_param { sched_priority: 0 };
    // SAFETY: pid 0 is the calling thread; `param` is a valid sched_param.
    if unsafe { libc::sched_setscheduler(0, libc::SCHED_OTHER, &param) } == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn policy() -> i32 {
        // SAFETY: pid 0 is the calling thread.
        unsafe { libc::sched_getscheduler(0) }
    }

    #[test]
    fn priorities_outside_the_range_are_refused_and_change_nothing() {
        let (min, max) = realtime_priority_range();
        assert_eq!((min, max), (1, 99));
        let before = policy();
        for p in [0, -1, 100, i32::MAX] {
            let err = set_realtime_priority(p).expect_err("out of range");
            assert!(matches!(err, PriorityError::OutOfRange { priority, .. } if priority == p));
            assert!(err.to_string().contains("1 to 99"), "{err}");
        }
        assert_eq!(policy(), before);
    }

    #[test]
    fn a_refusal_names_the_capability_and_the_limit() {
        // Whether this process may: with the capability or the limit the
        // call succeeds (checked on a thread of its own, which then ends);
        // without, the refusal must say what to grant.
        std::thread::spawn(|| match set_realtime_priority(3) {
            Ok(()) => {
                assert_eq!(policy(), libc::SCHED_FIFO);
                reset_priority().expect("back to SCHED_OTHER");
                assert_eq!(policy(), libc::SCHED_OTHER);
            }
            Err(e) => {
                let PriorityError::NotPermitted { rlimit, .. } = e else {
                    panic!("{e:?}")
                };
                assert!(rlimit < 3);
                let text = e.to_string();
                assert!(text.contains("CAP_SYS_NICE"), "{text}");
                assert!(text.contains("RLIMIT_RTPRIO"), "{text}");
                assert_eq!(policy(), libc::SCHED_OTHER);
            }
        })
        .join()
        .expect("thread");
    }
}
