//! `gjkd bench tradeoff`: what each speed setting costs in accuracy, measured
//! side by side on the same queries in one run.
//!
//! The queries are the paper's Section 7 family (separated, touching and
//! intersecting pairs of its twelve polytopes) and the extremes family
//! ([`super::extremes`]). Every query's true distance comes from
//! [`gjkd_testkit::reference`](mod@gjkd_testkit::reference) (closed forms, or a brute force over hull features
//! with a separating-axis test), computed once and cached in `--cache-dir`.
//!
//! The settings: the tolerance `ε` from 1e-15 to 1e-2, cold and warm; iteration
//! caps at the default tolerance; early-exit margins as a fraction of the
//! pair's size; the f32 support search (`Precision::Single`). A warm query
//! starts from the simplex of the same pair one small step (1% of its size,
//! 0.02 rad) earlier, as along a motion. The f32 search, which only pays on
//! large vertex sets, is also timed on box clouds of 16 to 16 384 points
//! (closed-form truths), f64 against f32, cold and warm.
//!
//! Each (query, setting) is timed as a block of `--reps` back-to-back calls,
//! in `--passes` passes, keeping the fastest block: settings are interleaved
//! query by query, so drift and noise hit them all alike.

mod report;
mod workload;

use super::extremes;
use super::plot::{self, Axis, Chart, Mark, Series};
use super::stats::{Csv, Progress, mean, pareto_front, percentile};
use super::{BenchError, CommonArgs, io, out_dir};
use gjk::{Options, Precision, Shape, Status, WarmStart};
use gjkd_testkit::paper::{self, Case};
use gjkd_testkit::reference::{self, Hull};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use report::*;
use std::collections::BTreeMap;
use std::hash::Hasher;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Instant;
use workload::*;

/// Flags of `gjkd bench tradeoff`.
#[derive(clap::Args, Debug, Clone)]
pub struct TradeoffArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Examples per pair and situation of the paper's family (20 pairs, 3
    /// situations).
    #[arg(long, default_value_t = 25)]
    per_pair: usize,
    /// Calls per timed block.
    #[arg(long, default_value_t = 32)]
    reps: u32,
    /// Timing passes; the fastest block of each query and setting is kept.
    #[arg(long, default_value_t = 5)]
    passes: u32,
    /// Where the reference distances are cached.
    #[arg(long, default_value = "target/gjkd-bench")]
    cache_dir: PathBuf,
}

/// The default tolerance, 100 × machine epsilon.
const DEFAULT_EPS: f64 = 100.0 * f64::EPSILON;

/// Reference distances may be off by their own round-off; a bound counts as
/// missed only past this many units of the pair's size.
const BOUND_SLACK: f64 = 1e-13;

/// Per-setting results.
struct Outcome {
    ns: Vec<f64>,
    err: Vec<f64>,
    dist_rel: Vec<f64>,
    misses: usize,
    wrong: usize,
    capped: usize,
    by_family: BTreeMap<String, f64>,
}

/// Runs `gjkd bench tradeoff`.
///
/// # Errors
/// File-system errors and plotting errors.
pub fn run(args: &TradeoffArgs) -> Result<(), BenchError> {
    let mut args = args.clone();
    if args.common.quick {
        args.per_pair = args.per_pair.min(1);
        args.reps = args.reps.min(4);
        args.passes = 1;
    }
    let dir = out_dir(&args.common)?;
    let settings = settings();
    println!(
        "gjkd bench tradeoff: {} settings on the paper's family ({} per pair and situation) and the extremes family; {} calls per block, {} passes\nmachine: {}",
        settings.len(),
        args.per_pair,
        args.reps,
        args.passes,
        super::machine()
    );
    let progress = Progress::new(u64::from(args.passes) + 1);
    progress.step("building the families");
    let (shapes, raw) = workload(args.per_pair.max(1));
    let truths = references(&raw, &shapes, &args.cache_dir, &progress)?;
    progress.inc();
    let mut queries: Vec<Query> = Vec::with_capacity(raw.len());
    for ((r, ia, ib), truth) in raw.iter().zip(truths) {
        // Two points have no size: their distance stands in.
        let size = (bounding(&shapes[*ia]) + bounding(&shapes[*ib]))
            .max(truth)
            .max(f64::MIN_POSITIVE);
        let before = step_back(&r.pose_b, size);
        let warm = gjk::distance(
            &shapes[*ia],
            &r.pose_a,
            &shapes[*ib],
            &before,
            &Options::default(),
            None,
        )?
        .warm_start;
        queries.push(Query {
            family: r.family.to_owned(),
            label: r.label.clone(),
            a: *ia,
            b: *ib,
            pose_a: r.pose_a,
            pose_b: r.pose_b,
            size,
            truth,
            warm: Some(warm),
        });
    }
    // best[setting][query]: fastest block mean, ns per call.
    let mut best = vec![vec![f64::INFINITY; queries.len()]; settings.len()];
    let mut answers = vec![vec![None; queries.len()]; settings.len()];
    for pass in 0..args.passes {
        progress.step(format!(
            "timing pass {}/{}: {} queries x {} settings x {} calls",
            pass + 1,
            args.passes,
            queries.len(),
            settings.len(),
            args.reps
        ));
        for (qi, q) in queries.iter().enumerate() {
            let (a, b) = (&shapes[q.a], &shapes[q.b]);
            for (si, s) in settings.iter().enumerate() {
                let options = Options {
                    margin: s.margin.map(|f| f * q.size),
                    ..s.options
                };
                let warm = if options.warm_start {
                    q.warm.as_ref()
                } else {
                    None
                };
                if answers[si][qi].is_none() {
                    answers[si][qi] =
                        Some(gjk::distance(a, &q.pose_a, b, &q.pose_b, &options, warm)?);
                }
                let t0 = Instant::now();
                for _ in 0..args.reps {
                    let r = gjk::distance(
                        black_box(a),
                        black_box(&q.pose_a),
                        b,
                        &q.pose_b,
                        &options,
                        warm,
                    );
                    black_box(&r);
                }
                let ns = t0.elapsed().as_nanos() as f64 / f64::from(args.reps);
                let cell = &mut best[si][qi];
                *cell = cell.min(ns);
            }
        }
        progress.inc();
    }
    progress.finish();

    let outcomes: Vec<Outcome> = settings
        .iter()
        .enumerate()
        .map(|(si, s)| {
            let mut o = Outcome {
                ns: best[si].clone(),
                err: Vec::new(),
                dist_rel: Vec::new(),
                misses: 0,
                wrong: 0,
                capped: 0,
                by_family: BTreeMap::new(),
            };
            for (qi, q) in queries.iter().enumerate() {
                let Some(ans) = &answers[si][qi] else {
                    continue;
                };
                let e = (ans.distance - q.truth).abs() / q.size;
                o.err.push(e);
                let fam = if q.family.starts_with('§') {
                    "§7"
                } else {
                    "extremes"
                };
                let slot = o.by_family.entry(fam.to_owned()).or_insert(0.0);
                *slot = slot.max(e);
                if q.truth > 0.0 {
                    o.dist_rel.push((ans.distance - q.truth).abs() / q.truth);
                }
                let slack = BOUND_SLACK * q.size;
                if q.truth < ans.lower - slack || q.truth > ans.upper + slack {
                    o.misses += 1;
                }
                if let Some(f) = s.margin {
                    let m = f * q.size;
                    let wrong = match ans.status {
                        Status::Farther => q.truth <= m - slack,
                        Status::Closer => q.truth > m + slack,
                        _ => false,
                    };
                    o.wrong += usize::from(wrong);
                }
                if ans.status == Status::IterationCap {
                    o.capped += 1;
                }
            }
            o
        })
        .collect();
    report(&args, &dir, &settings, &outcomes, &queries)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analytic_extremes_agree_with_the_brute_force() {
        // The two reference methods are independent of each other as well:
        // where both apply they must agree.
        for e in extremes::cases() {
            let Some(want) = e.analytic else { continue };
            let (pa, ra) = points_of(&e.a);
            let (pb, rb) = points_of(&e.b);
            let got = reference::distance(
                &Hull::new(&pa),
                &e.pose_a,
                ra,
                &Hull::new(&pb),
                &e.pose_b,
                rb,
            );
            let size = bounding(&e.a) + bounding(&e.b);
            let offset = e
                .pose_a
                .translation
                .vector
                .amax()
                .max(e.pose_b.translation.vector.amax());
            // The brute force works in world coordinates: far from the origin
            // it loses what the offset's ulp hides.
            let tol = 1e-14 * size + 4.0 * f64::EPSILON * offset;
            assert!(
                (got.distance - want).abs() <= tol,
                "{}: brute force {} vs closed form {want}",
                e.label,
                got.distance
            );
        }
    }

    #[test]
    fn the_settings_span_the_issue_range() {
        let s = settings();
        let tols: Vec<f64> = s.iter().map(|s| s.options.tolerance).collect();
        assert!(tols.contains(&1e-15) && tols.contains(&1e-2));
        assert!(s.iter().any(|s| s.group == Group::TolWarm));
        assert!(s.iter().any(|s| s.margin.is_some()));
        assert!(s.iter().any(|s| s.options.max_iterations < 4));
        assert!(s.iter().any(|s| s.options.precision == Precision::Single));
    }
}
