//! Cylinder queries against a 16-vertex polytope's, in one run.
//!
//! ```text
//! cargo run --release -p gjkd-bench --example cylinder_compare
//! ```
//!
//! The same random poses (separated, near contact and overlapping), once
//! with exact cylinders and once with each cylinder replaced by the octagonal
//! prism of its size (16 vertices): cylinder against cylinder and against a
//! box, cold and warm along a motion. Timing is by `std::time::Instant`,
//! the two interleaved batch by batch, the median over batches reported.

use std::hint::black_box;
use std::time::Instant;

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

/// Nanoseconds per query of `a` against `b` at `poses`, cold or warm (each
/// query warm-started from the previous one's answer).
fn per_query(a: &Shape, b: &Shape, poses: &[Isometry3<f64>], warm: bool) -> f64 {
    let opts = Options::default();
    let id = Isometry3::identity();
    let mut last: Option<WarmStart> = None;
    let start = Instant::now();
    for p in poses {
        let ans = distance(a, &id, b, p, &opts, if warm { last.as_ref() } else { None })
            .expect("valid input");
        last = Some(ans.warm_start);
        black_box(ans.distance);
    }
    start.elapsed().as_nanos() as f64 / poses.len() as f64
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
    let cyl_a: Shape = Convex::cylinder(r1, h1, 0.0).expect("valid").into();
    let cyl_b: Shape = Convex::cylinder(r2, h2, 0.0).expect("valid").into();
    let (poly_a, poly_b) = (prism(r1, h1), prism(r2, h2));
    let boxed: Shape = Convex::cuboid(Vector3::new(0.4, 0.3, 0.5), 0.0)
        .expect("valid")
        .into();
    println!(
        "{:<32} {:>12} {:>12} {:>7}",
        "query", "cylinder ns", "16-vert ns", "ratio"
    );
    let pairs = [
        ("cylinder-cylinder", (&cyl_a, &cyl_b), (&poly_a, &poly_b)),
        ("cylinder-box", (&cyl_a, &boxed), (&poly_a, &boxed)),
    ];
    for (name, (ca, cb), (pa, pb)) in pairs {
        for (mode, poses, warm) in [("cold", &random, false), ("warm motion", &moving, true)] {
            let (mut cyl, mut poly) = (Vec::new(), Vec::new());
            for _ in 0..BATCHES {
                cyl.push(per_query(ca, cb, poses, warm));
                poly.push(per_query(pa, pb, poses, warm));
            }
            let (c, p) = (median(cyl), median(poly));
            println!(
                "{:<32} {c:>12.1} {p:>12.1} {:>7.2}",
                format!("{name}, {mode}"),
                c / p
            );
        }
    }
}
