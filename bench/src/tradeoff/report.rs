//! The report: summaries per setting, the table, the precision by
//! shape size and the Pareto plot.

#[allow(unused_imports)]
use super::*;

pub(crate) struct Summary {
    pub(crate) mean_ns: f64,
    pub(crate) p50_ns: f64,
    pub(crate) p99_ns: f64,
    pub(crate) max_err: f64,
    pub(crate) mean_err: f64,
    pub(crate) max_dist_rel: f64,
}

pub(crate) fn summarise(o: &Outcome) -> Summary {
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
pub(crate) const ERR_FLOOR: f64 = 1e-17;

pub(crate) fn report(
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
        crate::machine(),
        if args.common.quick { " --quick" } else { "" },
        queries.len(),
        args.reps,
        args.passes
    );
    let by_size = precision_by_size(args)?;
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

/// The support search where it matters: the paper's polytopes have at most
/// 100 vertices, too few for the scan to dominate. Box clouds (8 corners and
/// `n - 8` points inside, so the hull is the box and the truth a closed form)
/// of 16 to 65 536 points, in a common random rotation with random gaps,
/// timed in f64 and f32, cold and warm. From 512 vertices the f64 search is
/// the block search, from 1 024 the f32 setting uses it too (see
/// `gjk::Precision`), so the table shows both the f32 knob and how the time
/// grows with the number of vertices.
pub(crate) struct BySize {
    pub(crate) md: String,
    pub(crate) csv: Csv,
}

pub(crate) fn precision_by_size(args: &TradeoffArgs) -> Result<BySize, BenchError> {
    let sizes: &[usize] = if args.common.quick {
        &[16, 1024]
    } else {
        &[16, 64, 256, 512, 1024, 4096, 16384, 65536]
    };
    let poses = if args.common.quick { 4 } else { 40 };
    let (ha, hb) = (Vector3::new(1.0, 0.6, 0.8), Vector3::new(0.7, 0.9, 0.5));
    let size = ha.norm() + hb.norm();
    let mut seed = 0x0dd_ba11_u64;
    let mut rnd = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut csv = Csv::new(&[
        "vertices",
        "setting",
        "mean_ns",
        "speedup_vs_f64_same_start",
        "max_err_rel_size",
        "widest_interval_rel_size",
        "bounds_missed",
        "queries",
    ]);
    let mut md = format!(
        "Box clouds of n points each (corners plus points inside), {poses} poses per n, gaps uniform in [0, 0.5) of the size and touching; {} calls per timed block, fastest of {} passes. Errors against the closed-form box distance, and the widest certified interval (upper - lower), divided by the size ({size:.2}). The f64 search scans every vertex below 64 vertices per shape, takes the exact cube map of candidate lists from 64 to 4 095 and the exact block search from 4 096 on; the f32 setting scans in f32 only where the exact search would be the portable scan of every vertex (16 to 1 023 vertices on a CPU without AVX2 and FMA), and is the exact search elsewhere.\n\n| vertices per shape | f64 cold ns | f32 cold ns | f32 speed-up, cold | f64 warm ns | f32 warm ns | f32 speed-up, warm | max error / size, f64 | max error / size, f32 | widest interval / size, f64 | widest interval / size, f32 | bounds missed |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        args.reps, args.passes
    );
    let cloud =
        |h: Vector3<f64>, n: usize, rnd: &mut dyn FnMut() -> f64| -> Result<Shape, BenchError> {
            let mut pts: Vec<Point3<f64>> = (0..n - 8)
                .map(|_| {
                    Point3::new(
                        (2.0 * rnd() - 1.0) * h.x,
                        (2.0 * rnd() - 1.0) * h.y,
                        (2.0 * rnd() - 1.0) * h.z,
                    )
                })
                .collect();
            pts.extend(gjk::Convex::cuboid(h, 0.0)?.vertices().iter().copied());
            Ok(gjk::Convex::new(pts, 0.0)?.into())
        };
    let mut cases = Vec::new();
    for &n in sizes {
        let (a, b) = (cloud(ha, n, &mut rnd)?, cloud(hb, n, &mut rnd)?);
        let mut qs = Vec::new();
        for k in 0..poses {
            let rot = UnitQuaternion::from_scaled_axis(
                Vector3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 6.0,
            );
            let dir = Vector3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
            let axis = dir.iamax();
            let gap = if k % 8 == 0 { 0.0 } else { 0.5 * size * rnd() };
            let mut rel = dir.component_mul(&(ha + hb));
            rel[axis] = (ha[axis] + hb[axis] + gap).copysign(dir[axis]);
            let pa = Isometry3::from_parts(Translation3::new(3.0, -2.0, 1.0), rot);
            let pb =
                Isometry3::from_parts(Translation3::from(pa.translation.vector + rot * rel), rot);
            let local =
                rot.inverse_transform_vector(&(pb.translation.vector - pa.translation.vector));
            let truth = reference::aabb_distance(&Vector3::zeros(), &ha, &local, &hb);
            let before = step_back(&pb, size);
            let warm = gjk::distance(&a, &pa, &b, &before, &Options::default(), None)?.warm_start;
            qs.push((pa, pb, truth, warm));
        }
        cases.push((n, a, b, qs));
    }
    let modes = [
        ("f64 cold", Precision::Double, false),
        ("f32 cold", Precision::Single, false),
        ("f64 warm", Precision::Double, true),
        ("f32 warm", Precision::Single, true),
    ];
    for (n, a, b, qs) in &cases {
        let mut ns = [0.0f64; 4];
        let mut err = [0.0f64; 4];
        let mut missed = [0usize; 4];
        let mut width = [0.0f64; 4];
        for (mi, &(_, precision, warm_on)) in modes.iter().enumerate() {
            let options = Options {
                precision,
                warm_start: warm_on,
                ..Options::default()
            };
            let mut total = 0.0;
            for (pa, pb, truth, warm) in qs {
                let warm = warm_on.then_some(warm);
                let ans = gjk::distance(a, pa, b, pb, &options, warm)?;
                err[mi] = err[mi].max((ans.distance - truth).abs() / size);
                width[mi] = width[mi].max((ans.upper - ans.lower) / size);
                let slack = BOUND_SLACK * size;
                if *truth < ans.lower - slack || *truth > ans.upper + slack {
                    missed[mi] += 1;
                }
                let mut best = f64::INFINITY;
                for _ in 0..args.passes {
                    let t0 = Instant::now();
                    for _ in 0..args.reps {
                        black_box(gjk::distance(black_box(a), pa, b, pb, &options, warm)?);
                    }
                    best = best.min(t0.elapsed().as_nanos() as f64 / f64::from(args.reps));
                }
                total += best;
            }
            ns[mi] = total / qs.len() as f64;
        }
        for (mi, (name, _, _)) in modes.iter().enumerate() {
            // f64 of the same start (cold or warm) is the baseline.
            let speed = ns[mi & 2] / ns[mi];
            csv.row(&[
                n.to_string(),
                (*name).to_owned(),
                format!("{:.1}", ns[mi]),
                format!("{speed:.3}"),
                format!("{:.3e}", err[mi]),
                format!("{:.3e}", width[mi]),
                missed[mi].to_string(),
                qs.len().to_string(),
            ]);
        }
        md.push_str(&format!(
            "| {n} | {:.0} | {:.0} | {:.2}× | {:.0} | {:.0} | {:.2}× | {:.1e} | {:.1e} | {:.1e} | {:.1e} | {} |\n",
            ns[0],
            ns[1],
            ns[0] / ns[1],
            ns[2],
            ns[3],
            ns[2] / ns[3],
            err[0].max(err[2]),
            err[1].max(err[3]),
            width[0].max(width[2]),
            width[1].max(width[3]),
            missed.iter().sum::<usize>()
        ));
    }
    Ok(BySize { md, csv })
}

pub(crate) fn pareto_plot(
    dir: &Path,
    settings: &[Setting],
    sums: &[Summary],
) -> Result<(), BenchError> {
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
