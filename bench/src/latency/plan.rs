//! The settings of one run, defaults filled in from the flags.

use std::time::Duration;

use super::args::{Condition, LatencyArgs, Pinning};
use super::transport::Transport;

/// The settings of one run, defaults filled in.
#[derive(Clone, Debug)]
pub(super) struct Plan {
    pub(super) requests: u64,
    pub(super) max_seconds: f64,
    pub(super) min_requests: u64,
    pub(super) gaps: Vec<Duration>,
    pub(super) batches: Vec<usize>,
    pub(super) transports: Vec<Transport>,
    pub(super) rounds: usize,
    pub(super) conditions: Vec<Condition>,
    pub(super) quick: bool,
}

impl Plan {
    pub(super) fn new(args: &LatencyArgs) -> Self {
        let c = args.contention;
        let or = |v: &Vec<u64>, plain: &[u64], contention: &[u64]| -> Vec<u64> {
            if !v.is_empty() {
                v.clone()
            } else if c {
                contention.to_vec()
            } else {
                plain.to_vec()
            }
        };
        let gaps = or(&args.gap_us, &[100], &[10, 100, 1000])
            .into_iter()
            .map(Duration::from_micros)
            .collect();
        let batches = if !args.batches.is_empty() {
            args.batches.iter().map(|&n| n.max(1)).collect()
        } else if c {
            Vec::new()
        } else {
            vec![1, 8, 64, 512]
        };
        let competitors = if !args.competitors.is_empty() {
            args.competitors.clone()
        } else if c {
            vec![0, 1]
        } else {
            vec![0]
        };
        let pinnings = if args.no_pin {
            vec![Pinning::Unpinned]
        } else if !args.pinning.is_empty() {
            args.pinning.clone()
        } else if c {
            vec![Pinning::Pinned, Pinning::Unpinned]
        } else {
            vec![Pinning::Pinned]
        };
        let priorities: Vec<Option<i32>> = if args.priority.is_empty() {
            vec![None]
        } else {
            args.priority
                .iter()
                .map(|&p| (p > 0).then_some(p))
                .collect()
        };
        let mut conditions = Vec::new();
        for &competitors in &competitors {
            for &pinning in &pinnings {
                for &priority in &priorities {
                    conditions.push(Condition {
                        competitors,
                        pinned: pinning == Pinning::Pinned,
                        priority,
                    });
                }
            }
        }
        let transports = if args.transports.is_empty() {
            // The socket server answers every condition alike (tens of µs,
            // a blocking read): the contention tables leave it out.
            Transport::ALL
                .into_iter()
                .filter(|&t| !c || t != Transport::Uds)
                .collect()
        } else {
            Transport::ALL
                .into_iter()
                .filter(|t| args.transports.contains(t))
                .collect()
        };
        let mut plan = Plan {
            requests: args.requests,
            max_seconds: args.max_seconds.unwrap_or(if c { 1.0 } else { 4.0 }),
            min_requests: args.min_requests.unwrap_or(if c { 300 } else { 10_000 }),
            gaps,
            batches,
            transports,
            rounds: args.rounds.max(1),
            conditions,
            quick: args.common.quick,
        };
        if plan.quick {
            plan.requests = plan.requests.min(2_000);
            plan.min_requests = plan.min_requests.min(if c { 100 } else { 300 });
            plan.max_seconds = plan.max_seconds.min(if c { 0.25 } else { 0.2 });
            plan.rounds = 1;
        }
        plan
    }

    /// The command line that gives this plan, for the tables.
    pub(super) fn command(&self, args: &LatencyArgs) -> String {
        let mut cmd = String::from("gjkd bench latency");
        if args.contention {
            cmd.push_str(" --contention");
        }
        if args.common.quick {
            cmd.push_str(" --quick");
        }
        let list = |v: Vec<String>| v.join(",");
        if !args.gap_us.is_empty() {
            cmd.push_str(&format!(
                " --gap-us {}",
                list(args.gap_us.iter().map(u64::to_string).collect())
            ));
        }
        if !args.competitors.is_empty() {
            cmd.push_str(&format!(
                " --competitors {}",
                list(args.competitors.iter().map(usize::to_string).collect())
            ));
        }
        if args.no_pin {
            cmd.push_str(" --no-pin");
        } else if !args.pinning.is_empty() {
            cmd.push_str(&format!(
                " --pinning {}",
                list(
                    args.pinning
                        .iter()
                        .map(|p| format!("{p:?}").to_lowercase())
                        .collect()
                )
            ));
        }
        if !args.priority.is_empty() {
            cmd.push_str(&format!(
                " --priority {}",
                list(args.priority.iter().map(i32::to_string).collect())
            ));
        }
        cmd
    }
}
