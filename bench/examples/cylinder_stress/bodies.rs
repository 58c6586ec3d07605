//! The bodies the hunt draws: cylinders and the other shapes, each as gjk
//! sees it and as the independent bracket sees it.

#[allow(unused_imports)]
use super::*;

/// A small xorshift generator.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn bits(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    /// Uniform in [0, 1).
    pub(crate) fn unit_interval(&mut self) -> f64 {
        (self.bits() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub(crate) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit_interval()
    }
    /// `10^x` for `x` uniform in `[lo, hi)`.
    pub(crate) fn log(&mut self, lo: f64, hi: f64) -> f64 {
        10f64.powf(self.range(lo, hi))
    }
    pub(crate) fn below(&mut self, n: u64) -> u64 {
        self.bits() % n
    }
    pub(crate) fn chance(&mut self, p: f64) -> bool {
        self.unit_interval() < p
    }
    pub(crate) fn direction(&mut self) -> Vector3<f64> {
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
    pub(crate) fn rotation(&mut self) -> UnitQuaternion<f64> {
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
pub(crate) fn special_rotation(rng: &mut Rng) -> UnitQuaternion<f64> {
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
pub(crate) fn relative_rotation(rng: &mut Rng) -> (UnitQuaternion<f64>, &'static str) {
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
pub(crate) enum Geom {
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
pub(crate) struct Piece {
    pub(crate) geom: Geom,
    pub(crate) rho: f64,
    pub(crate) convex: Convex,
    /// A hull's core (no rounding), for the projections onto it.
    pub(crate) core: Option<Shape>,
}

impl Piece {
    pub(crate) fn new(geom: Geom, rho: f64, rng: &mut Rng) -> Piece {
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

    pub(crate) fn kind(&self) -> &'static str {
        match &self.geom {
            Geom::Cylinder { .. } => "cylinder",
            Geom::Cuboid { .. } => "box",
            Geom::Segment { a, b } if a == b => "sphere",
            Geom::Segment { .. } => "capsule",
            Geom::Hull { .. } => "hull",
        }
    }

    /// The largest distance from the body origin to a point of the piece.
    pub(crate) fn size(&self) -> f64 {
        let core = match &self.geom {
            Geom::Cylinder { r, h } => r.hypot(*h),
            Geom::Cuboid { half } => half.norm(),
            Geom::Segment { a, b } => a.norm().max(b.norm()),
            Geom::Hull { verts } => verts.iter().map(|v| v.norm()).fold(0.0, f64::max),
        };
        core + self.rho
    }

    /// The support function of the core in direction `n` (any length).
    pub(crate) fn core_support(&self, n: &Vector3<f64>) -> f64 {
        match &self.geom {
            Geom::Cylinder { r, h } => r * n.x.hypot(n.y) + h * n.z.abs(),
            Geom::Cuboid { half } => half.x * n.x.abs() + half.y * n.y.abs() + half.z * n.z.abs(),
            Geom::Segment { a, b } => a.dot(n).max(b.dot(n)),
            Geom::Hull { verts } => verts.iter().map(|v| v.dot(n)).fold(f64::MIN, f64::max),
        }
    }

    /// The support function of the piece (unit `n`).
    pub(crate) fn support(&self, n: &Vector3<f64>) -> f64 {
        self.core_support(n) + self.rho
    }

    /// A point of the core's support face in direction `n` (unit): where
    /// the face is a disk, a segment or a rectangle (a component of `n`
    /// within `flat` of zero), a random point of it.
    pub(crate) fn face_point(&self, n: &Vector3<f64>, rng: &mut Rng) -> Vector3<f64> {
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
    pub(crate) fn support_point(&self, n: &Vector3<f64>) -> Vector3<f64> {
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
    pub(crate) fn core_project(&self, p: &Vector3<f64>, point_shape: &Shape) -> Vector3<f64> {
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
    pub(crate) fn project(&self, p: &Vector3<f64>, point_shape: &Shape) -> Vector3<f64> {
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
pub(crate) struct Body {
    pub(crate) pieces: Vec<(Isometry3<f64>, Piece)>,
    pub(crate) shape: Shape,
}

impl Body {
    pub(crate) fn convex(piece: Piece) -> Body {
        let shape = piece.convex.clone().into();
        Body {
            pieces: vec![(Isometry3::identity(), piece)],
            shape,
        }
    }

    pub(crate) fn compound(pieces: Vec<(Isometry3<f64>, Piece)>) -> Body {
        let shape = Compound::new(pieces.iter().map(|(o, p)| (*o, p.convex.clone())).collect())
            .expect("a valid compound")
            .into();
        Body { pieces, shape }
    }

    pub(crate) fn size(&self) -> f64 {
        self.pieces
            .iter()
            .map(|(o, p)| o.translation.vector.norm() + p.size())
            .fold(0.0, f64::max)
    }

    pub(crate) fn kind(&self) -> String {
        if self.pieces.len() == 1 {
            self.pieces[0].1.kind().to_string()
        } else {
            "compound".to_string()
        }
    }

    /// The largest valid index of a warm start into this body's piece
    /// `piece` (`u32::MAX` for a cylinder, whose codes are all valid).
    pub(crate) fn index_limit(&self, piece: usize) -> u32 {
        let p = &self.pieces[piece].1;
        match p.geom {
            Geom::Cylinder { .. } => u32::MAX,
            _ => (p.convex.len() - 1) as u32,
        }
    }
}

/// A random cylinder of about `scale`: ordinary, a flat disk, a needle,
/// or degenerate (zero radius or height), sharp or rounded.
pub(crate) fn random_cylinder(rng: &mut Rng, scale: f64) -> Piece {
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
pub(crate) fn rounding(rng: &mut Rng, scale: f64) -> f64 {
    if rng.chance(0.5) {
        0.0
    } else {
        scale * rng.log(-6.0, 0.0)
    }
}

/// A random piece of another kind (or another cylinder), of about `scale`.
pub(crate) fn random_other(rng: &mut Rng, scale: f64) -> Piece {
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
