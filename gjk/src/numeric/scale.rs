//! Exact scaling by powers of two, and a norm that neither overflows nor
//! underflows.

use nalgebra::Vector3;

/// A power of two `k` and its inverse such that `m·k` lies in [1, 2) for a
/// normal `m` (and is at least 2^-52 for a subnormal one): scaling by `k` is
/// exact, and brings lengths near 1 where their squares, and the cofactors'
/// products of squares, can neither overflow nor underflow. `(1, 1)` for 0,
/// infinity and NaN.
#[inline]
pub(crate) fn pow2_scale(m: f64) -> (f64, f64) {
    if !(m > 0.0 && m <= f64::MAX) {
        return (1.0, 1.0);
    }
    let biased = ((m.to_bits() >> 52) & 0x7ff) as i32;
    // Subnormals count as 2^-1022; the clamp keeps both factors normal.
    let e = (biased.max(1) - 1023).clamp(-1020, 1020);
    let pow = |x: i32| f64::from_bits(((1023 + x) as u64) << 52);
    (pow(-e), pow(e))
}

/// `|v|` without overflow or underflow of the squares: the plain norm where
/// that is safe, else the norm of `v` scaled by a power of two.
#[inline]
pub(crate) fn robust_norm(v: &Vector3<f64>) -> f64 {
    let n = v.norm();
    if n > 1e-140 && n < 1e140 {
        return n;
    }
    let (k, inv_k) = pow2_scale(v.amax());
    (v * k).norm() * inv_k
}
