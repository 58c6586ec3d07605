//! A seed for the run of a pair with a cylinder: Newton's method on the
//! direction between the nearest points.
//!
//! On a cylinder's curved rim the plain run converges linearly (about one
//! iteration a decimal digit), where a polytope's ends at exact vertices in
//! three or four. The distance is the largest separation of the two
//! shapes' projections on a unit direction `u`,
//! `F(u) = -h_K(u) = -u·s_K(u)`, whose gradient is `-s_K(u)` and whose
//! Hessian is minus the sum of the shapes' support Hessians: a rim's is
//! `k·t·tᵀ` (`t` the rim's tangent, `k = r / |u_xy|`), a vertex's zero.
//! Newton's method on the unit sphere converges quadratically where `F` is
//! smooth. Where the answer lies on a flat feature (a cylinder's side, a
//! polytope's edge or face) `F` has a kink, found when a step changes a
//! shape's cap or vertex: the difference of the two support points is then
//! perpendicular to the answer's direction, and the steps go on in the
//! directions perpendicular to it. The support points at the final
//! direction, with the partners of each kink, are the seed.
//!
//! The seed only chooses where the ordinary run starts: the run certifies
//! the bounds (Theorem 4.1) as for any start, so a seed on the wrong
//! feature, or none when the steps do not converge, costs time, never
//! exactness.

use nalgebra::Vector3;

use super::pair::{ConvexPair, rotate, rotate_back};
use crate::cylinder;
use crate::johnson::Vertex;
use crate::shape::Convex;

/// Newton steps before the seed is given up.
const MAX_STEPS: u32 = 8;

/// The step (in radians) below which the direction has converged: the next
/// step would be of its square's order, and the run's stopping rule needs
/// the direction to about 1e-7.
const CONVERGED_STEP: f64 = 1e-6;

/// One shape's support at a direction, in the pair frame (scaled).
#[derive(Clone, Copy)]
struct Touch {
    /// The support point.
    point: Vector3<f64>,
    /// The vertex index, or for a cylinder its cap (0 or 1): a change is a
    /// kink.
    key: u32,
    /// The support Hessian `k·t·tᵀ`: zero for a polytope.
    curvature: f64,
    tangent: Vector3<f64>,
    /// A cylinder's axis (the difference of its caps): zero for a polytope,
    /// whose kinks are the differences of its vertices.
    axis: Vector3<f64>,
}

/// What one shape's kinks have shown: the support keys seen on either side
/// of each (a cylinder's two caps, a polytope's vertices), at most three.
#[derive(Clone, Copy, Default)]
struct Kinks {
    keys: [u32; 3],
    len: usize,
}

impl Kinks {
    fn has(&self, key: u32) -> bool {
        self.keys[..self.len].contains(&key)
    }

    fn add(&mut self, key: u32) -> bool {
        if self.has(key) || self.len == 3 {
            return false;
        }
        self.keys[self.len] = key;
        self.len += 1;
        true
    }
}

/// The directions the answer's direction is known to be perpendicular to,
/// orthonormal, at most two.
#[derive(Clone, Copy, Default)]
struct Constraints {
    axes: [Vector3<f64>; 2],
    len: usize,
}

impl Constraints {
    /// Adds `c` (any length) unless it is (nearly) in the span of those
    /// already held.
    fn add(&mut self, mut c: Vector3<f64>) {
        for axis in &self.axes[..self.len] {
            c -= *axis * axis.dot(&c);
        }
        let norm = c.norm();
        if self.len < 2 && norm > 1e-6 {
            self.axes[self.len] = c / norm;
            self.len += 1;
        }
    }

    /// `u` moved onto the directions perpendicular to every constraint,
    /// unit; `None` if it has no such part.
    fn project(&self, u: &Vector3<f64>) -> Option<Vector3<f64>> {
        let p = match self.len {
            0 => *u,
            1 => u - self.axes[0] * self.axes[0].dot(u),
            _ => {
                let n = self.axes[0].cross(&self.axes[1]);
                n * n.dot(u).signum()
            }
        };
        let norm = p.norm();
        (norm > 1e-12).then(|| p / norm)
    }
}

/// The support of `shape` (a body frame's centroid-relative coordinates)
/// at the body direction `d` (unit), by the cylinder's closed form with its
/// curvature, or the polytope's support search. `None` at a cylinder's
/// axis, where the curvature is unbounded.
#[inline(always)]
fn body_touch(shape: &Convex, d: &Vector3<f64>) -> Option<Touch> {
    let Some((r, h)) = shape.cylinder_dimensions() else {
        let (index, point) = shape.support_point(d);
        return Some(Touch {
            point,
            key: index as u32,
            curvature: 0.0,
            tangent: Vector3::zeros(),
            axis: Vector3::zeros(),
        });
    };
    let rho = d.x.hypot(d.y);
    if !(rho > 1e-9) {
        return None;
    }
    let (cx, sy) = (d.x / rho, d.y / rho);
    let top = d.z > 0.0;
    Some(Touch {
        point: Vector3::new(r * cx, r * sy, if top { h } else { -h }),
        key: u32::from(top),
        curvature: r / rho,
        tangent: Vector3::new(-sy, cx, 0.0),
        axis: Vector3::z(),
    })
}

/// A running Newton solve: the direction, what each shape's kinks showed,
/// and the constraints they impose.
struct Solve {
    u: Vector3<f64>,
    kinks: [Kinks; 2],
    constraints: Constraints,
}

impl ConvexPair<'_> {
    /// Both shapes' supports at `u` (pair frame, unit): A's at `u`, B's at
    /// `-u`, B's moved into the pair frame.
    #[inline(always)]
    fn touches(&self, u: &Vector3<f64>) -> Option<[Touch; 2]> {
        let mut a = body_touch(self.a, u)?;
        let mut b = body_touch(self.b, &-rotate_back(&self.rotation, u))?;
        a.point *= self.scale;
        a.curvature *= self.scale;
        b.point = rotate(&self.rotation, &b.point) * self.scale + self.centroid_gap;
        b.curvature *= self.scale;
        b.tangent = rotate(&self.rotation, &b.tangent);
        b.axis = rotate(&self.rotation, &b.axis);
        Some([a, b])
    }

    /// The seed of a pair with a cylinder, from the direction `-v` of an
    /// iterate or a warm start: at most three index pairs, or `None` when
    /// the solve fails (the shapes overlap, a direction along a cylinder's
    /// axis, no convergence).
    pub(super) fn newton_seed(&self, v: &Vector3<f64>) -> Option<([[u32; 2]; 3], usize)> {
        let norm = v.norm();
        if !(norm > 0.0 && norm.is_finite()) {
            return None;
        }
        let mut solve = Solve {
            u: -v / norm,
            kinks: [Kinks::default(); 2],
            constraints: Constraints::default(),
        };
        let mut last: Option<[Touch; 2]> = None;
        for _ in 0..MAX_STEPS {
            let touches = self.touches(&solve.u)?;
            if let Some(previous) = last
                && self.note_kinks(&mut solve, &previous, &touches)
            {
                solve.u = solve.constraints.project(&solve.u)?;
                last = None;
                continue;
            }
            last = Some(touches);
            let step = newton_step(&solve, &touches)?;
            let length = step.norm();
            solve.u = solve.constraints.project(&(solve.u + step))?;
            if length < CONVERGED_STEP || solve.constraints.len == 2 {
                return self.seed_at(&solve);
            }
        }
        None
    }

    /// Records the kinks crossed between `previous` and `now`: a cylinder's
    /// cap or a polytope's vertex changed, so the answer's direction is
    /// perpendicular to the two support points' difference. Whether a new
    /// constraint was added.
    fn note_kinks(&self, solve: &mut Solve, previous: &[Touch; 2], now: &[Touch; 2]) -> bool {
        let mut added = false;
        for k in 0..2 {
            let (was, is) = (&previous[k], &now[k]);
            if was.key == is.key {
                continue;
            }
            let kinks = &mut solve.kinks[k];
            let fresh = kinks.len == 0 || !kinks.has(is.key) || !kinks.has(was.key);
            if fresh {
                kinks.add(was.key);
                kinks.add(is.key);
                let before = solve.constraints.len;
                let edge = if is.axis == Vector3::zeros() {
                    is.point - was.point
                } else {
                    is.axis
                };
                solve.constraints.add(edge);
                added |= solve.constraints.len > before;
            }
        }
        added
    }

    /// The index pairs of the support points at the solved direction, each
    /// kink's partners included, at most three.
    fn seed_at(&self, solve: &Solve) -> Option<([[u32; 2]; 3], usize)> {
        let u = solve.u;
        let a = self.seed_indices(self.a, &u, &solve.kinks[0]);
        let b = self.seed_indices(self.b, &-rotate_back(&self.rotation, &u), &solve.kinks[1]);
        let mut pairs = [[0; 2]; 3];
        let mut len = 0;
        for &ib in &b.0[..b.1] {
            for &ia in &a.0[..a.1] {
                if len < 3 {
                    pairs[len] = [ia, ib];
                    len += 1;
                }
            }
        }
        (len > 0).then_some((pairs, len))
    }

    /// The indices of `shape`'s support at body direction `d`: its code or
    /// vertex, then a cylinder's other cap at the same angle or a polytope's
    /// other kink vertices.
    fn seed_indices(&self, shape: &Convex, d: &Vector3<f64>, kinks: &Kinks) -> ([u32; 3], usize) {
        let mut out = ([0; 3], 1);
        if shape.cylinder_dimensions().is_some() {
            out.0[0] = cylinder::support_code(d);
            if kinks.len > 0 {
                out.0[1] = cylinder::other_cap(out.0[0]);
                out.1 = 2;
            }
            return out;
        }
        out.0[0] = shape.support_point(d).0 as u32;
        for &key in &kinks.keys[..kinks.len] {
            if key != out.0[0] && out.1 < 3 {
                out.0[out.1] = key;
                out.1 += 1;
            }
        }
        out
    }

    /// The seed's points as simplex vertices.
    pub(super) fn seed_vertices(&self, pairs: &[[u32; 2]]) -> ([Vertex; 4], usize) {
        let mut points = [Vertex::default(); 4];
        for (point, &[ia, ib]) in points.iter_mut().zip(pairs) {
            *point = self.difference_vertex(ia as usize, ib as usize);
        }
        (points, pairs.len().min(4))
    }
}

/// The Newton step at `solve.u` for the supports `touches`: the tangent
/// vector `ξ` with `(P·H·P + F)·ξ = -P·y`, `y = a - b`, `F = -u·y > 0`, `P`
/// the projection on the directions perpendicular to `u` and to the
/// constraints. `None` where the projections overlap (`F <= 0`).
#[inline(always)]
fn newton_step(solve: &Solve, touches: &[Touch; 2]) -> Option<Vector3<f64>> {
    let u = solve.u;
    let y = touches[0].point - touches[1].point;
    let f = -u.dot(&y);
    if !(f > 0.0 && f.is_finite()) {
        return None;
    }
    let hessian = |e: &Vector3<f64>, g: &Vector3<f64>| {
        touches
            .iter()
            .map(|t| t.curvature * t.tangent.dot(e) * t.tangent.dot(g))
            .sum::<f64>()
    };
    match solve.constraints.len {
        0 => {
            let e1 = perpendicular(&u);
            let e2 = u.cross(&e1);
            let (m11, m12, m22) = (
                hessian(&e1, &e1) + f,
                hessian(&e1, &e2),
                hessian(&e2, &e2) + f,
            );
            let (r1, r2) = (-e1.dot(&y), -e2.dot(&y));
            let det = m11 * m22 - m12 * m12;
            let (x1, x2) = ((r1 * m22 - r2 * m12) / det, (m11 * r2 - m12 * r1) / det);
            Some(e1 * x1 + e2 * x2)
        }
        1 => {
            let e = u.cross(&solve.constraints.axes[0]);
            Some(e * (-e.dot(&y) / (hessian(&e, &e) + f)))
        }
        _ => Some(Vector3::zeros()),
    }
    .map(|step: Vector3<f64>| {
        // Far from the answer the quadratic model is poor: no step turns
        // the direction by more than about half a radian.
        let length = step.norm();
        if length > 0.5 { step * (0.5 / length) } else { step }
    })
}

/// A unit vector perpendicular to the unit `u`.
#[inline(always)]
fn perpendicular(u: &Vector3<f64>) -> Vector3<f64> {
    let p = if u.x.abs() < 0.6 {
        Vector3::new(0.0, -u.z, u.y)
    } else {
        Vector3::new(-u.z, 0.0, u.x)
    };
    p / p.norm()
}
