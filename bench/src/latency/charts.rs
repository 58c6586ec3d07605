//! The plots of a run.

use std::path::Path;

use super::row::Row;
use super::transport::{Transport, Workload};
use crate::BenchError;
use crate::plot::{self, Axis, Chart, Mark, Series};

pub(super) fn plots(rows: &[&Row], dir: &Path) -> Result<(), BenchError> {
    let color = |t: Transport| Transport::ALL.iter().position(|&x| x == t).unwrap_or(0);
    let spectrum = |r: &Row| -> Vec<(f64, f64)> {
        let mut pts: Vec<(f64, f64)> = r
            .hist
            .iter_quantiles(4)
            .filter(|v| v.quantile_iterated_to() < 1.0)
            .map(|v| {
                (
                    -(1.0 - v.quantile_iterated_to()).log10(),
                    v.value_iterated_to() as f64 / 1e3,
                )
            })
            .filter(|p| p.0 <= 5.0)
            .collect();
        pts.dedup_by(|a, b| (a.0 - b.0).abs() < 0.01);
        pts
    };
    for (gapped, file, what) in [
        (false, "latency-back-to-back.svg", "back to back"),
        (true, "latency-gaps.svg", "with gaps"),
    ] {
        let mut charts = Vec::new();
        let workloads: Vec<Workload> = rows
            .iter()
            .filter(|r| r.transport == Transport::Spin && r.gap.is_some() == gapped)
            .map(|r| r.workload)
            .collect();
        for w in workloads {
            let sel: Vec<&Row> = rows
                .iter()
                .copied()
                .filter(|r| r.workload == w && r.gap.is_some() == gapped)
                .collect();
            let series: Vec<Series> = sel
                .iter()
                .map(|r| Series {
                    name: r.transport.name().into(),
                    points: spectrum(r),
                    mark: Mark::Line,
                    color: color(r.transport),
                })
                .collect();
            let y = Axis::fit(
                series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
                true,
            );
            charts.push(Chart {
                title: format!("{}, {what}: round trip by percentile", w.name()),
                x: Axis::linear("percentile (log scale of 1 - q)", (0.0, 5.0))
                    .with_ticks(nines)
                    .with_labels(6),
                y: Axis::log("round trip, µs (log)", y).with_ticks(us_ticks),
                series,
                legend: plot::Corner::LowerRight,
            });
        }
        let path = dir.join(file);
        plot::render(&path, &charts, 3, (520, 360))
            .map_err(|e| BenchError::Plot(path.display().to_string(), e))?;
    }
    let mut charts = Vec::new();
    for (gapped, what) in [(false, "back to back"), (true, "with gaps")] {
        let series: Vec<Series> = Transport::ALL
            .iter()
            .map(|&t| Series {
                name: t.name().into(),
                points: rows
                    .iter()
                    .filter(|r| r.transport == t && r.gap.is_some() == gapped)
                    .filter_map(|r| match r.workload {
                        Workload::Batch(n) => Some((n as f64, r.us(0.5))),
                        Workload::Single => None,
                    })
                    .collect(),
                mark: Mark::LinePoints,
                color: color(t),
            })
            .collect();
        let x = Axis::fit(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.0)),
            true,
        );
        let y = Axis::fit(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
            true,
        );
        charts.push(Chart {
            title: format!("median round trip against batch size, {what}"),
            x: Axis::log("pairs per request (log)", x).with_ticks(|v| format!("{v:.0}")),
            y: Axis::log("p50 round trip, µs (log)", y).with_ticks(us_ticks),
            series,
            legend: plot::Corner::UpperLeft,
        });
    }
    let path = dir.join("latency-p50.svg");
    plot::render(&path, &charts, 2, (560, 380))
        .map_err(|e| BenchError::Plot(path.display().to_string(), e))
}

/// `q = 1 - 10^-x` as a percentage label: the x axis of a percentile
/// spectrum counts nines.
pub(super) fn nines(x: &f64) -> String {
    let q = 100.0 * (1.0 - 10f64.powf(-x));
    if *x < 0.5 {
        "0%".into()
    } else {
        let digits = (x.round() as usize).saturating_sub(2);
        format!("{q:.digits$}%")
    }
}

pub(super) fn us_ticks(v: &f64) -> String {
    if *v >= 10.0 {
        format!("{v:.0}")
    } else if *v >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nines_label_the_percentile_axis() {
        assert_eq!(nines(&0.0), "0%");
        assert_eq!(nines(&1.0), "90%");
        assert_eq!(nines(&2.0), "99%");
        assert_eq!(nines(&3.0), "99.9%");
        assert_eq!(nines(&5.0), "99.999%");
    }
}
