//! Measured rows and their tables and CSV.

use std::path::Path;
use std::time::Duration;

use super::args::Condition;
use super::charts::plots;
use super::plan::Plan;
use super::row::Row;
use super::transport::{Transport, Workload};
use crate::stats::Csv;
use crate::{BenchError, io};

/// The p50 or another quantile of `t`'s single pair at `gap`, µs, among
/// `rows` (NaN when not measured).
pub(super) fn single_us(rows: &[&Row], t: Transport, gap: Option<Duration>, q: f64) -> f64 {
    rows.iter()
        .find(|r| r.transport == t && r.workload == Workload::Single && r.gap == gap)
        .map_or(f64::NAN, |r| r.us(q))
}

/// The lines under a condition's table: each mode against `block` and
/// `spin` against the floor, single pair, per pacing.
pub(super) fn condition_summary(rows: &[&Row], gaps: &[Option<Duration>]) -> String {
    let mut out = String::new();
    for &gap in gaps {
        let label = gap.map_or("back to back".into(), |g| {
            format!("gap {} µs", g.as_micros())
        });
        let u = |t, q| single_us(rows, t, gap, q);
        let spin = u(Transport::Spin, 0.5);
        let floor = u(Transport::Iceoryx2, 0.5) + u(Transport::InProcess, 0.5);
        out.push_str(&format!(
            "Single pair, {label}: p50 spin {spin:.2} µs ({:.2}x the floor: iceoryx2 {:.2} + in-process {:.2}), adaptive {:.2} µs (p99 {:.1}), block {:.2} µs (p99 {:.1}); adaptive / block: p50 {:.2}x, p99 {:.2}x\n",
            spin / floor,
            u(Transport::Iceoryx2, 0.5),
            u(Transport::InProcess, 0.5),
            u(Transport::Adaptive, 0.5),
            u(Transport::Adaptive, 0.99),
            u(Transport::Block, 0.5),
            u(Transport::Block, 0.99),
            u(Transport::Adaptive, 0.5) / u(Transport::Block, 0.5),
            u(Transport::Adaptive, 0.99) / u(Transport::Block, 0.99),
        ));
    }
    out
}

pub(super) fn report(
    rows: &[Row],
    dir: &Path,
    plan: &Plan,
    command: &str,
    probes: &[f64],
) -> Result<(), BenchError> {
    let mut csv = Csv::new(&[
        "transport",
        "request",
        "pacing",
        "requests",
        "p50_us",
        "p90_us",
        "p99_us",
        "p99_9_us",
        "max_us",
        "mean_us",
        "competitors",
        "pinned",
        "priority",
    ]);
    let f = |v: f64| format!("{v:.2}");
    let mut gaps = vec![None];
    gaps.extend(plan.gaps.iter().copied().map(Some));
    let mut text = String::new();
    let mut conditions: Vec<Condition> = Vec::new();
    for r in rows {
        if !conditions.contains(&r.condition) {
            conditions.push(r.condition);
        }
    }
    for condition in &conditions {
        let sel: Vec<&Row> = rows.iter().filter(|r| r.condition == *condition).collect();
        let Some(first) = sel.first() else { continue };
        text.push_str(&format!("\n### {}\n\n", first.condition.label()));
        text.push_str("| transport | request | pacing | requests | p50 µs | p90 µs | p99 µs | p99.9 µs | max µs |\n|---|---|---|---:|---:|---:|---:|---:|---:|\n");
        for r in &sel {
            csv.row(&[
                r.transport.name().to_owned(),
                r.workload.name(),
                r.pacing(),
                r.hist.len().to_string(),
                f(r.us(0.5)),
                f(r.us(0.9)),
                f(r.us(0.99)),
                f(r.us(0.999)),
                f(r.hist.max() as f64 / 1e3),
                f(r.hist.mean() / 1e3),
                r.condition.competitors.to_string(),
                r.condition.pinned.to_string(),
                r.condition.priority.unwrap_or(0).to_string(),
            ]);
            text.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                r.transport.name(),
                r.workload.name(),
                r.pacing(),
                r.hist.len(),
                f(r.us(0.5)),
                f(r.us(0.9)),
                f(r.us(0.99)),
                f(r.us(0.999)),
                f(r.hist.max() as f64 / 1e3),
            ));
        }
        text.push('\n');
        text.push_str(&condition_summary(&sel, &gaps));
    }
    if !probes.is_empty() {
        let list: Vec<String> = probes.iter().map(|ns| format!("{ns:.0}")).collect();
        text.push_str(&format!(
            "\nCache-line round trip CPU 0 <-> CPU 1 before each round and after the last: {} ns (the host's state: this VM has shown ~65 ns and ~340 ns at different times, and the slow state doubles a single round trip)\n",
            list.join(", ")
        ));
    }
    println!("{text}");
    let doc = format!(
        "Machine: {}\n\nCommand: `{command}` (requests per configuration: up to {}, at most ~{} s each, at least {}, in {} rounds)\n{text}",
        crate::machine(),
        plan.requests,
        plan.max_seconds,
        plan.min_requests,
        plan.rounds,
    );
    io("write latency.csv", csv.write(&dir.join("latency.csv")))?;
    io(
        "write latency.md",
        std::fs::write(dir.join("latency.md"), doc),
    )?;
    // The plots show the first condition at the first gap: the classic
    // figures; the other conditions are in the tables.
    let first_gap = plan.gaps.first().copied();
    let first: Vec<&Row> = rows
        .iter()
        .filter(|r| r.condition == rows[0].condition && (r.gap.is_none() || r.gap == first_gap))
        .collect();
    plots(&first, dir)?;
    println!(
        "wrote {0}/latency.csv, {0}/latency.md, {0}/latency-back-to-back.svg, {0}/latency-gaps.svg, {0}/latency-p50.svg",
        dir.display()
    );
    Ok(())
}
