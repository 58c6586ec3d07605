//! Small statistics and output helpers shared by the bench commands:
//! percentiles of samples, a least-squares line, the Pareto front, CSV, and a
//! progress bar that still says what it is doing when stderr is not a
//! terminal.

use std::fmt::Write as _;
use std::path::Path;

use indicatif::{ProgressBar, ProgressStyle};

/// The `q`-quantile (`0 <= q <= 1`) of `sorted` by the nearest-rank method:
/// the smallest sample with at least `q` of the samples at or below it.
/// `NaN` for no samples.
pub fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = (q.clamp(0.0, 1.0) * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

/// Mean of `xs`, `NaN` for none.
pub fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len() as f64
}

/// A least-squares line `y = intercept + slope·x`, with its coefficient of
/// determination.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    /// Slope.
    pub slope: f64,
    /// Intercept.
    pub intercept: f64,
    /// R², 1 for points exactly on the line.
    pub r2: f64,
}

/// The least-squares line through `points` (at least two distinct x).
pub fn fit_line(points: &[(f64, f64)]) -> Fit {
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let syy: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let sse: f64 = points
        .iter()
        .map(|p| (p.1 - intercept - slope * p.0).powi(2))
        .sum();
    let r2 = if syy > 0.0 { 1.0 - sse / syy } else { 1.0 };
    Fit {
        slope,
        intercept,
        r2,
    }
}

/// Indices of the points not dominated by any other (lower or equal in both
/// coordinates, lower in one), ordered by increasing first coordinate: the
/// Pareto front when both coordinates are costs (time, error).
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in order {
        if points[i].1 < best {
            best = points[i].1;
            front.push(i);
        }
    }
    front
}

/// A CSV file built in memory.
#[derive(Clone, Debug, Default)]
pub struct Csv {
    text: String,
}

impl Csv {
    /// A file with this header row.
    pub fn new(header: &[&str]) -> Self {
        let mut csv = Csv::default();
        csv.row(header);
        csv
    }

    /// Appends a row; fields holding a comma, quote or newline are quoted.
    pub fn row<S: AsRef<str>>(&mut self, fields: &[S]) {
        for (i, f) in fields.iter().enumerate() {
            if i > 0 {
                self.text.push(',');
            }
            let f = f.as_ref();
            if f.contains([',', '"', '\n']) {
                let _ = write!(self.text, "\"{}\"", f.replace('"', "\"\""));
            } else {
                self.text.push_str(f);
            }
        }
        self.text.push('\n');
    }

    /// The text so far.
    pub fn as_str(&self) -> &str {
        &self.text
    }

    /// Writes the file.
    ///
    /// # Errors
    /// The file system's.
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        std::fs::write(path, &self.text)
    }
}

/// A progress bar over `len` steps that, when it cannot draw (stderr not a
/// terminal, as in CI logs), prints each step's message on its own line
/// instead, so a run always says what it is doing.
pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    /// A bar of `len` steps.
    pub fn new(len: u64) -> Self {
        let bar = ProgressBar::new(len);
        if let Ok(style) = ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:32.cyan/blue} {pos}/{len} {msg}",
        ) {
            bar.set_style(style);
        }
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        Progress { bar }
    }

    /// Says what the next step is.
    pub fn step(&self, msg: impl Into<String>) {
        let msg = msg.into();
        if self.bar.is_hidden() {
            eprintln!(
                "[{}/{}] {msg}",
                self.bar.position() + 1,
                self.bar.length().unwrap_or(0)
            );
        }
        self.bar.set_message(msg);
    }

    /// Marks one step done.
    pub fn inc(&self) {
        self.bar.inc(1);
    }

    /// Prints a line above the bar (or plainly when the bar is hidden).
    pub fn println(&self, line: impl AsRef<str>) {
        if self.bar.is_hidden() {
            eprintln!("{}", line.as_ref());
        } else {
            self.bar.println(line.as_ref());
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_rank_percentiles() {
        let xs: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&xs, 0.5), 50.0);
        assert_eq!(percentile(&xs, 0.99), 99.0);
        assert_eq!(percentile(&xs, 1.0), 100.0);
        assert_eq!(percentile(&xs, 0.0), 1.0);
        assert_eq!(percentile(&[7.0], 0.999), 7.0);
        assert!(percentile(&[], 0.5).is_nan());
    }

    #[test]
    fn a_line_is_fitted_exactly() {
        let pts: Vec<(f64, f64)> = (0..10).map(|i| (i as f64, 3.0 + 2.0 * i as f64)).collect();
        let f = fit_line(&pts);
        assert!((f.slope - 2.0).abs() < 1e-12);
        assert!((f.intercept - 3.0).abs() < 1e-12);
        assert!((f.r2 - 1.0).abs() < 1e-12);
        // Noise lowers R².
        let noisy = [(0.0, 0.0), (1.0, 2.0), (2.0, 1.0), (3.0, 3.0)];
        assert!(fit_line(&noisy).r2 < 0.9);
    }

    #[test]
    fn pareto_front_keeps_only_undominated_points() {
        // (time, error)
        let pts = [
            (1.0, 10.0), // fastest
            (2.0, 5.0),
            (2.5, 6.0), // dominated by (2, 5)
            (3.0, 1.0),
            (4.0, 1.0), // ties on error, slower: dominated
            (5.0, 0.1),
        ];
        assert_eq!(pareto_front(&pts), vec![0, 1, 3, 5]);
    }

    #[test]
    fn csv_quotes_what_needs_quoting() {
        let mut c = Csv::new(&["a", "b"]);
        c.row(&["1", "x,y"]);
        c.row(&["say \"hi\"", "2"]);
        assert_eq!(c.as_str(), "a,b\n1,\"x,y\"\n\"say \"\"hi\"\"\",2\n");
    }
}
