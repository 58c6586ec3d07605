//! gjk against parry3d-f64 on the paper's test data, in one run.
//!
//! ```text
//! cargo run --release -p gjkd-bench --example paper_compare [PER_PAIR]
//! ```
//!
//! Section 7: the family of twelve polytopes, twenty pairs, three cases,
//! `PER_PAIR` random poses each (default 100, the paper's 6000 queries).
//! Timing is by `std::time::Instant`: each timed batch runs a group's queries
//! several times; the reported time is the median over batches, the two
//! libraries interleaved batch by batch. Errors are measured against a
//! reference: gjk with tolerance 0, cross-checked against the construction
//! (the drawn gap, or 0) and against parry.
//!
//! Section 8: the collision sweep of `gjkd_testkit::paper::section8()` for T = 10, 100,
//! 1000, cold start against warm start, beside the paper's Table 1; then warm
//! against cold along a 1000-step motion of family pairs from M = 16 to 200.

use std::hint::black_box;
use std::time::Instant;

use gjk::{Options, Shape};
use gjkd_testkit::paper::{self, Case, FamilyCase, PAIRS};
use gjkd_testkit::parry::{parry_family, parry_pose};
use gjkd_testkit::reference::{self, Hull};
use parry3d_f64::math::Pose;

/// Target duration of one timed batch.
const BATCH_NS: f64 = 200_000.0;
/// Batches per measurement (the median is reported).
const BATCHES: usize = 31;

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn percentile(v: &mut [f64], p: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * p).round() as usize]
}

/// Batch timings of two closures, ns per query.
struct Timing {
    f_median: f64,
    g_median: f64,
    f_min: f64,
    g_min: f64,
}

/// Times `f` and `g` (each doing `per_call` queries) in batches, interleaved
/// so drift hits both alike; ns per query, median and fastest batch.
fn time_pair(per_call: usize, mut f: impl FnMut() -> f64, mut g: impl FnMut() -> f64) -> Timing {
    // Calibrate the repetition count on f (the two are within a small factor).
    let t = Instant::now();
    black_box(f());
    black_box(g());
    let one = t.elapsed().as_nanos().max(1) as f64 / 2.0;
    let reps = ((BATCH_NS / one).ceil() as usize).clamp(1, 100_000);
    let (mut tf, mut tg) = (Vec::with_capacity(BATCHES), Vec::with_capacity(BATCHES));
    for _ in 0..BATCHES {
        let t = Instant::now();
        for _ in 0..reps {
            black_box(f());
        }
        tf.push(t.elapsed().as_nanos() as f64 / (reps * per_call) as f64);
        let t = Instant::now();
        for _ in 0..reps {
            black_box(g());
        }
        tg.push(t.elapsed().as_nanos() as f64 / (reps * per_call) as f64);
    }
    Timing {
        f_median: median(&mut tf),
        g_median: median(&mut tg),
        f_min: percentile(&mut tf, 0.0),
        g_min: percentile(&mut tg, 0.0),
    }
}

/// One line of the table by M: `M`, pair index, (gjk, parry) ns per query
/// for each case, mean gjk iterations.
type Row = (usize, usize, [(f64, f64); 3], f64);

struct Prepared {
    case: FamilyCase,
    pa: Pose,
    pb: Pose,
}

fn main() {
    let per_pair: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().expect("PER_PAIR must be a number"))
        .unwrap_or(100);
    let seed = 7;
    let family = paper::family();
    let shapes: Vec<Shape> = family.iter().cloned().map(Shape::from).collect();
    let parry = parry_family(&family);
    let options = Options::default();
    let exact = Options {
        tolerance: 0.0,
        max_iterations: 1000,
        margin: None,
        warm_start: false,
        ..Options::default()
    };

    let gjk_q = |c: &FamilyCase, o: &Options| {
        gjk::distance(&shapes[c.a], &c.pose_a, &shapes[c.b], &c.pose_b, o, None)
            .expect("valid input")
    };
    let parry_q = |p: &Prepared| {
        parry3d_f64::query::distance(&p.pa, &*parry[p.case.a], &p.pb, &*parry[p.case.b])
            .expect("supported pair")
            .distance
    };

    println!(
        "Section 7 family: {} pairs x 3 cases x {} poses = {} queries (seed {seed})",
        PAIRS.len(),
        per_pair,
        PAIRS.len() * 3 * per_pair
    );
    println!(
        "gjk: Options::default() (tolerance 100 eps), no warm start; parry3d-f64 0.31 query::distance\n"
    );

    // ---------------------------------------------------------------- accuracy
    println!("Accuracy. Reference: brute force over hull boundaries (separated, touching),");
    println!("0 by construction (intersecting, also checked: gjk lower bound 0 and parry 0).");
    println!(
        "{:<13} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>5} {:>8}",
        "case",
        "ref-constr",
        "gjk med",
        "gjk max",
        "parry med",
        "parry max",
        "gjk up-lo",
        "bkup",
        "tol0 bad"
    );
    let hulls: Vec<Hull> = family.iter().map(|c| Hull::new(c.vertices())).collect();
    let mut all: Vec<(Case, Vec<Prepared>)> = Vec::new();
    for case in Case::ALL {
        let prepared: Vec<Prepared> = paper::cases(case, per_pair, seed)
            .into_iter()
            .map(|c| Prepared {
                pa: parry_pose(&c.pose_a),
                pb: parry_pose(&c.pose_b),
                case: c,
            })
            .collect();
        let mut ref_constr = 0.0f64;
        let (mut eg, mut ep) = (Vec::new(), Vec::new());
        let mut width = 0.0f64;
        let (mut backups, mut tol0_bad) = (0, 0);
        for p in &prepared {
            let c = &p.case;
            let reference = match case {
                Case::Intersecting => 0.0,
                _ => {
                    let (ha, hb) = (&hulls[c.a], &hulls[c.b]);
                    reference::distance(ha, &c.pose_a, 0.0, hb, &c.pose_b, 0.0).distance
                }
            };
            let g = gjk_q(c, &options);
            let d = parry_q(p);
            let z = gjk_q(c, &exact);
            backups += usize::from(g.backup_used);
            tol0_bad += usize::from((z.distance - reference).abs() > 1e-6);
            ref_constr = ref_constr.max((reference - c.expected).abs());
            width = width.max(g.upper - g.lower);
            assert!(
                g.lower <= reference + 1e-12 && reference <= g.upper + 1e-12,
                "bounds"
            );
            eg.push((g.distance - reference).abs());
            ep.push((d - reference).abs());
        }
        println!(
            "{:<13} {:>10.1e} {:>10.1e} {:>10.1e} {:>10.1e} {:>10.1e} {:>10.1e} {:>5} {:>8}",
            case.name(),
            ref_constr,
            median(&mut eg),
            percentile(&mut eg, 1.0),
            median(&mut ep),
            percentile(&mut ep, 1.0),
            width,
            backups,
            tol0_bad
        );
        all.push((case, prepared));
    }
    let fallback = all[2]
        .1
        .iter()
        .zip(&all[1].1)
        .filter(|(i, t)| i.case.push != t.case.push)
        .count();
    println!(
        "(ref-constr: largest |reference - constructed distance|; med/max: median and largest"
    );
    println!(
        " absolute error; gjk up-lo: widest certified interval; bkup: gjk queries that used the"
    );
    println!(
        " Backup Procedure; tol0 bad: gjk with tolerance 0 off the reference by more than 1e-6)"
    );
    println!(
        " {fallback} of {} intersecting examples were pushed towards A's centroid (the near-point line",
        all[2].1.len()
    );
    println!(" left A - B at once); the rest along the near-point line, as in the paper.\n");

    // ------------------------------------------------------------ time by M
    println!("Time per query (ns, median of {BATCHES} batches), by M = M1 + M2:");
    println!(
        "{:>4} {:>8}  {:>9} {:>9} {:>6}  {:>9} {:>9} {:>6}  {:>9} {:>9} {:>6}  {:>6}",
        "M",
        "pair",
        "sep gjk",
        "parry",
        "ratio",
        "tch gjk",
        "parry",
        "ratio",
        "int gjk",
        "parry",
        "ratio",
        "iters"
    );
    let mut rows: Vec<Row> = Vec::new();
    for (pair, &(a, b)) in PAIRS.iter().enumerate() {
        let mut cols = [(0.0, 0.0); 3];
        let mut iters = 0u64;
        for (k, (_, prepared)) in all.iter().enumerate() {
            let group = &prepared[pair * per_pair..(pair + 1) * per_pair];
            iters += group
                .iter()
                .map(|p| u64::from(gjk_q(&p.case, &options).iterations))
                .sum::<u64>();
            let t = time_pair(
                group.len(),
                || {
                    group
                        .iter()
                        .map(|p| {
                            gjk::distance(
                                black_box(&shapes[a]),
                                black_box(&p.case.pose_a),
                                &shapes[b],
                                black_box(&p.case.pose_b),
                                &options,
                                None,
                            )
                            .expect("valid input")
                            .distance
                        })
                        .sum()
                },
                || {
                    group
                        .iter()
                        .map(|p| {
                            parry3d_f64::query::distance(
                                black_box(&p.pa),
                                black_box(&*parry[a]),
                                black_box(&p.pb),
                                &*parry[b],
                            )
                            .expect("supported pair")
                            .distance
                        })
                        .sum()
                },
            );
            cols[k] = (t.f_median, t.g_median);
        }
        let m = all[0].1[pair * per_pair].case.m;
        rows.push((m, pair, cols, iters as f64 / (3 * per_pair) as f64));
    }
    rows.sort_by_key(|r| r.0);
    for (m, pair, cols, iters) in &rows {
        let (a, b) = PAIRS[*pair];
        print!("{m:>4} {:>8}", format!("({},{})", a + 1, b + 1));
        for (g, p) in cols {
            print!("  {g:>9.0} {p:>9.0} {:>6.2}", g / p);
        }
        println!("  {iters:>6.2}");
    }
    println!(
        "(pair in the paper's 1-based numbering; iters: mean gjk subalgorithm runs per query)\n"
    );

    // Summary: the time of one query of the family, per library.
    let mut per_group_g = Vec::new();
    let mut per_group_p = Vec::new();
    let mut ratios = Vec::new();
    for (_, _, cols, _) in &rows {
        for (g, p) in cols {
            per_group_g.push(*g);
            per_group_p.push(*p);
            ratios.push(g / p);
        }
    }
    let mean_g = per_group_g.iter().sum::<f64>() / per_group_g.len() as f64;
    let mean_p = per_group_p.iter().sum::<f64>() / per_group_p.len() as f64;
    let (med_g, med_p) = (median(&mut per_group_g), median(&mut per_group_p));
    println!("Whole family (60 groups of {per_pair}):");
    println!(
        "  mean ns/query     gjk {mean_g:>8.0}   parry {mean_p:>8.0}   gjk/parry {:.3}",
        mean_g / mean_p
    );
    println!(
        "  median of groups  gjk {med_g:>8.0}   parry {med_p:>8.0}   gjk/parry {:.3}",
        med_g / med_p
    );
    println!(
        "  per-group gjk/parry ratio: median {:.3}, min {:.3}, max {:.3}",
        median(&mut ratios),
        percentile(&mut ratios, 0.0),
        percentile(&mut ratios, 1.0)
    );

    // Per-query median: each query timed alone (16 calls, best of 5).
    let mut qg = Vec::new();
    let mut qp = Vec::new();
    for (_, prepared) in &all {
        for p in prepared {
            let (a, b) = (p.case.a, p.case.b);
            let mut bg = f64::INFINITY;
            let mut bp = f64::INFINITY;
            for _ in 0..5 {
                let t = Instant::now();
                for _ in 0..16 {
                    black_box(
                        gjk::distance(
                            black_box(&shapes[a]),
                            black_box(&p.case.pose_a),
                            &shapes[b],
                            &p.case.pose_b,
                            &options,
                            None,
                        )
                        .expect("valid input"),
                    );
                }
                bg = bg.min(t.elapsed().as_nanos() as f64 / 16.0);
                let t = Instant::now();
                for _ in 0..16 {
                    black_box(
                        parry3d_f64::query::distance(
                            black_box(&p.pa),
                            black_box(&*parry[a]),
                            &p.pb,
                            &*parry[b],
                        )
                        .expect("supported pair"),
                    );
                }
                bp = bp.min(t.elapsed().as_nanos() as f64 / 16.0);
            }
            qg.push(bg);
            qp.push(bp);
        }
    }
    let (mg, mp) = (median(&mut qg), median(&mut qp));
    println!(
        "  median over all {} queries (each timed alone, best of 5 x 16 calls): gjk {mg:.0} ns, parry {mp:.0} ns, gjk/parry {:.3}\n",
        qg.len(),
        mg / mp
    );

    // ---------------------------------------------------------------- Section 8
    let motion = paper::section8();
    println!("Section 8 sweep: K_A = K6 u K7 through K1..K5, s = t/T, 5 distances per step");
    let probe = motion.sweep(1000, &options, false).expect("valid input");
    for i in 0..paper::OBSTACLES {
        let d: Vec<f64> = probe.distances.iter().map(|d| d[i]).collect();
        let zero = d.iter().filter(|&&x| x == 0.0).count();
        let first = d.iter().position(|&x| x == 0.0);
        let last = d.iter().rposition(|&x| x == 0.0);
        let min = d.iter().copied().fold(f64::INFINITY, f64::min);
        let pen = probe.penetrations.iter().map(|p| p[i]).fold(0.0, f64::max);
        match (first, last) {
            (Some(f), Some(l)) => println!(
                "  d{}: 0 for {zero} of 1001 steps, s in [{:.3}, {:.3}], largest penetration bound {pen:.3}",
                i + 1,
                f as f64 / 1000.0,
                l as f64 / 1000.0
            ),
            _ => println!("  d{}: never 0, min {min:.3}", i + 1),
        }
    }
    println!(
        "\n(compound: 5 queries of K_A = K6 u K7 per step, gjk warm-starts the nearest and runner-up piece pairs;"
    );
    println!(
        " pieces: the paper's setup, 10 convex queries d_6i, d_7i per step, each warm-started)"
    );
    println!(
        "{:>6} {:<9} {:>10} {:>10} {:>7} {:>9} {:>6} {:>10} {:>10} {:>10}",
        "T",
        "mode",
        "cold us",
        "warm us",
        "ratio",
        "ratio min",
        "paper",
        "cold it/q",
        "warm it/q",
        "warm ns/q"
    );
    for (steps, paper_ratio) in [(10usize, 1.7), (100, 2.9), (1000, 3.1)] {
        for pieces in [false, true] {
            let run = |warm: bool| {
                if pieces {
                    motion.sweep_pieces(black_box(steps), &options, warm)
                } else {
                    motion.sweep(black_box(steps), &options, warm)
                }
                .expect("valid input")
            };
            let queries = (steps + 1) * paper::OBSTACLES * if pieces { 2 } else { 1 };
            let (cold, warm) = (run(false), run(true));
            let t = time_pair(
                1,
                || run(false).iterations as f64,
                || run(true).iterations as f64,
            );
            let (tc, tw) = (t.f_median, t.g_median);
            println!(
                "{steps:>6} {:<9} {:>10.1} {:>10.1} {:>7.2} {:>9.2} {:>6.1} {:>10.2} {:>10.2} {:>10.0}",
                if pieces { "pieces" } else { "compound" },
                tc / 1000.0,
                tw / 1000.0,
                tc / tw,
                t.f_min / t.g_min,
                paper_ratio,
                cold.iterations as f64 / queries as f64,
                warm.iterations as f64 / queries as f64,
                tw / queries as f64
            );
        }
    }
    println!(
        "(times: median batch per whole sweep; ratio = cold/warm of the medians, ratio min = of the\n fastest batches; paper = Table 1; it/q = subalgorithm runs per query)"
    );
    larger_motions(&options);
}

/// Warm against cold along a 1000-step motion of two members of the Section
/// 7 family, small to large: the fixed cost of a query (poses, set-up, the
/// answer in world coordinates) is the same either way, so the ratio grows
/// with the support scans that a warm start saves.
fn larger_motions(options: &Options) {
    use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
    let family: Vec<Shape> = paper::family().into_iter().map(Into::into).collect();
    println!(
        "\nWarm vs cold along a 1000-step motion of family pairs (B slides 4 units and turns 1.5 rad past A turning 0.6 rad):"
    );
    println!(
        "{:>4} {:>8} {:>10} {:>10} {:>7} {:>10} {:>10}",
        "M", "pair", "cold ns/q", "warm ns/q", "ratio", "cold it/q", "warm it/q"
    );
    let steps = 1000;
    let poses: Vec<(Isometry3<f64>, Isometry3<f64>)> = (0..=steps)
        .map(|t| {
            let s = t as f64 / steps as f64;
            let pa = Isometry3::from_parts(
                Translation3::new(0.0, 0.0, 0.0),
                UnitQuaternion::from_scaled_axis(Vector3::new(0.3, 0.1, 0.2) * (3.0 * s)),
            );
            let pb = Isometry3::from_parts(
                Translation3::new(9.0 - 4.0 * s, s, 0.5),
                UnitQuaternion::from_scaled_axis(Vector3::new(-0.2, 0.4, 0.1) * (5.0 * s)),
            );
            (pa, pb)
        })
        .collect();
    for (a, b) in [(2usize, 2usize), (4, 5), (7, 9), (10, 11), (11, 11)] {
        let run = |warm: bool| {
            let mut last: Option<gjk::WarmStart> = None;
            let mut iterations = 0u64;
            for (pa, pb) in &poses {
                let w = if warm { last.as_ref() } else { None };
                let ans = gjk::distance(black_box(&family[a]), pa, &family[b], pb, options, w)
                    .expect("valid input");
                iterations += u64::from(ans.iterations);
                last = Some(ans.warm_start);
            }
            iterations as f64
        };
        let queries = (steps + 1) as f64;
        let (ic, iw) = (run(false) / queries, run(true) / queries);
        let t = time_pair(1, || run(false), || run(true));
        let m = match (&family[a], &family[b]) {
            (Shape::Convex(x), Shape::Convex(y)) => x.len() + y.len(),
            _ => 0,
        };
        println!(
            "{m:>4} {:>8} {:>10.0} {:>10.0} {:>7.2} {:>10.2} {:>10.2}",
            format!("({},{})", a + 1, b + 1),
            t.f_median / queries,
            t.g_median / queries,
            t.f_median / t.g_median,
            ic,
            iw
        );
    }
}
