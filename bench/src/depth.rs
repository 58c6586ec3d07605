//! `gjkd bench depth`: what the penetration depth's tolerance
//! (`gjk::DepthOptions::tolerance`) costs and buys, on the same
//! overlapping pairs in one run.
//!
//! Two families: random polytope pairs (4 to 8 points each, any pose,
//! overlapping), whose true depth is the brute force of
//! [`gjkd_testkit::minkowski_depth`] (the Minkowski difference's facets by
//! exact orientation, nothing of GJK or EPA), and pairs of cylinders with
//! parallel axes (offset sideways and along the axis), whose depth is a
//! closed form. For each tolerance, every pair's signed distance is timed
//! as the fastest of `--passes` blocks of `--reps` calls, tolerances
//! interleaved pair by pair; the error is `|value - truth| / depth`, the
//! width `(upper - lower) / depth`, and every interval is checked to hold
//! the truth.

use std::hint::black_box;
use std::time::Instant;

use gjk::{Convex, DepthOptions, Shape, signed_distance};
use gjkd_testkit::minkowski_depth::minkowski_depth;
use gjkd_testkit::reference::P;
use gjkd_testkit::sweep::Rng;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::BenchError;

/// Flags of `gjkd bench depth`.
#[derive(clap::Args, Debug, Clone)]
pub struct DepthArgs {
    /// Overlapping pairs per family.
    #[arg(long, default_value_t = 200)]
    pairs: usize,
    /// Calls per timed block.
    #[arg(long, default_value_t = 8)]
    reps: u32,
    /// Timing passes; the fastest block of each pair and tolerance is kept.
    #[arg(long, default_value_t = 3)]
    passes: u32,
}

/// The tolerances compared.
const TOLERANCES: [f64; 5] = [1e-3, 1e-6, 1e-9, 1e-12, 0.0];

/// One overlapping pair and its true signed distance.
struct Pair {
    a: Shape,
    pose_a: Isometry3<f64>,
    b: Shape,
    pose_b: Isometry3<f64>,
    truth: f64,
}

/// A uniform vector in the cube `[-1, 1)³`.
fn vector(rng: &mut Rng) -> Vector3<f64> {
    Vector3::new(
        rng.uniform(-1.0, 1.0),
        rng.uniform(-1.0, 1.0),
        rng.uniform(-1.0, 1.0),
    )
}

/// A translation of up to `spread` along each axis and any rotation.
fn pose(rng: &mut Rng, spread: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(vector(rng) * spread),
        UnitQuaternion::from_scaled_axis(vector(rng) * std::f64::consts::PI),
    )
}

/// Overlapping random polytope pairs, with the brute-force depth.
fn polytopes(n: usize, rng: &mut Rng) -> Vec<Pair> {
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let cloud = |rng: &mut Rng| -> Vec<P> {
            let k = 4 + rng.below(5);
            (0..k).map(|_| P::from(vector(rng))).collect()
        };
        let (a, b) = (cloud(rng), cloud(rng));
        let (pose_a, pose_b) = (pose(rng, 0.6), pose(rng, 0.6));
        let placed = |s: &[P], p: &Isometry3<f64>| s.iter().map(|x| p * x).collect::<Vec<_>>();
        let Some((depth, _)) = minkowski_depth(&placed(&a, &pose_a), &placed(&b, &pose_b)) else {
            continue;
        };
        let (Ok(a), Ok(b)) = (Convex::new(a, 0.0), Convex::new(b, 0.0)) else {
            continue;
        };
        out.push(Pair {
            a: a.into(),
            pose_a,
            b: b.into(),
            pose_b,
            truth: -depth,
        });
    }
    out
}

/// Cylinders with parallel axes, offset sideways by `e` and along the
/// axis by `z`: the depth is the least of the disks' and the lengths'
/// overlaps.
fn cylinders(n: usize, rng: &mut Rng) -> Vec<Pair> {
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        let (ra, ha) = (rng.uniform(0.5, 1.0), rng.uniform(0.5, 1.5));
        let (rb, hb) = (rng.uniform(0.2, 0.7), rng.uniform(0.3, 1.3));
        let angle = rng.uniform(-std::f64::consts::PI, std::f64::consts::PI);
        let e = (ra + rb) * rng.unit_interval();
        let z = (ha + hb) * rng.uniform(-1.0, 1.0);
        let depth = (ra + rb - e).min(ha + hb - z.abs());
        if depth <= 1e-3 * (ra + rb) {
            continue;
        }
        let frame = pose(rng, 2.0);
        let offset = Isometry3::translation(e * angle.cos(), e * angle.sin(), z);
        let (Ok(a), Ok(b)) = (Convex::cylinder(ra, ha, 0.0), Convex::cylinder(rb, hb, 0.0)) else {
            continue;
        };
        out.push(Pair {
            a: a.into(),
            pose_a: frame,
            b: b.into(),
            pose_b: frame * offset,
            truth: -depth,
        });
    }
    out
}

/// One family's figures at one tolerance.
#[derive(Default)]
struct Row {
    nanos: Vec<f64>,
    errors: Vec<f64>,
    widths: Vec<f64>,
    expansions: Vec<f64>,
    excluded: usize,
}

/// Runs `gjkd bench depth` and prints its table.
///
/// # Errors
/// A query that fails (none should).
pub fn run(args: &DepthArgs) -> Result<(), BenchError> {
    let mut rng = Rng::new(0x5eed_de97_0001);
    let families = [
        ("polytopes", polytopes(args.pairs, &mut rng)),
        ("cylinders", cylinders(args.pairs, &mut rng)),
    ];
    println!(
        "| family | tolerance | mean µs | median µs | median error / depth | max error / depth | \
         median width / depth | mean points added | intervals excluding the truth |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (name, pairs) in &families {
        let mut rows: Vec<Row> = TOLERANCES.iter().map(|_| Row::default()).collect();
        for pair in pairs {
            for (row, &tolerance) in rows.iter_mut().zip(&TOLERANCES) {
                let options = DepthOptions {
                    tolerance,
                    ..DepthOptions::default()
                };
                let mut best = f64::INFINITY;
                let mut answer = None;
                for _ in 0..args.passes.max(1) {
                    let start = Instant::now();
                    for _ in 0..args.reps.max(1) {
                        answer = Some(black_box(signed_distance(
                            black_box(&pair.a),
                            &pair.pose_a,
                            &pair.b,
                            &pair.pose_b,
                            &options,
                        )));
                    }
                    let each = start.elapsed().as_secs_f64() * 1e9 / f64::from(args.reps.max(1));
                    best = best.min(each);
                }
                let sd = answer.expect("at least one call")?;
                let depth = -pair.truth;
                row.nanos.push(best);
                row.errors.push((sd.value - pair.truth).abs() / depth);
                row.widths.push((sd.upper - sd.lower) / depth);
                row.expansions.push(f64::from(sd.expansions));
                row.excluded += usize::from(!(sd.lower <= pair.truth && pair.truth <= sd.upper));
            }
        }
        for (row, tolerance) in rows.iter_mut().zip(TOLERANCES) {
            let n = row.nanos.len() as f64;
            let mean = |v: &[f64]| v.iter().sum::<f64>() / n;
            let median = |v: &mut Vec<f64>| {
                v.sort_by(f64::total_cmp);
                v[v.len() / 2]
            };
            let max = row.errors.iter().copied().fold(0.0, f64::max);
            println!(
                "| {name} | {tolerance:e} | {:.1} | {:.1} | {:.1e} | {:.1e} | {:.1e} | {:.1} | {} of {} |",
                mean(&row.nanos) / 1e3,
                median(&mut row.nanos) / 1e3,
                median(&mut row.errors),
                max,
                median(&mut row.widths),
                mean(&row.expansions),
                row.excluded,
                row.nanos.len()
            );
        }
    }
    Ok(())
}
