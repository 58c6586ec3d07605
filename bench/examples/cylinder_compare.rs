//! Cylinder queries against a 16-vertex polytope's, in one run.
//!
//! ```text
//! cargo run --release -p gjkd-bench --example cylinder_compare
//! ```
//!
//! The same random poses (separated, near contact and overlapping), once
//! with exact cylinders and once with each cylinder replaced by the octagonal
//! prism of its size (16 vertices): cylinder against cylinder and against a
//! box, cold and warm along a motion. Timing is by the thread's CPU clock
//! (`CLOCK_THREAD_CPUTIME_ID`), the two interleaved batch by batch, the
//! median over batches reported. Not wall time: on a loaded machine a
//! cylinder batch (milliseconds) is preempted far more often than a
//! prism batch (a tenth of that), which biased the wall-time ratio
//! against the cylinder by up to 2x.
//!
//! Beside the times, on the same cases: the mean iterations of each, and
//! the cylinder answers' error against a reference, the 65 536-sided
//! prisms inscribed in and circumscribed about each cylinder, whose
//! certified bounds bracket the truth within 1.2e-9 of the radius:
//! `out` counts answers outside the judged bound (relative 1e-6,
//! absolute 1e-9 of the size) of the bracket or whose bounds miss it.
//! The `seeded` rows start each query from the final simplex of the same
//! query at the same pose: a warm start at the answer itself, which the
//! cylinder's Newton seed (`gjk/src/query/newton_seed.rs`) confirms from
//! its first supports, and the run, where the answer lies on a flat
//! feature, certifies in one iteration.

use std::hint::black_box;

use gjk::{Convex, Options, Shape, WarmStart, distance};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// Batches per measurement (the median is reported).
const BATCHES: usize = 41;

/// The octagonal prism of a cylinder's size: 16 vertices.
fn prism(r: f64, h: f64) -> Shape {
    let mut pts = Vec::new();
    for k in 0..8 {
        let t = std::f64::consts::TAU * f64::from(k) / 8.0;
        for z in [-h, h] {
            pts.push(Point3::new(r * t.cos(), r * t.sin(), z));
        }
    }
    Convex::new(pts, 0.0).expect("a valid prism").into()
}

/// A small xorshift generator, uniform in [-1, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// Random poses of B about A at the origin: some far, some near contact,
/// some overlapping.
fn poses(rng: &mut Rng, n: usize) -> Vec<Isometry3<f64>> {
    (0..n)
        .map(|k| {
            let reach = [4.0, 2.2, 1.2][k % 3];
            let dir = Vector3::new(rng.next(), rng.next(), rng.next()).normalize();
            Isometry3::from_parts(
                Translation3::from(dir * reach),
                UnitQuaternion::from_euler_angles(
                    rng.next() * 3.0,
                    rng.next() * 3.0,
                    rng.next() * 3.0,
                ),
            )
        })
        .collect()
}

/// A motion of B past A: `n` small steps.
fn motion(n: usize) -> Vec<Isometry3<f64>> {
    (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            Isometry3::from_parts(
                Translation3::new(-3.0 + 6.0 * t, 0.3, 1.4 * (3.0 * t).sin()),
                UnitQuaternion::from_scaled_axis(Vector3::new(0.3, 1.0, 0.5).normalize() * 5.0 * t),
            )
        })
        .collect()
}

/// How each query of a batch starts.
#[derive(Clone, Copy)]
enum Start {
    Cold,
    /// From the previous query's answer.
    Warm,
    /// From the same query's own final simplex (see the module's note).
    Seeded,
}

/// Nanoseconds per query of `a` against `b` at `poses`, and the mean
/// iterations; `seeds` holds each pose's own final simplex.
fn per_query(
    a: &Shape,
    b: &Shape,
    poses: &[Isometry3<f64>],
    start: Start,
    seeds: &[WarmStart],
) -> (f64, f64) {
    let opts = Options::default();
    let id = Isometry3::identity();
    let mut last: Option<WarmStart> = None;
    let mut iterations = 0u64;
    let clock = thread_cpu_ns();
    for (k, p) in poses.iter().enumerate() {
        let warm = match start {
            Start::Cold => None,
            Start::Warm => last.as_ref(),
            Start::Seeded => Some(&seeds[k]),
        };
        let ans = distance(a, &id, b, p, &opts, warm).expect("valid input");
        last = Some(ans.warm_start);
        iterations += u64::from(ans.iterations);
        black_box(ans.distance);
    }
    (
        (thread_cpu_ns() - clock) as f64 / poses.len() as f64,
        iterations as f64 / poses.len() as f64,
    )
}

/// This thread's CPU time so far, in nanoseconds.
fn thread_cpu_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid timespec to write; the clock id is a constant.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "the thread CPU clock is available on Linux");
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

/// Each pose's own final simplex, cold.
fn own_simplexes(a: &Shape, b: &Shape, poses: &[Isometry3<f64>]) -> Vec<WarmStart> {
    let id = Isometry3::identity();
    poses
        .iter()
        .map(|p| {
            distance(a, &id, b, p, &Options::default(), None)
                .expect("valid input")
                .warm_start
        })
        .collect()
}

/// A shape with the fine prisms that bracket it (itself for a polytope).
struct Bracketed {
    exact: Shape,
    inner: Shape,
    outer: Shape,
    size: f64,
}

/// Sides of the reference prisms (see the module's note).
const FINE_SIDES: u32 = 65_536;

fn fine_prism(r: f64, h: f64) -> Shape {
    let mut pts = Vec::new();
    for k in 0..FINE_SIDES {
        let t = std::f64::consts::TAU * f64::from(k) / f64::from(FINE_SIDES);
        for z in [-h, h] {
            pts.push(Point3::new(r * t.cos(), r * t.sin(), z));
        }
    }
    Convex::new(pts, 0.0).expect("a valid prism").into()
}

fn bracketed_cylinder(r: f64, h: f64) -> Bracketed {
    let widen = 1.0 / (std::f64::consts::PI / f64::from(FINE_SIDES)).cos();
    Bracketed {
        exact: Convex::cylinder(r, h, 0.0).expect("valid").into(),
        inner: fine_prism(r, h),
        outer: fine_prism(r * widen, h),
        size: r.hypot(h),
    }
}

/// The error of the cylinder answers that [`per_query`] times, started
/// the same way: answers outside the judged bound of the reference
/// bracket, or with bounds that miss it, and the widest relative bound gap.
fn errors(
    a: &Bracketed,
    b: &Bracketed,
    poses: &[Isometry3<f64>],
    start: Start,
    seeds: &[WarmStart],
) -> (usize, f64) {
    let (opts, id) = (Options::default(), Isometry3::identity());
    let size = a.size + b.size;
    let (mut out, mut widest) = (0, 0.0f64);
    let mut last: Option<WarmStart> = None;
    for (k, p) in poses.iter().enumerate() {
        let warm = match start {
            Start::Cold => None,
            Start::Warm => last.as_ref(),
            Start::Seeded => Some(&seeds[k]),
        };
        let got = distance(&a.exact, &id, &b.exact, p, &opts, warm).expect("valid input");
        last = Some(got.warm_start);
        let lo = distance(&a.outer, &id, &b.outer, p, &opts, None)
            .expect("valid input")
            .lower;
        let hi = distance(&a.inner, &id, &b.inner, p, &opts, None)
            .expect("valid input")
            .upper;
        let bound = 1e-6 * lo.max(0.0) + 1e-9 * size;
        let fuzz = 1e-12 * size;
        if (got.distance - lo).abs() > bound
            || (got.distance - hi).abs() > bound
            || got.lower > hi + fuzz
            || got.upper < lo - fuzz
        {
            out += 1;
        }
        widest = widest.max((got.upper - got.lower) / (1e-6 * got.distance + 1e-9 * size));
    }
    (out, widest)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut rng = Rng(0x5eed_c711_bea7_0001);
    let random = poses(&mut rng, 3000);
    let moving = motion(3000);
    let (r1, h1, r2, h2) = (0.5, 0.8, 0.3, 0.6);
    let cyl_a = bracketed_cylinder(r1, h1);
    let cyl_b = bracketed_cylinder(r2, h2);
    let (poly_a, poly_b) = (prism(r1, h1), prism(r2, h2));
    let half = Vector3::new(0.4, 0.3, 0.5);
    let boxed: Shape = Convex::cuboid(half, 0.0).expect("valid").into();
    let box_bracket = Bracketed {
        exact: boxed.clone(),
        inner: boxed.clone(),
        outer: boxed.clone(),
        size: half.norm(),
    };
    println!(
        "{:<32} {:>11} {:>11} {:>6} {:>6} {:>6} {:>4} {:>8}",
        "query", "cylinder ns", "16-vert ns", "ratio", "cyl it", "16v it", "out", "max gap"
    );
    let pairs = [
        ("cylinder-cylinder", (&cyl_a, &cyl_b), (&poly_a, &poly_b)),
        ("cylinder-box", (&cyl_a, &box_bracket), (&poly_a, &boxed)),
    ];
    for (name, (ca, cb), (pa, pb)) in pairs {
        let modes = [
            ("cold", &random, Start::Cold),
            ("warm motion", &moving, Start::Warm),
            ("seeded, random", &random, Start::Seeded),
            ("seeded, motion", &moving, Start::Seeded),
        ];
        for (mode, poses, start) in modes {
            let cyl_seeds = own_simplexes(&ca.exact, &cb.exact, poses);
            let poly_seeds = own_simplexes(pa, pb, poses);
            let (out, widest) = errors(ca, cb, poses, start, &cyl_seeds);
            let (mut cyl, mut poly) = (Vec::new(), Vec::new());
            let (mut cyl_it, mut poly_it) = (0.0, 0.0);
            for _ in 0..BATCHES {
                let (t, it) = per_query(&ca.exact, &cb.exact, poses, start, &cyl_seeds);
                cyl.push(t);
                cyl_it = it;
                let (t, it) = per_query(pa, pb, poses, start, &poly_seeds);
                poly.push(t);
                poly_it = it;
            }
            let (c, p) = (median(cyl), median(poly));
            println!(
                "{:<32} {c:>11.1} {p:>11.1} {:>6.2} {cyl_it:>6.2} {poly_it:>6.2} {out:>4} {widest:>8.1e}",
                format!("{name}, {mode}"),
                c / p
            );
        }
    }
}
