//! `gjkd bench tradeoff`'s table of the f32 support search by vertex count:
//! box clouds of 16 to 65 536 points, f64 against f32, cold and warm, with
//! closed-form truths. Also what the family's measurement shares with it:
//! the step a warm query starts from, and the slack of a missed bound.

use std::hint::black_box;
use std::time::Instant;

use gjk::{Options, Precision, Shape};
use gjkd_testkit::reference;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

use crate::BenchError;
use crate::stats::Csv;

/// Reference distances may be off by their own round-off; a bound counts as
/// missed only past this many units of the pair's size.
pub(crate) const BOUND_SLACK: f64 = 1e-13;

/// The pose one small step before `pose`: 1% of `size` along a fixed
/// direction and 0.02 rad about a fixed axis.
pub(crate) fn step_back(pose: &Isometry3<f64>, size: f64) -> Isometry3<f64> {
    let dir = Vector3::new(0.6, -0.48, 0.64);
    let rot = UnitQuaternion::from_scaled_axis(Vector3::new(0.3, 0.9, -0.3).normalize() * 0.02);
    Isometry3::from_parts(
        Translation3::from(pose.translation.vector - dir * (0.01 * size)),
        rot * pose.rotation,
    )
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

pub(crate) fn precision_by_size(quick: bool, reps: u32, passes: u32) -> Result<BySize, BenchError> {
    let sizes: &[usize] = if quick {
        &[16, 1024]
    } else {
        &[16, 64, 256, 512, 1024, 4096, 16384, 65536]
    };
    let poses = if quick { 4 } else { 40 };
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
        reps, passes
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
                for _ in 0..passes {
                    let t0 = Instant::now();
                    for _ in 0..reps {
                        black_box(gjk::distance(black_box(a), pa, b, pb, &options, warm)?);
                    }
                    best = best.min(t0.elapsed().as_nanos() as f64 / f64::from(reps));
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
