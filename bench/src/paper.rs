//! `gjkd bench paper`: the paper's Section 7 experiment, reproduced.
//!
//! For each of the twenty pairs of the family (`M` = 5 to 200 vertices in
//! all) and each situation (separated, touching, intersecting), `--per-pair`
//! examples are timed cold at the default tolerance, as in the paper (which
//! had no warm start). The plot is the paper's Figure 2: mean time per query
//! against `M`, one line per situation, with a least-squares line; and the
//! time per vertex, which is flat when the cost is linear in `M`.

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use gjk::{Options, Shape};
use gjkd_testkit::paper::{self, Case, PAIRS};

use super::plot::{self, Axis, Chart, Mark, Series};
use super::stats::{Csv, Fit, Progress, fit_line, mean};
use super::{BenchError, CommonArgs, io, out_dir};

/// Flags of `gjkd bench paper`.
#[derive(clap::Args, Debug, Clone)]
pub struct PaperArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Examples per pair and situation.
    #[arg(long, default_value_t = 100)]
    per_pair: usize,
    /// Calls per timed block.
    #[arg(long, default_value_t = 64)]
    reps: u32,
    /// Timing passes; the fastest block of each example is kept.
    #[arg(long, default_value_t = 5)]
    passes: u32,
}

/// One pair's mean time in one situation.
struct Point {
    case: Case,
    m: usize,
    ns: f64,
}

/// Runs `gjkd bench paper`.
///
/// # Errors
/// File-system and plotting errors.
pub fn run(args: &PaperArgs) -> Result<(), BenchError> {
    let mut args = args.clone();
    if args.common.quick {
        args.per_pair = args.per_pair.min(3);
        args.reps = args.reps.min(4);
        args.passes = 1;
    }
    let dir = out_dir(&args.common)?;
    println!(
        "gjkd bench paper: Section 7, {} pairs x 3 situations x {} examples, {} calls per block, fastest of {} passes, cold, default tolerance\nmachine: {}",
        PAIRS.len(),
        args.per_pair,
        args.reps,
        args.passes,
        super::machine()
    );
    let shapes: Vec<Shape> = paper::family().into_iter().map(Shape::from).collect();
    let options = Options {
        warm_start: false,
        ..Options::default()
    };
    let progress = Progress::new(3 * u64::from(args.passes));
    let mut points = Vec::new();
    let mut iterations = Vec::new();
    for case in Case::ALL {
        let examples = paper::cases(case, args.per_pair.max(1), 1986);
        let mut best = vec![f64::INFINITY; examples.len()];
        for pass in 0..args.passes {
            progress.step(format!(
                "{}: pass {}/{}, {} examples",
                case.name(),
                pass + 1,
                args.passes,
                examples.len()
            ));
            for (c, slot) in examples.iter().zip(best.iter_mut()) {
                let (a, b) = (&shapes[c.a], &shapes[c.b]);
                let t0 = Instant::now();
                for _ in 0..args.reps {
                    black_box(gjk::distance(
                        black_box(a),
                        &c.pose_a,
                        b,
                        &c.pose_b,
                        &options,
                        None,
                    )?);
                }
                *slot = slot.min(t0.elapsed().as_nanos() as f64 / f64::from(args.reps));
            }
            progress.inc();
        }
        for pair in 0..PAIRS.len() {
            let sel: Vec<f64> = examples
                .iter()
                .zip(&best)
                .filter(|(c, _)| c.pair == pair)
                .map(|(_, ns)| *ns)
                .collect();
            let its: Vec<f64> = examples
                .iter()
                .filter(|c| c.pair == pair)
                .map(|c| {
                    gjk::distance(
                        &shapes[c.a],
                        &c.pose_a,
                        &shapes[c.b],
                        &c.pose_b,
                        &options,
                        None,
                    )
                    .map_or(f64::NAN, |a| f64::from(a.iterations))
                })
                .collect();
            let m = examples.iter().find(|c| c.pair == pair).map_or(0, |c| c.m);
            points.push(Point {
                case,
                m,
                ns: mean(&sel),
            });
            iterations.push(mean(&its));
        }
    }
    progress.finish();
    report(&args, &dir, &points, &iterations)
}

/// The plain statement for one situation: linear means affine here, a fixed
/// cost per query plus a cost per vertex.
fn verdict(f: &Fit) -> String {
    let share = 100.0 * f.slope * 200.0 / (f.intercept + f.slope * 200.0);
    if f.r2 >= 0.9 && f.slope > 0.0 {
        format!(
            "linear: {:.0} ns + {:.2} ns × M (R² {:.3}); the per-vertex part is {share:.0}% of the time at M = 200",
            f.intercept, f.slope, f.r2
        )
    } else if f.r2 >= 0.7 {
        format!("roughly linear (R² {:.3})", f.r2)
    } else {
        format!("not well described by a line (R² {:.3})", f.r2)
    }
}

fn report(
    args: &PaperArgs,
    dir: &Path,
    points: &[Point],
    iterations: &[f64],
) -> Result<(), BenchError> {
    let mut csv = Csv::new(&[
        "situation",
        "M",
        "mean_ns_per_query",
        "ns_per_vertex",
        "mean_iterations",
    ]);
    for (p, it) in points.iter().zip(iterations) {
        csv.row(&[
            p.case.name().to_owned(),
            p.m.to_string(),
            format!("{:.1}", p.ns),
            format!("{:.2}", p.ns / p.m as f64),
            format!("{it:.2}"),
        ]);
    }
    let mut md = String::from(
        "| situation | slope, ns per vertex | intercept, ns | R² | mean ns at M = 5 | mean ns at M = 200 | cost in M |\n|---|---:|---:|---:|---:|---:|---|\n",
    );
    let mut fits = Vec::new();
    for case in Case::ALL {
        let sel: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.case == case)
            .map(|p| (p.m as f64, p.ns))
            .collect();
        let f = fit_line(&sel);
        let at = |m: f64| {
            sel.iter()
                .filter(|p| p.0 == m)
                .map(|p| p.1)
                .next()
                .unwrap_or(f64::NAN)
        };
        md.push_str(&format!(
            "| {} | {:.2} | {:.0} | {:.3} | {:.0} | {:.0} | {} |\n",
            case.name(),
            f.slope,
            f.intercept,
            f.r2,
            at(5.0),
            at(200.0),
            verdict(&f)
        ));
        fits.push((case, f));
    }
    let all_linear = fits.iter().all(|(_, f)| f.r2 >= 0.9 && f.slope > 0.0);
    let statement = if all_linear {
        "Is the cost linear in M? Yes, in all three situations: a fixed cost per query plus a cost per vertex, a least-squares line explaining at least 90% of the variance of the mean time per query (R² above), as in the paper's Figure 2. The time per vertex falls with M only because the fixed part is spread over more vertices.".to_owned()
    } else {
        format!(
            "Is the cost linear in M? Not in every situation: R² = {}. See the plot.",
            fits.iter()
                .map(|(c, f)| format!("{:.3} ({})", f.r2, c.name()))
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let text = format!(
        "Machine: {}\n\nCommand: `gjkd bench paper{}` ({} examples per pair and situation, {} calls per timed block, fastest of {} passes; cold, default tolerance)\n\n{md}\n{statement}\n",
        super::machine(),
        if args.common.quick { " --quick" } else { "" },
        args.per_pair,
        args.reps,
        args.passes
    );
    println!("\n{text}");
    io("write paper.csv", csv.write(&dir.join("paper.csv")))?;
    io(
        "write paper.md",
        std::fs::write(dir.join("paper.md"), &text),
    )?;

    let mut time_series = Vec::new();
    let mut vertex_series = Vec::new();
    for (ci, (case, f)) in fits.iter().enumerate() {
        let mut pts: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.case == *case)
            .map(|p| (p.m as f64, p.ns))
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        time_series.push(Series {
            name: format!("{} (measured)", case.name()),
            points: pts.clone(),
            mark: Mark::Points,
            color: ci,
        });
        time_series.push(Series {
            name: format!(
                "{} fit: {:.0} + {:.2}·M ns, R² {:.2}",
                case.name(),
                f.intercept,
                f.slope,
                f.r2
            ),
            points: vec![(0.0, f.intercept), (210.0, f.intercept + 210.0 * f.slope)],
            mark: Mark::Line,
            color: ci,
        });
        vertex_series.push(Series {
            name: case.name().into(),
            points: pts.iter().map(|p| (p.0, p.1 / p.0)).collect(),
            mark: Mark::LinePoints,
            color: ci,
        });
    }
    let y_max = points.iter().map(|p| p.ns).fold(0.0, f64::max) * 1.15;
    let v = Axis::fit(
        vertex_series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1)),
        true,
    );
    let charts = [
        Chart {
            title: "Section 7 (Figure 2): time per query against M".into(),
            x: Axis::linear("M = total vertices of the pair", (0.0, 210.0)),
            y: Axis::linear("mean time per query, ns", (0.0, y_max)),
            series: time_series,
            legend: plot::Corner::UpperLeft,
        },
        Chart {
            title: "time per vertex against M".into(),
            x: Axis::linear("M = total vertices of the pair", (0.0, 210.0)),
            y: Axis::log("time per query / M, ns (log)", v),
            series: vertex_series,
            legend: plot::Corner::UpperRight,
        },
    ];
    let path = dir.join("paper-figure2.svg");
    plot::render(&path, &charts, 2, (600, 420))
        .map_err(|e| BenchError::Plot(path.display().to_string(), e))?;
    println!(
        "wrote {0}/paper.csv, {0}/paper.md, {0}/paper-figure2.svg",
        dir.display()
    );
    Ok(())
}
