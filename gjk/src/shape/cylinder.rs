//! The cylinder's support function, and the 32-bit codes by which its
//! support points ride in the simplex and the warm start where a polytope's
//! vertex indices do.
//!
//! A cylinder of radius `r` and half-height `h` about the body z axis is a
//! disk swept along a segment: `s(d) = sign(d_z)·h·ẑ + r·(d_x, d_y)/|(d_x, d_y)|`.
//! Its support points have no index, so the direction of the rim point is
//! kept instead, as a code: bit 31 says which cap (set: `z = +h`), the other
//! 31 bits the rim direction's "diamond angle" `t ∈ [0, 4)` (the angle's
//! piecewise-rational stand-in: a division to compute, none of the trigonometry)
//! quantised in `2^31 - 1` steps, or 0 for the cap's centre (the support
//! point of a direction along the axis). Any code is a point of the cylinder,
//! so any code is a valid warm start.
//!
//! The quantised direction is within `2·(4 / (2^31 - 1)) / 2 < 1.9e-9` rad
//! of the exact one (the diamond angle's slope is at least 1/2), so its
//! support value falls short of the exact `r·|d_xy|` by a relative
//! `1 - cos(1.9e-9) < 2e-18`: a hundredth of f64's round-off, well inside
//! the `64 ε` allowance every bound already carries for round-off. The
//! support function is exact to f64 precision; it is not a polytope of any
//! resolution the arithmetic could tell.

use nalgebra::Vector3;

/// The cap bit of a code: set for the top cap (`z = +h`).
const TOP: u32 = 1 << 31;

/// The number of quantised rim directions.
const STEPS: u32 = (1 << 31) - 1;

/// The code of the support point of a cylinder in direction `d`: the cap
/// by the sign of `d_z` (a zero goes to the bottom, as a box gives ties to
/// the lower face), the rim point by `(d_x, d_y)`, or the cap's centre when
/// that is zero or NaN.
#[inline(always)]
pub(crate) fn support_code(d: &Vector3<f64>) -> u32 {
    let cap = if d.z > 0.0 { TOP } else { 0 };
    let (mut x, mut y) = (d.x, d.y);
    let mut sum = x.abs() + y.abs();
    if sum == f64::INFINITY {
        // Both near f64::MAX: halving is exact and changes no direction.
        (x, y) = (x * 0.5, y * 0.5);
        sum = x.abs() + y.abs();
    }
    // Zero (the axis direction), NaN or an infinite component: the centre.
    if !(sum > 0.0 && sum < f64::INFINITY) {
        return cap;
    }
    let t = diamond_angle(x, y, sum);
    let q = round_small(t * (f64::from(STEPS) / 4.0)) as u32;
    cap | (if q >= STEPS { 0 } else { q } + 1)
}

/// `x` (in `[0, 2^51)`) rounded to the nearest integer, ties to even: the
/// addition of `2^52` leaves no fraction bits. `f64::round` is a call into
/// libm on a target without SSE4.1, in the support of every iteration.
#[inline(always)]
fn round_small(x: f64) -> f64 {
    const SHIFT: f64 = 4_503_599_627_370_496.0;
    (x + SHIFT) - SHIFT
}

/// The diamond angle of `(x, y)` (not both zero, `sum = |x| + |y|` finite):
/// `t ∈ [0, 4]`, increasing with the angle, one unit a quadrant. On the
/// upper half (`y >= 0`) it is `1 - x/sum`, on the lower `3 + x/sum`
/// (`|x| + |y| = sum` gives each quadrant's form from these), that is
/// `2 ∓ (1 + x/sum)`: one division and a sign flip, where a branch on the
/// quadrant was mispredicted on every turn of the direction.
#[inline(always)]
fn diamond_angle(x: f64, y: f64, sum: f64) -> f64 {
    let share = x / sum;
    2.0 - negate_if(1.0 + share, y < 0.0)
}

/// `x`, negated when `flip`: a flip of the sign bit, with no branch (the
/// compiler made one of a select between `x` and `-x`, mispredicted on a
/// random cap or half).
#[inline(always)]
pub(crate) fn negate_if(x: f64, flip: bool) -> f64 {
    f64::from_bits(x.to_bits() ^ (u64::from(flip) << 63))
}

/// The code of the point at the same angle on the other cap.
#[inline(always)]
pub(crate) fn other_cap(code: u32) -> u32 {
    code ^ TOP
}

/// Whether `code` is a point of the top cap.
#[inline(always)]
pub(crate) fn is_top(code: u32) -> bool {
    code & TOP != 0
}

/// Whether `code` is a rim point (not a cap's centre).
#[inline(always)]
pub(crate) fn on_rim(code: u32) -> bool {
    code & !TOP != 0
}

/// The point of `code` on the cylinder of radius `r`, half-height `h`
/// (its body frame, centred at the origin).
#[inline(always)]
pub(crate) fn point(code: u32, r: f64, h: f64) -> Vector3<f64> {
    let z = negate_if(h, code & TOP == 0);
    let q = code & !TOP;
    if q == 0 {
        return Vector3::new(0.0, 0.0, z);
    }
    let t = f64::from(q - 1) * (4.0 / f64::from(STEPS));
    // The inverse of `diamond_angle`, by halves as it is: `x = 1 - t` on
    // the upper half, `t - 3` on the lower.
    let upper = t <= 2.0;
    let x = negate_if(t - 2.0, upper) - 1.0;
    let y = negate_if(1.0 - x.abs(), !upper);
    // |x| + |y| = 1: the length is in [1/√2, 1], no overflow, no underflow.
    let k = r / (x * x + y * y).sqrt();
    Vector3::new(x * k, y * k, z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shape::test_rng::Rng;

    /// The support value of a code's point reaches the exact one,
    /// `h·|d_z| + r·|d_xy|`, to a few ε, for random, axis, tiny and huge
    /// directions; every code's point lies on the cylinder's surface.
    #[test]
    fn codes_give_the_exact_support_value() {
        let mut rng = Rng(0x5eed_c711_0000_0001);
        let (r, h) = (0.7, 1.3);
        for k in 0..20_000 {
            let mut d = Vector3::new(rng.next(), rng.next(), rng.next());
            match k % 6 {
                1 => d.x = 0.0,
                2 => d *= 1e-300,
                3 => d *= 1e300,
                4 => d = Vector3::new(f64::MAX, -f64::MAX, d.z),
                5 => d = Vector3::new(d.x * 1e-12, 0.0, d.z),
                _ => {}
            }
            let p = point(support_code(&d), r, h);
            let exact = h * d.z.abs() + r * d.x.hypot(d.y);
            let got = p.dot(&d);
            let scale = (h * d.z.abs()).max(r * d.x.hypot(d.y));
            assert!(
                (got - exact).abs() <= 4.0 * f64::EPSILON * scale,
                "{d:?}: {got:e} vs {exact:e}"
            );
            let rim = p.x.hypot(p.y);
            assert!(rim == 0.0 || (rim - r).abs() <= 2.0 * f64::EPSILON * r);
            assert_eq!(p.z.abs(), h);
            assert_eq!(p.z > 0.0, d.z > 0.0, "{d:?}: the cap");
        }
    }

    #[test]
    fn axis_and_nan_directions_give_the_cap_centre() {
        for (d, z) in [
            (Vector3::new(0.0, 0.0, 1.0), 2.0),
            (Vector3::new(-0.0, 0.0, -1.0), -2.0),
            (Vector3::new(0.0, 0.0, 0.0), -2.0),
            (Vector3::new(f64::NAN, 0.0, 1.0), 2.0),
        ] {
            assert_eq!(point(support_code(&d), 1.0, 2.0), Vector3::new(0.0, 0.0, z));
        }
        // The cap bit alone is the top's centre; every other code is a rim
        // point, the largest included.
        assert_eq!(point(TOP, 1.0, 2.0), Vector3::new(0.0, 0.0, 2.0));
        for code in [u32::MAX, TOP + 1, TOP - 1, 1] {
            let p = point(code, 1.0, 2.0);
            assert!((p.x.hypot(p.y) - 1.0).abs() < 1e-15, "{code}");
        }
    }

    /// The shifted rounding is `f64::round` but at ties (to even, not
    /// away from zero), over the codes' whole range and its ends.
    #[test]
    fn shifted_rounding_matches_round_but_at_ties() {
        let mut rng = Rng(0x5eed_c711_0000_0003);
        let top = f64::from(STEPS);
        let mut xs = vec![0.0, 0.25, 0.75, 1.0 - 1e-16, 1.0, top - 0.5 + 1e-6, top];
        xs.extend((0..20_000).map(|_| (rng.next() * 0.5 + 0.5) * top));
        for x in xs {
            assert_eq!(round_small(x), x.round(), "{x}");
        }
        for (tie, even) in [(0.5, 0.0), (1.5, 2.0), (2.5, 2.0), (top - 0.5, top - 1.0)] {
            assert_eq!(round_small(tie), even, "{tie}");
        }
    }
}
