//! # gjkd-paper
//!
//! The test data of the 1986 paper, rebuilt deterministically: the family of
//! twelve polytopes and twenty pairs of Section 7 ("Numerical Experiments") and
//! a collision sweep modelled on Section 8 ("An Example of Collision
//! Detection").
//!
//! Everything here is generated from fixed seeds by a small local generator
//! (SplitMix64), so the crate gains no dependency and every run, bench and test
//! sees the same geometry.
//!
//! ```
//! use gjkd_paper::{self as paper, Case};
//! use gjk::{distance, Options, Shape};
//!
//! let family = paper::family();
//! assert_eq!(family.len(), 12);
//! let shapes: Vec<Shape> = family.into_iter().map(Shape::from).collect();
//! for c in paper::cases(Case::Separated, 2, 7) {
//!     let d = distance(&shapes[c.a], &c.pose_a, &shapes[c.b], &c.pose_b, &Options::default(), None)?;
//!     assert!((d.distance - c.expected).abs() < 1e-6);
//! }
//! # Ok::<(), gjk::Error>(())
//! ```
//!
//! What the paper leaves open is filled in as follows, and documented at each
//! item: the exact sizes of the polytopes, how the random two-plane vertices are
//! drawn, what "expected relative translation 10/3" is measured on, how deep the
//! intersecting cases go, and the whole scene of Section 8 (the paper's Figure 3,
//! due to Canny, is not reproduced in the text).

#![warn(missing_docs)]

use std::f64::consts::PI;

use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};

use gjk::{Answer, Compound, Convex, Error, Options, Shape, WarmStart, distance};

/// SplitMix64 (Steele, Lea, Flood 2014): 64 bits of state, good enough for
/// test geometry, and tiny.
#[derive(Clone, Debug)]
struct SplitMix64(u64);

impl SplitMix64 {
    fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`, 53 bits.
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in `[lo, hi)`.
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform on the unit sphere.
    fn direction(&mut self) -> Vector3<f64> {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, 2.0 * PI);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vector3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// Uniform (Haar) rotation, by Shoemake's method.
    fn rotation(&mut self) -> UnitQuaternion<f64> {
        let (u1, u2, u3) = (self.unit(), self.unit(), self.unit());
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        let (t2, t3) = (2.0 * PI * u2, 2.0 * PI * u3);
        UnitQuaternion::from_quaternion(Quaternion::new(
            b * t3.cos(),
            a * t2.sin(),
            a * t2.cos(),
            b * t3.sin(),
        ))
    }
}

/// Mixes several words into one seed, so that every example has its own
/// stream whatever order the examples are built in.
fn mix(words: &[u64]) -> u64 {
    let mut h = 0x243F_6A88_85A3_08D3u64;
    for &w in words {
        h = SplitMix64::new(h ^ w).next_u64();
    }
    h
}

/// Seed of the random two-plane polytopes of [`family`]: fixed, so the family
/// is the same everywhere.
const FAMILY_SEED: u64 = 1986;

/// Vertex counts `M_i` of the twelve polytopes, in the paper's order.
pub const VERTEX_COUNTS: [usize; 12] = [2, 3, 8, 12, 16, 20, 20, 40, 50, 60, 100, 100];

/// The twelve polytopes of Section 7, in the paper's order (index 0 here is the
/// paper's polytope 1):
///
/// | index | paper | shape | `M` | bounding radius |
/// |---|---|---|---|---|
/// | 0 | 1 | line segment along z | 2 | 1.5 |
/// | 1 | 2 | equilateral triangle in the xy plane | 3 | 2.0 |
/// | 2 | 3 | rectangular box 2 × 3 × 4 | 8 | 2.69 |
/// | 3 | 4 | truncated cone, hexagonal ends of circumradius 2 and 1, height 2 | 12 | 2.24 |
/// | 4 | 5 | octagonal truncated cylinder (prism), radius 1.5, height 3 | 16 | 2.12 |
/// | 5 | 6 | decagonal truncated cylinder (prism), radius 2, height 5 | 20 | 3.20 |
/// | 6..=11 | 7..=12 | random two-plane polytopes | 20, 40, 50, 60, 100, 100 | 2.0, 3.0, 2.5, 3.5, 4.0, 3.0 |
///
/// Every polytope is centred on the origin (the mean of its vertices is the
/// origin) and lies in a sphere of radius between 1 and 4 about it. Radii are
/// 0: these are plain polytopes, as in the paper.
///
/// The random polytopes put half their vertices in the plane `z = +h` and half
/// in `z = -h`, on an ellipse of random semi-axes, orientation and centre in
/// each plane, at stratified random angles. Every vertex is therefore a vertex
/// of the hull, so `M` counts exactly what any support-point scan visits (a
/// library that first reduces the set to its hull sees the same `M`).
pub fn family() -> Vec<Convex> {
    let mut out = Vec::with_capacity(12);
    let p = Point3::new;
    out.push(vec![p(0.0, 0.0, -1.5), p(0.0, 0.0, 1.5)]);
    out.push(
        (0..3)
            .map(|k| {
                let a = 2.0 * PI * k as f64 / 3.0 + PI / 2.0;
                p(2.0 * a.cos(), 2.0 * a.sin(), 0.0)
            })
            .collect(),
    );
    let h = Vector3::new(1.0, 1.5, 2.0);
    out.push(
        (0..8)
            .map(|i| {
                p(
                    if i & 1 == 0 { -h.x } else { h.x },
                    if i & 2 == 0 { -h.y } else { h.y },
                    if i & 4 == 0 { -h.z } else { h.z },
                )
            })
            .collect(),
    );
    out.push(prism(6, 2.0, 1.0, 1.0));
    out.push(prism(8, 1.5, 1.5, 1.5));
    out.push(prism(10, 2.0, 2.0, 2.5));
    let mut rng = SplitMix64::new(FAMILY_SEED);
    for (&m, &radius) in VERTEX_COUNTS[6..]
        .iter()
        .zip(&[2.0, 3.0, 2.5, 3.5, 4.0, 3.0])
    {
        out.push(two_plane(&mut rng, m, radius));
    }
    out.into_iter()
        .map(|v| Convex::new(v, 0.0).expect("the family's vertices are finite"))
        .collect()
}

/// `n`-gonal frustum (a prism when `r_bottom == r_top`) between `z = ±half_h`,
/// centred on the origin.
fn prism(n: usize, r_bottom: f64, r_top: f64, half_h: f64) -> Vec<Point3<f64>> {
    let mut v = Vec::with_capacity(2 * n);
    for (r, z) in [(r_bottom, -half_h), (r_top, half_h)] {
        for k in 0..n {
            let a = 2.0 * PI * k as f64 / n as f64;
            v.push(Point3::new(r * a.cos(), r * a.sin(), z));
        }
    }
    v
}

/// `m` vertices, `m/2` on a random ellipse in each of two parallel planes,
/// centred on their mean and scaled to bounding radius `radius`.
fn two_plane(rng: &mut SplitMix64, m: usize, radius: f64) -> Vec<Point3<f64>> {
    let half = m / 2;
    let h = rng.range(0.3, 1.0);
    let mut v = Vec::with_capacity(m);
    for z in [-h, h] {
        let (a, b) = (rng.range(0.5, 1.0), rng.range(0.5, 1.0));
        let tilt = rng.range(0.0, PI);
        let (cx, cy) = (rng.range(-0.2, 0.2), rng.range(-0.2, 0.2));
        let phase = rng.range(0.0, 2.0 * PI);
        for k in 0..half {
            // Stratified angles: random, yet no two vertices nearly coincide.
            let t = phase + 2.0 * PI * (k as f64 + 0.8 * rng.unit()) / half as f64;
            let (x, y) = (a * t.cos(), b * t.sin());
            let (s, c) = tilt.sin_cos();
            v.push(Point3::new(cx + c * x - s * y, cy + s * x + c * y, z));
        }
    }
    let mean = v.iter().fold(Vector3::zeros(), |acc, p| acc + p.coords) / v.len() as f64;
    let r = v
        .iter()
        .map(|p| (p.coords - mean).norm())
        .fold(0.0, f64::max);
    v.iter()
        .map(|p| Point3::from((p.coords - mean) * (radius / r)))
        .collect()
}

/// The twenty pairs of Section 7, as 0-based indices into [`family`].
///
/// The paper numbers its polytopes from 1 and lists `(i, j) = (i, 2), (i, 4),
/// (i, 5), (i, 10)` for `i = 1, 3, 6, 8`, then `(7, 9), (7, 12), (11, 9),
/// (11, 12)`; each index here is the paper's minus one. Every pair has a
/// different `M = M_i + M_j`, from 5 to 200.
pub const PAIRS: [(usize, usize); 20] = [
    (0, 1),
    (0, 3),
    (0, 4),
    (0, 9),
    (2, 1),
    (2, 3),
    (2, 4),
    (2, 9),
    (5, 1),
    (5, 3),
    (5, 4),
    (5, 9),
    (7, 1),
    (7, 3),
    (7, 4),
    (7, 9),
    (6, 8),
    (6, 11),
    (10, 8),
    (10, 11),
];

/// The three situations of Section 7.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Case {
    /// Random poses, the polytopes apart.
    Separated,
    /// The separated example translated along its near-point line until the
    /// polytopes just touch.
    Touching,
    /// The separated example translated along its near-point line past contact.
    Intersecting,
}

impl Case {
    /// The three cases, in the paper's order.
    pub const ALL: [Case; 3] = [Case::Separated, Case::Touching, Case::Intersecting];

    /// A short lowercase name, for tables and bench ids.
    pub fn name(self) -> &'static str {
        match self {
            Case::Separated => "separated",
            Case::Touching => "touching",
            Case::Intersecting => "intersecting",
        }
    }
}

/// One example of Section 7: two members of [`family`] in world poses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FamilyCase {
    /// Which situation this is.
    pub case: Case,
    /// Index into [`PAIRS`].
    pub pair: usize,
    /// Index of the first polytope in [`family`] (0-based).
    pub a: usize,
    /// Index of the second polytope in [`family`] (0-based).
    pub b: usize,
    /// World pose of the first polytope.
    pub pose_a: Isometry3<f64>,
    /// World pose of the second polytope.
    pub pose_b: Isometry3<f64>,
    /// `M = M_a + M_b`, the total number of vertices.
    pub m: usize,
    /// The distance the construction aims at: the drawn gap for a separated
    /// example, 0 for touching and intersecting ones. Exact up to the
    /// round-off of composing the poses (about `1e-15` relative to the scene).
    pub expected: f64,
    /// How far past contact an intersecting example was pushed (0 otherwise).
    pub overlap: f64,
    /// The world direction in which the second polytope was moved to make this
    /// example from its far placement: the near-point line (from B's near point
    /// towards A's), or for an intersecting example whose near-point line
    /// leaves `A - B` at once (a sharp edge or vertex of `A - B`), the
    /// direction from contact towards A's centroid used for the overlap.
    pub push: Vector3<f64>,
}

/// Upper end of the uniform gap of a separated example: the gap is uniform in
/// `[0, 20/3)`, so its expectation is the paper's 10/3.
pub const MAX_GAP: f64 = 20.0 / 3.0;

/// Options for the queries that build the examples: the paper's tolerance
/// (on polytopes the algorithm ends on the exact nearest simplex in finitely
/// many steps; a tolerance of 0 only lets round-off pick the last step), a
/// generous iteration cap, no warm start.
fn accurate() -> Options {
    Options {
        max_iterations: 1000,
        warm_start: false,
        ..Options::default()
    }
}

/// `per_pair` examples of `case` for each of the 20 [`PAIRS`], pair by pair
/// (so `per_pair * 20` in all), from `seed`.
///
/// As in the paper, a touching or intersecting example is the separated
/// example of the same seed, pair and number, translated along the line that
/// joins its near points; so `cases(Touching, n, s)[k]` is
/// `cases(Separated, n, s)[k]` brought into contact.
///
/// How a separated example is drawn: independent uniform rotations for both
/// polytopes; the first placed uniformly in the cube `[-5, 5]³`; the second
/// put far away in a uniform random direction, then slid along the near-point
/// line (found by [`distance`]) until the gap between the
/// polytopes is a uniform draw from `[0, 20/3)`: the expected distance between
/// the polytopes is the paper's 10/3. Sliding along the near-point line
/// changes the distance by exactly the slide, so the gap is exact.
///
/// Intersecting examples are pushed past contact along the same line by a
/// uniform fraction in `[0.1, 0.5)` of the width of `A - B` along it (so the
/// overlap is commensurate with the objects), halved up to twice until the
/// polytopes overlap with a positive depth (the final simplex holds the origin
/// in its interior). When the contact is at a sharp edge or vertex of `A - B`,
/// the line leaves `A - B` at once and no push along it overlaps; the second
/// polytope is then pushed from contact towards the first one's centroid by
/// the same fraction of the distance between centroids, which always ends
/// strictly inside ([`FamilyCase::push`] records the direction used).
pub fn cases(case: Case, per_pair: usize, seed: u64) -> Vec<FamilyCase> {
    let family = family();
    let mut out = Vec::with_capacity(per_pair * PAIRS.len());
    for (pair, &(a, b)) in PAIRS.iter().enumerate() {
        for k in 0..per_pair {
            out.push(make_case(
                &family[a],
                &family[b],
                case,
                pair,
                (a, b),
                seed,
                k as u64,
            ));
        }
    }
    out
}

fn bounding_radius(c: &Convex) -> f64 {
    c.vertices()
        .iter()
        .map(|v| v.coords.norm())
        .fold(0.0, f64::max)
}

/// Width of the world-posed vertex set along `n`: `h(n) + h(-n)`.
fn width(c: &Convex, pose: &Isometry3<f64>, n: &Vector3<f64>) -> f64 {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in c.vertices() {
        let d = (pose * v).coords.dot(n);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    hi - lo
}

fn make_case(
    ca: &Convex,
    cb: &Convex,
    case: Case,
    pair: usize,
    (a, b): (usize, usize),
    seed: u64,
    k: u64,
) -> FamilyCase {
    let mut rng = SplitMix64::new(mix(&[seed, pair as u64, k]));
    let rot_a = rng.rotation();
    let rot_b = rng.rotation();
    let ta = Vector3::new(
        rng.range(-5.0, 5.0),
        rng.range(-5.0, 5.0),
        rng.range(-5.0, 5.0),
    );
    let dir = rng.direction();
    let gap = rng.range(0.0, MAX_GAP);
    let frac = rng.range(0.1, 0.5);
    let far = bounding_radius(ca) + bounding_radius(cb) + 1.0;
    let pose_a = Isometry3::from_parts(Translation3::from(ta), rot_a);
    let far_b = Isometry3::from_parts(Translation3::from(ta + dir * far), rot_b);
    let (sa, sb): (Shape, Shape) = (ca.clone().into(), cb.clone().into());
    let d0 = distance(&sa, &pose_a, &sb, &far_b, &accurate(), None)
        .expect("finite poses and valid options");
    let n = d0.normal;
    let slide = |by: f64| {
        Isometry3::from_parts(Translation3::from(far_b.translation.vector - n * by), rot_b)
    };
    let (pose_b, expected, overlap, push) = match case {
        Case::Separated => (slide(d0.distance - gap), gap, 0.0, -n),
        Case::Touching => (slide(d0.distance), 0.0, 0.0, -n),
        Case::Intersecting => {
            let overlaps = |pose: &Isometry3<f64>| {
                let d = distance(&sa, &pose_a, &sb, pose, &accurate(), None)
                    .expect("finite poses and valid options");
                d.distance == 0.0 && d.penetration > 0.0
            };
            // The paper's way: further along the near-point line.
            let mut depth = frac * (width(ca, &pose_a, &n) + width(cb, &far_b, &n));
            let mut found = None;
            for _ in 0..3 {
                let pose = slide(d0.distance + depth);
                if overlaps(&pose) {
                    found = Some((pose, depth, -n));
                    break;
                }
                depth *= 0.5;
            }
            // At a sharp edge or vertex of A - B the line leaves the set at
            // once: push from contact towards A's centroid instead, which ends
            // strictly inside (the segment from the contact to the centroid
            // difference lies in the interior of A - B).
            let (pose, depth, dir) = found.unwrap_or_else(|| {
                let touch = slide(d0.distance);
                let to_a = pose_a * ca.centroid() - touch * cb.centroid();
                let depth = frac * to_a.norm();
                let dir = to_a.normalize();
                let pose = Isometry3::from_parts(
                    Translation3::from(touch.translation.vector + dir * depth),
                    rot_b,
                );
                (pose, depth, dir)
            });
            (pose, 0.0, depth, dir)
        }
    };
    FamilyCase {
        case,
        pair,
        a,
        b,
        pose_a,
        pose_b,
        m: ca.len() + cb.len(),
        expected,
        overlap,
        push,
    }
}

/// Number of fixed obstacles in [`section8`].
pub const OBSTACLES: usize = 5;

/// The collision sweep of Section 8: an object `K_A = K6 ∪ K7` (a compound of
/// two convex pieces) moved along a path `q(s)`, `s ∈ [0, 1]`, through five
/// fixed convex obstacles `K1..K5`.
///
/// The position and the quaternion vary linearly in `s`, as the configuration
/// variables of the paper's example do (the quaternion is renormalised, so the
/// rotation is the normalised linear interpolation of the end rotations).
#[derive(Clone, Debug)]
pub struct Motion {
    moving: Shape,
    /// `K6` and `K7` alone, with their offsets in the moving body frame.
    pieces: Vec<(Isometry3<f64>, Shape)>,
    obstacles: Vec<(Shape, Isometry3<f64>)>,
    start: (Vector3<f64>, Quaternion<f64>),
    end: (Vector3<f64>, Quaternion<f64>),
}

/// What [`Motion::sweep`] measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// `distances[t][i]` is `d_{i+1}` at `s = t/T`, for `t = 0..=T`.
    pub distances: Vec<[f64; OBSTACLES]>,
    /// Penetration lower bounds, same layout (0 where separated): the paper
    /// plots them as negative distances in its Figure 4.
    pub penetrations: Vec<[f64; OBSTACLES]>,
    /// Subalgorithm iterations over the whole sweep.
    pub iterations: u64,
}

impl Motion {
    /// World pose of the moving object at `s` (clamped to `[0, 1]`).
    pub fn pose(&self, s: f64) -> Isometry3<f64> {
        let s = s.clamp(0.0, 1.0);
        let p = self.start.0 * (1.0 - s) + self.end.0 * s;
        let q = self.start.1 * (1.0 - s) + self.end.1 * s;
        Isometry3::from_parts(Translation3::from(p), UnitQuaternion::from_quaternion(q))
    }

    /// The fixed obstacles `K1..K5` with their world poses.
    pub fn obstacles(&self) -> &[(Shape, Isometry3<f64>)] {
        &self.obstacles
    }

    /// The moving object `K_A = K6 ∪ K7`, in its body frame.
    pub fn moving(&self) -> &Shape {
        &self.moving
    }

    /// One query of the sweep: the distance from the moving object at `s` to
    /// obstacle `i`, optionally warm-started.
    ///
    /// # Errors
    /// As [`distance`]; `i` must be below [`OBSTACLES`] (it panics otherwise).
    pub fn query(
        &self,
        i: usize,
        s: f64,
        options: &Options,
        warm: Option<&WarmStart>,
    ) -> Result<Answer, Error> {
        let (obstacle, pose) = &self.obstacles[i];
        distance(&self.moving, &self.pose(s), obstacle, pose, options, warm)
    }

    /// The paper's procedure: the five distances at `s = t/T`, `t = 0..=T`
    /// (`steps` is `T`, at least 1). With `warm`, each obstacle's query starts
    /// from the previous step's final simplex for that obstacle (Section 8);
    /// without, every query starts cold (single point, Section 6).
    ///
    /// # Errors
    /// As [`distance`].
    pub fn sweep(&self, steps: usize, options: &Options, warm: bool) -> Result<Sweep, Error> {
        let steps = steps.max(1);
        let mut distances = Vec::with_capacity(steps + 1);
        let mut penetrations = Vec::with_capacity(steps + 1);
        let mut iterations = 0u64;
        let mut last: [Option<WarmStart>; OBSTACLES] = [None; OBSTACLES];
        for t in 0..=steps {
            let pose = self.pose(t as f64 / steps as f64);
            let mut d = [0.0; OBSTACLES];
            let mut p = [0.0; OBSTACLES];
            for (i, (obstacle, obstacle_pose)) in self.obstacles.iter().enumerate() {
                let w = if warm { last[i].as_ref() } else { None };
                let ans = distance(&self.moving, &pose, obstacle, obstacle_pose, options, w)?;
                d[i] = ans.distance;
                p[i] = ans.penetration;
                iterations += u64::from(ans.iterations);
                last[i] = Some(ans.warm_start);
            }
            distances.push(d);
            penetrations.push(p);
        }
        Ok(Sweep {
            distances,
            penetrations,
            iterations,
        })
    }

    /// The moving object's convex pieces `K6`, `K7`, each with its offset in
    /// the moving body frame.
    pub fn pieces(&self) -> &[(Isometry3<f64>, Shape)] {
        &self.pieces
    }

    /// The sweep exactly as the paper sets it up: ten convex-convex distances
    /// per step, `d_6i` and `d_7i` for the pieces `K6`, `K7` and each obstacle
    /// `Ki`, each with its own warm start when `warm`; `d_i = min(d_6i, d_7i)`
    /// (2.3). Same distances as [`Motion::sweep`], which hands the union to
    /// [`distance`] and so warm-starts only the nearest and runner-up piece pairs.
    ///
    /// # Errors
    /// As [`distance`].
    pub fn sweep_pieces(
        &self,
        steps: usize,
        options: &Options,
        warm: bool,
    ) -> Result<Sweep, Error> {
        let steps = steps.max(1);
        let mut distances = Vec::with_capacity(steps + 1);
        let mut penetrations = Vec::with_capacity(steps + 1);
        let mut iterations = 0u64;
        let mut last: [[Option<WarmStart>; OBSTACLES]; 2] = [[None; OBSTACLES]; 2];
        for t in 0..=steps {
            let pose = self.pose(t as f64 / steps as f64);
            let mut d = [f64::INFINITY; OBSTACLES];
            let mut p = [0.0f64; OBSTACLES];
            for (k, (offset, piece)) in self.pieces.iter().enumerate() {
                let piece_pose = pose * offset;
                for (i, (obstacle, obstacle_pose)) in self.obstacles.iter().enumerate() {
                    let w = if warm { last[k][i].as_ref() } else { None };
                    let ans = distance(piece, &piece_pose, obstacle, obstacle_pose, options, w)?;
                    d[i] = d[i].min(ans.distance);
                    p[i] = p[i].max(ans.penetration);
                    iterations += u64::from(ans.iterations);
                    last[k][i] = Some(ans.warm_start);
                }
            }
            distances.push(d);
            penetrations.push(p);
        }
        Ok(Sweep {
            distances,
            penetrations,
            iterations,
        })
    }
}

/// The scene of Section 8.
///
/// The paper's Figure 3 (Canny's example) is only drawn, not specified, so
/// this scene is modelled on it: a moving object made of two convex pieces
/// (`K6`, a 1 × 1 × 3 box, and `K7`, a hexagonal frustum of 12 vertices
/// sticking out of its side: 20 vertices in all), translated by 14 units along
/// x while turning by 150° about a tilted axis, past five obstacles of 8 to 40
/// vertices (a box, a hexagonal frustum, an octagonal prism, a random
/// two-plane polytope of 40 vertices and a decagonal prism). The path runs
/// into `K1`, `K2`, `K3` and `K4` (their distances go to 0 over part of the
/// path, as `d_i` do in the paper's Figure 4) and passes `K5` at a distance.
pub fn section8() -> Motion {
    let k6 = Convex::cuboid(Vector3::new(0.5, 0.5, 1.5), 0.0).expect("valid box");
    let k7_vertices: Vec<Point3<f64>> = prism(6, 0.8, 0.4, 0.6)
        .into_iter()
        // Axis along x, sticking out of K6's +x face.
        .map(|p| Point3::new(p.z, p.x, p.y))
        .collect();
    let k7 = Convex::new(k7_vertices, 0.0).expect("valid frustum");
    let pieces = vec![
        (Isometry3::identity(), k6),
        (Isometry3::translation(1.1, 0.0, 0.6), k7),
    ];
    let moving = Compound::new(pieces.clone())
        .expect("valid compound")
        .into();
    let pieces = pieces.into_iter().map(|(o, c)| (o, c.into())).collect();

    let mut rng = SplitMix64::new(mix(&[FAMILY_SEED, 8]));
    let convex = |v: Vec<Point3<f64>>| -> Shape { Convex::new(v, 0.0).expect("finite").into() };
    let rot = |axis: Vector3<f64>, angle: f64| {
        UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle)
    };
    let at = |x: f64, y: f64, z: f64, r: UnitQuaternion<f64>| {
        Isometry3::from_parts(Translation3::new(x, y, z), r)
    };
    let obstacles = vec![
        (
            Convex::cuboid(Vector3::new(0.8, 0.8, 1.2), 0.0)
                .expect("valid box")
                .into(),
            at(2.0, 1.6, 0.0, rot(Vector3::z(), 0.35)),
        ),
        (
            convex(prism(6, 1.2, 0.7, 1.0)),
            at(5.0, -1.7, 0.3, rot(Vector3::x(), 0.4)),
        ),
        (
            convex(prism(8, 0.9, 0.9, 1.4)),
            at(8.0, 1.3, -0.2, rot(Vector3::new(1.0, 1.0, 0.0), 1.1)),
        ),
        (
            convex(two_plane(&mut rng, 40, 1.6)),
            at(11.0, -1.2, 0.4, rot(Vector3::new(0.2, 1.0, 0.3), 0.8)),
        ),
        (
            convex(prism(10, 1.0, 1.0, 1.0)),
            at(6.5, 4.2, 0.0, rot(Vector3::y(), 0.5)),
        ),
    ];
    let q_end = rot(Vector3::new(0.3, 0.2, 1.0), 150f64.to_radians());
    Motion {
        moving,
        pieces,
        obstacles,
        start: (
            Vector3::new(-1.5, 0.0, 0.0),
            *UnitQuaternion::identity().quaternion(),
        ),
        end: (Vector3::new(12.5, 0.0, 0.3), *q_end.quaternion()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shapes() -> Vec<Shape> {
        family().into_iter().map(Shape::from).collect()
    }

    #[test]
    fn family_matches_the_paper() {
        let f = family();
        assert_eq!(f.len(), 12);
        for (i, c) in f.iter().enumerate() {
            assert_eq!(c.len(), VERTEX_COUNTS[i], "polytope {i}");
            let r = bounding_radius(c);
            assert!((1.0..=4.0 + 1e-12).contains(&r), "polytope {i}: radius {r}");
            assert!(
                c.centroid().coords.norm() < 1e-12,
                "polytope {i} not centred"
            );
        }
        // Deterministic.
        assert_eq!(family(), f);
    }

    #[test]
    fn pairs_are_the_papers_minus_one() {
        let mut paper = Vec::new();
        for i in [1, 3, 6, 8] {
            for j in [2, 4, 5, 10] {
                paper.push((i - 1, j - 1));
            }
        }
        paper.extend([(6, 8), (6, 11), (10, 8), (10, 11)]);
        assert_eq!(PAIRS.to_vec(), paper);
        let mut ms: Vec<usize> = PAIRS
            .iter()
            .map(|&(a, b)| VERTEX_COUNTS[a] + VERTEX_COUNTS[b])
            .collect();
        ms.sort_unstable();
        ms.dedup();
        assert_eq!(ms.len(), 20);
    }

    #[test]
    fn cases_have_the_intended_distances() {
        let s = shapes();
        let opts = Options::default();
        let sep = cases(Case::Separated, 5, 42);
        let touch = cases(Case::Touching, 5, 42);
        let inter = cases(Case::Intersecting, 5, 42);
        assert_eq!(sep.len(), 100);
        assert_eq!(sep, cases(Case::Separated, 5, 42));
        let mut gap_sum = 0.0;
        for ((cs, ct), ci) in sep.iter().zip(&touch).zip(&inter) {
            assert_eq!((cs.a, cs.b, cs.pose_a), (ct.a, ct.b, ct.pose_a));
            assert_eq!(cs.m, VERTEX_COUNTS[cs.a] + VERTEX_COUNTS[cs.b]);
            let q = |c: &FamilyCase| {
                distance(&s[c.a], &c.pose_a, &s[c.b], &c.pose_b, &opts, None).unwrap()
            };
            let ds = q(cs);
            assert!(ds.distance > 0.0);
            assert!((ds.distance - cs.expected).abs() < 1e-9 * (1.0 + cs.expected));
            gap_sum += cs.expected;
            let dt = q(ct);
            assert!(dt.distance < 1e-9, "touching: {}", dt.distance);
            let di = q(ci);
            assert!(di.distance < 1e-9, "intersecting: {}", di.distance);
            assert!(di.lower == 0.0);
            assert_eq!(di.distance, 0.0);
            assert!(di.penetration > 0.0 && ci.overlap > 0.0);
        }
        let mean = gap_sum / sep.len() as f64;
        assert!((mean - 10.0 / 3.0).abs() < 0.7, "mean gap {mean}");
    }

    #[test]
    fn cases_agree_with_parry() {
        use parry3d_f64::math::{Pose, Rot3, Vector};
        use parry3d_f64::shape::{ConvexPolyhedron, Segment, Triangle};
        let f = family();
        let pose = |p: &Isometry3<f64>| {
            let q = p.rotation.quaternion();
            let t = p.translation.vector;
            Pose::from_parts(
                Vector::new(t.x, t.y, t.z),
                Rot3::from_xyzw(q.i, q.j, q.k, q.w),
            )
        };
        let parry: Vec<Box<dyn parry3d_f64::shape::Shape>> = f
            .iter()
            .map(|c| {
                let v: Vec<Vector> = c
                    .vertices()
                    .iter()
                    .map(|v| Vector::new(v.x, v.y, v.z))
                    .collect();
                let b: Box<dyn parry3d_f64::shape::Shape> = match v.len() {
                    2 => Box::new(Segment::new(v[0], v[1])),
                    3 => Box::new(Triangle::new(v[0], v[1], v[2])),
                    n => {
                        let h = ConvexPolyhedron::from_convex_hull(&v).unwrap();
                        assert_eq!(h.points().len(), n, "every vertex is on the hull");
                        Box::new(h)
                    }
                };
                b
            })
            .collect();
        for case in Case::ALL {
            for c in cases(case, 3, 11) {
                let d = parry3d_f64::query::distance(
                    &pose(&c.pose_a),
                    &*parry[c.a],
                    &pose(&c.pose_b),
                    &*parry[c.b],
                )
                .unwrap()
                .distance;
                let tol = if case == Case::Touching { 1e-7 } else { 1e-9 };
                assert!(
                    (d - c.expected).abs() <= tol * (1.0 + c.expected),
                    "{case:?} pair {}: parry {d} vs {}",
                    c.pair,
                    c.expected
                );
            }
        }
    }

    #[test]
    fn section8_hits_some_obstacles_and_misses_one() {
        let m = section8();
        assert_eq!(m.obstacles().len(), OBSTACLES);
        assert_eq!(m.moving().piece_count(), 2);
        assert!((m.pose(0.5).rotation.quaternion().norm() - 1.0).abs() < 1e-12);
        let cold = m.sweep(200, &Options::default(), false).unwrap();
        let warm = m.sweep(200, &Options::default(), true).unwrap();
        assert_eq!(cold.distances.len(), 201);
        for i in 0..OBSTACLES {
            let min = cold
                .distances
                .iter()
                .map(|d| d[i])
                .fold(f64::INFINITY, f64::min);
            assert!(cold.distances[0][i] > 0.0 && cold.distances[200][i] > 0.0);
            if i < 4 {
                assert_eq!(min, 0.0, "K{} is never hit", i + 1);
            } else {
                assert!(min > 0.1, "K5 is hit");
            }
        }
        for (c, w) in cold.distances.iter().zip(&warm.distances) {
            for i in 0..OBSTACLES {
                assert!((c[i] - w[i]).abs() < 1e-9, "warm {} cold {}", w[i], c[i]);
            }
        }
        assert!(warm.iterations < cold.iterations);
        let pieces = m.sweep_pieces(200, &Options::default(), true).unwrap();
        for (c, w) in cold.distances.iter().zip(&pieces.distances) {
            for i in 0..OBSTACLES {
                assert!((c[i] - w[i]).abs() < 1e-9, "pieces {} cold {}", w[i], c[i]);
            }
        }
    }
}
