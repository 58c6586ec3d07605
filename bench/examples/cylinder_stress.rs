//! A hunt for wrong cylinder answers: millions of varied cases, each
//! checked against a certified reference bracket of its own.
//!
//! ```text
//! cargo run --release -p gjkd-bench --example cylinder_stress -- [cases] [seed]
//! ```
//!
//! Every case puts a cylinder (sharp or rounded, flat disks, needles,
//! zero radius or height, 1e-9 to 1e6 in size, up to 1e9 from the origin)
//! against a cylinder, a box, a sphere, a capsule or a point cloud's hull
//! (small, large enough for the other support searches, flat, with
//! repeated points), alone or as pieces of compounds, either way round,
//! in one of several placements: random; a contact built from the two
//! shapes' support faces at a chosen gap (touching, tiny gaps, overlaps;
//! cap on cap, side on side, rim on face or edge by the special
//! directions and relative rotations it draws: parallel, flipped,
//! perpendicular, nearly so, exact quarter turns); far apart; or on the
//! same centre. Each case is asked cold, from the previous pair's warm
//! start (when its indices fit), from random codes, sometimes with a
//! margin near its distance, and sometimes along a warm motion of sixteen
//! steps. A grid of round-number closed-form placements (parallel axes
//! side by side, coaxial caps, a cap on a box face, crossing axes, a ball
//! at the rim, at gaps from 1e-3 of the size to overlaps) closes the run.
//!
//! The reference is independent of the query: in the pair's relative
//! frame, alternating projections onto the shapes (closed forms, or a
//! polytope query for a hull, not the cylinder's code) give a pair of
//! points, one in each shape, hence an upper bound on the distance, and
//! the shapes' support functions in closed form give, for any unit
//! direction, a lower bound (the separation of their projections). The
//! truth lies in that bracket whatever the query answered; the answer's
//! own points and normal, and the construction's, only seed it. An answer
//! fails when its distance is out of the judged bound (relative 1e-6,
//! absolute 1e-9 of the larger shape's size) of the bracket, when its
//! bounds miss the bracket, when an early exit is on the wrong side of
//! its margin, or when the form compiled for any CPU answers differently
//! (one query in eight is asked both ways). A case whose bracket stays
//! too wide to judge is counted as undecided, not passed. Beside these,
//! the `other` column counts answers whose penetration bound exceeds the
//! overlap along some direction, or whose nearest points lie off their
//! shapes or not the distance apart (beyond the same bound plus the
//! round-off of their world coordinates): the issue does not judge them.

use std::collections::BTreeMap;
use std::f64::consts::{FRAC_1_SQRT_2, PI};

use gjk::{
    Compound, Convex, Options, Shape, Status, WarmStart, Workspace, distance, distance_in_baseline,
};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};

/// A small xorshift generator.
struct Rng(u64);

impl Rng {
    fn bits(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    /// Uniform in [0, 1).
    fn unit_interval(&mut self) -> f64 {
        (self.bits() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit_interval()
    }
    /// `10^x` for `x` uniform in `[lo, hi)`.
    fn log(&mut self, lo: f64, hi: f64) -> f64 {
        10f64.powf(self.range(lo, hi))
    }
    fn below(&mut self, n: u64) -> u64 {
        self.bits() % n
    }
    fn chance(&mut self, p: f64) -> bool {
        self.unit_interval() < p
    }
    fn direction(&mut self) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            let n = v.norm();
            if n > 0.1 && n <= 1.0 {
                return v / n;
            }
        }
    }
    fn rotation(&mut self) -> UnitQuaternion<f64> {
        loop {
            let q = Quaternion::new(
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
                self.range(-1.0, 1.0),
            );
            if q.norm() > 0.1 && q.norm() <= 1.0 {
                return UnitQuaternion::from_quaternion(q);
            }
        }
    }
}

/// A rotation of the kind a scene holds: random, or one of the special
/// ones (identity, quarter and half turns, some written exactly, some by
/// their axis and angle, which leaves round-off in them).
fn special_rotation(rng: &mut Rng) -> UnitQuaternion<f64> {
    let s = FRAC_1_SQRT_2;
    let exact = |w, x, y, z| UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z));
    match rng.below(12) {
        0 => UnitQuaternion::identity(),
        1 => exact(0.0, 1.0, 0.0, 0.0),
        2 => exact(0.0, 0.0, 1.0, 0.0),
        3 => exact(0.0, 0.0, 0.0, 1.0),
        4 => exact(s, s, 0.0, 0.0),
        5 => exact(s, 0.0, s, 0.0),
        6 => exact(s, 0.0, 0.0, s),
        7 => exact(0.5, 0.5, 0.5, 0.5),
        8 => UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI),
        9 => UnitQuaternion::from_axis_angle(&Vector3::y_axis(), PI / 2.0),
        10 => UnitQuaternion::from_axis_angle(&Vector3::z_axis(), rng.range(-PI, PI)),
        _ => rng.rotation(),
    }
}

/// B's rotation relative to A's: parallel, antiparallel, perpendicular,
/// nearly one of these, axis-aligned or random.
fn relative_rotation(rng: &mut Rng) -> (UnitQuaternion<f64>, &'static str) {
    let spin = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), rng.range(-PI, PI));
    let tilt_axis = Vector3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), 0.0);
    let tilt = |angle: f64| match nalgebra::Unit::try_new(tilt_axis, 1e-6) {
        Some(axis) => UnitQuaternion::from_axis_angle(&axis, angle),
        None => UnitQuaternion::identity(),
    };
    let quarter = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI / 2.0);
    match rng.below(9) {
        0 => (UnitQuaternion::identity(), "same"),
        1 => (spin, "parallel"),
        2 => (
            UnitQuaternion::new_unchecked(Quaternion::new(0.0, 1.0, 0.0, 0.0)) * spin,
            "flipped",
        ),
        3 => (spin * quarter * spin.inverse(), "perpendicular"),
        4 => (tilt(rng.log(-12.0, -2.0)) * spin, "near-parallel"),
        5 => (
            tilt(rng.log(-12.0, -2.0)) * spin * quarter,
            "near-perpendicular",
        ),
        6 => (special_rotation(rng), "special"),
        _ => (rng.rotation(), "random"),
    }
}

/// The geometry of a convex piece in its body frame, as the reference
/// sees it.
#[derive(Clone, Debug)]
enum Geom {
    Cylinder {
        r: f64,
        h: f64,
    },
    Cuboid {
        half: Vector3<f64>,
    },
    /// A segment; a sphere when both ends are the origin.
    Segment {
        a: Vector3<f64>,
        b: Vector3<f64>,
    },
    Hull {
        verts: Vec<Vector3<f64>>,
    },
}

/// A convex piece: its core and rounding radius, and the query's form.
#[derive(Clone, Debug)]
struct Piece {
    geom: Geom,
    rho: f64,
    convex: Convex,
    /// A hull's core (no rounding), for the projections onto it.
    core: Option<Shape>,
}

impl Piece {
    fn new(geom: Geom, rho: f64, rng: &mut Rng) -> Piece {
        let convex = match &geom {
            Geom::Cylinder { r, h } => Convex::cylinder(*r, *h, rho).expect("a valid cylinder"),
            Geom::Cuboid { half } if rng.chance(0.5) => {
                Convex::cuboid(*half, rho).expect("a valid box")
            }
            Geom::Cuboid { half } => {
                let corners: Vec<Point3<f64>> = (0..8)
                    .map(|i| {
                        Point3::new(
                            if i & 1 == 0 { -half.x } else { half.x },
                            if i & 2 == 0 { -half.y } else { half.y },
                            if i & 4 == 0 { -half.z } else { half.z },
                        )
                    })
                    .collect();
                Convex::new(corners, rho).expect("a valid box")
            }
            Geom::Segment { a, b } if a == b => Convex::sphere(rho).expect("a valid sphere"),
            Geom::Segment { a, b } => {
                Convex::capsule(Point3::from(*a), Point3::from(*b), rho).expect("a valid capsule")
            }
            Geom::Hull { verts } => {
                let pts: Vec<Point3<f64>> = verts.iter().map(|v| Point3::from(*v)).collect();
                Convex::new(pts, rho).expect("a valid hull")
            }
        };
        let core = match &geom {
            Geom::Hull { verts } => {
                let pts: Vec<Point3<f64>> = verts.iter().map(|v| Point3::from(*v)).collect();
                Some(Convex::new(pts, 0.0).expect("a valid hull").into())
            }
            _ => None,
        };
        Piece {
            geom,
            rho,
            convex,
            core,
        }
    }

    fn kind(&self) -> &'static str {
        match &self.geom {
            Geom::Cylinder { .. } => "cylinder",
            Geom::Cuboid { .. } => "box",
            Geom::Segment { a, b } if a == b => "sphere",
            Geom::Segment { .. } => "capsule",
            Geom::Hull { .. } => "hull",
        }
    }

    /// The largest distance from the body origin to a point of the piece.
    fn size(&self) -> f64 {
        let core = match &self.geom {
            Geom::Cylinder { r, h } => r.hypot(*h),
            Geom::Cuboid { half } => half.norm(),
            Geom::Segment { a, b } => a.norm().max(b.norm()),
            Geom::Hull { verts } => verts.iter().map(|v| v.norm()).fold(0.0, f64::max),
        };
        core + self.rho
    }

    /// The support function of the core in direction `n` (any length).
    fn core_support(&self, n: &Vector3<f64>) -> f64 {
        match &self.geom {
            Geom::Cylinder { r, h } => r * n.x.hypot(n.y) + h * n.z.abs(),
            Geom::Cuboid { half } => half.x * n.x.abs() + half.y * n.y.abs() + half.z * n.z.abs(),
            Geom::Segment { a, b } => a.dot(n).max(b.dot(n)),
            Geom::Hull { verts } => verts.iter().map(|v| v.dot(n)).fold(f64::MIN, f64::max),
        }
    }

    /// The support function of the piece (unit `n`).
    fn support(&self, n: &Vector3<f64>) -> f64 {
        self.core_support(n) + self.rho
    }

    /// A point of the core's support face in direction `n` (unit): where
    /// the face is a disk, a segment or a rectangle (a component of `n`
    /// within `flat` of zero), a random point of it.
    fn face_point(&self, n: &Vector3<f64>, rng: &mut Rng) -> Vector3<f64> {
        let flat = 1e-13;
        let pick = |rng: &mut Rng, c: f64, h: f64| {
            if c.abs() <= flat {
                match rng.below(4) {
                    0 => h,
                    1 => -h,
                    _ => rng.range(-h, h),
                }
            } else {
                h.copysign(c)
            }
        };
        match &self.geom {
            Geom::Cylinder { r, h } => {
                let z = pick(rng, n.z, *h);
                let xy = n.x.hypot(n.y);
                if xy <= flat {
                    // A point of the cap's disk (its rim a quarter of the time).
                    let t = rng.range(-PI, PI);
                    let rad = match rng.below(8) {
                        0 | 1 => *r,
                        // Just inside the rim, where a cap's answer turns
                        // into a rim's.
                        2 => r * (1.0 - rng.log(-12.0, -2.0)),
                        _ => r * rng.unit_interval().sqrt(),
                    };
                    Vector3::new(rad * t.cos(), rad * t.sin(), z)
                } else {
                    Vector3::new(r * n.x / xy, r * n.y / xy, z)
                }
            }
            Geom::Cuboid { half } => Vector3::new(
                pick(rng, n.x, half.x),
                pick(rng, n.y, half.y),
                pick(rng, n.z, half.z),
            ),
            Geom::Segment { a, b } => {
                let (da, db) = (a.dot(n), b.dot(n));
                if (da - db).abs() <= flat * (a - b).norm() {
                    a.lerp(b, rng.unit_interval())
                } else if da > db {
                    *a
                } else {
                    *b
                }
            }
            Geom::Hull { verts } => *verts
                .iter()
                .max_by(|p, q| p.dot(n).total_cmp(&q.dot(n)))
                .expect("a hull has vertices"),
        }
    }

    /// A point of the piece's support face in direction `n` (unit): the
    /// face's centre where it is flat.
    fn support_point(&self, n: &Vector3<f64>) -> Vector3<f64> {
        let core = match &self.geom {
            Geom::Cylinder { r, h } => {
                let xy = n.x.hypot(n.y);
                let z = if n.z == 0.0 { 0.0 } else { h.copysign(n.z) };
                if xy == 0.0 {
                    Vector3::new(0.0, 0.0, z)
                } else {
                    Vector3::new(r * n.x / xy, r * n.y / xy, z)
                }
            }
            Geom::Cuboid { half } => {
                let pick = |c: f64, h: f64| if c == 0.0 { 0.0 } else { h.copysign(c) };
                Vector3::new(pick(n.x, half.x), pick(n.y, half.y), pick(n.z, half.z))
            }
            Geom::Segment { a, b } => {
                if a.dot(n) >= b.dot(n) {
                    *a
                } else {
                    *b
                }
            }
            Geom::Hull { verts } => *verts
                .iter()
                .max_by(|p, q| p.dot(n).total_cmp(&q.dot(n)))
                .expect("a hull has vertices"),
        };
        core + n * self.rho
    }

    /// The point of the core nearest `p`.
    fn core_project(&self, p: &Vector3<f64>, point_shape: &Shape) -> Vector3<f64> {
        match &self.geom {
            Geom::Cylinder { r, h } => {
                let xy = p.x.hypot(p.y);
                let k = if xy > *r { r / xy } else { 1.0 };
                Vector3::new(p.x * k, p.y * k, p.z.clamp(-h, *h))
            }
            Geom::Cuboid { half } => Vector3::new(
                p.x.clamp(-half.x, half.x),
                p.y.clamp(-half.y, half.y),
                p.z.clamp(-half.z, half.z),
            ),
            Geom::Segment { a, b } => {
                let d = b - a;
                let len2 = d.norm_squared();
                if len2 == 0.0 {
                    return *a;
                }
                a + d * ((p - a).dot(&d) / len2).clamp(0.0, 1.0)
            }
            Geom::Hull { .. } => {
                // The polytope query, not the cylinder's code: the point of
                // the hull nearest `p` is its answer's point on the hull.
                let hull = self.core.as_ref().expect("a hull keeps its core");
                let ans = distance(
                    point_shape,
                    &Isometry3::translation(p.x, p.y, p.z),
                    hull,
                    &Isometry3::identity(),
                    &Options::default(),
                    None,
                )
                .expect("a valid projection");
                if ans.upper == 0.0 {
                    *p
                } else {
                    ans.point_b.coords
                }
            }
        }
    }

    /// The point of the (rounded) piece nearest `p`.
    fn project(&self, p: &Vector3<f64>, point_shape: &Shape) -> Vector3<f64> {
        let q = self.core_project(p, point_shape);
        let d = p - q;
        let len = d.norm();
        if len <= self.rho {
            *p
        } else {
            q + d * (self.rho / len)
        }
    }
}

/// A body: convex pieces with their offsets (one piece at the identity is
/// a plain convex shape), and the query's form.
struct Body {
    pieces: Vec<(Isometry3<f64>, Piece)>,
    shape: Shape,
}

impl Body {
    fn convex(piece: Piece) -> Body {
        let shape = piece.convex.clone().into();
        Body {
            pieces: vec![(Isometry3::identity(), piece)],
            shape,
        }
    }

    fn compound(pieces: Vec<(Isometry3<f64>, Piece)>) -> Body {
        let shape = Compound::new(pieces.iter().map(|(o, p)| (*o, p.convex.clone())).collect())
            .expect("a valid compound")
            .into();
        Body { pieces, shape }
    }

    fn size(&self) -> f64 {
        self.pieces
            .iter()
            .map(|(o, p)| o.translation.vector.norm() + p.size())
            .fold(0.0, f64::max)
    }

    fn kind(&self) -> String {
        if self.pieces.len() == 1 {
            self.pieces[0].1.kind().to_string()
        } else {
            "compound".to_string()
        }
    }

    /// The largest valid index of a warm start into this body's piece
    /// `piece` (`u32::MAX` for a cylinder, whose codes are all valid).
    fn index_limit(&self, piece: usize) -> u32 {
        let p = &self.pieces[piece].1;
        match p.geom {
            Geom::Cylinder { .. } => u32::MAX,
            _ => (p.convex.len() - 1) as u32,
        }
    }
}

/// A random cylinder of about `scale`: ordinary, a flat disk, a needle,
/// or degenerate (zero radius or height), sharp or rounded.
fn random_cylinder(rng: &mut Rng, scale: f64) -> Piece {
    let (r, h) = match rng.below(10) {
        0..=4 => (scale * rng.range(0.1, 1.0), scale * rng.range(0.1, 1.0)),
        5 | 6 => (scale, scale * rng.log(-7.0, -1.0)),
        7 | 8 => (scale * rng.log(-7.0, -1.0), scale),
        _ => match rng.below(5) {
            0 | 1 => (scale, 0.0),
            2 | 3 => (0.0, scale),
            // A point, or a ball when rounded.
            _ => (0.0, 0.0),
        },
    };
    let rho = if r == 0.0 && h == 0.0 {
        scale * rng.range(0.0, 1.0)
    } else {
        rounding(rng, scale)
    };
    Piece::new(Geom::Cylinder { r, h }, rho, rng)
}

/// A rounding radius: none half of the time, else up to the scale.
fn rounding(rng: &mut Rng, scale: f64) -> f64 {
    if rng.chance(0.5) {
        0.0
    } else {
        scale * rng.log(-6.0, 0.0)
    }
}

/// A random piece of another kind (or another cylinder), of about `scale`.
fn random_other(rng: &mut Rng, scale: f64) -> Piece {
    match rng.below(6) {
        0 | 1 => random_cylinder(rng, scale),
        2 => {
            let half = Vector3::new(
                scale * rng.log(-3.0, 0.0),
                scale * rng.log(-3.0, 0.0),
                scale * rng.log(-3.0, 0.0),
            );
            Piece::new(Geom::Cuboid { half }, rounding(rng, scale), rng)
        }
        3 => Piece::new(
            Geom::Segment {
                a: Vector3::zeros(),
                b: Vector3::zeros(),
            },
            if rng.chance(0.2) {
                0.0
            } else {
                scale * rng.log(-2.0, 0.0)
            },
            rng,
        ),
        4 => {
            let d = rng.direction() * scale * rng.range(0.1, 1.0);
            Piece::new(
                Geom::Segment { a: -d, b: d },
                scale * rng.log(-3.0, 0.0),
                rng,
            )
        }
        _ => {
            // Mostly small hulls; some large enough for the other
            // support searches (the cube map, the block search); some
            // flat (a polygon) or with repeated points.
            let n = match rng.below(10) {
                0 => 64 + rng.below(600) as usize,
                1 => 600 + rng.below(1500) as usize,
                _ => 4 + rng.below(30) as usize,
            };
            let flat = rng.chance(0.15);
            let mut verts: Vec<Vector3<f64>> = (0..n)
                .map(|_| {
                    let mut v = rng.direction() * scale * rng.range(0.3, 1.0);
                    if flat {
                        v.z = 0.0;
                    }
                    v
                })
                .collect();
            if rng.chance(0.1) {
                let copies: Vec<Vector3<f64>> = verts.iter().take(3).copied().collect();
                verts.extend(copies);
            }
            Piece::new(Geom::Hull { verts }, rounding(rng, scale), rng)
        }
    }
}

/// A reference bracket `[lo, hi]` of the true distance, and the
/// magnitude of the coordinates it was computed from (for its round-off).
#[derive(Clone, Copy, Debug)]
struct Bracket {
    lo: f64,
    hi: f64,
    mag: f64,
}

/// The lower bound of direction `n` (A's frame, towards B), B at `rel`.
fn separation(a: &Piece, b: &Piece, rel: &Isometry3<f64>, n: &Vector3<f64>) -> f64 {
    let len = n.norm();
    if !(len > 0.0 && len.is_finite()) {
        return 0.0;
    }
    let n = n / len;
    let nb = rel.rotation.inverse_transform_vector(&-n);
    n.dot(&rel.translation.vector) - a.support(&n) - b.support(&nb)
}

/// The bracket of one piece pair, B at `rel` in A's frame, seeded by
/// points (A's frame) to start the projections from and directions to try.
fn pair_bracket(
    a: &Piece,
    b: &Piece,
    rel: &Isometry3<f64>,
    starts: &[Vector3<f64>],
    dirs: &[Vector3<f64>],
    iterations: usize,
    point_shape: &Shape,
) -> Bracket {
    let into_b = |p: &Vector3<f64>| {
        let local = rel
            .rotation
            .inverse_transform_vector(&(p - rel.translation.vector));
        rel.rotation * b.project(&local, point_shape) + rel.translation.vector
    };
    // The support points of the best direction so far start the
    // projections too: on a curved contact they are the nearest points.
    // When the first round leaves the case undecided, the direction of
    // the nearest points found seeds further rounds.
    let mut starts = starts.to_vec();
    let mut dirs = dirs.to_vec();
    let rounds = if iterations > 64 { 4 } else { 1 };
    let mut hi = f64::INFINITY;
    let mut tried = 0;
    for _ in 0..rounds {
        let best_given = dirs
            .iter()
            .filter(|n| n.norm() > 0.0)
            .max_by(|m, n| separation(a, b, rel, m).total_cmp(&separation(a, b, rel, n)));
        if let Some(n) = best_given {
            let n = n.normalize();
            starts.push(a.support_point(&n));
            let nb = rel.rotation.inverse_transform_vector(&-n);
            starts.push(
                rel.transform_point(&Point3::from(b.support_point(&nb)))
                    .coords,
            );
        }
        let mut best_dir = Vector3::zeros();
        for s in &starts[tried..] {
            let mut qa = a.project(s, point_shape);
            let mut prev = f64::INFINITY;
            for _ in 0..iterations {
                let qb = into_b(&qa);
                let d = (qb - qa).norm();
                if d < hi {
                    hi = d;
                    best_dir = qb - qa;
                }
                if d == 0.0 || d >= prev * (1.0 - 1e-13) {
                    break;
                }
                prev = d;
                qa = a.project(&qb, point_shape);
            }
        }
        tried = starts.len();
        dirs.push(best_dir);
    }
    let lo = dirs
        .iter()
        .map(|n| separation(a, b, rel, n))
        .fold(0.0, f64::max);
    Bracket {
        lo: lo.max(0.0),
        hi,
        mag: rel.translation.vector.norm() + a.size() + b.size(),
    }
}

/// What the reference knows of a case beyond the shapes and poses: the
/// construction's points and direction (world frame), if any.
#[derive(Clone, Copy, Default)]
struct Hint {
    points: Option<(Point3<f64>, Point3<f64>)>,
    normal: Option<Vector3<f64>>,
}

/// The bracket of the case's pair (the least over piece pairs), seeded
/// by the answer's points and normal and by the case's hint.
fn bracket(
    case: &Case<'_>,
    answer: Option<&gjk::Answer>,
    iterations: usize,
    point_shape: &Shape,
) -> Bracket {
    let (a, pa, b, pb, hint) = (case.a, &case.pa, case.b, &case.pb, &case.hint);
    let rel = pa.inv_mul(pb);
    let mut out = Bracket {
        lo: f64::INFINITY,
        hi: f64::INFINITY,
        mag: 0.0,
    };
    for (oa, piece_a) in &a.pieces {
        for (ob, piece_b) in &b.pieces {
            let r = oa.inv_mul(&(rel * ob));
            // World points into piece A's frame.
            let local = |p: &Point3<f64>| {
                let q = pa
                    .rotation
                    .inverse_transform_vector(&(p.coords - pa.translation.vector));
                oa.rotation
                    .inverse_transform_vector(&(q - oa.translation.vector))
            };
            let local_dir = |n: &Vector3<f64>| {
                oa.rotation
                    .inverse_transform_vector(&pa.rotation.inverse_transform_vector(n))
            };
            let mut starts = vec![r.translation.vector, Vector3::zeros()];
            let mut dirs = vec![r.translation.vector];
            if let Some(ans) = answer {
                starts.push(local(&ans.point_a));
                starts.push(local(&ans.point_b));
                dirs.push(local_dir(&ans.normal));
            }
            if let Some((qa, qb)) = hint.points {
                starts.push(local(&qa));
                starts.push(local(&qb));
            }
            if let Some(n) = hint.normal {
                dirs.push(local_dir(&n));
            }
            let br = pair_bracket(
                piece_a,
                piece_b,
                &r,
                &starts,
                &dirs,
                iterations,
                point_shape,
            );
            out.lo = out.lo.min(br.lo);
            out.hi = out.hi.min(br.hi);
            out.mag = out.mag.max(br.mag);
        }
    }
    out
}

/// The most the pair can penetrate: for each piece pair, the least
/// overlap of the two shapes' projections over a set of directions (any
/// direction's overlap separates them, so the depth is at most it); the
/// largest over piece pairs, as a compound's bound is.
fn deepest_possible(case: &Case<'_>, answer: &gjk::Answer) -> f64 {
    let rel = case.pa.inv_mul(&case.pb);
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut sample: Vec<Vector3<f64>> = (0..64).map(|_| rng.direction()).collect();
    for x in [-1.0, 0.0, 1.0] {
        for y in [-1.0, 0.0, 1.0] {
            for z in [-1.0, 0.0, 1.0] {
                if x != 0.0 || y != 0.0 || z != 0.0 {
                    sample.push(Vector3::new(x, y, z).normalize());
                }
            }
        }
    }
    let mut most = 0.0f64;
    for (oa, a) in &case.a.pieces {
        for (ob, b) in &case.b.pieces {
            let r = oa.inv_mul(&(rel * ob));
            let to_a = |n: &Vector3<f64>| {
                oa.rotation
                    .inverse_transform_vector(&case.pa.rotation.inverse_transform_vector(n))
            };
            let mut dirs: Vec<Vector3<f64>> = Vec::with_capacity(3 * sample.len() + 2);
            for n in &sample {
                dirs.push(*n);
                dirs.push(r.rotation * n);
            }
            dirs.push(to_a(&answer.normal));
            dirs.push(r.translation.vector);
            let least = dirs
                .iter()
                .filter(|n| n.norm() > 0.0)
                .map(|n| -separation(a, b, &r, n))
                .fold(f64::INFINITY, f64::min);
            most = most.max(least);
        }
    }
    most
}

/// What the reference says of an answer.
enum Verdict {
    Pass,
    /// The bracket stayed too wide to tell.
    Undecided,
    Fail(Failure, String),
}

/// The verdict on `answer` against the reference bracket, widened by more
/// projections until it decides; with the bracket and the judged bound.
fn judge(
    case: &Case<'_>,
    answer: &gjk::Answer,
    size: f64,
    point_shape: &Shape,
) -> (Verdict, Bracket, f64) {
    let mut iterations = 64;
    loop {
        let br = bracket(case, Some(answer), iterations, point_shape);
        let bound = 1e-6 * br.lo + 1e-9 * size;
        let fuzz = 64.0 * f64::EPSILON * br.mag;
        let d = answer.distance;
        let margin = case.margin.unwrap_or(f64::NAN);
        let fail = |f| (Verdict::Fail(f, String::new()), br, bound);
        if answer.lower > br.hi + fuzz {
            return fail(Failure::LowerAboveTruth);
        }
        if answer.upper < br.lo - fuzz {
            return fail(Failure::UpperBelowTruth);
        }
        // An early exit decides the margin, not the distance.
        match answer.status {
            Status::Farther if br.hi <= margin - fuzz => return fail(Failure::WrongSide),
            Status::Closer if br.lo > margin + fuzz => return fail(Failure::WrongSide),
            Status::Farther | Status::Closer => return (Verdict::Pass, br, bound),
            _ => {}
        }
        if d > br.hi + bound + fuzz || d < br.lo - bound - fuzz {
            return fail(Failure::Distance);
        }
        if d <= br.lo + bound + fuzz && d >= br.hi - bound - fuzz {
            return (Verdict::Pass, br, bound);
        }
        if iterations >= 20_000 {
            return (Verdict::Undecided, br, bound);
        }
        iterations *= 16;
    }
}

/// How a case is started.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Start {
    Cold,
    /// The previous step's warm start along a motion.
    Motion,
    /// Another pair's warm start.
    Foreign,
    /// Random codes and indices.
    Random,
    /// Cold, with a margin near the distance: an early exit's bounds
    /// must hold the truth and decide the margin as its status says.
    Margin,
}

/// One query to check.
struct Case<'c> {
    a: &'c Body,
    pa: Isometry3<f64>,
    b: &'c Body,
    pb: Isometry3<f64>,
    hint: Hint,
    warm: Option<WarmStart>,
    margin: Option<f64>,
    label: String,
}

/// What went wrong with an answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Failure {
    Error,
    NotFinite,
    Distance,
    LowerAboveTruth,
    UpperBelowTruth,
    /// An early exit on the wrong side of its margin.
    WrongSide,
    /// A penetration bound above the overlap along some direction.
    Penetration,
    /// Nearest points off their shapes, or not the distance apart.
    Points,
    /// The two compiled forms of the query answered differently.
    CompiledForms,
}

impl Failure {
    /// Whether the class breaks what the issue judges (the distance, its
    /// bounds, a status), as against the penetration and points.
    fn is_judged(self) -> bool {
        !matches!(self, Failure::Penetration | Failure::Points)
    }
}

#[derive(Default)]
struct Tally {
    cases: u64,
    /// Foreign warm starts the query refused (indices out of range).
    refused: u64,
    failures: BTreeMap<Failure, u64>,
    undecided: u64,
    statuses: BTreeMap<String, u64>,
    widest: f64,
}

struct Hunt {
    tallies: BTreeMap<String, Tally>,
    printed: BTreeMap<(String, String), u32>,
    point_shape: Shape,
    options: Options,
    workspace: Workspace,
    asked: u64,
}

/// The shape's parameters as Rust would write them.
fn describe(body: &Body) -> String {
    body.pieces
        .iter()
        .map(|(o, p)| {
            let g = match &p.geom {
                Geom::Cylinder { r, h } => format!("Convex::cylinder({r:?}, {h:?}, {:?})", p.rho),
                Geom::Cuboid { half } => format!(
                    "Convex::cuboid(Vector3::new({:?}, {:?}, {:?}), {:?})",
                    half.x, half.y, half.z, p.rho
                ),
                Geom::Segment { a, b } if a == b => format!("Convex::sphere({:?})", p.rho),
                Geom::Segment { a, b } => format!(
                    "Convex::capsule({:?}, {:?}, {:?})",
                    a.as_slice(),
                    b.as_slice(),
                    p.rho
                ),
                Geom::Hull { verts } => format!(
                    "Convex::new({:?}, {:?})",
                    verts
                        .iter()
                        .map(|v| v.as_slice().to_vec())
                        .collect::<Vec<_>>(),
                    p.rho
                ),
            };
            if body.pieces.len() == 1 {
                g
            } else {
                format!("({}, {g})", pose(o))
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn pose(p: &Isometry3<f64>) -> String {
    let t = p.translation.vector;
    let q = p.rotation.quaternion();
    format!(
        "pose(t = [{:?}, {:?}, {:?}], q(w,x,y,z) = [{:?}, {:?}, {:?}, {:?}])",
        t.x, t.y, t.z, q.w, q.i, q.j, q.k
    )
}

impl Hunt {
    /// Query `case`, check it against the reference and tally it; the
    /// answer, for a motion's next warm start.
    fn check(&mut self, case: &Case<'_>, start: Start) -> Option<gjk::Answer> {
        let key = format!("{:<8} {}", format!("{start:?}"), case.label);
        let options = Options {
            margin: case.margin,
            ..self.options
        };
        let (a, b, warm) = (&case.a.shape, &case.b.shape, case.warm.as_ref());
        let result = distance(a, &case.pa, b, &case.pb, &options, warm);
        // The form compiled for any CPU must answer the same, bit for bit
        // (on a CPU with AVX2 and FMA `distance` runs the other form).
        self.asked += 1;
        if self.asked.is_multiple_of(8) {
            let baseline = distance_in_baseline(
                &mut self.workspace,
                a,
                &case.pa,
                b,
                &case.pb,
                &options,
                warm,
            );
            if baseline != result {
                let text = format!("baseline {baseline:?}\n  vs {result:?}");
                *self
                    .tallies
                    .entry(key.clone())
                    .or_default()
                    .failures
                    .entry(Failure::CompiledForms)
                    .or_default() += 1;
                self.report(case, "FAIL CompiledForms", &text, &key);
            }
        }
        let size = case.a.size().max(case.b.size());
        let tally = self.tallies.entry(key.clone()).or_default();
        tally.cases += 1;
        let answer = match result {
            Ok(ans) => ans,
            Err(gjk::Error::WarmStartOutOfRange) if start == Start::Foreign => {
                // Another pair's indices need not fit these shapes: the
                // query refuses it, as documented, and nothing is checked.
                tally.cases -= 1;
                tally.refused += 1;
                return None;
            }
            Err(e) => {
                *tally.failures.entry(Failure::Error).or_default() += 1;
                self.report(case, "FAIL Error", &format!("error {e:?}"), &key);
                return None;
            }
        };
        *tally
            .statuses
            .entry(format!("{:?}", answer.status))
            .or_default() += 1;
        let finite = [answer.distance, answer.lower, answer.upper]
            .iter()
            .all(|x| x.is_finite());
        if !finite || answer.lower > answer.upper {
            *tally.failures.entry(Failure::NotFinite).or_default() += 1;
            self.report(case, "FAIL NotFinite", &format!("{answer:?}"), &key);
            return Some(answer);
        }
        let (verdict, br, bound) = judge(case, &answer, size, &self.point_shape);
        let verdict = match verdict {
            Verdict::Pass => self
                .side_checks(case, &answer, size, &br)
                .map_or(Verdict::Pass, |(f, t)| Verdict::Fail(f, t)),
            v => v,
        };
        let tally = self.tallies.get_mut(&key).expect("counted above");
        let err = (answer.distance - br.lo.max(br.hi.min(answer.distance))).abs();
        if !matches!(answer.status, Status::Farther | Status::Closer) {
            tally.widest = tally.widest.max(err / bound);
        }
        let summary = format!(
            "got {:?} [{:?}, {:?}] {:?} it {} vs bracket [{:?}, {:?}] (bound {bound:e}, off by {:.3e} bounds)",
            answer.distance,
            answer.lower,
            answer.upper,
            answer.status,
            answer.iterations,
            br.lo,
            br.hi,
            err / bound
        );
        match verdict {
            Verdict::Pass => {}
            Verdict::Undecided => {
                tally.undecided += 1;
                self.report(case, "UNDECIDED", &summary, &key);
            }
            Verdict::Fail(f, text) => {
                *tally.failures.entry(f).or_default() += 1;
                self.report(
                    case,
                    &format!("FAIL {f:?}"),
                    &format!("{text}{summary}"),
                    &key,
                );
            }
        }
        Some(answer)
    }

    /// The answer's penetration and nearest points, checked when its
    /// distance passed: `Some` with what is wrong with them.
    fn side_checks(
        &self,
        case: &Case<'_>,
        answer: &gjk::Answer,
        size: f64,
        br: &Bracket,
    ) -> Option<(Failure, String)> {
        let fuzz = 64.0 * f64::EPSILON * br.mag;
        if answer.penetration > 0.0 {
            let most = deepest_possible(case, answer);
            if answer.penetration > most + fuzz + 1e-12 * size {
                let text = format!("penetration {:?} > {most:?}; ", answer.penetration);
                return Some((Failure::Penetration, text));
            }
        }
        // The points: on their shapes and the distance apart, to the
        // judged bound plus the round-off of their world coordinates.
        let world =
            64.0 * f64::EPSILON * (answer.point_a.coords.norm() + answer.point_b.coords.norm());
        let tol = 1e-6 * answer.distance + 1e-9 * size + world + fuzz;
        let gap = (answer.point_b - answer.point_a).norm();
        if answer.distance > 0.0 && (gap - answer.distance).abs() > tol {
            let text = format!("points {gap:?} apart (tolerance {tol:e}); ");
            return Some((Failure::Points, text));
        }
        let off = |body: &Body, pose: &Isometry3<f64>, p: &Point3<f64>| {
            body.pieces
                .iter()
                .map(|(o, piece)| {
                    let local = (pose * o).inverse_transform_point(p).coords;
                    (piece.project(&local, &self.point_shape) - local).norm()
                })
                .fold(f64::INFINITY, f64::min)
        };
        let (off_a, off_b) = (
            off(case.a, &case.pa, &answer.point_a),
            off(case.b, &case.pb, &answer.point_b),
        );
        if off_a > tol || off_b > tol {
            let text = format!(
                "points {off_a:?} and {off_b:?} off their shapes (tolerance {tol:e}); normal {:?}, penetration {:?}, pieces {:?}; ",
                answer.normal.as_slice(),
                answer.penetration,
                answer.pieces
            );
            return Some((Failure::Points, text));
        }
        None
    }

    /// Prints the first few of each class and key, with a repro.
    fn report(&mut self, case: &Case<'_>, what: &str, text: &str, key: &str) {
        let n = self
            .printed
            .entry((what.to_string(), key.to_string()))
            .or_default();
        *n += 1;
        if *n > 3 {
            return;
        }
        println!(
            "{what} {key}: {text}\n  A = {} at {}\n  B = {} at {}\n  warm = {:?}, margin = {:?}",
            describe(case.a),
            pose(&case.pa),
            describe(case.b),
            pose(&case.pb),
            case.warm.as_ref().map(|w| (w.pieces(), w.pairs().to_vec())),
            case.margin
        );
    }
}

/// Where a case is placed.
#[derive(Clone, Copy, Debug)]
enum Placement {
    Random,
    /// Support faces at a gap (0, tiny, ordinary or negative).
    Contact,
    Far,
    /// The same centre, or nearly.
    Coincident,
}

/// A world pose for A: at or far from the origin, special or random.
fn world_pose(rng: &mut Rng) -> Isometry3<f64> {
    let t = if rng.chance(0.3) {
        Vector3::zeros()
    } else {
        let reach = if rng.chance(0.8) { 6.0 } else { 9.0 };
        rng.direction() * rng.log(0.0, reach)
    };
    let rot = if rng.chance(0.5) {
        special_rotation(rng)
    } else {
        rng.rotation()
    };
    Isometry3::from_parts(Translation3::from(t), rot)
}

/// A contact direction in A's frame: its cap, its side, a tilt off
/// either, B's face, or random.
fn contact_direction(
    rng: &mut Rng,
    b: &Piece,
    rot_b: &UnitQuaternion<f64>,
) -> (Vector3<f64>, &'static str) {
    let around = rng.range(-PI, PI);
    let side = Vector3::new(around.cos(), around.sin(), 0.0);
    let cap = Vector3::new(0.0, 0.0, if rng.chance(0.5) { 1.0 } else { -1.0 });
    match rng.below(7) {
        0 => (cap, "cap"),
        1 => (side, "side"),
        2 => ((cap + side * rng.log(-12.0, -1.0)).normalize(), "near-cap"),
        3 => ((side + cap * rng.log(-12.0, -1.0)).normalize(), "near-side"),
        4 if !matches!(b.geom, Geom::Cylinder { .. }) && rng.chance(0.5) => {
            // B's edge: -n has one zero component in B's frame.
            let t = rng.range(-PI, PI);
            let (c, s) = (t.cos(), t.sin());
            let local = match rng.below(3) {
                0 => Vector3::new(c, s, 0.0),
                1 => Vector3::new(c, 0.0, s),
                _ => Vector3::new(0.0, c, s),
            };
            (-rot_b.transform_vector(&local), "b-edge")
        }
        4 => {
            // B's face, cap or side: -n is one of B's special directions.
            let local = match b.geom {
                Geom::Cylinder { .. } if rng.chance(0.5) => side,
                _ => {
                    let axis = match rng.below(3) {
                        0 => Vector3::x(),
                        1 => Vector3::y(),
                        _ => Vector3::z(),
                    };
                    axis * if rng.chance(0.5) { 1.0 } else { -1.0 }
                }
            };
            (-(rot_b.transform_vector(&local)), "b-face")
        }
        5 if rng.chance(0.3) => {
            // About a quarter off the axis (the sine), where the query
            // turns from its rim steps to its cap's closed form.
            let sin = 0.25 * (1.0 + rng.range(-1e-3, 1e-3));
            let cos = (1.0 - sin * sin).sqrt();
            ((side * sin + cap * cos).normalize(), "quarter-tilt")
        }
        _ => (rng.direction(), "random-dir"),
    }
}

/// A gap for a contact, relative to `scale`: touching, tiny, ordinary or
/// overlapping.
fn contact_gap(rng: &mut Rng, scale: f64) -> (f64, &'static str) {
    match rng.below(5) {
        0 | 1 => (0.0, "touch"),
        2 => (scale * rng.log(-12.0, -3.0), "tiny-gap"),
        3 => (scale * rng.range(0.01, 2.0), "gap"),
        _ => (
            -scale
                * if rng.chance(0.5) {
                    rng.log(-12.0, -3.0)
                } else {
                    rng.range(0.0, 0.5)
                },
            "overlap",
        ),
    }
}

/// Builds B's pose about A for `placement`, with the hint the reference
/// may use and a label for the tally.
fn place(
    rng: &mut Rng,
    a: &Body,
    pa: &Isometry3<f64>,
    b: &Body,
    placement: Placement,
) -> (Isometry3<f64>, Hint, String) {
    let (rot, rot_label) = relative_rotation(rng);
    let scale = a.size().max(b.size());
    match placement {
        Placement::Random => {
            let t = rng.direction() * (a.size() + b.size()) * rng.range(0.2, 2.0);
            let rel = Isometry3::from_parts(Translation3::from(t), rot);
            (pa * rel, Hint::default(), format!("random {rot_label}"))
        }
        Placement::Far => {
            let t = rng.direction() * scale * rng.log(1.0, 6.0);
            let rel = Isometry3::from_parts(Translation3::from(t), rot);
            (pa * rel, Hint::default(), format!("far {rot_label}"))
        }
        Placement::Coincident => {
            let t = if rng.chance(0.5) {
                Vector3::zeros()
            } else {
                rng.direction() * scale * rng.log(-12.0, 0.0)
            };
            let rel = Isometry3::from_parts(Translation3::from(t), rot);
            (pa * rel, Hint::default(), format!("coincident {rot_label}"))
        }
        Placement::Contact => {
            // Piece 0 of each: the cylinder of A, B's first piece.
            let (oa, piece_a) = &a.pieces[0];
            let (ob, piece_b) = &b.pieces[0];
            // Directions in piece A's frame; B's piece rotation relative
            // to piece A is `rot`.
            let (n, dir_label) = contact_direction(rng, piece_b, &rot);
            let (gap, gap_label) = contact_gap(rng, scale);
            let qa = piece_a.face_point(&n, rng) + n * piece_a.rho;
            let nb = rot.inverse_transform_vector(&-n);
            let qb_local = piece_b.face_point(&nb, rng) + nb * piece_b.rho;
            // Piece B placed so that its point lands on A's plus gap·n.
            let t = qa + n * gap - rot * qb_local;
            let rel_pieces = Isometry3::from_parts(Translation3::from(t), rot);
            // Body B's pose: pa · oa · rel_pieces · ob⁻¹.
            let pb = pa * (oa * rel_pieces * ob.inverse());
            let world_a = pa * (oa * Point3::from(qa));
            let hint = Hint {
                points: Some((world_a, world_a + pa.rotation * (oa.rotation * (n * gap)))),
                normal: Some(pa.rotation * (oa.rotation * n)),
            };
            (
                pb,
                hint,
                format!("contact {gap_label} {dir_label} {rot_label}"),
            )
        }
    }
}

/// A random garbage warm start for the pair: one to four index pairs,
/// each valid for the pieces it names.
fn random_warm(rng: &mut Rng, a: &Body, b: &Body) -> WarmStart {
    let pieces = [
        rng.below(a.pieces.len() as u64) as u32,
        rng.below(b.pieces.len() as u64) as u32,
    ];
    let (la, lb) = (
        a.index_limit(pieces[0] as usize),
        b.index_limit(pieces[1] as usize),
    );
    let n = 1 + rng.below(4) as usize;
    let pick = |rng: &mut Rng, limit: u32| {
        if limit == u32::MAX {
            match rng.below(4) {
                0 => 0,
                1 => 1u32 << 31,
                _ => rng.bits() as u32,
            }
        } else {
            rng.below(u64::from(limit) + 1) as u32
        }
    };
    let pairs: Vec<[u32; 2]> = (0..n).map(|_| [pick(rng, la), pick(rng, lb)]).collect();
    WarmStart::new(pieces, &pairs).expect("at most four pairs")
}

fn main() {
    let mut args = std::env::args().skip(1);
    let total: u64 = args
        .next()
        .map_or(1_000_000, |s| s.parse().expect("a count"));
    let seed: u64 = args
        .next()
        .map_or(0x5eed_c711_57e5_0001, |s| s.parse().expect("a seed"));
    let mut rng = Rng(seed | 1);
    let mut hunt = Hunt {
        tallies: BTreeMap::new(),
        printed: BTreeMap::new(),
        point_shape: Convex::sphere(0.0).expect("a point").into(),
        options: Options::default(),
        workspace: Workspace::new(),
        asked: 0,
    };
    let mut foreign: Option<WarmStart> = None;
    let mut done = 0u64;
    while done < total {
        let (a, b) = random_pair(&mut rng);
        let placement = match rng.below(10) {
            0..=3 => Placement::Random,
            4..=8 => Placement::Contact,
            9 if rng.chance(0.3) => Placement::Coincident,
            _ => Placement::Far,
        };
        let pa = world_pose(&mut rng);
        let (pb, hint, label) = place(&mut rng, &a, &pa, &b, placement);
        // The cylinder as the second shape a third of the time.
        let case = if rng.chance(1.0 / 3.0) {
            Case {
                a: &b,
                pa: pb,
                b: &a,
                pb: pa,
                hint: Hint {
                    points: hint.points.map(|(x, y)| (y, x)),
                    normal: hint.normal.map(|n| -n),
                },
                warm: None,
                margin: None,
                label: format!("{:<18} {label}", format!("{}-{}", b.kind(), a.kind())),
            }
        } else {
            Case {
                a: &a,
                pa,
                b: &b,
                pb,
                hint,
                warm: None,
                margin: None,
                label: format!("{:<18} {label}", format!("{}-{}", a.kind(), b.kind())),
            }
        };
        done += ask_every_way(&mut hunt, &mut rng, case, &mut foreign);
    }
    let grid = grid_cases(&mut hunt, &mut rng);
    summarise(&hunt, total + grid, seed);
}

/// A random pair: a cylinder (alone, or a piece of a compound beside a
/// box) and another shape (alone, or a compound with a cylinder piece).
fn random_pair(rng: &mut Rng) -> (Body, Body) {
    let scale = rng.log(-9.0, 6.0);
    let cyl = random_cylinder(rng, scale);
    let other_scale = if rng.chance(0.8) {
        scale * rng.log(-1.0, 1.0)
    } else {
        rng.log(-9.0, 6.0)
    };
    let other = random_other(rng, other_scale);
    let a = if rng.chance(0.1) {
        let off = Isometry3::from_parts(
            Translation3::from(rng.direction() * scale * rng.range(0.0, 0.5)),
            special_rotation(rng),
        );
        let box_off = Isometry3::translation(2.0 * scale, 0.0, 0.0);
        let half = Vector3::new(0.3, 0.4, 0.5) * scale;
        let bx = Piece::new(Geom::Cuboid { half }, 0.0, rng);
        Body::compound(vec![(off, cyl), (box_off, bx)])
    } else {
        Body::convex(cyl)
    };
    let b = if rng.chance(0.05) {
        let off = Isometry3::from_parts(
            Translation3::from(rng.direction() * other_scale * rng.range(0.0, 2.0)),
            rng.rotation(),
        );
        let second = random_cylinder(rng, other_scale);
        Body::compound(vec![(Isometry3::identity(), other), (off, second)])
    } else {
        Body::convex(other)
    };
    (a, b)
}

/// Asks `case` cold, from `foreign` (the previous pair's warm start, if
/// it fits), from random codes, sometimes with a margin near its
/// distance and sometimes along a warm motion; leaves this pair's warm
/// start in `foreign`. Returns the number of queries checked.
fn ask_every_way(
    hunt: &mut Hunt,
    rng: &mut Rng,
    mut case: Case<'_>,
    foreign: &mut Option<WarmStart>,
) -> u64 {
    let mut asked = 1;
    let cold = hunt.check(&case, Start::Cold);
    if let Some(w) = foreign.take() {
        case.warm = Some(w);
        hunt.check(&case, Start::Foreign);
        asked += 1;
    }
    case.warm = Some(random_warm(rng, case.a, case.b));
    hunt.check(&case, Start::Random);
    asked += 1;
    case.warm = None;
    if let Some(c) = &cold
        && rng.chance(0.25)
    {
        let near = if rng.chance(0.5) {
            c.distance * (1.0 + rng.range(-1e-3, 1e-3))
        } else {
            c.distance * rng.range(0.0, 2.0)
        };
        case.margin = Some(near);
        hunt.check(&case, Start::Margin);
        case.margin = None;
        asked += 1;
    }
    *foreign = cold.map(|c| c.warm_start);
    if rng.chance(0.125) {
        asked += warm_motion(hunt, rng, &case, cold.map(|c| c.warm_start));
    }
    asked
}

/// Sixteen small steps of B (a drift and a turn) from `case`'s pose, each
/// started from the previous step's answer.
fn warm_motion(hunt: &mut Hunt, rng: &mut Rng, case: &Case<'_>, warm: Option<WarmStart>) -> u64 {
    let size = case.a.size() + case.b.size();
    let drift = rng.direction() * size * rng.log(-6.0, -1.0);
    let turn = UnitQuaternion::from_scaled_axis(rng.direction() * rng.log(-6.0, -1.0));
    let mut warm = warm;
    let mut pose_b = case.pb;
    for _ in 0..16 {
        pose_b = Isometry3::from_parts(
            Translation3::from(pose_b.translation.vector + drift),
            turn * pose_b.rotation,
        );
        let step = Case {
            a: case.a,
            pa: case.pa,
            b: case.b,
            pb: pose_b,
            hint: Hint::default(),
            warm,
            margin: None,
            label: case.label.clone(),
        };
        warm = hunt.check(&step, Start::Motion).map(|c| c.warm_start);
    }
    16
}

/// A grid of closed-form placements with round numbers, the kind a
/// hand-written test set holds: sizes 1e-9 to 1e6, at the origin and far
/// from it, under exact quarter and half turns, at gaps from touching to
/// overlapping: parallel axes side by side (caps overlapping in z),
/// coaxial caps, a cap on a box face, crossing axes side on side, a ball
/// at the rim. Each is asked cold, then warm from the previous gap's
/// answer. Returns the number of cases.
fn grid_cases(hunt: &mut Hunt, rng: &mut Rng) -> u64 {
    let s2 = FRAC_1_SQRT_2;
    let exact = |w, x, y, z| UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z));
    let turns = [
        UnitQuaternion::identity(),
        exact(s2, s2, 0.0, 0.0),
        exact(s2, 0.0, s2, 0.0),
        exact(0.0, 1.0, 0.0, 0.0),
        exact(0.5, 0.5, 0.5, 0.5),
    ];
    let mut count = 0;
    for scale in [1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e6] {
        for base in [0.0, 1e3, 1e6, 1e9] {
            for rounded in [0.0, 0.1] {
                let set = GridSet::new(scale, rounded * scale, rng);
                for turn in turns {
                    let pa = Isometry3::from_parts(Translation3::new(base, -base, base), turn);
                    for placement in set.placements() {
                        count += grid_gaps(hunt, &set, &pa, &placement);
                    }
                }
            }
        }
    }
    count
}

/// The shapes of the grid at one scale and rounding.
struct GridSet {
    scale: f64,
    rho: f64,
    a: Body,
    other: Body,
    cuboid: Body,
    ball: Body,
}

/// One placement of the grid: its label, B, B's offset in A's frame at
/// gap 0, B's rotation relative to A, and the gap's direction.
struct GridPlacement<'g> {
    label: &'static str,
    b: &'g Body,
    offset: Vector3<f64>,
    rotation: UnitQuaternion<f64>,
    out: Vector3<f64>,
}

impl GridSet {
    fn new(scale: f64, rho: f64, rng: &mut Rng) -> GridSet {
        let cylinder = |r: f64, h: f64, rng: &mut Rng| {
            Body::convex(Piece::new(Geom::Cylinder { r, h }, rho, rng))
        };
        let half = Vector3::new(0.4, 0.3, 0.6) * scale;
        let centre = Geom::Segment {
            a: Vector3::zeros(),
            b: Vector3::zeros(),
        };
        GridSet {
            scale,
            rho,
            a: cylinder(0.5 * scale, scale, rng),
            other: cylinder(0.3 * scale, 0.7 * scale, rng),
            cuboid: Body::convex(Piece::new(Geom::Cuboid { half }, rho, rng)),
            ball: Body::convex(Piece::new(centre, 0.2 * scale, rng)),
        }
    }

    fn placements(&self) -> Vec<GridPlacement<'_>> {
        let s2 = FRAC_1_SQRT_2;
        let exact = |w, x, y, z| UnitQuaternion::new_unchecked(Quaternion::new(w, x, y, z));
        let flip = exact(0.0, 1.0, 0.0, 0.0);
        let quarter_z = exact(s2, 0.0, 0.0, s2);
        let across = exact(s2, s2, 0.0, 0.0);
        let none = UnitQuaternion::identity();
        let (s, radii) = (self.scale, 2.0 * self.rho);
        let at = |label, b, offset: Vector3<f64>, rotation, out: Vector3<f64>| GridPlacement {
            label,
            b,
            offset,
            rotation,
            out: out.normalize(),
        };
        let (x, z) = (Vector3::x(), Vector3::z());
        let rim = Vector3::new(s2, 0.0, s2);
        vec![
            at("side", &self.other, x * (0.8 * s + radii), flip, x),
            at(
                "side-z",
                &self.other,
                x * (0.8 * s + radii) + z * (1.6 * s),
                quarter_z,
                x,
            ),
            at("caps", &self.other, z * (1.7 * s + radii), quarter_z, z),
            at(
                "caps-off",
                &self.other,
                x * (0.6 * s) - z * (1.7 * s + radii),
                flip,
                -z,
            ),
            at(
                "box-face",
                &self.cuboid,
                Vector3::new(0.2 * s, 0.1 * s, 1.6 * s + radii),
                none,
                z,
            ),
            at("crossing", &self.other, x * (0.8 * s + radii), across, x),
            at(
                "rim-ball",
                &self.ball,
                Vector3::new(0.5 * s, 0.0, s) + rim * (0.2 * s + self.rho),
                none,
                rim,
            ),
        ]
    }
}

/// One grid placement at gaps from a thousandth of the scale to an
/// overlap of a tenth, each cold and warm from the previous gap's answer.
fn grid_gaps(hunt: &mut Hunt, set: &GridSet, pa: &Isometry3<f64>, p: &GridPlacement<'_>) -> u64 {
    let (a, scale) = (&set.a, set.scale);
    let mut warm = None;
    let mut count = 0;
    for gap in [1e-3, 1e-6, 1e-9, 1e-12, 0.0, -1e-9, -1e-6, -0.1] {
        let rel = Isometry3::from_parts(
            Translation3::from(p.offset + p.out * (gap * scale)),
            p.rotation,
        );
        let mut case = Case {
            a,
            pa: *pa,
            b: p.b,
            pb: pa * rel,
            hint: Hint::default(),
            warm: None,
            margin: None,
            label: format!("grid-{}", p.label),
        };
        hunt.check(&case, Start::Cold);
        case.warm = warm;
        warm = hunt.check(&case, Start::Motion).map(|c| c.warm_start);
        count += 2;
    }
    count
}

/// The tallies, grouped by start and kinds, and the failures by class.
fn summarise(hunt: &Hunt, total: u64, seed: u64) {
    #[derive(Default)]
    struct Group {
        cases: u64,
        judged: u64,
        other: u64,
        undecided: u64,
        worst: f64,
    }
    let mut groups: BTreeMap<String, Group> = BTreeMap::new();
    let mut statuses: BTreeMap<String, u64> = BTreeMap::new();
    let mut classes: BTreeMap<Failure, u64> = BTreeMap::new();
    let mut refused = 0;
    // Contacts by gap and by direction (the key's fourth and fifth words).
    let mut contacts: BTreeMap<String, u64> = BTreeMap::new();
    for (key, t) in &hunt.tallies {
        refused += t.refused;
        let words: Vec<&str> = key.split_whitespace().collect();
        if words.get(2) == Some(&"contact") {
            for w in &words[3..5] {
                *contacts.entry((*w).to_string()).or_default() += t.cases;
            }
        }
        // Start, kinds and placement (the first three words).
        let group: String = key.split_whitespace().take(3).collect::<Vec<_>>().join(" ");
        let g = groups.entry(group).or_default();
        g.cases += t.cases;
        for (f, n) in &t.failures {
            if f.is_judged() {
                g.judged += n;
            } else {
                g.other += n;
            }
            *classes.entry(*f).or_default() += n;
        }
        g.undecided += t.undecided;
        g.worst = g.worst.max(t.widest);
        for (s, n) in &t.statuses {
            *statuses.entry(s.clone()).or_default() += n;
        }
    }
    println!("\nseed {seed}, {total} cases asked\n");
    println!(
        "{:<48} {:>9} {:>6} {:>6} {:>9} {:>10}",
        "start, kinds, placement", "cases", "fail", "other", "undecided", "worst/bnd"
    );
    for (name, g) in &groups {
        println!(
            "{name:<48} {:>9} {:>6} {:>6} {:>9} {:>10.2e}",
            g.cases, g.judged, g.other, g.undecided, g.worst
        );
    }
    println!("\nforeign warm starts refused as out of range (not counted): {refused}");
    println!("contacts by gap and direction: {contacts:?}");
    println!("statuses: {statuses:?}");
    println!("failures by class: {classes:?}");
}
