//! The arithmetic of one Newton step and of the seed's features: the
//! step on the sphere of directions, its halving towards an axis, the stop
//! at a cylinder's side, and the weights of the seed's points.

use nalgebra::Vector3;

use super::kinks::{Constraints, Kinks, Solve, Touch, cylinder_of};
use crate::johnson::{Vertex, triangle_weights};
use crate::shape::cylinder;
use crate::support_map::SupportMap;

/// The sine of the angle to a cylinder's axis below which a direction is
/// tried against its cap (see [`super::cap`]): Newton's steps close in on a
/// cap's answer without reaching it.
pub(super) const CAP_NEAR: f64 = 0.25;

/// The sum of `shape`'s points named by the pairs (`k`: 0 for A's
/// index, 1 for B's), a point repeated from the pair before, or its other
/// cap's, not decoded again; and the first of them.
#[inline(always)]
pub(super) fn point_sum<S: SupportMap + ?Sized>(
    shape: &S,
    pairs: &[[u32; 2]],
    k: usize,
) -> (Vector3<f64>, Vector3<f64>) {
    let cylinder = cylinder_of(shape).is_some();
    let mut sum = Vector3::zeros();
    let mut first = None;
    let mut last: Option<(u32, Vector3<f64>)> = None;
    for pair in pairs {
        let index = pair[k];
        let point = match last {
            Some((seen, point)) if seen == index => point,
            Some((seen, point)) if cylinder && seen == cylinder::other_cap(index) => {
                Vector3::new(point.x, point.y, -point.z)
            }
            _ => shape.local_point(index as usize),
        };
        last = Some((index, point));
        first.get_or_insert(point);
        sum += point;
    }
    (sum, first.unwrap_or_default())
}

/// Whether the point `y` of `K`, with `F = -u·y` at the unit `u`, is within
/// `stop_d` of the distance (see [`ConvexPair::certify`]), the shapes apart
/// by more than `slack`.
#[inline(always)]
pub(super) fn certifies(
    u: &Vector3<f64>,
    y: &Vector3<f64>,
    f: f64,
    slack: f64,
    stop_d: f64,
) -> bool {
    let across = y + u * f;
    f > slack && across.norm_squared() <= 2.0 * f * stop_d
}

/// The seed triangle `points` (normal `u`, unit) turned to hold the
/// origin's projection on its plane: when the projection lies past one of
/// its edges, the corner opposite that edge is replaced by
/// `corner(opposite, away)` (`away` the unit direction across the edge,
/// in the plane), if the new triangle holds the projection. When `corner`
/// gives none, the edge's corners and `away`: nothing lies past that edge.
/// When the new triangle lies past another of its own edges, that edge's
/// corners and the direction across it: the projection is past both
/// halves of a face, off the face. Otherwise the seed stays as it is (the
/// run certifies from any start).
pub(super) fn turn_triangle(
    points: &mut [Vertex; 3],
    u: &Vector3<f64>,
    corner: impl FnOnce(usize, Vector3<f64>) -> Option<Vertex>,
) -> Option<(Vertex, Vertex, Vector3<f64>)> {
    let projection = u * u.dot(&points[0].y);
    let weights = triangle_weights(points.map(|p| p.y), &projection)?;
    let (k, least) = least_weight(&weights);
    if least >= -HOLDS_SLACK {
        return None;
    }
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let away = away_across(points, u, k)?;
    let Some(corner) = corner(k, away) else {
        return Some((points[i], points[j], away));
    };
    let mut turned = *points;
    turned[k] = corner;
    let weights = triangle_weights(turned.map(|p| p.y), &projection)?;
    let (m, least) = least_weight(&weights);
    if least >= -HOLDS_SLACK {
        *points = turned;
        return None;
    }
    // Past the new corner's weight is back across the edge the turn
    // crossed: not a face's outer edge.
    if m == k {
        return None;
    }
    let away = away_across(&turned, u, m)?;
    Some((turned[(m + 1) % 3], turned[(m + 2) % 3], away))
}

/// The least of a triangle's three weights, and its corner.
pub(super) fn least_weight(weights: &[f64; 3]) -> (usize, f64) {
    let (k, &least) = weights
        .iter()
        .enumerate()
        .min_by(|x, y| x.1.total_cmp(y.1))
        .expect("three weights");
    (k, least)
}

/// The unit direction in the plane across `u` (unit) from triangle
/// `points`' corner `k` across the edge opposite it, outwards; `None` for
/// a degenerate edge.
pub(super) fn away_across(
    points: &[Vertex; 3],
    u: &Vector3<f64>,
    k: usize,
) -> Option<Vector3<f64>> {
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let edge = points[j].y - points[i].y;
    let out = points[i].y - points[k].y;
    let away = out - edge * (edge.dot(&out) / edge.norm_squared());
    let away = away - u * u.dot(&away);
    let norm = away.norm();
    (norm > 0.0 && norm.is_finite()).then(|| away / norm)
}

/// How far outside a seed face's triangle its point's projection may lie,
/// in weights, and still count as held: round-off, not a wrong half.
pub(super) const HOLDS_SLACK: f64 = 1e-9;

/// A shape's support point `support` (index and body point) and the
/// partners of its held kinks: a cylinder's other cap at the same angle,
/// a polytope's other kink vertices. At most three.
#[inline(always)]
pub(super) fn seed_features<S: SupportMap + ?Sized>(
    shape: &S,
    support: (usize, Vector3<f64>),
    kinks: &Kinks,
    side: bool,
) -> ([(usize, Vector3<f64>); 3], usize) {
    let mut out = ([support; 3], 1);
    if cylinder_of(shape).is_some() {
        if side {
            let (code, point) = support;
            let other = cylinder::other_cap(code as u32) as usize;
            out.0[1] = (other, Vector3::new(point.x, point.y, -point.z));
            out.1 = 2;
        }
        return out;
    }
    for &key in &kinks.keys[..kinks.len] {
        if key as usize != support.0 && out.1 < 3 {
            out.0[out.1] = (key as usize, shape.local_point(key as usize));
            out.1 += 1;
        }
    }
    out
}

/// The Newton step at `solve.u` for the supports `touches`: the tangent
/// vector `ξ` with `(P·H·P + F)·ξ = -P·y`, `y = a - b`, `F = -u·y > 0`, `P`
/// the projection on the directions perpendicular to `u` and to the
/// constraints. `None` where the projections overlap (`F <= 0`).
#[inline(always)]
pub(super) fn newton_step(
    u: &Vector3<f64>,
    constraints: &Constraints,
    touches: &[Touch; 2],
) -> Option<Vector3<f64>> {
    let u = *u;
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
    match constraints.len {
        0 => Some(free_step(&u, &y, f, touches)),
        1 => {
            let e = u.cross(&constraints.axes[0]);
            Some(e * (-e.dot(&y) / (hessian(&e, &e) + f)))
        }
        _ => Some(Vector3::zeros()),
    }
    .map(|step: Vector3<f64>| {
        let step = toward_axes_by_half(step, touches);
        // Far from the answer the quadratic model is poor: no step turns
        // the direction by more than about half a radian.
        let squared = step.norm_squared();
        if squared > 0.25 {
            step * (0.5 / squared.sqrt())
        } else {
            step
        }
    })
}

/// `step` with its part towards each cylinder's axis cut to half the
/// direction's angle to it: near an axis the rim's curvature (`r / rho`)
/// changes faster than the quadratic model knows, and a full step would
/// cross the axis; the part along the rim is kept, so the rim point still
/// turns to the answer's.
#[inline(always)]
pub(super) fn toward_axes_by_half(mut step: Vector3<f64>, touches: &[Touch; 2]) -> Vector3<f64> {
    for (k, touch) in touches.iter().enumerate() {
        if touch.rho >= CAP_NEAR {
            continue;
        }
        // The direction in which the angle to the axis grows: A's support
        // direction is `u`, B's `-u`.
        let outward = touch.tangent.cross(&touch.axis);
        let outward = if k == 0 { outward } else { -outward };
        let along = step.dot(&outward);
        let floor = -0.5 * touch.rho;
        if along < floor {
            step += outward * (floor - along);
        }
    }
    step
}

/// The unconstrained step: `(F + Σ k_i·p_i·p_iᵀ)·ξ = g`, `g = -P·y`,
/// `p_i = P·t_i`, by the Woodbury identity: a 2×2 solve for `α_i = p_i·ξ`,
/// then `ξ = (g - Σ k_i·α_i·p_i) / F`. No basis of the tangent plane, so
/// no square root.
#[inline(always)]
pub(super) fn free_step(
    u: &Vector3<f64>,
    y: &Vector3<f64>,
    f: f64,
    touches: &[Touch; 2],
) -> Vector3<f64> {
    let flat = |x: &Vector3<f64>| x - u * u.dot(x);
    let g = -flat(y);
    let (p1, p2) = (flat(&touches[0].tangent), flat(&touches[1].tangent));
    let (k1, k2) = (touches[0].curvature, touches[1].curvature);
    let (p11, p12, p22) = (p1.dot(&p1), p1.dot(&p2), p2.dot(&p2));
    let (m11, m12, m21, m22) = (f + k1 * p11, k2 * p12, k1 * p12, f + k2 * p22);
    let (r1, r2) = (p1.dot(&g), p2.dot(&g));
    let det = m11 * m22 - m12 * m21;
    let (a1, a2) = ((r1 * m22 - m12 * r2) / det, (m11 * r2 - m21 * r1) / det);
    (g - p1 * (k1 * a1) - p2 * (k2 * a2)) / f
}

/// Cuts `step` where it would first cross a cylinder's side kink (the
/// direction perpendicular to its axis, where its support changes cap) and
/// holds the direction there: Newton's quadratic model knows nothing of the
/// kink and would overshoot it. Whether it did.
pub(super) fn stop_at_side(
    solve: &mut Solve,
    touches: &[Touch; 2],
    step: &mut Vector3<f64>,
) -> bool {
    let mut first: Option<(f64, usize)> = None;
    for (k, touch) in touches.iter().enumerate() {
        if touch.axis == Vector3::zeros() || solve.side[k] || solve.off_side[k] {
            continue;
        }
        let (now, change) = (touch.axis.dot(&solve.u), touch.axis.dot(step));
        if now * (now + change) >= 0.0 {
            continue;
        }
        let at = -now / change;
        if at > 0.0 && at < 1.0 && first.is_none_or(|(best, _)| at < best) {
            first = Some((at, k));
        }
    }
    let Some((at, k)) = first else {
        return false;
    };
    *step *= at;
    solve.side[k] = true;
    true
}

/// A cylinder's support point and its other cap's (`seed_features`), the
/// one on the cap named by `top` first.
pub(super) fn cap_pair(
    features: &[(usize, Vector3<f64>); 3],
    top: bool,
) -> [(usize, Vector3<f64>); 2] {
    let [this, other, _] = *features;
    if cylinder::is_top(this.0 as u32) == top {
        [this, other]
    } else {
        [other, this]
    }
}

/// The weights `α` with `y + Σ α_j·span_j = 0` (least squares), for one
/// or two spans; `None` when they are degenerate.
pub(super) fn span_weights(y: &Vector3<f64>, spans: &[(usize, Vector3<f64>)]) -> Option<[f64; 2]> {
    match spans {
        [(_, d)] => {
            let dd = d.norm_squared();
            (dd > 0.0).then(|| [-y.dot(d) / dd, 0.0])
        }
        [(_, d1), (_, d2)] => {
            let (m11, m12, m22) = (d1.norm_squared(), d1.dot(d2), d2.norm_squared());
            let det = m11 * m22 - m12 * m12;
            let (r1, r2) = (-y.dot(d1), -y.dot(d2));
            (det > 1e-12 * m11 * m22)
                .then(|| [(r1 * m22 - r2 * m12) / det, (m11 * r2 - m12 * r1) / det])
        }
        _ => None,
    }
}
