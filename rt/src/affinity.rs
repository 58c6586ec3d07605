//! Pinning a thread to one CPU.
//!
//! A thread that stays on one CPU keeps its caches warm and is never
//! migrated in the middle of a burst; a server and its client on two
//! different CPUs never queue behind each other. Linux only (the whole
//! crate is).

use std::fmt::Write as _;

/// Why a thread could not be pinned.
#[derive(Debug, thiserror::Error)]
pub enum PinError {
    /// The CPU number is beyond what the kernel's CPU sets can name.
    #[error("CPU {cpu} does not exist: CPU numbers go up to {max}")]
    NoSuchCpu {
        /// The CPU asked for.
        cpu: usize,
        /// The largest number a CPU set can hold.
        max: usize,
    },
    /// The CPU is offline, or outside the CPUs this process may use (its
    /// cpuset, a container's `--cpuset-cpus`, or an earlier `taskset`).
    #[error("CPU {cpu} is not one this thread may run on (allowed: {allowed})")]
    NotAllowed {
        /// The CPU asked for.
        cpu: usize,
        /// The CPUs the thread may use, as a list such as `0-3,6`.
        allowed: String,
    },
    /// Any other refusal by the kernel.
    #[error("cannot pin to CPU {cpu}: {source}")]
    Os {
        /// The CPU asked for.
        cpu: usize,
        /// What the kernel said.
        source: std::io::Error,
    },
}

/// The CPUs the calling thread may run on now, in increasing order.
///
/// # Errors
/// What the kernel said when the mask cannot be read.
pub fn allowed_cpus() -> std::io::Result<Vec<usize>> {
    // SAFETY: a zeroed cpu_set_t is a valid empty set; sched_getaffinity
    // writes at most `size_of::<cpu_set_t>()` bytes into it.
    let set = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return Err(std::io::Error::last_os_error());
        }
        set
    };
    Ok((0..libc::CPU_SETSIZE as usize)
        // SAFETY: `cpu` is below CPU_SETSIZE, inside the set.
        .filter(|&cpu| unsafe { libc::CPU_ISSET(cpu, &set) })
        .collect())
}

/// `cpus` (increasing) as the kernel writes CPU lists: `0-3,6`.
fn cpu_list(cpus: &[usize]) -> String {
    let mut out = String::new();
    let mut i = 0;
    while i < cpus.len() {
        let mut j = i;
        while j + 1 < cpus.len() && cpus[j + 1] == cpus[j] + 1 {
            j += 1;
        }
        if !out.is_empty() {
            out.push(',');
        }
        let _ = if j > i {
            write!(out, "{}-{}", cpus[i], cpus[j])
        } else {
            write!(out, "{}", cpus[i])
        };
        i = j + 1;
    }
    if out.is_empty() {
        out.push_str("none");
    }
    out
}

/// Sets the affinity of thread `tid` (0: the calling thread) to `cpu` alone.
fn set_affinity(tid: libc::pid_t, cpu: usize) -> Result<(), PinError> {
    let max = libc::CPU_SETSIZE as usize - 1;
    if cpu > max {
        return Err(PinError::NoSuchCpu { cpu, max });
    }
    // Read before trying: a refused mask leaves the thread's own as it was,
    // and that is what the error should list.
    let allowed = allowed_cpus().map(|c| cpu_list(&c));
    // SAFETY: a zeroed cpu_set_t is the empty set; CPU_SET writes inside it
    // (`cpu` <= max); sched_setaffinity reads `size_of::<cpu_set_t>()` bytes.
    let rc = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(tid, std::mem::size_of::<libc::cpu_set_t>(), &set)
    };
    if rc == 0 {
        return Ok(());
    }
    let source = std::io::Error::last_os_error();
    match source.raw_os_error() {
        // EINVAL: no CPU of the mask is online and in the cpuset.
        Some(libc::EINVAL) => Err(PinError::NotAllowed {
            cpu,
            allowed: allowed.unwrap_or_else(|e| format!("unknown: {e}")),
        }),
        _ => Err(PinError::Os { cpu, source }),
    }
}

/// Pins the calling thread to `cpu`: from now on the scheduler runs it
/// there and nowhere else. Threads it starts later inherit the pin.
///
/// # Errors
/// [`PinError::NoSuchCpu`] for a number no CPU set can hold,
/// [`PinError::NotAllowed`] for a CPU that is offline or outside this
/// process's cpuset (the message lists the allowed ones), [`PinError::Os`]
/// otherwise. On error the thread's affinity is unchanged.
pub fn pin_current_thread(cpu: usize) -> Result<(), PinError> {
    set_affinity(0, cpu)
}

/// Pins the main thread of process `pid` to `cpu`, as `taskset -p` does
/// (for tools that start a process and place it from outside; its other
/// threads keep their affinity).
///
/// # Errors
/// As [`pin_current_thread`]; the allowed CPUs listed are the caller's.
pub fn pin_process(pid: u32, cpu: usize) -> Result<(), PinError> {
    let tid = libc::pid_t::try_from(pid).map_err(|_| PinError::Os {
        cpu,
        source: std::io::Error::from_raw_os_error(libc::ESRCH),
    })?;
    set_affinity(tid, cpu)
}

/// Lets the calling thread run on every CPU its cpuset allows again.
///
/// # Errors
/// What the kernel said.
pub fn unpin_current_thread() -> std::io::Result<()> {
    // SAFETY: as in `set_affinity`, with every CPU a set can name; the
    // kernel intersects the mask with the cpuset.
    let rc = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        for cpu in 0..libc::CPU_SETSIZE as usize {
            libc::CPU_SET(cpu, &mut set);
        }
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set)
    };
    if rc == 0 {
        Ok(())
    } else {
        Err(std::io::Error::last_os_error())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CPU the calling thread runs on now.
    fn current_cpu() -> usize {
        // SAFETY: sched_getcpu has no arguments.
        let cpu = unsafe { libc::sched_getcpu() };
        usize::try_from(cpu).expect("sched_getcpu")
    }

    #[test]
    fn cpu_lists_are_written_as_ranges() {
        assert_eq!(cpu_list(&[0, 1, 2, 3, 6]), "0-3,6");
        assert_eq!(cpu_list(&[1]), "1");
        assert_eq!(cpu_list(&[0, 2, 4, 5]), "0,2,4-5");
        assert_eq!(cpu_list(&[]), "none");
    }

    #[test]
    fn a_pinned_thread_runs_on_its_cpu_and_nowhere_else() {
        let allowed = allowed_cpus().expect("affinity");
        assert!(!allowed.is_empty());
        // A thread of its own: the test harness's threads keep their masks.
        std::thread::spawn(move || {
            for &cpu in &allowed {
                pin_current_thread(cpu).expect("pin to an allowed CPU");
                assert_eq!(allowed_cpus().expect("affinity"), vec![cpu]);
                assert_eq!(current_cpu(), cpu);
            }
            unpin_current_thread().expect("unpin");
            assert_eq!(allowed_cpus().expect("affinity"), allowed);
        })
        .join()
        .expect("pinning thread");
    }

    #[test]
    fn a_cpu_beyond_any_set_is_refused_by_number() {
        let err = pin_current_thread(1 << 20).expect_err("no such CPU");
        assert!(matches!(err, PinError::NoSuchCpu { cpu, .. } if cpu == 1 << 20));
        assert!(
            err.to_string().contains("CPU 1048576 does not exist"),
            "{err}"
        );
    }

    #[test]
    fn a_cpu_outside_the_allowed_set_is_refused_listing_the_allowed_ones() {
        std::thread::spawn(|| {
            let before = allowed_cpus().expect("affinity");
            // The last number a set can hold: no machine this runs on has it.
            let cpu = libc::CPU_SETSIZE as usize - 1;
            let err = pin_current_thread(cpu).expect_err("offline CPU");
            let PinError::NotAllowed { allowed, .. } = &err else {
                panic!("{err:?}")
            };
            assert_eq!(*allowed, cpu_list(&before));
            assert!(err.to_string().contains("not one this thread may run on"));
            // Nothing changed.
            assert_eq!(allowed_cpus().expect("affinity"), before);
        })
        .join()
        .expect("thread");
    }
}
