//! One measured configuration and its histogram.

use std::time::Duration;

use hdrhistogram::Histogram;

use super::args::Condition;
use super::transport::{Transport, Workload};

/// One measured configuration.
pub struct Row {
    /// What ran beside it, and where.
    pub condition: Condition,
    /// Transport.
    pub transport: Transport,
    /// Request shape.
    pub workload: Workload,
    /// Gap between requests, `None` for back to back.
    pub gap: Option<Duration>,
    /// Round trips, nanoseconds.
    pub hist: Histogram<u64>,
}

impl Row {
    pub(super) fn us(&self, q: f64) -> f64 {
        self.hist.value_at_quantile(q) as f64 / 1e3
    }
    pub(super) fn pacing(&self) -> String {
        match self.gap {
            None => "back-to-back".into(),
            Some(g) => format!("gap {} µs", g.as_micros()),
        }
    }
}
