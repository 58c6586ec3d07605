//! Randomised extreme cases whose distance is known by construction, shared by
//! `testkit/tests/random_extremes.rs` (gjk alone, every case must pass) and
//! `bench/examples/extremes_compare.rs` (gjk beside parry3d-f64).
//!
//! The truth comes from a slab argument, not from another distance routine:
//! when `p` is a point of A that maximises `n·x` over A, and `q` a point of B
//! that minimises it over B, and `q = p + c·n` with `c >= 0`, then the cores
//! are exactly `c` apart (the slab between the two support planes separates
//! them by `c`, and `|q - p| = c`). With radii, the distance is `c - rA - rB`
//! when that is positive. Overlap cases put one point in both cores (or the
//! cores `c < rA + rB` apart, where the penetration depth is `rA + rB - c`).
//!
//! Each body's support point comes from its construction: a box's sign
//! pattern, a segment's perpendicular, a triangle's face or edge, or the
//! vertex maximising `n·x` for a general set. Contacts are vertex to vertex,
//! but also face to face (parallel faces touching), edge to edge (crossing or
//! nearly parallel, down to 1e-12 rad) and edge to face.
//!
//! Far poses round B's translation: `ta + δ` is stored as `tb` with an exact
//! error `e` (TwoSum), and B's body vertices are moved by `Rb⁻¹·e` so that the
//! realised geometry is the constructed one. The truth is then exact up to the
//! round-off of a few products at the bodies' own scale, `32 ε · extent`.

use gjk::{Convex, Shape};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// A point in three-space.
pub type P = Point3<f64>;
/// A vector in three-space.
pub type V = Vector3<f64>;

/// A small deterministic generator (SplitMix64), so a seed names a sweep.
pub struct Rng(u64);

impl Rng {
    /// The generator whose draws `seed` names.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit_interval(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit_interval()
    }

    /// Uniform in 0..n (`n` > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    /// One of `items` (not empty), uniformly.
    pub fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.below(items.len())]
    }

    /// Fisher-Yates.
    pub fn shuffle<T>(&mut self, items: &mut [T]) {
        for i in (1..items.len()).rev() {
            items.swap(i, self.below(i + 1));
        }
    }

    /// 1 or -1, evenly.
    pub fn sign(&mut self) -> f64 {
        if self.next_u64() & 1 == 0 { 1.0 } else { -1.0 }
    }

    /// A uniformly distributed unit vector (rejection from the cube).
    pub fn direction(&mut self) -> V {
        loop {
            let x = V::new(
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
                self.uniform(-1.0, 1.0),
            );
            let n2 = x.norm_squared();
            if n2 > 1e-4 && n2 <= 1.0 {
                return x / n2.sqrt();
            }
        }
    }

    /// A uniformly distributed rotation (Shoemake).
    pub fn rotation(&mut self) -> UnitQuaternion<f64> {
        let (u1, u2, u3) = (
            self.unit_interval(),
            self.unit_interval(),
            self.unit_interval(),
        );
        let tau = std::f64::consts::TAU;
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            a * (tau * u2).cos(),
            a * (tau * u2).sin(),
            b * (tau * u3).sin(),
            b * (tau * u3).cos(),
        ))
    }
}

/// How a user of a library with typed primitives would model a body, for
/// side-by-side runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Form {
    /// One point with a radius.
    Ball,
    /// Two points with a radius (a segment when the radius is 0).
    Capsule,
    /// A box with these half extents, centred on the body origin.
    Cuboid(V),
    /// Three points.
    Triangle,
    /// Any point set: its convex hull.
    Points,
}

/// Where a body's support points are known in closed form.
#[derive(Clone, Copy, Debug)]
enum Feature {
    Box(V),
    Segment(P, P),
    Triangle([P; 3]),
    /// An `n`-gonal frustum (a prism when its ends match): vertices `0..n`
    /// are the bottom end's, `n..2n` the top's, in the same turn.
    Prism(usize),
    /// Only the vertex maximising `n·x` is known.
    Generic,
}

/// One body of a case, as built.
#[derive(Clone, Debug)]
pub struct Body {
    /// What it is, for messages.
    pub name: &'static str,
    /// How its support point is known.
    pub form: Form,
    /// The body-frame vertices handed to gjk (after the shift, if any).
    pub vertices: Vec<P>,
    /// The rounding radius.
    pub radius: f64,
    /// Added to every template vertex to absorb a far pose's rounding;
    /// zero when the pose was stored exactly.
    pub shift: V,
    /// For a collinear or coplanar set, the hull's corners (the two ends, or
    /// the rectangle's corners in the order (-,-), (+,-), (-,+), (+,+)), for
    /// libraries that cannot take the hull of a flat set; shifted as the
    /// vertices are.
    pub outline: Vec<P>,
    feature: Feature,
}

impl Body {
    fn new(
        name: &'static str,
        form: Form,
        vertices: Vec<P>,
        radius: f64,
        feature: Feature,
    ) -> Self {
        let outline = match (name, feature) {
            ("collinear", Feature::Segment(a, b)) => vec![a, b],
            ("coplanar", Feature::Box(h)) => vec![
                P::new(-h.x, -h.y, 0.0),
                P::new(h.x, -h.y, 0.0),
                P::new(-h.x, h.y, 0.0),
                P::new(h.x, h.y, 0.0),
            ],
            _ => Vec::new(),
        };
        Body {
            name,
            form,
            vertices,
            radius,
            shift: V::zeros(),
            outline,
            feature,
        }
    }

    /// The mean of the vertices: a point of the core.
    pub fn centre(&self) -> P {
        let sum = self
            .vertices
            .iter()
            .fold(V::zeros(), |acc, x| acc + x.coords);
        P::from(sum / self.vertices.len() as f64)
    }

    /// Twice the largest distance from the centre, radius included.
    fn diameter(&self) -> f64 {
        let c = self.centre();
        let reach = self
            .vertices
            .iter()
            .map(|x| (x - c).norm())
            .fold(0.0, f64::max);
        2.0 * (reach + self.radius)
    }

    /// The vertex maximising `n·x`: a support point in direction `n`.
    fn argmax(&self, n: &V) -> P {
        *self
            .vertices
            .iter()
            .max_by(|x, y| x.coords.dot(n).total_cmp(&y.coords.dot(n)))
            .expect("bodies have vertices")
    }

    /// The body as a gjk shape.
    pub fn shape(&self) -> Shape {
        Convex::new(self.vertices.clone(), self.radius)
            .expect("constructed bodies are valid")
            .into()
    }

    /// A support point and its outward direction in the body frame, with the
    /// direction of the edge it lies on when the feature is an edge. Faces and
    /// edges are drawn as often as vertices, so that contacts are not all
    /// vertex to vertex.
    fn feature(&self, rng: &mut Rng) -> (V, P, Option<V>) {
        match self.feature {
            Feature::Box(h) => {
                // 1, 2 or 3 nonzero signs: a face, an edge or a corner.
                let nonzero = 1 + rng.below(3);
                let skip = rng.below(3);
                let mut sigma = [0.0; 3];
                let mut k = 0;
                for i in 0..3 {
                    let i = (i + skip) % 3;
                    if k < nonzero {
                        sigma[i] = rng.sign();
                        k += 1;
                    }
                }
                let mut n = V::zeros();
                let mut p = P::origin();
                let mut edge = None;
                for i in 0..3 {
                    if sigma[i] != 0.0 {
                        n[i] = sigma[i] * rng.uniform(0.2, 1.0);
                        p[i] = sigma[i] * h[i];
                    } else {
                        p[i] = rng.uniform(-h[i], h[i]);
                        if nonzero == 2 {
                            edge = Some(V::ith(i, 1.0));
                        }
                    }
                }
                (n.normalize(), p, edge)
            }
            Feature::Segment(a, b) => {
                let d = b - a;
                if rng.below(2) == 0 {
                    // Perpendicular: the whole segment is the support feature.
                    let e = d.normalize();
                    let n = perpendicular(&e, rng);
                    (n, a + d * rng.unit_interval(), Some(e))
                } else {
                    let n = rng.direction();
                    (n, self.argmax(&n), None)
                }
            }
            Feature::Triangle([a, b, c]) => {
                let normal = (b - a).cross(&(c - a)).normalize() * rng.sign();
                match rng.below(3) {
                    0 => {
                        let (mut u, mut w) = (rng.unit_interval(), rng.unit_interval());
                        if u + w > 1.0 {
                            (u, w) = (1.0 - u, 1.0 - w);
                        }
                        (normal, a + (b - a) * u + (c - a) * w, None)
                    }
                    1 => {
                        // An edge: its normal cone is the half plane spanned
                        // by the face normals and the in-plane outward normal.
                        let (p0, p1, other) = [(a, b, c), (b, c, a), (c, a, b)][rng.below(3)];
                        let e = (p1 - p0).normalize();
                        let mut out = normal.cross(&e);
                        if out.dot(&(other - p0)) > 0.0 {
                            out = -out;
                        }
                        let t = rng.uniform(-1.4, 1.4);
                        let n = (out * t.cos() + normal * t.sin()).normalize();
                        (n, p0 + (p1 - p0) * rng.unit_interval(), Some(e))
                    }
                    _ => {
                        let n = rng.direction();
                        (n, self.argmax(&n), None)
                    }
                }
            }
            Feature::Prism(k) => self.prism_feature(k, rng),
            Feature::Generic => {
                let n = rng.direction();
                (n, self.argmax(&n), None)
            }
        }
    }

    /// [`feature`](Self::feature) of an `k`-gonal frustum: an end face, a
    /// side face, a side edge, an end edge or a vertex. Faces get a point of
    /// the face (a mix of three of its corners); edges a normal between their
    /// two faces' normals.
    fn prism_feature(&self, k: usize, rng: &mut Rng) -> (V, P, Option<V>) {
        let v = &self.vertices;
        let (bottom, top) = (&v[..k], &v[k..2 * k]);
        let mix = |rng: &mut Rng, a: P, b: P, c: P| {
            let (mut u, mut w) = (rng.unit_interval(), rng.unit_interval());
            if u + w > 1.0 {
                (u, w) = (1.0 - u, 1.0 - w);
            }
            a + (b - a) * u + (c - a) * w
        };
        let i = rng.below(k);
        let j = (i + 1) % k;
        // Side face i (corners bottom i, i + 1, top i + 1, i), outward.
        let side = |i: usize| {
            let j = (i + 1) % k;
            let n = (bottom[j] - bottom[i]).cross(&(top[i] - bottom[i]));
            let n = n.normalize();
            if n.dot(&bottom[i].coords) < 0.0 {
                -n
            } else {
                n
            }
        };
        let end_up = rng.below(2) == 0;
        let (end, end_n) = if end_up {
            (top, V::z())
        } else {
            (bottom, -V::z())
        };
        let blend = |rng: &mut Rng, x: V, y: V| {
            let t = rng.uniform(0.05, 0.95);
            (x * t + y * (1.0 - t)).normalize()
        };
        match rng.below(5) {
            0 => {
                let (a, b, c) = (end[i], end[(i + k / 3) % k], end[(i + 2 * k / 3) % k]);
                (end_n, mix(rng, a, b, c), None)
            }
            1 => (side(i), mix(rng, bottom[i], bottom[j], top[i]), None),
            2 => {
                let n = blend(rng, side((i + k - 1) % k), side(i));
                let e = top[i] - bottom[i];
                (n, bottom[i] + e * rng.unit_interval(), Some(e.normalize()))
            }
            3 => {
                let n = blend(rng, end_n, side(i));
                let e = end[j] - end[i];
                (n, end[i] + e * rng.unit_interval(), Some(e.normalize()))
            }
            _ => {
                let n = rng.direction();
                (n, self.argmax(&n), None)
            }
        }
    }
}

/// The bodies a case draws from, at scale `s`.
fn template(rng: &mut Rng, s: f64, big: bool) -> Body {
    let rounded = |rng: &mut Rng| {
        if rng.below(2) == 0 {
            0.0
        } else {
            s * rng.uniform(0.05, 0.5)
        }
    };
    let half = |rng: &mut Rng| {
        V::new(
            s * rng.uniform(0.2, 1.0),
            s * rng.uniform(0.2, 1.0),
            s * rng.uniform(0.2, 1.0),
        )
    };
    let corners = |h: V| -> Vec<P> {
        (0..8)
            .map(|i| {
                P::new(
                    if i & 1 == 0 { -h.x } else { h.x },
                    if i & 2 == 0 { -h.y } else { h.y },
                    if i & 4 == 0 { -h.z } else { h.z },
                )
            })
            .collect()
    };
    let kinds = if big { 12 } else { 10 };
    match rng.below(kinds) {
        0 => {
            let h = half(rng);
            Body::new(
                "box",
                Form::Cuboid(h),
                corners(h),
                rounded(rng),
                Feature::Box(h),
            )
        }
        1 => Body::new(
            "sphere",
            Form::Ball,
            vec![P::origin()],
            s * rng.uniform(0.2, 1.0),
            Feature::Generic,
        ),
        2 => {
            let d = rng.direction() * s * rng.uniform(0.2, 1.0);
            let (a, b) = (P::from(-d), P::from(d));
            let name = if rng.below(2) == 0 {
                "segment"
            } else {
                "capsule"
            };
            let r = if name == "segment" {
                0.0
            } else {
                s * rng.uniform(0.05, 0.5)
            };
            Body::new(name, Form::Capsule, vec![a, b], r, Feature::Segment(a, b))
        }
        3 => {
            let pts = loop {
                let pts = [0; 3].map(|_| P::from(rng.direction() * s));
                if (pts[1] - pts[0]).cross(&(pts[2] - pts[0])).norm() > 0.3 * s * s {
                    break pts;
                }
            };
            Body::new(
                "triangle",
                Form::Triangle,
                pts.to_vec(),
                rounded(rng),
                Feature::Triangle(pts),
            )
        }
        4 => {
            // Points on an ellipsoid: all of them hull vertices.
            let axes = half(rng);
            let n = 12 + rng.below(40);
            let pts = (0..n)
                .map(|_| P::from(rng.direction().component_mul(&axes)))
                .collect();
            Body::new(
                "polytope",
                Form::Points,
                pts,
                rounded(rng),
                Feature::Generic,
            )
        }
        5 => {
            // A box's corners three times each, its centre and its edge
            // midpoints, shuffled: duplicates and non-hull points.
            let h = half(rng);
            let c = corners(h);
            let mut pts: Vec<P> = c.iter().chain(&c).chain(&c).copied().collect();
            pts.push(P::origin());
            for i in 0..8 {
                for bit in [1, 2, 4] {
                    if i & bit == 0 {
                        pts.push(P::from((c[i].coords + c[i | bit].coords) * 0.5));
                    }
                }
            }
            rng.shuffle(&mut pts);
            Body::new(
                "duplicates",
                Form::Points,
                pts,
                rounded(rng),
                Feature::Box(h),
            )
        }
        6 => {
            // Collinear: both ends, points between, one repeated.
            let d = rng.direction() * s * rng.uniform(0.2, 1.0);
            let (a, b) = (P::from(-d), P::from(d));
            let mut pts = vec![a, b, a];
            for _ in 0..6 {
                pts.push(a + (b - a) * rng.unit_interval());
            }
            rng.shuffle(&mut pts);
            Body::new(
                "collinear",
                Form::Points,
                pts,
                rounded(rng),
                Feature::Segment(a, b),
            )
        }
        7 => {
            // Coplanar: a rectangle's corners (each twice) and inner points.
            let mut h = half(rng);
            h.z = 0.0;
            let mut pts: Vec<P> = corners(h);
            for _ in 0..6 {
                pts.push(P::new(rng.uniform(-h.x, h.x), rng.uniform(-h.y, h.y), 0.0));
            }
            Body::new("coplanar", Form::Points, pts, rounded(rng), Feature::Box(h))
        }
        8 => Body::new(
            "point",
            Form::Ball,
            vec![P::origin()],
            0.0,
            Feature::Generic,
        ),
        9 => {
            // A frustum or prism of 3 to 12 sides, like the paper's family:
            // end faces of up to 12 coplanar vertices, trapezoid sides.
            let k = 3 + rng.below(10);
            let rb = s * rng.uniform(0.2, 1.0);
            let rt = if rng.below(2) == 0 {
                rb
            } else {
                s * rng.uniform(0.2, 1.0)
            };
            let h = s * rng.uniform(0.1, 1.0);
            let phase = rng.uniform(0.0, std::f64::consts::TAU);
            let ring = |r: f64, z: f64| {
                (0..k).map(move |i| {
                    let a = phase + std::f64::consts::TAU * i as f64 / k as f64;
                    P::new(r * a.cos(), r * a.sin(), z)
                })
            };
            let pts = ring(rb, -h).chain(ring(rt, h)).collect();
            Body::new("prism", Form::Points, pts, rounded(rng), Feature::Prism(k))
        }
        10 => {
            // 100 000 points on a box's faces, its corners among them: the
            // hull is the box, and each face holds some 16 000 coplanar
            // points, every one a tie for the support in its normal.
            let h = half(rng);
            let mut pts = corners(h);
            while pts.len() < 100_000 {
                let axis = rng.below(3);
                let mut x = V::new(
                    rng.uniform(-h.x, h.x),
                    rng.uniform(-h.y, h.y),
                    rng.uniform(-h.z, h.z),
                );
                x[axis] = rng.sign() * h[axis];
                pts.push(P::from(x));
            }
            rng.shuffle(&mut pts);
            Body::new("100k box", Form::Points, pts, 0.0, Feature::Box(h))
        }
        _ => {
            let r = s * rng.uniform(0.5, 1.0);
            let pts = (0..100_000).map(|_| P::from(rng.direction() * r)).collect();
            Body::new("100k points", Form::Points, pts, 0.0, Feature::Generic)
        }
    }
}

/// How the two bodies meet.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Contact {
    /// B turned at random: its support point is (almost always) a vertex.
    Separated,
    /// B turned so that its drawn feature faces A's: face to face (parallel
    /// faces), edge to face, edge to edge crossing.
    Aligned,
    /// Edge to edge, the edges within 1e-2 to 1e-12 rad of parallel, or
    /// exactly parallel.
    NearlyParallelEdges,
    /// The cores apart, the rounded shells overlapping: depth known exactly.
    ShellsOverlap,
    /// A point of B's boundary a fraction 1e-12 to 0.1 of the way from A's
    /// boundary to its centre.
    ShallowOverlap,
    /// The centres together.
    DeepOverlap,
    /// The same body at the same pose twice.
    Identical,
    /// B a copy of a centrally symmetric A, facing it across the drawn
    /// feature and turned about the normal by 0 or 1e-2 to 1e-12 rad:
    /// parallel faces, and equal edges nearly parallel, whose K has nearly
    /// coincident points.
    Twins,
}

/// One query with its truth.
pub struct Case {
    /// How the bodies meet.
    pub contact: Contact,
    /// The first body.
    pub a: Body,
    /// The first body's pose.
    pub pa: Isometry3<f64>,
    /// The second body.
    pub b: Body,
    /// The second body's pose.
    pub pb: Isometry3<f64>,
    /// The distance after radii.
    pub truth: f64,
    /// The penetration depth, where the construction knows it.
    pub depth: Option<f64>,
    /// The larger body's diameter: the absolute part of the requirement.
    pub size: f64,
    /// How far the truth may be from the real geometry of the stored inputs.
    pub truth_slack: f64,
    /// The bodies' scale drawn, one of [`SCALES`].
    pub scale: f64,
    /// The distance from the world origin drawn, one of [`OFFSETS`].
    pub offset: f64,
    /// The gap drawn, as a fraction of `size` (0 for overlaps).
    pub gap: f64,
    /// The world direction `n` of the construction: for the separated kinds
    /// (and twins) A's core lies in `n·x <= h` and B's in `n·x >= h + c`, so
    /// a body moved or shrunk within its half space is no nearer.
    pub normal: V,
}

impl Case {
    /// A one-line description for a failure message.
    pub fn describe(&self) -> String {
        format!(
            "{:?} {} vs {} (r {:e}, {:e}), scale {:e}, offset {:e}, gap {:e}·size, truth {:e}, size {:e}",
            self.contact,
            self.a.name,
            self.b.name,
            self.a.radius,
            self.b.radius,
            self.scale,
            self.offset,
            self.gap,
            self.truth,
            self.size
        )
    }
}

/// The bodies' scales drawn.
pub const SCALES: [f64; 6] = [1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e6];
/// The distances of the pair from the world origin drawn.
pub const OFFSETS: [f64; 4] = [0.0, 1e3, 1e6, 1e9];
/// The gaps drawn, as fractions of the size.
pub const GAPS: [f64; 7] = [1.0, 1e-1, 1e-3, 1e-6, 1e-9, 1e-12, 0.0];

/// `a + b = s + e` exactly, `s` the rounded sum (Knuth's TwoSum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `x` made orthogonal to unit `u` and normalised: Gram-Schmidt twice, so
/// that `u·result` is round-off of `ε` however close `x` was to `u` (once
/// leaves `ε/|x - (u·x)u|`, which the generator's nearly parallel edges turn
/// into a tilt of the common normal, and a truth off by 1e-13 of the size).
fn orthogonal(u: &V, x: &V) -> V {
    let once = x - u * u.dot(x);
    let twice = once - u * u.dot(&once);
    twice.normalize()
}

/// A random unit vector orthogonal to unit `u`.
fn perpendicular(u: &V, rng: &mut Rng) -> V {
    loop {
        let x = rng.direction();
        if u.cross(&x).norm() > 0.5 {
            return orthogonal(u, &x);
        }
    }
}

/// The rotation taking the orthonormal pair `(from, from_t)` to `(to, to_t)`,
/// built from the two frames rather than from an angle and an axis (whose
/// round-off grows as the vectors near antiparallel): it maps `from` to `to`
/// within a few ε.
fn frame_rotation(from: &V, from_t: &V, to: &V, to_t: &V) -> UnitQuaternion<f64> {
    let frame = |a: &V, b: &V| nalgebra::Matrix3::from_columns(&[*a, *b, a.cross(b)]);
    let m = frame(to, to_t) * frame(from, from_t).transpose();
    UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(m))
}

/// Draw one case. `big` lets 100 000-point bodies in.
pub fn draw(rng: &mut Rng, big: bool) -> Case {
    let scale = rng.pick(&SCALES) * rng.uniform(0.5, 2.0);
    let offset = rng.pick(&OFFSETS);
    let contact = match rng.below(22) {
        0..=6 => Contact::Separated,
        7..=10 => Contact::Aligned,
        11..=13 => Contact::NearlyParallelEdges,
        14..=15 => Contact::ShellsOverlap,
        16..=17 => Contact::ShallowOverlap,
        18 => Contact::DeepOverlap,
        19 => Contact::Identical,
        _ => Contact::Twins,
    };
    let scale_b = scale * rng.uniform(0.3, 3.0);
    let mut a = template(rng, scale, big);
    let mut b = template(rng, scale_b, big);
    if contact == Contact::NearlyParallelEdges {
        // Two bodies with edges: boxes, segments, capsules, triangles.
        let edged = |rng: &mut Rng, s: f64| loop {
            let t = template(rng, s, false);
            if matches!(t.feature, Feature::Box(h) if h.z != 0.0)
                || matches!(
                    t.feature,
                    Feature::Segment(..) | Feature::Triangle(_) | Feature::Prism(_)
                )
            {
                break t;
            }
        };
        a = edged(rng, scale);
        b = edged(rng, scale_b);
    }
    if contact == Contact::ShellsOverlap {
        if a.radius == 0.0 {
            a.radius = scale * rng.uniform(0.05, 0.5);
        }
        if b.radius == 0.0 {
            b.radius = scale * rng.uniform(0.05, 0.5);
        }
    }
    if contact == Contact::Twins {
        // Centrally symmetric bodies only: the copy's support point facing
        // A is then the reflection of A's.
        while !matches!(
            a.name,
            "box"
                | "sphere"
                | "segment"
                | "capsule"
                | "duplicates"
                | "collinear"
                | "coplanar"
                | "point"
        ) {
            a = template(rng, scale, false);
        }
    }
    if matches!(contact, Contact::Identical | Contact::Twins) {
        b = a.clone();
    }
    let size = a.diameter().max(b.diameter());
    let ra = rng.rotation();
    let ta = rng.direction() * offset;
    let pa = Isometry3::from_parts(Translation3::from(ta), ra);

    // A's support point p (body frame) in direction na, and B's rotation and
    // point q, with the core gap c along n = Ra·na between them.
    let (na, p, edge_a) = loop {
        let f = a.feature(rng);
        if contact != Contact::NearlyParallelEdges || f.2.is_some() {
            break f;
        }
    };
    let n = ra * na;
    let mut gap = 0.0;
    // B's rotation, its point q, the core gap c (for touching and separated
    // cases) and the world point, relative to ta, where q is put.
    let (rb, q, c, world_target): (UnitQuaternion<f64>, P, f64, V) = match contact {
        Contact::Separated | Contact::Aligned | Contact::NearlyParallelEdges => {
            gap = rng.pick(&GAPS);
            let c = gap * size + a.radius + b.radius;
            let (rb, q) = match contact {
                Contact::Separated => {
                    let rb = rng.rotation();
                    (rb, b.argmax(&(rb.inverse() * -n)))
                }
                _ => {
                    let (nb, q, edge_b) = loop {
                        let f = b.feature(rng);
                        if contact != Contact::NearlyParallelEdges || f.2.is_some() {
                            break f;
                        }
                    };
                    // B's feature faces A's: nb goes to -n; its second axis
                    // (B's edge, or any direction across nb) goes to A's edge
                    // turned by a drawn angle about n (or to any direction
                    // across n).
                    let from_t = match edge_b {
                        Some(e) => orthogonal(&nb, &e),
                        None => perpendicular(&nb, rng),
                    };
                    let to_t = if contact == Contact::NearlyParallelEdges {
                        let w = orthogonal(&n, &(ra * edge_a.expect("drawn")));
                        let off = match rng.below(7) {
                            0 => 0.0,
                            k => rng.sign() * 10f64.powi(-2 * k as i32),
                        };
                        orthogonal(&n, &(w * off.cos() + n.cross(&w) * off.sin()))
                    } else {
                        perpendicular(&n, rng)
                    };
                    (frame_rotation(&nb, &from_t, &-n, &to_t), q)
                }
            };
            (rb, q, c, ra * p.coords + n * c)
        }
        Contact::ShellsOverlap => {
            let rb = rng.rotation();
            let q = b.argmax(&(rb.inverse() * -n));
            let c = (a.radius + b.radius) * rng.uniform(0.01, 0.99);
            (rb, q, c, ra * p.coords + n * c)
        }
        Contact::ShallowOverlap => {
            // B's support point goes a fraction h of the way from A's
            // support point to A's centre: a point of A's core.
            let rb = rng.rotation();
            let q = b.argmax(&(rb.inverse() * -n));
            let h = rng.pick(&[1e-12, 1e-9, 1e-6, 1e-3, 0.1]);
            let target = p + (a.centre() - p) * h;
            (rb, q, 0.0, ra * target.coords)
        }
        Contact::DeepOverlap => {
            let rb = rng.rotation();
            (rb, b.centre(), 0.0, ra * a.centre().coords)
        }
        Contact::Identical => (ra, p, 0.0, ra * p.coords),
        Contact::Twins => {
            gap = rng.pick(&GAPS);
            let c = gap * size + a.radius + b.radius;
            let off = match rng.below(7) {
                0 => 0.0,
                k => rng.sign() * 10f64.powi(-2 * k as i32),
            };
            let turn = UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_unchecked(na), off);
            (ra * turn, -p, c, ra * p.coords + n * c)
        }
    };

    let delta = world_target - rb * q.coords;
    let mut tb = V::zeros();
    let mut err = V::zeros();
    for i in 0..3 {
        (tb[i], err[i]) = two_sum(ta[i], delta[i]);
    }
    if contact != Contact::Identical {
        // Realised: tb + Rb·(v + Rb⁻¹e) = ta + δ + Rb·v.
        let shift = rb.inverse() * err;
        if shift != V::zeros() {
            b.shift = shift;
            for x in b.vertices.iter_mut().chain(&mut b.outline) {
                *x += shift;
            }
        }
    }
    let pb = Isometry3::from_parts(Translation3::from(tb), rb);
    let (truth, depth) = match contact {
        Contact::Separated | Contact::Aligned | Contact::NearlyParallelEdges | Contact::Twins => {
            ((c - a.radius - b.radius).max(0.0), None)
        }
        Contact::ShellsOverlap => (0.0, Some(a.radius + b.radius - c)),
        _ => (0.0, None),
    };
    let extent = size + b.shift.norm() + a.diameter();
    Case {
        contact,
        a,
        pa,
        b,
        pb,
        truth,
        depth,
        size,
        truth_slack: 32.0 * f64::EPSILON * extent,
        scale,
        offset,
        gap,
        normal: n,
    }
}

/// `Some(why)` when a reported distance misses the requirement:
/// within 1e-6 of the truth, or 1e-9 of the size where that is larger.
pub fn distance_error(case: &Case, distance: f64) -> Option<String> {
    let allowed = (1e-6 * case.truth).max(1e-9 * case.size) + case.truth_slack;
    let err = distance - case.truth;
    if err.is_nan() || err.abs() > allowed {
        Some(format!("error {err:e} > allowed {allowed:e}"))
    } else {
        None
    }
}

/// `Some(why)` when certified bounds miss the truth.
pub fn bounds_error(case: &Case, lower: f64, upper: f64) -> Option<String> {
    let t = case.truth;
    if lower.is_nan()
        || upper.is_nan()
        || lower > t + case.truth_slack
        || t > upper + case.truth_slack
    {
        Some(format!("bounds [{lower:e}, {upper:e}] miss the truth"))
    } else {
        None
    }
}

/// `Some(why)` when a penetration depth the construction knows exactly is
/// missed (held to the same requirement as the distance).
pub fn depth_error(case: &Case, penetration: f64) -> Option<String> {
    let depth = case.depth?;
    let allowed = (1e-6 * depth).max(1e-9 * case.size) + case.truth_slack;
    let err = penetration - depth;
    if err.is_nan() || err.abs() > allowed {
        Some(format!("penetration {penetration:e} against {depth:e}"))
    } else {
        None
    }
}
