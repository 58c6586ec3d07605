//! The flags of `gjkd bench latency` and the conditions it runs under.

use super::transport::Transport;
use crate::CommonArgs;

/// Flags of `gjkd bench latency`.
#[derive(clap::Args, Debug, Clone)]
pub struct LatencyArgs {
    #[command(flatten)]
    pub(super) common: CommonArgs,
    /// Requests per configuration.
    #[arg(long, default_value_t = 100_000)]
    pub(super) requests: u64,
    /// Longest a configuration may take: fewer requests are sent (never
    /// fewer than --min-requests) when the estimate is longer. Default 4 s,
    /// 1 s with --contention.
    #[arg(long)]
    pub(super) max_seconds: Option<f64>,
    /// Fewest requests per configuration. Default 10 000, 300 with
    /// --contention.
    #[arg(long)]
    pub(super) min_requests: Option<u64>,
    /// Gaps between requests in the paced runs, microseconds (a list).
    /// Default 100; 10,100,1000 with --contention.
    #[arg(long, value_delimiter = ',')]
    pub(super) gap_us: Vec<u64>,
    /// Batch sizes (besides the single pair). Default 1,8,64,512; none
    /// with --contention.
    #[arg(long, value_delimiter = ',')]
    pub(super) batches: Vec<usize>,
    /// Transports to measure (default: all; all but uds with --contention).
    #[arg(long, value_delimiter = ',', value_enum)]
    pub(super) transports: Vec<Transport>,
    /// Rounds: every configuration is measured a share at a time in each
    /// round, servers restarted, so slow spells of a shared machine fall on
    /// all transports alike.
    #[arg(long, default_value_t = 4)]
    pub(super) rounds: usize,
    /// Competing busy processes, one condition per count (a list). Default
    /// 0; 0,1 with --contention.
    #[arg(long, value_delimiter = ',')]
    pub(super) competitors: Vec<usize>,
    /// Placements, one condition each (a list): `pinned` puts the client on
    /// CPU 0 and every server on CPU 1, as `taskset` would, so that a woken
    /// server is never queued behind its own spinning client on one core;
    /// `unpinned` leaves the scheduler free. Default pinned; both with
    /// --contention.
    #[arg(long, value_delimiter = ',', value_enum)]
    pub(super) pinning: Vec<Pinning>,
    /// Same as `--pinning unpinned`.
    #[arg(long)]
    pub(super) no_pin: bool,
    /// SCHED_FIFO priorities for the client thread and the servers, one
    /// condition each (a list; 0: ordinary scheduling). Default 0.
    #[arg(long, value_delimiter = ',')]
    pub(super) priority: Vec<i32>,
    /// The deployment guide's tables: single pairs, back to back and at
    /// 10 µs, 100 µs and 1 ms, quiet and beside one busy process, pinned and
    /// unpinned (flags given explicitly still win).
    #[arg(long)]
    pub(super) contention: bool,
}

/// Where the client and the servers run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Pinning {
    /// Client on CPU 0, servers on CPU 1.
    Pinned,
    /// Wherever the scheduler puts them.
    Unpinned,
}

/// What runs beside the measurement, and where it runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Condition {
    /// Competing busy processes.
    pub competitors: usize,
    /// Client on CPU 0, servers on CPU 1 (false: unpinned).
    pub pinned: bool,
    /// SCHED_FIFO priority of the client and the servers, if any.
    pub priority: Option<i32>,
}

impl Condition {
    /// The heading of its table.
    pub fn label(&self) -> String {
        let load = match self.competitors {
            0 => "quiet".to_owned(),
            1 => "1 competing busy process".to_owned(),
            n => format!("{n} competing busy processes"),
        };
        let place = if self.pinned {
            "pinned (client CPU 0, servers CPU 1)"
        } else {
            "unpinned"
        };
        match self.priority {
            Some(p) => format!("{load}, {place}, SCHED_FIFO {p}"),
            None => format!("{load}, {place}"),
        }
    }
}
