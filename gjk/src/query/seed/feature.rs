//! The seed's solve on the features a warm start names: Newton's method
//! in closed form.
//!
//! Where the features of a pair's answer are known (a cylinder's rim on
//! one cap or its side, a polytope's vertex or edge), the separation on a
//! unit direction `u` (see `seed`) is a closed form. A rim of radius
//! `r` about the unit axis `a` (pair frame) contributes `-r·√(1 - (a·u)²)`
//! and its cap `∓h·(a·u)`; a polytope's vertex `p`, `±u·p`; a held side
//! its radius, a constant, on the circle of directions across its axis;
//! the centroids' gap `u·c`. So
//! `F(u) = u·m - Σ rᵢ·√(1 - (aᵢ·u)²)`, with one or two rims, and `m` the sum
//! of the linear terms. Its maximum is found by Newton's method on these
//! terms alone: on the sphere where no kink is held (two rims, or a rim
//! and a vertex), on the circle across the held axis where one is (a side
//! or an edge, with at most one rim; with none the maximum is
//! `atan2(Q, P)`, no step at all). Two rims whose direction is near
//! either's axis are solved on the rims' angles instead, the nearest
//! points of two circles. The general steps compute both
//! shapes' supports, curvatures, kinks and constraints at every step; these
//! compute a few dot products.
//!
//! The features are the warm start's guess. The supports at the solved
//! direction must name the same ones (the polytope's vertex, or one of the
//! held edge's; the rim's cap); otherwise the general
//! steps start over, from the warm start as before, and only the closed
//! form's time is lost. The run certifies whatever seed follows.

use nalgebra::Vector3;

use super::kinks::{Kinks, Solve};
use crate::query::pair::ConvexPair;
use crate::shape::cylinder;
use crate::support_map::SupportMap;

/// What a warm start names as one shape's part of the answer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Feature {
    /// A cylinder's side: both caps at one angle.
    Side,
    /// A cylinder's rim point on the top cap (`true`) or the bottom.
    Rim(bool),
    /// One vertex of a polytope.
    Vertex(u32),
    /// An edge of a polytope, its vertices held as the shape's kinks.
    Edge,
    /// A face of a polytope, three of its vertices held as the shape's
    /// kinks: the direction is the held one.
    Face,
    /// Anything else (a cap's points, a polytope's points on no one edge
    /// or face): no closed form.
    Other,
}

/// The sine of the angle to a rim's axis below which the closed form on
/// the sphere of directions is not tried: nearer, the rim's curvature
/// `r / sin` outgrows the steps' model (two rims are then solved on their
/// angles, see `rim_pair_newton`, and a cap may hold the answer, see
/// `seed::cap`).
const RIM_FLOOR: f64 = 0.05;

/// Newton steps before the closed form is given up: from a warm start a
/// step's error squares, so three or four reach f64's precision.
const FEATURE_STEPS: u32 = 8;

/// The Newton step (radians) below which a Chebyshev step has converged:
/// its error, of the cube's order, is then below the run's need, as
/// Newton's is below the general steps' converged step. It shrinks with
/// a rim's sine to its axis below [`CUBIC_FULL_SINE`] (see
/// `cubic_converged`).
const CUBIC_CONVERGED: f64 = 2e-3;

/// The sine of a direction's angle to a rim's axis below which the
/// converged step shrinks in proportion: the rim point turns by the
/// direction's turn over the sine, and the step's error grows with the
/// rim's curvature `r / sine` and its derivatives.
const CUBIC_FULL_SINE: f64 = 0.5;

/// [`CUBIC_CONVERGED`] at the smallest sine `sine` of the direction to a
/// rim's axis.
#[inline(always)]
fn cubic_converged(sine: f64) -> f64 {
    CUBIC_CONVERGED * (sine / CUBIC_FULL_SINE).min(1.0)
}

/// The largest step (radians) the closed form takes: a larger one means
/// the warm start's features no longer hold the answer.
const LARGEST_STEP: f64 = 0.5;

/// A rim's axis (unit, pair frame) and radius (scaled).
type Rim = (Vector3<f64>, f64);

impl<A: SupportMap, B: SupportMap> ConvexPair<'_, A, B> {
    /// The direction that maximises the separation of the supports the
    /// warm start's `features` name, from `solve.u`: on the sphere when
    /// `solve` holds no kink, on the circle across its one held axis when
    /// it holds one; `None` where the features give no closed form or its
    /// steps do not converge.
    pub(super) fn feature_optimum(
        &self,
        solve: &Solve,
        features: [Feature; 2],
    ) -> Option<Vector3<f64>> {
        // Two kinks fix the direction.
        if solve.held.len == 2 {
            return (!features.contains(&Feature::Other)).then_some(solve.u);
        }
        // F(u) = -u·a + u·b: A's linear terms subtract, B's add, B's in
        // the pair frame.
        let mut linear = self.centroid_gap;
        let mut rims: [Rim; 2] = [(Vector3::zeros(), 0.0); 2];
        let mut rim_count = 0;
        let axes = self.axes();
        for (k, feature) in features.into_iter().enumerate() {
            let sign = if k == 0 { -self.scale } else { self.scale };
            match feature {
                Feature::Side => {}
                Feature::Edge => {
                    let kinks = &solve.kinks[k];
                    if kinks.len != 2 {
                        return None;
                    }
                    linear +=
                        self.in_pair_frame(k, self.point_at(k, kinks.keys[0] as usize)) * sign;
                }
                Feature::Vertex(index) => {
                    linear += self.in_pair_frame(k, self.point_at(k, index as usize)) * sign;
                }
                Feature::Rim(top) => {
                    let (r, h) = self.cylinder_at(k)?;
                    let axis = axes[k];
                    let cap = if top { h } else { -h };
                    linear += axis * (cap * sign);
                    rims[rim_count] = (axis, r * self.scale);
                    rim_count += 1;
                }
                Feature::Face | Feature::Other => return None,
            }
        }
        let rims = &rims[..rim_count];
        match (solve.held.len, rims) {
            // One rim: the maximum lies in the plane of its axis and `m`
            // (there the gradient `m - r·n` is along `u`), a line.
            (0, [rim]) => {
                let normal = rim.0.cross(&linear);
                let e1 = solve.u - normal * (normal.dot(&solve.u) / normal.norm_squared());
                let e1 = e1 / e1.norm();
                let e2 = normal.cross(&e1) / normal.norm();
                circle_optimum(e1, e2, &linear, Some(rim))
            }
            // Near a rim's axis the sphere's chart fails (see
            // `rim_pair_newton`).
            (0, [a, b]) => sphere_newton(solve.u, &linear, rims)
                .or_else(|| rim_pair_newton(solve.rim_radials, &linear, a, b)),
            (1, [] | [_]) => {
                let e1 = solve.u;
                let e2 = solve.held.axes[0].cross(&e1);
                circle_optimum(e1, e2, &linear, rims.first())
            }
            _ => None,
        }
    }
}

/// The direction `cos θ·e₁ + sin θ·e₂` (orthonormal, `e₁` the start) that
/// maximises `F` on that circle: `u·m`, less the `rim`'s term if there is
/// one (see [`line_newton`]); with none, `m`'s own direction in the plane,
/// `atan2(Q, P)`, if it is less than a quarter turn from `e₁`.
#[inline(always)]
fn circle_optimum(
    e1: Vector3<f64>,
    e2: Vector3<f64>,
    m: &Vector3<f64>,
    rim: Option<&Rim>,
) -> Option<Vector3<f64>> {
    let (p, q) = (m.dot(&e1), m.dot(&e2));
    let (cos, sin) = match rim {
        Some((axis, r)) => line_newton(p, q, axis.dot(&e1), axis.dot(&e2), *r)?,
        None => {
            let norm = p.hypot(q);
            if !(p > 0.0 && norm.is_finite()) {
                return None;
            }
            (p / norm, q / norm)
        }
    };
    Some(e1 * cos + e2 * sin)
}

/// The maximum of `F(θ) = P·cos θ + Q·sin θ - r·√(1 - g²)`,
/// `g = g₁·cos θ + g₂·sin θ`, by Chebyshev's method (Newton's with the
/// third derivative, whose error cubes where Newton's squares) from
/// `θ = 0`, as `(cos θ, sin θ)`; `None` where it is not concave (the
/// features are wrong), a step is too large, the direction comes near the
/// rim's axis or the steps do not converge.
///
/// With `g' = g₂·cos θ - g₁·sin θ`, `S = √(1 - g²)` and `L` the linear
/// part (`L''' = -L'`, `L'' = -L`):
/// `F' = L' + r·g·g'/S`,
/// `F'' = -L + r·((g'² - g²) + g²·g'²/S²)/S`,
/// `F''' = -L' - r·(4·g·g'/S - 3·g·g'·(g'² - g²)/S³ - 3·g³·g'³/S⁵)`.
/// The step is `N - F'''·N²/(2·F'')`, `N = -F'/F''` Newton's.
#[inline(always)]
fn line_newton(p: f64, q: f64, g1: f64, g2: f64, r: f64) -> Option<(f64, f64)> {
    let (mut cos, mut sin) = (1.0f64, 0.0f64);
    for _ in 0..FEATURE_STEPS {
        let g = g1 * cos + g2 * sin;
        let turn = g2 * cos - g1 * sin;
        let across = 1.0 - g * g;
        if across.is_nan() || across < RIM_FLOOR * RIM_FLOOR {
            return None;
        }
        let inv = 1.0 / across;
        let root = across.sqrt();
        let inv_root = root * inv;
        let (gt, spread) = (g * turn, turn * turn - g * g);
        let linear_slope = q * cos - p * sin;
        let slope = linear_slope + r * gt * inv_root;
        let bend = -(p * cos + q * sin) + r * (spread + gt * gt * inv) * inv_root;
        let third = -linear_slope
            - r * gt * inv_root * (4.0 - inv * (3.0 * spread + 3.0 * g * g * turn * turn * inv));
        if bend.is_nan() || bend >= 0.0 {
            return None;
        }
        let inv_bend = 1.0 / bend;
        let newton = -slope * inv_bend;
        let step = newton - 0.5 * third * newton * newton * inv_bend;
        if step.is_nan() || step.abs() > LARGEST_STEP {
            return None;
        }
        let (along, k) = turn_by(step);
        (cos, sin) = ((cos - sin * along) * k, (sin + cos * along) * k);
        if newton.abs() < cubic_converged(root) {
            return Some((cos, sin));
        }
    }
    None
}

/// The nearest points of two rims, `a` (A's, centre `0`) and `b` (B's,
/// centre `m`, the sum of the linear terms), by Newton's method on the
/// angles of their points from the radial directions `starts` (pair
/// frame, any length: the warm start's points'), as the direction between
/// them; `None` where the squared distance is not convex there, a step is
/// too large, a start is zero or the steps do not converge.
///
/// It serves where a rim's sine to its axis is below [`RIM_FLOOR`]: there
/// the rim point turns by the direction's turn over the sine, and on the
/// sphere of directions `F`'s curvature `r / sine` outgrows the steps'
/// model, while on the rims' angles nothing is near a singularity. Nor is
/// the direction a start: near an axis its small part across the axis,
/// which names the rim point, is the part the warm start's guess gets
/// wrong. With `D = m + r_b·n_b - r_a·n_a` (`n` a rim's unit radial
/// direction, `t = axis × n` its tangent, both turning with the angle),
/// the gradient of `|D|²/2` is `(-r_a·D·t_a, r_b·D·t_b)` and its Hessian
/// `[[r_a² + r_a·D·n_a, -r_a·r_b·t_a·t_b], [·, r_b² - r_b·D·n_b]]`.
fn rim_pair_newton(
    starts: [Vector3<f64>; 2],
    m: &Vector3<f64>,
    a: &Rim,
    b: &Rim,
) -> Option<Vector3<f64>> {
    let (&(axis_a, r_a), &(axis_b, r_b)) = (a, b);
    let unit = |x: Vector3<f64>| {
        let norm = x.norm();
        (norm > 0.0 && norm.is_finite()).then(|| x / norm)
    };
    let (mut n_a, mut n_b) = (unit(starts[0])?, unit(starts[1])?);
    for _ in 0..FEATURE_STEPS {
        let (t_a, t_b) = (axis_a.cross(&n_a), axis_b.cross(&n_b));
        let d = m + n_b * r_b - n_a * r_a;
        let (g_a, g_b) = (-r_a * d.dot(&t_a), r_b * d.dot(&t_b));
        let h_aa = r_a * r_a + r_a * d.dot(&n_a);
        let h_bb = r_b * r_b - r_b * d.dot(&n_b);
        let h_ab = -r_a * r_b * t_a.dot(&t_b);
        let det = h_aa * h_bb - h_ab * h_ab;
        if !(h_aa > 0.0 && det > 0.0) {
            return None;
        }
        let inv_det = 1.0 / det;
        let step_a = (h_ab * g_b - h_bb * g_a) * inv_det;
        let step_b = (h_ab * g_a - h_aa * g_b) * inv_det;
        let largest = step_a.abs().max(step_b.abs());
        if largest.is_nan() || largest > LARGEST_STEP {
            return None;
        }
        let turn = |n: Vector3<f64>, t: Vector3<f64>, step: f64| {
            let (along, k) = turn_by(step);
            (n + t * along) * k
        };
        (n_a, n_b) = (turn(n_a, t_a, step_a), turn(n_b, t_b, step_b));
        // Newton's error squares: the next is far below the run's need.
        if largest < ANGLE_CONVERGED {
            return unit(m + n_b * r_b - n_a * r_a);
        }
    }
    None
}

/// The step (radians) on the rims' angles below which
/// [`rim_pair_newton`] has converged: the next, of its square's order, is
/// below the quantisation of a cylinder's support codes.
const ANGLE_CONVERGED: f64 = 1e-6;

/// The turn of a unit vector `n` by `step` radians towards its unit
/// tangent `t`: `(along, k)` with `(n + t·along)·k` the turned vector,
/// `along` being `tan(step)` to the cube's order and `k` the scale back
/// onto the circle.
#[inline(always)]
fn turn_by(step: f64) -> (f64, f64) {
    let along = step * (1.0 + step * step * (1.0 / 3.0));
    (along, inverse_hypot_one(along * along))
}

/// `1 / √(1 + x2)`, the length's inverse of a unit vector plus a step of
/// squared length `x2` across it: for a small step (a warm start's) by
/// its series, exact to f64's precision, which spares a square root and a
/// division on the steps' critical path.
#[inline(always)]
fn inverse_hypot_one(x2: f64) -> f64 {
    if x2 < 1e-4 {
        // 1 - x²/2 + 3x⁴/8 - 5x⁶/16 + 35x⁸/128: the next term, 63x¹⁰/256,
        // is below 2.5e-21 here.
        1.0 - x2 * (0.5 - x2 * (0.375 - x2 * (0.3125 - x2 * 0.2734375)))
    } else {
        1.0 / (1.0 + x2).sqrt()
    }
}

/// The maximum of `F(u) = u·m - Σ rᵢ·√(1 - (aᵢ·u)²)` on the unit sphere
/// (one or two rims), by Chebyshev's method from the unit `u`.
///
/// The steps are taken in the plane tangent at `u`: `ξ` there is the
/// direction `(u + ξ)/√(1 + |ξ|²)`, where `F` is
/// `Ψ(ξ) = G(u + ξ)/√(1 + |ξ|²)`, `G(x) = x·m - Σ rᵢ·|Pᵢ·x|` its
/// 1-homogeneous extension (`Pᵢ` the projection across the axis). With
/// `nᵢ` the rim's unit radial direction at `u`, `tᵢ = aᵢ × nᵢ` its tangent
/// (across `u` already), `Sᵢ = √(1 - (aᵢ·u)²)` and `kᵢ = rᵢ/Sᵢ`:
/// - the gradient is `g = ∇G - F·u`, `∇G = m - Σ rᵢ·nᵢ`;
/// - the Hessian is `-(F + Σ kᵢ·tᵢ·tᵢᵀ)`, and Newton's step `N` solves
///   `(F + Σ kᵢ·tᵢ·tᵢᵀ)·N = g` by the Woodbury identity, as the general
///   step does;
/// - the cubic terms' gradient at `N` is
///   `C = ½·T[N, N] - (g·N)·N - ½·|N|²·g`, the last two from the
///   chart's `1/√(1 + |ξ|²)`, and
///   `T[w, w] = Σ (rᵢ/Sᵢ²)·((tᵢ·w)²·nᵢ + 2·(nᵢ·w)·(tᵢ·w)·tᵢ)`, the second
///   derivative of `-rᵢ·nᵢ(x)` along `w`, taken across `u`.
///
/// Chebyshev's step is `N + (F + Σ kᵢ·tᵢ·tᵢᵀ)⁻¹·C`: the same system, no
/// square root or division more, and an error of `N³`'s order, where
/// Newton's is of `N²`'s. `None` where the separation is not positive, a
/// step is too large, the direction comes near a rim's axis or the steps
/// do not converge.
#[inline(always)]
fn sphere_newton(mut u: Vector3<f64>, m: &Vector3<f64>, rims: &[Rim]) -> Option<Vector3<f64>> {
    for _ in 0..FEATURE_STEPS {
        let mut grad = *m;
        let mut radials = [Vector3::zeros(); 2];
        let mut tangents = [Vector3::zeros(); 2];
        let mut curvatures = [0.0; 2];
        let mut inverses = [0.0; 2];
        for (i, (axis, r)) in rims.iter().enumerate() {
            let along = axis.dot(&u);
            let across = 1.0 - along * along;
            if across.is_nan() || across < RIM_FLOOR * RIM_FLOOR {
                return None;
            }
            // A square root and a division side by side, not one after
            // the other.
            let inv = across.sqrt() * (1.0 / across);
            let radial = (u - axis * along) * inv;
            grad -= radial * *r;
            radials[i] = radial;
            tangents[i] = axis.cross(&radial);
            curvatures[i] = r * inv;
            inverses[i] = inv;
        }
        let f = u.dot(&grad);
        if !(f > 0.0 && f.is_finite()) {
            return None;
        }
        let g = grad - u * f;
        let [t1, t2] = tangents;
        let [k1, k2] = curvatures;
        let (p11, p12, p22) = (t1.dot(&t1), t1.dot(&t2), t2.dot(&t2));
        let (m11, m12, m21, m22) = (f + k1 * p11, k2 * p12, k1 * p12, f + k2 * p22);
        let inv_f = 1.0 / f;
        let inv_det = 1.0 / (m11 * m22 - m12 * m21);
        let solve = |rhs: &Vector3<f64>| {
            let (r1, r2) = (t1.dot(rhs), t2.dot(rhs));
            let (a1, a2) = (
                (r1 * m22 - m12 * r2) * inv_det,
                (m11 * r2 - m21 * r1) * inv_det,
            );
            (rhs - t1 * (k1 * a1) - t2 * (k2 * a2)) * inv_f
        };
        let newton = solve(&g);
        let squared = newton.norm_squared();
        if squared.is_nan() || squared > LARGEST_STEP * LARGEST_STEP {
            return None;
        }
        let mut cubic = newton * -g.dot(&newton) - g * (0.5 * squared);
        for (i, (_, r)) in rims.iter().enumerate() {
            let (t, n) = (tangents[i], radials[i]);
            let (tw, nw) = (t.dot(&newton), n.dot(&newton));
            let weight = 0.5 * r * inverses[i] * inverses[i];
            let across_n = n - u * u.dot(&n);
            cubic += (across_n * (tw * tw) + t * (2.0 * nw * tw)) * weight;
        }
        let step = newton + solve(&cubic);
        // `step` is across `u`: the sum's length is `√(1 + |step|²)`.
        u = (u + step) * inverse_hypot_one(step.norm_squared());
        let converged = cubic_converged(1.0 / inverses[0].max(inverses[1]));
        if squared < converged * converged {
            return Some(u);
        }
    }
    None
}

impl<A: SupportMap, B: SupportMap> ConvexPair<'_, A, B> {
    /// Whether the supports at the solved direction name the features the
    /// closed form assumed: each shape's support index (a cylinder's code)
    /// and the unit body direction it was taken at, against its feature:
    /// the vertex, one of the held edge's, a vertex of the held face (its
    /// fourth ties with the three held, and round-off picks among them),
    /// the rim's cap. A rim's support near its axis is still its rim's
    /// point, and where a cap holds the answer instead the supports do not
    /// certify: the run goes on from them.
    pub(super) fn features_hold(
        &self,
        kinks: &[Kinks; 2],
        supports: [(usize, Vector3<f64>); 2],
        features: [Feature; 2],
    ) -> bool {
        supports
            .into_iter()
            .zip(features)
            .zip(kinks)
            .enumerate()
            .all(|(k, (((index, d), feature), kinks))| {
                let key = index as u32;
                match feature {
                    Feature::Side => true,
                    Feature::Edge => kinks.has(key),
                    Feature::Face => {
                        kinks.has(key) || {
                            let rise =
                                self.point_at(k, index) - self.point_at(k, kinks.keys[0] as usize);
                            d.dot(&rise).abs() <= FACE_TIE * rise.norm()
                        }
                    }
                    Feature::Vertex(vertex) => key == vertex,
                    Feature::Rim(top) => cylinder::is_top(key) == top,
                    Feature::Other => false,
                }
            })
    }
}

/// How far (in radians) from perpendicular to a held face's direction a
/// vertex's offset from the face may be and the vertex still count as the
/// face's: round-off of the held direction, far below any other face's
/// angle.
const FACE_TIE: f64 = 1e-9;

#[cfg(test)]
mod tests {
    use nalgebra::Vector3;

    use super::{RIM_FLOOR, inverse_hypot_one, line_newton, rim_pair_newton, sphere_newton};

    /// The series agrees with the closed form to an ulp or two on both
    /// sides of its switch.
    #[test]
    fn inverse_hypot_one_matches_the_closed_form() {
        for x in [
            0.0f64, 1e-9, -3e-5, 1e-3, 4e-3, -9.99e-3, 1.001e-2, 0.3, -0.5,
        ] {
            let exact = 1.0 / (1.0 + x * x).sqrt();
            assert!(
                (inverse_hypot_one(x * x) - exact).abs() <= 2.0 * f64::EPSILON,
                "{x}"
            );
        }
    }

    /// The line's maximum against a fine scan of the same `F`, and its
    /// derivative there.
    #[test]
    fn line_newton_finds_the_scanned_maximum() {
        let f = |p: f64, q: f64, g1: f64, g2: f64, r: f64, t: f64| {
            let g = g1 * t.cos() + g2 * t.sin();
            p * t.cos() + q * t.sin() - r * (1.0 - g * g).sqrt()
        };
        for (p, q, g1, g2, r) in [
            (1.5, 0.01, 0.3, 0.2, 0.5),
            (2.0, -0.02, -0.6, 0.1, 0.3),
            (1.0, 0.002, 0.0, 0.5, 0.8),
        ] {
            let (cos, sin) = line_newton(p, q, g1, g2, r).expect("converges");
            let best = sin.atan2(cos);
            let scanned = (-20_000..=20_000)
                .map(|k| f64::from(k) * 1e-5)
                .max_by(|x, y| f(p, q, g1, g2, r, *x).total_cmp(&f(p, q, g1, g2, r, *y)))
                .unwrap();
            assert!((best - scanned).abs() < 2e-5, "{best} vs {scanned}");
            let h = 1e-6;
            let slope = (f(p, q, g1, g2, r, best + h) - f(p, q, g1, g2, r, best - h)) / (2.0 * h);
            assert!(slope.abs() < 1e-8, "{slope}");
            assert!((cos.hypot(sin) - 1.0).abs() < 1e-15);
        }
    }

    /// The sphere's maximum is stationary: no small turn of the solved
    /// direction raises `F`, for one rim and for two.
    #[test]
    fn sphere_newton_finds_a_stationary_maximum() {
        let f = |u: &Vector3<f64>, m: &Vector3<f64>, rims: &[(Vector3<f64>, f64)]| {
            let u = u.normalize();
            u.dot(m)
                - rims
                    .iter()
                    .map(|(a, r)| r * (1.0 - a.dot(&u).powi(2)).sqrt())
                    .sum::<f64>()
        };
        let cases = [
            (
                Vector3::new(2.0, 0.3, 0.1),
                vec![(Vector3::new(0.2, 0.9, 0.3).normalize(), 0.5)],
            ),
            (
                Vector3::new(1.6, -0.4, 0.5),
                vec![
                    (Vector3::z(), 0.5),
                    (Vector3::new(0.5, 0.3, 0.8).normalize(), 0.3),
                ],
            ),
        ];
        for (m, rims) in cases {
            // A start a tenth of a radian or so off, as a warm start's.
            let start = (m.normalize() + Vector3::new(0.02, 0.05, -0.03)).normalize();
            let u = sphere_newton(start, &m, &rims).expect("converges");
            assert!((u.norm() - 1.0).abs() < 1e-15);
            let best = f(&u, &m, &rims);
            let across = [
                u.cross(&Vector3::x()).normalize(),
                u.cross(&Vector3::y()).normalize(),
            ];
            for e in across {
                for h in [1e-4, -1e-4, 1e-3, -1e-3] {
                    assert!(f(&(u + e * h), &m, &rims) <= best + 1e-15, "{h}");
                }
                let slope = (f(&(u + e * 1e-6), &m, &rims) - f(&(u - e * 1e-6), &m, &rims)) / 2e-6;
                assert!(slope.abs() < 1e-8, "{slope}");
            }
        }
    }

    /// Two rims whose nearest points lie just outside A's rim and above
    /// it, so that the direction between them is within a hundredth of a
    /// radian of A's axis, where the sphere's closed form gives up: the
    /// rims' angles give the points that a scan of both angles, refined
    /// about its best, finds, from starts a tenth of a radian off.
    #[test]
    fn rim_pair_newton_finds_the_scanned_nearest_points_near_an_axis() {
        let (r_a, r_b) = (0.5, 0.3);
        let axis_b = Vector3::new(0.3, 0.9, 0.2).normalize();
        let down = (-Vector3::z() + axis_b * axis_b.z).normalize();
        let side = axis_b.cross(&down);
        for (angle, outside, height) in [(1.2, 5e-4, 0.1), (-2.0, 3e-4, 0.05), (0.4, 1e-4, 0.3)] {
            let radial = Vector3::new(f64::cos(angle), f64::sin(angle), 0.0);
            // B's lowest point hovers over A's rim.
            let lowest = radial * (r_a + outside) + Vector3::z() * height;
            let m = lowest - down * r_b;
            let point = |a: f64, b: f64| {
                let n_a = Vector3::new(a.cos(), a.sin(), 0.0);
                let n_b = down * b.cos() + side * b.sin();
                m + n_b * r_b - n_a * r_a
            };
            // The scan: a coarse grid of both angles, then finer grids
            // about the best.
            let (mut best, mut span) = ((0.0, 0.0), std::f64::consts::PI);
            for _ in 0..12 {
                let (a0, b0) = best;
                let mut least = f64::INFINITY;
                for i in -50..=50 {
                    for j in -50..=50 {
                        let (a, b) = (
                            a0 + span * f64::from(i) / 50.0,
                            b0 + span * f64::from(j) / 50.0,
                        );
                        let d = point(a, b).norm();
                        if d < least {
                            (least, best) = (d, (a, b));
                        }
                    }
                }
                span /= 10.0;
            }
            let scanned = point(best.0, best.1);
            let want = scanned / scanned.norm();
            let sine = want.x.hypot(want.y);
            assert!(sine < RIM_FLOOR / 4.0, "{sine}");
            let rims = [(Vector3::z(), r_a), (axis_b, r_b)];
            assert!(sphere_newton(want, &m, &rims).is_none());
            let starts = [
                Vector3::new(f64::cos(angle + 0.1), f64::sin(angle + 0.1), 0.0),
                down * f64::cos(0.1) - side * f64::sin(0.1),
            ];
            let u = rim_pair_newton(starts, &m, &rims[0], &rims[1]).expect("converges");
            // The scan finds the angles only to about the square root of
            // f64's precision, the distance is flat there.
            assert!((u - want).norm() < 1e-7, "{u:?} vs {want:?}");
            // The rims' points at `u` (A's support at `u`, B's at `-u`)
            // are the nearest: their difference lies along `u` and is no
            // longer than the scan's. Near A's axis its rim point turns by
            // `u`'s round-off over the sine, hence the looser direction.
            let across =
                |axis: &Vector3<f64>, d: Vector3<f64>| (d - axis * axis.dot(&d)).normalize();
            let gap = m + across(&axis_b, -u) * r_b - across(&Vector3::z(), u) * r_a;
            assert!(
                gap.norm() <= scanned.norm() + 1e-15,
                "{} vs {}",
                gap.norm(),
                scanned.norm()
            );
            assert!((gap / gap.norm() - u).norm() < 1e-10, "{gap:?} vs {u:?}");
        }
    }
}
