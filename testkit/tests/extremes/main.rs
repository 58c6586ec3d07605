//! Extreme inputs with analytic truths computed from the actual f64 inputs:
//! far from the world origin, tiny and huge scales, vanishing gaps,
//! degenerate vertex sets, identical objects, parallel faces and edges, deep
//! intersections and 100 000-vertex sets.
//!
//! Requirement per case: |distance - truth| <= 1e-6 · truth, or 1e-9 · size
//! where that is larger (truth near zero), and lower <= truth <= upper. Each
//! test gathers every failing case and prints them all; nothing is printed on
//! success.

use gjkd_testkit::input::{p, v};
use gjkd_testkit::reference::{P, V, aabb_distance};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

mod contacts;
mod far;
mod scales;

use gjk::{Answer, Compound, Convex, Options, Precision, Shape, Status, distance};

struct Case {
    name: String,
    a: Shape,
    pa: Isometry3<f64>,
    b: Shape,
    pb: Isometry3<f64>,
    truth: f64,
    /// Size of the objects (not of their position), for the absolute part of
    /// the requirement.
    size: f64,
    /// Upper bound on the true penetration depth when the shapes overlap.
    depth: Option<f64>,
}

impl Case {
    fn new(
        name: impl Into<String>,
        a: Shape,
        pa: Isometry3<f64>,
        b: Shape,
        pb: Isometry3<f64>,
        truth: f64,
        size: f64,
    ) -> Self {
        Case {
            name: name.into(),
            a,
            pa,
            b,
            pb,
            truth,
            size,
            depth: None,
        }
    }
}

/// Check one case; `None` when it passes. `extra` widens the allowed error
/// (absolute), for [`Precision::Single`].
fn failure(c: &Case, options: &Options, extra: f64) -> Option<String> {
    let ans: Answer = match distance(&c.a, &c.pa, &c.b, &c.pb, options, None) {
        Ok(a) => a,
        Err(e) => return Some(format!("{}: error {e:?}", c.name)),
    };
    let allowed = (1e-6 * c.truth).max(1e-9 * c.size) + extra;
    // Round-off of the truth itself (computed from rounded inputs).
    let eps = 1e-15 * c.size;
    let mut why = Vec::new();
    let err = (ans.distance - c.truth).abs();
    if err.is_nan() || err > allowed {
        why.push(format!(
            "error {:e} > allowed {allowed:e}",
            ans.distance - c.truth
        ));
    }
    if ans.lower.is_nan()
        || ans.upper.is_nan()
        || ans.lower > c.truth + eps
        || c.truth > ans.upper + eps
    {
        why.push(format!(
            "bounds [{:e}, {:e}] miss the truth",
            ans.lower, ans.upper
        ));
    }
    if ans.status != Status::Converged {
        why.push(format!("status {:?}", ans.status));
    }
    if let Some(depth) = c.depth
        && (ans.penetration.is_nan()
            || ans.penetration <= 0.0
            || ans.penetration > depth * (1.0 + 1e-12))
    {
        why.push(format!(
            "penetration {:e} not in (0, {depth:e}]",
            ans.penetration
        ));
    }
    if why.is_empty() {
        None
    } else {
        Some(format!(
            "{}: truth {:e}, got {:e} [{:e}, {:e}] after {} iterations: {}",
            c.name,
            c.truth,
            ans.distance,
            ans.lower,
            ans.upper,
            ans.iterations,
            why.join("; ")
        ))
    }
}

#[track_caller]
fn run(cases: &[Case]) {
    run_with(cases, Precision::Double);
}

/// `Precision::Single` may miss the support value by 2⁻²⁰ of each shape's
/// size; the distance may then be off by twice that, which the test allows
/// on top of the usual requirement (the bounds must still hold exactly).
#[track_caller]
fn run_with(cases: &[Case], precision: Precision) {
    let options = Options {
        precision,
        ..Options::default()
    };
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|c| {
            let extra = match precision {
                Precision::Double => 0.0,
                Precision::Single => 2f64.powi(-18) * c.size,
            };
            failure(c, &options, extra)
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

fn cuboid(h: V, r: f64) -> Shape {
    Convex::cuboid(h, r).unwrap().into()
}

fn sphere(r: f64) -> Shape {
    Convex::sphere(r).unwrap().into()
}

fn segment(a: P, b: P, r: f64) -> Shape {
    Convex::capsule(a, b, r).unwrap().into()
}

fn at(t: V) -> Isometry3<f64> {
    Isometry3::from(Translation3::from(t))
}

fn posed(t: V, r: UnitQuaternion<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::from(t), r)
}

const OFFSETS: [f64; 4] = [0.0, 1e3, 1e6, 1e9];

const GAPS: [f64; 6] = [1.0, 1e-3, 1e-6, 1e-9, 1e-12, 0.0];

fn rotations() -> [UnitQuaternion<f64>; 3] {
    [
        UnitQuaternion::identity(),
        UnitQuaternion::from_euler_angles(0.3, -1.1, 2.0),
        UnitQuaternion::from_euler_angles(-2.5, 0.7, 0.05),
    ]
}

/// Distance from the point `x` (world) to the cube of half extent `h` posed at
/// the origin with rotation `rot`.
fn rel_box_point(rot: &UnitQuaternion<f64>, x: &V, h: f64) -> f64 {
    let l = rot.inverse_transform_vector(x);
    let cl = v(l.x.clamp(-h, h), l.y.clamp(-h, h), l.z.clamp(-h, h));
    (l - cl).norm()
}

// ---------------------------------------------------------------------------

/// A small deterministic generator (xorshift64*), to avoid a dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }

    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// 100 000 points on a sphere of radius `r` (Fibonacci lattice), including
/// both poles exactly. The hull lies in the ball and touches its surface at the
/// poles, so the distance from a point on the z axis outside is `z - r`.
fn sphere_points(r: f64, n: usize) -> Vec<P> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut pts: Vec<P> = (1..n - 1)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64) / ((n - 1) as f64);
            let rho = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            p(r * rho * phi.cos(), r * rho * phi.sin(), r * z)
        })
        .collect();
    pts.push(p(0., 0., r));
    pts.push(p(0., 0., -r));
    pts
}

/// 100 000 points in a box (interior points and the 8 corners): the hull is
/// the box.
fn box_points(h: V, n: usize, rng: &mut Rng) -> Vec<P> {
    let mut pts: Vec<P> = (0..n - 8)
        .map(|_| {
            p(
                rng.uniform(-h.x, h.x),
                rng.uniform(-h.y, h.y),
                rng.uniform(-h.z, h.z),
            )
        })
        .collect();
    pts.extend(Convex::cuboid(h, 0.0).unwrap().vertices().iter().copied());
    pts
}

/// A box given as the 26 surface points of its 3×3×3 grid (corners, edge
/// midpoints, face centres), so that the f32 scan of `Precision::Single`
/// takes it and no closed form does.
fn dotted_box(h: V) -> Shape {
    let mut pts = Vec::new();
    for i in [-1.0, 0.0, 1.0] {
        for j in [-1.0, 0.0, 1.0] {
            for k in [-1.0, 0.0, 1.0] {
                if (i, j, k) != (0.0, 0.0, 0.0) {
                    pts.push(p(i * h.x, j * h.y, k * h.z));
                }
            }
        }
    }
    Convex::new(pts, 0.0).unwrap().into()
}
