//! Double-double arithmetic for the one place it is needed: the offset between
//! two centroids when a body frame (or a compound's piece frame) sits far
//! from its vertices. There the pose translation and the rotated centroid are
//! both huge and cancel, and plain f64 would lose the digits the distance is
//! made of.

use nalgebra::{Isometry3, Point3, Vector3};

/// An unevaluated sum `hi + lo` with `|lo| <= ulp(hi)/2`.
#[derive(Clone, Copy, Debug)]
struct Dd {
    hi: f64,
    lo: f64,
}

fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    Dd {
        hi: s,
        lo: (a - (s - bb)) + (b - bb),
    }
}

fn two_prod(a: f64, b: f64) -> Dd {
    let p = a * b;
    Dd {
        hi: p,
        lo: a.mul_add(b, -p),
    }
}

impl Dd {
    fn add(self, o: Dd) -> Dd {
        let s = two_sum(self.hi, o.hi);
        let lo = s.lo + self.lo + o.lo;
        let hi = s.hi + lo;
        Dd {
            hi,
            lo: lo - (hi - s.hi),
        }
    }

    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }

    fn mul(self, b: f64) -> Dd {
        let p = two_prod(self.hi, b);
        let lo = p.lo + self.lo * b;
        let hi = p.hi + lo;
        Dd {
            hi,
            lo: lo - (hi - p.hi),
        }
    }

    fn mul_dd(self, b: Dd) -> Dd {
        let p = two_prod(self.hi, b.hi);
        let lo = p.lo + (self.hi * b.lo + self.lo * b.hi);
        let hi = p.hi + lo;
        Dd {
            hi,
            lo: lo - (hi - p.hi),
        }
    }

    fn scale2(self) -> Dd {
        Dd {
            hi: 2.0 * self.hi,
            lo: 2.0 * self.lo,
        }
    }
}

fn one() -> Dd {
    Dd { hi: 1.0, lo: 0.0 }
}

/// `pose * c` in double-double, the rotation matrix formed from the quaternion
/// in double-double too.
fn place(pose: &Isometry3<f64>, c: &Point3<f64>) -> [Dd; 3] {
    let r = matrix(pose);
    let t = pose.translation.vector;
    [0, 1, 2].map(|i| {
        (0..3).fold(Dd { hi: t[i], lo: 0.0 }, |acc, j| {
            acc.add(r[i][j].mul(c[j]))
        })
    })
}

/// `pose * c` for a point `c` already in double-double.
fn place_dd(pose: &Isometry3<f64>, c: &[Dd; 3]) -> [Dd; 3] {
    let r = matrix(pose);
    let t = pose.translation.vector;
    [0, 1, 2].map(|i| {
        (0..3).fold(Dd { hi: t[i], lo: 0.0 }, |acc, j| {
            acc.add(r[i][j].mul_dd(c[j]))
        })
    })
}

/// `pose * (offset * c)`, or `pose * c` without an offset, in double-double.
fn place_in(pose: &Isometry3<f64>, offset: Option<&Isometry3<f64>>, c: &Point3<f64>) -> [Dd; 3] {
    match offset {
        Some(o) => place_dd(pose, &place(o, c)),
        None => place(pose, c),
    }
}

/// The rotation matrix of `pose`, formed from its quaternion in
/// double-double.
fn matrix(pose: &Isometry3<f64>) -> [[Dd; 3]; 3] {
    let q = pose.rotation.quaternion();
    let (x, y, z, w) = (q.i, q.j, q.k, q.w);
    let sq = |a: f64, b: f64| two_prod(a, a).add(two_prod(b, b));
    [
        [
            one().add(sq(y, z).scale2().neg()),
            two_prod(x, y).add(two_prod(z, w).neg()).scale2(),
            two_prod(x, z).add(two_prod(y, w)).scale2(),
        ],
        [
            two_prod(x, y).add(two_prod(z, w)).scale2(),
            one().add(sq(x, z).scale2().neg()),
            two_prod(y, z).add(two_prod(x, w).neg()).scale2(),
        ],
        [
            two_prod(x, z).add(two_prod(y, w).neg()).scale2(),
            two_prod(y, z).add(two_prod(x, w)).scale2(),
            one().add(sq(x, y).scale2().neg()),
        ],
    ]
}

/// `pose_b * (offset_b * cb) - pose_a * (offset_a * ca)` in world
/// coordinates (without an offset, `pose * c`), rounded once at the end.
pub(crate) fn centroid_gap(
    (pose_a, offset_a): (&Isometry3<f64>, Option<&Isometry3<f64>>),
    ca: &Point3<f64>,
    (pose_b, offset_b): (&Isometry3<f64>, Option<&Isometry3<f64>>),
    cb: &Point3<f64>,
) -> Vector3<f64> {
    let (a, b) = (
        place_in(pose_a, offset_a, ca),
        place_in(pose_b, offset_b, cb),
    );
    Vector3::from_fn(|i, _| {
        let d = b[i].add(a[i].neg());
        d.hi + d.lo
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    #[test]
    fn cancellation_at_1e9_keeps_the_small_gap() {
        let rot = UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7);
        let c = Point3::new(1e9, -2e9, 0.5e9);
        let pa = Isometry3::from_parts(Translation3::from(-(rot * c.coords)), rot);
        // World centroid of A: pa * c = 0 up to the rounding of the translation.
        let gap = centroid_gap(
            (&pa, None),
            &c,
            (&Isometry3::identity(), None),
            &Point3::new(1.5, 0.0, 0.0),
        );
        let naive = Point3::new(1.5, 0.0, 0.0) - pa * c;
        // The translation was itself rounded, so the true residue is what the
        // exact product leaves; double-double sees it, plain f64 does not.
        assert!((gap - naive).norm() < 1e-6, "{gap} vs {naive}");
        assert!((gap.x - 1.5).abs() < 1e-6);
    }
}
