//! # gjkd-rt
//!
//! Where and how urgently a thread runs: pin it to one CPU
//! ([`pin_current_thread`]), give it a real-time priority
//! ([`set_realtime_priority`]), or, without any privilege, short time
//! slices so that its wake-ups preempt busy neighbours
//! ([`request_short_slice`]). The server uses both for `gjkd serve --cpu N
//! --priority P`; a client calls the same functions on the thread that
//! sends its queries (the Rust client re-exports them as `gjkd_client::rt`,
//! the C library as `gjkd_pin_thread` and `gjkd_set_realtime_priority`, the
//! Python package as `gjkd.pin_thread` and `gjkd.set_realtime_priority`).
//!
//! A crate of its own, below both `gjkd-server` and `gjkd-client`, because
//! neither is a home for the other's thread settings and the wire crate
//! (`gjkd-proto`) holds only what travels in shared memory. It depends on
//! `libc` alone.
//!
//! What each setting buys, measured, is in `docs/deployment.md`.
//!
//! ```no_run
//! // Pin this thread to CPU 1 and run it at SCHED_FIFO priority 10.
//! gjkd_rt::pin_current_thread(1)?;
//! gjkd_rt::set_realtime_priority(10)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs)]

mod affinity;
mod priority;
mod slice;

pub use affinity::{PinError, allowed_cpus, pin_current_thread, pin_process, unpin_current_thread};
pub use priority::{PriorityError, realtime_priority_range, reset_priority, set_realtime_priority};
pub use slice::{MIN_SLICE, current_slice, request_short_slice};
