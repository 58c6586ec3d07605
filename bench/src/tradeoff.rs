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

use std::collections::BTreeMap;
use std::hash::Hasher;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Instant;

use gjk::{Options, Precision, Shape, Status, WarmStart};
use gjkd_testkit::paper::{self, Case};
use nalgebra::{Isometry3, Point3, Translation3};

use super::extremes;
use super::plot::{self, Axis, Chart, Mark, Series};
use super::stats::{Csv, Progress, mean, pareto_front, percentile};
use super::{BenchError, CommonArgs, io, out_dir};
use gjkd_testkit::reference::{self, Hull};

use crate::tradeoff_by_size::{BOUND_SLACK, precision_by_size, step_back};

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

/// A query with its reference.
struct Query {
    family: String,
    label: String,
    a: usize,
    b: usize,
    pose_a: Isometry3<f64>,
    pose_b: Isometry3<f64>,
    /// Sum of the bounding radii about the body origins.
    size: f64,
    truth: f64,
    warm: Option<WarmStart>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Group {
    TolCold,
    TolWarm,
    Cap,
    Margin,
    Precision,
}

impl Group {
    fn name(self) -> &'static str {
        match self {
            Group::TolCold => "tolerance, cold",
            Group::TolWarm => "tolerance, warm",
            Group::Cap => "iteration cap, cold",
            Group::Margin => "early-exit margin",
            Group::Precision => "f32 support search",
        }
    }
}

struct Setting {
    name: String,
    group: Group,
    options: Options,
    /// Margin as a fraction of each pair's size.
    margin: Option<f64>,
}

fn settings() -> Vec<Setting> {
    let mut out = Vec::new();
    let tols = [
        1e-15,
        1e-14,
        DEFAULT_EPS,
        1e-13,
        1e-12,
        1e-10,
        1e-8,
        1e-6,
        1e-4,
        1e-3,
        1e-2,
    ];
    for (group, warm) in [(Group::TolCold, false), (Group::TolWarm, true)] {
        for &t in &tols {
            let tag = if t == DEFAULT_EPS {
                "ε=2.2e-14 (default)".to_owned()
            } else {
                format!("ε={t:.0e}")
            };
            out.push(Setting {
                name: format!("{tag} {}", if warm { "warm" } else { "cold" }),
                group,
                options: Options {
                    tolerance: t,
                    warm_start: warm,
                    ..Options::default()
                },
                margin: None,
            });
        }
    }
    for cap in [1u32, 2, 3, 4, 6, 8, 12] {
        out.push(Setting {
            name: format!("cap {cap} cold"),
            group: Group::Cap,
            options: Options {
                max_iterations: cap,
                warm_start: false,
                ..Options::default()
            },
            margin: None,
        });
    }
    for warm in [false, true] {
        out.push(Setting {
            name: format!("f32 support {}", if warm { "warm" } else { "cold" }),
            group: Group::Precision,
            options: Options {
                precision: Precision::Single,
                warm_start: warm,
                ..Options::default()
            },
            margin: None,
        });
    }
    for (f, warm) in [(0.01, false), (0.1, false), (1.0, false), (0.1, true)] {
        out.push(Setting {
            name: format!("margin {f}·size {}", if warm { "warm" } else { "cold" }),
            group: Group::Margin,
            options: Options {
                warm_start: warm,
                ..Options::default()
            },
            margin: Some(f),
        });
    }
    out
}

fn bounding(s: &Shape) -> f64 {
    let convex = |c: &gjk::Convex, off: &Isometry3<f64>| {
        c.vertices()
            .iter()
            .map(|v| (off * v).coords.norm())
            .fold(0.0, f64::max)
            + c.radius()
    };
    match s {
        Shape::Convex(c) => convex(c, &Isometry3::identity()),
        Shape::Compound(c) => c
            .pieces()
            .iter()
            .map(|(o, p)| convex(p, o))
            .fold(0.0, f64::max),
    }
}

fn scaled(c: &gjk::Convex, s: f64) -> gjk::Convex {
    let v: Vec<Point3<f64>> = c.vertices().iter().map(|p| p * s).collect();
    gjk::Convex::new(v, c.radius() * s).expect("scaled vertices are finite")
}

/// The workload: shapes and queries (references not yet known).
fn workload(per_pair: usize) -> (Vec<Shape>, Vec<(extremes::RawCase, usize, usize)>) {
    let family = paper::family();
    let mut shapes: Vec<Shape> = family.iter().cloned().map(Shape::from).collect();
    let mut raw = Vec::new();
    for case in Case::ALL {
        for c in paper::cases(case, per_pair, 7) {
            raw.push((
                extremes::RawCase {
                    family: match case {
                        Case::Separated => "§7 separated",
                        Case::Touching => "§7 touching",
                        Case::Intersecting => "§7 intersecting",
                    },
                    label: format!("pair {} (M={})", c.pair + 1, c.m),
                    a: shapes[c.a].clone(),
                    pose_a: c.pose_a,
                    b: shapes[c.b].clone(),
                    pose_b: c.pose_b,
                    analytic: None,
                },
                c.a,
                c.b,
            ));
        }
    }
    // The paper's separated cases at tiny and huge scales.
    for (scale, name) in [(1e-6, "tiny scale"), (1e6, "huge scale")] {
        let base = shapes.len();
        shapes.extend(family.iter().map(|c| Shape::from(scaled(c, scale))));
        for c in paper::cases(Case::Separated, 1, 11) {
            let sc = |p: &Isometry3<f64>| {
                Isometry3::from_parts(Translation3::from(p.translation.vector * scale), p.rotation)
            };
            raw.push((
                extremes::RawCase {
                    family: name,
                    label: format!("§7 pair {} scaled by {scale:e}", c.pair + 1),
                    a: shapes[base + c.a].clone(),
                    pose_a: sc(&c.pose_a),
                    b: shapes[base + c.b].clone(),
                    pose_b: sc(&c.pose_b),
                    analytic: None,
                },
                base + c.a,
                base + c.b,
            ));
        }
    }
    for e in extremes::cases() {
        let (ia, ib) = (shapes.len(), shapes.len() + 1);
        shapes.push(e.a.clone());
        shapes.push(e.b.clone());
        raw.push((e, ia, ib));
    }
    (shapes, raw)
}

fn points_of(s: &Shape) -> (Vec<Point3<f64>>, f64) {
    match s {
        Shape::Convex(c) => (c.vertices().to_vec(), c.radius()),
        Shape::Compound(_) => unreachable!("the bench families are convex"),
    }
}

/// A hash of everything a reference depends on, so a cache from other
/// inputs (another family version, another `--per-pair`) is never used.
fn inputs_hash(raw: &[(extremes::RawCase, usize, usize)]) -> u64 {
    let mut h = std::hash::DefaultHasher::new();
    // The reference method's version: a cache from another method is stale.
    h.write_u32(3);
    for (r, _, _) in raw {
        for s in [&r.a, &r.b] {
            let (pts, rad) = points_of(s);
            for p in pts {
                for c in p.coords.iter() {
                    h.write_u64(c.to_bits());
                }
            }
            h.write_u64(rad.to_bits());
        }
        for p in [&r.pose_a, &r.pose_b] {
            for c in p.translation.vector.iter().chain(p.rotation.coords.iter()) {
                h.write_u64(c.to_bits());
            }
        }
    }
    h.finish()
}

/// References for `raw`, from the cache when it holds these very inputs.
fn references(
    raw: &[(extremes::RawCase, usize, usize)],
    shapes: &[Shape],
    cache_dir: &Path,
    progress: &Progress,
) -> Result<Vec<f64>, BenchError> {
    let hash = inputs_hash(raw);
    let path = cache_dir.join(format!("reference-{hash:016x}.csv"));
    if let Ok(text) = std::fs::read_to_string(&path) {
        let vals: Vec<f64> = text
            .lines()
            .skip(1)
            .filter_map(|l| l.split(',').nth(1))
            .filter_map(|hex| u64::from_str_radix(hex, 16).ok())
            .map(f64::from_bits)
            .collect();
        if vals.len() == raw.len() {
            progress.println(format!("reference distances: cached in {}", path.display()));
            return Ok(vals);
        }
    }
    let t0 = Instant::now();
    let mut hulls: BTreeMap<usize, (Hull, f64)> = BTreeMap::new();
    let mut out = Vec::with_capacity(raw.len());
    for (i, (r, ia, ib)) in raw.iter().enumerate() {
        if i % 50 == 0 {
            progress.step(format!("exact reference distances: {i}/{}", raw.len()));
        }
        if let Some(d) = r.analytic {
            out.push(d);
            continue;
        }
        for &k in [ia, ib] {
            hulls.entry(k).or_insert_with(|| {
                let (pts, rad) = points_of(&shapes[k]);
                (Hull::new(&pts), rad)
            });
        }
        let (ha, ra) = &hulls[ia];
        let (hb, rb) = &hulls[ib];
        let truth = reference::distance(ha, &r.pose_a, *ra, hb, &r.pose_b, *rb);
        // Cores not proven apart are within round-off of contact, where the
        // reference may answer a round-off-sized distance: they count as
        // touching, so that "per distance" errors stay those of separated
        // queries.
        out.push(if truth.separated { truth.distance } else { 0.0 });
    }
    let mut csv = Csv::new(&["index", "distance_bits", "distance", "family", "label"]);
    for ((r, _, _), d) in raw.iter().zip(&out) {
        csv.row(&[
            String::new(),
            format!("{:016x}", d.to_bits()),
            format!("{d:e}"),
            r.family.to_owned(),
            r.label.clone(),
        ]);
    }
    io("create the cache dir", std::fs::create_dir_all(cache_dir))?;
    io("write the reference cache", csv.write(&path))?;
    progress.println(format!(
        "reference distances: computed in {:.1} s, cached in {}",
        t0.elapsed().as_secs_f64(),
        path.display()
    ));
    Ok(out)
}

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

struct Summary {
    mean_ns: f64,
    p50_ns: f64,
    p99_ns: f64,
    max_err: f64,
    mean_err: f64,
    max_dist_rel: f64,
}

fn summarise(o: &Outcome) -> Summary {
    let mut ns = o.ns.clone();
    ns.sort_by(f64::total_cmp);
    Summary {
        mean_ns: mean(&ns),
        p50_ns: percentile(&ns, 0.5),
        p99_ns: percentile(&ns, 0.99),
        max_err: o.err.iter().copied().fold(0.0, f64::max),
        mean_err: mean(&o.err),
        max_dist_rel: o.dist_rel.iter().copied().fold(0.0, f64::max),
    }
}

/// Errors of 0 are drawn at this floor on the log axis.
const ERR_FLOOR: f64 = 1e-17;

fn report(
    args: &TradeoffArgs,
    dir: &Path,
    settings: &[Setting],
    outcomes: &[Outcome],
    queries: &[Query],
) -> Result<(), BenchError> {
    let sums: Vec<Summary> = outcomes.iter().map(summarise).collect();
    let base = settings
        .iter()
        .position(|s| s.group == Group::TolCold && s.options.tolerance == DEFAULT_EPS)
        .unwrap_or(0);
    let base_ns = sums[base].mean_ns;
    let mut csv = Csv::new(&[
        "setting",
        "group",
        "mean_ns",
        "p50_ns",
        "p99_ns",
        "speedup_vs_default",
        "max_err_rel_size",
        "mean_err_rel_size",
        "max_err_rel_distance",
        "max_err_rel_size_s7",
        "max_err_rel_size_extremes",
        "bounds_missed",
        "wrong_decisions",
        "iteration_capped",
        "queries",
    ]);
    let mut md = String::from(
        "| setting | mean ns | p50 ns | p99 ns | speed vs default | max error / size | mean error / size | max error / distance | max error / size, §7 | max error / size, extremes | bounds missed | wrong margin decisions |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for ((s, o), m) in settings.iter().zip(outcomes).zip(&sums) {
        let fam = |k: &str| o.by_family.get(k).copied().unwrap_or(f64::NAN);
        let speed = base_ns / m.mean_ns;
        csv.row(&[
            s.name.clone(),
            s.group.name().to_owned(),
            format!("{:.1}", m.mean_ns),
            format!("{:.1}", m.p50_ns),
            format!("{:.1}", m.p99_ns),
            format!("{speed:.3}"),
            format!("{:.3e}", m.max_err),
            format!("{:.3e}", m.mean_err),
            format!("{:.3e}", m.max_dist_rel),
            format!("{:.3e}", fam("§7")),
            format!("{:.3e}", fam("extremes")),
            o.misses.to_string(),
            o.wrong.to_string(),
            o.capped.to_string(),
            o.err.len().to_string(),
        ]);
        md.push_str(&format!(
            "| {} | {:.0} | {:.0} | {:.0} | {speed:.2}× | {:.1e} | {:.1e} | {:.1e} | {:.1e} | {:.1e} | {} | {} |\n",
            s.name,
            m.mean_ns,
            m.p50_ns,
            m.p99_ns,
            m.max_err,
            m.mean_err,
            m.max_dist_rel,
            fam("§7"),
            fam("extremes"),
            o.misses,
            if s.margin.is_some() { o.wrong.to_string() } else { "–".into() },
        ));
    }
    // What does going N× faster cost? Among the settings that still compute
    // the distance (margins answer a yes/no question instead), the most
    // accurate one at least N× faster than the default: once for independent
    // queries (cold), once for queries along a motion (warm start allowed).
    let mut rec = String::new();
    for (title, allow_warm) in [
        ("Independent queries (no warm start)", false),
        ("Queries along a motion (warm start allowed)", true),
    ] {
        rec.push_str(&format!(
            "{title}:\n\n| wanted speed-up | most accurate setting that fast | measured speed-up | max error / size | mean error / size | max error / distance |\n|---|---|---:|---:|---:|---:|\n"
        ));
        for want in [1.25, 1.5, 2.0, 3.0] {
            let pick = settings
                .iter()
                .zip(&sums)
                .filter(|(s, m)| {
                    s.group != Group::Margin
                        && (allow_warm || !s.options.warm_start)
                        && base_ns / m.mean_ns >= want
                })
                .min_by(|a, b| {
                    a.1.max_err
                        .total_cmp(&b.1.max_err)
                        .then(a.1.mean_ns.total_cmp(&b.1.mean_ns))
                });
            match pick {
                Some((s, m)) => rec.push_str(&format!(
                    "| {want}× | {} | {:.2}× | {:.1e} | {:.1e} | {:.1e} |\n",
                    s.name,
                    base_ns / m.mean_ns,
                    m.max_err,
                    m.mean_err,
                    m.max_dist_rel
                )),
                None => rec.push_str(&format!(
                    "| {want}× | none measured is this fast | | | | |\n"
                )),
            }
        }
        rec.push('\n');
    }
    // Fastest settings within an error budget.
    let mut budget = String::from(
        "Independent queries (no warm start):\n\n| max error / size allowed | fastest cold setting | mean ns | speed vs default | max error / size |\n|---|---|---:|---:|---:|\n",
    );
    let base_err = sums[base].max_err;
    for (label, cap) in [
        (
            format!("as accurate as the default ({base_err:.1e})"),
            base_err.max(ERR_FLOOR),
        ),
        ("1e-12".to_owned(), 1e-12),
        ("1e-9".to_owned(), 1e-9),
        ("1e-6".to_owned(), 1e-6),
        ("1e-3".to_owned(), 1e-3),
    ] {
        let pick = settings
            .iter()
            .zip(&sums)
            .zip(outcomes)
            .filter(|((s, m), o)| {
                s.group != Group::Margin
                    && !s.options.warm_start
                    && m.max_err <= cap
                    && o.misses == 0
            })
            .min_by(|a, b| a.0.1.mean_ns.total_cmp(&b.0.1.mean_ns));
        if let Some(((s, m), _)) = pick {
            budget.push_str(&format!(
                "| {label} | {} | {:.0} | {:.2}× | {:.1e} |\n",
                s.name,
                m.mean_ns,
                base_ns / m.mean_ns,
                m.max_err
            ));
        }
    }
    let counts = {
        let mut c: BTreeMap<&str, usize> = BTreeMap::new();
        for q in queries {
            *c.entry(q.family.as_str()).or_default() += 1;
        }
        c.iter()
            .map(|(k, v)| format!("{k}: {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let header = format!(
        "Machine: {}\n\nCommand: `gjkd bench tradeoff{}` ({} queries: {counts}; {} calls per timed block, fastest of {} passes)\n\nErrors are absolute errors of the returned distance against the exact reference, divided by the pair's size (sum of bounding radii); \"per distance\" divides by the true distance instead (separated queries only). A bound is missed when the reference lies outside the answer's certified [lower, upper] by more than {BOUND_SLACK:e} of the size (the reference's own round-off). The default setting (ε = 2.2e-14, cold, cap 128) is the speed baseline: {base_ns:.0} ns per query on average.\n\n",
        super::machine(),
        if args.common.quick { " --quick" } else { "" },
        queries.len(),
        args.reps,
        args.passes
    );
    let by_size = precision_by_size(args.common.quick, args.reps, args.passes)?;
    io(
        "write tradeoff-precision.csv",
        by_size.csv.write(&dir.join("tradeoff-precision.csv")),
    )?;
    let text = format!(
        "{header}## All settings\n\n{md}\n## What does going faster cost?\n\n{rec}\n## Fastest setting within an error budget\n\n{budget}\n## The support search by vertex count\n\n{}",
        by_size.md
    );
    println!("\n{text}");
    io("write tradeoff.csv", csv.write(&dir.join("tradeoff.csv")))?;
    io(
        "write tradeoff.md",
        std::fs::write(dir.join("tradeoff.md"), &text),
    )?;
    // Per-query times and errors, for anyone who wants to look at the worst
    // cases.
    let mut detail = Csv::new(&[
        "setting",
        "family",
        "query",
        "truth",
        "size",
        "ns",
        "error_rel_size",
    ]);
    for (s, o) in settings.iter().zip(outcomes) {
        for ((q, ns), e) in queries.iter().zip(&o.ns).zip(&o.err) {
            detail.row(&[
                s.name.clone(),
                q.family.clone(),
                q.label.clone(),
                format!("{:e}", q.truth),
                format!("{:e}", q.size),
                format!("{ns:.1}"),
                format!("{e:.3e}"),
            ]);
        }
    }
    // Large: kept beside the reference cache rather than in --out.
    let detail_path = args.cache_dir.join("tradeoff-queries.csv");
    io("write tradeoff-queries.csv", detail.write(&detail_path))?;
    pareto_plot(dir, settings, &sums)?;
    println!(
        "wrote {0}/tradeoff.csv, {0}/tradeoff.md, {0}/tradeoff-precision.csv, {0}/tradeoff-pareto.svg, {1}",
        dir.display(),
        detail_path.display()
    );
    Ok(())
}

fn pareto_plot(dir: &Path, settings: &[Setting], sums: &[Summary]) -> Result<(), BenchError> {
    let groups = [
        Group::TolCold,
        Group::TolWarm,
        Group::Cap,
        Group::Margin,
        Group::Precision,
    ];
    let mut charts = Vec::new();
    for (title, err) in [
        (
            "worst error against time (Pareto front)",
            (|m: &Summary| m.max_err) as fn(&Summary) -> f64,
        ),
        ("mean error against time (Pareto front)", |m: &Summary| {
            m.mean_err
        }),
    ] {
        let pts: Vec<(f64, f64)> = sums
            .iter()
            .map(|m| (err(m).max(ERR_FLOOR), m.mean_ns))
            .collect();
        // Front over (time, error): both are costs.
        let front_idx = pareto_front(&pts.iter().map(|p| (p.1, p.0)).collect::<Vec<_>>());
        let mut series: Vec<Series> = groups
            .iter()
            .enumerate()
            .map(|(gi, g)| Series {
                name: g.name().into(),
                points: settings
                    .iter()
                    .zip(&pts)
                    .filter(|(s, _)| s.group == *g)
                    .map(|(_, p)| *p)
                    .collect(),
                mark: Mark::Points,
                color: gi,
            })
            .collect();
        let mut front: Vec<(f64, f64)> = front_idx.iter().map(|&i| pts[i]).collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        series.push(Series {
            name: "Pareto front".into(),
            points: front,
            mark: Mark::Line,
            color: 7,
        });
        let x = Axis::fit(pts.iter().map(|p| p.0), true);
        // Times span less than a decade: a linear axis from 0 reads better.
        let y_max = pts
            .iter()
            .map(|p| p.1)
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        charts.push(Chart {
            title: title.into(),
            x: Axis::log("error / object size (log; 1e-17 = exact)", x)
                .with_ticks(|v| format!("{v:.0e}")),
            y: Axis::linear("mean time per query, ns", (0.0, y_max * 1.1))
                .with_ticks(|v| format!("{v:.0}")),
            series,
            legend: plot::Corner::LowerLeft,
        });
    }
    let path = dir.join("tradeoff-pareto.svg");
    plot::render(&path, &charts, 2, (600, 420))
        .map_err(|e| BenchError::Plot(path.display().to_string(), e))
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
