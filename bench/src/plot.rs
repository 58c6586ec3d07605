//! SVG charts for the bench commands, drawn with plotters' SVG backend only
//! (no system font libraries: text goes into the SVG as text elements).
//!
//! A [`Chart`] is a declarative description (axes, series); [`render`] lays
//! one or more charts out in a grid in one SVG file.

use std::path::Path;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// A polyline.
    Line,
    /// Dots.
    Points,
    /// A polyline with dots on its points.
    LinePoints,
}

/// One named series of `(x, y)` points.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// The points, in drawing order.
    pub points: Vec<(f64, f64)>,
    /// How to draw them.
    pub mark: Mark,
    /// Index into the palette, so a series keeps its colour across panels.
    pub color: usize,
}

/// One axis.
#[derive(Clone, Debug)]
pub struct Axis {
    /// Label, with the unit.
    pub label: String,
    /// Logarithmic scale.
    pub log: bool,
    /// Shown range (both ends positive on a log axis).
    pub range: (f64, f64),
    /// Tick label text for a value; `None` for plotters' default.
    pub ticks: Option<fn(&f64) -> String>,
    /// How many tick labels plotters should aim for.
    pub labels: usize,
}

impl Axis {
    /// A linear axis.
    pub fn linear(label: &str, range: (f64, f64)) -> Self {
        Axis {
            label: label.to_owned(),
            log: false,
            range,
            ticks: None,
            labels: 10,
        }
    }

    /// A logarithmic axis.
    pub fn log(label: &str, range: (f64, f64)) -> Self {
        Axis {
            log: true,
            ..Axis::linear(label, range)
        }
    }

    /// The same axis with these tick labels.
    pub fn with_ticks(mut self, ticks: fn(&f64) -> String) -> Self {
        self.ticks = Some(ticks);
        self
    }

    /// The same axis aiming at `n` tick labels.
    pub fn with_labels(mut self, n: usize) -> Self {
        self.labels = n;
        self
    }

    /// The range that holds `values` with a margin (a factor on a log axis),
    /// ignoring non-finite values and, on a log axis, values `<= 0`.
    pub fn fit(values: impl IntoIterator<Item = f64>, log: bool) -> (f64, f64) {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values {
            if v.is_finite() && (!log || v > 0.0) {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        if lo > hi {
            return if log { (0.1, 10.0) } else { (0.0, 1.0) };
        }
        if log {
            (lo / 1.6, hi * 1.6)
        } else {
            let pad = ((hi - lo) * 0.05).max(hi.abs() * 1e-3).max(1e-12);
            (lo - pad, hi + pad)
        }
    }
}

/// A chart: title, axes and series.
#[derive(Clone, Debug)]
pub struct Chart {
    /// Title above the plot area.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// What to draw.
    pub series: Vec<Series>,
    /// Where the legend goes: a corner the data leaves empty.
    pub legend: Corner,
}

/// A corner of the plot area.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Corner {
    /// Upper left.
    #[default]
    UpperLeft,
    /// Upper right.
    UpperRight,
    /// Lower right.
    LowerRight,
    /// Lower left.
    LowerLeft,
}

/// Colour `i` of a palette that stays readable on white.
pub fn color(i: usize) -> RGBColor {
    const PALETTE: [RGBColor; 8] = [
        RGBColor(0x1f, 0x77, 0xb4),
        RGBColor(0xd6, 0x27, 0x28),
        RGBColor(0x2c, 0xa0, 0x2c),
        RGBColor(0xff, 0x7f, 0x0e),
        RGBColor(0x94, 0x67, 0xbd),
        RGBColor(0x8c, 0x56, 0x4b),
        RGBColor(0xe3, 0x77, 0xc2),
        RGBColor(0x7f, 0x7f, 0x7f),
    ];
    PALETTE[i % PALETTE.len()]
}

/// Draws `charts` in a grid of `cols` columns into the SVG file `path`, each
/// panel `panel` pixels in size.
///
/// # Errors
/// A description of what plotters or the file system refused.
pub fn render(path: &Path, charts: &[Chart], cols: usize, panel: (u32, u32)) -> Result<(), String> {
    let cols = cols.clamp(1, charts.len().max(1));
    let rows = charts.len().div_ceil(cols).max(1);
    let size = (panel.0 * cols as u32, panel.1 * rows as u32);
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| format!("{e:?}"))?;
    let areas = root.split_evenly((rows, cols));
    for (area, chart) in areas.iter().zip(charts) {
        let (x0, x1) = chart.x.range;
        let (y0, y1) = chart.y.range;
        match (chart.x.log, chart.y.log) {
            (false, false) => panel_with(area, chart, x0..x1, y0..y1),
            (true, false) => panel_with(area, chart, (x0..x1).log_scale(), y0..y1),
            (false, true) => panel_with(area, chart, x0..x1, (y0..y1).log_scale()),
            (true, true) => panel_with(area, chart, (x0..x1).log_scale(), (y0..y1).log_scale()),
        }?;
    }
    root.present().map_err(|e| format!("{e:?}"))
}

fn panel_with<X, Y>(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    chart: &Chart,
    x: X,
    y: Y,
) -> Result<(), String>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let err = |e: DrawingAreaErrorKind<_>| format!("{e:?}");
    let mut ctx = ChartBuilder::on(area)
        .caption(&chart.title, ("sans-serif", 17))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    let default_fmt = |v: &f64| {
        let a = v.abs();
        if a != 0.0 && !(1e-3..1e5).contains(&a) {
            format!("{v:.0e}")
        } else {
            format!("{v}")
        }
    };
    let xf = chart.x.ticks;
    let yf = chart.y.ticks;
    let x_fmt = move |v: &f64| xf.map_or_else(|| default_fmt(v), |f| f(v));
    let y_fmt = move |v: &f64| yf.map_or_else(|| default_fmt(v), |f| f(v));
    ctx.configure_mesh()
        .x_desc(chart.x.label.as_str())
        .y_desc(chart.y.label.as_str())
        .x_labels(chart.x.labels)
        .y_labels(chart.y.labels)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .light_line_style(WHITE.mix(0.0))
        .bold_line_style(BLACK.mix(0.12))
        .label_style(("sans-serif", 12))
        .axis_desc_style(("sans-serif", 13))
        .draw()
        .map_err(err)?;
    let in_range = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite();
    for s in &chart.series {
        let c = color(s.color);
        let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(in_range).collect();
        let legend = s.name.clone();
        if matches!(s.mark, Mark::Line | Mark::LinePoints) {
            ctx.draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
                .map_err(err)?
                .label(legend.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2))
                });
        }
        if matches!(s.mark, Mark::Points | Mark::LinePoints) {
            let drawn = ctx
                .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
                .map_err(err)?;
            if s.mark == Mark::Points {
                drawn
                    .label(legend)
                    .legend(move |(x, y)| Circle::new((x + 9, y), 3, c.filled()));
            }
        }
    }
    if chart.series.iter().any(|s| !s.name.is_empty()) {
        ctx.configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.3))
            .label_font(("sans-serif", 12))
            .position(match chart.legend {
                Corner::UpperLeft => SeriesLabelPosition::UpperLeft,
                Corner::UpperRight => SeriesLabelPosition::UpperRight,
                Corner::LowerRight => SeriesLabelPosition::LowerRight,
                Corner::LowerLeft => SeriesLabelPosition::LowerLeft,
            })
            .draw()
            .map_err(err)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_fit_pads_and_skips_bad_values() {
        let (lo, hi) = Axis::fit([1.0, 100.0, f64::NAN, 0.0], true);
        assert!(lo < 1.0 && lo > 0.5 && hi > 100.0 && hi < 200.0);
        let (lo, hi) = Axis::fit([2.0, 4.0], false);
        assert!(lo < 2.0 && hi > 4.0);
        assert_eq!(Axis::fit([], true), (0.1, 10.0));
    }

    #[test]
    fn renders_an_svg() {
        let dir = std::env::temp_dir().join(format!("gjkd-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join("t.svg");
        let chart = Chart {
            title: "t".into(),
            x: Axis::log("x", (1.0, 100.0)),
            y: Axis::linear("y", (0.0, 3.0)),
            series: vec![Series {
                name: "s".into(),
                points: vec![(1.0, 1.0), (10.0, 2.0), (100.0, f64::NAN)],
                mark: Mark::LinePoints,
                color: 0,
            }],
            legend: Corner::LowerRight,
        };
        render(&path, &[chart.clone(), chart], 2, (300, 200)).expect("render");
        let svg = std::fs::read_to_string(&path).expect("svg");
        assert!(svg.starts_with("<svg") && svg.contains("polyline"));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
